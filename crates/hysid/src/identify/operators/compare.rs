//! Several hysteresis families fitted to one record and ranked by how well they predict data
//! they were not fitted to.
//!
//! **Split.** Without a validation record the first 60 % of the samples train every family
//! and the rest validate it. A rate-independent operator's output depends on its memory (the
//! past extrema of the input), so each fitted model is simulated over the *whole* record from
//! its own initial state and only the validation samples are scored: the memory built on the
//! training part is carried across the split, as it is in the system. With a separate
//! validation record the model is simulated on it from its initial state (Coleman–Hodgdon
//! models from the record's first measured output).
//!
//! **Figures per family.** Validation fit % = 100(1 − ‖y − ŷ‖/‖y − ȳ‖) and RMSE on the
//! validation samples; the number of estimated parameters p; AIC = N ln V + 2p + N(ln 2π + 1)
//! on the training samples (Akaike 1974, MATLAB's `aic`); the fit's wall-clock time. A family
//! whose fit or simulation fails carries its error in its row and the comparison goes on.

use super::family::{fit_operator, Family, FamilyOptions, FittedOperator, OrientationSource};
use crate::model::operators::LoopOrientation;
use crate::model::saved::FittedModel;
use crate::numerics::{metrics, Control};
use crate::{Error, Result};
use serde::Serialize;

/// Settings of a comparison.
#[derive(Clone, Debug, PartialEq)]
pub struct CompareOptions {
    /// The families to fit, in this order before ranking.
    pub families: Vec<Family>,
    /// The recipes' options.
    pub family: FamilyOptions,
    /// The training fraction of a single record (0.6), in (0, 1).
    pub train_fraction: f64,
}

impl Default for CompareOptions {
    fn default() -> Self {
        Self {
            families: Family::ALL.to_vec(),
            family: FamilyOptions::default(),
            train_fraction: 0.6,
        }
    }
}

/// How the data were split between training and validation.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Split {
    /// Samples `0..train` train, `train..samples` validate (the operator's memory carried over).
    Fraction {
        /// The training fraction asked for.
        fraction: f64,
        /// Training samples (the first ones).
        train: usize,
        /// All samples of the record.
        samples: usize,
    },
    /// A separate validation record.
    Record {
        /// Training samples.
        train: usize,
        /// Validation samples.
        validation: usize,
    },
}

impl std::fmt::Display for Split {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Split::Fraction {
                fraction,
                train,
                samples,
            } => write!(
                f,
                "trained on the first {:.0} % (samples 0..{train}), validated on the rest \
                 (samples {train}..{samples}, simulated from the start of the record)",
                100.0 * fraction
            ),
            Split::Record { train, validation } => write!(
                f,
                "trained on the estimation record ({train} samples), validated on the \
                 validation record ({validation} samples)"
            ),
        }
    }
}

/// One family's row of the comparison.
#[derive(Clone, Debug, Serialize)]
pub struct CompareRow {
    /// The family's name.
    pub family: &'static str,
    /// Validation fit % (None when the family failed).
    pub validation_fit_percent: Option<f64>,
    /// Validation RMSE.
    pub validation_rmse: Option<f64>,
    /// Fit % on the training samples.
    pub train_fit_percent: Option<f64>,
    /// Estimated parameters p.
    pub parameters: Option<usize>,
    /// AIC on the training samples (None when not finite, e.g. an exact fit).
    pub aic: Option<f64>,
    /// Wall-clock seconds of the fit.
    pub fit_time_s: Option<f64>,
    /// Whether the fit's search converged (a direct least-squares solve always does).
    pub converged: Option<bool>,
    /// Why the search stopped.
    pub termination: Option<String>,
    /// The turning sense of the fitted model's loop, `ccw` or `cw` (None when the family
    /// failed, and for ch4/ch6).
    pub orientation: Option<&'static str>,
    /// Where it came from: `given`, `detected`, `record` (the comparison's, detected on all
    /// its data), `fitted` or `assumed` ([`OrientationSource`]).
    pub orientation_source: Option<&'static str>,
    /// The initial state the fitted model starts from (`demagnetised`, `descending`,
    /// `ascending`, `estimated`; None when the family failed).
    pub initial_state: Option<&'static str>,
    /// The one-line error of a family that failed.
    pub error: Option<String>,
    /// The fitted model (None when the family failed).
    #[serde(skip)]
    pub fitted: Option<FittedOperator>,
    /// The model's output on the validation samples.
    #[serde(skip)]
    pub validation_simulated: Vec<f64>,
}

impl CompareRow {
    /// The row of a family that has no result, with the one-line `error` saying why.
    fn failed(family: Family, error: &Error) -> Self {
        Self {
            family: family.name(),
            validation_fit_percent: None,
            validation_rmse: None,
            train_fit_percent: None,
            parameters: None,
            aic: None,
            fit_time_s: None,
            converged: None,
            termination: None,
            orientation: None,
            orientation_source: None,
            initial_state: None,
            error: Some(error.to_string()),
            fitted: None,
            validation_simulated: Vec::new(),
        }
    }
}

/// The ranked comparison.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// The split used.
    pub split: Split,
    /// One row per family, best validation fit % first, failed families last.
    pub rows: Vec<CompareRow>,
    /// Input of the scored validation samples (those of each row's `validation_simulated`).
    #[serde(skip)]
    pub validation_input: Vec<f64>,
    /// Measured output of the scored validation samples.
    #[serde(skip)]
    pub validation_output: Vec<f64>,
    /// True when the observer stopped the comparison (a time limit): the families after
    /// the stop have rows saying they were not fitted.
    pub stopped: bool,
    /// The record's loop orientation: the given one, else the one detected on the training
    /// samples, else on all the data compared (None when they cannot tell; each row then
    /// says what its family did).
    #[serde(skip)]
    pub orientation: Option<(LoopOrientation, OrientationSource)>,
}

impl Comparison {
    /// The best row (highest validation fit %), if any family succeeded.
    pub fn best(&self) -> Option<&CompareRow> {
        self.rows.first().filter(|r| r.fitted.is_some())
    }
    /// The row of `family`, if it was compared.
    pub fn row(&self, family: Family) -> Option<&CompareRow> {
        self.rows.iter().find(|r| r.family == family.name())
    }
}

/// Fits every family of `options` to (u, y) and ranks them by validation fit % on
/// `validation` = (u, y) of a separate record, or on the last part of (u, y) when None.
pub fn compare(
    u: &[f64],
    y: &[f64],
    validation: Option<(&[f64], &[f64])>,
    options: &CompareOptions,
) -> Result<Comparison> {
    options.family.validate()?;
    if u.len() != y.len() {
        return Err(Error::InvalidData(format!(
            "the input has {} samples and the output {}; give equally long signals",
            u.len(),
            y.len()
        )));
    }
    let outputs = std::iter::once(("the output", y))
        .chain(validation.map(|v| ("the validation output", v.1)));
    for (what, out) in outputs {
        if !crate::data::varies(out) {
            return Err(Error::InvalidData(format!(
                "{what} does not vary at double precision: there is nothing to fit and fit % is undefined; check the output column"
            )));
        }
    }
    if options.families.is_empty() {
        return Err(Error::invalid_option(
            "families",
            "[]",
            "no family to compare; name at least one".into(),
        ));
    }
    let (split, train, valid) = split(u, y, validation, options.train_fraction)?;
    let orientation = record_orientation(train, (u, y), validation, &options.family);
    // What a family whose training part cannot tell the orientation is given.
    let fallback = match orientation {
        Some((l, OrientationSource::Record)) => Some(l),
        _ => None,
    };
    // The observer sees "family k/N" and may stop the comparison (a time limit): the
    // families not fitted by then are listed as such, once at least one has a result.
    let observer = &options.family.observer;
    let total = options.families.len();
    let mut rows: Vec<CompareRow> = Vec::with_capacity(total);
    let mut stopped = false;
    for (k, &family) in options.families.iter().enumerate() {
        stopped |= observer.report("family", k, total) == Control::Stop;
        if stopped && rows.iter().any(|r| r.fitted.is_some()) {
            rows.push(CompareRow::failed(
                family,
                &Error::Cancelled(
                    "the comparison was stopped (time limit) before this family was fitted".into(),
                ),
            ));
        } else {
            rows.push(row(family, train, valid, &split, &options.family, fallback));
        }
    }
    observer.report("family", total, total);
    let validation_input = scored(&split, valid.0).to_vec();
    let validation_output = scored(&split, valid.1).to_vec();
    Ok(Comparison {
        split,
        rows: ranked(rows),
        validation_input,
        validation_output,
        stopped,
        orientation,
    })
}

type Signals<'a> = (&'a [f64], &'a [f64]);

/// The loop orientation of a comparison: the given one; else the one detected on the
/// training samples; else, when they cannot tell (a single loop measured from its tip, whose
/// training part holds one short return), the one detected on all the data compared — the
/// record, and the separate validation record when there is one — a single structural
/// choice, reported as [`OrientationSource::Record`]. None when no data tell it.
fn record_orientation(
    train: Signals<'_>,
    record: Signals<'_>,
    validation: Option<Signals<'_>>,
    options: &FamilyOptions,
) -> Option<(LoopOrientation, OrientationSource)> {
    if let Some(l) = options.loop_orientation {
        return Some((l, OrientationSource::Given));
    }
    if let Ok(l) = LoopOrientation::detect(train.0, train.1) {
        return Some((l, OrientationSource::Detected));
    }
    let detected = match validation {
        Some(v) => {
            let u: Vec<f64> = record.0.iter().chain(v.0).copied().collect();
            let y: Vec<f64> = record.1.iter().chain(v.1).copied().collect();
            LoopOrientation::detect(&u, &y)
        }
        None => LoopOrientation::detect(record.0, record.1),
    };
    detected.ok().map(|l| (l, OrientationSource::Record))
}

fn split<'a>(
    u: &'a [f64],
    y: &'a [f64],
    validation: Option<Signals<'a>>,
    fraction: f64,
) -> Result<(Split, Signals<'a>, Signals<'a>)> {
    if let Some((uv, yv)) = validation {
        if uv.len() != yv.len() || uv.len() < 2 {
            return Err(Error::InvalidData(format!(
                "the validation record has {} input and {} output samples; give at least 2 of each, equally many",
                uv.len(),
                yv.len()
            )));
        }
        let split = Split::Record {
            train: u.len(),
            validation: uv.len(),
        };
        return Ok((split, (u, y), (uv, yv)));
    }
    if !(fraction > 0.0 && fraction < 1.0) {
        return Err(Error::invalid_option(
            "training_fraction",
            fraction,
            format!("the training fraction {fraction} must lie strictly between 0 and 1"),
        ));
    }
    let train = (fraction * u.len() as f64).round() as usize;
    if train < 2 || u.len() - train < 2 {
        return Err(Error::TooFewSamples {
            samples: u.len(),
            parameters: 1,
            needed: 5,
        });
    }
    let split = Split::Fraction {
        fraction,
        train,
        samples: u.len(),
    };
    Ok((split, (&u[..train], &y[..train]), (u, y)))
}

fn row(
    family: Family,
    train: Signals<'_>,
    valid: Signals<'_>,
    split: &Split,
    options: &FamilyOptions,
    fallback: Option<LoopOrientation>,
) -> CompareRow {
    let failed = |e: Error| CompareRow::failed(family, &e);
    let fitted = match (fit_operator(family, train.0, train.1, options), fallback) {
        (Ok(f), _) => f,
        // The training part cannot tell the orientation: the one the record tells, so said.
        (Err(Error::UndeterminedOrientation { .. }), Some(l)) => {
            let given = FamilyOptions {
                loop_orientation: Some(l),
                ..options.clone()
            };
            match fit_operator(family, train.0, train.1, &given) {
                Ok(mut f) => {
                    if let Some(used) = f.orientation.as_mut() {
                        used.source = OrientationSource::Record;
                    }
                    f
                }
                Err(e) => return failed(e),
            }
        }
        (Err(e), _) => return failed(e),
    };
    let simulated = match validation_output(&fitted.fit.model, split, valid) {
        Ok(s) => s,
        Err(e) => return failed(e),
    };
    let measured = scored(split, valid.1);
    let fit = &fitted.fit;
    CompareRow {
        family: family.name(),
        validation_fit_percent: Some(metrics::fit_percent(measured, &simulated)),
        validation_rmse: Some(metrics::rmse(measured, &simulated)),
        train_fit_percent: Some(fit.fit_percent),
        parameters: Some(fitted.estimated_parameters()),
        aic: fit.aic.is_finite().then_some(fit.aic),
        fit_time_s: Some(fit.elapsed_s),
        converged: Some(fit.termination.converged()),
        termination: Some(fit.termination.to_string()),
        orientation: fitted.orientation.map(|o| o.orientation.short_name()),
        orientation_source: fitted.orientation.map(|o| o.source.name()),
        initial_state: Some(fit.initial_state.map_or("demagnetised", |s| s.name())),
        error: None,
        fitted: Some(fitted),
        validation_simulated: simulated,
    }
}

/// The model's output on the validation samples (see the module doc for the state).
fn validation_output(model: &FittedModel, split: &Split, valid: Signals<'_>) -> Result<Vec<f64>> {
    let y0 = valid.1.first().copied();
    let mut out = model.simulate(&[valid.0], 1.0, y0)?.swap_remove(0);
    if let Split::Fraction { train, .. } = split {
        out.drain(..*train);
    }
    Ok(out)
}

fn scored<'a>(split: &Split, y: &'a [f64]) -> &'a [f64] {
    match split {
        Split::Fraction { train, .. } => &y[*train..],
        Split::Record { .. } => y,
    }
}

fn ranked(mut rows: Vec<CompareRow>) -> Vec<CompareRow> {
    let key = |r: &CompareRow| r.validation_fit_percent.unwrap_or(f64::NEG_INFINITY);
    rows.sort_by(|a, b| key(b).total_cmp(&key(a)));
    rows
}
