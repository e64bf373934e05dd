//! The report of the three-step actuator identification of Gunnar et al. (2006): one
//! [`Report`] per step in `details.steps`, the m67 model at the top. The step-2 and step-3
//! models carry the pre-filter they were fitted with (`prefilter`), so that `hysid simulate`
//! on the raw data sets reproduces their fit %.

use super::{DataSummary, Report, SearchSummary, UncertaintySummary, ValidationEntry};
use crate::identify::actuator::{tables::MODELS, ActuatorIdentification, PARAMETERS};
use crate::model::greybox::models::ActuatorFixed;
use crate::model::greybox::{Simulation, StateSpaceModel};
use crate::model::saved::FittedGreyBox;
use crate::model::saved::FittedModel;
use crate::{Error, Result};
use serde_json::json;

/// The report of `id`: `model`, `fit` and `search` are m67's (sets 6 and 7), `validation`
/// lists m67 on data sets 6, 7 and 8 (filtered, simulated from rest: Table II), and
/// `details.steps` holds one report per step: step 1 (rigid body, data set 1), step 2 (m0 from
/// the steady-state loops, sets 2–5), and the four step-3 fits m67, m68, m67f, m68f.
pub fn three_steps_report(
    id: &ActuatorIdentification,
    truth: Option<&[f64]>,
    source: Vec<String>,
    simulation: Simulation,
) -> Result<Report> {
    let mut steps = vec![step1(id), step2(id, simulation)];
    for (name, second) in [("m67", 1), ("m68", 2), ("m67f", 1), ("m68f", 2)] {
        let data = id.validation.select(&[0, second])?;
        let fit = &id.step3[name];
        let model = id
            .fitted(name, simulation)
            .map(|m| m.to_file())
            .ok_or_else(|| Error::InvalidModel(format!("step 3 has no fit {name}")))?;
        let step = Report::of_output_error(
            &format!("actuator identify: step 3 {name}"),
            &data,
            vec![format!("data sets 6 and {}", second + 6)],
            model,
            &fit.fit,
            fit.elapsed_s,
            UncertaintySummary::asymptotic(),
        )?;
        steps.push(step);
    }
    let m67 = steps[2].clone();
    let validation = (0..id.validation.n_experiments())
        .map(|e| {
            ValidationEntry::of(
                format!("data set {} (filtered, from rest)", e + 6),
                id.validation.output(e, 0),
                &id.simulated["m67"][e],
                None,
            )
        })
        .collect::<Result<Vec<_>>>()?;
    let truth = truth.map(|t| {
        PARAMETERS
            .iter()
            .zip(t)
            .map(|(n, v)| (n.to_string(), *v))
            .collect::<std::collections::BTreeMap<_, _>>()
    });
    Ok(Report {
        data: Some(DataSummary {
            source,
            samples: id.validation.n_samples(),
            experiments: 8,
            ts: Some(id.validation.ts()),
        }),
        validation,
        details: json!({
            "steps": steps,
            "fit_table": MODELS.iter().map(|m| (m.to_string(), id.fit_table[*m].clone())).collect::<std::collections::BTreeMap<_, _>>(),
            "sensitivity": id.sensitivity,
            "j": id.j,
            "truth": truth,
        }),
        ..Report::new("actuator identify").with_model(
            m67.model,
            m67.fit,
            m67.search,
            m67.uncertainty,
        )
    })
}

/// Step 1: rigid-body least squares on data set 1 (Jt, Fv, Fc; no simulation model).
fn step1(id: &ActuatorIdentification) -> Report {
    let s = &id.step1;
    let parameters: Vec<_> = s
        .names
        .iter()
        .zip(s.values.iter().zip(&s.std))
        .map(|(n, (v, e))| json!({"name": n, "value": v, "std": e}))
        .collect();
    Report {
        data: Some(DataSummary {
            source: vec!["data set 1".into()],
            samples: 0,
            experiments: 1,
            ts: None,
        }),
        search: Some(SearchSummary::direct(0.0)),
        uncertainty: Some(UncertaintySummary::least_squares()),
        details: json!({
            "parameters": parameters,
            "relative_std_percent": s.relative_std_percent,
            "relative_error_percent": s.relative_error_percent,
            "condition_number": s.condition_number,
            "J": id.j,
        }),
        ..Report::new("actuator identify: step 1")
    }
}

/// Step 2: m0 = (J, Fv, Fc from step 1; k1, k2, α, A from the steady-state loops).
fn step2(id: &ActuatorIdentification, simulation: Simulation) -> Report {
    let mut parameters = ActuatorFixed.parameters();
    parameters.set_values(&id.m0);
    let mut std = vec![f64::NAN; PARAMETERS.len()];
    std[1] = id.step1.std.get(1).copied().unwrap_or(f64::NAN);
    std[2] = id.step1.std.get(2).copied().unwrap_or(f64::NAN);
    std[3..].copy_from_slice(&id.step2.std);
    let m0 = FittedModel::prefiltered(
        FittedModel::GreyBox(FittedGreyBox {
            kind: "actuator_fixed".into(),
            parameters,
            std,
            simulation,
            initial_state: vec![0.0; 3],
        }),
        id.prefilter,
    );
    Report {
        data: Some(DataSummary {
            source: vec!["data sets 2-5".into()],
            samples: id.step2.loops.iter().map(|l| l.x1.len()).sum(),
            experiments: id.step2.loops.len(),
            ts: None,
        }),
        model: Some(m0.to_file()),
        search: Some(SearchSummary::direct(0.0)),
        uncertainty: Some(UncertaintySummary::least_squares()),
        details: json!({"rms_residual_torque": id.step2.rms}),
        ..Report::new("actuator identify: step 2")
    }
}
