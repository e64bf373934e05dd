//! Coleman–Hodgdon hysteresis followed by a linear dynamic block (Vörös 2015).
//!
//! # Equations
//!
//! ```text
//! v(t) = v(t−1) + α|Δx(t)|[f(x(t)) − v(t−1)] + g(x(t))Δx(t)     (hysteresis, not measured)
//! A(q⁻¹) y(t) = B(q⁻¹) v(t) + e(t),   B = q⁻ᵏ(1 + b2 q⁻¹ + … + bm q⁻ᵐ⁺¹)
//! ```
//!
//! b1 = 1 fixes the split of the static gain between the two blocks (SEED); without it only
//! the product of the gains would be identifiable. The hysteresis starts from v(0) = 0 and the
//! linear block from rest.
//!
//! Parameter vector used by the estimators, [`HysteresisCascade::params`]:
//! `[hysteresis parameters (ChForm order), b2 … bm, a1 … an]`.
//!
//! Reference: Vörös (2015), Section 3; layout RECONSTRUCTED
//! (docs/models/coleman-hodgdon-cascade.md §6).

use super::{ChForm, ColemanHodgdon, LinearBlock};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// The cascade of a Coleman–Hodgdon hysteresis and a linear block with b1 = 1 and delay k ≥ 1.
///
/// ```
/// use hysid::model::{ColemanHodgdon, HysteresisCascade, LinearBlock};
/// let ch = ColemanHodgdon::saturated(0.3, 1.0, 0.5, 3.0).unwrap();
/// let lin = LinearBlock::new(vec![-0.6, 0.2], vec![1.0, 0.5], 1).unwrap();
/// let cascade = HysteresisCascade::new(ch, lin).unwrap();
/// let out = cascade.simulate(&[0.0, 0.5, 1.0, 1.5]).unwrap();
/// assert_eq!(out.y[0], 0.0);
/// assert_eq!(out.y[2], out.v[1]); // y(2) = 0.6·y(1) + v(1) + 0.5·v(0), y(1) = v(0) = 0
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HysteresisCascade {
    /// The input hysteresis.
    pub hysteresis: ColemanHodgdon,
    /// The linear block.
    pub linear: LinearBlock,
}

/// Signals of a cascade simulation.
#[derive(Clone, Debug, PartialEq)]
pub struct CascadeOutput {
    /// The internal hysteresis output v(t).
    pub v: Vec<f64>,
    /// The cascade output y(t).
    pub y: Vec<f64>,
}

impl HysteresisCascade {
    /// Builds a cascade; b1 must be 1 and the delay at least 1.
    pub fn new(hysteresis: ColemanHodgdon, linear: LinearBlock) -> Result<Self> {
        if (linear.b()[0] - 1.0).abs() > 1e-12 {
            return Err(Error::InvalidModel(format!(
                "the cascade fixes b1 = 1 (it splits the gain between the blocks), got b1 = {}",
                linear.b()[0]
            )));
        }
        if linear.delay() < 1 {
            return Err(Error::InvalidModel(
                "the cascade needs a delay k >= 1 (key-term separation isolates v(t-k))".into(),
            ));
        }
        Ok(Self { hysteresis, linear })
    }

    /// Parameter names in [`params`](Self::params) order, e.g.
    /// `alpha, m1, c1, d, b2, a1, a2` for ch4 with m = 2, n = 2.
    pub fn parameter_names(form: ChForm, na: usize, nb: usize) -> Vec<String> {
        let mut names: Vec<String> = form
            .parameter_names()
            .iter()
            .map(|s| s.to_string())
            .collect();
        names.extend((2..=nb).map(|j| format!("b{j}")));
        names.extend((1..=na).map(|i| format!("a{i}")));
        names
    }

    /// The estimator parameter vector `[hysteresis, b2…bm, a1…an]`.
    pub fn params(&self) -> Vec<f64> {
        let mut p = self.hysteresis.params();
        p.extend_from_slice(&self.linear.b()[1..]);
        p.extend_from_slice(self.linear.a());
        p
    }

    /// Rebuilds a cascade from a parameter vector in [`params`](Self::params) order.
    pub fn from_params(
        form: ChForm,
        na: usize,
        nb: usize,
        delay: usize,
        p: &[f64],
    ) -> Result<Self> {
        let nh = form.n_params();
        let expected = nh + nb.saturating_sub(1) + na;
        if p.len() != expected || nb == 0 {
            return Err(Error::InvalidModel(format!(
                "a {} cascade with na = {na}, nb = {nb} has {expected} parameters, got {}",
                form.short_name(),
                p.len()
            )));
        }
        let hysteresis = ColemanHodgdon::from_params(form, &p[..nh])?;
        let mut b = vec![1.0];
        b.extend_from_slice(&p[nh..nh + nb - 1]);
        let a = p[nh + nb - 1..].to_vec();
        Self::new(hysteresis, LinearBlock::new(a, b, delay)?)
    }

    /// Simulates the cascade from rest; errors when α·|Δx| > 1 somewhere.
    pub fn simulate(&self, x: &[f64]) -> Result<CascadeOutput> {
        self.hysteresis.check_rate(x)?;
        Ok(self.simulate_unchecked(x))
    }

    /// [`simulate`](Self::simulate) without the rate check.
    pub fn simulate_unchecked(&self, x: &[f64]) -> CascadeOutput {
        let v = self.hysteresis.simulate_unchecked(x, 0.0);
        let y = self.linear.simulate(&v);
        CascadeOutput { v, y }
    }
}
