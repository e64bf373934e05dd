//! Time integration of ordinary differential equations ẋ = f(t, x) that knows nothing of
//! models.
//!
//! * [`rk4`]: the classical fourth-order Runge–Kutta step, the one implementation that plain
//!   simulation, simulation with forward sensitivities, stick–slip steps and closed-loop rigs
//!   share.

pub mod rk4;

pub use rk4::{Rk4, Stage};
