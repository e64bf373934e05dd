//! Tests of `hysid::model::greybox`.

mod discrete;
mod equation_kernel;
mod equation_model;
mod models;
mod native;
mod sensitivity;
mod simulate;
mod stick_slip;
