//! The report of several hysteresis families compared on one record (`hysid compare`,
//! Python's `hysid.compare`): the same report from both front ends.

use super::{DataSummary, Report, ValidationEntry};
use crate::data::IdData;
use crate::identify::operators::Comparison;
use crate::Result;
use serde_json::json;

/// The report of `comparison` on `data` (read from `sources`; `validation_source` names
/// the validation samples): the best family's model and its validation entry, and
/// `details` with the split, the best family's name, whether the comparison was stopped,
/// and every family's row, ranked.
pub fn compare_report(
    data: &IdData,
    comparison: &Comparison,
    sources: Vec<String>,
    validation_source: &str,
) -> Result<Report> {
    let mut report = Report::new("compare");
    report.data = Some(DataSummary::of(data, sources));
    let best = comparison.best();
    if let Some(best) = best {
        if let Some(fitted) = &best.fitted {
            report.model = Some(fitted.fit.model.to_file());
        }
        report.validation.push(ValidationEntry::of(
            format!("{} ({validation_source})", best.family),
            &comparison.validation_output,
            &best.validation_simulated,
            None,
        )?);
    }
    report.details = json!({
        "split": comparison.split,
        "split_text": comparison.split.to_string(),
        "best": best.map(|b| b.family),
        // True when the comparison was stopped (a time limit) before every family was
        // fitted; the rows of those not fitted say so.
        "stopped": comparison.stopped,
        // The record's turning sense (given, detected on the training samples, or on all the
        // data compared when they cannot tell; null when none tell); each row holds its own
        // model's.
        "orientation": comparison.orientation.map(|o| o.0.short_name()),
        "orientation_source": comparison.orientation.map(|o| o.1.name()),
        "families": comparison.rows,
    });
    Ok(report)
}
