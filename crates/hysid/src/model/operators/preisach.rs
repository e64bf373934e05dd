//! The discrete Preisach operator: relays on a triangular grid with a piecewise-constant
//! density, simulated through the staircase memory and the Everett function.
//!
//! The input range [x₀, x_N] is cut into N equal intervals; cell (i, j), j ≤ i, of the Preisach
//! half-plane α ≥ β holds the relays with up-switching value α ∈ [xᵢ, xᵢ₊₁] and down-switching
//! value β ∈ [xⱼ, xⱼ₊₁] (the cells on the diagonal are triangles), with a uniform density whose
//! integral over the cell is the weight w_{ij} ≥ 0. The output is
//!
//! G\[u\] = c + a₀u + ∫∫_{α≥β} μ(α, β) γ_{αβ}\[u\] dα dβ = c + a₀u + Σ_{cells} w_{ij} φ_{ij},
//!
//! γ_{αβ} = ±1 the relay outputs and φ_{ij} = 2·(area of the cell in S⁺)/(cell area) − 1, S⁺
//! the part of the plane whose relays are up. It is continuous and non-decreasing along every
//! branch, so it can be inverted by a monotone per-sample solve.
//!
//! **Memory (wiping-out, Mayergoyz 1991).** The boundary of S⁺ is a staircase fixed by the
//! alternating dominant extrema x₀ = m₀ < M₁ > m₁ < M₂ > … (each maximum below the previous one,
//! each minimum above): S⁺ = ∪ₖ {mₖ₋₁ ≤ β < mₖ, β ≤ α ≤ Mₖ}. An input that passes an earlier
//! extremum of its kind wipes that extremum and the one after it out. The initial state is
//! negative saturation (all relays down, memory m₀ = x₀).
//!
//! **Everett function.** E(α, β) = ∫∫_{β ≤ β' ≤ α' ≤ α} μ, computed from the prefix sums of the
//! weights over the triangle plus the partial cells of one row and one column; the output is
//! G = c + a₀u + 2 Σₖ [E(Mₖ, mₖ₋₁) − E(Mₖ, mₖ)] − Σ w, a cost of O(memory length · N) per
//! sample instead of O(N²) ([`Preisach::everett`], the simulation's form, unchanged so that
//! saved models simulate to the bit). The inverse's trial steps use the same function in O(1)
//! from the sums along each row and column as well ([`Preisach::everett_by_sums`]; equal up to
//! rounding); the inverse's own memory advances with it too, so that its trials and its state
//! agree.
//!
//! **Inverse in a bounded number of steps.** From the current memory, the branch
//! f(x) = G\[…, x\] is continuous and non-decreasing in the next input x, and it is a
//! quadratic in x between consecutive *breakpoints*: the grid levels (where α or β enters
//! another row or column of cells: the Everett function's partial cells are linear in α or β
//! off the diagonal and quadratic on it) and the memory's extrema the input would wipe out
//! (where the staircase, so the strip whose Everett integral moves, changes). Beyond the grid
//! only the term a₀x moves. [`Preisach`]'s G⁻¹(v) from the last command u with output y:
//!
//! 1. v = y gives u. Otherwise the target lies towards the grid's end e in the direction of
//!    v − y (its upper end for v > y); one trial at e gives f(e). When v is beyond it (or u
//!    is beyond the grid already) the linear term gives x = e + (v − f(e))/a₀ exactly; with
//!    a₀ = 0 the command is e and the target is clipped.
//! 2. Otherwise [a, b] = [u, e] (or [e, u]) brackets v, f(a) ≤ v ≤ f(b). Bisection over the
//!    grid levels strictly inside it (at most ⌈log₂(N + 2)⌉ trials: the N + 1 levels when
//!    the last command lies beyond the grid), then over the memory's
//!    points strictly inside what remains (the extrema the input would wipe out: all on the
//!    target's side of u, so all maxima or all minima, monotone in their age; at most
//!    ⌈log₂ 33⌉ = 6 trials for the 64 points a stream holds), narrows [a, b] to an
//!    interval without a breakpoint.
//! 3. On it f is the quadratic through f(a), f(m), f(b), m the midpoint (one trial): with
//!    t = (x − a)/(b − a), f = f(a) + B t + A t², A = 2(f(b) − 2f(m) + f(a)),
//!    B = 4f(m) − 3f(a) − f(b), and the root in [0, 1] is t = −2C / (B + √(B² − 4AC)),
//!    C = f(a) − v (the form without cancellation: B ≥ 0 on a non-decreasing branch).
//!
//! So a step costs at most 1 + ⌈log₂(N + 2)⌉ + 6 + 1 trial steps and the final one (13 + 1 on a
//! 20 × 20 grid), each a copy of the memory and one advance — whatever the input sequence,
//! where a bracketing and Illinois solve took up to hundreds; the exported code
//! (`export::families::preisach`) makes the same computation. The root is exact up to the
//! rounding of the three values.
//!
//! Reference: I. D. Mayergoyz, *Mathematical Models of Hysteresis*, Springer 1991.

use super::elementary::{
    check_finite, clip_tolerance, oriented_invert, oriented_simulate, Core, Orientation,
};
use super::{HysteresisOperator, Inversion};
use crate::model::{Parameter, ParameterSet};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::cell::RefCell;

/// The grid of a discrete Preisach plane: N equal intervals over [x₀, x_N].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub struct Grid {
    pub lower: f64,
    pub upper: f64,
    pub n: usize,
}

impl Grid {
    fn h(&self) -> f64 {
        (self.upper - self.lower) / self.n as f64
    }
    /// The level x_k (x_N is the upper end itself).
    pub fn level(&self, k: usize) -> f64 {
        if k >= self.n {
            self.upper
        } else {
            self.lower + k as f64 * self.h()
        }
    }
    /// The interval containing x, clamped to 0..N−1.
    fn interval(&self, x: f64) -> usize {
        (((x - self.lower) / self.h()).floor().max(0.0) as usize).min(self.n - 1)
    }
    /// Number of cells N(N+1)/2.
    pub fn cells(&self) -> usize {
        self.n * (self.n + 1) / 2
    }
    /// Index of cell (i, j), j ≤ i.
    pub fn index(i: usize, j: usize) -> usize {
        i * (i + 1) / 2 + j
    }
    /// Area of cell (i, j) ∩ {b_lo ≤ β < b_hi, β ≤ α ≤ a_hi} divided by the cell's area.
    pub fn fraction(&self, i: usize, j: usize, b_lo: f64, b_hi: f64, a_hi: f64) -> f64 {
        let h = self.h();
        let bl = self.level(j).max(b_lo);
        let bh = self.level(j + 1).min(b_hi);
        let al = self.level(i);
        let ah = self.level(i + 1).min(a_hi);
        if bl >= bh || al >= ah {
            return 0.0;
        }
        if i > j {
            (bh - bl) * (ah - al) / (h * h)
        } else if ah > bl {
            let t = bh.min(ah);
            ((ah - bl).powi(2) - (ah - t).powi(2)) / (h * h)
        } else {
            0.0
        }
    }
}

/// The corners a streaming Preisach state holds ([`Preisach`]'s stepper): the staircase of at
/// most 32 nested minor loops. A batch simulation holds every corner its record can make.
pub const STREAM_MEMORY: usize = 64;

/// The staircase memory: alternating extrema [m₀ = x₀, M₁, m₁, M₂, …, current input], the input
/// clamped to the grid, at most `capacity` of them (its storage is reserved when it is built
/// and never grows; a memory that would need more corners is marked overflowed).
#[derive(Clone, Debug, PartialEq)]
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub struct Memory {
    points: Vec<f64>,
    capacity: usize,
    overflowed: bool,
}

impl Memory {
    /// The stored extrema, oldest first (the staircase's corners).
    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn points(&self) -> &[f64] {
        &self.points
    }
    /// Negative saturation, with room for every corner a record can make.
    pub fn new(grid: &Grid) -> Self {
        Self {
            points: vec![grid.lower],
            capacity: usize::MAX,
            overflowed: false,
        }
    }

    /// Negative saturation, with room for `capacity` corners (≥ 1): storage for them (and
    /// the one a step holds before it wipes out) is reserved now.
    pub fn with_capacity(grid: &Grid, capacity: usize) -> Self {
        let capacity = capacity.max(1);
        let mut points = Vec::with_capacity(capacity.saturating_add(1));
        points.push(grid.lower);
        Self {
            points,
            capacity,
            overflowed: false,
        }
    }

    /// True once the input made more corners than the capacity (the memory no longer
    /// represents the plane).
    pub fn overflowed(&self) -> bool {
        self.overflowed
    }

    /// Becomes a copy of `other` without allocating (the storage reserved stays).
    fn copy_from(&mut self, other: &Memory) {
        self.points.clone_from(&other.points);
        self.capacity = other.capacity;
        self.overflowed = other.overflowed;
    }

    /// Moves the input to x, wiping out the extrema it passes; returns the index of the first
    /// point that changed (the points' length when none did).
    pub fn apply(&mut self, grid: &Grid, x: f64) -> usize {
        let v = x.clamp(grid.lower, grid.upper);
        let p = &mut self.points;
        let len = p.len();
        let cur = p[len - 1];
        if v == cur {
            return len;
        }
        let continuing = len >= 2 && ((cur > p[len - 2]) == (v > cur));
        let mut first = if continuing {
            p[len - 1] = v;
            len - 1
        } else {
            p.push(v);
            len
        };
        // wiping-out: the new value passes the previous extremum of its kind
        while p.len() >= 3 {
            let n = p.len();
            let rising = p[n - 1] > p[n - 2];
            let passes = if rising { v >= p[n - 3] } else { v <= p[n - 3] };
            if !passes {
                break;
            }
            if n == 3 && !rising {
                p.truncate(1);
                first = 1;
                break;
            }
            p.drain(n - 3..n - 1);
            first = first.min(n - 3);
        }
        if p.len() > self.capacity {
            self.overflowed = true;
        }
        first
    }

    /// The strip s = (m_{s}, m_{s+1} (or M when it is the last point), M_{s+1}).
    fn strip(&self, s: usize) -> (f64, f64, f64) {
        let p = &self.points;
        let k = 2 * s + 1;
        let m_next = if k + 1 < p.len() { p[k + 1] } else { p[k] };
        (p[k - 1], m_next, p[k])
    }

    /// Number of strips.
    fn n_strips(&self) -> usize {
        self.points.len() / 2
    }

    /// The strips (m_{k−1}, m_k, M_k) whose union is S⁺.
    pub fn strips(&self) -> impl Iterator<Item = (f64, f64, f64)> + '_ {
        (0..self.n_strips()).map(move |s| self.strip(s))
    }
}

/// A form of the Everett function ([`Preisach::everett`], [`Preisach::everett_by_sums`]).
type Everett = fn(&Preisach, f64, f64) -> f64;

/// The memory with the running sums of the strips' Everett integrals
/// Σ_{t≤s} [E(M_t, m_{t−1}) − E(M_t, m_t)], so that a sample costs only the strips it changes.
#[derive(Clone, Debug)]
pub(crate) struct State {
    memory: Memory,
    prefix: Vec<f64>,
}

impl State {
    /// Negative saturation with room for `capacity` corners.
    fn new(grid: &Grid, capacity: usize) -> Self {
        Self {
            memory: Memory::with_capacity(grid, capacity),
            prefix: Vec::with_capacity(capacity / 2 + 1),
        }
    }

    /// The state of a batch (`horizon` its samples: storage grows with the corners the record
    /// makes, never overflowing) or of a stream (None: [`STREAM_MEMORY`] corners reserved).
    fn for_horizon(grid: &Grid, horizon: Option<usize>) -> Self {
        match horizon {
            Some(_) => Self {
                memory: Memory::new(grid),
                prefix: Vec::new(),
            },
            None => Self::new(grid, STREAM_MEMORY),
        }
    }

    /// Becomes a copy of `other` without allocating.
    fn copy_from(&mut self, other: &State) {
        self.memory.copy_from(&other.memory);
        self.prefix.clone_from(&other.prefix);
    }

    /// Moves the input to x and returns the integral of μ over S⁺, each changed strip's
    /// Everett integrals by `everett` (the simulation's [`Preisach::everett`], or the
    /// inverse's [`Preisach::everett_by_sums`]).
    fn advance(&mut self, model: &Preisach, x: f64, everett: Everett) -> f64 {
        let first = self.memory.apply(&model.grid, x);
        // strip s uses points 2s … 2s + 2
        let keep = first.saturating_sub(2) / 2;
        self.prefix.truncate(keep.min(self.prefix.len()));
        for s in self.prefix.len()..self.memory.n_strips() {
            let (m_prev, m_next, big) = self.memory.strip(s);
            let a = everett(model, big, m_prev) - everett(model, big, m_next);
            let before = self.prefix.last().copied().unwrap_or(0.0);
            self.prefix.push(before + a);
        }
        self.prefix.last().copied().unwrap_or(0.0)
    }
}

/// A discrete Preisach operator G\[u\] = c + a₀u + Σ w_{ij} φ_{ij}\[u\] in an [`Orientation`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Preisach {
    grid: Grid,
    weights: Vec<f64>,
    a0: f64,
    offset: f64,
    orientation: Orientation,
    /// q[a·N + b] = Σ_{a ≤ j ≤ i ≤ b} w_{ij} (prefix sums over the triangle).
    #[serde(skip)]
    q: Vec<f64>,
    /// The sums along each row and column ([`row_sums`], [`column_sums`]).
    #[serde(skip)]
    rows: Vec<f64>,
    #[serde(skip)]
    columns: Vec<f64>,
}

impl Preisach {
    /// A Preisach plane of `n` intervals over [lower, upper] with cell weights w_{ij} ≥ 0 in the
    /// order (0,0), (1,0), (1,1), (2,0), … (row i = α interval, column j = β interval), a
    /// reversible part a₀ ≥ 0 and an offset c.
    pub fn new(
        lower: f64,
        upper: f64,
        n: usize,
        weights: Vec<f64>,
        a0: f64,
        offset: f64,
        orientation: Orientation,
    ) -> Result<Self> {
        check_finite("lower", lower)?;
        check_finite("upper", upper)?;
        check_finite("a0", a0)?;
        check_finite("c", offset)?;
        if upper <= lower || n == 0 {
            return Err(Error::InvalidModel(format!(
                "Preisach grid [{lower}, {upper}] with {n} intervals: need lower < upper and n >= 1"
            )));
        }
        let grid = Grid { lower, upper, n };
        if weights.len() != grid.cells() {
            return Err(Error::InvalidModel(format!(
                "Preisach: {} weights for a {n}-level triangle of {} cells",
                weights.len(),
                grid.cells()
            )));
        }
        for (k, &w) in std::iter::once(&a0).chain(&weights).enumerate() {
            if !w.is_finite() || w < 0.0 {
                return Err(Error::InvalidParameter {
                    name: if k == 0 {
                        "a0".into()
                    } else {
                        format!("w{}", k)
                    },
                    value: w,
                    reason: "Preisach weights must be finite and >= 0".into(),
                });
            }
        }
        if a0 == 0.0 && weights.iter().all(|&w| w == 0.0) {
            return Err(Error::InvalidParameter {
                name: "a0".into(),
                value: 0.0,
                reason: "every weight is zero: the operator is constant".into(),
            });
        }
        Ok(Self {
            q: prefix_sums(&grid, &weights),
            rows: row_sums(&grid, &weights),
            columns: column_sums(&grid, &weights),
            grid,
            weights,
            a0,
            offset,
            orientation,
        })
    }

    /// The grid's lower end x₀.
    pub fn lower(&self) -> f64 {
        self.grid.lower
    }
    /// The grid's upper end x_N.
    pub fn upper(&self) -> f64 {
        self.grid.upper
    }
    /// The number of intervals N.
    pub fn levels(&self) -> usize {
        self.grid.n
    }
    /// The plane's grid of cells.
    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn grid(&self) -> &Grid {
        &self.grid
    }
    /// The cell weights w_{ij}, order (0,0), (1,0), (1,1), (2,0), …
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }
    /// The reversible part a₀.
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

    /// The Everett function E(α, β) = ∫∫_{β ≤ β' ≤ α' ≤ α} μ: the whole cells from the
    /// prefix sums, the cut cells of α's row and β's column each by its area fraction (O(N)).
    /// The simulation's form, kept to the bit for saved models; the inverse's trial steps use
    /// [`Preisach::everett_by_sums`].
    pub fn everett(&self, alpha: f64, beta: f64) -> f64 {
        let g = &self.grid;
        let (alpha, beta) = (alpha.min(g.upper), beta.max(g.lower));
        if alpha <= beta {
            return 0.0;
        }
        let (ii, jj) = (g.interval(alpha), g.interval(beta));
        let n = g.n;
        let full = if jj + 1 < ii {
            self.q[(jj + 1) * n + ii - 1]
        } else {
            0.0
        };
        let partial_row: f64 = (jj..=ii)
            .map(|j| {
                self.weights[Grid::index(ii, j)] * g.fraction(ii, j, beta, f64::INFINITY, alpha)
            })
            .sum();
        let partial_col: f64 = (jj..ii)
            .map(|i| {
                self.weights[Grid::index(i, jj)] * g.fraction(i, jj, beta, f64::INFINITY, alpha)
            })
            .sum();
        full + partial_row + partial_col
    }

    /// The Everett function E(α, β) = ∫∫_{β ≤ β' ≤ α' ≤ α} μ in O(1), equal to
    /// [`Preisach::everett`] up to rounding (the inverse's form): with i = the row of α,
    /// j = the column of β, dα = α − x_i and dβ = x_{j+1} − β (how far each reaches into
    /// its cell), E = w_ii (α − β)² / h² when i = j, else
    ///
    /// E = Q + w_ij dβ dα / h² + R dα / h + w_ii dα² / h² + w_jj dβ² / h² + C dβ / h,
    ///
    /// Q the whole cells strictly between (the prefix sums q), R the row i's cells strictly
    /// between columns j and i, C the column j's cells strictly between rows j and i (the
    /// row and column sums): the cells of row i are cut at α (the diagonal one along the
    /// triangle), those of column j at β.
    pub fn everett_by_sums(&self, alpha: f64, beta: f64) -> f64 {
        let g = &self.grid;
        let (alpha, beta) = (alpha.min(g.upper), beta.max(g.lower));
        if alpha <= beta {
            return 0.0;
        }
        let (i, j) = (g.interval(alpha), g.interval(beta));
        let (h, w) = (g.h(), &self.weights);
        let hh = h * h;
        if i == j {
            let d = alpha - beta;
            return w[Grid::index(i, i)] * (d * d) / hh;
        }
        let whole = if j + 1 < i {
            self.q[(j + 1) * g.n + i - 1]
        } else {
            0.0
        };
        let da = alpha - g.level(i);
        let db = g.level(j + 1) - beta;
        let row = self.rows[Grid::index(i, i)] - self.rows[Grid::index(i, j + 1)];
        let column = self.columns[Grid::index(i, j)] - self.columns[Grid::index(j + 1, j)];
        whole
            + w[Grid::index(i, j)] * (db * da) / hh
            + row * da / h
            + w[Grid::index(i, i)] * (da * da) / hh
            + w[Grid::index(j, j)] * (db * db) / hh
            + column * db / h
    }

    /// The output from the integral over S⁺ and the input x.
    fn output(&self, up: f64, x: f64) -> f64 {
        self.offset + self.a0 * x + 2.0 * up - self.q[self.grid.n - 1]
    }
}

/// q[a·N + b] = Σ_{a ≤ j ≤ i ≤ b} w_{ij} for a ≤ b (also the exported code's table,
/// `export::families::preisach`).
pub(crate) fn prefix_sums(grid: &Grid, w: &[f64]) -> Vec<f64> {
    let n = grid.n;
    let mut q = vec![0.0; n * n];
    for a in 0..n {
        let mut acc = 0.0;
        for b in a..n {
            acc += (a..=b).map(|j| w[Grid::index(b, j)]).sum::<f64>();
            q[a * n + b] = acc;
        }
    }
    q
}

/// rows[index(i, j)] = Σ_{k < j} w_{ik}: the sums along row i, before column j (also the
/// exported code's table).
pub(crate) fn row_sums(grid: &Grid, w: &[f64]) -> Vec<f64> {
    let mut rows = vec![0.0; grid.cells()];
    for i in 0..grid.n {
        let mut acc = 0.0;
        for j in 0..=i {
            rows[Grid::index(i, j)] = acc;
            acc += w[Grid::index(i, j)];
        }
    }
    rows
}

/// columns[index(i, j)] = Σ_{j ≤ k < i} w_{kj}: the sums down column j, before row i (also
/// the exported code's table).
pub(crate) fn column_sums(grid: &Grid, w: &[f64]) -> Vec<f64> {
    let mut columns = vec![0.0; grid.cells()];
    for j in 0..grid.n {
        let mut acc = 0.0;
        for i in j..grid.n {
            columns[Grid::index(i, j)] = acc;
            acc += w[Grid::index(i, j)];
        }
    }
    columns
}

/// The regressors φ_{ij} = 2·(area in S⁺)/(cell area) − 1 of every cell for a memory.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn regressors(grid: &Grid, memory: &Memory, phi: &mut [f64]) {
    phi.iter_mut().for_each(|p| *p = -1.0);
    for (m_prev, m_next, big) in memory.strips() {
        if m_next <= m_prev {
            continue;
        }
        let (j0, j1, i1) = (
            grid.interval(m_prev),
            grid.interval(m_next),
            grid.interval(big),
        );
        for j in j0..=j1 {
            for i in j..=i1 {
                let f = grid.fraction(i, j, m_prev, m_next, big);
                phi[Grid::index(i, j)] += 2.0 * f;
            }
        }
    }
}

/// The inverse's state: the plane's, the last command and its output (the branch's start),
/// and scratch space for the solve's trial steps.
#[derive(Clone, Debug)]
pub(crate) struct PreisachBackward {
    state: State,
    command: f64,
    output: f64,
    trial: RefCell<State>,
}

/// The root t ∈ [0, 1] of the quadratic through (0, fa), (½, fm), (1, fb) equal to v, for
/// fa ≤ v ≤ fb on a non-decreasing branch (module docs, "Inverse", step 3).
fn quadratic_root(fa: f64, fm: f64, fb: f64, v: f64) -> f64 {
    let a = 2.0 * (fb - 2.0 * fm + fa);
    let b = 4.0 * fm - 3.0 * fa - fb;
    let c = fa - v;
    let disc = (b * b - 4.0 * a * c).max(0.0);
    let den = b + disc.sqrt();
    if den > 0.0 {
        (-2.0 * c / den).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

impl Preisach {
    /// G⁻¹(v) from the last command (module docs, "Inverse"): (command, clipped).
    fn solve(&self, backward: &PreisachBackward, v: f64) -> (f64, bool) {
        let g = self.grid;
        let state = &backward.state;
        let f = |x: f64| {
            let mut trial = backward.trial.borrow_mut();
            trial.copy_from(state);
            let up = trial.advance(self, x, Preisach::everett_by_sums);
            self.output(up, x)
        };
        let (u, y) = (backward.command, backward.output);
        if v == y {
            return (u, false);
        }
        let rising = v > y;
        let end = if rising { g.upper } else { g.lower };
        // Beyond the grid only a₀x moves: from (x0, f0) the root is linear.
        let linear = |x0: f64, f0: f64| -> (f64, bool) {
            if self.a0 > 0.0 {
                let x = x0 + (v - f0) / self.a0;
                if x.is_finite() {
                    return (x, false);
                }
            }
            (x0, (v - f0).abs() > clip_tolerance(v))
        };
        if (rising && u >= end) || (!rising && u <= end) {
            return linear(u, y);
        }
        let f_end = f(end);
        if (rising && f_end < v) || (!rising && f_end > v) {
            return linear(end, f_end);
        }
        let ((mut a, mut fa), (mut b, mut fb)) = if rising {
            ((u, y), (end, f_end))
        } else {
            ((end, f_end), (u, y))
        };
        // The grid levels x_0 … x_N strictly inside (a, b): k_lo ≤ k < k_end (the ends x_0,
        // x_N too when the last command lies beyond the grid).
        let mut k_lo = if a < g.lower { 0 } else { g.interval(a) + 1 };
        if g.level(k_lo) <= a {
            k_lo += 1;
        }
        let mut k_end = if b > g.upper {
            g.n + 1
        } else {
            g.interval(b) + 1
        };
        if g.level(k_end - 1) >= b {
            k_end -= 1;
        }
        while k_lo < k_end {
            let mid = k_lo + (k_end - k_lo) / 2;
            let x = g.level(mid);
            let fx = f(x);
            if fx == v {
                return (x, false);
            }
            if fx < v {
                (a, fa, k_lo) = (x, fx, mid + 1);
            } else {
                (b, fb, k_end) = (x, fx, mid);
            }
        }
        // The extrema the input would wipe out on its way: the memory's points strictly
        // inside (a, b), all on one side of u, so all maxima (rising) or all minima
        // (falling), every other point p[first], p[first + 2], …, nearer u the later.
        let p = state.memory.points();
        let (mut first, mut last) = (p.len(), 0);
        for (i, &c) in p[..p.len() - 1].iter().enumerate() {
            if c > a && c < b {
                if i < first {
                    first = i;
                }
                last = i;
            }
        }
        let mut j_lo = 0;
        let mut j_end = if first <= last {
            (last - first) / 2 + 1
        } else {
            0
        };
        while j_lo < j_end {
            let mid = j_lo + (j_end - j_lo) / 2;
            let x = p[first + 2 * mid];
            let fx = f(x);
            if fx == v {
                return (x, false);
            }
            if fx < v {
                (a, fa) = (x, fx);
            } else {
                (b, fb) = (x, fx);
            }
            // The root lies above x when f(x) < v: rising, towards the older maxima.
            if (fx < v) == rising {
                j_end = mid;
            } else {
                j_lo = mid + 1;
            }
        }
        if fa == v {
            return (a, false);
        }
        if fb == v {
            return (b, false);
        }
        let m = 0.5 * (a + b);
        let t = quadratic_root(fa, f(m), fb, v);
        ((a + t * (b - a)).clamp(a, b), false)
    }
}

impl Core for Preisach {
    /// The staircase memory and the running sums of its strips' Everett integrals.
    type Forward = State;
    type Backward = PreisachBackward;

    fn orientation(&self) -> Orientation {
        self.orientation
    }

    fn forward_state(&self, horizon: Option<usize>) -> State {
        State::for_horizon(&self.grid, horizon)
    }

    /// c + a₀u + 2·Σₖ [E(Mₖ, mₖ₋₁) − E(Mₖ, mₖ)] − Σw, the strips' sums accumulated oldest
    /// first (module doc).
    fn forward_step(&self, state: &mut State, u: f64) -> f64 {
        let up = state.advance(self, u, Preisach::everett);
        self.output(up, u)
    }

    /// Negative saturation, the last command the grid's lower end.
    fn backward_state(&self, horizon: Option<usize>) -> PreisachBackward {
        let state = State::for_horizon(&self.grid, horizon);
        PreisachBackward {
            trial: RefCell::new(state.clone()),
            state,
            command: self.grid.lower,
            output: self.output(0.0, self.grid.lower),
        }
    }

    /// The branch from the current memory solved for v in a bounded number of trial steps
    /// on a copy of the state (module docs, "Inverse"), then the state advanced with the
    /// solution.
    fn backward_step(&self, backward: &mut PreisachBackward, v: f64) -> (f64, bool) {
        let (u, clipped) = self.solve(backward, v);
        let up = backward.state.advance(self, u, Preisach::everett_by_sums);
        backward.command = u;
        backward.output = self.output(up, u);
        (u, clipped)
    }

    fn overflowed(&self, forward: Option<&State>, backward: Option<&PreisachBackward>) -> bool {
        forward.is_some_and(|s| s.memory.overflowed())
            || backward.is_some_and(|b| b.state.memory.overflowed())
    }
}

impl HysteresisOperator for Preisach {
    fn family(&self) -> &'static str {
        <Self as super::OperatorFamily>::NAME
    }

    fn parameters(&self) -> ParameterSet {
        let mut p = vec![Parameter::new("a0", self.a0).bounds(0.0, f64::INFINITY)];
        for i in 0..self.grid.n {
            for j in 0..=i {
                let w = self.weights[Grid::index(i, j)];
                p.push(
                    Parameter::new(format!("w{}_{}", i + 1, j + 1), w).bounds(0.0, f64::INFINITY),
                );
            }
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

    /// Twice the grid's extent from 0: a history then leaves the grid and saturates every cell.
    fn memory_reach(&self) -> f64 {
        2.0 * (self.grid.lower.abs() + self.grid.upper.abs())
    }
}

impl super::OperatorFamily for Preisach {
    const NAME: &'static str = "preisach";
    const TITLE: &'static str = "discrete Preisach plane (Mayergoyz 1991)";

    fn example() -> Result<Self> {
        let weights = vec![0.1, 0.2, 0.05, 0.3, 0.1, 0.15];
        Self::new(-1.0, 1.0, 3, weights, 0.2, 0.0, Orientation::default())
    }

    fn checked(self) -> Result<Self> {
        Self::new(
            self.lower(),
            self.upper(),
            self.levels(),
            self.weights().to_vec(),
            self.a0(),
            self.offset(),
            self.orientation(),
        )
    }

    /// Values a0, μ1 … μN (the cells), c.
    fn with_values(&self, values: &[f64]) -> Result<Self> {
        super::check_values(self, values)?;
        let n = self.weights().len();
        Self::new(
            self.lower(),
            self.upper(),
            self.levels(),
            values[1..=n].to_vec(),
            values[0],
            values[n + 1],
            self.orientation(),
        )
    }

    /// Every parameter (not for the inverse-operator parameterisation).
    fn output_scale(&self) -> Option<Vec<usize>> {
        (!self.orientation().inverse).then(|| (0..self.weights().len() + 2).collect())
    }
}
