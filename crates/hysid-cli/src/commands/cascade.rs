//! Reporting and plotting a cascade identification (shared by `demo voros` and
//! `identify cascade`).

use crate::cli::UncertaintyArg;
use crate::report::{figures, of_output_error, Report, Row};
use anyhow::Result;
use hysid::data::IdData;
use hysid::identify::cascade::CascadeFit;
use hysid::identify::Uncertainty;
use hysid::model::saved::FittedModel;
use hysid::report::UncertaintySummary;
use serde_json::json;

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
    FittedModel::Cascade {
        model: fit.model.clone(),
        std: fit.std(),
    }
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

/// The report of a cascade fit on `data` (read from `sources`).
pub fn report(
    command: &str,
    fit: &CascadeFit,
    data: &IdData,
    sources: Vec<String>,
    uncertainty: Uncertainty,
    extra: serde_json::Value,
) -> Result<Report> {
    let oe = &fit.output_error;
    let key_term = fit.key_term.as_ref().map(|k| {
        json!({
            "termination": k.termination.to_string(),
            "iterations": k.history.len().saturating_sub(1),
            "history": k.history,
            "equation_error": k.costs,
        })
    });
    let mut details = json!({
        "admissibility": fit.model.hysteresis.admissibility(),
        "linear_block_spectral_radius": fit.model.linear.spectral_radius(),
        "threshold": fit.threshold,
        "switching_consistent": fit.switching_consistent,
        "key_term_iteration": key_term,
        "output_error_history": oe.report.history,
        "candidates": fit.candidates.iter().map(|c| json!({"origin": c.origin, "cost": c.cost, "start": c.start, "refined": c.refined})).collect::<Vec<_>>(),
        "asymptotic_std": oe.std(),
        "bootstrap": fit.bootstrap.as_ref().map(|b| json!({"replicates": b.replicates.len(), "failed": b.failed, "std": b.std})),
    });
    if let (Some(obj), serde_json::Value::Object(more)) = (details.as_object_mut(), extra) {
        obj.extend(more);
    }
    let uncertainty = match (&fit.bootstrap, uncertainty) {
        (Some(b), _) => UncertaintySummary::bootstrap(b.replicates.len(), b.failed),
        (None, _) => UncertaintySummary::asymptotic(),
    };
    Ok(of_output_error(
        command,
        oe,
        data,
        sources,
        fitted(fit).to_file(),
        fit.elapsed_s,
        uncertainty,
        details,
    )?)
}

/// Prints the lines under the table: the paper's iteration, the final fit, warnings.
pub fn print_summary(fit: &CascadeFit, report: &Report) {
    if let Some(k) = &fit.key_term {
        println!(
            "  paper iteration (key-term separation): {} iterations, {}",
            k.history.len().saturating_sub(1),
            k.termination
        );
    }
    let oe = &fit.output_error;
    println!(
        "  output-error fit: {} iterations, {} function evaluations, {}",
        oe.report.iterations, oe.report.function_evaluations, oe.report.termination
    );
    let (fit_percent, rmse, fpe) = figures(report);
    let method = report
        .uncertainty
        .as_ref()
        .map_or("none", |u| u.method.as_str());
    println!(
        "  fit {fit_percent:.2} %   RMSE {rmse:.4e}   FPE {fpe:.4e}   time {:.2} s   std: {method} (threshold d: truncated normal)",
        fit.elapsed_s
    );
    let adm = fit.model.hysteresis.admissibility();
    if !adm.holds {
        println!(
            "  warning: the identified hysteresis is not admissible: {}",
            adm.violations.join("; ")
        );
    }
    if !fit.model.linear.is_stable() {
        println!(
            "  warning: the identified linear block is unstable (spectral radius {:.4})",
            fit.model.linear.spectral_radius()
        );
    }
    if !fit.switching_consistent {
        println!(
            "  note: re-classifying the samples by the final d did not lower the criterion; the best classification is kept"
        );
    }
}
