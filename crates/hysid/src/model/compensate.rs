//! Feed-forward compensation: the input u that makes a fitted model's output follow a
//! reference r, so that the model's inverse placed before the system cancels its hysteresis.
//!
//! * **Operators** (kind `operator`): each family's own inverse
//!   ([`crate::model::operators::HysteresisOperator::invert`]): the analytic inverse of
//!   Krejčí & Kuhnen (2001) for PI and Maxwell-slip, Kuhnen's (2003) for the generalised PI, a
//!   monotone per-sample solve for Preisach and the differential families.
//! * **Coleman–Hodgdon hysteresis alone** (kind `coleman_hodgdon`, ch4/ch6): the recursion
//!   y(t) = y(t−1) + α|Δx|(f(x) − y(t−1)) + g(x)Δx (Coleman & Hodgdon 1986) is solved for x(t)
//!   sample by sample, y(t) = r(t), by bracketing on |Δx| ≤ 1/α (the recursion's own rate
//!   limit, beyond which it is not a blend of y(t−1) and f(x)). The output starts at the
//!   reference's first sample (a model starting from the measured output) or at 0, and the
//!   first input at the value where the anhysteretic f(x) equals it.
//! * **Operator cascades** (kind `operator_cascade`): the linear block inverted (stable only for
//!   a minimum-phase B, refused otherwise), then the operator
//!   ([`crate::model::OperatorCascade::compensate`]); the output follows from the delay k on.
//! * Other kinds (the Coleman–Hodgdon cascade, grey-box models) give
//!   [`Error::NotInvertible`].
//!
//! A reference sample the model cannot reach (beyond a saturation level, or faster than the
//! rate limit allows) is clipped to the nearest reachable output and listed in
//! [`Compensation::clipped`], never silently; so is a command beyond the actuator's limits
//! ([`compensate_within`], the one rule of [`crate::model::limits`]).

use crate::model::limits::Limits;
use crate::model::saved::FittedModel;
use crate::numerics::metrics;
use crate::{Error, Result};
use serde::Serialize;

/// The compensating input and what the model predicts for it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Compensation {
    /// The reference r.
    pub reference: Vec<f64>,
    /// The input u that makes the model follow r.
    pub u: Vec<f64>,
    /// The model's output for u (equal to r where r is reachable).
    pub predicted: Vec<f64>,
    /// Samples where r lay outside the reachable range and was clipped.
    pub clipped: Vec<usize>,
    /// The first sample the model can follow: 0 for a hysteresis alone, the linear block's
    /// delay k for a cascade (its first k outputs do not depend on u).
    pub settled_from: usize,
}

impl Compensation {
    /// The predicted tracking error e = predicted − r: (RMS, max |e|) over the samples from
    /// [`settled_from`](Self::settled_from) on.
    pub fn tracking_error(&self) -> (f64, f64) {
        let from = self.settled_from.min(self.reference.len());
        let (r, p) = (&self.reference[from..], &self.predicted[from..]);
        if r.is_empty() {
            return (0.0, 0.0);
        }
        let rms = metrics::rmse(r, p);
        let max = r
            .iter()
            .zip(p)
            .fold(0.0f64, |m, (r, p)| m.max((p - r).abs()));
        (rms, max)
    }

    /// The clipped samples as inclusive index ranges (first, last).
    pub fn clipped_ranges(&self) -> Vec<(usize, usize)> {
        let mut ranges: Vec<(usize, usize)> = Vec::new();
        for &k in &self.clipped {
            match ranges.last_mut() {
                Some((_, last)) if *last + 1 == k => *last = k,
                _ => ranges.push((k, k)),
            }
        }
        ranges
    }
}

/// Refuses an empty reference or one with a non-finite sample (the checks of [`compensate`]).
pub(crate) fn check_reference(reference: &[f64]) -> Result<()> {
    if reference.is_empty() {
        return Err(Error::InvalidData("the reference is empty".into()));
    }
    if let Some(k) = reference.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            channel: "reference".into(),
            index: k,
            value: reference[k],
        });
    }
    Ok(())
}

/// The error for a model kind [`compensate`] does not invert.
pub(crate) fn not_invertible(model: &FittedModel) -> Error {
    crate::model::kinds::not_invertible(model.to_file().kind())
}

/// [`compensate`] with the command limited to `limits` ([`crate::model::limits`]): each
/// command beyond them is set to the nearer limit and its sample counted as clipped (the
/// predicted output stays the model's output for the unlimited command); None: unlimited.
/// Equal to the stream ([`compensate_stream`](crate::model::stream::compensate_stream) of a compensator with the same limits).
pub fn compensate_within(
    model: &FittedModel,
    reference: &[f64],
    limits: Option<Limits>,
) -> Result<Compensation> {
    let mut c = compensate(model, reference)?;
    if let Some(limits) = limits {
        let mut clipped = std::mem::take(&mut c.clipped).into_iter().peekable();
        for (k, u) in c.u.iter_mut().enumerate() {
            let (v, limited) = limits.apply(*u);
            *u = v;
            let by_model = clipped.next_if_eq(&k).is_some();
            if limited || by_model {
                c.clipped.push(k);
            }
        }
    }
    Ok(c)
}

/// The input that makes `model` follow `reference` (see the module doc), unlimited.
pub fn compensate(model: &FittedModel, reference: &[f64]) -> Result<Compensation> {
    check_reference(reference)?;
    match model.as_kind() {
        Some(kind) => kind.compensate(reference),
        None => Err(not_invertible(model)),
    }
}
