//! The report of `hysid simulate`: a saved model run on one or more records.
//!
//! Every record is processed as the model's fit processed it ([`FittedModel::predict`]:
//! filtered for a pre-filtered model, decimated for an inverse-dynamics one), so that the
//! report's `fit` over all records, and `fit.per_experiment` per record, are the figures
//! of the report that saved the model. fit % is MATLAB's `compare` figure
//! 100 (1 − ‖y − ŷ‖ / ‖y − ȳ‖) over the records stacked.

use super::{DataSummary, FitSummary, Report};
use crate::data::IdData;
use crate::model::saved::{FittedModel, Prediction};
use crate::Result;

/// `model` run on every record of `records` (`(source, data)`, the first experiment of
/// each, all its input channels; output channel 0, when there is one, is the measured
/// output): the report (with `fit` when every record has a measured output) and each
/// record's [`Prediction`].
pub fn simulate_report(
    model: &FittedModel,
    records: &[(String, &IdData)],
) -> Result<(Report, Vec<Prediction>)> {
    let mut predictions = Vec::with_capacity(records.len());
    for (_, data) in records {
        let exp = data.experiment(0);
        let inputs: Vec<&[f64]> = (0..data.input_channels().len())
            .map(|c| exp.input(c))
            .collect();
        let measured = (!data.output_channels().is_empty()).then(|| exp.output(0));
        predictions.push(model.predict(&inputs, measured, data.ts())?);
    }
    let measured: Option<Vec<&[f64]>> = predictions.iter().map(|p| p.measured.as_deref()).collect();
    let fit = match measured {
        Some(y) => {
            let names: Vec<String> = records.iter().map(|(s, _)| s.clone()).collect();
            let yhat: Vec<&[f64]> = predictions
                .iter()
                .map(|p| p.outputs[0].as_slice())
                .collect();
            Some(FitSummary::of(&names, &y, &yhat)?)
        }
        None => None,
    };
    let report = Report {
        data: Some(DataSummary {
            source: records.iter().map(|(s, _)| s.clone()).collect(),
            samples: records.iter().map(|(_, d)| d.experiment(0).len()).sum(),
            experiments: records.len(),
            ts: records.first().map(|(_, d)| d.ts()),
        }),
        model: Some(model.to_file()),
        fit,
        ..Report::new("simulate")
    };
    Ok((report, predictions))
}
