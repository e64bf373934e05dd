//! Hysteresis operators y = Γ\[u\]: rate-independent (and rate-dependent) hysteresis families
//! with their simulation from a documented initial state and their inverse for feed-forward
//! compensation.
//!
//! Families in this module (the linear-in-weights ones):
//! * [`Backlash`] — the play operator (Krasnosel'skii & Pokrovskii 1989) with gain and offset.
//! * [`PrandtlIshlinskii`] — a weighted superposition of play operators with the analytic
//!   inverse of Krejčí & Kuhnen (2001) and Kuhnen (2003).
//! * [`GeneralizedPi`] — Kuhnen's (2003) modified PI: a PI followed by a superposition of
//!   one-sided dead zones, for asymmetric loops; analytic inverse.
//! * [`Preisach`] — the discrete Preisach plane (Mayergoyz 1991) with a piecewise-constant
//!   density on a triangular grid, simulated through the Everett function.
//! * [`Kp`] — the Krasnosel'skii–Pokrovskii operator (Krasnosel'skii & Pokrovskii 1989; Banks,
//!   Kurdila & Webb 1997): continuous play-and-ridge kernels on a triangular threshold grid.
//! * [`MaxwellSlip`] — generalised Maxwell-slip friction elements (Lampaert, Al-Bender &
//!   Swevers 2003), a stop-operator superposition, inverted through the PI inverse.
//!
//! The differential families:
//! * differential operators, a state x with dx/du = F(u, x, sign du) integrated in the input
//!   ([`differential`]): Jiles–Atherton (`jiles-atherton`, [`JilesAtherton`]), the static
//!   Bouc–Wen operator (`bouc-wen`, [`BoucWen`]), the generalised Duhem / Coleman–Hodgdon
//!   operator (`duhem`, [`Duhem`]) and Dahl friction (`dahl`, [`Dahl`]).
//!
//! **Initial states.** Every play/stop operator starts from the state 0 as if the input had
//! been 0 before the first sample: F_r\[u\]₀ = max(u₀ − r, min(u₀ + r, 0)); so does the play
//! inside every KP kernel. The Preisach plane starts in negative saturation (all relays down,
//! as if the input came from below the grid).
//!
//! **Orientation.** A counter-clockwise loop (the output lags the input, as most B(H) loops and
//! the play operator itself) is modelled directly: Γ = G. A clockwise loop (the output leads)
//! is the mirror image of a counter-clockwise one under exchanging the axes, so it is modelled
//! by the *inverse-operator parameterisation* Γ = G⁻¹, G fitted from y to u; a decreasing
//! trend is a sign flip of the output. See [`Orientation`]. The inverse of Γ then is G itself
//! (for the clockwise case) — exact and analytic.
//!
//! For the differential families: A loop is counter-clockwise when its ascending branch lies below the
//! descending one ([`LoopOrientation`]). Each family says how it represents the other
//! orientation: Bouc–Wen by the sign of k_w, Duhem by the sign of c − a, Jiles–Atherton
//! (natively counter-clockwise) and Dahl (natively clockwise) by a sign flip of the input (the
//! loop is mirrored, so its slope changes sign too).
//!
//! **Initial states.** Every differential operator carries its state at the first input
//! sample as a parameter (`m0`, `w0`, `y0`, `f0`), so a record that starts anywhere on a loop
//! can be simulated and fitted. A declared history (descending, ascending: [`initial_state`])
//! is run through the operator before the record, for every family alike.
use crate::model::ParameterSet;
use crate::Result;
use serde::{Deserialize, Serialize};

pub(crate) mod backlash;
pub mod bouc_wen;
pub mod dahl;
pub mod differential;
pub mod duhem;
pub(crate) mod elementary;
pub mod envelope;
pub(crate) mod gpi;
pub mod initial_state;
pub mod jiles_atherton;
pub mod kp;
pub(crate) mod maxwell_slip;
pub mod orientation;
pub(crate) mod pi;
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub mod preisach;
pub mod registry;
pub(crate) mod streaming;

pub use backlash::Backlash;
pub use bouc_wen::BoucWen;
pub use dahl::Dahl;
pub use differential::{InputOde, LoopOrientation};
pub use duhem::Duhem;
pub use elementary::{
    play, play_step, solve_monotone, stop, validate_thresholds, Branch, Orientation,
};
pub use envelope::Envelope;
pub use gpi::{DeadZones, GeneralizedPi};
pub use initial_state::{InitialState, InitialStateUsed};
pub use jiles_atherton::{Anhysteretic, JaOutput, JilesAtherton};
pub use kp::Kp;
pub use maxwell_slip::MaxwellSlip;
pub use orientation::{loop_evidence, LoopEvidence};
pub use pi::PrandtlIshlinskii;
pub use preisach::Preisach;
pub(crate) use registry::operator_families;
pub use registry::{check_values, Family, OperatorFamily, OperatorModel};
pub use streaming::CompensatorStep;

/// The result of inverting an operator for feed-forward compensation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Inversion {
    /// The input u that makes the operator's output follow the reference.
    pub u: Vec<f64>,
    /// Γ\[u\]: the operator's output for `u` (equal to the reference where it is reachable).
    pub predicted: Vec<f64>,
    /// Indices of the samples where the reference lay outside the reachable range and was clipped.
    pub clipped: Vec<usize>,
}

/// A scalar hysteresis operator with its documented initial state.
pub trait HysteresisOperator: Send + Sync + std::fmt::Debug {
    /// The family's name on the command line ([`OperatorFamily::NAME`]).
    fn family(&self) -> &'static str;
    /// The parameters, names from the literature, flattened (`a0`, `a1`, …, `r1`, …), with units and
    /// bounds where they have them.
    fn parameters(&self) -> ParameterSet;
    /// Γ\[u\] from the documented initial state (u\[0\] is the first input sample).
    fn simulate(&self, u: &[f64]) -> Result<Vec<f64>>;
    /// The input that makes Γ follow `reference`, from the same initial state; samples outside the
    /// reachable range are clipped to it and listed, never silently.
    fn invert(&self, reference: &[f64]) -> Result<Inversion>;
    /// The input distance beyond the record over which a monotone excursion wipes out the
    /// operator's memory ([`initial_state`]): twice the largest play threshold, the span of a
    /// Preisach grid, 100 sub-steps of a differential family's input scale. 0 (the default):
    /// twice the record's span is enough.
    fn memory_reach(&self) -> f64 {
        0.0
    }
}
