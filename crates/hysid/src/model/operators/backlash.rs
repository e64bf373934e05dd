//! Backlash: the play operator with gain and offset.
//!
//! G[u]ₖ = c + g·zₖ, zₖ = max(uₖ − r, min(uₖ + r, zₖ₋₁)), z₋₁ = 0, so
//! z₀ = max(u₀ − r, min(u₀ + r, 0)) (Krasnosel'skii & Pokrovskii 1989); g > 0 is the gain and
//! 2r ≥ 0 the dead band.
//!
//! **Inverse** (the play's right inverse, Tao & Kokotović 1996): the play output w = (v − c)/g
//! is produced by uₖ = wₖ + r when w rises, uₖ = wₖ − r when it falls and uₖ = uₖ₋₁ when it
//! holds, so the input jumps across the dead band at every reversal. Every reference is
//! reachable. In the clockwise orientation (Γ = G⁻¹) the references Γ can produce are those
//! with G⁻¹[G[ρ]] = ρ; others are listed as clipped.
//!
//! References: M. A. Krasnosel'skii, A. V. Pokrovskii, *Systems with Hysteresis*, Springer
//! 1989; G. Tao, P. V. Kokotović, *Adaptive Control of Systems with Actuator and Sensor
//! Nonlinearities*, Wiley 1996.

use super::elementary::{
    check_finite, oriented_invert, oriented_simulate, play_step, Core, Orientation,
};
use super::{HysteresisOperator, Inversion};
use crate::model::{Parameter, ParameterSet};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// Backlash y = c + g·F_r\[u\] in an [`Orientation`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Backlash {
    g: f64,
    r: f64,
    offset: f64,
    orientation: Orientation,
}

impl Backlash {
    /// Backlash with gain g > 0, half-width r ≥ 0 and offset c.
    pub fn new(g: f64, r: f64, offset: f64, orientation: Orientation) -> Result<Self> {
        check_finite("g", g)?;
        check_finite("r", r)?;
        check_finite("c", offset)?;
        if g <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "g".into(),
                value: g,
                reason: "the gain must be > 0 (a decreasing loop is an orientation)".into(),
            });
        }
        if r < 0.0 {
            return Err(Error::InvalidParameter {
                name: "r".into(),
                value: r,
                reason: "the half-width must be >= 0".into(),
            });
        }
        Ok(Self {
            g,
            r,
            offset,
            orientation,
        })
    }

    /// The gain g.
    pub fn gain(&self) -> f64 {
        self.g
    }
    /// The half-width r (the dead band is 2r).
    pub fn half_width(&self) -> f64 {
        self.r
    }
    /// The offset c.
    pub fn offset(&self) -> f64 {
        self.offset
    }
    /// The orientation.
    pub fn orientation(&self) -> Orientation {
        self.orientation
    }
}

impl Core for Backlash {
    /// The play state z.
    type Forward = f64;
    /// The play output w and the input u of the previous sample.
    type Backward = (f64, f64);

    fn orientation(&self) -> Orientation {
        self.orientation
    }

    fn forward_state(&self, _horizon: Option<usize>) -> f64 {
        0.0
    }

    /// c + g·zₖ, zₖ = max(uₖ − r, min(uₖ + r, zₖ₋₁)).
    fn forward_step(&self, z: &mut f64, u: f64) -> f64 {
        *z = play_step(*z, u, self.r);
        self.offset + self.g * *z
    }

    fn backward_state(&self, _horizon: Option<usize>) -> (f64, f64) {
        (0.0, 0.0)
    }

    /// The right inverse of the module doc: w = (v − c)/g; u = w ± r as w rises or falls,
    /// the previous u while it holds.
    fn backward_step(&self, (z, u_prev): &mut (f64, f64), v: f64) -> (f64, bool) {
        let w = (v - self.offset) / self.g;
        let u = if w > *z {
            w + self.r
        } else if w < *z {
            w - self.r
        } else {
            *u_prev
        };
        *z = w;
        *u_prev = u;
        (u, false)
    }
}

impl HysteresisOperator for Backlash {
    fn family(&self) -> &'static str {
        <Self as super::OperatorFamily>::NAME
    }

    fn parameters(&self) -> ParameterSet {
        ParameterSet::new(vec![
            Parameter::new("g", self.g).bounds(0.0, f64::INFINITY),
            Parameter::new("r", self.r).bounds(0.0, f64::INFINITY),
            Parameter::new("c", self.offset),
        ])
        .unwrap_or_default()
    }

    fn simulate(&self, u: &[f64]) -> Result<Vec<f64>> {
        oriented_simulate(self, u)
    }

    fn invert(&self, reference: &[f64]) -> Result<Inversion> {
        oriented_invert(self, reference)
    }
}

impl super::OperatorFamily for Backlash {
    const NAME: &'static str = "backlash";
    const TITLE: &'static str = "play operator with gain (Krasnosel'skii & Pokrovskii 1989)";

    fn example() -> Result<Self> {
        Self::new(1.5, 0.2, 0.1, Orientation::default())
    }

    fn checked(self) -> Result<Self> {
        Self::new(
            self.gain(),
            self.half_width(),
            self.offset(),
            self.orientation(),
        )
    }

    /// Values g, r, c.
    fn with_values(&self, values: &[f64]) -> Result<Self> {
        super::check_values(self, values)?;
        Self::new(values[0], values[1], values[2], self.orientation())
    }

    /// g and c (not for the inverse-operator parameterisation).
    fn output_scale(&self) -> Option<Vec<usize>> {
        (!self.orientation().inverse).then(|| vec![0, 2])
    }
}
