//! The identification recipes: each takes validated data ([`crate::data::IdData`]) and a
//! settings struct, and returns a typed result. Non-convergence is a
//! [`Termination`](crate::numerics::Termination) in the result, not an error.
//!
//! * [`output_error`]: output-error estimation over several experiments for any
//!   [`OutputErrorModel`] (the generic layer over the Levenberg–Marquardt engine).
//! * [`multistart`]: several starts inside the bounds, fitted in parallel, the best kept.
//! * [`bootstrap`]: parametric bootstrap standard deviations where the curvature misleads.
//! * [`budget`]: memory and work estimates of the recipes, made before large allocations.
//! * [`hysteresis`]: the Coleman–Hodgdon hysteresis alone, from measured input and output.
//! * [`key_term`]: the iterative key-term-separation method of Vörös (2015) for the cascade.
//! * [`global`]: the (α, d) grid stage that makes the cascade fit independent of the start.
//! * [`switching`]: the switching function h as an internal variable of output-error fits.
//! * [`cascade`]: the whole cascade pipeline (global stage, paper iteration, output error).
//! * [`rls`]: recursive least squares with forgetting for online identification.
//! * [`rigid_body`]: rigid-body inverse-dynamics least squares with friction (IDIM, EMPS,
//!   step 1 of Gunnar et al. 2006).
//! * [`greybox`]: output-error estimation of continuous-time grey-box models with
//!   multi-start (MATLAB's `nlgreyest`).
//! * [`actuator`]: the three-step identification of Gunnar et al. (2006).
//! * [`bouc_wen_benchmark`]: the hysteretic benchmark of Noël & Schoukens (2016): fit, e_RMS
//!   scores and test-record generation.
//! * [`operators`]: identification of the hysteresis operator families from the data alone.
//! * [`operator_cascade`]: any operator family followed by a linear block (global start,
//!   output error).
//! * [`validate`]: residual analysis and the one-at-a-time sensitivity table.

pub mod actuator;
pub mod bootstrap;
pub mod bouc_wen_benchmark;
pub mod budget;
pub mod cascade;
pub mod cascade_pass;
pub mod global;
pub mod greybox;
pub mod grid_regression;
pub mod hysteresis;
pub mod key_term;
pub mod multistart;
pub mod operator_cascade;
pub mod operators;
pub mod output_error;
pub mod rigid_body;
pub mod rls;
pub mod switching;
pub mod validate;

pub use output_error::{OutputError, OutputErrorFit, OutputErrorModel};

use serde::Serialize;

/// How the standard deviations of an estimate are obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Uncertainty {
    /// σ²(JᵀJ)⁻¹ from the curvature at the estimate (fast; MATLAB's).
    Asymptotic,
    /// Parametric bootstrap with this many replicates, each identified again from scratch
    /// ([`bootstrap`]): right when the criterion has several nearly equal minima.
    Bootstrap(usize),
}
