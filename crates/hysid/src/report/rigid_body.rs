//! The report of `rigid-body ls`: inverse-dynamics least squares of
//! g·u = M q̈ + Fv q̇ + Fc sgn(q̇) (+ offset) (J. Gunnar, E. Wernholt, G. Hovland,
//! T. Brogårdh, "Nonlinear Grey-Box Identification of Linear Actuators Containing
//! Hysteresis", ICRA 2006, step 1; the IDIM reference of A. Janot, M. Gautier, M. Brunot,
//! "Data set and reference models of EMPS", 2019).
//!
//! The model is the built-in `rigid_body` grey-box model with the estimates and the
//! regression's preprocessing (`inverse_dynamics`): it predicts the drive signal
//! û = (M q̈ + Fv q̇ + Fc sgn(q̇) + offset)/g from the measured position. `fit` is that
//! prediction's fit % against the measured drive signal, on the regression's samples
//! (filtered, decimated, borders dropped), so `hysid simulate` reproduces it; `validation`
//! holds the same per validation record; `details` hold the relative standard deviations,
//! the relative error per record, the condition numbers and the settings.

use super::{DataSummary, FitSummary, Report, SearchSummary, UncertaintySummary, ValidationEntry};
use crate::identify::rigid_body::{RigidBodyEstimate, RigidBodyLs};
use crate::model::greybox::models::RigidBody;
use crate::model::greybox::{Simulation, StateSpaceModel};
use crate::model::saved::FittedModel;
use crate::Result;
use serde_json::{json, Value};
use std::collections::BTreeMap;

/// The estimate as the built-in `rigid_body` grey-box model with the preprocessing of `ls`:
/// the estimated parameters with their standard deviations, the others fixed (the offset at
/// 0 when not estimated, the gain at `ls.gain`).
pub fn rigid_body_model(estimate: &RigidBodyEstimate, ls: &RigidBodyLs) -> FittedModel {
    let mut parameters = RigidBody.parameters();
    let mut std = vec![f64::NAN; parameters.len()];
    for (i, sigma) in std.iter_mut().enumerate() {
        let p = parameters.get_mut(i);
        // The inertia is the regression's first column whatever its name (`M`, `Jt`).
        let column = match p.name.as_str() {
            "M" => Some(0),
            name => estimate.names.iter().position(|n| n == name),
        };
        match column {
            Some(k) => {
                p.value = estimate.values[k];
                *sigma = estimate.std[k];
            }
            None => {
                p.fixed = true;
                if p.name == "gain" {
                    p.value = ls.gain;
                }
            }
        }
    }
    FittedModel::InverseDynamics {
        model: Box::new(FittedModel::GreyBox {
            kind: "rigid_body".into(),
            parameters,
            std,
            simulation: Simulation::default(),
            initial_state: vec![0.0; RigidBody.states().len()],
        }),
        preprocessing: ls.preprocessing(),
    }
}

/// One record of `rigid-body ls`: position q and drive signal u sampled every `ts`, read
/// from `source`.
#[derive(Clone, Copy, Debug)]
pub struct RigidBodyRecord<'a> {
    /// Where it was read from.
    pub source: &'a str,
    /// Position q.
    pub q: &'a [f64],
    /// Drive signal u.
    pub u: &'a [f64],
    /// Sample time \[s\].
    pub ts: f64,
}

impl RigidBodyRecord<'_> {
    /// The measured and predicted drive signal of `model` on this record.
    fn prediction(&self, model: &FittedModel) -> Result<(Vec<f64>, Vec<f64>)> {
        let p = model.predict(&[self.q], Some(self.u), self.ts)?;
        let measured = p.measured.unwrap_or_default();
        Ok((measured, p.outputs.into_iter().next().unwrap_or_default()))
    }
}

/// The report of `rigid-body ls` of `estimate` (with `ls`) on the `estimation` record, with
/// the relative error and fit % on every `validation` record; `settings` (e.g. the column
/// names) are added to `details.settings`.
pub fn rigid_body_report(
    estimate: &RigidBodyEstimate,
    ls: &RigidBodyLs,
    estimation: RigidBodyRecord,
    validation: &[RigidBodyRecord],
    elapsed_s: f64,
    settings: Value,
) -> Result<Report> {
    let model = rigid_body_model(estimate, ls);
    let (u, u_hat) = estimation.prediction(&model)?;
    let fit = FitSummary::of(&[estimation.source.to_string()], &[&u], &[&u_hat])?;
    let mut records = vec![json!({
        "file": estimation.source,
        "role": "estimation",
        "relative_error_percent": estimate.relative_error_percent,
    })];
    let mut entries = Vec::new();
    for r in validation {
        let error = ls.relative_error(estimate, r.q, r.u, r.ts)?;
        records
            .push(json!({"file": r.source, "role": "validation", "relative_error_percent": error}));
        let (u, u_hat) = r.prediction(&model)?;
        entries.push(ValidationEntry::of(r.source.to_string(), &u, &u_hat, None)?);
    }
    Ok(Report {
        data: Some(DataSummary {
            source: vec![estimation.source.to_string()],
            samples: estimation.q.len(),
            experiments: 1,
            ts: Some(estimation.ts),
        }),
        validation: entries,
        details: details(estimate, ls, records, settings),
        ..Report::new("rigid-body ls").with_model(
            Some(model.to_file()),
            Some(fit),
            Some(SearchSummary::direct(elapsed_s)),
            Some(UncertaintySummary::least_squares()),
        )
    })
}

/// The relative standard deviations, the relative error per record, the condition numbers
/// and the settings.
fn details(
    estimate: &RigidBodyEstimate,
    ls: &RigidBodyLs,
    records: Vec<Value>,
    settings: Value,
) -> Value {
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
    json!({
        "relative_std_percent": relative_std,
        "records": records,
        "condition_number": estimate.condition_number_unscaled,
        "condition_number_scaled": estimate.condition_number,
        "equations": estimate.equations,
        "settings": all_settings,
    })
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
    /// value and the offset, not estimated, fixed; the preprocessing is saved.
    #[test]
    fn model_holds_the_estimates_and_fixes_the_rest() {
        let ls = RigidBodyLs {
            gain: 35.15,
            ..RigidBodyLs::emps()
        };
        let file = rigid_body_model(&estimate(), &ls).to_file();
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
        let id = file.inverse_dynamics.unwrap();
        assert_eq!(
            (id.cutoff_hz, id.order, id.decimation, id.border),
            (100.0, 4, 10, 50)
        );
    }

    /// On a noise-free record of the estimated rigid body (a slow sine, u from the analytic
    /// derivatives) the predicted drive signal fits to the accuracy of the numerical
    /// differentiation, on the decimated samples without the borders.
    #[test]
    fn report_states_the_fit_of_the_predicted_drive_signal() {
        let (ts, n) = (1e-3, 20_000);
        let q: Vec<f64> = (0..n).map(|k| 0.1 * (2.0 * k as f64 * ts).sin()).collect();
        let u: Vec<f64> = (0..n)
            .map(|k| {
                let t = k as f64 * ts;
                let (qd, qdd) = (0.2 * (2.0 * t).cos(), -0.4 * (2.0 * t).sin());
                1.5 * qdd + 20.0 * qd + 3.0 * crate::numerics::sign0(qd)
            })
            .collect();
        let ls = RigidBodyLs {
            decimation: 10,
            border: 50,
            ..RigidBodyLs::default()
        };
        let record = RigidBodyRecord {
            source: "a.csv",
            q: &q,
            u: &u,
            ts,
        };
        let r = rigid_body_report(
            &estimate(),
            &ls,
            record,
            &[record],
            0.1,
            json!({"position": "q"}),
        )
        .unwrap();
        assert_eq!(r.command, "rigid-body ls");
        let fit = r.fit.as_ref().unwrap();
        assert!(fit.fit_percent > 99.0, "{}", fit.fit_percent);
        assert_eq!(fit.per_experiment[0].samples, 2000 - 10);
        assert_eq!(r.validation[0].fit_percent, fit.fit_percent);
        assert_eq!(r.details["relative_std_percent"]["Fv"], 1.0);
        assert_eq!(r.details["settings"]["cutoff_hz"], 100.0);
        assert_eq!(r.details["settings"]["position"], "q");
        assert_eq!(r.details["condition_number"], 40.0);
        assert_eq!(r.data.as_ref().map(|d| d.samples), Some(n));
        assert!(r.to_json().is_ok());
    }
}
