//! Tests of `hysid::identify`.

mod actuator;
mod bootstrap;
mod bouc_wen_benchmark;
mod budget;
mod cascade;
mod cascade_pass;
mod global;
mod grid_regression;
mod multistart;
mod operator_cascade;
mod operators;
mod output_error;
mod rigid_body;
mod rls;
mod switching;
mod validate;
