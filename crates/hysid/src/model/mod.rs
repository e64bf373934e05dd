//! Model structures.
//!
//! * [`ColemanHodgdon`]: discrete Coleman–Hodgdon hysteresis, piecewise-linear material
//!   functions, 4- and 6-parameter forms.
//! * [`LinearBlock`]: A(q⁻¹) y = B(q⁻¹) v with delay.
//! * [`HysteresisCascade`]: the two in series (Vörös 2015).

mod cascade;
pub mod coleman_hodgdon;
mod linear;
pub mod operators;

pub use cascade::{CascadeOutput, HysteresisCascade};
pub use coleman_hodgdon::{Admissibility, ChForm, ColemanHodgdon};
pub use linear::LinearBlock;
