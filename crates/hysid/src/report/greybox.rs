//! The reports of `greybox fit` and `benchmark bouc-wen`: a continuous-time grey-box model
//! ẋ = f(t, x, u, θ), y = h(x, u, θ) fitted by output error (L. Ljung, *System
//! Identification: Theory for the User*, 2nd ed., 1999, §4.5, §10.2), and the Bouc–Wen
//! hysteretic benchmark of J.-P. Noël and M. Schoukens ("Hysteretic benchmark with a dynamic
//! nonlinearity", Workshop on Nonlinear System Identification Benchmarks, 2016), scored by
//! e_RMS = √(mean (y − ŷ)²) in simulation.
//!
//! `details` of a grey-box fit: mean-square error per experiment, the number of simulations
//! without and with sensitivities, rejected trial steps, the correlation matrix of the
//! estimates, the iteration history and the multi-start screening.

use super::cascade::merged;
use super::{Report, UncertaintySummary, ValidationEntry};
use crate::data::IdData;
use crate::identify::bouc_wen_benchmark::PUBLISHED;
use crate::identify::greybox::GreyBoxFit;
use crate::identify::validate::{residual_analysis, ResidualAnalysis};
use crate::model::saved::ModelFile;
use crate::Result;
use serde_json::{json, Value};

/// Residual lags of the residual analysis in the reports.
pub const RESIDUAL_LAGS: usize = 25;

/// The report of a grey-box fit under `command` on `data` (read from `source`), with the
/// model file `model`; the keys of `extra` are added to `details`, the fit's warnings (a
/// band-limited input held between samples) are the report's `warnings`.
pub fn greybox_report(
    command: &str,
    fit: &GreyBoxFit,
    data: &IdData,
    source: Vec<String>,
    model: ModelFile,
    extra: Value,
) -> Result<Report> {
    let oe = &fit.fit;
    let n = oe.parameters.len();
    let correlation: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| oe.covariance.correlation[(i, j)]).collect())
        .collect();
    let details = json!({
        "mse_per_experiment": oe.mse,
        "simulations_without_sensitivities": oe.report.residual_evaluations,
        "simulations_with_sensitivities": oe.report.sensitivity_evaluations,
        "rejected_trials": oe.report.rejected_trials,
        "correlation": correlation,
        "history": oe.report.history,
        "starts": fit.starts,
        "hold_check": fit.hold_check,
        "evaluation": fit.evaluation,
    });
    let mut report = Report::of_output_error(
        command,
        data,
        source,
        model,
        oe,
        fit.elapsed_s,
        UncertaintySummary::asymptotic(),
    )?
    .with_details(merged(details, extra));
    report.warnings = fit.warnings();
    Ok(report)
}

/// Residual analysis (auto-correlation of the residual, cross-correlation with each input,
/// [`RESIDUAL_LAGS`] lags) of every experiment's first output.
pub fn greybox_residuals(fit: &GreyBoxFit, data: &IdData) -> Vec<ResidualAnalysis> {
    (0..data.n_experiments())
        .map(|e| residual_analysis(data, e, 0, &fit.fit.simulated[e][0], RESIDUAL_LAGS))
        .collect()
}

/// The report of `benchmark bouc-wen`: the grey-box report of the training fit with the
/// training e_RMS, the published e_RMS of other methods and the residual analysis in
/// `details`, and one `validation` entry (with e_RMS) per test record.
pub fn bouc_wen_benchmark_report(
    fit: &GreyBoxFit,
    data: &IdData,
    source: Vec<String>,
    model: ModelFile,
    tests: Vec<ValidationEntry>,
    steady_state: bool,
) -> Result<Report> {
    let extra = json!({
        "training_e_rms": fit.fit.mse[0][0].sqrt(),
        "steady_state": steady_state,
        "published_multisine_e_rms": PUBLISHED.iter().map(|(who, e)| json!({"method": who, "e_rms": e})).collect::<Vec<_>>(),
        "residual_analysis": greybox_residuals(fit, data),
    });
    let mut report = greybox_report("benchmark bouc-wen", fit, data, source, model, extra)?;
    report.validation = tests;
    Ok(report)
}
