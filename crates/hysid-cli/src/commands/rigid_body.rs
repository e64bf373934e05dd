//! `hysid rigid-body ls`: inverse-dynamics least squares of a rigid body with friction (step
//! 1 of Gunnar et al. 2006; the reference method of the EMPS benchmark, Janot et al. 2019).

use crate::cli::RigidBodyLsArgs;
use crate::output::{preflight, write_json};
use anyhow::{Context, Result};
use hysid::data::{CsvSpec, IdData};
use hysid::identify::rigid_body::{RigidBodyEstimate, RigidBodyLs};
use serde_json::json;
use std::path::Path;

/// Estimates on one record; relative errors on every validation record.
pub fn ls(args: &RigidBodyLsArgs) -> Result<()> {
    preflight(&[args.json.as_deref()], &[])?;
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
    if let Some(path) = &args.json {
        write_json(path, &report(&estimate, records, args))?;
        println!("  report: {}", path.display());
    }
    Ok(())
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

/// The JSON report: parameters by name, a relative error per record, the settings.
fn report(
    estimate: &RigidBodyEstimate,
    records: Vec<serde_json::Value>,
    args: &RigidBodyLsArgs,
) -> serde_json::Value {
    let parameters: serde_json::Map<String, serde_json::Value> = (0..estimate.names.len())
        .map(|i| {
            (
                estimate.names[i].clone(),
                json!({
                    "value": estimate.values[i],
                    "std": estimate.std[i],
                    "relative_std_percent": estimate.relative_std_percent[i],
                }),
            )
        })
        .collect();
    json!({
        "model": "rigid_body",
        "parameters": parameters,
        "records": records,
        "condition_number": estimate.condition_number_unscaled,
        "condition_number_scaled": estimate.condition_number,
        "equations": estimate.equations,
        "settings": {
            "gain": args.gain, "offset": args.offset, "cutoff_hz": args.cutoff,
            "filter_order": args.order, "decimation": args.decimate, "border": args.border,
            "position": args.position, "input": args.input,
        },
    })
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
