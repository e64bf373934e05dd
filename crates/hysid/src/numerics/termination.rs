//! Why an iterative method stopped (MATLAB's "WhyStop"): one vocabulary for every search.

use serde::{Deserialize, Serialize};
use std::fmt;

/// Why an iterative estimator stopped (MATLAB's "WhyStop").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(tag = "code", rename_all = "snake_case")]
pub enum Termination {
    /// The maximum number of iterations was reached.
    MaxIterations,
    /// The relative decrease of the criterion (actual and predicted) fell below the tolerance.
    ImprovementBelowTolerance {
        /// The last relative decrease.
        relative: f64,
    },
    /// The parameter step fell below the tolerance.
    StepBelowTolerance,
    /// The gradient is orthogonal to the residuals to within the tolerance.
    GradientBelowTolerance,
    /// The residuals are zero to working precision: the data are fitted exactly.
    ZeroResidual,
    /// No step decreased the criterion even with very large damping.
    NoDescent,
    /// The progress callback asked to stop.
    Stopped,
    /// Every parameter is fixed: nothing to estimate.
    NothingToEstimate,
    /// An iteration of a fixed-point method converged: the parameter change fell below the
    /// tolerance.
    Converged {
        /// The last relative change of the parameters.
        change: f64,
    },
    /// The search stopped on a flat region, not at a minimum: its steps gained less than the
    /// tolerance while the undamped Gauss–Newton model at the point still promises the
    /// relative decrease `expected` of the criterion (e.g. after many trial points where the
    /// model is not defined, the damped steps became too short to matter).
    FlatRegion {
        /// The relative decrease gᵀ(JᵀJ)⁻¹g/S that a Gauss–Newton step still promises.
        expected: f64,
    },
    /// A fixed-point iteration left the region where the model is defined.
    Diverged {
        /// What went wrong.
        reason: String,
    },
}

impl Termination {
    /// True for the reasons that mean the search reached a (local) optimum.
    pub fn converged(&self) -> bool {
        matches!(
            self,
            Termination::ImprovementBelowTolerance { .. }
                | Termination::StepBelowTolerance
                | Termination::GradientBelowTolerance
                | Termination::ZeroResidual
                | Termination::Converged { .. }
                | Termination::NothingToEstimate
        )
    }
}

impl fmt::Display for Termination {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Termination::MaxIterations => write!(f, "maximum number of iterations reached"),
            Termination::ImprovementBelowTolerance { relative } => {
                write!(f, "relative improvement {relative:.2e} below tolerance")
            }
            Termination::StepBelowTolerance => write!(f, "parameter step below tolerance"),
            Termination::GradientBelowTolerance => write!(f, "gradient below tolerance (optimum)"),
            Termination::ZeroResidual => {
                write!(f, "residuals zero to working precision (exact fit)")
            }
            Termination::NoDescent => write!(f, "no step decreases the criterion any further"),
            Termination::Stopped => write!(f, "stopped by the caller"),
            Termination::NothingToEstimate => {
                write!(f, "all parameters fixed: nothing to estimate")
            }
            Termination::Converged { change } => {
                write!(f, "parameter change {change:.2e} below tolerance")
            }
            Termination::FlatRegion { expected } => write!(
                f,
                "stopped on a flat region (a Gauss-Newton step still promises a relative \
                 decrease of {expected:.2e})"
            ),
            Termination::Diverged { reason } => write!(f, "diverged: {reason}"),
        }
    }
}
