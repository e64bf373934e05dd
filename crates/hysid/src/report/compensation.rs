//! The report of a feed-forward compensation (`hysid compensate`, Python's
//! `hysid.compensate`): the same report from both front ends.

use super::{DataSummary, Report};
use crate::data::IdData;
use crate::model::compensate::Compensation;
use crate::model::saved::FittedModel;
use serde_json::json;

/// The report of `compensation`, the input that makes `model` (read from `model_source`)
/// follow the reference column `reference_column` of `data` (read from `sources`): the
/// model, and `details` with the predicted tracking error (RMS, max) and the clipped
/// samples (count, indices, inclusive ranges).
pub fn compensation_report(
    model: &FittedModel,
    data: &IdData,
    compensation: &Compensation,
    sources: Vec<String>,
    reference_column: &str,
    model_source: &str,
) -> Report {
    let (rms, max) = compensation.tracking_error();
    let mut report = Report::new("compensate");
    report.data = Some(DataSummary::of(data, sources));
    report.model = Some(model.to_file());
    report.details = json!({
        "reference_column": reference_column,
        "model_source": model_source,
        "tracking_error": { "rms": rms, "max": max },
        "clipped": {
            "count": compensation.clipped.len(),
            "indices": compensation.clipped,
            "ranges": compensation.clipped_ranges(),
        },
    });
    report
}
