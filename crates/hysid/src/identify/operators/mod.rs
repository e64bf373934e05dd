//! Identification recipes of the hysteresis operators of [`crate::model::operators`]: each
//! family's `fit(u, y, options)` starts from the data alone (a data-driven start, a small
//! multi-start) and returns an [`OperatorFit`].
//!
//! * [`jiles_atherton`], [`bouc_wen`], [`duhem`], [`dahl`]: bounded Levenberg–Marquardt
//!   output-error fits of the differential operators ([`differential_fit`] holds their common
//!   part).
use crate::estimate::{ParameterSet, Termination};
use serde::Serialize;

pub mod bouc_wen;
pub mod dahl;
pub mod differential_fit;
pub mod duhem;
pub mod jiles_atherton;

/// A fitted operator and how it was obtained.
// The shared doc comments cover the fields grouped on one line.
#[allow(missing_docs)]
#[derive(Clone, Debug, Serialize)]
pub struct OperatorFit<M> {
    /// The fitted operator.
    pub model: M,
    /// Estimated parameters (the same names as `model.parameters()`).
    pub parameters: ParameterSet,
    /// Standard deviation per parameter (None where the parameter was not estimated, e.g. fixed
    /// thresholds or a weight held at the NNLS bound 0).
    pub std: Vec<Option<f64>>,
    /// Γ[u] of the fitted operator on the estimation data.
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
}
