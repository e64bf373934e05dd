//! # hysid — identification of dynamic systems with hysteresis
//!
//! hysid identifies models of systems that contain hysteresis from measured input/output data:
//! a piezo stage, a harmonic drive, a lead-screw actuator, a magnetic core.
//!
//! The library reads top-down in layers; each depends only on the layers below it
//! (`docs/architecture.md` draws them and says where new code goes):
//!
//! 1. [`numerics`] — the Levenberg–Marquardt engine, least squares, a simplex minimiser,
//!    filters and excitation signals, fit metrics; knows nothing of hysteresis. [`data`] —
//!    the validated identification data set ([`data::IdData`]), CSV and .mat input.
//!    [`toolchain`] — the machine's C compiler (`$CC`), for native code and FMU binaries.
//! 2. [`model`] — parameters and every model (Coleman–Hodgdon hysteresis, linear blocks,
//!    cascades, continuous-time grey-box models), each able to simulate itself, and the
//!    saved-model file. No model imports an estimator.
//! 3. [`experiments`] — virtual experiments built from the models (the project's examples,
//!    the actuator rig).
//! 4. [`identify`] — the recipes: cascade pipeline and paper iteration, hysteresis alone,
//!    grey-box output error with multi-start, the three-step actuator procedure, rigid-body
//!    least squares, bootstrap, recursive least squares, residual analysis.
//! 5. [`report`] — the one report schema every command writes (`hysid.report/1`).
//! 6. [`export`] — a fitted model as C99, `no_std` Rust or an FMI Co-Simulation FMU.
//!
//! Results that do not converge are reported in the estimator's report, never hidden;
//! bad input is an [`Error`] with a one-line message.
//!
//! ## References
//! * J. Vörös, "Modeling and Identification of Discrete-Time Nonlinear Dynamic Cascade Systems
//!   with Input Hysteresis", Mathematical Problems in Engineering 2015, Article ID 393572.
//!   The copy this project holds lost its formulas; the equations used here are the
//!   reconstruction in `docs/models/coleman-hodgdon-cascade.md`, and the docs say where.
//! * J. Gunnar, E. Wernholt, G. Hovland, T. Brogårdh, "Nonlinear Grey-Box Identification of
//!   Linear Actuators Containing Hysteresis", ICRA 2006.

pub mod data;
pub mod error;
pub mod experiments;
pub mod export;
pub mod identify;
pub mod io;
pub mod model;
pub mod numerics;
pub mod report;
pub mod toolchain;

pub use error::{Error, Result};
