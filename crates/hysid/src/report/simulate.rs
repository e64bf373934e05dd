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
use crate::{Error, Result};

/// `model` run on every record of `records` (`(source, data)`, the first experiment of
/// each, all its input channels; output channel 0, when there is one, is the measured
/// output): the report (with `fit` when every record has a measured output) and each
/// record's [`Prediction`].
pub fn simulate_report(
    model: &FittedModel,
    records: &[(String, &IdData)],
) -> Result<(Report, Vec<Prediction>)> {
    simulate_report_after(model, records, None, 0)
}

/// [`simulate_report`] from the state a history leaves (`hysid simulate --history FILE
/// --warm-up N`): each record is simulated after the inputs of `history` (its first
/// experiment, the same input channels; a model with a declared initial state applies it at
/// the history's first input), and its first `warm_up` samples set the state without being
/// scored or returned. Only for models that simulate sample by sample (not a pre-filtered
/// or inverse-dynamics model).
pub fn simulate_report_after(
    model: &FittedModel,
    records: &[(String, &IdData)],
    history: Option<&IdData>,
    warm_up: usize,
) -> Result<(Report, Vec<Prediction>)> {
    if (history.is_some() || warm_up > 0)
        && matches!(
            model,
            FittedModel::Prefiltered { .. } | FittedModel::InverseDynamics { .. }
        )
    {
        return Err(Error::Unsupported(
            "a history or warm-up needs a model that simulates sample by sample, not a \
             pre-filtered or inverse-dynamics one; leave --history and --warm-up out"
                .into(),
        ));
    }
    let mut predictions = Vec::with_capacity(records.len());
    for (source, data) in records {
        let exp = data.experiment(0);
        let channels = data.input_channels().len();
        if warm_up >= exp.len() {
            return Err(Error::InvalidData(format!(
                "{source}: the warm-up of {warm_up} samples leaves none of its {} to score; \
                 give a smaller --warm-up",
                exp.len()
            )));
        }
        let mut inputs: Vec<Vec<f64>> = vec![Vec::new(); channels];
        let mut measured: Option<Vec<f64>> = (!data.output_channels().is_empty()).then(Vec::new);
        if let Some(h) = history {
            if h.input_channels().len() != channels {
                return Err(Error::InvalidData(format!(
                    "the history has {} input channels, {source} {channels}; give the same \
                     --input columns in both",
                    h.input_channels().len()
                )));
            }
            let he = h.experiment(0);
            for (c, x) in inputs.iter_mut().enumerate() {
                x.extend_from_slice(he.input(c));
            }
            if let Some(m) = measured.as_mut() {
                // Not scored: the history's output only keeps the samples aligned.
                let first = exp.output(0).first().copied().unwrap_or(0.0);
                m.extend(std::iter::repeat_n(first, he.len()));
            }
        }
        let skip = inputs.first().map_or(0, Vec::len) + warm_up;
        for (c, x) in inputs.iter_mut().enumerate() {
            x.extend_from_slice(exp.input(c));
        }
        if let Some(m) = measured.as_mut() {
            m.extend_from_slice(exp.output(0));
        }
        let slices: Vec<&[f64]> = inputs.iter().map(Vec::as_slice).collect();
        let mut p = model.predict(&slices, measured.as_deref(), data.ts())?;
        if skip > 0 {
            for v in p.inputs.iter_mut().chain(p.outputs.iter_mut()) {
                v.drain(..skip.min(v.len()));
            }
            if let Some(m) = p.measured.as_mut() {
                m.drain(..skip.min(m.len()));
            }
        }
        predictions.push(p);
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
