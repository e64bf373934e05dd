//! The model size of the linear-in-weights families chosen from the data: threshold counts
//! and placements (PI, generalised PI, Maxwell-slip), the PI's static envelope, and the
//! Preisach / KP grid.
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
//! whole record (`linear_support::fit_initial_state`: `estimate` refits
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

use super::gpi::ZonePlacement;
use super::linear_support::{
    first_state, fit_initial_state, geometric_thresholds, threshold_grid, Fit,
};
use super::OperatorFit;
use crate::model::operators::{initial_state, HysteresisOperator, InitialState, Orientation};
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
/// the grid of n intervals (its arguments as [`choose`]'s). The choice is recorded in the
/// fit's `model_size`.
pub(crate) fn choose_grid<M, F>(
    u: &[f64],
    y: &[f64],
    bound: f64,
    request: InitialState,
    fit: F,
) -> Result<OperatorFit<M>>
where
    M: HysteresisOperator,
    F: Fn(&[f64], &[f64], usize, Fit<M>) -> Result<OperatorFit<M>>,
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
    choose(
        u,
        y,
        candidates,
        parameters(20),
        bound,
        request,
        |u, y, &n, start| fit(u, y, n, start),
    )
}

/// What a play family's candidate carries beside its plays: a static envelope (the PI's
/// cubic, `model::operators::envelope`), and the generalised PI's dead zones per side when
/// their count is part of the choice (None: fixed, counted in the family's `extra`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PlayVariant {
    /// A cubic static envelope beside the plays.
    pub envelope: bool,
    /// Dead zones per side of the static map S (generalised PI) and their placement,
    /// chosen with the plays.
    pub dead_zones: Option<(usize, ZonePlacement)>,
}

impl PlayVariant {
    /// The plays alone.
    pub const PLAIN: Self = Self {
        envelope: false,
        dead_zones: None,
    };

    /// The parameters the variant adds: the envelope's three slope values less a₀, which
    /// the envelope holds (`identify::operators::pi`), and two per dead zone and side.
    fn parameters(self) -> usize {
        usize::from(self.envelope) * ENVELOPE_PARAMETERS + 2 * self.dead_zones.map_or(0, |d| d.0)
    }

    /// The label's suffix: `" + envelope"`, `", m dead zones"` (uniform),
    /// `", m quantile dead zones"`, or nothing.
    fn suffix(self) -> String {
        let envelope = if self.envelope { " + envelope" } else { "" };
        match self.dead_zones {
            Some((m, ZonePlacement::Uniform)) => format!("{envelope}, {m} dead zones"),
            Some((m, ZonePlacement::Quantile)) => format!("{envelope}, {m} quantile dead zones"),
            None => envelope.to_string(),
        }
    }
}

/// A play family's candidate size: its thresholds and what it carries beside them.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct PlaySize {
    /// The thresholds r₁ < … < rₙ.
    pub grid: Vec<f64>,
    /// The envelope, the dead zones.
    pub variant: PlayVariant,
}

/// The parameters a static envelope adds to a candidate: a cubic's three slope values less
/// a₀, which the envelope holds (`identify::operators::pi`).
const ENVELOPE_PARAMETERS: usize = crate::model::operators::envelope::CUBIC - 1;

/// The play and stop families' (PI, generalised PI, Maxwell-slip) choice of their
/// thresholds: the candidates of [`threshold_candidates`] on the core's input
/// `x`, each with `extra` parameters beside its weights and once per entry of `variants`
/// (without and with a static envelope; the generalised PI's dead-zone counts), chosen by
/// [`choose`] within [`PLAY_WORK_BOUND`] fits of the default ten thresholds per entry; `fit`
/// fits a [`PlaySize`] in the orientation `o`. The choice is recorded in the fit's
/// `model_size`.
pub(crate) fn choose_thresholds<M, F>(
    u: &[f64],
    y: &[f64],
    o: Orientation,
    extra: usize,
    variants: &[PlayVariant],
    request: InitialState,
    fit: F,
) -> Result<OperatorFit<M>>
where
    M: HysteresisOperator,
    F: Fn(&[f64], &[f64], &PlaySize, Fit<M>) -> Result<OperatorFit<M>>,
{
    let (x, _) = o.core_data(u, y);
    let candidates = threshold_candidates(&x, extra, variants)?;
    let bound = PLAY_WORK_BOUND * variants.len().max(1) as f64;
    let default = 10 + extra + variants.first().map_or(0, |v| v.parameters());
    choose(u, y, candidates, default, bound, request, fit)
}

/// The work bound of the threshold-count choice, in fits of the fixed default size
/// ([`choose_thresholds`]): a play sum's fit is a few passes over the
/// data, so all twelve candidates fit within it on any record.
const PLAY_WORK_BOUND: f64 = 12.0;

/// The candidate threshold grids of the count choice: every count of
/// [`super::family::THRESHOLD_CANDIDATES`], uniform then geometric
/// (the geometric one only where it differs), each once per entry of `variants`, labelled
/// `"n uniform"` / `"n geometric"` with the variant's suffix (`" + envelope"`,
/// `", m dead zones"`), with `extra` parameters beside the n weights (and the variant's);
/// smallest first (a stable sort by the parameter count, so that the work bound and a tie
/// favour the smaller model).
fn threshold_candidates(
    x: &[f64],
    extra: usize,
    variants: &[PlayVariant],
) -> Result<Vec<Candidate<PlaySize>>> {
    let mut out = Vec::new();
    for &n in &super::family::THRESHOLD_CANDIDATES {
        let uniform = threshold_grid(x, n)?;
        let geometric = geometric_thresholds(x, n)?;
        let mut grids = vec![(uniform.clone(), "uniform")];
        if geometric != uniform {
            grids.push((geometric, "geometric"));
        }
        for &variant in variants {
            for (grid, placement) in &grids {
                out.push(Candidate {
                    setting: PlaySize {
                        grid: grid.clone(),
                        variant,
                    },
                    label: format!("{n} {placement}{}", variant.suffix()),
                    parameters: n + extra + variant.parameters(),
                });
            }
        }
    }
    out.sort_by_key(|c| c.parameters);
    Ok(out)
}

/// Chooses among `candidates` (smallest first) by the held-out fit % within `bound` default
/// fits of `default_parameters` parameters, and refits the winner on the whole record; the
/// candidates are fitted from the initial state [`first_state`] of `request` (each
/// simulated from it), the winner's state then settled by [`fit_initial_state`]. `fit` fits a
/// candidate's setting from the start [`Fit`]. The choice is recorded in the fit's
/// `model_size`.
pub(crate) fn choose<M, C, F>(
    u: &[f64],
    y: &[f64],
    candidates: Vec<Candidate<C>>,
    default_parameters: usize,
    bound: f64,
    request: InitialState,
    fit: F,
) -> Result<OperatorFit<M>>
where
    M: HysteresisOperator,
    F: Fn(&[f64], &[f64], &C, Fit<M>) -> Result<OperatorFit<M>>,
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
            let start = Fit { state, first: None };
            score = fit(&u[..split], &y[..split], &c.setting, start)
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
    let mut result = fit_initial_state(request, &u[..n], |start| {
        fit(&u[..n], &y[..n], &chosen.setting, start)
    })?;
    result.model_size = Some(ModelSizeChoice {
        chosen: chosen.label.clone(),
        criterion,
        training_samples: split,
        candidates: scores,
    });
    Ok(result)
}
