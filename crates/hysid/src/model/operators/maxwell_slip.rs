//! Generalised Maxwell-slip friction (rate-independent part).
//!
//! Element i is a spring of stiffness kᵢ whose end block sticks until the spring force reaches
//! its slip force Wᵢ: Fᵢ = kᵢ·E_{δᵢ}[x] with the stop operator E_δ[x] = x − F_δ[x] of
//! half-width δᵢ = Wᵢ/kᵢ, every element from rest (state 0). The total force is
//! F = c + k₀x + Σᵢ kᵢ E_{δᵢ}[x], k₀ ≥ 0 a linear spring (an element that never slips).
//!
//! Rate-independently this is a PI operator with a₀ = k₀ + Σ kᵢ, play weights aᵢ = −kᵢ and
//! thresholds δᵢ; its inverse is the PI inverse (Krejčí & Kuhnen 2001): analytic when k₀ > 0,
//! otherwise the force saturates at c ± Σ Wᵢ and references beyond are clipped.
//!
//! **Orientation.** A stop operator's loop is clockwise (the force leads the displacement),
//! so Γ = G (`Orientation::inverse == false`) is the clockwise friction loop and Γ = G⁻¹ the
//! counter-clockwise one.
//!
//! References: V. Lampaert, F. Al-Bender, J. Swevers, "A generalized Maxwell-slip friction
//! model appropriate for control purposes", Proc. PhysCon 2003; F. Al-Bender, V. Lampaert,
//! J. Swevers, "The generalized Maxwell-slip model: a novel model for friction simulation and
//! compensation", IEEE Trans. Automatic Control 50 (2005) 1883–1887.

use super::elementary::{
    check_finite, oriented_invert, oriented_simulate, validate_thresholds, Core, Orientation,
};
use super::{HysteresisOperator, Inversion, PrandtlIshlinskii};
use crate::model::{Parameter, ParameterSet};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// Maxwell-slip elements (kᵢ, δᵢ = Wᵢ/kᵢ), a linear spring k₀ and an offset, in an
/// [`Orientation`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MaxwellSlip {
    k0: f64,
    stiffness: Vec<f64>,
    widths: Vec<f64>,
    offset: f64,
    orientation: Orientation,
    pi: PrandtlIshlinskii,
}

impl MaxwellSlip {
    /// Elements with stiffnesses kᵢ ≥ 0 and slip widths δᵢ = Wᵢ/kᵢ (strictly increasing,
    /// > 0), linear spring k₀ ≥ 0 and force offset c.
    pub fn new(
        k0: f64,
        stiffness: Vec<f64>,
        widths: Vec<f64>,
        offset: f64,
        orientation: Orientation,
    ) -> Result<Self> {
        check_finite("k0", k0)?;
        validate_thresholds("delta", &widths)?;
        if stiffness.len() != widths.len() {
            return Err(Error::InvalidModel(format!(
                "Maxwell-slip: {} stiffnesses for {} widths; give one per element",
                stiffness.len(),
                widths.len()
            )));
        }
        for (i, &k) in std::iter::once(&k0).chain(&stiffness).enumerate() {
            check_finite(&format!("k{i}"), k)?;
            if k < 0.0 {
                return Err(Error::InvalidParameter {
                    name: format!("k{i}"),
                    value: k,
                    reason: "stiffnesses must be >= 0".into(),
                });
            }
        }
        let a0 = k0 + stiffness.iter().sum::<f64>();
        let a: Vec<f64> = stiffness.iter().map(|k| -k).collect();
        let pi = PrandtlIshlinskii::new(a0, a, widths.clone(), offset, Orientation::default())?;
        Ok(Self {
            k0,
            stiffness,
            widths,
            offset,
            orientation,
            pi,
        })
    }

    /// The linear spring k₀.
    pub fn k0(&self) -> f64 {
        self.k0
    }
    /// The element stiffnesses kᵢ.
    pub fn stiffness(&self) -> &[f64] {
        &self.stiffness
    }
    /// The slip widths δᵢ = Wᵢ/kᵢ.
    pub fn widths(&self) -> &[f64] {
        &self.widths
    }
    /// The slip forces Wᵢ = kᵢδᵢ.
    pub fn slip_forces(&self) -> Vec<f64> {
        self.stiffness
            .iter()
            .zip(&self.widths)
            .map(|(k, d)| k * d)
            .collect()
    }
    /// The force offset c.
    pub fn offset(&self) -> f64 {
        self.offset
    }
    /// The orientation.
    pub fn orientation(&self) -> Orientation {
        self.orientation
    }
    /// The equivalent PI operator (a₀ = k₀ + Σkᵢ, aᵢ = −kᵢ, rᵢ = δᵢ).
    pub fn as_pi(&self) -> &PrandtlIshlinskii {
        &self.pi
    }
}

/// The equivalent PI operator's steps ([`MaxwellSlip::as_pi`]).
impl Core for MaxwellSlip {
    type Forward = <PrandtlIshlinskii as Core>::Forward;
    type Backward = <PrandtlIshlinskii as Core>::Backward;

    fn orientation(&self) -> Orientation {
        self.orientation
    }
    fn forward_state(&self, horizon: Option<usize>) -> Self::Forward {
        self.pi.forward_state(horizon)
    }
    fn forward_step(&self, state: &mut Self::Forward, u: f64) -> f64 {
        self.pi.forward_step(state, u)
    }
    fn backward_state(&self, horizon: Option<usize>) -> Self::Backward {
        self.pi.backward_state(horizon)
    }
    fn backward_step(&self, state: &mut Self::Backward, v: f64) -> (f64, bool) {
        self.pi.backward_step(state, v)
    }
}

impl HysteresisOperator for MaxwellSlip {
    fn family(&self) -> &'static str {
        <Self as super::OperatorFamily>::NAME
    }

    fn parameters(&self) -> ParameterSet {
        let mut p = vec![Parameter::new("k0", self.k0).bounds(0.0, f64::INFINITY)];
        for (i, &k) in self.stiffness.iter().enumerate() {
            p.push(Parameter::new(format!("k{}", i + 1), k).bounds(0.0, f64::INFINITY));
        }
        for (i, w) in self.slip_forces().into_iter().enumerate() {
            p.push(Parameter::new(format!("W{}", i + 1), w).bounds(0.0, f64::INFINITY));
        }
        p.push(Parameter::new("c", self.offset));
        ParameterSet::new(p).unwrap_or_default()
    }

    fn simulate(&self, u: &[f64]) -> Result<Vec<f64>> {
        oriented_simulate(self, u)
    }

    fn invert(&self, reference: &[f64]) -> Result<Inversion> {
        oriented_invert(self, reference)
    }
}

impl super::OperatorFamily for MaxwellSlip {
    const NAME: &'static str = "maxwell-slip";
    const TITLE: &'static str = "generalised Maxwell-slip (Lampaert, Al-Bender & Swevers 2003)";

    fn example() -> Result<Self> {
        Self::new(
            0.2,
            vec![1.0, 0.5],
            vec![0.1, 0.4],
            0.0,
            Orientation::default(),
        )
    }

    fn checked(self) -> Result<Self> {
        Self::new(
            self.k0(),
            self.stiffness().to_vec(),
            self.widths().to_vec(),
            self.offset(),
            self.orientation(),
        )
    }

    /// Values k0, k1 … kn, W1 … Wn (derived, recomputed), c.
    fn with_values(&self, values: &[f64]) -> Result<Self> {
        super::check_values(self, values)?;
        let n = self.stiffness().len();
        Self::new(
            values[0],
            values[1..=n].to_vec(),
            self.widths().to_vec(),
            values[2 * n + 1],
            self.orientation(),
        )
    }

    /// The slip forces Wᵢ = kᵢδᵢ are derived from the stiffnesses.
    fn held(&self) -> Vec<usize> {
        let n = self.stiffness().len();
        (n + 1..=2 * n).collect()
    }

    /// k0 … kn and c (not for the inverse-operator parameterisation).
    fn output_scale(&self) -> Option<Vec<usize>> {
        let n = self.stiffness().len();
        (!self.orientation().inverse).then(|| (0..=n).chain([2 * n + 1]).collect())
    }
}
