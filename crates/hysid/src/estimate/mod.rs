//! Estimators.
//!
//! Each estimator is a plain settings struct with builder methods and one `estimate` call that
//! returns a report. Non-convergence is a [`Termination`] in the report, not an error.
//!
//! * [`least_squares`]: linear least squares with covariance and a rank check.
//! * [`levenberg_marquardt`]: the bounded Levenberg–Marquardt engine.
//! * [`output_error`]: output-error estimation over several experiments for any
//!   [`OutputErrorModel`].
//! * [`bootstrap`]: parametric bootstrap standard deviations where the curvature misleads.
//! * [`hysteresis`]: the Coleman–Hodgdon hysteresis alone, from measured input and output.
//! * [`inverse_dynamics`]: rigid-body least squares with friction (IDIM, step 1 of paper 2).
//! * [`key_term`]: the iterative key-term-separation method of Vörös (2015) for the cascade.
//! * [`global`]: the (α, d) grid stage that makes the cascade fit independent of the start.
//! * [`cascade`]: the whole cascade pipeline (global stage, paper iteration, output error).
//! * [`multistart`]: several starts inside the bounds, fitted in parallel, the best kept.
//! * [`nelder_mead`]: a small simplex minimiser for the non-smooth (α, d) profile.
//! * [`rls`]: recursive least squares with forgetting for online identification.
//! * [`switching`]: the switching function h as an internal variable of output-error fits.

pub mod bootstrap;
pub mod cascade;
pub mod cascade_pass;
pub mod global;
pub mod grid_regression;
pub mod hysteresis;
pub mod inverse_dynamics;
pub mod key_term;
pub mod levenberg_marquardt;
mod linear_ls;
pub mod multistart;
pub mod nelder_mead;
pub mod output_error;
mod parameters;
pub mod rls;
pub mod switching;

pub use levenberg_marquardt::{Control, Covariance, IterationRecord, LmConfig, LmReport};
pub use linear_ls::{least_squares, LsSolution};
pub use output_error::{OutputError, OutputErrorFit, OutputErrorModel};
pub use parameters::{Parameter, ParameterSet};

use serde::Serialize;
use std::fmt;

/// How the standard deviations of an estimate are obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Uncertainty {
    /// σ²(JᵀJ)⁻¹ from the curvature at the estimate (fast; MATLAB's).
    Asymptotic,
    /// Parametric bootstrap with this many replicates, each identified again from scratch
    /// ([`bootstrap`]): right when the criterion has several nearly equal minima.
    Bootstrap(usize),
}

/// Why an iterative estimator stopped (MATLAB's "WhyStop").
#[derive(Clone, Debug, PartialEq, Serialize)]
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
            Termination::Diverged { reason } => write!(f, "diverged: {reason}"),
        }
    }
}
