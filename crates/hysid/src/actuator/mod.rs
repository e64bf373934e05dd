//! The linear actuator with hysteresis of Gunnar, Wernholt, Hovland & Brogårdh (2006):
//! steady-state loops, the virtual test rig and the three-step identification.
//!
//! * [`loops`]: the steady-state loop formula of step 2 (corrected).
//! * [`rig`]: the virtual test rig reproducing the paper's eight experiments.
//! * [`identify`]: the three steps.
//! * [`tables`]: the paper's Tables I–III regenerated, as Markdown and JSON.

pub mod identify;
pub mod loops;
pub mod rig;
pub mod tables;
