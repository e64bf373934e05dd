//! `hysid rigid-body ls`: inverse-dynamics least squares of a rigid body with friction (step
//! 1 of Gunnar et al. 2006; the reference method of the EMPS benchmark, Janot et al. 2019).

use crate::cli::RigidBodyLsArgs;
use crate::output::Outputs;
use anyhow::{Context, Result};
use hysid::data::{CsvSpec, IdData};
use hysid::identify::rigid_body::{RigidBodyEstimate, RigidBodyLs};
use hysid::model::greybox::models::RigidBody;
use hysid::model::greybox::{Simulation, StateSpaceModel};
use hysid::model::saved::FittedModel;
use hysid::report::{DataSummary, Report, SearchSummary, UncertaintySummary};
use serde_json::json;
use std::path::Path;

/// Estimates on one record; relative errors on every validation record.
pub fn ls(args: &RigidBodyLsArgs) -> Result<()> {
    let mut inputs = vec![args.data.as_path()];
    inputs.extend(args.validate.iter().map(|p| p.as_path()));
    let out = Outputs::new(
        &inputs,
        args.json.as_deref(),
        args.model_out.as_deref(),
        None,
    )?;
    let clock = std::time::Instant::now();
    let ls = RigidBodyLs {
        inertia_name: "M".into(),
        gain: args.gain,
        offset: args.offset,
        cutoff_hz: args.cutoff,
        filter_order: args.order,
        decimation: args.decimate,
        border: args.border,
    };
    let (q, u, ts) = record(&args.data, args)?;
    let estimate = ls
        .estimate(&q, &u, ts)
        .with_context(|| args.data.display().to_string())?;
    print_estimate(&estimate, args);
    let mut records = vec![json!({
        "file": args.data,
        "role": "estimation",
        "relative_error_percent": estimate.relative_error_percent,
    })];
    for path in &args.validate {
        let (q, u, ts) = record(path, args)?;
        let error = ls
            .relative_error(&estimate, &q, &u, ts)
            .with_context(|| path.display().to_string())?;
        println!("  relative error {error:.4} % on {}", path.display());
        records.push(json!({
            "file": path,
            "role": "validation",
            "relative_error_percent": error,
        }));
    }
    let report = report(
        &estimate,
        records,
        args,
        q.len(),
        clock.elapsed().as_secs_f64(),
    );
    out.finish(Some(&report), Some(&fitted(&estimate, args)))
}

/// The settings, the estimates with their standard deviations, the fit and the condition.
fn print_estimate(estimate: &RigidBodyEstimate, args: &RigidBodyLsArgs) {
    println!(
        "Rigid body g·u = M q̈ + Fv q̇ + Fc sgn(q̇){}: inverse-dynamics least squares on {}",
        if args.offset { " + offset" } else { "" },
        args.data.display()
    );
    println!(
        "  {} Hz Butterworth (order {}, zero phase), decimation {}, {} border samples, gain {}; {} equations",
        args.cutoff, args.order, args.decimate, args.border, args.gain, estimate.equations
    );
    println!(
        "  {:<10}{:>16}   {:<12}{:>12}",
        "parameter", "estimate", "± std", "rel. std"
    );
    for i in 0..estimate.names.len() {
        println!(
            "  {:<10}{:>16.6}   {:<12}{:>10.3} %",
            estimate.names[i],
            estimate.values[i],
            format!("{:.3e}", estimate.std[i]),
            estimate.relative_std_percent[i]
        );
    }
    println!(
        "  relative error {:.4} % on the estimation record; condition number {:.2} ({:.2} with the columns scaled to unit norm)",
        estimate.relative_error_percent,
        estimate.condition_number_unscaled,
        estimate.condition_number
    );
}

/// The report: the estimate as a `rigid_body` model (M q̈ + Fv q̇ + Fc sgn(q̇) + offset =
/// gain·u), `fit` null (an inverse-dynamics fit predicts the force, it does not simulate),
/// the relative error per record, the condition numbers and the settings in `details`.
fn report(
    estimate: &RigidBodyEstimate,
    records: Vec<serde_json::Value>,
    args: &RigidBodyLsArgs,
    samples: usize,
    elapsed_s: f64,
) -> Report {
    Report {
        data: Some(DataSummary {
            source: vec![args.data.display().to_string()],
            samples,
            experiments: 1,
            ts: None,
        }),
        model: Some(fitted(estimate, args).to_file()),
        search: Some(SearchSummary::direct(elapsed_s)),
        uncertainty: Some(UncertaintySummary::least_squares()),
        details: json!({
            "relative_std_percent": estimate.names.iter().cloned().zip(estimate.relative_std_percent.iter().copied()).collect::<std::collections::BTreeMap<_, _>>(),
            "records": records,
            "condition_number": estimate.condition_number_unscaled,
            "condition_number_scaled": estimate.condition_number,
            "equations": estimate.equations,
            "settings": {
                "gain": args.gain, "offset": args.offset, "cutoff_hz": args.cutoff,
                "filter_order": args.order, "decimation": args.decimate, "border": args.border,
                "position": args.position, "input": args.input,
            },
        }),
        ..Report::new("rigid-body ls")
    }
}

/// The estimate as the built-in `rigid_body` grey-box model (offset fixed at 0 when not
/// estimated, the gain fixed at `--gain`).
fn fitted(estimate: &RigidBodyEstimate, args: &RigidBodyLsArgs) -> FittedModel {
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
                    p.value = args.gain;
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

/// Position, drive signal and sample time of a record.
fn record(path: &Path, args: &RigidBodyLsArgs) -> Result<(Vec<f64>, Vec<f64>, f64)> {
    let spec = CsvSpec {
        inputs: vec![args.input.clone()],
        outputs: vec![args.position.clone()],
        time: None,
        ts: None,
    };
    let data = IdData::from_file(path, &spec)?;
    let exp = data.experiment(0);
    Ok((exp.output(0).to_vec(), exp.input(0).to_vec(), data.ts()))
}
