//! The Prandtl–Ishlinskii (PI) operator and its analytic inverse.
//!
//! G[u] = c + a₀u + Σᵢ₌₁ⁿ aᵢ F_{rᵢ}[u] with play operators F_r (see [`super::play`]),
//! 0 < r₁ < … < rₙ, every play from the state 0. On a branch that has moved a distance d since
//! its last reversal the slope is âᵢ = a₀ + … + aᵢ for 2rᵢ ≤ d < 2rᵢ₊₁, so G is non-decreasing
//! iff every âᵢ ≥ 0 (weights may be signed, as in the Maxwell-slip form).
//!
//! **Inverse** (Krejčí & Kuhnen 2001; Kuhnen 2003): with âᵢ = a₀ + … + aᵢ,
//! sᵢ = a₀rᵢ + Σ_{j<i} aⱼ(rᵢ − rⱼ), b₀ = 1/a₀ and bᵢ = −aᵢ/(âᵢ âᵢ₋₁),
//! G⁻¹[v] = b₀(v − c) + Σ bᵢ F_{sᵢ}[v − c], its plays also from 0 (the virgin state of G maps
//! to the virgin state of G⁻¹). It needs every âᵢ > 0; otherwise (a₀ = 0 or a saturating
//! tail) the inverse is the exact per-sample solve of the piecewise-linear branch and
//! references beyond a saturation level are clipped.
//!
//! **Static envelope.** G may carry a monotone static term E(u) ([`super::envelope`]):
//! G[u] = c + a₀u + E(u) + Σ aᵢ F_{rᵢ}[u], for a static curve the plays cannot follow (a
//! saturating magnet). G then has no PI-shaped inverse; its inverse is the per-sample solve,
//! unbounded on a side where the final slope âₙ plus E's end slope there is > 0.
//!
//! References: M. Brokate, J. Sprekels, *Hysteresis and Phase Transitions*, Springer 1996;
//! P. Krejčí, K. Kuhnen, "Inverse control of systems with hysteresis and creep", IEE Proc.
//! Control Theory Appl. 148 (2001) 185–192; K. Kuhnen, "Modeling, identification and
//! compensation of complex hysteretic nonlinearities: a modified Prandtl–Ishlinskii
//! approach", European Journal of Control 9 (2003) 407–418.

use super::elementary::{
    check_finite, oriented_invert, oriented_simulate, play_step, solve_monotone,
    validate_thresholds, Branch, Core, Orientation,
};
use super::envelope::Envelope;
use super::{HysteresisOperator, Inversion};
use crate::model::{Parameter, ParameterSet};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// A Prandtl–Ishlinskii operator y = c + a₀u + Σ aᵢ F_{rᵢ}\[u\] in an [`Orientation`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PrandtlIshlinskii {
    a0: f64,
    weights: Vec<f64>,
    thresholds: Vec<f64>,
    offset: f64,
    orientation: Orientation,
    /// The static envelope E(u), if any (absent from files without one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    envelope: Option<Envelope>,
}

impl PrandtlIshlinskii {
    /// A PI operator with linear weight `a0`, play weights aᵢ on thresholds rᵢ (strictly
    /// increasing, > 0), output offset c. Every partial sum âᵢ must be ≥ 0 (a monotone
    /// operator) and at least one weight non-zero.
    pub fn new(
        a0: f64,
        weights: Vec<f64>,
        thresholds: Vec<f64>,
        offset: f64,
        orientation: Orientation,
    ) -> Result<Self> {
        Self::with_static_envelope(a0, weights, thresholds, offset, orientation, None)
    }

    /// A PI operator as [`PrandtlIshlinskii::new`] with the static envelope `envelope` added
    /// to G (`model::operators::envelope`); the plays' weights may then all be zero if the
    /// envelope has a positive slope value.
    pub fn with_static_envelope(
        a0: f64,
        weights: Vec<f64>,
        thresholds: Vec<f64>,
        offset: f64,
        orientation: Orientation,
        envelope: Option<Envelope>,
    ) -> Result<Self> {
        check_finite("a0", a0)?;
        check_finite("c", offset)?;
        if a0 < 0.0 {
            return Err(Error::InvalidParameter {
                name: "a0".into(),
                value: a0,
                reason: "must be >= 0 for a monotone operator".into(),
            });
        }
        validate_thresholds("r", &thresholds)?;
        if weights.len() != thresholds.len() {
            return Err(Error::InvalidModel(format!(
                "PI: {} weights for {} thresholds; give one weight per threshold",
                weights.len(),
                thresholds.len()
            )));
        }
        let mut partial = a0;
        for (i, &a) in weights.iter().enumerate() {
            check_finite(&format!("a{}", i + 1), a)?;
            partial += a;
            if partial < -1e-12 * (a0.abs() + a.abs()) {
                return Err(Error::InvalidParameter {
                    name: format!("a{}", i + 1),
                    value: a,
                    reason: "the partial sum a0 + … + ai is negative: the operator would not \
                             be monotone; use non-negative weights"
                        .into(),
                });
            }
        }
        let sloped = envelope
            .as_ref()
            .is_some_and(|e| e.slopes().iter().any(|&c| c > 0.0));
        if a0 == 0.0 && weights.iter().all(|&a| a == 0.0) && !sloped {
            return Err(Error::InvalidParameter {
                name: "a0".into(),
                value: 0.0,
                reason: "every weight is zero: the operator is constant".into(),
            });
        }
        Ok(Self {
            a0,
            weights,
            thresholds,
            offset,
            orientation,
            envelope,
        })
    }

    /// The static envelope E(u) of G, if any.
    pub fn envelope(&self) -> Option<&Envelope> {
        self.envelope.as_ref()
    }

    /// a₀, the weight of the input itself (the play of threshold 0).
    pub fn a0(&self) -> f64 {
        self.a0
    }
    /// The play weights a₁ … aₙ.
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }
    /// The thresholds r₁ < … < rₙ.
    pub fn thresholds(&self) -> &[f64] {
        &self.thresholds
    }
    /// The output offset c.
    pub fn offset(&self) -> f64 {
        self.offset
    }
    /// The orientation (Γ = G or G⁻¹, sign).
    pub fn orientation(&self) -> Orientation {
        self.orientation
    }

    /// The analytic inverse's parameters (b₀, [b₁ … bₙ], [s₁ … sₙ]) of Krejčí & Kuhnen (2001),
    /// or None when some âᵢ = a₀ + … + aᵢ is not > 0 or G has a static envelope.
    pub fn inverse_parameters(&self) -> Option<(f64, Vec<f64>, Vec<f64>)> {
        if self.a0 <= 0.0 || self.envelope.is_some() {
            return None;
        }
        let n = self.weights.len();
        let (mut b, mut s) = (Vec::with_capacity(n), Vec::with_capacity(n));
        let mut hat_prev = self.a0;
        for i in 0..n {
            let hat = hat_prev + self.weights[i];
            if hat <= 0.0 {
                return None;
            }
            let ri = self.thresholds[i];
            let si = self.a0 * ri
                + (0..i)
                    .map(|j| self.weights[j] * (ri - self.thresholds[j]))
                    .sum::<f64>();
            b.push(-self.weights[i] / (hat * hat_prev));
            s.push(si);
            hat_prev = hat;
        }
        Some((1.0 / self.a0, b, s))
    }

    /// The final slope âₙ = a₀ + Σ aᵢ (0 when the operator saturates).
    pub fn final_slope(&self) -> f64 {
        self.a0 + self.weights.iter().sum::<f64>()
    }

    /// Whether G grows without bound as u → −∞ and as u → +∞: its final slope plus the
    /// envelope's end slope on that side is > 0.
    pub fn unbounded(&self) -> (bool, bool) {
        let (below, above) = self
            .envelope
            .as_ref()
            .map_or((0.0, 0.0), Envelope::end_slopes);
        let slope = self.final_slope();
        (slope + below > 0.0, slope + above > 0.0)
    }

    /// How far from the previous input `u_prev` the branch may still bend, the numerical
    /// inverse's bracket: 2rₙ (beyond it every play moves with the input), and with an
    /// envelope as far as its range reaches, max(2rₙ, hi − u_prev, u_prev − lo) (beyond it
    /// E is a tangent line). The bracket is grown past it only on an unbounded side.
    pub fn solve_reach(&self, u_prev: f64) -> f64 {
        let plays = 2.0 * self.thresholds.last().copied().unwrap_or(0.0);
        match &self.envelope {
            Some(e) => plays.max(e.hi() - u_prev).max(u_prev - e.lo()),
            None => plays,
        }
    }

    /// c + a₀u + E(u), the static part of G (summed in that order).
    fn static_part(&self, u: f64) -> f64 {
        let y = self.offset + self.a0 * u;
        match &self.envelope {
            Some(e) => y + e.value(u),
            None => y,
        }
    }

    /// G's output for input `u` from play states `z` (not updated).
    fn branch(&self, z: &[f64], u: f64) -> f64 {
        self.static_part(u)
            + self
                .weights
                .iter()
                .zip(&self.thresholds)
                .zip(z)
                .map(|((a, r), &zi)| a * play_step(zi, u, *r))
                .sum::<f64>()
    }
}

/// The state of the PI inverse G⁻¹: the analytic one's plays on its thresholds sᵢ with its
/// weights (b₀, bᵢ) precomputed, or the play states of G and the previous input for the
/// per-sample solve (see the module doc).
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum PiBackward {
    /// G⁻¹\[v\] = b₀(v − c) + Σ bᵢ F_{sᵢ}\[v − c\] (Krejčí & Kuhnen 2001).
    Analytic {
        /// b₀ = 1/a₀.
        b0: f64,
        /// The plays' weights bᵢ.
        b: Vec<f64>,
        /// The plays' thresholds sᵢ.
        s: Vec<f64>,
        /// The plays' states.
        z: Vec<f64>,
    },
    /// The exact per-sample solve of G's branch.
    Numerical {
        /// G's play states.
        z: Vec<f64>,
        /// The previous input (the bracket's centre).
        u_prev: f64,
    },
}

impl Core for PrandtlIshlinskii {
    /// The play states z₁ … zₙ.
    type Forward = Vec<f64>;
    type Backward = PiBackward;

    fn orientation(&self) -> Orientation {
        self.orientation
    }

    fn forward_state(&self, _horizon: Option<usize>) -> Vec<f64> {
        vec![0.0; self.weights.len()]
    }

    /// y = (c + a₀u + E(u)) + a₁z₁ + … + aₙzₙ, summed in that order.
    fn forward_step(&self, z: &mut Vec<f64>, u: f64) -> f64 {
        let mut y = self.static_part(u);
        for ((zi, a), &r) in z.iter_mut().zip(&self.weights).zip(&self.thresholds) {
            *zi = play_step(*zi, u, r);
            y += a * *zi;
        }
        y
    }

    fn backward_state(&self, _horizon: Option<usize>) -> PiBackward {
        let z = vec![0.0; self.weights.len()];
        match self.inverse_parameters() {
            Some((b0, b, s)) => PiBackward::Analytic { b0, b, s, z },
            None => PiBackward::Numerical { z, u_prev: 0.0 },
        }
    }

    /// Analytic: u = b₀w + b₁F_{s₁}\[w\] + … (w = v − c), summed in that order. Numerical:
    /// the branch from the current play states solved for v, then the plays advanced.
    fn backward_step(&self, state: &mut PiBackward, v: f64) -> (f64, bool) {
        match state {
            PiBackward::Analytic { b0, b, s, z } => {
                let w = v - self.offset;
                let mut u = *b0 * w;
                for ((zi, bi), &si) in z.iter_mut().zip(b.iter()).zip(s.iter()) {
                    *zi = play_step(*zi, w, si);
                    u += bi * *zi;
                }
                (u, false)
            }
            PiBackward::Numerical { z, u_prev } => {
                let (unbounded_below, unbounded_above) = self.unbounded();
                let branch = Branch {
                    center: *u_prev,
                    span: self.solve_reach(*u_prev)
                        + 1e-9 * (1.0 + u_prev.abs())
                        + f64::MIN_POSITIVE,
                    unbounded_below,
                    unbounded_above,
                };
                let (u, clipped) = solve_monotone(|x| self.branch(z, x), v, branch);
                for (zi, r) in z.iter_mut().zip(&self.thresholds) {
                    *zi = play_step(*zi, u, *r);
                }
                *u_prev = u;
                (u, clipped)
            }
        }
    }
}

impl HysteresisOperator for PrandtlIshlinskii {
    fn family(&self) -> &'static str {
        <Self as super::OperatorFamily>::NAME
    }

    /// `a0, a1…an, r1…rn (fixed), c`, then with an envelope `e0…ed, e_lo, e_hi (fixed)`.
    fn parameters(&self) -> ParameterSet {
        let base = pi_parameters(
            self.a0,
            &self.weights,
            &self.thresholds,
            self.offset,
            "a",
            "r",
        );
        let Some(e) = &self.envelope else {
            return base;
        };
        let mut p: Vec<Parameter> = base.iter().cloned().collect();
        for (j, &c) in e.slopes().iter().enumerate() {
            p.push(Parameter::new(format!("e{j}"), c).bounds(0.0, f64::INFINITY));
        }
        p.push(Parameter::new("e_lo", e.lo()).fixed(true));
        p.push(Parameter::new("e_hi", e.hi()).fixed(true));
        ParameterSet::new(p).unwrap_or_default()
    }

    fn simulate(&self, u: &[f64]) -> Result<Vec<f64>> {
        oriented_simulate(self, u)
    }

    fn invert(&self, reference: &[f64]) -> Result<Inversion> {
        oriented_invert(self, reference)
    }

    /// Twice the largest threshold: every play then sits on an edge.
    fn memory_reach(&self) -> f64 {
        2.0 * self.thresholds.last().copied().unwrap_or(0.0)
    }
}

/// The parameter list `a0, a1…an, r1…rn (fixed), c` shared by the PI-like families.
pub(crate) fn pi_parameters(
    a0: f64,
    weights: &[f64],
    thresholds: &[f64],
    offset: f64,
    a: &str,
    r: &str,
) -> ParameterSet {
    let mut p = vec![Parameter::new(format!("{a}0"), a0).bounds(0.0, f64::INFINITY)];
    for (i, &w) in weights.iter().enumerate() {
        p.push(Parameter::new(format!("{a}{}", i + 1), w));
    }
    for (i, &t) in thresholds.iter().enumerate() {
        p.push(Parameter::new(format!("{r}{}", i + 1), t).fixed(true));
    }
    p.push(Parameter::new("c", offset));
    ParameterSet::new(p).unwrap_or_default()
}

impl super::OperatorFamily for PrandtlIshlinskii {
    const NAME: &'static str = "pi";
    const TITLE: &'static str = "Prandtl–Ishlinskii (Krejčí & Kuhnen 2001)";

    fn example() -> Result<Self> {
        Self::new(
            0.5,
            vec![0.3, 0.2, 0.1],
            vec![0.1, 0.3, 0.6],
            0.05,
            Orientation::default(),
        )
    }

    /// The example with a saturating static envelope on [−1, 1] (slope values 0.1, 0.8,
    /// 0.05: steep in the middle, flat at the ends).
    fn variants() -> Result<Vec<(&'static str, Self)>> {
        let example = Self::example()?;
        let envelope = Envelope::new(-1.0, 1.0, vec![0.1, 0.8, 0.05])?;
        let enveloped = Self::with_static_envelope(
            example.a0,
            example.weights,
            example.thresholds,
            example.offset,
            example.orientation,
            Some(envelope),
        )?;
        Ok(vec![("envelope", enveloped)])
    }

    fn checked(self) -> Result<Self> {
        Self::with_static_envelope(
            self.a0,
            self.weights,
            self.thresholds,
            self.offset,
            self.orientation,
            self.envelope,
        )
    }

    /// Values a0, a1 … an, r1 … rn, c, then with an envelope e0 … ed, e_lo, e_hi.
    fn with_values(&self, values: &[f64]) -> Result<Self> {
        super::check_values(self, values)?;
        let n = self.weights().len();
        let envelope = match &self.envelope {
            Some(e) => {
                let d = e.slopes().len();
                let at = 2 * n + 2;
                Some(Envelope::new(
                    values[at + d],
                    values[at + d + 1],
                    values[at..at + d].to_vec(),
                )?)
            }
            None => None,
        };
        Self::with_static_envelope(
            values[0],
            values[1..=n].to_vec(),
            values[n + 1..=2 * n].to_vec(),
            values[2 * n + 1],
            self.orientation(),
            envelope,
        )
    }

    /// a0 … an, c and the envelope's slope values (not for the inverse-operator
    /// parameterisation).
    fn output_scale(&self) -> Option<Vec<usize>> {
        let n = self.weights().len();
        let d = self.envelope.as_ref().map_or(0, |e| e.slopes().len());
        (!self.orientation().inverse).then(|| {
            (0..=n)
                .chain([2 * n + 1])
                .chain(2 * n + 2..2 * n + 2 + d)
                .collect()
        })
    }
}
