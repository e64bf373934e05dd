//! Identification of a discrete Preisach operator by regularised non-negative least squares.
//!
//! With the grid fixed (N intervals over the input range), G\[u\] = c + a₀u + Σ w_{ij} φ_{ij}\[u\]
//! is linear in (a₀, w, c); the regressors φ_{ij} (see [`crate::model::operators::Preisach`])
//! are built per sample from the staircase memory, touching only the cells under its strips,
//! and accumulated into the Gram matrix in blocks. The weights minimise
//!
//! ‖v − Φθ‖² + λ̃ Σ_{neighbouring cells} (w_c − w_d)², w ≥ 0, a₀ ≥ 0,
//!
//! λ̃ = λ·tr(Φ_wᵀΦ_w)/(number of cells): the smoothness penalty makes cells the data never
//! sweep take their neighbours' values instead of arbitrary ones; λ → 0 recovers the exact
//! weights of data produced by the model itself. Standard deviations are those of the
//! penalised normal equations (σ² from the unpenalised residual). A clockwise loop is fitted
//! in the inverse parameterisation (u = G\[y\]).
//!
//! Reference: I. D. Mayergoyz, *Mathematical Models of Hysteresis*, Springer 1991.

use super::family::{FamilyOptions, FamilySetting, Identify};
use super::linear_support::{
    check_data, core_path, finish, fit_initial_state, orientation, range, solve_weights, unscaled,
    GramAccumulator, Spread,
};
use super::model_size::choose_grid;
use super::OperatorFit;
use crate::model::operators::preisach::{regressors, Grid, Memory};
use crate::model::operators::{InitialStateUsed, Orientation, Preisach};
use crate::{Error, Result};
use nalgebra::DMatrix;
use std::time::Instant;

/// The work bound of the grid choice, in fits of the default grid 20
/// ([`super::model_size`]): the candidates 6 … 20 cost about one such fit together on the
/// training part, 30 about 3.4 more, so the default choice stays within about twice one
/// fixed fit and stops before 30 and 40 (reached with `--grid`).
pub const GRID_WORK_BOUND: f64 = 2.0;

/// Options of the Preisach identification.
#[derive(Clone, Debug, PartialEq)]
pub struct PreisachOptions {
    /// Number of intervals N of the grid over the input range (20: 210 cells).
    pub levels: usize,
    /// Smoothness penalty λ (relative to the mean diagonal of the Gram matrix), ≥ 0 (1e-6).
    pub lambda: f64,
    /// The grid's range [x₀, x_N]; the input's range when None.
    pub range: Option<(f64, f64)>,
    /// Include a reversible part a₀u (true).
    pub reversible: bool,
    /// The orientation; detected from the data when None.
    pub orientation: Option<Orientation>,
    /// The declared initial state the memory starts from (None: negative saturation,
    /// demagnetised).
    pub initial_state: Option<InitialStateUsed>,
}

impl Default for PreisachOptions {
    fn default() -> Self {
        Self {
            levels: 20,
            lambda: 1e-6,
            range: None,
            reversible: true,
            orientation: None,
            initial_state: None,
        }
    }
}

/// Fits a Preisach operator to input `u` and output `y`.
pub fn fit(u: &[f64], y: &[f64], options: &PreisachOptions) -> Result<OperatorFit<Preisach>> {
    let start = Instant::now();
    if options.levels == 0 || !(options.lambda >= 0.0 && options.lambda.is_finite()) {
        return Err(Error::invalid_option(
            "levels",
            options.levels,
            format!(
                "Preisach: levels = {}, lambda = {}; need levels >= 1 and a finite lambda >= 0",
                options.levels, options.lambda
            ),
        ));
    }
    let o = orientation(u, y, options.orientation)?;
    let (x, v) = o.core_data(u, y);
    let (lower, upper) = options.range.unwrap_or_else(|| range(&x));
    if upper <= lower || !lower.is_finite() || !upper.is_finite() {
        return Err(Error::invalid_option(
            "grid",
            format!("[{lower}, {upper}]"),
            format!("Preisach grid range [{lower}, {upper}] is empty; give lower < upper"),
        ));
    }
    let grid = Grid {
        lower,
        upper,
        n: options.levels,
    };
    let cells = grid.cells();
    let first = usize::from(options.reversible);
    let p = first + cells + 1;
    check_data(u, y, p)?;
    let (path, skip) = core_path(options.initial_state, &x, 2.0 * (upper - lower));
    let (g, b, yy, n) = normal_equations(&grid, &path[..skip], &x, &v, options.reversible);
    let mut g_pen = g.clone();
    add_smoothness(&mut g_pen, &grid, first, options.lambda);
    let mut unconstrained = vec![false; p];
    unconstrained[p - 1] = true;
    let sol = solve_weights(&g_pen, &b, yy, n, &unconstrained, Some(&g))?;
    let a0 = if options.reversible { sol.x[0] } else { 0.0 };
    let w = sol.x[first..first + cells].to_vec();
    let model =
        Preisach::new(lower, upper, options.levels, w, a0, sol.x[p - 1], o).map_err(|e| {
            Error::NotExciting {
                channel: "u".into(),
                reason: format!("no Preisach operator fits these data ({e})"),
            }
        })?;
    // (a0, the weights, c); a0 is estimated only when reversible.
    let map = unscaled(
        [options.reversible.then_some(0)]
            .into_iter()
            .chain((first..sol.x.len()).map(Some)),
    );
    Ok(finish(
        model,
        o,
        options.initial_state,
        u,
        y,
        Spread::of(&sol, &map),
        sol.iterations,
        1,
        sol.converged,
        start,
    ))
}

/// The normal equations of the regressors [x, φ_cells, 1] over the data, the memory first
/// run through the declared `history` (empty: from negative saturation).
fn normal_equations(
    grid: &Grid,
    history: &[f64],
    x: &[f64],
    v: &[f64],
    reversible: bool,
) -> (DMatrix<f64>, nalgebra::DVector<f64>, f64, usize) {
    let first = usize::from(reversible);
    let p = first + grid.cells() + 1;
    let mut acc = GramAccumulator::new(p);
    let mut memory = Memory::new(grid);
    for &xk in history {
        memory.apply(grid, xk);
    }
    let mut row = vec![0.0; p];
    row[p - 1] = 1.0;
    for (&xk, &vk) in x.iter().zip(v) {
        memory.apply(grid, xk);
        if reversible {
            row[0] = xk;
        }
        regressors(grid, &memory, &mut row[first..p - 1]);
        acc.push(&row, vk);
    }
    acc.finish()
}

/// Adds λ̃·L to the weight block, L the graph Laplacian of neighbouring cells (same row or
/// same column of the triangle).
fn add_smoothness(g: &mut DMatrix<f64>, grid: &Grid, first: usize, lambda: f64) {
    if lambda == 0.0 {
        return;
    }
    let cells = grid.cells();
    let trace: f64 = (first..first + cells).map(|i| g[(i, i)]).sum();
    let l = lambda * trace / cells as f64;
    let mut couple = |a: usize, b: usize| {
        let (a, b) = (first + a, first + b);
        g[(a, a)] += l;
        g[(b, b)] += l;
        g[(a, b)] -= l;
        g[(b, a)] -= l;
    };
    for i in 0..grid.n {
        for j in 0..=i {
            if j < i {
                couple(Grid::index(i, j), Grid::index(i, j + 1));
            }
            if i + 1 < grid.n {
                couple(Grid::index(i, j), Grid::index(i + 1, j));
            }
        }
    }
}

impl Identify for Preisach {
    const SETTINGS: &'static [FamilySetting] = &[
        FamilySetting::Grid,
        FamilySetting::Lambda,
        FamilySetting::Orientation,
    ];

    /// With [`FamilyOptions::choose_grid`] the grid's intervals are chosen among
    /// [`GRID_CANDIDATES`](super::family::GRID_CANDIDATES) on a held-out part, within
    /// [`GRID_WORK_BOUND`] fits of the default grid 20
    /// ([`model_size`](super::model_size)); otherwise `grid` fixes them.
    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>> {
        let given = options.given_orientation(u, y)?;
        let request = options.initial_state;
        let settings =
            |levels: usize,
             orientation: Option<Orientation>,
             initial_state: Option<InitialStateUsed>| PreisachOptions {
                levels,
                lambda: options.lambda,
                orientation,
                initial_state,
                ..PreisachOptions::default()
            };
        if options.choose_grid {
            let o = orientation(u, y, given)?;
            return choose_grid(u, y, GRID_WORK_BOUND, request, |u, y, n, start| {
                fit(u, y, &settings(n, Some(o), start.state))
            });
        }
        fit_initial_state(request, u, |start| {
            fit(u, y, &settings(options.grid, given, start.state))
        })
    }
}
