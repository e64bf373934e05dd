//! `hysid simulate`: run a saved model on new input data.

use crate::cli::SimulateArgs;
use crate::output::write_json;
use anyhow::{Context, Result};
use hysid::data::{read_columns, write_csv};
use hysid::fitted::FittedModel;
use hysid::metrics;
use serde_json::json;

/// Simulates the model on the input column; compares with the output column when given.
pub fn run(args: &SimulateArgs) -> Result<()> {
    let model = FittedModel::load(&args.model)?;
    let mut names = vec![args.input.as_str()];
    if let Some(out) = &args.output {
        names.push(out.as_str());
    }
    let (_, columns) = read_columns(&args.data, &names)?;
    let x = &columns[0];
    let measured = columns.get(1);
    let yhat = model
        .simulate(x, measured.and_then(|y| y.first().copied()))
        .with_context(|| format!("simulating on {}", args.data.display()))?;
    let kind = model.to_file().kind;
    println!(
        "Simulated {kind} on {} ({} samples)",
        args.data.display(),
        x.len()
    );
    let scores = measured.map(|y| (metrics::fit_percent(y, &yhat), metrics::rmse(y, &yhat)));
    if let Some((fit, rmse)) = scores {
        println!("  fit {fit:.2} %   RMSE {rmse:.4e}");
    }
    if let Some(path) = &args.out_csv {
        let mut headers = vec![args.input.as_str(), "simulated"];
        let mut cols: Vec<&[f64]> = vec![x, &yhat];
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
            "samples": x.len(),
            "fit_percent": scores.map(|s| s.0),
            "rmse": scores.map(|s| s.1),
        });
        write_json(path, &report)?;
        println!("  report: {}", path.display());
    }
    Ok(())
}
