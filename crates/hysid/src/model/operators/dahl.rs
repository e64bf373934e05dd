//! The Dahl friction operator (Dahl 1968; 1976): the friction force F as a function of the
//! displacement x,
//!
//! ```text
//! dF/dx = σ·(1 − (F/F_c)·sign(dx))^i,      i ≥ 1,   F(x[0]) = f0
//! ```
//!
//! with the rest stiffness σ > 0 and the Coulomb force F_c > 0; |F| approaches F_c on a long
//! monotone branch. For |f0| > F_c the base is negative and the power is taken as
//! sign(b)·|b|^i (Dahl's form), which drives |F| back towards F_c. The state is F itself,
//! integrated in x with error control ([`super::differential`]).
//!
//! **Orientation.** The Dahl loop is clockwise with a positive slope (the force rises steeply
//! after each reversal, then runs along ±F_c: an elasto-plastic loop). A counter-clockwise
//! loop is represented by driving the operator with −u
//! ([`LoopOrientation::CounterClockwise`]): the loop is mirrored, so its slope is negative.
//!
//! # References
//! * P. R. Dahl, "A solid friction model", The Aerospace Corporation, TOR-0158(3107-18)-1,
//!   1968.
//! * P. R. Dahl, "Solid friction damping of mechanical vibrations", AIAA J. 14 (1976)
//!   1675–1682.

use super::differential::{self, InputOde, InputOdeSensitivity, LoopOrientation};
use super::{HysteresisOperator, Inversion};
use crate::model::Parameter;
use crate::model::ParameterSet;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// A Dahl friction operator (module doc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Dahl {
    /// Rest stiffness σ > 0 (force per unit displacement).
    pub sigma: f64,
    /// Coulomb force F_c > 0.
    pub fc: f64,
    /// Shape exponent i ≥ 1.
    pub i: f64,
    /// The force at the first sample.
    pub f0: f64,
    /// Clockwise: the native loop; counter-clockwise: driven by −u.
    pub orientation: LoopOrientation,
}

impl Dahl {
    /// A validated operator in its native (clockwise) orientation with f0 = 0.
    pub fn new(sigma: f64, fc: f64, i: f64) -> Result<Self> {
        let model = Self {
            sigma,
            fc,
            i,
            f0: 0.0,
            orientation: LoopOrientation::Clockwise,
        };
        model.validate()?;
        Ok(model)
    }

    /// Checks σ, F_c > 0, i ≥ 1, all finite.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &str, value: f64, reason: &str| {
            Err(Error::InvalidParameter {
                name: name.into(),
                value,
                reason: reason.into(),
            })
        };
        for (name, v) in [("sigma", self.sigma), ("Fc", self.fc)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(name, v, "must be finite and > 0");
            }
        }
        if !(self.i.is_finite() && self.i >= 1.0) {
            return bad("i", self.i, "must be finite and >= 1");
        }
        if !self.f0.is_finite() {
            return bad("f0", self.f0, "must be finite");
        }
        Ok(())
    }
}

impl InputOde for Dahl {
    fn slope(&self, _u: f64, f: f64, direction: f64) -> f64 {
        // +1 in the native (clockwise) orientation, −1 when driven by −u.
        let s = -self.orientation.sign();
        let base = 1.0 - f / self.fc * s * direction;
        s * self.sigma * base.signum() * base.abs().powf(self.i)
    }
    fn output(&self, _u: f64, f: f64) -> f64 {
        f
    }
    fn initial_state(&self) -> f64 {
        self.f0
    }
    fn state_scale(&self) -> f64 {
        self.fc
    }
    fn max_substep(&self) -> f64 {
        0.25 * self.fc / self.sigma
    }
    fn inversion_span(&self) -> f64 {
        60.0 * self.fc / self.sigma
    }
}

/// θ = (σ, F_c, i, f0): with s = ±1 the orientation's sign, b = 1 − (F/F_c)·s·δ and
/// F' = s·σ·i·|b|ⁱ⁻¹: ∂F/∂F = −F'·s·δ/F_c, ∂F/∂σ = s·sign(b)·|b|ⁱ, ∂F/∂F_c = F'·F·s·δ/F_c²,
/// ∂F/∂i = s·σ·sign(b)·|b|ⁱ·ln|b|; the output is the state; ∂F(u\[0\])/∂f0 = 1.
impl InputOdeSensitivity for Dahl {
    fn n_parameters(&self) -> usize {
        4
    }
    fn slope_partials(&self, u: f64, f: f64, direction: f64, dtheta: &mut [f64]) -> (f64, f64) {
        let slope = self.slope(u, f, direction);
        let s = -self.orientation.sign();
        let sd = s * direction;
        let base = 1.0 - f / self.fc * sd;
        let ab = base.abs();
        let power = base.signum() * ab.powf(self.i);
        let db = s * self.sigma * self.i * ab.powf(self.i - 1.0);
        dtheta.copy_from_slice(&[
            s * power,
            db * f * sd / (self.fc * self.fc),
            if ab > 0.0 { slope * ab.ln() } else { 0.0 },
            0.0,
        ]);
        (slope, -db * sd / self.fc)
    }
    fn output_partials(&self, _u: f64, _f: f64, dtheta: &mut [f64]) -> f64 {
        dtheta.fill(0.0);
        1.0
    }
    fn initial_state_partials(&self, dtheta: &mut [f64]) {
        dtheta.copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
    }
}

super::streaming::differential_streaming!(Dahl);

impl HysteresisOperator for Dahl {
    fn family(&self) -> &'static str {
        <Self as super::OperatorFamily>::NAME
    }
    fn parameters(&self) -> ParameterSet {
        let inf = f64::INFINITY;
        let p = vec![
            Parameter::new("sigma", self.sigma).bounds(0.0, inf),
            Parameter::new("Fc", self.fc).bounds(0.0, inf),
            Parameter::new("i", self.i).bounds(1.0, inf),
            Parameter::new("f0", self.f0),
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

impl super::OperatorFamily for Dahl {
    const NAME: &'static str = "dahl";
    const TITLE: &'static str = "Dahl friction (Dahl 1968)";

    fn example() -> Result<Self> {
        Self::new(3.0, 1.0, 1.0)
    }

    fn checked(self) -> Result<Self> {
        self.validate()?;
        Ok(self)
    }

    fn with_values(&self, values: &[f64]) -> Result<Self> {
        let [sigma, fc, i, f0] = super::registry::values_array(self, values)?;
        let next = Self {
            sigma,
            fc,
            i,
            f0,
            ..self.clone()
        };
        next.validate()?;
        Ok(next)
    }

    /// The exponent i, held as the family's own fit holds it.
    fn held(&self) -> Vec<usize> {
        vec![2]
    }

    /// σ, F_c and f0.
    fn output_scale(&self) -> Option<Vec<usize>> {
        Some(vec![0, 1, 3])
    }
}
