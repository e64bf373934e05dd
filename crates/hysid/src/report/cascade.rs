//! The reports of `identify cascade` and `identify hysteresis`: the Coleman–Hodgdon
//! hysteresis (J. Vörös, "Modeling and Identification of Discrete-Time Nonlinear Dynamic
//! Cascade Systems with Input Hysteresis", Math. Probl. Eng. 2015, 393572) alone or followed
//! by a linear block A(q⁻¹)y = q⁻ᵏB(q⁻¹)v, fitted by output error.
//!
//! `details` of a cascade: admissibility of the hysteresis, spectral radius of the linear
//! block, the switching threshold d, whether re-classifying the samples by the final d was
//! consistent, the key-term iteration, the output-error history, the multi-start candidates,
//! the asymptotic standard deviations σ²(JᵀJ)⁻¹ and the bootstrap's (when run).

use super::{Report, UncertaintySummary};
use crate::data::IdData;
use crate::identify::cascade::CascadeFit;
use crate::identify::hysteresis::{HysteresisFit, InitialOutput};
use crate::identify::operator_cascade::OperatorCascadeFit;
use crate::model::saved::FittedModel;
use crate::model::saved::{FittedCascade, FittedHysteresis, FittedOperatorCascade};
use crate::Result;
use serde_json::{json, Value};

/// The report of a cascade fit on `data` (read from `source`) under `command`
/// (`identify cascade`, `demo voros`); the keys of `extra` are added to `details`.
pub fn cascade_report(
    command: &str,
    fit: &CascadeFit,
    data: &IdData,
    source: Vec<String>,
    extra: Value,
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
    let details = json!({
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
    let uncertainty = match &fit.bootstrap {
        Some(b) => UncertaintySummary::bootstrap(b.replicates.len(), b.failed),
        None => UncertaintySummary::asymptotic(),
    };
    let model = FittedModel::Cascade(FittedCascade {
        model: fit.model.clone(),
        std: fit.std(),
    });
    Ok(Report::of_output_error(
        command,
        data,
        source,
        model.to_file(),
        oe,
        fit.elapsed_s,
        uncertainty,
    )?
    .with_details(merged(details, extra)))
}

/// The report of `identify hysteresis`: the hysteresis fitted on `data` (read from
/// `source`), starting from the measured or a zero output (`initial`).
pub fn hysteresis_report(
    fit: &HysteresisFit,
    data: &IdData,
    source: Vec<String>,
    initial: InitialOutput,
) -> Result<Report> {
    let oe = &fit.output_error;
    let model = FittedModel::Hysteresis(FittedHysteresis {
        model: fit.model.clone(),
        initial,
        std: fit.std(),
    });
    let details = json!({
        "admissibility": fit.model.admissibility(),
        "threshold": fit.threshold,
        "separated_regression": {
            "d_history": fit.separated.d_history,
            "termination": fit.separated.termination.to_string(),
        },
        "output_error_history": oe.report.history,
    });
    Ok(Report::of_output_error(
        "identify hysteresis",
        data,
        source,
        model.to_file(),
        oe,
        fit.elapsed_s,
        UncertaintySummary::asymptotic(),
    )?
    .with_details(details))
}

/// `details` with the keys of `extra` added (an `extra` that is not an object adds nothing).
pub(super) fn merged(mut details: Value, extra: Value) -> Value {
    if let (Some(obj), Value::Object(more)) = (details.as_object_mut(), extra) {
        obj.extend(more);
    }
    details
}

/// The fitted model of an operator cascade (any hysteresis operator followed by a linear
/// block, `docs/models/operator-cascade.md`) with its asymptotic standard deviations.
pub fn operator_cascade_model(fit: &OperatorCascadeFit) -> FittedModel {
    FittedModel::OperatorCascade(FittedOperatorCascade {
        model: fit.model.clone(),
        std: fit.output_error.std().to_vec(),
    })
}

/// The report of `identify cascade` with an operator family (`family`) on `data` (read
/// from `source`): the output-error fit of the operator cascade; `details` hold the family,
/// the global start and how it was found, the spectral radius of the linear block and the
/// largest modulus of its zeros, and the output-error history; the keys of `extra` are
/// added to `details`.
pub fn operator_cascade_report(
    family: &str,
    fit: &OperatorCascadeFit,
    data: &IdData,
    source: Vec<String>,
    extra: Value,
) -> Result<Report> {
    let details = json!({
        "family": family,
        "initialisation": fit.initialisation,
        "start": fit.start.parameters().values(),
        "linear_block_spectral_radius": fit.model.linear.spectral_radius(),
        "linear_block_zero_radius": fit.model.zero_radius(),
        "output_error_history": fit.output_error.report.history,
        "orientation": fit.orientation.map(|o| o.orientation.short_name()),
        "orientation_source": fit.orientation.map(|o| o.source.name()),
    });
    Ok(Report::of_output_error(
        "identify cascade",
        data,
        source,
        operator_cascade_model(fit).to_file(),
        &fit.output_error,
        fit.elapsed_s,
        UncertaintySummary::asymptotic(),
    )?
    .with_details(merged(extra, details)))
}
