//! `hysid identify cascade --hysteresis FAMILY` for the operator families (any hysteresis
//! operator followed by a linear block); `ch4`/`ch6` keep the paper-1 pipeline of
//! `identify.rs`.

use super::identify::{load, register};
use crate::cli::{CascadeArgs, UncertaintyArg};
use crate::progress::FitProgress;
use crate::report::{figures, print_table, Row};
use anyhow::Result;
use hysid::identify::operator_cascade::{
    CascadeFamily, OperatorCascadeFit, OperatorCascadeIdentification,
};
use hysid::report::plot::operator_cascade_figures;
use hysid::report::{operator_cascade_model, operator_cascade_report};
use serde_json::json;

/// The family named on the command line with its structure options (the lead unifies this
/// parser with the `Family` enum of `identify operator` at merge).
fn family_operator(name: &str, args: &CascadeArgs) -> Result<CascadeFamily> {
    let thresholds = args.thresholds.unwrap_or(10);
    let family = match name.trim().to_ascii_lowercase().as_str() {
        "pi" => CascadeFamily::Pi { thresholds },
        "gpi" => CascadeFamily::Gpi { thresholds },
        "preisach" => CascadeFamily::Preisach {
            levels: args.levels.unwrap_or(10),
        },
        "jiles-atherton" => CascadeFamily::JilesAtherton,
        "bouc-wen" => CascadeFamily::BoucWen,
        "duhem" => CascadeFamily::Duhem,
        "dahl" => CascadeFamily::Dahl,
        "maxwell-slip" => CascadeFamily::MaxwellSlip {
            elements: thresholds,
        },
        "backlash" => CascadeFamily::Backlash { profile_points: 60 },
        other => anyhow::bail!(
            "unknown --hysteresis '{other}'; use ch4, ch6, pi, gpi, preisach, jiles-atherton, \
             bouc-wen, duhem, dahl, maxwell-slip or backlash"
        ),
    };
    let uses_thresholds = matches!(
        family,
        CascadeFamily::Pi { .. } | CascadeFamily::Gpi { .. } | CascadeFamily::MaxwellSlip { .. }
    );
    if args.thresholds.is_some() && !uses_thresholds {
        anyhow::bail!("--thresholds applies to pi, gpi and maxwell-slip, not {name}");
    }
    if args.levels.is_some() && !matches!(family, CascadeFamily::Preisach { .. }) {
        anyhow::bail!("--levels applies to preisach, not {name}");
    }
    Ok(family)
}

/// `hysid identify cascade` with an operator family.
pub fn identify(args: &CascadeArgs) -> Result<()> {
    let family = family_operator(&args.hysteresis, args)?;
    anyhow::ensure!(
        args.uncertainty == UncertaintyArg::Asymptotic,
        "--uncertainty bootstrap is available for ch4 and ch6; operator cascades report \
         asymptotic standard deviations (use --uncertainty asymptotic)"
    );
    let out = register(&args.data, &args.output)?;
    let data = load(&args.data)?;
    let id = OperatorCascadeIdentification::new(family, args.na, args.nb, args.delay);
    let fit = {
        let progress = FitProgress::new("identifying cascade");
        let mut callback = progress.callback();
        id.estimate(&data, &mut callback)?
    };
    let (u, y) = (data.experiment(0).input(0), data.experiment(0).output(0));
    println!(
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
    println!(
        "  start: {}; output-error fit: {} iterations, {}",
        fit.initialisation, fit.iterations, fit.termination
    );
    println!(
        "  fit {fit_percent:.4} %   RMSE {rmse:.4e}   FPE {}   time {:.2} s   std: asymptotic",
        crate::report::criterion(fpe, true),
        fit.elapsed_s
    );
    if !fit.model.linear.is_stable() {
        println!(
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
