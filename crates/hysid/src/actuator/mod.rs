//! The linear actuator with hysteresis of Gunnar, Wernholt, Hovland & Brogårdh (2006):
//! steady-state loops, the virtual test rig and the three-step identification.
//!
//! * [`loops`]: the steady-state loop formula of step 2 (corrected).
//! * [`rig`]: the virtual test rig reproducing the paper's eight experiments.
//! * [`identify`]: the three steps and the paper's tables.

pub mod identify;
pub mod loops;
pub mod rig;
