//! Any hysteresis operator followed by a linear dynamic block (the cascade structure of
//! Vörös 2015 with the operator families of [`super::operators`]).
//!
//! # Equations
//!
//! ```text
//! v(t) = Γ[u](t)                                   (any operator family, not measured)
//! A(q⁻¹) y(t) = B(q⁻¹) v(t),   B = q⁻ᵏ(b1 + b2 q⁻¹ + … + bm q⁻ᵐ⁺¹),  b1 = 1
//! y(t) = −a1 y(t−1) − … − an y(t−n) + v(t−k) + b2 v(t−k−1) + … + bm v(t−k−m+1)
//! ```
//!
//! **Normalisation.** Γ ∘ (B/A) and (s·Γ) ∘ (B/(s·A)) give the same output for every s ≠ 0,
//! so only the product of the gains is identifiable. As in the Coleman–Hodgdon cascade
//! ([`super::HysteresisCascade`]), the first numerator coefficient is fixed, b1 = 1, and the
//! gain (and sign) sit in Γ: every family has an output scale there (a weight, a gain, a
//! saturation level), and the operator's parameters keep their physical meaning on the scale
//! of y's first response sample. The operator starts from its documented initial state, the
//! linear block from rest (y = v = 0 before t = 0).
//!
//! **Parameters** (flattened): the operator's names from the literature, then a1 … an, then
//! b1 (fixed at 1) … bm. Where an operator's names collide with a linear coefficient (the PI
//! weights a0, a1, …), all of the operator's names carry the prefix `op_`.
//!
//! **Compensation** ([`OperatorCascade::compensate`]): the input u that makes y follow a
//! reference r inverts the two blocks in turn: v(t) = A(q⁻¹)/B(q⁻¹) r(t + k) — the reference is
//! advanced by the delay k, so it must be known k samples ahead; past the record's end it is
//! held at its last value — then u = Γ⁻¹\[v\]. The inverse of the linear block is stable only
//! when B is minimum phase (every zero of b1 zᵐ⁻¹ + … + bm strictly inside the unit circle); a
//! block that is not is refused.
//!
//! References: I. Vörös, "Iterative identification of nonlinear dynamic systems with output
//! backlash using three-block cascade models", Nonlinear Dynamics 79 (2015) — the cascade
//! structure and the b1 = 1 normalisation; for each operator its own reference in
//! [`super::operators`]; G. Tao, P. V. Kokotović, *Adaptive Control of Systems with Actuator
//! and Sensor Nonlinearities*, Wiley 1996 — inverse compensation of a hysteresis ahead of
//! linear dynamics.

use super::operators::OperatorModel;
use super::{CascadeOutput, LinearBlock, Parameter, ParameterSet};
use crate::{Error, Result};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// A hysteresis operator Γ followed by a linear block B/A with b1 = 1 (module doc).
///
/// ```
/// use hysid::model::operators::{Backlash, Orientation};
/// use hysid::model::{LinearBlock, OperatorCascade, OperatorModel};
/// let gamma = Backlash::new(2.0, 0.5, 0.0, Orientation::default()).unwrap();
/// let lin = LinearBlock::new(vec![-0.5], vec![1.0], 1).unwrap();
/// let cascade = OperatorCascade::new(OperatorModel::Backlash(gamma), lin).unwrap();
/// let out = cascade.simulate(&[0.0, 1.0, 2.0]).unwrap();
/// assert_eq!(out.v, vec![0.0, 1.0, 3.0]); // 2·F_0.5[u]
/// assert_eq!(out.y, vec![0.0, 0.0, 1.0]); // y(t) = 0.5 y(t−1) + v(t−1)
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OperatorCascade {
    /// The input hysteresis Γ.
    pub operator: OperatorModel,
    /// The linear block (b1 = 1).
    pub linear: LinearBlock,
}

impl OperatorCascade {
    /// Builds a cascade; b1 must be 1 (the normalisation, module doc).
    pub fn new(operator: OperatorModel, linear: LinearBlock) -> Result<Self> {
        if linear.b()[0] != 1.0 {
            return Err(Error::InvalidModel(format!(
                "the operator cascade fixes b1 = 1 (the gain sits in the operator), got b1 = {}",
                linear.b()[0]
            )));
        }
        Ok(Self { operator, linear })
    }

    /// The operator's parameter names as the cascade lists them (`op_` prefix on a collision
    /// with a1…, b1…).
    fn operator_names(operator: &OperatorModel) -> Vec<String> {
        let names = operator.as_operator().parameters().names();
        let linear_like = |n: &str| {
            let rest = n.strip_prefix('a').or_else(|| n.strip_prefix('b'));
            rest.is_some_and(|r| !r.is_empty() && r.chars().all(|c| c.is_ascii_digit()))
        };
        if names.iter().any(|n| linear_like(n)) {
            names.into_iter().map(|n| format!("op_{n}")).collect()
        } else {
            names
        }
    }

    /// Number of operator parameters (the first entries of [`parameters`](Self::parameters)).
    pub fn n_operator_parameters(&self) -> usize {
        self.operator.as_operator().parameters().len()
    }

    /// The flattened parameters: the operator's (bounds and fixed flags as the family gives
    /// them, plus [`OperatorModel::held`]), a1 … an, b1 (fixed at 1), b2 … bm.
    pub fn parameters(&self) -> ParameterSet {
        let op = self.operator.as_operator().parameters();
        let held = self.operator.held();
        let names = Self::operator_names(&self.operator);
        let mut p: Vec<Parameter> = op
            .iter()
            .zip(names)
            .enumerate()
            .map(|(i, (q, name))| {
                let mut q = q.clone();
                q.name = name;
                if held.contains(&i) {
                    q.fixed = true;
                }
                q
            })
            .collect();
        p.extend(
            self.linear
                .a()
                .iter()
                .enumerate()
                .map(|(i, &a)| Parameter::new(format!("a{}", i + 1), a)),
        );
        p.extend(self.linear.b().iter().enumerate().map(|(j, &b)| {
            let q = Parameter::new(format!("b{}", j + 1), b);
            if j == 0 {
                q.fixed(true)
            } else {
                q
            }
        }));
        ParameterSet::new(p).unwrap_or_default()
    }

    /// The same structure with the values `values` in [`parameters`](Self::parameters) order
    /// (b1 must be 1).
    pub fn with_values(&self, values: &[f64]) -> Result<Self> {
        let no = self.n_operator_parameters();
        let (na, nb) = (self.linear.na(), self.linear.nb());
        if values.len() != no + na + nb {
            return Err(Error::InvalidModel(format!(
                "a {} cascade with na = {na}, nb = {nb} has {} parameters, got {}",
                self.operator.family(),
                no + na + nb,
                values.len()
            )));
        }
        let operator = self.operator.with_values(&values[..no])?;
        let linear = LinearBlock::new(
            values[no..no + na].to_vec(),
            values[no + na..].to_vec(),
            self.linear.delay(),
        )?;
        Self::new(operator, linear)
    }

    /// v = Γ\[u\] and y = B/A v from rest.
    pub fn simulate(&self, u: &[f64]) -> Result<CascadeOutput> {
        let v = self.operator.as_operator().simulate(u)?;
        let y = self.linear.simulate(&v);
        if let Some(index) = y.iter().position(|x| !x.is_finite()) {
            return Err(Error::Diverged {
                index,
                reason: "the linear block's output is not finite; it is unstable for this input"
                    .into(),
            });
        }
        Ok(CascadeOutput { v, y })
    }

    /// Refuses a linear block that is not minimum phase (a zero of B on or outside the unit
    /// circle): its inverse, which compensation runs, is unstable.
    pub fn check_minimum_phase(&self) -> Result<()> {
        let radius = self.zero_radius();
        if radius >= 1.0 {
            return Err(Error::InvalidModel(format!(
                "the linear block is not minimum phase (a zero of B at |z| = {radius:.4} >= 1): \
                 its inverse is unstable; compensate the hysteresis operator alone, or refit \
                 with fewer B coefficients"
            )));
        }
        Ok(())
    }

    /// The largest modulus of the zeros of B (roots of b1 zᵐ⁻¹ + … + bm); < 1 means minimum
    /// phase.
    pub fn zero_radius(&self) -> f64 {
        let b = self.linear.b();
        let monic: Vec<f64> = b[1..].iter().map(|v| v / b[0]).collect();
        root_radius(&monic)
    }

    /// The input u that makes y follow `reference` (module doc): v = A/B r advanced by k,
    /// then u = Γ⁻¹\[v\]. Errors when B is not minimum phase.
    pub fn compensate(&self, reference: &[f64]) -> Result<CascadeCompensation> {
        if reference.is_empty() {
            return Err(Error::InvalidData(
                "the reference is empty; give at least one sample".into(),
            ));
        }
        if let Some(index) = reference.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                channel: "reference".into(),
                index,
                value: reference[index],
            });
        }
        self.check_minimum_phase()?;
        let v_desired = self.invert_linear(reference);
        let inversion = self.operator.as_operator().invert(&v_desired)?;
        let predicted = self.simulate(&inversion.u)?.y;
        Ok(CascadeCompensation {
            u: inversion.u,
            v: v_desired,
            predicted,
            clipped: inversion.clipped,
            delay: self.linear.delay(),
        })
    }

    /// v(s) = r(s + k) + Σ aᵢ ρ(s + k − i) − Σ_{j≥2} bⱼ v(s − j + 1), with ρ(t) = r(t) for t ≥ k
    /// and 0 before (the block's output is 0 there whatever v is) and r held past the end.
    fn invert_linear(&self, r: &[f64]) -> Vec<f64> {
        let k = self.linear.delay();
        let n = r.len();
        let rho = |t: isize| -> f64 {
            if t < k as isize {
                0.0
            } else {
                r[(t as usize).min(n - 1)]
            }
        };
        let mut v = vec![0.0; n];
        for s in 0..n {
            let t = (s + k) as isize;
            let mut acc = rho(t);
            for (i, &a) in self.linear.a().iter().enumerate() {
                acc += a * rho(t - i as isize - 1);
            }
            for (j, &b) in self.linear.b().iter().enumerate().skip(1) {
                if let Some(p) = s.checked_sub(j) {
                    acc -= b * v[p];
                }
            }
            v[s] = acc;
        }
        v
    }
}

/// The largest root modulus of the monic polynomial zⁿ + c1 zⁿ⁻¹ + … + cn (0 when n = 0).
fn root_radius(c: &[f64]) -> f64 {
    let n = c.len();
    if n == 0 {
        return 0.0;
    }
    let mut m = DMatrix::<f64>::zeros(n, n);
    for (j, &cj) in c.iter().enumerate() {
        m[(0, j)] = -cj;
    }
    for i in 1..n {
        m[(i, i - 1)] = 1.0;
    }
    m.complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

/// The input computed by [`OperatorCascade::compensate`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CascadeCompensation {
    /// The compensating input u.
    pub u: Vec<f64>,
    /// The operator output v = A/B r(· + k) that u is computed to produce.
    pub v: Vec<f64>,
    /// The cascade's output for u (equal to the reference from sample k on, where reachable).
    pub predicted: Vec<f64>,
    /// Samples where v lay outside the operator's reachable range and was clipped.
    pub clipped: Vec<usize>,
    /// The delay k: the first k outputs cannot follow the reference (the block is at rest).
    pub delay: usize,
}
