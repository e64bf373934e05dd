//! Numerical building blocks that know nothing of hysteresis: the bounded
//! Levenberg–Marquardt engine, linear least squares with covariance, a simplex minimiser,
//! MATLAB-compatible filters and excitation signals, fit metrics, and the termination
//! vocabulary of every search.
//!
//! * [`levenberg_marquardt`]: the bounded Levenberg–Marquardt engine (options struct,
//!   report with the termination reason, covariance).
//! * [`mod@least_squares`]: linear least squares by QR with covariance and a rank check.
//! * [`nnls`]: non-negative least squares (Lawson–Hanson) on the Gram matrix.
//! * [`nelder_mead`]: a small simplex minimiser for non-smooth one- and two-dimensional
//!   profiles.
//! * [`signal`]: excitation signals, seeded noise and MATLAB-compatible filters (`butter`,
//!   `cheby1`, `filter`, `filtfilt`, `decimate`, `gradient`).
//! * [`integrate`]: the classical RK4 step shared by every fixed-step simulation.
//! * [`metrics`]: fit %, RMSE, NRMSE, FPE and AIC.
//! * [`termination`]: why an iterative method stopped.
//! * [`progress`]: progress of the phases of a recipe, reported to an observer.

pub mod cpu;
pub mod integrate;
pub mod least_squares;
pub mod levenberg_marquardt;
pub mod metrics;
pub mod nelder_mead;
pub mod nnls;
pub mod progress;
pub mod signal;
pub mod termination;

pub use least_squares::{least_squares, LsSolution};
pub use levenberg_marquardt::{
    Control, Covariance, DampingScale, IterationRecord, LmConfig, LmReport,
};
pub use progress::{Observer, Progress};
pub use termination::Termination;

/// sgn with sgn(0) = 0 (friction and hysteresis laws use it).
#[inline]
pub fn sign0(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}
