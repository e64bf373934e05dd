//! A static envelope term: a monotone polynomial E(u) added to a play operator's output, for
//! the static curve its plays cannot follow (the saturation of a magnet's yoke: a PI's
//! loading curve only steepens with the input, a saturating one flattens).
//!
//! **Form.** On the range [lo, hi] (the fitting record's), with w = hi − lo and
//! t = (u − lo)/w, the slope is a polynomial in Bernstein form with non-negative control
//! values c₀ … c_d (d + 1 = the envelope's degree):
//!
//! E′(u) = Σⱼ cⱼ B_{j,d}(t),  B_{j,d}(t) = C(d, j) tʲ (1 − t)^{d−j},
//!
//! so E′ ≥ 0 on the range (Bernstein polynomials are non-negative on [0, 1]) and E is
//! non-decreasing. Integrated (∫₀ᵗ B_{j,d} = (1/(d + 1)) Σ_{i>j} B_{i,d+1}(t)):
//!
//! E(u) = w Σ_{i=0}^{d+1} Pᵢ B_{i,d+1}(t),  P₀ = 0,  Pᵢ = (c₀ + … + c_{i−1})/(d + 1),
//!
//! E(lo) = 0 and E(hi) = w·P_{d+1}. Beyond the range E continues along its end tangents,
//! E(u) = c₀(u − lo) below lo and E(hi) + c_d(u − hi) above hi, so it is monotone for every
//! input (a compensator's references may leave the fitting range) and continuously
//! differentiable. E is linear in the cⱼ, so a fit adds d + 1 columns to the play regression
//! and keeps it a non-negative least-squares problem. The default degree is 3 (a cubic
//! envelope, d = 2: three slope values, low–middle–high).
//!
//! **Evaluation.** The Bernstein form is converted once to monomial coefficients
//! mₖ = w Σ_{i≤k} Pᵢ C(n, i) C(n − i, k − i) (−1)^{k−i} (n = d + 1) and E is evaluated by
//! Horner's rule in t, t = (u − lo)·(1/w); the exported code takes these same coefficients
//! and performs the same operations, so it gives the same bits. E(hi) is Horner's value at
//! t(hi) = (hi − lo)·(1/w) as computed (within an ulp of 1), so the pieces meet exactly.
//!
//! References: R. T. Farouki, "The Bernstein polynomial basis: a centennial retrospective",
//! Computer Aided Geometric Design 29 (2012) 379–419 (non-negativity of the basis). A static
//! polynomial beside the plays is the usual engineering complement of a PI for saturating
//! curves; Al Janaideh, Rakheja & Su (IEEE/ASME Trans. Mechatronics 16 (2011) 734–744) put
//! envelope functions on the plays instead, which loses the linear regression.

use super::elementary::check_finite;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// The envelope's degree in the default fit: a cubic (three slope values).
pub const CUBIC: usize = 3;

/// A monotone static envelope E(u) (see the module documentation), read back from a model
/// file through [`Envelope::new`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawEnvelope", into = "RawEnvelope")]
pub struct Envelope {
    lo: f64,
    hi: f64,
    slopes: Vec<f64>,
    /// 1/w.
    inverse_width: f64,
    /// m₀ … m_n, Horner's coefficients in t.
    monomial: Vec<f64>,
    /// E(hi), Horner's value at t = 1.
    top: f64,
}

/// The serde form of [`Envelope`]: its range and slope values, the rest derived.
#[derive(Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEnvelope {
    lo: f64,
    hi: f64,
    slopes: Vec<f64>,
}

impl TryFrom<RawEnvelope> for Envelope {
    type Error = Error;
    fn try_from(raw: RawEnvelope) -> Result<Self> {
        Self::new(raw.lo, raw.hi, raw.slopes)
    }
}

impl From<Envelope> for RawEnvelope {
    fn from(e: Envelope) -> Self {
        Self {
            lo: e.lo,
            hi: e.hi,
            slopes: e.slopes,
        }
    }
}

/// The binomial coefficient C(n, k) as a float (exact for the small n of an envelope).
fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

impl Envelope {
    /// The envelope of slope values c₀ … c_d ≥ 0 (at least two) on the range lo < hi.
    pub fn new(lo: f64, hi: f64, slopes: Vec<f64>) -> Result<Self> {
        check_finite("e_lo", lo)?;
        check_finite("e_hi", hi)?;
        let width = hi - lo;
        if !(width > 0.0 && width.is_finite() && (1.0 / width).is_finite()) {
            return Err(Error::InvalidParameter {
                name: "e_hi".into(),
                value: hi,
                reason: format!("the envelope's range must have e_hi > e_lo (e_lo = {lo})"),
            });
        }
        if slopes.len() < 2 {
            return Err(Error::InvalidModel(format!(
                "an envelope needs at least 2 slope values, got {}",
                slopes.len()
            )));
        }
        for (j, &c) in slopes.iter().enumerate() {
            check_finite(&format!("e{j}"), c)?;
            if c < 0.0 {
                return Err(Error::InvalidParameter {
                    name: format!("e{j}"),
                    value: c,
                    reason: "an envelope's slope values must be >= 0 (a monotone envelope)".into(),
                });
            }
        }
        Ok(Self::build(lo, hi, slopes))
    }

    /// The envelope of checked values (a range lo < hi, slopes finite and ≥ 0).
    fn build(lo: f64, hi: f64, slopes: Vec<f64>) -> Self {
        let width = hi - lo;
        let n = slopes.len();
        // Pᵢ = (c₀ + … + c_{i−1})/n, P₀ = 0
        let mut control = vec![0.0; n + 1];
        for i in 1..=n {
            control[i] = control[i - 1] + slopes[i - 1] / n as f64;
        }
        let monomial: Vec<f64> = (0..=n)
            .map(|k| {
                let sum: f64 = (0..=k)
                    .map(|i| {
                        let sign = if (k - i) % 2 == 0 { 1.0 } else { -1.0 };
                        control[i] * binomial(n, i) * binomial(n - i, k - i) * sign
                    })
                    .sum();
                width * sum
            })
            .collect();
        let mut e = Self {
            lo,
            hi,
            slopes,
            inverse_width: 1.0 / width,
            monomial,
            top: 0.0,
        };
        // Horner's value at t(hi) as `value` computes it (not always exactly 1): the pieces
        // meet exactly
        e.top = e.horner((hi - lo) * e.inverse_width);
        e
    }

    /// The envelope on the range of `x` with zero slopes, the start of a fit (None for a
    /// record of one input value).
    pub fn over(x: &[f64], degree: usize) -> Option<Self> {
        let lo = x.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Self::new(lo, hi, vec![0.0; degree]).ok()
    }

    /// The same range with the slope values `slopes`.
    pub fn with_slopes(&self, slopes: Vec<f64>) -> Result<Self> {
        Self::new(self.lo, self.hi, slopes)
    }

    /// The lower end of the range.
    pub fn lo(&self) -> f64 {
        self.lo
    }
    /// The upper end of the range.
    pub fn hi(&self) -> f64 {
        self.hi
    }
    /// The slope values c₀ … c_d.
    pub fn slopes(&self) -> &[f64] {
        &self.slopes
    }
    /// 1/(hi − lo), as the evaluation uses it.
    pub fn inverse_width(&self) -> f64 {
        self.inverse_width
    }
    /// Horner's coefficients m₀ … m_n in t (lowest first).
    pub fn monomial(&self) -> &[f64] {
        &self.monomial
    }
    /// E(hi).
    pub fn top(&self) -> f64 {
        self.top
    }
    /// E′ below the range (c₀) and above it (c_d).
    pub fn end_slopes(&self) -> (f64, f64) {
        (self.slopes[0], self.slopes[self.slopes.len() - 1])
    }

    /// Σ mₖ tᵏ by Horner's rule: p = m_n, then p = p·t + mₖ for k = n − 1 … 0.
    fn horner(&self, t: f64) -> f64 {
        let (last, rest) = self
            .monomial
            .split_last()
            .expect("an envelope has at least three coefficients");
        rest.iter().rev().fold(*last, |p, &m| p * t + m)
    }

    /// E(u).
    pub fn value(&self, u: f64) -> f64 {
        if u < self.lo {
            self.slopes[0] * (u - self.lo)
        } else if u > self.hi {
            self.top + self.slopes[self.slopes.len() - 1] * (u - self.hi)
        } else {
            self.horner((u - self.lo) * self.inverse_width)
        }
    }

    /// The columns of a fit: E(x) for each unit slope vector, one column per slope value.
    pub fn columns(&self, x: &[f64]) -> Vec<Vec<f64>> {
        (0..self.slopes.len())
            .map(|j| {
                let mut unit = vec![0.0; self.slopes.len()];
                unit[j] = 1.0;
                let basis = Self::build(self.lo, self.hi, unit);
                x.iter().map(|&v| basis.value(v)).collect()
            })
            .collect()
    }
}
