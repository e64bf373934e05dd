//! Tests of `hysid::numerics`.

mod integrate;
mod least_squares;
mod levenberg_marquardt;
mod metrics;
mod nelder_mead;
mod nnls;
mod progress;
mod signal;
