//! Identification recipes of the hysteresis operators in [`crate::model::operators`], each
//! from the measured input and output alone (no initial guess):
//!
//! * [`backlash`]: profile over the half-width r with closed-form gain and offset, then a
//!   Levenberg–Marquardt polish on (g, r, c).
//! * [`pi`], [`maxwell_slip`]: non-negative least squares ([`crate::numerics::nnls`]) on the play/stop outputs
//!   of a threshold grid.
//! * [`gpi`]: the same plus the inverse dead zones, linear in the equation error
//!   S⁻¹\[y\] = H\[u\] (Kuhnen 2003).
//! * [`preisach`]: regularised non-negative least squares on the cell regressors of a
//!   triangular Preisach grid.
//! * [`kp`]: the same on the kernel states of a Krasnosel'skii–Pokrovskii grid, the ridge
//!   width profiled over a few candidates.
//! * [`jiles_atherton`], [`bouc_wen`], [`duhem`], [`dahl`]: output-error fits of the
//!   differential operators, each a small [`differential_fit::DifferentialFamily`] run by one
//!   driver ([`differential_fit::fit`]: a variable-projection start grid on a decimated
//!   record, local searches, then bounded Levenberg–Marquardt on the full record with
//!   sensitivities integrated in u, and a checked stop).
//!
//! The loop orientation is detected from the area between the ascending and descending
//! branches ([`crate::model::operators::Orientation::detect`],
//! [`crate::model::operators::orientation`]) unless given; a clockwise loop is fitted in the inverse-operator parameterisation (the core operator from
//! y to u).
use crate::model::operators::InitialStateUsed;
use crate::model::ParameterSet;
use crate::numerics::Termination;
use serde::Serialize;

pub use compare::{compare, CompareOptions, CompareRow, Comparison, Split};
pub use family::{
    fit_operator, EnvelopeChoice, Family, FamilyOptions, FamilySetting, FittedOperator,
    OrientationSource, OrientationUsed,
};

pub mod backlash;
pub mod bouc_wen;
pub mod compare;
pub mod dahl;
pub mod differential_fit;
pub mod duhem;
pub mod family;
pub mod gpi;
pub mod jiles_atherton;
pub mod kp;
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub mod linear_support;
pub mod maxwell_slip;
pub mod model_size;
pub mod pi;
pub mod preisach;

/// A fitted operator and how it was obtained.
#[allow(missing_docs)] // the shared item documents several fields in one comment
#[derive(Clone, Debug, Serialize)]
pub struct OperatorFit<M> {
    /// The fitted operator.
    pub model: M,
    /// Estimated parameters (the same names as `model.parameters()`).
    pub parameters: ParameterSet,
    /// Standard deviation per parameter (None where the parameter was not estimated, e.g. fixed
    /// thresholds or a weight held at the NNLS bound 0).
    pub std: Vec<Option<f64>>,
    /// The covariance of the estimates over `parameters`, p rows of p: σ²(JᵀJ)⁻¹ of the
    /// search (or of the least-squares solve) mapped to the model's parameters, zero in the
    /// rows and columns of the parameters whose `std` is None; its diagonal is `std`².
    pub covariance: Vec<Vec<f64>>,
    /// Γ\[u\] of the fitted operator on the estimation data.
    pub simulated: Vec<f64>,
    /// fit % = 100 (1 − ‖y − ŷ‖/‖y − ȳ‖), RMSE, loss V = mean squared residual, FPE, AIC
    pub fit_percent: f64,
    pub rmse: f64,
    pub loss: f64,
    pub fpe: f64,
    pub aic: f64,
    /// Iterations and criterion evaluations of the search (0/1 for a direct least-squares solve).
    pub iterations: usize,
    pub evaluations: usize,
    /// Why the search stopped (`Termination::ZeroResidual`/`Converged` for a direct solve); a
    /// search that did not converge must say so here, never be reported as success.
    pub termination: Termination,
    /// Wall-clock seconds of the fit.
    pub elapsed_s: f64,
    /// The initial state the fitted operator starts from (None: as its structure holds it,
    /// the family's neutral state; [`crate::model::operators::initial_state`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub initial_state: Option<InitialStateUsed>,
    /// The input a declared history turned at in the fit, where the fit placed it with
    /// another model than the one it returns (a differential family's turn is placed with the
    /// best grid point's memory reach); None: placed from the returned model and the record
    /// ([`InitialStateUsed::turning_input`]), which for the linear-in-weights families, whose
    /// reach depends only on the structure, is the fit's.
    #[serde(skip)]
    pub history_turn: Option<f64>,
    /// How the model size was chosen from the data (None: fixed by the options or the
    /// family's structure; [`model_size`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model_size: Option<model_size::ModelSizeChoice>,
}

/// Checks that the input u reverses at least once by more than
/// [`REVERSAL_FRACTION`](crate::model::operators::orientation::REVERSAL_FRACTION) of its
/// range ([`orientation::reversals`](crate::model::operators::orientation::reversals)): a
/// hysteresis fit needs an ascending and a descending branch, and a major loop measured from
/// its tip (a B(H) loop from +Hₘₐₓ down to −Hₘₐₓ and back) has exactly one reversal. Every
/// operator family asks this of its record, the linear-in-weights recipes
/// (`linear_support::check_data`) and the differential driver
/// (`differential_fit::check_record`) alike.
pub(crate) fn check_reversal(u: &[f64]) -> crate::Result<()> {
    use crate::model::operators::orientation::{reversals, REVERSAL_FRACTION};
    if reversals(u) < 1 {
        return Err(crate::Error::NotExciting {
            channel: "u".into(),
            reason: format!(
                "it never reverses direction by more than {} % of its range; a hysteresis fit \
                 needs an ascending and a descending branch (at least one reversal): excite \
                 with a periodic or decaying oscillating input, or a loop from one end of the \
                 range to the other and back",
                100.0 * REVERSAL_FRACTION
            ),
        });
    }
    Ok(())
}
