//! The Krasnosel'skii–Pokrovskii (KP) operator: a Preisach-type superposition of continuous
//! hysterons — KP kernels — with non-negative weights on a triangular grid of threshold pairs.
//!
//! **Kernel.** For a threshold pair s₁ ≤ s₂ and a ridge width a > 0, let
//!
//! ρ_a(x) = min(1, max(−1, 2x/a))
//!
//! be the saturating ramp (ridge) that climbs from −1 to +1 over [−a/2, a/2]. The kernel's
//! state ξ ∈ [−1, 1] is updated at every sample by
//!
//! ξₖ = max(ρ_a(uₖ − s₂), min(ρ_a(uₖ − s₁), ξₖ₋₁)),
//!
//! so it climbs along the ridge ρ_a(u − s₂) while the input rises through [s₂ − a/2, s₂ + a/2],
//! falls along ρ_a(u − s₁) while the input falls through [s₁ − a/2, s₁ + a/2], and holds its
//! value in between. Because ρ_a is non-decreasing it commutes with max and min, so the kernel
//! is exactly ρ_a(F_r\[u\] − m): the play operator F_r of half-width r = (s₂ − s₁)/2 (centre
//! m = (s₁ + s₂)/2) followed by the ramp of width a (Krasnosel'skii & Pokrovskii 1989). Tracking
//! ξ itself costs one max and one min per kernel and sample. A kernel on the diagonal
//! (s₁ = s₂) has no memory: it is the anhysteretic ramp ρ_a(u − s). As a → 0 a kernel tends to
//! the relay that switches up at s₂ and down at s₁, and the operator to the Preisach model.
//!
//! **Ridge convention.** Banks, Kurdila & Webb (1997) write the ridge as starting at the
//! threshold (rising over [s₂, s₂ + a], falling over [s₁, s₁ + a]); hysid centres it on the
//! threshold, so that s₁ and s₂ are the midpoints of the falling and rising ramps and the
//! kernel is the play of half-width (s₂ − s₁)/2 around (s₁ + s₂)/2. The two forms describe the
//! same family: the kernel of theirs with thresholds (s₁, s₂) is ours with (s₁ + a/2, s₂ + a/2).
//!
//! **Operator.** With thresholds t₀ < t₁ < … < t_{n−1} and the n(n + 1)/2 pairs (i, j), j ≤ i
//! (s₂ = tᵢ the rising, s₁ = tⱼ the falling threshold),
//!
//! G\[u\] = c + a₀u + Σ_{j ≤ i} μ_{ij} ξ_{ij}\[u\],   μ_{ij} ≥ 0, a₀ ≥ 0,
//!
//! linear in (a₀, μ, c). Every branch is continuous and non-decreasing in u, and Lipschitz
//! with constant a₀ + 2Σμ/a (no relay jumps). The weights are stored in the order (0,0), (1,0),
//! (1,1), (2,0), … (row i = rising threshold, column j = falling threshold), as the Preisach
//! cells; their parameter names are `mu{i+1}_{j+1}`. The thresholds and the ridge width are
//! the operator's *structure* (fixed by the identification recipe, stored in the model file),
//! not estimated parameters. [`Kp::uniform_thresholds`] gives the recipe's grid: the midpoints
//! of n equal intervals over the input range, so that with a equal to the interval width the
//! ramps of the rising thresholds tile the range as the Preisach cells do.
//!
//! **Initial state.** Every kernel's play starts at 0, the project's convention for the play
//! operator (F_r\[u\]₋₁ = 0, as if the input had been 0 before the first sample):
//!
//! ξ₋₁ = ρ_a(−(s₁ + s₂)/2),   so   ξ₀ = max(ρ_a(u₀ − s₂), min(ρ_a(u₀ − s₁), ξ₋₁)).
//!
//! Kernels centred above a/2 start down (−1), those centred below −a/2 up (+1), those in
//! between on their ramp: the demagnetised state of a Preisach plane (boundary α = −β),
//! smoothed by the ridge. It is the state of a device at rest at input 0 and, for a record
//! that starts part-way along a branch, a better guess than a saturated plane: a record that
//! starts falling from an earlier maximum is seen as a fall from 0. (On the piezo record of
//! `data/piezo`, which starts falling from +150 V, negative saturation instead of this state
//! costs the default fit 0.8 point of validation fit %.)
//!
//! **Orientation.** The core operator G above is counter-clockwise (the output lags the input);
//! clockwise and decreasing loops use the [`Orientation`] convention of the other
//! linear-in-weights families (Γ = ±G or ±G⁻¹).
//!
//! **Inverse.** On a sample the output as a function of the new input x,
//! f(x) = c + a₀x + Σ μ_{ij} max(ρ_a(x − tᵢ), min(ρ_a(x − tⱼ), ξ_{ij})), is continuous and
//! non-decreasing, piecewise linear with breakpoints at tᵢ ± a/2, constant (or linear with slope
//! a₀) outside [t₀ − a/2, t_{n−1} + a/2]. The inverse solves f(x) = reference per sample by
//! bracketing and safeguarded regula falsi ([`super::solve_monotone`]: at most 300 iterations,
//! and when a₀ > 0 at most about 500 doublings of the bracket), then advances the kernel states
//! with the solution. A reference beyond the saturation levels c ± Σμ of an operator without a
//! reversible part is clipped to the level and listed in [`Inversion::clipped`].
//!
//! | symbol | meaning | constraint |
//! | --- | --- | --- |
//! | tᵢ (`thresholds`) | threshold grid (input units) | finite, strictly increasing, n ≥ 1 |
//! | a (`width`) | ridge width (input units) | finite, > 0 |
//! | a₀ (`a0`) | reversible slope | ≥ 0 |
//! | μ_{ij} (`mu{i+1}_{j+1}`) | kernel weights (output units) | ≥ 0 |
//! | c (`c`) | offset (output units) | finite |
//!
//! References: M. A. Krasnosel'skii, A. V. Pokrovskii, *Systems with Hysteresis*, Springer
//! 1989; H. T. Banks, A. J. Kurdila, G. Webb, "Identification of hysteretic control influence
//! operators representing smart actuators, part I: formulation", Mathematical Problems in
//! Engineering 3 (1997) 287–328; G. V. Webb, D. C. Lagoudas, A. J. Kurdila, "Hysteresis
//! modeling of SMA actuators for control applications", J. Intelligent Material Systems and
//! Structures 9 (1998) 432–448.
//!
//! ```
//! use hysid::model::operators::{HysteresisOperator, Kp, Orientation};
//! let t = Kp::uniform_thresholds(-1.0, 1.0, 4).unwrap();
//! let kp = Kp::new(t, 0.3, vec![0.1; 10], 0.5, 0.0, Orientation::default()).unwrap();
//! let u = [0.0, 0.8, -0.6, 0.4, -0.2];
//! let y = kp.simulate(&u).unwrap();
//! let back = kp.invert(&y).unwrap();
//! assert!(back.u.iter().zip(&u).all(|(a, b)| (a - b).abs() < 1e-9));
//! ```

use super::elementary::{
    check_finite, oriented_invert, oriented_simulate, solve_monotone, Branch, Core, Orientation,
};
use super::{HysteresisOperator, Inversion};
use crate::model::{Parameter, ParameterSet};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::cell::RefCell;

/// The ridge ρ_a(x) = min(1, max(−1, 2x/a)), given 2/a.
#[inline(always)]
fn ridge(x: f64, two_over_a: f64) -> f64 {
    (x * two_over_a).clamp(-1.0, 1.0)
}

/// The states ξ_{ij} of the kernels of a threshold grid with a ridge width, in the weights'
/// order (0,0), (1,0), (1,1), (2,0), …; each advanced by ξ ← max(ρ_a(x − tᵢ), min(ρ_a(x − tⱼ), ξ)).
///
/// This is the operator's memory and, per sample, its regressor row: the identification recipe
/// builds its least-squares problem from [`KernelStates::values`].
#[derive(Clone, Debug, PartialEq)]
pub struct KernelStates {
    thresholds: Vec<f64>,
    two_over_a: f64,
    xi: Vec<f64>,
    ramps: Vec<f64>,
}

impl KernelStates {
    /// The initial state of the kernels of the grid `thresholds` with ridge width `width`
    /// (as validated by [`Kp::new`]): every kernel's play at 0, ξ_{ij} = ρ_a(−(tᵢ + tⱼ)/2)
    /// (see the module documentation).
    pub fn new(thresholds: &[f64], width: f64) -> Self {
        let two_over_a = 2.0 / width;
        let n = thresholds.len();
        let mut xi = Vec::with_capacity(n * (n + 1) / 2);
        for (i, &ti) in thresholds.iter().enumerate() {
            for &tj in &thresholds[..=i] {
                xi.push(ridge(-0.5 * (ti + tj), two_over_a));
            }
        }
        Self {
            thresholds: thresholds.to_vec(),
            two_over_a,
            xi,
            ramps: vec![0.0; n],
        }
    }

    /// The kernel states, order (0,0), (1,0), (1,1), (2,0), …
    pub fn values(&self) -> &[f64] {
        &self.xi
    }

    /// ρ_a(x − tᵢ) for every threshold into `ramps`.
    #[inline(always)]
    fn ramps_at(thresholds: &[f64], two_over_a: f64, x: f64, ramps: &mut [f64]) {
        for (r, &t) in ramps.iter_mut().zip(thresholds) {
            *r = ridge(x - t, two_over_a);
        }
    }

    /// Moves the input to `x`.
    pub fn advance(&mut self, x: f64) {
        Self::ramps_at(&self.thresholds, self.two_over_a, x, &mut self.ramps);
        let mut k = 0;
        for (i, &up) in self.ramps.iter().enumerate() {
            let row = &mut self.xi[k..k + i + 1];
            for (xi, &down) in row.iter_mut().zip(&self.ramps[..=i]) {
                // max(up, min(down, ξ)) by comparisons: the states are finite, and these
                // compile to the packed min/max instructions
                let held = if down < *xi { down } else { *xi };
                *xi = if up > held { up } else { held };
            }
            k += i + 1;
        }
    }

    /// Moves the input to `x` and returns Σ wₖξₖ (summed in four interleaved partial sums,
    /// so that the sum is not one chain of dependent additions).
    fn advance_weighted(&mut self, weights: &[f64], x: f64) -> f64 {
        self.advance(x);
        let mut acc = [0.0; 4];
        let mut chunks = self.xi.chunks_exact(4).zip(weights.chunks_exact(4));
        for (xi, w) in &mut chunks {
            for l in 0..4 {
                acc[l] += w[l] * xi[l];
            }
        }
        let tail = self.xi.len() - self.xi.len() % 4;
        let rest: f64 = self.xi[tail..]
            .iter()
            .zip(&weights[tail..])
            .map(|(xi, w)| w * xi)
            .sum();
        (acc[0] + acc[1]) + (acc[2] + acc[3]) + rest
    }

    /// Σ wₖξₖ if the input moved to `x`, without moving it; `ramps` is scratch space of one
    /// value per threshold.
    fn trial_weighted(&self, weights: &[f64], x: f64, ramps: &mut [f64]) -> f64 {
        Self::ramps_at(&self.thresholds, self.two_over_a, x, ramps);
        let mut k = 0;
        let mut acc = 0.0;
        for (i, &up) in ramps.iter().enumerate() {
            let row = &self.xi[k..k + i + 1];
            let w = &weights[k..k + i + 1];
            for ((&xi, &down), &wk) in row.iter().zip(&ramps[..=i]).zip(w) {
                let held = if down < xi { down } else { xi };
                acc += wk * if up > held { up } else { held };
            }
            k += i + 1;
        }
        acc
    }
}

/// A Krasnosel'skii–Pokrovskii operator G\[u\] = c + a₀u + Σ μ_{ij} ξ_{ij}\[u\] in an
/// [`Orientation`] (see the [module documentation](self) for the kernel convention).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Kp {
    thresholds: Vec<f64>,
    width: f64,
    weights: Vec<f64>,
    a0: f64,
    offset: f64,
    orientation: Orientation,
}

impl Kp {
    /// A KP operator on the threshold grid `thresholds` (finite, strictly increasing, at least
    /// one) with ridge width `width` > 0, kernel weights μ_{ij} ≥ 0 in the order (0,0), (1,0),
    /// (1,1), (2,0), … (n(n + 1)/2 of them for n thresholds), a reversible slope a₀ ≥ 0 and an
    /// offset c. Errors name the rule that a value breaks; an operator whose weights and a₀ are
    /// all zero (a constant) is refused.
    pub fn new(
        thresholds: Vec<f64>,
        width: f64,
        weights: Vec<f64>,
        a0: f64,
        offset: f64,
        orientation: Orientation,
    ) -> Result<Self> {
        if thresholds.is_empty() {
            return Err(Error::InvalidModel(
                "KP: the threshold grid is empty; give at least one threshold".into(),
            ));
        }
        for (i, &t) in thresholds.iter().enumerate() {
            if !t.is_finite() {
                return Err(Error::InvalidParameter {
                    name: format!("t{}", i + 1),
                    value: t,
                    reason: "KP thresholds must be finite".into(),
                });
            }
            if i > 0 && t <= thresholds[i - 1] {
                return Err(Error::InvalidParameter {
                    name: format!("t{}", i + 1),
                    value: t,
                    reason: format!(
                        "KP thresholds must be strictly increasing (t{} = {}); sort the grid \
                         and remove duplicates",
                        i,
                        thresholds[i - 1]
                    ),
                });
            }
        }
        if !(width.is_finite() && width > 0.0) {
            return Err(Error::InvalidParameter {
                name: "a".into(),
                value: width,
                reason: "the KP ridge width a must be finite and > 0".into(),
            });
        }
        check_finite("c", offset)?;
        let n = thresholds.len();
        let kernels = n * (n + 1) / 2;
        if weights.len() != kernels {
            return Err(Error::InvalidModel(format!(
                "KP: {} weights for a grid of {n} thresholds, which has {kernels} kernels",
                weights.len()
            )));
        }
        if !(a0.is_finite() && a0 >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "a0".into(),
                value: a0,
                reason: "the KP reversible slope a0 must be finite and >= 0".into(),
            });
        }
        if let Some(k) = weights.iter().position(|w| !(w.is_finite() && *w >= 0.0)) {
            let (i, j) = pair(k);
            return Err(Error::InvalidParameter {
                name: format!("mu{}_{}", i + 1, j + 1),
                value: weights[k],
                reason: "KP weights must be finite and >= 0".into(),
            });
        }
        if a0 == 0.0 && weights.iter().all(|&w| w == 0.0) {
            return Err(Error::InvalidParameter {
                name: "a0".into(),
                value: 0.0,
                reason: "every KP weight and a0 is zero: the operator is constant".into(),
            });
        }
        Ok(Self {
            thresholds,
            width,
            weights,
            a0,
            offset,
            orientation,
        })
    }

    /// The midpoints of `levels` equal intervals over [lower, upper]: the identification
    /// recipe's grid.
    pub fn uniform_thresholds(lower: f64, upper: f64, levels: usize) -> Result<Vec<f64>> {
        if !(lower.is_finite() && upper.is_finite() && lower < upper) || levels == 0 {
            return Err(Error::InvalidModel(format!(
                "KP grid [{lower}, {upper}] with {levels} intervals: need finite lower < upper \
                 and at least one interval"
            )));
        }
        let h = (upper - lower) / levels as f64;
        Ok((0..levels).map(|k| lower + (k as f64 + 0.5) * h).collect())
    }

    /// The threshold grid t₀ < … < t_{n−1}.
    pub fn thresholds(&self) -> &[f64] {
        &self.thresholds
    }
    /// The number of thresholds n.
    pub fn levels(&self) -> usize {
        self.thresholds.len()
    }
    /// The ridge width a.
    pub fn width(&self) -> f64 {
        self.width
    }
    /// The kernel weights μ_{ij}, order (0,0), (1,0), (1,1), (2,0), …
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }
    /// The reversible slope a₀.
    pub fn a0(&self) -> f64 {
        self.a0
    }
    /// The offset c.
    pub fn offset(&self) -> f64 {
        self.offset
    }
    /// The orientation.
    pub fn orientation(&self) -> Orientation {
        self.orientation
    }

    /// The interval outside which every kernel is saturated.
    fn active_range(&self) -> (f64, f64) {
        let n = self.thresholds.len();
        (
            self.thresholds[0] - 0.5 * self.width,
            self.thresholds[n - 1] + 0.5 * self.width,
        )
    }
}

/// The pair (i, j), j ≤ i, of weight index k in the order (0,0), (1,0), (1,1), (2,0), …
fn pair(k: usize) -> (usize, usize) {
    let mut i = 0;
    while (i + 1) * (i + 2) / 2 <= k {
        i += 1;
    }
    (i, k - i * (i + 1) / 2)
}

/// The kernel states and, for the inverse, scratch space of one ramp per threshold (the
/// trial evaluations of the solve).
pub(crate) type KpBackward = (KernelStates, RefCell<Vec<f64>>);

impl Core for Kp {
    type Forward = KernelStates;
    type Backward = KpBackward;

    fn orientation(&self) -> Orientation {
        self.orientation
    }

    fn forward_state(&self, _horizon: Option<usize>) -> KernelStates {
        KernelStates::new(&self.thresholds, self.width)
    }

    /// (c + a₀u) + Σ μξ (the sum in four interleaved partial sums, see
    /// [`KernelStates`]).
    fn forward_step(&self, states: &mut KernelStates, u: f64) -> f64 {
        let s = states.advance_weighted(&self.weights, u);
        self.offset + self.a0 * u + s
    }

    fn backward_state(&self, _horizon: Option<usize>) -> KpBackward {
        (
            KernelStates::new(&self.thresholds, self.width),
            RefCell::new(vec![0.0; self.levels()]),
        )
    }

    /// The monotone branch from the current kernel states solved for v (module doc), then
    /// the states advanced with the solution.
    fn backward_step(&self, (states, scratch): &mut KpBackward, v: f64) -> (f64, bool) {
        let (lo, hi) = self.active_range();
        let branch = Branch {
            center: 0.5 * (lo + hi),
            span: 0.5 * (hi - lo) * (1.0 + 1e-12),
            unbounded_below: self.a0 > 0.0,
            unbounded_above: self.a0 > 0.0,
        };
        let trial = |x: f64| {
            let mut ramps = scratch.borrow_mut();
            let s = states.trial_weighted(&self.weights, x, &mut ramps);
            self.offset + self.a0 * x + s
        };
        let (u, clipped) = solve_monotone(trial, v, branch);
        states.advance(u);
        (u, clipped)
    }
}

impl HysteresisOperator for Kp {
    fn family(&self) -> &'static str {
        <Self as super::OperatorFamily>::NAME
    }

    fn parameters(&self) -> ParameterSet {
        let mut p = Vec::with_capacity(self.weights.len() + 2);
        p.push(Parameter::new("a0", self.a0).bounds(0.0, f64::INFINITY));
        for (k, &w) in self.weights.iter().enumerate() {
            let (i, j) = pair(k);
            p.push(Parameter::new(format!("mu{}_{}", i + 1, j + 1), w).bounds(0.0, f64::INFINITY));
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

    /// Twice the threshold grid's extent from 0 and the ridge width: every kernel saturates.
    fn memory_reach(&self) -> f64 {
        let (lo, hi) = (
            self.thresholds.first().copied().unwrap_or(0.0),
            self.thresholds.last().copied().unwrap_or(0.0),
        );
        2.0 * (lo.abs() + hi.abs()) + 2.0 * self.width.abs()
    }
}

impl super::OperatorFamily for Kp {
    const NAME: &'static str = "kp";
    const TITLE: &'static str =
        "Krasnosel'skii–Pokrovskii kernels on the Preisach triangle (Krasnosel'skii & Pokrovskii 1989; Banks, Kurdila & Webb 1997)";

    fn example() -> Result<Self> {
        let thresholds = Self::uniform_thresholds(-1.0, 1.0, 3)?;
        let weights = vec![0.1, 0.2, 0.05, 0.3, 0.1, 0.15];
        Self::new(thresholds, 0.3, weights, 0.2, 0.0, Orientation::default())
    }

    /// The same operator rebuilt through [`Kp::new`]: the check for a structure read from a
    /// model file (serde does not validate).
    fn checked(self) -> Result<Self> {
        Self::new(
            self.thresholds,
            self.width,
            self.weights,
            self.a0,
            self.offset,
            self.orientation,
        )
    }

    /// Values a0, μ…, c ([`HysteresisOperator::parameters`] order) on the same thresholds,
    /// ridge width and orientation.
    fn with_values(&self, values: &[f64]) -> Result<Self> {
        super::check_values(self, values)?;
        let n = self.weights.len();
        Self::new(
            self.thresholds.clone(),
            self.width,
            values[1..=n].to_vec(),
            values[0],
            values[n + 1],
            self.orientation,
        )
    }

    /// a₀, every μ and c: Γ\[u\] scaled by s > 0 is these multiplied by s; None for an
    /// inverse-parameterised orientation (Γ = ±G⁻¹), whose output is not linear in them.
    fn output_scale(&self) -> Option<Vec<usize>> {
        (!self.orientation.inverse).then(|| (0..self.weights.len() + 2).collect())
    }
}
