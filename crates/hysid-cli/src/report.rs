//! The JSON report and the printed parameter table.

use hysid::data::IdData;
use hysid::identify::OutputErrorFit;
use hysid::model::saved::ModelFile;
use hysid::numerics::metrics;
use hysid::numerics::Termination;
use serde::Serialize;

/// The JSON report every identification command writes with `--json`.
#[derive(Debug, Serialize)]
pub struct Report {
    /// The fitted model, in the model-file layout.
    pub model: ModelFile,
    /// fit % of the simulated against the measured output.
    pub fit_percent: f64,
    /// Root-mean-square error of the simulated output.
    pub rmse: f64,
    /// Iterations of the final output-error fit.
    pub iterations: usize,
    /// Why the final fit stopped, in words.
    pub termination: String,
    /// Why the final fit stopped, as a code.
    pub termination_code: Termination,
    /// Wall-clock time of the identification.
    pub elapsed_s: f64,
    /// Samples used.
    pub samples: usize,
    /// Mean squared residual.
    pub loss: f64,
    /// Akaike's final prediction error.
    pub fpe: f64,
    /// Akaike's information criterion.
    pub aic: f64,
    /// How the standard deviations were obtained.
    pub uncertainty: String,
    /// Command-specific details.
    pub details: serde_json::Value,
}

impl Report {
    /// The report of an output-error fit whose simulated output `yhat` is compared with the
    /// measured `y`.
    pub fn new(
        model: ModelFile,
        fit: &OutputErrorFit,
        (y, yhat): (&[f64], &[f64]),
        elapsed_s: f64,
        uncertainty: String,
        details: serde_json::Value,
    ) -> Self {
        Self {
            model,
            fit_percent: metrics::fit_percent(y, yhat),
            rmse: metrics::rmse(y, yhat),
            iterations: fit.report.iterations,
            termination: fit.report.termination.to_string(),
            termination_code: fit.report.termination.clone(),
            elapsed_s,
            samples: y.len(),
            loss: fit.loss,
            fpe: fit.fpe,
            aic: fit.aic,
            uncertainty,
            details,
        }
    }

    /// [`Report::new`] over every experiment of `data`: output 0 of each, measured and
    /// simulated, stacked.
    pub fn stacked(
        model: ModelFile,
        fit: &OutputErrorFit,
        data: &IdData,
        elapsed_s: f64,
        uncertainty: String,
        details: serde_json::Value,
    ) -> Self {
        let y: Vec<f64> = data
            .experiments()
            .iter()
            .flat_map(|e| e.output(0).iter().copied())
            .collect();
        let yhat: Vec<f64> = fit
            .simulated
            .iter()
            .flat_map(|s| s[0].iter().copied())
            .collect();
        Self::new(model, fit, (&y, &yhat), elapsed_s, uncertainty, details)
    }
}

/// One row of the printed parameter table.
pub struct Row {
    /// Parameter name.
    pub name: String,
    /// True value (examples only).
    pub truth: Option<f64>,
    /// Initial value (when one was given).
    pub initial: Option<f64>,
    /// Estimate.
    pub estimate: f64,
    /// Standard deviation.
    pub std: f64,
}

/// Prints the rows as an aligned table, MATLAB-`present` style.
pub fn print_table(rows: &[Row]) {
    let with_truth = rows.iter().any(|r| r.truth.is_some());
    let with_initial = rows.iter().any(|r| r.initial.is_some());
    let mut header = format!("  {:<10}", "parameter");
    if with_truth {
        header += &format!("{:>12}", "true");
    }
    if with_initial {
        header += &format!("{:>12}", "initial");
    }
    header += &format!("{:>14}   {:<12}", "estimate", "± std");
    println!("{header}");
    for r in rows {
        let mut line = format!("  {:<10}", r.name);
        if with_truth {
            line += &r
                .truth
                .map_or(format!("{:>12}", ""), |v| format!("{v:>12.6}"));
        }
        if with_initial {
            line += &r
                .initial
                .map_or(format!("{:>12}", "-"), |v| format!("{v:>12.6}"));
        }
        let std = if r.std.is_finite() {
            format!("{:.3e}", r.std)
        } else {
            "n/a".into()
        };
        line += &format!("{:>14.8} ± {std}", r.estimate);
        println!("{line}");
    }
}
