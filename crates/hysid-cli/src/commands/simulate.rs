//! `hysid simulate`: run a saved model on new input data.

use crate::cli::SimulateArgs;
use crate::output::{preflight, write_json};
use anyhow::{Context, Result};
use hysid::data::{write_csv, CsvSpec, IdData};
use hysid::model::saved::FittedModel;
use hysid::numerics::metrics;
use serde_json::json;

/// Simulates the model on the input columns; compares with the output column when given.
pub fn run(args: &SimulateArgs) -> Result<()> {
    let model = FittedModel::load(&args.model)?;
    preflight(&[args.out_csv.as_deref(), args.json.as_deref()], &[])?;
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
    println!(
        "Simulated {kind} on {} ({} samples)",
        args.data.display(),
        exp.len()
    );
    let scores = measured.map(|y| (metrics::fit_percent(y, yhat), metrics::rmse(y, yhat)));
    if let Some((fit, rmse)) = scores {
        println!("  fit {fit:.2} %   RMSE {rmse:.4e}");
    }
    if let Some(path) = &args.out_csv {
        let mut headers: Vec<&str> = args.input.iter().map(String::as_str).collect();
        headers.push("simulated");
        let mut cols: Vec<&[f64]> = inputs.clone();
        cols.push(yhat);
        if let (Some(name), Some(y)) = (&args.output, measured) {
            headers.push(name.as_str());
            cols.push(y);
        }
        write_csv(path, &headers, &cols)?;
        println!("  simulated output: {}", path.display());
    }
    if let Some(path) = &args.json {
        let report = json!({
            "model": model.to_file(),
            "samples": exp.len(),
            "fit_percent": scores.map(|s| s.0),
            "rmse": scores.map(|s| s.1),
        });
        write_json(path, &report)?;
        println!("  report: {}", path.display());
    }
    Ok(())
}
