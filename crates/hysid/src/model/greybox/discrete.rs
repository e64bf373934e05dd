//! Discrete-time state-space models: simulation by the recursion and exact forward
//! sensitivities by its chain rule.
//!
//! A model whose [`StateSpaceModel::discrete_time`] is true gives, through
//! [`StateSpaceModel::rhs`], the next state instead of a derivative:
//!
//! ```text
//! x[k+1] = f(t_k, x[k], u[k], θ),     y[k] = h(x[k], u[k], θ),     t_k = k·ts
//! ```
//!
//! with x\[0\] the initial state and u\[k\] the k-th input sample (no interpolation: the
//! integrator and the interpolation of a [`super::Simulation`] do not apply). Differentiating
//! the recursion gives the sensitivities S\[k\] = ∂x\[k\]/∂p to q quantities p (parameters
//! θ\[params\] first, then initial states):
//!
//! ```text
//! S[k+1] = f_x(k)·S[k] + [f_θ(k)[params], 0],     S[0] = [0, E]
//! ```
//!
//! (E the unit columns of the estimated initial states), the exact derivative of the
//! simulated outputs, as the forward sensitivity equations are for a continuous-time model
//! (L. Ljung, *System Identification: Theory for the User*, 2nd ed., 1999, §10.3, the
//! gradient of the output-error criterion of a nonlinear state-space model). It is the same
//! product as the continuous right-hand side Ṡ = f_x·S + f_θ, so it is evaluated by
//! [`StateSpaceModel::rhs_sensitivities`].

use super::simulate::InputTrack;
use super::{JacobianScratch, StateSpaceModel};
use crate::{Error, Result};
use std::ops::ControlFlow;

fn diverged(k: usize) -> Error {
    Error::Diverged {
        index: k,
        reason: "the state is not finite".into(),
    }
}

/// Runs the recursion of a discrete-time `model` over the samples of `input` from `x0`,
/// calling `on_sample(k, x[k])` at every sample; [`Error::Diverged`] at the first sample
/// whose state is not finite.
pub(crate) fn simulate(
    model: &dyn StateSpaceModel,
    theta: &[f64],
    x0: &[f64],
    input: &InputTrack,
    ts: f64,
    mut on_sample: impl FnMut(usize, &[f64]),
) -> Result<()> {
    let n_samples = input.len();
    let mut u = vec![0.0; input.n_channels()];
    let (mut x, mut next) = (x0.to_vec(), vec![0.0; x0.len()]);
    for k in 0..n_samples {
        if x.iter().any(|v| !v.is_finite()) {
            return Err(diverged(k));
        }
        on_sample(k, &x);
        if k + 1 < n_samples {
            input.at(k, 0.0, &mut u);
            model.rhs(k as f64 * ts, &x, &u, theta, &mut next);
            std::mem::swap(&mut x, &mut next);
        }
    }
    Ok(())
}

/// The recursion with its sensitivities (see the module docs) for the parameters `params`
/// (indices into θ) and the initial states `initial` (indices into x); calls
/// `on_sample(k, x[k], S[k])` with S row-major n × q (`Break` ends the recursion there).
/// Ok(false) without simulating when the model has no analytic Jacobians.
#[allow(clippy::too_many_arguments)]
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn simulate_sensitivities(
    model: &dyn StateSpaceModel,
    theta: &[f64],
    x0: &[f64],
    input: &InputTrack,
    ts: f64,
    params: &[usize],
    initial: &[usize],
    mut on_sample: impl FnMut(usize, &[f64], &[f64]) -> ControlFlow<()>,
) -> Result<bool> {
    let (n, n_samples) = (x0.len(), input.len());
    let q = params.len() + initial.len();
    let mut scratch = JacobianScratch::new(n, theta.len());
    let mut u = vec![0.0; input.n_channels()];
    let (mut x, mut x_next) = (x0.to_vec(), vec![0.0; n]);
    let (mut s, mut s_next) = (vec![0.0; n * q], vec![0.0; n * q]);
    for (c, &i) in initial.iter().enumerate() {
        s[i * q + params.len() + c] = 1.0;
    }
    for k in 0..n_samples {
        if x.iter().chain(&s).any(|v| !v.is_finite()) {
            return Err(diverged(k));
        }
        if k + 1 == n_samples {
            let _ = on_sample(k, &x, &s);
            break;
        }
        input.at(k, 0.0, &mut u);
        // The product f_x·S + f_θ of the continuous right-hand side is S[k+1] here; it is
        // formed before sample k is reported, so that a model without Jacobians reports none.
        if !model.rhs_sensitivities(
            k as f64 * ts,
            &x,
            &u,
            theta,
            None,
            params,
            &s,
            &mut scratch,
            &mut x_next,
            &mut s_next,
        ) {
            return Ok(false);
        }
        if on_sample(k, &x, &s).is_break() {
            break;
        }
        std::mem::swap(&mut x, &mut x_next);
        std::mem::swap(&mut s, &mut s_next);
    }
    Ok(true)
}
