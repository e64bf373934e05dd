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

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate() -> RigidBodyEstimate {
        RigidBodyEstimate {
            names: vec!["M".into(), "Fv".into(), "Fc".into()],
            values: vec![1.5, 20.0, 3.0],
            std: vec![0.01, 0.2, 0.03],
            relative_std_percent: vec![0.67, 1.0, 1.0],
            relative_error_percent: 2.5,
            condition_number: 4.0,
            condition_number_unscaled: 40.0,
            equations: 1000,
        }
    }

    /// The estimates go into the built-in model by name; the gain is fixed at the given
    /// value and the offset, not estimated, fixed.
    #[test]
    fn model_holds_the_estimates_and_fixes_the_rest() {
        let file = rigid_body_model(&estimate(), 35.15).to_file();
        let p = |name: &str| file.parameters.iter().find(|p| p.name == name).unwrap();
        assert_eq!(file.kind, "rigid_body");
        assert_eq!(
            (p("M").value, p("M").std, p("M").fixed),
            (1.5, Some(0.01), false)
        );
        assert_eq!((p("Fc").value, p("Fc").std), (3.0, Some(0.03)));
        assert_eq!(
            (p("gain").value, p("gain").fixed, p("gain").std),
            (35.15, true, None)
        );
        assert!(p("offset").fixed);
    }

    #[test]
    fn report_lists_settings_and_records() {
        let ls = RigidBodyLs::default();
        let records =
            vec![json!({"file": "a.csv", "role": "estimation", "relative_error_percent": 2.5})];
        let r = rigid_body_report(
            &estimate(),
            &ls,
            "a.csv".into(),
            4000,
            0.1,
            records,
            json!({"position": "q"}),
        );
        assert_eq!(r.command, "rigid-body ls");
        assert_eq!(r.details["relative_std_percent"]["Fv"], 1.0);
        assert_eq!(r.details["settings"]["cutoff_hz"], 100.0);
        assert_eq!(r.details["settings"]["position"], "q");
        assert_eq!(r.details["condition_number"], 40.0);
        assert_eq!(r.data.as_ref().map(|d| d.samples), Some(4000));
        assert!(r.to_json().is_ok());
    }
}
