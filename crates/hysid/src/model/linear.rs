//! Linear discrete-time block with delay, A(q⁻¹) y(t) = B(q⁻¹) v(t).
//!
//! # Equations
//!
//! ```text
//! A(q⁻¹) = 1 + a1 q⁻¹ + … + an q⁻ⁿ
//! B(q⁻¹) = q⁻ᵏ (b1 + b2 q⁻¹ + … + bm q⁻ᵐ⁺¹)
//! y(t) = −a1 y(t−1) − … − an y(t−n) + b1 v(t−k) + … + bm v(t−k−m+1)
//! ```
//!
//! | symbol | meaning | constraint |
//! | --- | --- | --- |
//! | a1…an | denominator coefficients | roots of A inside the unit circle for a stable block |
//! | b1…bm | numerator coefficients | b1 = 1 in the cascade (fixes the gain split) |
//! | k | input delay in samples | k ≥ 1 in the cascade (k = 0 allowed here) |
//!
//! Samples before t = 0 are zero (the block starts at rest).
//!
//! Reference: Vörös (2015), Section 3 (layout RECONSTRUCTED,
//! docs/models/coleman-hodgdon-cascade.md §6).

use crate::{Error, Result};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// A linear block A(q⁻¹) y = B(q⁻¹) v with an input delay.
///
/// ```
/// use hysid::model::LinearBlock;
/// // y(t) = 0.6 y(t−1) − 0.2 y(t−2) + v(t−1) + 0.5 v(t−2)
/// let lin = LinearBlock::new(vec![-0.6, 0.2], vec![1.0, 0.5], 1).unwrap();
/// let y = lin.simulate(&[1.0, 0.0, 0.0, 0.0]);
/// assert_eq!(y, vec![0.0, 1.0, 1.1, 0.46]);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinearBlock {
    a: Vec<f64>,
    b: Vec<f64>,
    delay: usize,
}

impl LinearBlock {
    /// A block with denominator coefficients `a` = [a1…an], numerator `b` = [b1…bm] and delay k.
    pub fn new(a: Vec<f64>, b: Vec<f64>, delay: usize) -> Result<Self> {
        if b.is_empty() {
            return Err(Error::InvalidModel(
                "the numerator B needs at least one coefficient (b1)".into(),
            ));
        }
        for (name, values) in [("a", &a), ("b", &b)] {
            if let Some((i, v)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(Error::InvalidParameter {
                    name: format!("{name}[{}]", i + 1),
                    value: *v,
                    reason: "must be finite".into(),
                });
            }
        }
        Ok(Self { a, b, delay })
    }

    /// [a1…an].
    pub fn a(&self) -> &[f64] {
        &self.a
    }
    /// [b1…bm].
    pub fn b(&self) -> &[f64] {
        &self.b
    }
    /// The delay k.
    pub fn delay(&self) -> usize {
        self.delay
    }
    /// n, the order of A.
    pub fn na(&self) -> usize {
        self.a.len()
    }
    /// m, the number of B coefficients.
    pub fn nb(&self) -> usize {
        self.b.len()
    }

    /// Simulates the block from rest: y(t) for t = 0…N−1.
    pub fn simulate(&self, v: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; v.len()];
        for t in 0..v.len() {
            y[t] = self.output_at(t, v, &y);
        }
        y
    }

    /// y(t) from the past outputs `y[..t]` and the inputs `v` (zero before t = 0).
    #[inline]
    pub fn output_at(&self, t: usize, v: &[f64], y: &[f64]) -> f64 {
        let mut acc = 0.0;
        for (i, &ai) in self.a.iter().enumerate() {
            if let Some(s) = t.checked_sub(i + 1) {
                acc -= ai * y[s];
            }
        }
        for (j, &bj) in self.b.iter().enumerate() {
            if let Some(s) = t.checked_sub(self.delay + j) {
                acc += bj * v[s];
            }
        }
        acc
    }

    /// The static gain B(1)/A(1) (infinite when A(1) = 0).
    pub fn static_gain(&self) -> f64 {
        self.b.iter().sum::<f64>() / (1.0 + self.a.iter().sum::<f64>())
    }

    /// The largest modulus of the poles (roots of zⁿ + a1 zⁿ⁻¹ + … + an); < 1 means stable.
    pub fn spectral_radius(&self) -> f64 {
        let n = self.a.len();
        if n == 0 {
            return 0.0;
        }
        // Companion matrix of the monic denominator polynomial.
        let mut c = DMatrix::<f64>::zeros(n, n);
        for (j, &aj) in self.a.iter().enumerate() {
            c[(0, j)] = -aj;
        }
        for i in 1..n {
            c[(i, i - 1)] = 1.0;
        }
        c.complex_eigenvalues()
            .iter()
            .map(|z| z.norm())
            .fold(0.0, f64::max)
    }

    /// True when every pole lies strictly inside the unit circle.
    pub fn is_stable(&self) -> bool {
        self.spectral_radius() < 1.0
    }
}
