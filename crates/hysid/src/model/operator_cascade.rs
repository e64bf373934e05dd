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

use super::operators::{
    Backlash, BoucWen, Dahl, DeadZones, Duhem, GeneralizedPi, HysteresisOperator, JilesAtherton,
    MaxwellSlip, PrandtlIshlinskii, Preisach,
};
use super::{CascadeOutput, LinearBlock, Parameter, ParameterSet};
use crate::{Error, Result};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// The operator Γ of an [`OperatorCascade`]: one of the families of [`super::operators`].
#[allow(missing_docs)] // each variant is the family of the same name
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "family", content = "operator", rename_all = "kebab-case")]
pub enum CascadeOperator {
    Pi(PrandtlIshlinskii),
    Gpi(GeneralizedPi),
    Preisach(Preisach),
    JilesAtherton(JilesAtherton),
    BoucWen(BoucWen),
    Duhem(Duhem),
    Dahl(Dahl),
    MaxwellSlip(MaxwellSlip),
    Backlash(Backlash),
}

impl CascadeOperator {
    /// The operator behind the common interface.
    pub fn as_operator(&self) -> &dyn HysteresisOperator {
        match self {
            Self::Pi(m) => m,
            Self::Gpi(m) => m,
            Self::Preisach(m) => m,
            Self::JilesAtherton(m) => m,
            Self::BoucWen(m) => m,
            Self::Duhem(m) => m,
            Self::Dahl(m) => m,
            Self::MaxwellSlip(m) => m,
            Self::Backlash(m) => m,
        }
    }

    /// The family's command-line name (`pi`, `backlash`, …).
    pub fn family(&self) -> &'static str {
        self.as_operator().family()
    }

    /// The same operator structure (thresholds, grid, orientation, anhysteretic …) with the
    /// parameter values `values` in [`HysteresisOperator::parameters`] order, validated.
    /// Derived values (the Maxwell-slip slip forces Wᵢ = kᵢδᵢ) are recomputed, not read.
    pub fn with_values(&self, values: &[f64]) -> Result<Self> {
        let expected = self.as_operator().parameters().len();
        if values.len() != expected {
            return Err(Error::InvalidModel(format!(
                "a {} operator has {expected} parameters, got {}",
                self.family(),
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidParameter {
                name: self.as_operator().parameters().get(i).name.clone(),
                value: values[i],
                reason: "must be finite".into(),
            });
        }
        Ok(match self {
            Self::Pi(m) => Self::Pi(pi_with(m, values)?),
            Self::Gpi(m) => Self::Gpi(gpi_with(m, values)?),
            Self::Preisach(m) => {
                let n = m.weights().len();
                Self::Preisach(Preisach::new(
                    m.lower(),
                    m.upper(),
                    m.levels(),
                    values[1..=n].to_vec(),
                    values[0],
                    values[n + 1],
                    m.orientation(),
                )?)
            }
            Self::JilesAtherton(m) => {
                let mut next = m.clone();
                [next.ms, next.a, next.k, next.c, next.alpha, next.m0] =
                    [0, 1, 2, 3, 4, 5].map(|i| values[i]);
                next.validate()?;
                Self::JilesAtherton(next)
            }
            Self::BoucWen(m) => {
                let mut next = m.clone();
                [
                    next.kx, next.kw, next.a, next.beta, next.gamma, next.n, next.w0,
                ] = [0, 1, 2, 3, 4, 5, 6].map(|i| values[i]);
                next.validate()?;
                Self::BoucWen(next)
            }
            Self::Duhem(m) => {
                let mut next = m.clone();
                [next.alpha, next.a, next.b, next.c, next.y0] = [0, 1, 2, 3, 4].map(|i| values[i]);
                next.validate()?;
                Self::Duhem(next)
            }
            Self::Dahl(m) => {
                let mut next = m.clone();
                [next.sigma, next.fc, next.i, next.f0] = [0, 1, 2, 3].map(|i| values[i]);
                next.validate()?;
                Self::Dahl(next)
            }
            Self::MaxwellSlip(m) => {
                let n = m.stiffness().len();
                Self::MaxwellSlip(MaxwellSlip::new(
                    values[0],
                    values[1..=n].to_vec(),
                    m.widths().to_vec(),
                    values[2 * n + 1],
                    m.orientation(),
                )?)
            }
            Self::Backlash(m) => Self::Backlash(Backlash::new(
                values[0],
                values[1],
                values[2],
                m.orientation(),
            )?),
        })
    }

    /// Indices of the parameters a cascade fit holds fixed besides the family's own fixed ones:
    /// the shape exponents (Bouc–Wen n, Dahl i, as the family fits do by default) and the
    /// derived Maxwell-slip slip forces.
    pub fn held(&self) -> Vec<usize> {
        match self {
            Self::BoucWen(_) => vec![5],
            Self::Dahl(_) => vec![2],
            Self::MaxwellSlip(m) => {
                let n = m.stiffness().len();
                (n + 1..=2 * n).collect()
            }
            _ => Vec::new(),
        }
    }

    /// The operator whose output is s·Γ\[u\] (s > 0), where the family has an output scale
    /// that does not touch its shape; None otherwise (inverse-parameterised loops,
    /// Jiles–Atherton).
    pub fn scaled(&self, s: f64) -> Option<Self> {
        if !(s.is_finite() && s > 0.0) {
            return None;
        }
        let p = self.as_operator().parameters().values();
        let scale = |idx: &[usize]| {
            let mut v = p.clone();
            for &i in idx {
                v[i] *= s;
            }
            self.with_values(&v).ok()
        };
        match self {
            Self::Pi(m) if !m.orientation().inverse => {
                let n = m.weights().len();
                let mut idx: Vec<usize> = (0..=n).collect();
                idx.push(2 * n + 1);
                scale(&idx)
            }
            Self::Preisach(m) if !m.orientation().inverse => {
                scale(&(0..m.weights().len() + 2).collect::<Vec<_>>())
            }
            Self::MaxwellSlip(m) if !m.orientation().inverse => {
                let n = m.stiffness().len();
                let mut idx: Vec<usize> = (0..=n).collect();
                idx.push(2 * n + 1);
                scale(&idx)
            }
            Self::Backlash(m) if !m.orientation().inverse => scale(&[0, 2]),
            Self::BoucWen(_) => scale(&[0, 1]),
            Self::Duhem(_) => scale(&[1, 2, 3, 4]),
            Self::Dahl(_) => scale(&[0, 1, 3]),
            _ => None,
        }
    }
}

fn pi_with(m: &PrandtlIshlinskii, values: &[f64]) -> Result<PrandtlIshlinskii> {
    let n = m.weights().len();
    PrandtlIshlinskii::new(
        values[0],
        values[1..=n].to_vec(),
        values[n + 1..=2 * n].to_vec(),
        values[2 * n + 1],
        m.orientation(),
    )
}

/// GPI values: a0, a1…an, r1…rn, c, d0, dp1…, zp1…, dn1…, zn1… ([`GeneralizedPi`]'s order).
fn gpi_with(m: &GeneralizedPi, values: &[f64]) -> Result<GeneralizedPi> {
    let n = m.pi().weights().len();
    let pi = PrandtlIshlinskii::new(
        values[0],
        values[1..=n].to_vec(),
        values[n + 1..=2 * n].to_vec(),
        values[2 * n + 1],
        m.pi().orientation(),
    )?;
    let s = m.dead_zones();
    let mut at = 2 * n + 2;
    let d0 = values[at];
    at += 1;
    let mut side = |count: usize| {
        let zones: Vec<(f64, f64)> = (0..count)
            .map(|j| (values[at + count + j], values[at + j]))
            .collect();
        at += 2 * count;
        zones
    };
    let upper = side(s.upper().len());
    let lower = side(s.lower().len());
    Ok(GeneralizedPi::new(
        pi,
        DeadZones::new(d0, upper, lower)?,
        m.orientation(),
    ))
}

/// A hysteresis operator Γ followed by a linear block B/A with b1 = 1 (module doc).
///
/// ```
/// use hysid::model::operators::{Backlash, Orientation};
/// use hysid::model::{CascadeOperator, LinearBlock, OperatorCascade};
/// let gamma = Backlash::new(2.0, 0.5, 0.0, Orientation::default()).unwrap();
/// let lin = LinearBlock::new(vec![-0.5], vec![1.0], 1).unwrap();
/// let cascade = OperatorCascade::new(CascadeOperator::Backlash(gamma), lin).unwrap();
/// let out = cascade.simulate(&[0.0, 1.0, 2.0]).unwrap();
/// assert_eq!(out.v, vec![0.0, 1.0, 3.0]); // 2·F_0.5[u]
/// assert_eq!(out.y, vec![0.0, 0.0, 1.0]); // y(t) = 0.5 y(t−1) + v(t−1)
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OperatorCascade {
    /// The input hysteresis Γ.
    pub operator: CascadeOperator,
    /// The linear block (b1 = 1).
    pub linear: LinearBlock,
}

impl OperatorCascade {
    /// Builds a cascade; b1 must be 1 (the normalisation, module doc).
    pub fn new(operator: CascadeOperator, linear: LinearBlock) -> Result<Self> {
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
    fn operator_names(operator: &CascadeOperator) -> Vec<String> {
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
    /// them, plus [`CascadeOperator::held`]), a1 … an, b1 (fixed at 1), b2 … bm.
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
        let radius = self.zero_radius();
        if radius >= 1.0 {
            return Err(Error::InvalidModel(format!(
                "the linear block is not minimum phase (a zero of B at |z| = {radius:.4} >= 1): \
                 its inverse is unstable; compensate the hysteresis operator alone, or refit \
                 with fewer B coefficients"
            )));
        }
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
