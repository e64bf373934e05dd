//! Hysteresis operators y = Γ[u]: rate-independent maps from an input path to an output path.
//!
//! Families (the name on the command line in brackets):
//! * differential operators, a state x with dx/du = F(u, x, sign du) integrated in the input
//!   ([`differential`]): Jiles–Atherton (`jiles-atherton`, [`JilesAtherton`]), the static
//!   Bouc–Wen operator (`bouc-wen`, [`BoucWen`]), the generalised Duhem / Coleman–Hodgdon
//!   operator (`duhem`, [`Duhem`]) and Dahl friction (`dahl`, [`Dahl`]).
//!
//! **Orientation.** A loop is counter-clockwise when its ascending branch lies below the
//! descending one ([`LoopOrientation`]). Each family says how it represents the other
//! orientation: Bouc–Wen by the sign of k_w, Duhem by the sign of c − a, Jiles–Atherton
//! (natively counter-clockwise) and Dahl (natively clockwise) by a sign flip of the input (the
//! loop is mirrored, so its slope changes sign too).
//!
//! **Initial states.** Every differential operator carries its state at the first input
//! sample as a parameter (`m0`, `w0`, `y0`, `f0`), so a record that starts anywhere on a loop
//! can be simulated and fitted.
use crate::estimate::ParameterSet; // moves to crate::model later
use crate::Result;
use serde::{Deserialize, Serialize};

pub mod bouc_wen;
pub mod dahl;
pub mod differential;
pub mod duhem;
pub mod jiles_atherton;

pub use bouc_wen::BoucWen;
pub use dahl::Dahl;
pub use differential::{InputOde, LoopOrientation};
pub use duhem::Duhem;
pub use jiles_atherton::{Anhysteretic, JaOutput, JilesAtherton};

/// The result of inverting an operator for feed-forward compensation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Inversion {
    /// The input u that makes the operator's output follow the reference.
    pub u: Vec<f64>,
    /// Γ[u]: the operator's output for `u` (equal to the reference where it is reachable).
    pub predicted: Vec<f64>,
    /// Indices of the samples where the reference lay outside the reachable range and was clipped.
    pub clipped: Vec<usize>,
}

/// A scalar hysteresis operator with its documented initial state.
pub trait HysteresisOperator: Send + Sync + std::fmt::Debug {
    /// The family's name on the command line (`pi`, `gpi`, `preisach`, `jiles-atherton`, `bouc-wen`,
    /// `duhem`, `dahl`, `maxwell-slip`, `backlash`).
    fn family(&self) -> &'static str;
    /// The parameters, names from the literature, flattened (`a0`, `a1`, …, `r1`, …), with units and
    /// bounds where they have them.
    fn parameters(&self) -> ParameterSet;
    /// Γ[u] from the documented initial state (u[0] is the first input sample).
    fn simulate(&self, u: &[f64]) -> Result<Vec<f64>>;
    /// The input that makes Γ follow `reference`, from the same initial state; samples outside the
    /// reachable range are clipped to it and listed, never silently.
    fn invert(&self, reference: &[f64]) -> Result<Inversion>;
}
