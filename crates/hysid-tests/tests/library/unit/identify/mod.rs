//! Tests of `hysid::identify`.

mod actuator;
mod bootstrap;
mod bouc_wen_benchmark;
mod budget;
mod cascade;
mod cascade_pass;
mod global;
mod greybox;
mod grid_regression;
mod multistart;
mod operator_cascade;
mod operators;
mod output_error;
mod rigid_body;
mod rls;
mod switching;
mod validate;

use hysid::experiments::voros::CascadeExample;
use hysid::identify::cascade::CascadeStructure;

/// The output-error structure of an example's true cascade: its form and orders, the
/// switching following d.
fn true_structure(ex: &CascadeExample) -> CascadeStructure {
    let lin = &ex.truth.linear;
    CascadeStructure {
        form: ex.truth.hysteresis.form(),
        na: lin.na(),
        nb: lin.nb(),
        delay: lin.delay(),
        switching: None,
    }
}
