//! # hysid — identification of dynamic systems with hysteresis
//!
//! hysid identifies models of systems that contain hysteresis from measured input/output data:
//! a piezo stage, a harmonic drive, a lead-screw actuator, a magnetic core.
//!
//! * [`model`]: the model structures — the discrete Coleman–Hodgdon hysteresis with
//!   piecewise-linear material functions, linear blocks with delay, and their cascade
//!   (Vörös 2015).
//! * [`estimate`]: the estimators — linear least squares with covariance, the separated
//!   regression of the hysteresis, the iterative key-term-separation method of Vörös (2015),
//!   a global (α, d) grid stage, recursive least squares with forgetting, and a general
//!   output-error Levenberg–Marquardt engine with bounds, fixed parameters, several
//!   experiments and standard deviations.
//! * [`greybox`]: continuous-time grey-box models (Bouc–Wen oscillator, rigid body with
//!   friction), their integrators and their output-error estimation.
//! * [`actuator`]: the linear actuator of Gunnar et al. (2006): loops, virtual rig and the
//!   three-step identification.
//! * [`data`]: the [`data::IdData`] container and CSV input/output.
//! * [`signal`]: excitation signals and noise, all seeded.
//! * [`metrics`]: fit %, RMSE and information criteria.
//! * [`validate`]: residual analysis and the one-at-a-time sensitivity table.
//! * [`examples`]: the project's numerical examples (MODELS.md §1.6).
//! * [`fitted`]: fitted models and their JSON model files.
//!
//! Results that do not converge are reported in the estimator's report, never hidden;
//! bad input is an [`Error`] with a one-line message.
//!
//! ## References
//! * J. Vörös, "Modeling and Identification of Discrete-Time Nonlinear Dynamic Cascade Systems
//!   with Input Hysteresis", Mathematical Problems in Engineering 2015, Article ID 393572.
//!   The copy this project holds lost its formulas; the equations used here are the
//!   reconstruction documented in the project's `MODELS.md` §1, and the docs say where.
//! * J. Gunnar, E. Wernholt, G. Hovland, T. Brogårdh, "Nonlinear Grey-Box Identification of
//!   Linear Actuators Containing Hysteresis", ICRA 2006.

pub mod actuator;
pub mod data;
pub mod error;
pub mod estimate;
pub mod examples;
pub mod fitted;
pub mod greybox;
pub mod io;
pub mod metrics;
pub mod model;
pub mod signal;
pub mod validate;

pub use error::{Error, Result};
