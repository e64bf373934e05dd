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

use super::{CovarianceSummary, DataSummary, FitSummary, Report, SearchSummary};
use super::{UncertaintySummary, ValidationEntry};
use crate::identify::rigid_body::{RigidBodyEstimate, RigidBodyLs};
use crate::model::greybox::models::RigidBody;
use crate::model::greybox::{Simulation, StateSpaceModel};
use crate::model::saved::FittedGreyBox;
use crate::model::saved::FittedModel;
use crate::numerics::metrics;
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
        model: Box::new(FittedModel::GreyBox(FittedGreyBox {
            kind: "rigid_body".into(),
            parameters,
            std,
            simulation: Simulation::default(),
            initial_state: vec![0.0; RigidBody.states().len()],
        })),
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
    let mut fit = FitSummary::of(&[estimation.source.to_string()], &[&u], &[&u_hat])?;
    // AIC and FPE of the prediction scored in `fit` (its N samples, loss V its mean squared
    // error), with p the estimated parameters, as every output-error fit gives them.
    let (n, p) = (u.len(), estimate.values.len());
    let loss = metrics::mse(&u, &u_hat);
    let finite = |v: f64| v.is_finite().then_some(v);
    fit.aic = finite(metrics::aic(loss, n, p));
    fit.fpe = finite(metrics::fpe(loss, n, p));
    let file = model.to_file();
    // The regression's covariance over the model's names (its inertia column is `M`).
    let names: Vec<String> = (0..estimate.names.len())
        .map(|k| {
            if k == 0 {
                "M".into()
            } else {
                estimate.names[k].clone()
            }
        })
        .collect();
    let covariance = (estimate.covariance.len() == names.len())
        .then(|| CovarianceSummary::of(&file, &names, |i, j| estimate.covariance[i][j]))
        .flatten();
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
            Some(file),
            Some(fit),
            Some(SearchSummary::direct(elapsed_s)),
            Some(UncertaintySummary::least_squares().with_covariance(covariance)),
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
