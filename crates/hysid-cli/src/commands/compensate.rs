//! `hysid compensate`: the input that makes a fitted hysteresis model follow a reference.

use super::zoo::{signals, time_steps};
use crate::cli_zoo::CompensateArgs;
use anyhow::{Context, Result};
use hysid::data::{write_csv, CsvSpec, IdData};
use hysid::io::atomic::OutputSet;
use hysid::model::compensate::compensate_within;
use hysid::model::saved::{FittedModel, ModelFile, SavedModel};
use hysid::report::compensation_report;

/// Clipped ranges printed in the warning before it is cut short (the report lists all).
const PRINTED_RANGES: usize = 5;

/// Inverts the model along the reference, writes OUT.csv, the report and the plots.
pub fn run(args: &CompensateArgs) -> Result<()> {
    let mut files = OutputSet::new(&[args.model.as_path(), args.data.as_path()])?;
    // The directory first: a file inside it is then refused as a clash.
    let plots_tmp = args.plots.as_deref().map(|p| files.dir(p)).transpose()?;
    let csv_tmp = files.file(&args.csv)?;
    let json_tmp = args.json.as_deref().map(|p| files.file(p)).transpose()?;
    let saved = ModelFile::load(&args.model)?;
    let model = FittedModel::from_file(&saved)?;
    super::warn_history_beyond_the_inverse(&model, &args.model);
    let limits = args.limits.or_else(|| saved.limits());
    if limits.is_none() {
        tell!(
            "warning: {} records no input_range (a file of an earlier version) and no --limits was given: the command is not limited",
            args.model.display()
        );
    }
    let spec = CsvSpec {
        inputs: vec![args.reference.clone()],
        outputs: Vec::new(),
        time: args.time.clone(),
        ts: args.ts,
        time_steps: time_steps(&model),
    };
    let data = IdData::from_file(&args.data, &spec)
        .with_context(|| format!("reading {}", args.data.display()))?;
    let reference = data.experiment(0).input(0);
    let c = compensate_within(&model, reference, limits)
        .with_context(|| format!("compensating with {}", args.model.display()))?;
    let (rms, max) = c.tracking_error();
    let ranges = c.clipped_ranges();
    let file = model.to_file();
    let family = match &file.model {
        SavedModel::Operator(op) => op.family.as_str(),
        other => other.kind(),
    };
    say!(
        "Compensated {} samples of '{}' with the {family} model",
        reference.len(),
        args.reference
    );
    say!("  predicted tracking error: RMS {rms:.4e}, max {max:.4e}");
    if !c.clipped.is_empty() {
        let shown: Vec<String> = ranges
            .iter()
            .take(PRINTED_RANGES)
            .map(|(a, b)| {
                if a == b {
                    format!("{a}")
                } else {
                    format!("{a}-{b}")
                }
            })
            .collect();
        let more = if ranges.len() > PRINTED_RANGES {
            ", …"
        } else {
            ""
        };
        tell!(
            "warning: {} of {} reference samples lie outside the model's reachable range or need a command beyond the limits, and were clipped (samples {}{more}); see the report",
            c.clipped.len(),
            reference.len(),
            shown.join(", ")
        );
    }
    let report = compensation_report(
        &model,
        &data,
        &c,
        vec![args.data.display().to_string()],
        &args.reference,
        &args.model.display().to_string(),
    );
    write_csv(
        &csv_tmp,
        &["reference", "u", "predicted"],
        &[reference, &c.u, &c.predicted],
    )?;
    if let Some(dir) = &plots_tmp {
        signals(
            &dir.join("compensation.svg"),
            "Compensation: reference and predicted output",
            "output",
            &[("reference", reference), ("predicted", &c.predicted)],
        )?;
        signals(
            &dir.join("input.svg"),
            "Compensating input",
            "u",
            &[("u", &c.u)],
        )?;
    }
    if let Some(path) = &json_tmp {
        hysid::io::atomic::write(path, report.to_json()?)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    files.commit()?;
    say!("  compensating input: {}", args.csv.display());
    for (what, path) in [("report", &args.json), ("plots", &args.plots)] {
        if let Some(p) = path {
            say!("  {what}: {}", p.display());
        }
    }
    Ok(())
}
