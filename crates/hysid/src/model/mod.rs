//! Every model hysid identifies, each able to simulate itself. No model imports an
//! estimator: the identify layer sits above this one.
//!
//! * [`Parameter`], [`ParameterSet`]: named parameters with value, unit, bounds and a fixed
//!   flag (MATLAB's `idnlgrey` vocabulary).
//! * [`ColemanHodgdon`]: discrete Coleman–Hodgdon hysteresis, piecewise-linear material
//!   functions, 4- and 6-parameter forms.
//! * [`LinearBlock`]: A(q⁻¹) y = B(q⁻¹) v with delay.
//! * [`HysteresisCascade`]: the two in series (Vörös 2015).
//! * [`OperatorCascade`]: any operator family of [`operators`] followed by a linear block.
//! * [`greybox`]: continuous-time state-space models ([`greybox::StateSpaceModel`]), the
//!   built-in ones (Bouc–Wen oscillator, rigid body, the actuator of Gunnar et al. 2006),
//!   their integrators and forward sensitivities.
//! * [`record_filters`]: the processing a fit applied to its records (pre-filter,
//!   inverse-dynamics preprocessing), saved with the model.
//! * [`saved`]: fitted models and the saved-model file; [`kinds`]: the registry of its kinds,
//!   one module per kind.
//! * [`stream`]: every model one sample at a time ([`stream::Stepper`], [`stream::Compensator`]).

mod cascade;
pub mod coleman_hodgdon;
pub mod compensate;
pub mod greybox;
pub mod kinds;
pub mod limits;
mod linear;
pub mod operator_cascade;
pub mod operators;
mod parameters;
pub mod record_filters;
pub mod saved;
pub mod stream;

pub use cascade::{CascadeOutput, HysteresisCascade};
pub use coleman_hodgdon::{Admissibility, ChForm, ColemanHodgdon};
pub use linear::LinearBlock;
pub use operator_cascade::{CascadeCompensation, OperatorCascade};
pub use operators::OperatorModel;
pub use parameters::{Parameter, ParameterSet};
