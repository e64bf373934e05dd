//! placeholder
pub mod ast;
mod dag;
mod error;
mod file;
mod lower;
mod model;
mod num;
mod tape;

pub use error::EquationError;
pub use model::{EquationModel, InitialSpec, ParameterSpec, Scratch, TimeDomain};
