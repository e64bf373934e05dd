//! Virtual experiments: data generators built from the models, used by the demos, the
//! tests and the benchmarks.
//!
//! * [`voros`]: the project's Example 1 and Example 2 of the Coleman–Hodgdon cascade
//!   (excitation, truth, noise at an SNR).
//! * [`actuator_rig`]: the virtual test rig of the linear actuator of Gunnar et al. (2006):
//!   the paper's eight experiments under PI/PID control, noise, optional backlash.

pub mod actuator_rig;
pub mod voros;
