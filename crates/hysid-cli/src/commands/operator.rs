//! `hysid identify operator`: one hysteresis family fitted to a measured input and output.

use super::zoo::{family_options, load, loops, signals};
use crate::cli_zoo::OperatorArgs;
use crate::exit::UsageError;
use crate::output::Outputs;
use crate::progress::FitProgress;
use crate::report::{print_table, Row};
use anyhow::{Context, Result};
use hysid::identify::operators::{
    fit_operator, EnvelopeChoice, Family, FamilySetting, FittedOperator,
};
use hysid::report::{operator_report, operator_simulation, Report};

/// Parameters printed before the table is cut short (a Preisach plane has hundreds).
const PRINTED_PARAMETERS: usize = 16;

/// Fits the family, prints the parameters and fit, writes the report, model and plots.
pub fn run(args: &OperatorArgs) -> Result<()> {
    let family = Family::parse(&args.family)?;
    let mut options = family_options(&args.options)?;
    let reading = |setting| {
        Family::reading(setting)
            .into_iter()
            .map(Family::name)
            .collect::<Vec<&str>>()
            .join(", ")
    };
    if options.loop_orientation.is_some()
        && !family.settings().contains(&FamilySetting::Orientation)
    {
        return Err(UsageError(format!(
            "--orientation applies to {}, not {family} (its orientation is a result of the fit)",
            reading(FamilySetting::Orientation)
        ))
        .into());
    }
    if options.envelope != EnvelopeChoice::Auto
        && !family.settings().contains(&FamilySetting::Envelope)
    {
        return Err(UsageError(format!(
            "--envelope applies to {}, not {family} (its static curve is part of its own fit)",
            reading(FamilySetting::Envelope)
        ))
        .into());
    }
    let o = &args.output;
    let mut out = Outputs::new(
        &[args.data.data.as_path()],
        o.json.as_deref(),
        o.model_out.as_deref(),
        o.plots.as_deref(),
    )?;
    let data = load(&args.data, &args.data.data)?;
    out.fitted_on(&data);
    let exp = data.experiment(0);
    let (u, y) = (exp.input(0), exp.output(0));
    crate::progress::note(&format!("fitting {family} to {} samples …", u.len()));
    let progress = FitProgress::new(&format!("fitting {family}"));
    options.observer = progress.observer();
    let fitted = fit_operator(family, u, y, &options)
        .with_context(|| format!("identifying a {family} operator"))?;
    drop(progress);
    let yhat = operator_simulation(&fitted, &data)?;
    let report = operator_report(
        &fitted,
        &data,
        &yhat,
        vec![args.data.data.display().to_string()],
    )?;
    print_summary(&fitted, &report);
    if let Some(dir) = out.plots.as_ref().map(|d| &d.tmp) {
        let title = format!("{family}: measured and simulated loop");
        let names = (exp_name(&data, true), exp_name(&data, false));
        loops(
            &dir.join("loops.svg"),
            &title,
            (&names.0, &names.1),
            (u, y),
            &[(family.name().to_string(), &yhat)],
        )?;
        signals(
            &dir.join("output.svg"),
            "Output: measured and simulated",
            &names.1,
            &[("measured", y), ("simulated", &yhat)],
        )?;
    }
    out.finish(Some(&report), Some(&fitted.fit.model))
}

fn exp_name(data: &hysid::data::IdData, input: bool) -> String {
    let channels = if input {
        data.input_channels()
    } else {
        data.output_channels()
    };
    channels[0].to_string()
}

fn print_summary(fitted: &FittedOperator, report: &Report) {
    let fit = &fitted.fit;
    say!(
        "{} operator: {} estimated parameters, {} ({} iterations)",
        fitted.family,
        fitted.estimated_parameters(),
        fit.termination,
        fit.iterations
    );
    let rows: Vec<Row> = fit
        .parameters
        .iter()
        .zip(&fit.std)
        .take(PRINTED_PARAMETERS)
        .map(|(p, s)| Row {
            name: p.name.clone(),
            truth: None,
            initial: None,
            estimate: p.value,
            std: s.unwrap_or(f64::NAN),
        })
        .collect();
    print_table(&rows);
    if fit.parameters.len() > PRINTED_PARAMETERS {
        say!(
            "  … {} more parameters in the report and the model file",
            fit.parameters.len() - PRINTED_PARAMETERS
        );
    }
    if let Some(f) = &report.fit {
        say!(
            "  fit {:.3} %   RMSE {:.4e}   time {:.3} s",
            f.fit_percent,
            f.rmse,
            fit.elapsed_s
        );
    }
    if !fit.termination.converged() {
        tell!(
            "warning: the {} fit did not converge ({}); treat its parameters with care",
            fitted.family,
            fit.termination
        );
    }
}
