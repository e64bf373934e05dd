//! `hysid rigid-body ls`: inverse-dynamics least squares of a rigid body with friction (step
//! 1 of Gunnar et al. 2006; the reference method of the EMPS benchmark, Janot et al. 2019).

use crate::cli::RigidBodyLsArgs;
use crate::output::Outputs;
use anyhow::{Context, Result};
use hysid::data::{CsvSpec, IdData};
use hysid::identify::rigid_body::{RigidBodyEstimate, RigidBodyLs};
use hysid::report::{rigid_body_model, rigid_body_report, Report, RigidBodyRecord};
use serde_json::json;
use std::path::Path;

/// Estimates on one record; relative errors and fit % on every validation record.
pub fn ls(args: &RigidBodyLsArgs) -> Result<()> {
    let mut inputs = vec![args.data.as_path()];
    inputs.extend(args.validate.iter().map(|p| p.as_path()));
    let mut out = Outputs::new(
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
    // The model predicts the drive signal from the position (as `simulate` runs it).
    out.fitted_on_columns(
        ts,
        hysid::model::saved::Columns {
            inputs: vec![args.position.clone()],
            outputs: vec![args.input.clone()],
        },
    );
    let estimate = ls
        .estimate(&q, &u, ts)
        .with_context(|| args.data.display().to_string())?;
    print_estimate(&estimate, args);
    let validation = args
        .validate
        .iter()
        .map(|path| Ok((path.display().to_string(), record(path, args)?)))
        .collect::<Result<Vec<_>>>()?;
    let source = args.data.display().to_string();
    let estimation = RigidBodyRecord {
        source: &source,
        q: &q,
        u: &u,
        ts,
    };
    let validation: Vec<RigidBodyRecord> = validation
        .iter()
        .map(|(source, (q, u, ts))| RigidBodyRecord {
            source,
            q,
            u,
            ts: *ts,
        })
        .collect();
    let settings = json!({"position": args.position, "input": args.input});
    let report = rigid_body_report(
        &estimate,
        &ls,
        estimation,
        &validation,
        clock.elapsed().as_secs_f64(),
        settings,
    )?;
    print_records(&report);
    out.finish(Some(&report), Some(&rigid_body_model(&estimate, &ls)))
}

/// The relative error and fit % of the predicted drive signal per record.
fn print_records(report: &Report) {
    if let Some(fit) = &report.fit {
        say!(
            "  predicted drive signal: fit {:.2} % on the estimation record (decimated, borders dropped)",
            fit.fit_percent
        );
    }
    let records = report.details["records"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    for (r, v) in records.iter().skip(1).zip(&report.validation) {
        say!(
            "  relative error {:.4} %, fit {:.2} % on {}",
            r["relative_error_percent"].as_f64().unwrap_or(f64::NAN),
            v.fit_percent,
            v.source
        );
    }
}

/// The settings, the estimates with their standard deviations, the fit and the condition.
fn print_estimate(estimate: &RigidBodyEstimate, args: &RigidBodyLsArgs) {
    say!(
        "Rigid body g·u = M q̈ + Fv q̇ + Fc sgn(q̇){}: inverse-dynamics least squares on {}",
        if args.offset { " + offset" } else { "" },
        args.data.display()
    );
    say!(
        "  {} Hz Butterworth (order {}, zero phase), decimation {}, {} border samples, gain {}; {} equations",
        args.cutoff, args.order, args.decimate, args.border, args.gain, estimate.equations
    );
    say!(
        "  {:<10}{:>16}   {:<12}{:>12}",
        "parameter",
        "estimate",
        "± std",
        "rel. std"
    );
    for i in 0..estimate.names.len() {
        say!(
            "  {:<10}{:>16.6}   {:<12}{:>10.3} %",
            estimate.names[i],
            estimate.values[i],
            format!("{:.3e}", estimate.std[i]),
            estimate.relative_std_percent[i]
        );
    }
    say!(
        "  relative error {:.4} % on the estimation record; condition number {:.2} ({:.2} with the columns scaled to unit norm)",
        estimate.relative_error_percent,
        estimate.condition_number_unscaled,
        estimate.condition_number
    );
}

/// Position, drive signal and sample time of a record.
fn record(path: &Path, args: &RigidBodyLsArgs) -> Result<(Vec<f64>, Vec<f64>, f64)> {
    let spec = CsvSpec {
        inputs: vec![args.input.clone()],
        outputs: vec![args.position.clone()],
        time: None,
        ts: None,
        ..CsvSpec::default()
    };
    let data = IdData::from_file(path, &spec)?;
    let exp = data.experiment(0);
    Ok((exp.output(0).to_vec(), exp.input(0).to_vec(), data.ts()))
}
