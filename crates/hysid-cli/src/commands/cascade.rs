//! Printing a cascade identification (the report is `hysid::report::cascade_report`) (shared by `demo voros` and
//! `identify cascade`).

use crate::cli::UncertaintyArg;
use crate::report::{figures, Report, Row};
use hysid::identify::cascade::CascadeFit;
use hysid::identify::Uncertainty;
use hysid::model::saved::FittedCascade;
use hysid::model::saved::FittedModel;

/// True for the Coleman–Hodgdon forms (`ch4`, `ch6`) of the paper-1 pipeline; every other
/// name is an operator family (`commands/operator_cascade.rs`).
pub fn is_coleman_hodgdon(name: &str) -> bool {
    matches!(name.trim().to_ascii_lowercase().as_str(), "ch4" | "ch6")
}

/// The estimator setting for a command-line choice.
pub fn uncertainty(arg: UncertaintyArg, replicates: usize) -> Uncertainty {
    match arg {
        UncertaintyArg::Asymptotic => Uncertainty::Asymptotic,
        UncertaintyArg::Bootstrap => Uncertainty::Bootstrap(replicates),
    }
}

/// The fitted model with the reported standard deviations.
pub fn fitted(fit: &CascadeFit) -> FittedModel {
    FittedModel::Cascade(FittedCascade {
        model: fit.model.clone(),
        std: fit.std(),
    })
}

/// Table rows: estimate ± std, with the truth and the initial values when known.
pub fn rows(fit: &CascadeFit, truth: Option<&[f64]>, initial: Option<&[f64]>) -> Vec<Row> {
    let names = fit.output_error.parameters.names();
    let est = fit.model.params();
    let std = fit.std();
    names
        .into_iter()
        .enumerate()
        .map(|(i, name)| Row {
            name,
            truth: truth.map(|t| t[i]),
            initial: initial.and_then(|p| p.get(i).copied()),
            estimate: est[i],
            std: std[i],
        })
        .collect()
}

/// Prints the lines under the table: the paper's iteration, the final fit, warnings.
pub fn print_summary(fit: &CascadeFit, report: &Report) {
    if let Some(k) = &fit.key_term {
        say!(
            "  paper iteration (key-term separation): {} iterations, {}",
            k.history.len().saturating_sub(1),
            k.termination
        );
    }
    let oe = &fit.output_error;
    say!(
        "  output-error fit: {} iterations, {} function evaluations, {}",
        oe.report.iterations,
        oe.report.function_evaluations,
        oe.report.termination
    );
    let (fit_percent, rmse, fpe) = figures(report);
    let method = report
        .uncertainty
        .as_ref()
        .map_or("none", |u| u.method.as_str());
    say!(
        "  fit {fit_percent:.2} %   RMSE {rmse:.4e}   FPE {}   time {:.2} s   std: {method} (threshold d: truncated normal)",
        crate::report::criterion(fpe, true),
        fit.elapsed_s
    );
    let adm = fit.model.hysteresis.admissibility();
    if !adm.holds {
        say!(
            "  warning: the identified hysteresis is not admissible: {}",
            adm.violations.join("; ")
        );
    }
    if !fit.model.linear.is_stable() {
        say!(
            "  warning: the identified linear block is unstable (spectral radius {:.4})",
            fit.model.linear.spectral_radius()
        );
    }
    if !fit.switching_consistent {
        say!(
            "  note: re-classifying the samples by the final d did not lower the criterion; the best classification is kept"
        );
    }
}
