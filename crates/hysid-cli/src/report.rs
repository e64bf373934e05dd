//! The JSON report and the printed parameter table.

pub use hysid::report::Report;

/// The fit % and RMSE of a report for printing (NaN when it holds no fit).
pub fn figures(report: &Report) -> (f64, f64, f64) {
    report
        .fit
        .as_ref()
        .map_or((f64::NAN, f64::NAN, f64::NAN), |f| {
            (f.fit_percent, f.rmse, f.fpe.unwrap_or(f64::NAN))
        })
}

/// A criterion (FPE, AIC) for printing: its value (`scientific`: `1.2345e-4`, else
/// `-1234.5`), or "undefined" where it is not finite — a zero loss (an exact fit to exact
/// data) makes AIC −∞, and FPE is undefined with as many parameters as samples; the report
/// then holds null (docs/report.md §1.2).
pub fn criterion(value: f64, scientific: bool) -> String {
    match (value.is_finite(), scientific) {
        (false, _) => "undefined".into(),
        (true, true) => format!("{value:.4e}"),
        (true, false) => format!("{value:.1}"),
    }
}

/// One row of the printed parameter table.
pub struct Row {
    /// Parameter name.
    pub name: String,
    /// True value (examples only).
    pub truth: Option<f64>,
    /// Initial value (when one was given).
    pub initial: Option<f64>,
    /// Estimate.
    pub estimate: f64,
    /// Standard deviation.
    pub std: f64,
}

/// Prints the rows as an aligned table, MATLAB-`present` style.
pub fn print_table(rows: &[Row]) {
    let with_truth = rows.iter().any(|r| r.truth.is_some());
    let with_initial = rows.iter().any(|r| r.initial.is_some());
    let mut header = format!("  {:<10}", "parameter");
    if with_truth {
        header += &format!("{:>12}", "true");
    }
    if with_initial {
        header += &format!("{:>12}", "initial");
    }
    header += &format!("{:>14}   {:<12}", "estimate", "± std");
    say!("{header}");
    for r in rows {
        let mut line = format!("  {:<10}", r.name);
        if with_truth {
            line += &r
                .truth
                .map_or(format!("{:>12}", ""), |v| format!("{v:>12.6}"));
        }
        if with_initial {
            line += &r
                .initial
                .map_or(format!("{:>12}", "-"), |v| format!("{v:>12.6}"));
        }
        let std = if r.std.is_finite() {
            format!("{:.3e}", r.std)
        } else {
            "n/a".into()
        };
        line += &format!("{:>14.8} ± {std}", r.estimate);
        say!("{line}");
    }
}
