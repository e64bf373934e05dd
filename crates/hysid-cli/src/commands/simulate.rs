//! `hysid simulate`: run a saved model (or the model of a report) on new records.

use super::zoo::time_steps;
use crate::cli::SimulateArgs;
use crate::exit::UsageError;
use crate::output::Outputs;
use anyhow::{Context, Result};
use hysid::data::{write_csv, CsvSpec, IdData};
use hysid::model::saved::FittedModel;
use hysid::report::simulate_report_after;

/// Runs the model on every record (processed as its fit processed them) and compares with
/// the output column when given. The outputs are one transaction: written to temporaries,
/// renamed into place together at the end, and never an input file.
pub fn run(args: &SimulateArgs) -> Result<()> {
    if args.csv.is_some() && args.data.len() > 1 {
        return Err(UsageError(
            "--csv writes the signals of one record; give one --data with --csv, or leave --csv out; run 'hysid simulate --help' for the options".into(),
        )
        .into());
    }
    let mut inputs = vec![args.model.as_path()];
    inputs.extend(args.data.iter().map(|p| p.as_path()));
    inputs.extend(args.history.iter().map(|p| p.as_path()));
    let mut out = Outputs::new(&inputs, args.json.as_deref(), None, None)?;
    let csv = out.file(args.csv.as_deref())?;
    let model =
        FittedModel::load(&args.model)?.with_evaluator(crate::options::evaluator(&args.evaluator)?);
    let spec = CsvSpec {
        inputs: args.input.clone(),
        outputs: args.output.iter().cloned().collect(),
        time: args.time.clone(),
        ts: args.ts,
        time_steps: time_steps(&model),
    };
    let data = args
        .data
        .iter()
        .map(|path| IdData::from_file(path, &spec))
        .collect::<hysid::Result<Vec<_>>>()?;
    let records: Vec<(String, &IdData)> = args
        .data
        .iter()
        .map(|p| p.display().to_string())
        .zip(&data)
        .collect();
    // Errors (never returns) when the simulated output is not finite.
    let history = args
        .history
        .as_ref()
        .map(|path| {
            IdData::from_file(
                path,
                &CsvSpec {
                    outputs: Vec::new(),
                    ..spec.clone()
                },
            )
        })
        .transpose()
        .with_context(|| "reading --history".to_string())?;
    let (report, predictions) =
        simulate_report_after(&model, &records, history.as_ref(), args.warm_up).with_context(
            || {
                format!(
                    "simulating on {}",
                    records
                        .iter()
                        .map(|(s, _)| s.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            },
        )?;
    if let (Some(csv), Some(p)) = (&csv, predictions.first()) {
        let mut headers: Vec<&str> = args.input.iter().map(String::as_str).collect();
        headers.push("simulated");
        let mut cols: Vec<&[f64]> = p.inputs.iter().map(Vec::as_slice).collect();
        cols.push(&p.outputs[0]);
        if let (Some(name), Some(y)) = (&args.output, &p.measured) {
            headers.push(name.as_str());
            cols.push(y);
        }
        write_csv(&csv.tmp, &headers, &cols)?;
    }
    let kind = report.model.as_ref().map_or("", |m| m.kind());
    for ((source, d), p) in records.iter().zip(&predictions) {
        say!(
            "Simulated {kind} on {source} ({} samples{})",
            d.experiment(0).len(),
            if p.outputs[0].len() == d.experiment(0).len() {
                String::new()
            } else {
                format!(", {} as the fit saw them", p.outputs[0].len())
            }
        );
    }
    if let Some(fit) = &report.fit {
        say!("  fit {:.2} %   RMSE {:.4e}", fit.fit_percent, fit.rmse);
    }
    if let Some(path) = &args.csv {
        say!("  simulated output: {}", path.display());
    }
    out.finish(Some(&report), None)
}
