//! `hysid simulate`: run a saved model (or the model of a report) on new input data.

use crate::cli::SimulateArgs;
use crate::output::Outputs;
use anyhow::{Context, Result};
use hysid::data::{write_csv, CsvSpec, IdData};
use hysid::model::saved::FittedModel;
use hysid::report::{DataSummary, FitSummary, Report};

/// Simulates the model on the input columns; compares with the output column when given.
/// The outputs are one transaction: written to temporaries, renamed into place together at
/// the end, and never an input file.
pub fn run(args: &SimulateArgs) -> Result<()> {
    let mut out = Outputs::new(
        &[args.model.as_path(), args.data.as_path()],
        args.json.as_deref(),
        None,
        None,
    )?;
    let csv = out.file(args.csv.as_deref())?;
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
    // Errors (never returns) when the simulated output is not finite.
    let outputs = model
        .simulate(
            &inputs,
            data.ts(),
            measured.and_then(|y| y.first().copied()),
        )
        .with_context(|| format!("simulating on {}", args.data.display()))?;
    let yhat = &outputs[0];
    let file = model.to_file();
    let kind = file.kind.clone();
    let mut report = Report::new("simulate");
    report.data = Some(DataSummary::of(
        &data,
        vec![args.data.display().to_string()],
    ));
    if let Some(y) = measured {
        report.fit = Some(FitSummary::of(
            std::slice::from_ref(&exp.name),
            &[y],
            &[yhat],
        )?);
    }
    report.model = Some(file);
    if let Some(csv) = &csv {
        let mut headers: Vec<&str> = args.input.iter().map(String::as_str).collect();
        headers.push("simulated");
        let mut cols: Vec<&[f64]> = inputs.clone();
        cols.push(yhat);
        if let (Some(name), Some(y)) = (&args.output, measured) {
            headers.push(name.as_str());
            cols.push(y);
        }
        write_csv(&csv.tmp, &headers, &cols)?;
    }
    println!(
        "Simulated {kind} on {} ({} samples)",
        args.data.display(),
        exp.len()
    );
    if let Some(fit) = &report.fit {
        println!("  fit {:.2} %   RMSE {:.4e}", fit.fit_percent, fit.rmse);
    }
    if let Some(path) = &args.csv {
        println!("  simulated output: {}", path.display());
    }
    out.finish(Some(&report), None)
}
