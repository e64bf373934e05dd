//! The initial hysteresis state of an operator: where a record's memory starts
//! (MODELS.md §4.8).
//!
//! A measured record rarely starts in a family's neutral state. For an input record u
//! starting at u₀ with range \[u_min, u_max\] and span R = u_max − u_min, the declared states
//! are standard monotone histories run through the operator itself before the first sample:
//!
//! ```text
//! descending:  the input path u₀ → u_top → u₀, then the record,   u_top = u_max + M
//! ascending:   the input path u₀ → u_bot → u₀, then the record,   u_bot = u_min − M
//! M = max(2·R, reach),   reach = the operator's memory reach (HysteresisOperator::memory_reach)
//! ```
//!
//! so the record begins at the end of a descent from above its maximum (the state after a
//! standardisation: cycle to the maximum, come down), resp. of an ascent from below its
//! minimum. The excursion of M beyond the record wipes out the memory (Mayergoyz 2003,
//! wiping-out property): every play z_i = min(u₀ + r_i, …) sits on its upper edge
//! z_i = u₀ + r_i, the Preisach staircase holds u_top then u₀, a Bouc–Wen / Duhem state is the
//! one reached by integrating dz/du from its positive saturation down to u₀. The outputs of
//! the history are not part of the simulation.
//!
//! A fitted model keeps the turn its fit used (the model file's `history_turn`), and every
//! later record re-applies the history at its own first input with that turn,
//! u₀ → u_turn → u₀ ([`History::turn_at`]): the turn depends on nothing after the first
//! sample, so a stream ([`crate::model::OperatorModel::stepper_from`]) runs the same path as a
//! batch simulation and gives the same bits. A record starting beyond the saved turn (above
//! u_top, below u_bot) turns at u₀ ± max(reach, |u₀ − u_turn|) instead. A model file without
//! the key (earlier versions) places the turn from each record's range as above in a batch;
//! its stream turns at u₀ ± reach (for the linear-in-weights families the same state, by
//! wiping-out).
//!
//! `demagnetised` is the family's neutral state, the one its structure documents (today's
//! behaviour, and that of a model file without the field): plays from 0, the Preisach plane in
//! negative saturation, the differential families' state x₀ = 0 when fitted so (their saved
//! `w0`, `m0`, `y0`, `f0` otherwise). `estimated` is the state the fit chose, saved in the
//! operator's structure (the differential families' x₀) and simulated as saved.
//!
//! Reference: I. D. Mayergoyz, *Mathematical Models of Hysteresis and their Applications*,
//! Elsevier 2003 (wiping-out property, §1.2).

use super::HysteresisOperator;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// The initial state a fit is asked to use (`--initial-state`, Python `initial_state=`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InitialState {
    /// The family's neutral state (x₀ = 0; plays from 0; Preisach in negative saturation).
    Demagnetised,
    /// The end of a monotone descent from above the record's maximum (module doc).
    Descending,
    /// The end of a monotone ascent from below the record's minimum (module doc).
    Ascending,
    /// Fitted from the data (the default): the differential families score the
    /// demagnetised, descending and ascending starts and refine x₀ as a free parameter.
    #[default]
    Estimate,
}

impl InitialState {
    /// Every value, in the order of the command line's help.
    pub const ALL: [InitialState; 4] = [
        InitialState::Demagnetised,
        InitialState::Descending,
        InitialState::Ascending,
        InitialState::Estimate,
    ];

    /// `demagnetised`, `descending`, `ascending` or `estimate`.
    pub fn name(self) -> &'static str {
        match self {
            InitialState::Demagnetised => "demagnetised",
            InitialState::Descending => "descending",
            InitialState::Ascending => "ascending",
            InitialState::Estimate => "estimate",
        }
    }

    /// Parses a name of [`InitialState::name`] (case-insensitive; `demagnetized` accepted).
    pub fn parse(text: &str) -> Result<Self> {
        let wanted = text.trim().to_ascii_lowercase();
        let wanted = if wanted == "demagnetized" {
            "demagnetised".to_string()
        } else {
            wanted
        };
        InitialState::ALL
            .iter()
            .copied()
            .find(|s| s.name() == wanted)
            .ok_or_else(|| {
                Error::invalid_option(
                    "initial-state",
                    text,
                    format!(
                        "initial state '{text}' is none of demagnetised, descending, ascending, \
                         estimate"
                    ),
                )
            })
    }

    /// The declared history of this request, None for `estimate`.
    pub fn declared(self) -> Option<InitialStateUsed> {
        match self {
            InitialState::Demagnetised => Some(InitialStateUsed::Demagnetised),
            InitialState::Descending => Some(InitialStateUsed::Descending),
            InitialState::Ascending => Some(InitialStateUsed::Ascending),
            InitialState::Estimate => None,
        }
    }
}

/// The initial state a fitted operator uses, resolved: what a model file saves as
/// `"initial_state"` and what `simulate` applies to a new record (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum InitialStateUsed {
    /// The family's neutral state, as the operator's structure holds it.
    Demagnetised,
    /// A descent from above the record's maximum, re-applied at every record's first input.
    Descending,
    /// An ascent from below the record's minimum, re-applied at every record's first input.
    Ascending,
    /// The state the fit estimated, held in the operator's structure and simulated as saved.
    Estimated,
}

impl InitialStateUsed {
    /// `demagnetised`, `descending`, `ascending` or `estimated`.
    pub fn name(self) -> &'static str {
        match self {
            InitialStateUsed::Demagnetised => "demagnetised",
            InitialStateUsed::Descending => "descending",
            InitialStateUsed::Ascending => "ascending",
            InitialStateUsed::Estimated => "estimated",
        }
    }

    /// The input a declared history turns at before coming back to the record's first
    /// input (u_top or u_bot of the module doc), None for the states held in the structure.
    pub fn turning_input(self, op: &dyn HysteresisOperator, u: &[f64]) -> Option<f64> {
        let (lo, hi) = u
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                (lo.min(x), hi.max(x))
            });
        let reach = op.memory_reach();
        self.turning_point(lo, hi, if reach.is_finite() { reach } else { 0.0 })
    }

    /// The turning input for a record of range \[lo, hi\] and an operator of memory reach
    /// `reach`: hi + M (descending) or lo − M (ascending), M = max(2 (hi − lo), reach)
    /// (module doc); None for the states held in the structure or a range not finite.
    pub fn turning_point(self, lo: f64, hi: f64, reach: f64) -> Option<f64> {
        let direction = match self {
            InitialStateUsed::Descending => 1.0,
            InitialStateUsed::Ascending => -1.0,
            _ => return None,
        };
        if !(lo.is_finite() && hi.is_finite()) {
            return None;
        }
        let scale = hi.abs().max(lo.abs()).max(1.0);
        let margin = (2.0 * (hi - lo)).max(reach).max(1e-6 * scale);
        Some(if direction > 0.0 {
            hi + margin
        } else {
            lo - margin
        })
    }
}

/// A declared history as a fitted model holds it: the state and the input the history turns
/// at (the fit's; None in model files of earlier versions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct History {
    /// `descending` or `ascending`.
    pub state: InitialStateUsed,
    /// u_top (descending) or u_bot (ascending) of the fit.
    pub turn: Option<f64>,
}

impl History {
    /// The declared history of a model starting from `state` with the saved `turn`; None
    /// for the states held in the structure (none, `demagnetised`, `estimated`).
    pub fn of(state: Option<InitialStateUsed>, turn: Option<f64>) -> Option<History> {
        match state {
            Some(state @ (InitialStateUsed::Descending | InitialStateUsed::Ascending)) => {
                Some(History { state, turn })
            }
            _ => None,
        }
    }

    /// +1 for a descent from above, −1 for an ascent from below.
    pub fn direction(&self) -> f64 {
        if self.state == InitialStateUsed::Descending {
            1.0
        } else {
            -1.0
        }
    }

    /// `op`'s memory reach as the turn uses it (0 when not finite).
    pub fn reach(op: &dyn HysteresisOperator) -> f64 {
        let reach = op.memory_reach();
        if reach.is_finite() {
            reach
        } else {
            0.0
        }
    }

    /// The input the history turns at before a record whose first input is `u0` (module doc):
    /// the saved turn when it lies beyond u₀ in the history's direction, otherwise (or without
    /// a saved turn) u₀ ± max(reach, |u₀ − turn|, 10⁻⁶·max(|u₀|, 1)), with the operator's
    /// memory `reach` ([`History::reach`]).
    pub fn turn_at(&self, reach: f64, u0: f64) -> f64 {
        let direction = self.direction();
        if let Some(turn) = self.turn {
            if (turn - u0) * direction > 0.0 {
                return turn;
            }
        }
        let beyond = self.turn.map_or(0.0, |t| (u0 - t).abs());
        let margin = reach.max(beyond).max(1e-6 * u0.abs().max(1.0));
        u0 + direction * margin
    }

    /// The record u with the history prepended: \[u₀, u_turn\] then u (a model file without a
    /// saved turn: the turn placed from u's range, [`InitialStateUsed::turning_input`]).
    pub fn path(&self, op: &dyn HysteresisOperator, u: &[f64]) -> Vec<f64> {
        match (self.turn, u.first()) {
            (Some(_), Some(&u0)) => {
                let turn = self.turn_at(Self::reach(op), u0);
                [u0, turn].iter().chain(u).copied().collect()
            }
            _ => with_history(op, self.state, u),
        }
    }
}

/// Γ\[u\] of `op` after the declared `history` (None: from the state its structure holds):
/// the history's path run first, its outputs dropped. What `simulate` of a saved model does.
pub fn simulate_from(
    op: &dyn HysteresisOperator,
    history: Option<History>,
    u: &[f64],
) -> Result<Vec<f64>> {
    let Some(history) = history else {
        return op.simulate(u);
    };
    run_after(op, history.path(op, u), u.len())
}

/// Γ along `path` (a history, then a record of `n` samples), the record's outputs only.
fn run_after(op: &dyn HysteresisOperator, path: Vec<f64>, n: usize) -> Result<Vec<f64>> {
    let skip = path.len() - n;
    let mut y = op.simulate(&path)?;
    Ok(y.split_off(skip))
}

/// The input path of a declared history before the record u: \[u₀, u_turn\]
/// ([`HISTORY_SAMPLES`] samples), empty for the states held in the structure.
pub fn history(op: &dyn HysteresisOperator, state: InitialStateUsed, u: &[f64]) -> Vec<f64> {
    match (state.turning_input(op, u), u.first()) {
        (Some(turn), Some(&u0)) => vec![u0, turn],
        _ => Vec::new(),
    }
}

/// The samples of a declared history prepended to a record (u₀ and the turning input).
pub const HISTORY_SAMPLES: usize = 2;

/// The record u with the history of `state` prepended (module doc): what a fit with a
/// declared history simulates, its first [`history`] outputs not scored.
pub fn with_history(op: &dyn HysteresisOperator, state: InitialStateUsed, u: &[f64]) -> Vec<f64> {
    let mut path = history(op, state, u);
    path.extend_from_slice(u);
    path
}

/// Γ\[u\] of `op` from the initial state `state` (None: as the structure holds it, the
/// behaviour of a model file without `initial_state`): a declared history is run first and
/// its outputs dropped.
pub fn simulate(
    op: &dyn HysteresisOperator,
    state: Option<InitialStateUsed>,
    u: &[f64],
) -> Result<Vec<f64>> {
    match state {
        Some(state) => run_after(op, with_history(op, state, u), u.len()),
        None => op.simulate(u),
    }
}
