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
//! non-decreasing, and linear between its breakpoints: the ramp edges tᵢ ± a/2 (fixed), and
//! where a kernel leaves its held value, x = tᵢ + aξ_{ij}/2 on the rising side and
//! x = tⱼ + aξ_{ij}/2 on the falling side (ρ_a(x − tᵢ) = ξ or ρ_a(x − tⱼ) = ξ; the diagonal
//! kernels, ξ_{ii} = ρ_a(x − tᵢ), have none). Outside [t₀ − a/2, t_{n−1} + a/2] only a₀x
//! moves. The kernel states are ordered along every row and column of the triangle: ξ_{ij}
//! does not increase with j (a higher falling threshold) nor with i (a higher rising one) —
//! true of the initial state, and kept by the update, whose max and min are monotone and
//! whose ramps ρ_a(x − t) do not increase with t (also in rounded arithmetic). So row i's
//! switch points tᵢ + aξ_{ij}/2 are sorted in j, column j's tⱼ + aξ_{ij}/2 in i, and the
//! inverse solves f(x) = v in a number of trials fixed by the grid ([`Kp::inverse_trials`]):
//!
//! 1. f at the two outer edges; a reference beyond them is reached on the line of slope a₀
//!    or, without a reversible part, clipped to the saturation level c ± Σμ and
//!    listed in [`Inversion::clipped`];
//! 2. bisection over the sorted interior ramp edges, keeping f(a) ≤ v ≤ f(b): the bracket
//!    then lies between two neighbouring edges, where every ramp is linear or saturated;
//! 3. for every row and column whose ramp covers the bracket, bisection over its sorted
//!    switch points inside the bracket (comparisons only for the points outside it);
//! 4. f is now linear on [a, b]: the root a + (b − a)(v − f(a))/(f(b) − f(a)).
//!
//! A trial equal to v ends the solve at once. The kernel states then advance with the
//! solution. (A state whose rows were not ordered would only leave a breakpoint in the last
//! bracket: the root stays inside the bracket, every narrowing being by an evaluated trial.)
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
    check_finite, clip_tolerance, halvings, oriented_invert, oriented_simulate, Core, Orientation,
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
}

/// The pair (i, j), j ≤ i, of weight index k in the order (0,0), (1,0), (1,1), (2,0), …
fn pair(k: usize) -> (usize, usize) {
    let mut i = 0;
    while (i + 1) * (i + 2) / 2 <= k {
        i += 1;
    }
    (i, k - i * (i + 1) / 2)
}

/// The ramp edges tᵢ ± a/2 of a threshold grid, from the highest down, without repeats: the
/// breakpoints of f that do not move with the state (module docs, "Inverse"; also the
/// exported code's table).
pub(crate) fn ramp_edges(thresholds: &[f64], width: f64) -> Vec<f64> {
    let h = 0.5 * width;
    let mut edges: Vec<f64> = thresholds.iter().flat_map(|&t| [t - h, t + h]).collect();
    edges.sort_by(|x, y| y.total_cmp(x));
    edges.dedup();
    edges
}

/// The inverse's state: the kernels, scratch space of one ramp per threshold (the trial
/// evaluations of the solve) and the sorted ramp edges.
#[derive(Clone, Debug)]
pub(crate) struct KpBackward {
    states: KernelStates,
    ramps: RefCell<Vec<f64>>,
    edges: Vec<f64>,
}

/// A bracket [a, b] of the root of f(x) = v with f(a) ≤ v ≤ f(b), narrowed by trials.
struct Bracket {
    a: f64,
    fa: f64,
    b: f64,
    fb: f64,
}

impl Bracket {
    /// Narrows the bracket at x (a < x < b) by the trial f(x): `Err(x)` when f(x) = v, else
    /// whether the root lies above x.
    fn narrow(&mut self, x: f64, fx: f64, v: f64) -> std::result::Result<bool, f64> {
        if fx == v {
            return Err(x);
        }
        if fx < v {
            (self.a, self.fa) = (x, fx);
            Ok(true)
        } else {
            (self.b, self.fb) = (x, fx);
            Ok(false)
        }
    }

    /// Bisection over the points `point(k)`, k in [lo, end), that do not increase with k
    /// (step 3 of the module docs' "Inverse"): one trial for each point inside (a, b).
    fn over_sorted(
        &mut self,
        f: &impl Fn(f64) -> f64,
        v: f64,
        (mut lo, mut end): (usize, usize),
        point: impl Fn(usize) -> f64,
    ) -> std::result::Result<(), f64> {
        while lo < end {
            let mid = lo + (end - lo) / 2;
            let x = point(mid);
            // the larger points lie at the smaller k
            let above = if x <= self.a {
                true
            } else if x >= self.b {
                false
            } else {
                self.narrow(x, f(x), v)?
            };
            if above {
                end = mid;
            } else {
                lo = mid + 1;
            }
        }
        Ok(())
    }
}

impl Kp {
    /// An upper bound on the trial evaluations of f a step of the inverse takes, for every
    /// input sequence (module docs, "Inverse"): 2 at the outer edges, ⌊log₂ m⌋ + 1 over the
    /// m interior ramp edges, and, on the worst interval between neighbouring edges,
    /// ⌊log₂ i⌋ + 1 for every row i and ⌊log₂(n − 1 − j)⌋ + 1 for every column j whose ramp
    /// covers it (a bisection over k sorted points halves them at most ⌊log₂ k⌋ + 1 times,
    /// none for k = 0).
    pub fn inverse_trials(&self) -> usize {
        let (t, n) = (&self.thresholds, self.thresholds.len());
        let h = 0.5 * self.width;
        let edges = ramp_edges(t, self.width);
        let worst = edges
            .windows(2)
            .map(|w| {
                // edges from the highest down: (w[1], w[0])
                let covers = |ti: f64| ti - h < w[0] && ti + h > w[1];
                (0..n)
                    .filter(|&i| covers(t[i]))
                    .map(|i| halvings(i) + halvings(n - 1 - i))
                    .sum::<usize>()
            })
            .max()
            .unwrap_or(0);
        2 + halvings(edges.len().saturating_sub(2)) + worst
    }

    /// G⁻¹(v) from the kernel states in a bounded number of trials (module docs, "Inverse"):
    /// (command, clipped).
    fn solve(&self, backward: &KpBackward, v: f64) -> (f64, bool) {
        let f = |x: f64| self.trial(backward, x);
        self.solve_by(&f, &backward.states, &backward.edges, v)
    }

    /// f(x): the output if the input moved to x from the inverse's kernel states.
    fn trial(&self, backward: &KpBackward, x: f64) -> f64 {
        let mut ramps = backward.ramps.borrow_mut();
        let s = backward.states.trial_weighted(&self.weights, x, &mut ramps);
        self.offset + self.a0 * x + s
    }

    /// [`Kp::solve`] with the trial f(x) given.
    fn solve_by(
        &self,
        f: &impl Fn(f64) -> f64,
        states: &KernelStates,
        edges: &[f64],
        v: f64,
    ) -> (f64, bool) {
        let m = edges.len();
        let (a, b) = (edges[m - 1], edges[0]);
        let (fa, fb) = (f(a), f(b));
        // Beyond the outer edges only a₀x moves: from (x0, f0) the root is linear.
        let linear = |x0: f64, f0: f64| -> (f64, bool) {
            if f0 == v {
                return (x0, false);
            }
            if self.a0 > 0.0 {
                let x = x0 + (v - f0) / self.a0;
                if x.is_finite() {
                    return (x, false);
                }
            }
            (x0, (v - f0).abs() > clip_tolerance(v))
        };
        if v <= fa {
            return linear(a, fa);
        }
        if v >= fb {
            return linear(b, fb);
        }
        let mut br = Bracket { a, fa, b, fb };
        match self.narrow(&mut br, f, states, edges, v) {
            Err(x) => (x, false),
            Ok(()) => {
                let s = (v - br.fa) / (br.fb - br.fa);
                ((br.a + s * (br.b - br.a)).clamp(br.a, br.b), false)
            }
        }
    }

    /// G⁻¹\[v\] (the core operator's, whatever the orientation) with the number of trials of
    /// every sample's solve: the white-box check of [`Kp::inverse_trials`].
    #[doc(hidden)] // reached by crates/hysid-tests/tests/library/unit/model/operators/kp.rs
    pub fn core_inverse_counting_trials(&self, reference: &[f64]) -> (Vec<f64>, Vec<usize>) {
        let mut backward = self.backward_state(None);
        let (mut u, mut trials) = (Vec::new(), Vec::new());
        for &v in reference {
            let count = std::cell::Cell::new(0);
            let f = |x: f64| {
                count.set(count.get() + 1);
                self.trial(&backward, x)
            };
            let (x, _) = self.solve_by(&f, &backward.states, &backward.edges, v);
            backward.states.advance(x);
            u.push(x);
            trials.push(count.get());
        }
        (u, trials)
    }

    /// Steps 2 and 3 of the module docs' "Inverse" on a bracket of the outer edges:
    /// `Err(x)` at a trial with f(x) = v.
    fn narrow(
        &self,
        br: &mut Bracket,
        f: &impl Fn(f64) -> f64,
        states: &KernelStates,
        edges: &[f64],
        v: f64,
    ) -> std::result::Result<(), f64> {
        br.over_sorted(f, v, (1, edges.len() - 1), |k| edges[k])?;
        let (t, h, xi) = (&self.thresholds, 0.5 * self.width, states.values());
        for (i, &ti) in t.iter().enumerate() {
            if ti + h <= br.a || ti - h >= br.b {
                continue;
            }
            // row i: tᵢ + hξ_{ij}, j < i; column i: tᵢ + hξ_{ki}, k > i
            let row = i * (i + 1) / 2;
            br.over_sorted(f, v, (0, i), |j| ti + h * xi[row + j])?;
            br.over_sorted(f, v, (i + 1, t.len()), |k| ti + h * xi[k * (k + 1) / 2 + i])?;
        }
        Ok(())
    }
}

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
        KpBackward {
            states: KernelStates::new(&self.thresholds, self.width),
            ramps: RefCell::new(vec![0.0; self.levels()]),
            edges: ramp_edges(&self.thresholds, self.width),
        }
    }

    /// The branch from the current kernel states solved for v in a bounded number of trials
    /// (module docs, "Inverse"), then the states advanced with the solution.
    fn backward_step(&self, backward: &mut KpBackward, v: f64) -> (f64, bool) {
        let (u, clipped) = self.solve(backward, v);
        backward.states.advance(u);
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
