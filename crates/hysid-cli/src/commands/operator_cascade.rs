//! `hysid identify cascade --hysteresis FAMILY` for the operator families (any hysteresis
//! operator followed by a linear block); `ch4`/`ch6` keep the paper-1 pipeline of
//! `identify.rs`.

use super::identify::{load, register};
use crate::cli::{CascadeArgs, UncertaintyArg};
use crate::progress::FitProgress;
use crate::report::{figures, print_table, Row};
use anyhow::Result;
use hysid::identify::operator_cascade::{OperatorCascadeFit, OperatorCascadeIdentification};
use hysid::identify::operators::{Family, FamilyOptions, FamilySetting};
use hysid::report::plot::operator_cascade_figures;
use hysid::report::{operator_cascade_model, operator_cascade_report};
use serde_json::json;

/// The cascade's settings from the command line: the operator family (the registry's, not
/// ch4/ch6) and the options that apply to it.
fn identification(args: &CascadeArgs) -> Result<OperatorCascadeIdentification> {
    let name = &args.hysteresis;
    let family = Family::parse_operator(name).map_err(|_| {
        let operators: Vec<&str> = Family::operators().map(Family::name).collect();
        anyhow::anyhow!(
            "unknown --hysteresis '{name}'; use ch4, ch6 or an operator family: {}",
            operators.join(", ")
        )
    })?;
    for (given, flag, setting) in [
        (
            args.thresholds.is_some(),
            "--thresholds",
            FamilySetting::Thresholds,
        ),
        (args.grid.is_some(), "--grid", FamilySetting::Grid),
    ] {
        if given && !family.settings().contains(&setting) {
            let reading: Vec<&str> = Family::reading(setting)
                .into_iter()
                .map(Family::name)
                .collect();
            anyhow::bail!("{flag} applies to {}, not {name}", reading.join(", "));
        }
    }
    let mut id = OperatorCascadeIdentification::new(family, args.na, args.nb, args.delay);
    id.options = FamilyOptions {
        thresholds: args.thresholds.unwrap_or(10),
        // A cascade's Preisach (and KP) plane is smaller than `identify operator`'s: its cells share
        // the record with the linear block's coefficients.
        grid: args.grid.unwrap_or(10),
        loop_orientation: args.orientation.map(Into::into),
        choose_thresholds: false,
        choose_grid: false,
        ..FamilyOptions::default()
    };
    Ok(id)
}

/// `hysid identify cascade` with an operator family.
pub fn identify(args: &CascadeArgs) -> Result<()> {
    let id = identification(args)?;
    anyhow::ensure!(
        args.uncertainty == UncertaintyArg::Asymptotic,
        "--uncertainty bootstrap is available for ch4 and ch6; operator cascades report \
         asymptotic standard deviations (use --uncertainty asymptotic)"
    );
    let mut out = register(&args.data, &args.output)?;
    let data = load(&args.data, hysid::data::TimeSteps::Uniform)?;
    out.fitted_on(&data);
    let fit = {
        let progress = FitProgress::new("identifying cascade");
        let mut callback = progress.callback();
        id.estimate(&data, &mut callback)?
    };
    let (u, y) = (data.experiment(0).input(0), data.experiment(0).output(0));
    say!(
        "Cascade {} + linear block (na = {}, nb = {}, k = {}) from {} ({} samples)",
        id.family.name(),
        args.na,
        args.nb,
        args.delay,
        args.data.data.display(),
        u.len()
    );
    print_table(&rows(&fit));
    let model = operator_cascade_model(&fit);
    let extra = json!({"input": args.data.input, "output": args.data.output});
    let source = vec![args.data.data.display().to_string()];
    let report = operator_cascade_report(id.family.name(), &fit, &data, source, extra)?;
    let (fit_percent, rmse, fpe) = figures(&report);
    say!(
        "  start: {}; output-error fit: {} iterations, {}",
        fit.initialisation,
        fit.iterations,
        fit.termination
    );
    say!(
        "  fit {fit_percent:.4} %   RMSE {rmse:.4e}   FPE {}   time {:.2} s   std: asymptotic",
        crate::report::criterion(fpe, true),
        fit.elapsed_s
    );
    if !fit.model.linear.is_stable() {
        say!(
            "  warning: the identified linear block is unstable (spectral radius {:.4})",
            fit.model.linear.spectral_radius()
        );
    }
    out.figures(|| operator_cascade_figures(&fit, u, y))?;
    out.finish(Some(&report), Some(&model))
}

/// Table rows: estimate ± std with the global start as the initial value.
fn rows(fit: &OperatorCascadeFit) -> Vec<Row> {
    let start = fit.start.parameters().values();
    let std = fit.output_error.std();
    fit.output_error
        .parameters
        .iter()
        .enumerate()
        .map(|(i, p)| Row {
            name: p.name.clone(),
            truth: None,
            initial: Some(start[i]),
            estimate: p.value,
            std: std[i],
        })
        .collect()
}
