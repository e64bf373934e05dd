//! The model size of the linear-in-weights families chosen from the data: threshold counts
//! and placements (PI, generalised PI, Maxwell-slip) and the Preisach / KP grid.
//!
//! **Rule.** Each candidate size is fitted on the first 70 % of the record
//! ([`TRAINING_FRACTION`]), the fitted model simulates the whole record from its start, and
//! the candidate is scored by fit % = 100 (1 − ‖y − ŷ‖/‖y − ȳ‖) on the last 30 % (the
//! held-out part, as [`crate::identify::operators::pi::PiOptions::select`] does); the best
//! score wins (a tie goes to the smaller model), and the winner is refitted on the whole
//! record. A candidate is tried only if the training part has max(2p, p + 10) samples for its
//! p parameters (the data check of every linear-in-weights recipe), so a short record gets a
//! small model instead of a refusal; when no candidate fits in the training part, the
//! smallest one the whole record can hold is fitted on all of it.
//!
//! **Initial state.** The candidates are fitted and simulated from the requested initial
//! state (the demagnetised one under `estimate`); the winner's state is then settled on the
//! whole record (`linear_support::settle_state`: `estimate` refits
//! its structure from the descending and the ascending histories and keeps the least loss).
//!
//! **Work bound.** A fit's cost is dominated by the Gram matrix, N·p² for N samples and p
//! parameters. The candidates are tried smallest first while the training fits' total
//! Σ N_train·p² stays within `bound` times the cost N·p₀² of one fit of today's fixed default
//! size p₀ (the families give the bound: a few fits for the Preisach and KP planes, more for
//! the cheap play sums); larger candidates are reported as not tried.
//!
//! Reference: T. Hastie, R. Tibshirani, J. Friedman, *The Elements of Statistical Learning*,
//! 2nd ed., Springer 2009, §7.2 (model selection by a validation set).

use super::linear_support::{first_state, settle_state};
use super::OperatorFit;
use crate::model::operators::{initial_state, HysteresisOperator, InitialState, InitialStateUsed};
use crate::numerics::metrics;
use crate::Result;
use serde::Serialize;

/// The fraction of the record a candidate is fitted on; the rest scores it.
pub const TRAINING_FRACTION: (usize, usize) = (7, 10);

/// One candidate's score (the reports' `details.model_size.candidates`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SizeScore {
    /// The candidate, e.g. `"grid 20"` or `"10 geometric"`.
    pub size: String,
    /// Its number of parameters p.
    pub parameters: usize,
    /// Its fit % on the held-out part; None when it was not tried (too few training samples
    /// for p, beyond the work bound) or its fit failed.
    pub validation_fit_percent: Option<f64>,
    /// Why it has no score (`"too few samples"`, `"work bound"`, `"fit failed"`), else None.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skipped: Option<&'static str>,
}

/// How the size was chosen (the reports' `details.model_size`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModelSizeChoice {
    /// The chosen candidate.
    pub chosen: String,
    /// `"validation"` (held-out fit %) or `"smallest"` (no candidate could be scored).
    pub criterion: &'static str,
    /// Samples of the training part.
    pub training_samples: usize,
    /// Every candidate, smallest first.
    pub candidates: Vec<SizeScore>,
}

/// A candidate size: the recipe's setting, its label and its parameter count.
pub(crate) struct Candidate<C> {
    pub setting: C,
    pub label: String,
    pub parameters: usize,
}

/// The samples the linear-in-weights data check asks of p parameters.
fn needed(p: usize) -> usize {
    (2 * p).max(p + 10)
}

/// The Preisach-plane families' (Preisach, KP) choice of their grid: the candidates
/// [`GRID_CANDIDATES`](super::family::GRID_CANDIDATES), each with its n(n+1)/2 cells, offset
/// and slope, chosen by [`choose`] within `bound` fits of the default grid 20; `fit` fits
/// the grid of n intervals. The choice is recorded in the fit's `model_size`.
pub(crate) fn choose_grid<M, F>(
    u: &[f64],
    y: &[f64],
    bound: f64,
    request: InitialState,
    fit: F,
) -> Result<OperatorFit<M>>
where
    M: HysteresisOperator,
    F: Fn(&[f64], &[f64], usize, Option<InitialStateUsed>) -> Result<OperatorFit<M>>,
{
    let parameters = |n: usize| n * (n + 1) / 2 + 2;
    let candidates = super::family::GRID_CANDIDATES
        .iter()
        .map(|&n| Candidate {
            setting: n,
            label: format!("grid {n}"),
            parameters: parameters(n),
        })
        .collect();
    let (mut f, choice) = choose(
        u,
        y,
        candidates,
        parameters(20),
        bound,
        request,
        |u, y, &n, state| fit(u, y, n, state),
    )?;
    f.model_size = Some(choice);
    Ok(f)
}

/// Chooses among `candidates` (smallest first) by the held-out fit % within `bound` default
/// fits of `default_parameters` parameters, and refits the winner on the whole record; the
/// candidates are fitted from the initial state [`first_state`] of `request` (each
/// simulated from it), the winner's state then settled by [`settle_state`]. `fit` fits a
/// candidate's setting from a declared state (None: the structure's own).
pub(crate) fn choose<M, C, F>(
    u: &[f64],
    y: &[f64],
    candidates: Vec<Candidate<C>>,
    default_parameters: usize,
    bound: f64,
    request: InitialState,
    fit: F,
) -> Result<(OperatorFit<M>, ModelSizeChoice)>
where
    M: HysteresisOperator,
    F: Fn(&[f64], &[f64], &C, Option<InitialStateUsed>) -> Result<OperatorFit<M>>,
{
    let state = first_state(request);
    let n = u.len().min(y.len());
    let split = n * TRAINING_FRACTION.0 / TRAINING_FRACTION.1;
    let budget = bound * n as f64 * (default_parameters as f64).powi(2);
    let mut spent = 0.0;
    let mut scores = Vec::with_capacity(candidates.len());
    let mut best: Option<(f64, usize)> = None;
    for (k, c) in candidates.iter().enumerate() {
        let cost = split as f64 * (c.parameters as f64).powi(2);
        let skipped = if split < needed(c.parameters) || n - split < 2 {
            Some("too few samples")
        } else if best.is_some() && spent + cost > budget {
            Some("work bound")
        } else {
            None
        };
        let mut score = None;
        let mut skipped = skipped;
        if skipped.is_none() {
            spent += cost;
            score = fit(&u[..split], &y[..split], &c.setting, state)
                .ok()
                .and_then(|f| initial_state::simulate(&f.model, f.initial_state, &u[..n]).ok())
                .map(|sim| metrics::fit_percent(&y[split..n], &sim[split..n]))
                .filter(|s| s.is_finite());
            if score.is_none() {
                skipped = Some("fit failed");
            }
        }
        if let Some(s) = score {
            if best.is_none_or(|(b, _)| s > b) {
                best = Some((s, k));
            }
        }
        scores.push(SizeScore {
            size: c.label.clone(),
            parameters: c.parameters,
            validation_fit_percent: score,
            skipped,
        });
    }
    let (index, criterion) = match best {
        Some((_, k)) => (k, "validation"),
        None => (
            candidates
                .iter()
                .position(|c| n >= needed(c.parameters))
                .unwrap_or(0),
            "smallest",
        ),
    };
    let chosen = candidates.get(index).ok_or_else(|| {
        crate::Error::invalid_option("model size", "[]", "no candidate model size".into())
    })?;
    let first = fit(&u[..n], &y[..n], &chosen.setting, state)?;
    let result = settle_state(request, first, &u[..n], |s| {
        fit(&u[..n], &y[..n], &chosen.setting, s)
    })?;
    Ok((
        result,
        ModelSizeChoice {
            chosen: chosen.label.clone(),
            criterion,
            training_samples: split,
            candidates: scores,
        },
    ))
}
