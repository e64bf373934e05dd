//! `hysid simulate`: run a saved model on new input data.

use crate::cli::SimulateArgs;
use crate::output::{preflight, write_report};
use anyhow::{Context, Result};
use hysid::data::{write_csv, CsvSpec, IdData};
use hysid::model::saved::FittedModel;
use hysid::report::{DataSummary, FitSummary, Report};

/// Simulates the model on the input columns; compares with the output column when given.
pub fn run(args: &SimulateArgs) -> Result<()> {
    let model = FittedModel::load(&args.model)?;
    preflight(&[args.csv.as_deref(), args.json.as_deref()], &[])?;
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
    let file = model.to_file();
    println!(
        "Simulated {} on {} ({} samples)",
        file.kind,
        args.data.display(),
        exp.len()
    );
    let mut report = Report::new("simulate");
    report.data = Some(DataSummary::of(
        &data,
        vec![args.data.display().to_string()],
    ));
    if let Some(y) = measured {
        let fit = FitSummary::of(&[exp.name.clone()], &[y], &[yhat])?;
        println!("  fit {:.2} %   RMSE {:.4e}", fit.fit_percent, fit.rmse);
        report.fit = Some(fit);
    } else if yhat.iter().any(|v| !v.is_finite()) {
        anyhow::bail!("the simulated output is not finite: the model is unstable on this input");
    }
    report.model = Some(file);
    if let Some(path) = &args.csv {
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
        write_report(path, &report)?;
        println!("  report: {}", path.display());
    }
    Ok(())
}
