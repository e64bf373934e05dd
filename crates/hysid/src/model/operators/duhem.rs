//! The generalised Duhem operator in the form of Coleman & Hodgdon (1986):
//!
//! ```text
//! dy = α·|du|·(f(u) − y) + g(u)·du,      f(u) = a·u + b,   g(u) = c,      y(u[0]) = y0
//! ```
//!
//! with the material functions chosen linear (f) and constant (g), the classical choice for a
//! linear-plus-hysteresis material. Along a monotone branch the output approaches the line
//! f(u) + δ·(c − a)/α (δ = sign du) at the rate α per unit of input: the ascending and the
//! descending branches settle (c − a)/α apart. The state is the output itself; it is integrated
//! in u with error control ([`super::differential`]).
//!
//! **Orientation.** c < a gives a counter-clockwise loop (ascending branch below), c > a a
//! clockwise one: both orientations are the same model, no sign flip is needed, and the
//! inverse exists wherever dy/du keeps its sign.
//!
//! # References
//! * B. D. Coleman, M. L. Hodgdon, "A constitutive relation for rate-independent hysteresis in
//!   ferromagnetically soft materials", Int. J. Eng. Sci. 24 (1986) 897–919.
//! * A. Visintin, *Differential Models of Hysteresis*, Springer 1994, ch. V (Duhem models).

use super::differential::{self, InputOde, InputOdeSensitivity};
use super::{HysteresisOperator, Inversion};
use crate::model::Parameter;
use crate::model::ParameterSet;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// A Duhem / Coleman–Hodgdon operator with f(u) = a·u + b, g(u) = c (module doc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Duhem {
    /// Rate α > 0 at which a branch approaches f (per unit of input).
    pub alpha: f64,
    /// Slope a of f.
    pub a: f64,
    /// Offset b of f.
    pub b: f64,
    /// The constant g = c.
    pub c: f64,
    /// The output at the first sample.
    pub y0: f64,
}

impl Duhem {
    /// A validated operator with y0 = 0.
    pub fn new(alpha: f64, a: f64, b: f64, c: f64) -> Result<Self> {
        let model = Self {
            alpha,
            a,
            b,
            c,
            y0: 0.0,
        };
        model.validate()?;
        Ok(model)
    }

    /// Checks finiteness and α > 0.
    pub fn validate(&self) -> Result<()> {
        if !(self.alpha.is_finite() && self.alpha > 0.0) {
            return Err(Error::InvalidParameter {
                name: "alpha".into(),
                value: self.alpha,
                reason: "must be finite and > 0".into(),
            });
        }
        for (name, v) in [("a", self.a), ("b", self.b), ("c", self.c), ("y0", self.y0)] {
            if !v.is_finite() {
                return Err(Error::InvalidParameter {
                    name: name.into(),
                    value: v,
                    reason: "must be finite".into(),
                });
            }
        }
        Ok(())
    }
}

impl InputOde for Duhem {
    fn slope(&self, u: f64, y: f64, direction: f64) -> f64 {
        self.alpha * direction * (self.a * u + self.b - y) + self.c
    }
    fn output(&self, _u: f64, y: f64) -> f64 {
        y
    }
    fn initial_state(&self) -> f64 {
        self.y0
    }
    fn state_scale(&self) -> f64 {
        self.b.abs() + self.y0.abs() + (self.a.abs() + self.c.abs()) / self.alpha + 1e-300
    }
    fn max_substep(&self) -> f64 {
        0.25 / self.alpha
    }
    fn inversion_span(&self) -> f64 {
        1e6 / self.alpha
    }
    fn anchor_input(&self) -> f64 {
        // The centre of the band: f(u) = y0.
        if self.a != 0.0 {
            (self.y0 - self.b) / self.a
        } else {
            0.0
        }
    }
}

/// θ = (α, a, b, c, y0): ∂F/∂y = −α·δ, ∂F/∂α = δ·(a·u + b − y), ∂F/∂a = α·δ·u,
/// ∂F/∂b = α·δ, ∂F/∂c = 1; the output is the state; ∂y(u\[0\])/∂y0 = 1.
impl InputOdeSensitivity for Duhem {
    fn n_parameters(&self) -> usize {
        5
    }
    fn slope_partials(&self, u: f64, y: f64, direction: f64, dtheta: &mut [f64]) -> (f64, f64) {
        let f = self.slope(u, y, direction);
        let ad = self.alpha * direction;
        dtheta.copy_from_slice(&[direction * (self.a * u + self.b - y), ad * u, ad, 1.0, 0.0]);
        (f, -ad)
    }
    fn output_partials(&self, _u: f64, _y: f64, dtheta: &mut [f64]) -> f64 {
        dtheta.fill(0.0);
        1.0
    }
    fn initial_state_partials(&self, dtheta: &mut [f64]) {
        dtheta.copy_from_slice(&[0.0, 0.0, 0.0, 0.0, 1.0]);
    }
}

super::streaming::differential_streaming!(Duhem);

impl HysteresisOperator for Duhem {
    fn family(&self) -> &'static str {
        <Self as super::OperatorFamily>::NAME
    }
    fn parameters(&self) -> ParameterSet {
        let p = vec![
            Parameter::new("alpha", self.alpha).bounds(0.0, f64::INFINITY),
            Parameter::new("a", self.a),
            Parameter::new("b", self.b),
            Parameter::new("c", self.c),
            Parameter::new("y0", self.y0),
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

impl super::OperatorFamily for Duhem {
    const NAME: &'static str = "duhem";
    const TITLE: &'static str =
        "generalised Duhem / Coleman–Hodgdon operator (Coleman & Hodgdon 1986)";

    fn example() -> Result<Self> {
        Self::new(2.0, 0.5, 0.1, 1.0)
    }

    fn checked(self) -> Result<Self> {
        self.validate()?;
        Ok(self)
    }

    fn with_values(&self, values: &[f64]) -> Result<Self> {
        let [alpha, a, b, c, y0] = super::registry::values_array(self, values)?;
        let next = Self { alpha, a, b, c, y0 };
        next.validate()?;
        Ok(next)
    }

    /// a, b, c and y0 (α sets the loop's shape).
    fn output_scale(&self) -> Option<Vec<usize>> {
        Some(vec![1, 2, 3, 4])
    }
}
