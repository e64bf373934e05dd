//! The report of `rigid-body ls`: inverse-dynamics least squares of
//! g·u = M q̈ + Fv q̇ + Fc sgn(q̇) (+ offset) (J. Gunnar, E. Wernholt, G. Hovland,
//! T. Brogårdh, "Nonlinear Grey-Box Identification of Linear Actuators Containing
//! Hysteresis", ICRA 2006, step 1; the IDIM reference of A. Janot, M. Gautier, M. Brunot,
//! "Data set and reference models of EMPS", 2019).
//!
//! The model is the built-in `rigid_body` grey-box model with the estimates; `fit` is null
//! (an inverse-dynamics fit predicts the force, it does not simulate); `details` hold the
//! relative standard deviations, the relative error per record, the condition numbers and
//! the settings.

use super::{DataSummary, Report, SearchSummary, UncertaintySummary};
use crate::identify::rigid_body::{RigidBodyEstimate, RigidBodyLs};
use crate::model::greybox::models::RigidBody;
use crate::model::greybox::{Simulation, StateSpaceModel};
use crate::model::saved::FittedModel;
use serde_json::{json, Value};
use std::collections::BTreeMap;

/// The estimate as the built-in `rigid_body` grey-box model: the estimated parameters with
/// their standard deviations, the others fixed (the offset at 0 when not estimated, the
/// gain at `gain`).
pub fn rigid_body_model(estimate: &RigidBodyEstimate, gain: f64) -> FittedModel {
    let mut parameters = RigidBody.parameters();
    let mut std = vec![f64::NAN; parameters.len()];
    for (i, sigma) in std.iter_mut().enumerate() {
        let p = parameters.get_mut(i);
        match estimate.names.iter().position(|n| *n == p.name) {
            Some(k) => {
                p.value = estimate.values[k];
                *sigma = estimate.std[k];
            }
            None => {
                p.fixed = true;
                if p.name == "gain" {
                    p.value = gain;
                }
            }
        }
    }
    FittedModel::GreyBox {
        kind: "rigid_body".into(),
        parameters,
        std,
        simulation: Simulation::default(),
        initial_state: vec![0.0; RigidBody.states().len()],
    }
}

/// The report of `rigid-body ls` on one record of `samples` samples read from `source`:
/// `records` lists the relative error per record (`{file, role, relative_error_percent}`),
/// `settings` the settings beyond those of `ls` (e.g. the column names), added to
/// `details.settings`.
pub fn rigid_body_report(
    estimate: &RigidBodyEstimate,
    ls: &RigidBodyLs,
    source: String,
    samples: usize,
    elapsed_s: f64,
    records: Vec<Value>,
    settings: Value,
) -> Report {
    let mut all_settings = json!({
        "gain": ls.gain, "offset": ls.offset, "cutoff_hz": ls.cutoff_hz,
        "filter_order": ls.filter_order, "decimation": ls.decimation, "border": ls.border,
    });
    if let (Some(obj), Value::Object(more)) = (all_settings.as_object_mut(), settings) {
        obj.extend(more);
    }
    let relative_std: BTreeMap<String, f64> = estimate
        .names
        .iter()
        .cloned()
        .zip(estimate.relative_std_percent.iter().copied())
        .collect();
    Report {
        data: Some(DataSummary {
            source: vec![source],
            samples,
            experiments: 1,
            ts: None,
        }),
        model: Some(rigid_body_model(estimate, ls.gain).to_file()),
        search: Some(SearchSummary::direct(elapsed_s)),
        uncertainty: Some(UncertaintySummary::least_squares()),
        details: json!({
            "relative_std_percent": relative_std,
            "records": records,
            "condition_number": estimate.condition_number_unscaled,
            "condition_number_scaled": estimate.condition_number,
            "equations": estimate.equations,
            "settings": all_settings,
        }),
        ..Report::new("rigid-body ls")
    }
}
