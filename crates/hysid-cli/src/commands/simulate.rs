//! `hysid simulate`: run a saved model on new input data.

use crate::cli::SimulateArgs;
use anyhow::{Context, Result};
use hysid::data::{write_csv, CsvSpec, IdData};
use hysid::fitted::FittedModel;
use hysid::io::atomic::{ensure_finite, OutputSet};
use hysid::metrics;
use serde_json::json;

/// Simulates the model on the input columns; compares with the output column when given.
/// The outputs are one transaction: written to temporaries, renamed into place together at
/// the end, and never an input file.
pub fn run(args: &SimulateArgs) -> Result<()> {
    let mut files = OutputSet::new(&[args.model.as_path(), args.data.as_path()])?;
    let csv_tmp = args.out_csv.as_deref().map(|p| files.file(p)).transpose()?;
    let json_tmp = args.json.as_deref().map(|p| files.file(p)).transpose()?;
    let model = FittedModel::load(&args.model)?;
    let spec = CsvSpec {
        inputs: args.input.clone(),
        outputs: args.output.iter().cloned().collect(),
        time: args.time.clone(),
        ts: args.ts,
    };
    let data = IdData::from_file(&args.data, &spec)?;
    let exp = data.experiment(0);
    let inputs: Vec<&[f64]> = (0..args.input.len()).map(|c| exp.input(c)).collect();
    let measured = args.output.as_ref().map(|_| exp.output(0));
    let outputs = model
        .simulate(
            &inputs,
            data.ts(),
            measured.and_then(|y| y.first().copied()),
        )
        .with_context(|| format!("simulating on {}", args.data.display()))?;
    let yhat = &outputs[0];
    let kind = model.to_file().kind;
    let scores = measured.map(|y| (metrics::fit_percent(y, yhat), metrics::rmse(y, yhat)));
    // Refused as a numerical failure before anything is written or printed.
    ensure_finite(&(yhat, scores)).context("the simulated output")?;
    if let Some(path) = &csv_tmp {
        let mut headers: Vec<&str> = args.input.iter().map(String::as_str).collect();
        headers.push("simulated");
        let mut cols: Vec<&[f64]> = inputs.clone();
        cols.push(yhat);
        if let (Some(name), Some(y)) = (&args.output, measured) {
            headers.push(name.as_str());
            cols.push(y);
        }
        write_csv(path, &headers, &cols)?;
    }
    if let Some(path) = &json_tmp {
        let report = json!({
            "model": model.to_file(),
            "samples": exp.len(),
            "fit_percent": scores.map(|s| s.0),
            "rmse": scores.map(|s| s.1),
        });
        let text = serde_json::to_string_pretty(&report).context("serialising the report")?;
        std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))?;
    }
    files.commit()?;
    println!(
        "Simulated {kind} on {} ({} samples)",
        args.data.display(),
        exp.len()
    );
    if let Some((fit, rmse)) = scores {
        println!("  fit {fit:.2} %   RMSE {rmse:.4e}");
    }
    if let Some(path) = &args.out_csv {
        println!("  simulated output: {}", path.display());
    }
    if let Some(path) = &args.json {
        println!("  report: {}", path.display());
    }
    Ok(())
}
