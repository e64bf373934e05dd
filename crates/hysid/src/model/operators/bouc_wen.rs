//! The static (rate-independent) Bouc–Wen operator (Bouc 1967; Wen 1976; in the normalised
//! form of Ismail, Ikhouane & Rodellar 2009):
//!
//! ```text
//! y  = k_x·u + k_w·w
//! dw = (A − (β·sign(du·w) + γ)·|w|ⁿ) du,      A = 1 (normalisation), w(u[0]) = w0
//! ```
//!
//! The internal state w is integrated in u with error control ([`super::differential`]), so
//! the operator is rate independent. With A = 1 the scale of w is fixed and k_w is
//! identifiable (Ikhouane & Rodellar 2007). w stays bounded, |w| ≤ (A/(β + γ))^{1/n}, when
//! β + γ > 0 and β − γ ≥ 0 (Ikhouane & Rodellar's bounded classes); the constructor asks for
//! exactly that, and n ≥ 1.
//!
//! **Orientation.** The loop of w against u is clockwise (w rises steeply after a reversal and
//! then runs along its bound: an elasto-plastic loop); k_w > 0 keeps that orientation for y,
//! k_w < 0 turns the loop counter-clockwise (y = k_x·u − |k_w|·w, the usual piezo form). The inverse then still exists wherever
//! dy/du = k_x + k_w·dw/du keeps its sign.
//!
//! # References
//! * M. Ismail, F. Ikhouane, J. Rodellar, "The hysteresis Bouc–Wen model, a survey", Arch.
//!   Comput. Methods Eng. 16 (2009) 161–188.
//! * F. Ikhouane, J. Rodellar, *Systems with Hysteresis: Analysis, Identification and Control
//!   Using the Bouc–Wen Model*, Wiley 2007.
//! * Y.-K. Wen, "Method for random vibration of hysteretic systems", J. Eng. Mech. Div. 102
//!   (1976) 249–263.

use super::differential::{self, InputOde, InputOdeSensitivity};
use super::{HysteresisOperator, Inversion};
use crate::model::Parameter;
use crate::model::ParameterSet;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// A static Bouc–Wen operator (module doc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoucWen {
    /// Linear (elastic) gain k_x.
    pub kx: f64,
    /// Gain of the hysteretic state k_w (its sign sets the loop orientation).
    pub kw: f64,
    /// A (1 in the normalised form).
    pub a: f64,
    /// β > 0.
    pub beta: f64,
    /// γ, −β < γ ≤ β.
    pub gamma: f64,
    /// Exponent n ≥ 1.
    pub n: f64,
    /// The state w at the first sample.
    pub w0: f64,
}

impl BoucWen {
    /// A validated operator with A = 1 and w0 = 0.
    pub fn new(kx: f64, kw: f64, beta: f64, gamma: f64, n: f64) -> Result<Self> {
        let model = Self {
            kx,
            kw,
            a: 1.0,
            beta,
            gamma,
            n,
            w0: 0.0,
        };
        model.validate()?;
        Ok(model)
    }

    /// Checks finiteness, A > 0, β > 0, −β < γ ≤ β, n ≥ 1.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &str, value: f64, reason: &str| {
            Err(Error::InvalidParameter {
                name: name.into(),
                value,
                reason: reason.into(),
            })
        };
        for (name, v) in [("kx", self.kx), ("kw", self.kw), ("w0", self.w0)] {
            if !v.is_finite() {
                return bad(name, v, "must be finite");
            }
        }
        if !(self.a.is_finite() && self.a > 0.0) {
            return bad("A", self.a, "must be finite and > 0");
        }
        if !(self.beta.is_finite() && self.beta > 0.0) {
            return bad("beta", self.beta, "must be finite and > 0");
        }
        if !(self.gamma.is_finite() && self.gamma > -self.beta && self.gamma <= self.beta) {
            return bad(
                "gamma",
                self.gamma,
                "must satisfy -beta < gamma <= beta (bounded Bouc-Wen classes)",
            );
        }
        if !(self.n.is_finite() && self.n >= 1.0) {
            return bad("n", self.n, "must be finite and >= 1");
        }
        Ok(())
    }

    /// |w|ⁿ; the common n = 1 without the power function (x¹ is x exactly).
    #[inline(always)]
    fn power(&self, aw: f64) -> f64 {
        if self.n == 1.0 {
            aw
        } else {
            aw.powf(self.n)
        }
    }

    /// The bound of |w|: (A/(β + γ))^{1/n}.
    pub fn w_max(&self) -> f64 {
        (self.a / (self.beta + self.gamma)).powf(1.0 / self.n)
    }
}

impl InputOde for BoucWen {
    fn slope(&self, _u: f64, w: f64, direction: f64) -> f64 {
        let s = if direction * w >= 0.0 { 1.0 } else { -1.0 };
        self.a - (self.beta * s + self.gamma) * self.power(w.abs())
    }
    fn output(&self, u: f64, w: f64) -> f64 {
        self.kx * u + self.kw * w
    }
    fn initial_state(&self) -> f64 {
        self.w0
    }
    fn state_scale(&self) -> f64 {
        self.w_max()
    }
    fn max_substep(&self) -> f64 {
        0.25 * self.w_max() / self.a
    }
    fn inversion_span(&self) -> f64 {
        1e6 * self.w_max() / self.a
    }
}

/// θ = (k_x, k_w, A, β, γ, n, w0): with s = sign(δ·w) and σ = β·s + γ,
/// ∂F/∂w = −σ·n·|w|ⁿ⁻¹·sign w, ∂F/∂A = 1, ∂F/∂β = −s·|w|ⁿ, ∂F/∂γ = −|w|ⁿ,
/// ∂F/∂n = −σ·|w|ⁿ·ln|w|; ∂y/∂w = k_w, ∂y/∂k_x = u, ∂y/∂k_w = w; ∂w(u\[0\])/∂w0 = 1.
impl InputOdeSensitivity for BoucWen {
    fn n_parameters(&self) -> usize {
        7
    }
    fn slope_partials(&self, u: f64, w: f64, direction: f64, dtheta: &mut [f64]) -> (f64, f64) {
        let f = self.slope(u, w, direction);
        let s = if direction * w >= 0.0 { 1.0 } else { -1.0 };
        let sigma = self.beta * s + self.gamma;
        let aw = w.abs();
        let wn = self.power(aw);
        let sign_w = if w >= 0.0 { 1.0 } else { -1.0 };
        let slope_w = if self.n == 1.0 {
            1.0
        } else {
            self.n * aw.powf(self.n - 1.0)
        };
        let fw = -sigma * slope_w * sign_w;
        dtheta.copy_from_slice(&[
            0.0,
            0.0,
            1.0,
            -s * wn,
            -wn,
            if aw > 0.0 { -sigma * wn * aw.ln() } else { 0.0 },
            0.0,
        ]);
        (f, fw)
    }
    fn output_partials(&self, u: f64, w: f64, dtheta: &mut [f64]) -> f64 {
        dtheta.copy_from_slice(&[u, w, 0.0, 0.0, 0.0, 0.0, 0.0]);
        self.kw
    }
    fn initial_state_partials(&self, dtheta: &mut [f64]) {
        dtheta.copy_from_slice(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
    }
}

super::streaming::differential_streaming!(BoucWen);

impl HysteresisOperator for BoucWen {
    fn family(&self) -> &'static str {
        <Self as super::OperatorFamily>::NAME
    }
    fn parameters(&self) -> ParameterSet {
        let inf = f64::INFINITY;
        let p = vec![
            Parameter::new("kx", self.kx),
            Parameter::new("kw", self.kw),
            Parameter::new("A", self.a).bounds(0.0, inf).fixed(true),
            Parameter::new("beta", self.beta).bounds(0.0, inf),
            Parameter::new("gamma", self.gamma),
            Parameter::new("n", self.n).bounds(1.0, inf),
            Parameter::new("w0", self.w0),
        ];
        ParameterSet::new(p).expect("distinct names")
    }
    fn simulate(&self, u: &[f64]) -> Result<Vec<f64>> {
        self.validate()?;
        differential::simulate(self, u)
    }
    fn invert(&self, reference: &[f64]) -> Result<Inversion> {
        self.validate()?;
        differential::invert(self, reference)
    }
    /// 100 of the family's longest sub-steps (its input scale): the state forgets its start
    /// over that distance.
    fn memory_reach(&self) -> f64 {
        100.0 * InputOde::max_substep(self)
    }
}

impl super::OperatorFamily for BoucWen {
    const NAME: &'static str = "bouc-wen";
    const TITLE: &'static str =
        "static Bouc–Wen operator (Wen 1976; Ismail, Ikhouane & Rodellar 2009)";

    fn example() -> Result<Self> {
        Self::new(0.5, 1.0, 1.5, 0.5, 1.0)
    }

    fn checked(self) -> Result<Self> {
        self.validate()?;
        Ok(self)
    }

    fn with_values(&self, values: &[f64]) -> Result<Self> {
        let [kx, kw, a, beta, gamma, n, w0] = super::registry::values_array(self, values)?;
        let next = Self {
            kx,
            kw,
            a,
            beta,
            gamma,
            n,
            w0,
        };
        next.validate()?;
        Ok(next)
    }

    /// The exponent n, held as the family's own fit holds it.
    fn held(&self) -> Vec<usize> {
        vec![5]
    }

    /// k_x and k_w.
    fn output_scale(&self) -> Option<Vec<usize>> {
        Some(vec![0, 1])
    }
}
