//! The `present`-like report of a grey-box fit: parameters with standard deviations, units,
//! bounds and fixed flags; strong correlations; fit per experiment; loss, FPE, AIC; why the
//! search stopped; residual analysis; optional sensitivity table.

use crate::report::criterion;
use hysid::data::IdData;
use hysid::identify::greybox::GreyBoxFit;
use hysid::identify::validate::{ResidualAnalysis, SensitivityRow};
use hysid::report::greybox_residuals;

/// Prints the parameter table and the fit statistics.
pub fn print_fit(title: &str, fit: &GreyBoxFit) {
    let oe = &fit.fit;
    say!("{title}");
    say!(
        "  {:<14}{:>16}   {:<10} {:<10} {:>24}",
        "parameter",
        "value",
        "± std",
        "unit",
        "bounds"
    );
    let std = oe.std();
    for (i, p) in oe.parameters.iter().enumerate() {
        if p.fixed && p.name.starts_with("x0.") && p.value == 0.0 {
            continue;
        }
        let std = if p.fixed {
            "(fixed)".to_string()
        } else if std[i].is_finite() {
            format!("{:.3e}", std[i])
        } else {
            "n/a".into()
        };
        let bounds = if p.min.is_finite() || p.max.is_finite() {
            format!("[{:.3e}, {:.3e}]", p.min, p.max)
        } else {
            String::new()
        };
        say!(
            "  {:<14}{:>16.8e}   {:<10} {:<10} {:>24}",
            p.name,
            p.value,
            std,
            p.unit,
            bounds
        );
    }
    for (a, b, r) in strong_correlations(fit, 0.95) {
        say!("  note: {a} and {b} are correlated (r = {r:+.3})");
    }
    let fits: Vec<String> = oe
        .fit_percent
        .iter()
        .map(|f| format!("{:.2} %", f[0]))
        .collect();
    say!("  fit per experiment: {}", fits.join(", "));
    say!(
        "  loss {:.4e}   FPE {}   AIC {}   {} iterations, {} function evaluations, {} rejected trials",
        oe.loss, criterion(oe.fpe, true), criterion(oe.aic, false), oe.report.iterations, oe.report.function_evaluations, oe.report.rejected_trials
    );
    say!(
        "  stopped: {}   time {:.2} s",
        oe.report.termination,
        fit.elapsed_s
    );
    say!(
        "  simulations: {} without sensitivities, {} with",
        oe.report.residual_evaluations,
        oe.report.sensitivity_evaluations
    );
    if let Some(evaluation) = &fit.evaluation {
        say!("  evaluated by: {evaluation}");
    }
    if fit.starts.len() > 1 {
        let near = fit.starts_near_best(0.01);
        say!(
            "  multi-start: {} starts screened, {near} reached the best screened criterion",
            fit.starts.len()
        );
    }
}

/// Pairs of free parameters with |correlation| above `limit`.
pub fn strong_correlations(fit: &GreyBoxFit, limit: f64) -> Vec<(String, String, f64)> {
    let oe = &fit.fit;
    let free = &oe.report.free;
    let c = &oe.covariance.correlation;
    let mut out = Vec::new();
    for (a, &i) in free.iter().enumerate() {
        for &j in &free[a + 1..] {
            if c[(i, j)].abs() > limit {
                out.push((
                    oe.parameters.get(i).name.clone(),
                    oe.parameters.get(j).name.clone(),
                    c[(i, j)],
                ));
            }
        }
    }
    out
}

/// Residual analysis of every experiment's first output (the library's), printed in one
/// line each.
pub fn print_residuals(fit: &GreyBoxFit, data: &IdData) -> Vec<ResidualAnalysis> {
    let analyses = greybox_residuals(fit, data);
    for (e, a) in analyses.iter().enumerate() {
        say!(
            "  residuals, experiment {}: {} of {} auto-correlations and {} of {} input cross-correlations outside the 99 % band ±{:.3}",
            e + 1,
            a.auto_outside,
            a.max_lag,
            a.cross_outside.iter().sum::<usize>(),
            a.cross_correlation.iter().map(|c| c.len()).sum::<usize>(),
            a.band
        );
    }
    analyses
}

/// Prints the sensitivity table.
pub fn print_sensitivity(rows: &[SensitivityRow]) {
    say!("  change of fit % for ±20 % of each parameter (one at a time), per experiment:");
    for r in rows {
        let cells: Vec<String> =
            r.up.iter()
                .zip(&r.down)
                .map(|(u, d)| format!("{u:+8.3} / {d:+8.3}"))
                .collect();
        say!("    {:<12} {}", r.name, cells.join("   "));
    }
}
