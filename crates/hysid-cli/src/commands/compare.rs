//! `hysid compare`: several hysteresis families fitted to one record, ranked by validation
//! fit %.

use super::zoo::{family_options, load, loops};
use crate::cli_zoo::CompareArgs;
use crate::output::Outputs;
use crate::progress::FitProgress;
use anyhow::Result;
use hysid::identify::operators::{
    compare, CompareOptions, CompareRow, Comparison, Family, FamilyOptions,
};
use hysid::report::{compare_report, Report};
use std::path::Path;

/// Fits the families, prints the ranked table, writes the report, best model and plot.
pub fn run(args: &CompareArgs) -> Result<()> {
    let families = Family::parse_list(&args.families)?;
    let progress = FitProgress::new("comparing families");
    let options = CompareOptions {
        families,
        family: FamilyOptions {
            observer: progress.observer(),
            ..family_options(&args.options)?
        },
        ..CompareOptions::default()
    };
    let mut inputs = vec![args.data.data.as_path()];
    inputs.extend(args.validate.as_deref());
    let o = &args.output;
    let mut out = Outputs::new(
        &inputs,
        o.json.as_deref(),
        o.model_out.as_deref(),
        o.plots.as_deref(),
    )?;
    let data = load(&args.data, &args.data.data)?;
    out.fitted_on(&data);
    let validation = args
        .validate
        .as_deref()
        .map(|p| load(&args.data, p))
        .transpose()?;
    let exp = data.experiment(0);
    let held_out = validation
        .as_ref()
        .map(|v| (v.experiment(0).input(0), v.experiment(0).output(0)));
    crate::progress::note(&format!(
        "comparing {} families on {} samples …",
        options.families.len(),
        exp.len()
    ));
    let comparison = compare(exp.input(0), exp.output(0), held_out, &options)?;
    drop(progress);
    say!("Split: {}", comparison.split);
    print_table(&comparison.rows);
    for row in comparison.rows.iter().filter(|r| r.error.is_some()) {
        tell!(
            "warning: {} failed: {}",
            row.family,
            row.error.as_deref().unwrap_or("")
        );
    }
    let best = comparison.best();
    match best {
        Some(b) => say!(
            "Best: {} (validation fit {:.3} %)",
            b.family,
            b.validation_fit_percent.unwrap_or(f64::NAN)
        ),
        None => tell!("warning: no family could be fitted to these data"),
    }
    let report = report(args, &data, &comparison)?;
    if let Some(dir) = &out.plots {
        plot_loops(&dir.tmp, &data, &comparison)?;
    }
    let model = best.and_then(|b| b.fitted.as_ref()).map(|f| &f.fit.model);
    if out.model_out.is_some() && model.is_none() {
        anyhow::bail!("--model-out: no family could be fitted, so there is no model to write");
    }
    out.finish(Some(&report), model)
}

fn print_table(rows: &[CompareRow]) {
    say!(
        "  {:<16}{:>16}{:>14}{:>9}{:>14}{:>12}",
        "family",
        "validation fit %",
        "RMSE",
        "#params",
        "AIC",
        "fit time s"
    );
    let num = |v: Option<f64>, w: usize, p: usize| {
        v.map_or(format!("{:>w$}", "-"), |x| format!("{x:>w$.p$}"))
    };
    for r in rows {
        if let Some(e) = &r.error {
            say!("  {:<16}  failed: {}", r.family, first_words(e));
            continue;
        }
        say!(
            "  {:<16}{}{}{}{}{}",
            r.family,
            num(r.validation_fit_percent, 16, 3),
            r.validation_rmse
                .map_or(format!("{:>14}", "-"), |x| format!("{x:>14.4e}")),
            r.parameters
                .map_or(format!("{:>9}", "-"), |p| format!("{p:>9}")),
            num(r.aic, 14, 1),
            num(r.fit_time_s, 12, 4),
        );
    }
}

/// The error cut to one short line for the table (the report keeps it whole).
fn first_words(e: &str) -> String {
    let limit = 90;
    if e.chars().count() <= limit {
        e.to_string()
    } else {
        format!("{}…", e.chars().take(limit).collect::<String>())
    }
}

fn report(args: &CompareArgs, data: &hysid::data::IdData, c: &Comparison) -> Result<Report> {
    let mut sources = vec![args.data.data.display().to_string()];
    sources.extend(args.validate.iter().map(|p| p.display().to_string()));
    Ok(compare_report(data, c, sources, &validation_source(args))?)
}

fn validation_source(args: &CompareArgs) -> String {
    args.validate.as_ref().map_or_else(
        || format!("{}, validation samples", args.data.data.display()),
        |p| p.display().to_string(),
    )
}

fn plot_loops(dir: &Path, data: &hysid::data::IdData, c: &Comparison) -> Result<()> {
    let (u, y) = (&c.validation_input, &c.validation_output);
    let models: Vec<(String, &[f64])> = c
        .rows
        .iter()
        .filter(|r| r.fitted.is_some())
        .map(|r| {
            (
                format!(
                    "{} ({:.2} %)",
                    r.family,
                    r.validation_fit_percent.unwrap_or(f64::NAN)
                ),
                r.validation_simulated.as_slice(),
            )
        })
        .collect();
    let x_label = data.input_channels()[0].to_string();
    let y_label = data.output_channels()[0].to_string();
    loops(
        &dir.join("compare_loops.svg"),
        "Validation loops: measured and every family",
        (&x_label, &y_label),
        (u, y),
        &models,
    )
}
