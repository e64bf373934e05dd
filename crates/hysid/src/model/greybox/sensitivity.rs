//! The right-hand side of the forward sensitivity equations of a state-space model.
//!
//! For ẋ = f(t, x, u, θ) and the sensitivities S = ∂x/∂p to q quantities p (parameters
//! θ\[params\] first, then initial states),
//!
//! ```text
//! Ṡ = (∂f/∂x)·S + ∂f/∂p,      ∂f/∂p = [∂f/∂θ[params], 0]
//! ```
//!
//! with S(t₀) = [0, E] (E the unit columns of the estimated initial states). Integrated by
//! the same RK4 stages as the states, this gives the exact derivative of the discrete
//! simulation (Hairer, Nørsett & Wanner, *Solving Ordinary Differential Equations I*,
//! 2nd ed., §I.14; Ljung, *System Identification*, 2nd ed., §10.3 for its use in
//! output-error estimation).
//!
//! [`default_rhs_sensitivities`] evaluates it from a model's analytic Jacobians; a model may
//! fuse the two in [`StateSpaceModel::rhs_sensitivities`] to skip known zeros.

use super::StateSpaceModel;

/// Scratch space for ∂f/∂x (n × n) and ∂f/∂θ (n × p) of the default sensitivity right-hand
/// side, allocated once per simulation; also the registers of models evaluated from an
/// instruction tape (equation files), so that they need no per-thread look-up per stage.
#[derive(Clone, Debug, Default)]
pub struct JacobianScratch {
    fx: Vec<f64>,
    ftheta: Vec<f64>,
    tape: hysid_equations::Scratch,
}

impl JacobianScratch {
    /// Buffers for `n` states and `p` parameters.
    pub fn new(n: usize, p: usize) -> Self {
        Self {
            fx: vec![0.0; n * n],
            ftheta: vec![0.0; n * p],
            tape: hysid_equations::Scratch::new(),
        }
    }

    /// ∂f/∂x sized n × n, ∂f/∂θ sized n × p (contents unspecified) and the tape registers,
    /// for a model's own fused [`StateSpaceModel::rhs_sensitivities`].
    pub(crate) fn split(
        &mut self,
        n: usize,
        p: usize,
    ) -> (&mut [f64], &mut [f64], &mut hysid_equations::Scratch) {
        self.fx.resize(n * n, 0.0);
        self.ftheta.resize(n * p, 0.0);
        (&mut self.fx, &mut self.ftheta, &mut self.tape)
    }
}

/// ẋ and Ṡ (see the module docs) from `model`'s [`rhs`](StateSpaceModel::rhs) and
/// [`rhs_jacobians`](StateSpaceModel::rhs_jacobians) (their `_sliding` forms when `held` is
/// Some). `s` and `ds` are n × q row-major, q = `s.len()` / n. Returns false when the model
/// has no analytic Jacobians.
#[allow(clippy::too_many_arguments)]
pub fn default_rhs_sensitivities<M: StateSpaceModel + ?Sized>(
    model: &M,
    t: f64,
    x: &[f64],
    u: &[f64],
    theta: &[f64],
    held: Option<f64>,
    params: &[usize],
    s: &[f64],
    scratch: &mut JacobianScratch,
    dx: &mut [f64],
    ds: &mut [f64],
) -> bool {
    let (n, p) = (x.len(), theta.len());
    scratch.fx.resize(n * n, 0.0);
    scratch.ftheta.resize(n * p, 0.0);
    let (fx, ft) = (&mut scratch.fx, &mut scratch.ftheta);
    let provided = match held {
        Some(d) => {
            model.rhs_sliding(t, x, u, theta, d, dx);
            model.rhs_jacobians_sliding(t, x, u, theta, d, fx, ft)
        }
        None => {
            model.rhs(t, x, u, theta, dx);
            model.rhs_jacobians(t, x, u, theta, fx, ft)
        }
    };
    if !provided {
        return false;
    }
    let q = s.len() / n.max(1);
    for r in 0..n {
        for c in 0..q {
            let mut acc = if c < params.len() {
                ft[r * p + params[c]]
            } else {
                0.0
            };
            for j in 0..n {
                acc += fx[r * n + j] * s[j * q + c];
            }
            ds[r * q + c] = acc;
        }
    }
    true
}
