//! The generalised (modified) Prandtl–Ishlinskii operator of Kuhnen (2003) for asymmetric
//! loops: a PI operator H followed by a superposition S of one-sided dead zones,
//! G[u] = S[H[u]].
//!
//! S(v) = d₀v + Σⱼ d⁺ⱼ max(v − z⁺ⱼ, 0) + Σⱼ d⁻ⱼ min(v − z⁻ⱼ, 0), with
//! 0 < z⁺₁ < z⁺₂ < … and 0 > z⁻₁ > z⁻₂ > …: a static piecewise-linear map whose slope on each
//! side is the partial sum d̂ⱼ = d₀ + d₁ + … + dⱼ, different above and below — the asymmetry a
//! symmetric PI cannot produce (the loops of piezo stacks bend more on one side).
//!
//! **Why this form** rather than a polynomial envelope on the plays (Al Janaideh, Rakheja &
//! Su 2011): both H and S have analytic inverses of the same shape, so Γ⁻¹ = H⁻¹∘S⁻¹ is exact
//! and cheap, and the identification stays linear in the weights (the equation error
//! S⁻¹[y] − H[u] is linear in the weights of H and of S⁻¹), so it needs no search and no
//! start.
//!
//! **Inverse of S** (Kuhnen 2003): with sⱼ = S(zⱼ) = d₀zⱼ + Σ_{k<j} dₖ(zⱼ − zₖ) on each side,
//! S⁻¹(w) = w/d₀ + Σⱼ bⱼ·max(w − s⁺ⱼ, 0) + Σⱼ bⱼ·min(w − s⁻ⱼ, 0), bⱼ = −dⱼ/(d̂ⱼ d̂ⱼ₋₁),
//! valid when every d̂ⱼ > 0.
//!
//! Reference: K. Kuhnen, "Modeling, identification and compensation of complex hysteretic
//! nonlinearities: a modified Prandtl–Ishlinskii approach", European Journal of Control 9
//! (2003) 407–418.

use super::elementary::{check_finite, oriented_invert, oriented_simulate, Core, Orientation};
use super::pi::{pi_parameters, PiBackward};
use super::{HysteresisOperator, Inversion, PrandtlIshlinskii};
use crate::model::{Parameter, ParameterSet};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// A superposition of one-sided dead zones S(v) (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeadZones {
    d0: f64,
    upper: Vec<(f64, f64)>,
    lower: Vec<(f64, f64)>,
}

impl DeadZones {
    /// S with linear weight d₀ > 0, upper dead zones (z⁺ⱼ, d⁺ⱼ) with 0 < z⁺₁ < z⁺₂ < … and lower
    /// ones (z⁻ⱼ, d⁻ⱼ) with 0 > z⁻₁ > z⁻₂ > …; every partial sum d₀ + … + dⱼ must be > 0.
    pub fn new(d0: f64, upper: Vec<(f64, f64)>, lower: Vec<(f64, f64)>) -> Result<Self> {
        check_finite("d0", d0)?;
        if d0 <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "d0".into(),
                value: d0,
                reason: "the dead zones' linear weight must be > 0".into(),
            });
        }
        for (side, zones, sign) in [("dp", &upper, 1.0), ("dn", &lower, -1.0)] {
            let mut hat = d0;
            for (j, &(z, d)) in zones.iter().enumerate() {
                check_finite(&format!("{side}{}", j + 1), d)?;
                let previous = if j == 0 { 0.0 } else { sign * zones[j - 1].0 };
                if !z.is_finite() || sign * z <= previous {
                    return Err(Error::InvalidParameter {
                        name: format!("z{}{}", &side[1..], j + 1),
                        value: z,
                        reason: "dead-zone thresholds must move away from 0 strictly \
                                 monotonically; sort them"
                            .into(),
                    });
                }
                hat += d;
                if hat <= 0.0 {
                    return Err(Error::InvalidParameter {
                        name: format!("{side}{}", j + 1),
                        value: d,
                        reason: "the slope d0 + … + dj is not > 0: S would not be invertible"
                            .into(),
                    });
                }
            }
        }
        Ok(Self { d0, upper, lower })
    }

    /// The identity S(v) = v.
    pub fn identity() -> Self {
        Self {
            d0: 1.0,
            upper: Vec::new(),
            lower: Vec::new(),
        }
    }

    /// d₀.
    pub fn d0(&self) -> f64 {
        self.d0
    }
    /// The upper dead zones (z⁺ⱼ, d⁺ⱼ).
    pub fn upper(&self) -> &[(f64, f64)] {
        &self.upper
    }
    /// The lower dead zones (z⁻ⱼ, d⁻ⱼ).
    pub fn lower(&self) -> &[(f64, f64)] {
        &self.lower
    }

    /// S(v).
    pub fn eval(&self, v: f64) -> f64 {
        let up: f64 = self.upper.iter().map(|&(z, d)| d * (v - z).max(0.0)).sum();
        let down: f64 = self.lower.iter().map(|&(z, d)| d * (v - z).min(0.0)).sum();
        self.d0 * v + up + down
    }

    /// S⁻¹ as a dead-zone superposition of the same shape (Kuhnen 2003).
    pub fn inverse(&self) -> Self {
        let side = |zones: &[(f64, f64)]| {
            let mut out = Vec::with_capacity(zones.len());
            let mut hat_prev = self.d0;
            for (j, &(z, d)) in zones.iter().enumerate() {
                let s = self.d0 * z
                    + zones[..j]
                        .iter()
                        .map(|&(zk, dk)| dk * (z - zk))
                        .sum::<f64>();
                let hat = hat_prev + d;
                out.push((s, -d / (hat * hat_prev)));
                hat_prev = hat;
            }
            out
        };
        Self {
            d0: 1.0 / self.d0,
            upper: side(&self.upper),
            lower: side(&self.lower),
        }
    }
}

/// Kuhnen's modified PI operator G\[u\] = S\[H[u\]] in an [`Orientation`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GeneralizedPi {
    pi: PrandtlIshlinskii,
    dead_zones: DeadZones,
    orientation: Orientation,
}

impl GeneralizedPi {
    /// G = S∘H from a PI operator H (its own orientation is ignored: H is the core) and
    /// dead zones S.
    pub fn new(pi: PrandtlIshlinskii, dead_zones: DeadZones, orientation: Orientation) -> Self {
        Self {
            pi,
            dead_zones,
            orientation,
        }
    }
    /// The PI part H.
    pub fn pi(&self) -> &PrandtlIshlinskii {
        &self.pi
    }
    /// The dead zones S.
    pub fn dead_zones(&self) -> &DeadZones {
        &self.dead_zones
    }
    /// The orientation.
    pub fn orientation(&self) -> Orientation {
        self.orientation
    }
}

impl Core for GeneralizedPi {
    /// H's play states.
    type Forward = Vec<f64>;
    /// S⁻¹ (precomputed) and H⁻¹'s state.
    type Backward = (DeadZones, PiBackward);

    fn orientation(&self) -> Orientation {
        self.orientation
    }

    fn forward_state(&self, horizon: Option<usize>) -> Vec<f64> {
        self.pi.forward_state(horizon)
    }

    /// S(H\[u\]ₖ).
    fn forward_step(&self, z: &mut Vec<f64>, u: f64) -> f64 {
        self.dead_zones.eval(self.pi.forward_step(z, u))
    }

    fn backward_state(&self, horizon: Option<usize>) -> (DeadZones, PiBackward) {
        (self.dead_zones.inverse(), self.pi.backward_state(horizon))
    }

    /// H⁻¹\[S⁻¹(v)\]ₖ.
    fn backward_step(&self, (inverse, pi): &mut (DeadZones, PiBackward), v: f64) -> (f64, bool) {
        self.pi.backward_step(pi, inverse.eval(v))
    }
}

impl HysteresisOperator for GeneralizedPi {
    fn family(&self) -> &'static str {
        <Self as super::OperatorFamily>::NAME
    }

    fn parameters(&self) -> ParameterSet {
        let h = &self.pi;
        let mut p: Vec<Parameter> =
            pi_parameters(h.a0(), h.weights(), h.thresholds(), h.offset(), "a", "r")
                .iter()
                .cloned()
                .collect();
        let s = &self.dead_zones;
        p.push(Parameter::new("d0", s.d0).bounds(0.0, f64::INFINITY));
        for (side, zones) in [("p", &s.upper), ("n", &s.lower)] {
            for (j, &(_, d)) in zones.iter().enumerate() {
                p.push(Parameter::new(format!("d{side}{}", j + 1), d));
            }
            for (j, &(z, _)) in zones.iter().enumerate() {
                p.push(Parameter::new(format!("z{side}{}", j + 1), z).fixed(true));
            }
        }
        ParameterSet::new(p).unwrap_or_default()
    }

    fn simulate(&self, u: &[f64]) -> Result<Vec<f64>> {
        oriented_simulate(self, u)
    }

    fn invert(&self, reference: &[f64]) -> Result<Inversion> {
        oriented_invert(self, reference)
    }
}

impl super::OperatorFamily for GeneralizedPi {
    const NAME: &'static str = "gpi";
    const TITLE: &'static str = "generalised PI with dead zones (Kuhnen 2003)";

    fn example() -> Result<Self> {
        let pi = PrandtlIshlinskii::new(
            0.5,
            vec![0.3, 0.2],
            vec![0.2, 0.5],
            0.0,
            Orientation::default(),
        )?;
        let zones = DeadZones::new(1.0, vec![(0.3, 0.2)], vec![(-0.4, 0.1)])?;
        Ok(Self::new(pi, zones, Orientation::default()))
    }

    fn checked(self) -> Result<Self> {
        if self.pi.envelope().is_some() {
            return Err(Error::InvalidModel(
                "a generalised PI's plays carry no static envelope (its dead zones shape the \
                 static curve); remove \"envelope\" from its \"pi\""
                    .into(),
            ));
        }
        let z = self.dead_zones();
        let zones = DeadZones::new(z.d0(), z.upper().to_vec(), z.lower().to_vec())?;
        Ok(Self::new(
            self.pi.clone().checked()?,
            zones,
            self.orientation(),
        ))
    }

    /// Values a0, a1 … an, r1 … rn, c, d0, dp1 …, zp1 …, dn1 …, zn1 … (the order of
    /// [`GeneralizedPi::parameters`]).
    fn with_values(&self, values: &[f64]) -> Result<Self> {
        super::check_values(self, values)?;
        let n = self.pi().weights().len();
        let pi = PrandtlIshlinskii::new(
            values[0],
            values[1..=n].to_vec(),
            values[n + 1..=2 * n].to_vec(),
            values[2 * n + 1],
            self.pi().orientation(),
        )?;
        let zones = self.dead_zones();
        let mut at = 2 * n + 2;
        let d0 = values[at];
        at += 1;
        let mut side = |count: usize| {
            let weights = &values[at..at + count];
            let thresholds = &values[at + count..at + 2 * count];
            at += 2 * count;
            thresholds
                .iter()
                .copied()
                .zip(weights.iter().copied())
                .collect()
        };
        let upper = side(zones.upper().len());
        let lower = side(zones.lower().len());
        Ok(Self::new(
            pi,
            DeadZones::new(d0, upper, lower)?,
            self.orientation(),
        ))
    }

    /// The generalised PI's output scale touches the dead zones' thresholds too; none.
    fn output_scale(&self) -> Option<Vec<usize>> {
        None
    }
}
