//! Identification of a Krasnosel'skii–Pokrovskii operator by regularised non-negative least
//! squares, with the ridge width chosen from the data.
//!
//! **Grid.** The thresholds are the midpoints of N equal intervals over the input range
//! ([`Kp::uniform_thresholds`]; the range of the core operator's input, i.e. of y for a
//! clockwise loop), N(N + 1)/2 kernels.
//!
//! **Weights.** With the thresholds and the ridge width a fixed,
//! G\[u\] = c + a₀u + Σ μ_{ij} ξ_{ij}\[u\] is linear in (a₀, μ, c). The kernel states of every
//! sample are the regressor row (one pass over the data, O(N²) per sample), accumulated into
//! the Gram matrix in blocks; the weights minimise
//!
//! ‖v − Φθ‖² + λ̃ Σ_{neighbouring kernels} (μ_p − μ_q)²,   μ ≥ 0, a₀ ≥ 0,
//!
//! neighbours being the kernels next to each other in a row or a column of the triangle, and
//! λ̃ = λ·tr(Φ_μᵀΦ_μ)/(number of kernels) — the penalty of the Preisach recipe: kernels the
//! data never sweep take their neighbours' values; λ = 0 recovers the exact weights of data
//! produced by the model itself. Standard deviations are those of the penalised normal
//! equations on the free set (σ² from the unpenalised residual); a weight held at 0 has none.
//!
//! **Ridge width.** a is structure, not a weight: the recipe profiles it over a few candidate
//! widths (relative to the grid's range) and keeps the one with the smallest penalised
//! equation error ‖v − Φθ‖² + penalty on the estimation data — one Gram matrix and one NNLS
//! solve per candidate. A single candidate fixes a. The default candidates avoid a equal to
//! the interval width h: there the diagonal kernels' ramps tile the range exactly, their sum is
//! linear in u inside it, and a₀ and c would not be separable from them.
//!
//! A clockwise loop is fitted in the inverse-operator parameterisation (u = G\[y\]), as the
//! other linear-in-weights families (see [`crate::model::operators::Orientation`]).
//!
//! References: H. T. Banks, A. J. Kurdila, G. Webb, "Identification of hysteretic control
//! influence operators representing smart actuators, part I: formulation", Mathematical
//! Problems in Engineering 3 (1997) 287–328; C. L. Lawson, R. J. Hanson, *Solving Least
//! Squares Problems*, Prentice-Hall 1974.

use super::family::{FamilyOptions, FamilySetting, Identify};
use super::linear_support::{
    check_data, core_path, finish, fit_initial_state, orientation, range, solve_weights, unscaled,
    Fit, GramAccumulator, Spread, WeightSolution,
};
use super::model_size::choose_grid;
use super::OperatorFit;
use crate::model::operators::kp::KernelStates;
use crate::model::operators::{InitialStateUsed, Kp, Orientation};
use crate::{Error, Result};
use nalgebra::{DMatrix, DVector};
use std::time::Instant;

/// The work bound of the grid choice, in fits of the default grid 20
/// ([`super::model_size`]): each KP fit profiles four ridge widths, so the bound is tighter
/// than Preisach's — the candidates 6 … 20 (about one default fit together on the training
/// part); 30 and 40 only with `--grid`.
pub const GRID_WORK_BOUND: f64 = 2.0;

/// Options of the KP identification.
#[derive(Clone, Debug, PartialEq)]
pub struct KpOptions {
    /// Number of intervals N of the threshold grid over the input range, 1..=100 (default
    /// 20: 20 thresholds, 210 kernels, the size of the default Preisach plane). The Gram
    /// matrix has (N(N + 1)/2 + 2)² entries: 200 MB at N = 100.
    pub levels: usize,
    /// Candidate ridge widths a relative to the grid's range (upper − lower), each finite and
    /// positive; the one with the smallest penalised equation error is kept, a single entry
    /// fixes a (default [`KpOptions::DEFAULT_WIDTHS`]).
    pub widths: Vec<f64>,
    /// Smoothness penalty λ (relative to the mean diagonal of the weights' Gram matrix), finite
    /// and ≥ 0 (default 1e-6); 0 switches it off.
    pub lambda: f64,
    /// The grid's range [lower, upper]; the core input's range when None (default).
    pub range: Option<(f64, f64)>,
    /// Include a reversible part a₀u (default true).
    pub reversible: bool,
    /// The orientation; detected from the data when None (default).
    pub orientation: Option<Orientation>,
    /// The declared initial state the kernels start from (None: every kernel down,
    /// demagnetised).
    pub initial_state: Option<InitialStateUsed>,
}

impl KpOptions {
    /// The default candidate ridge widths relative to the range: 0.03, 0.07, 0.12 and 0.2 —
    /// with the default 20 intervals 0.6, 1.4, 2.4 and 4 times the interval width.
    pub const DEFAULT_WIDTHS: [f64; 4] = [0.03, 0.07, 0.12, 0.2];
}

impl Default for KpOptions {
    fn default() -> Self {
        Self {
            levels: 20,
            widths: Self::DEFAULT_WIDTHS.to_vec(),
            lambda: 1e-6,
            range: None,
            reversible: true,
            orientation: None,
            initial_state: None,
        }
    }
}

/// Fits a KP operator to input `u` and output `y`.
pub fn fit(u: &[f64], y: &[f64], options: &KpOptions) -> Result<OperatorFit<Kp>> {
    let start = Instant::now();
    check_options(options)?;
    // a given range is checked before the data are read for the orientation
    if let Some((lower, upper)) = options.range {
        if !(lower.is_finite() && upper.is_finite() && upper > lower) {
            return Err(Error::invalid_option(
                "range",
                format!("[{lower}, {upper}]"),
                format!("KP grid range [{lower}, {upper}] is empty; give lower < upper"),
            ));
        }
    }
    let o = orientation(u, y, options.orientation)?;
    let (x, v) = o.core_data(u, y);
    let (lower, upper) = options.range.unwrap_or_else(|| range(&x));
    if !(lower.is_finite() && upper.is_finite() && upper > lower) {
        return Err(Error::invalid_option(
            "range",
            format!("[{lower}, {upper}]"),
            format!("KP grid range [{lower}, {upper}] is empty; give lower < upper"),
        ));
    }
    let thresholds = Kp::uniform_thresholds(lower, upper, options.levels)?;
    let kernels = thresholds.len() * (thresholds.len() + 1) / 2;
    let first = usize::from(options.reversible);
    let p = first + kernels + 1;
    check_data(u, y, p)?;
    let mut unconstrained = vec![false; p];
    unconstrained[p - 1] = true;

    let (path, skip) = core_path(options.initial_state, &x, 2.0 * (upper - lower));
    let mut best: Option<(f64, f64, WeightSolution)> = None;
    let mut iterations = 0;
    for &relative in &options.widths {
        let width = relative * (upper - lower);
        let (g, b, yy, n) = normal_equations(
            &thresholds,
            width,
            &path[..skip],
            &x,
            &v,
            options.reversible,
        );
        let mut g_pen = g.clone();
        add_smoothness(&mut g_pen, thresholds.len(), first, options.lambda);
        let sol = solve_weights(&g_pen, &b, yy, n, &unconstrained, Some(&g))?;
        iterations += sol.iterations;
        let criterion = penalised_error(&g_pen, &b, yy, &sol.x);
        if best.as_ref().is_none_or(|(c, _, _)| criterion < *c) {
            best = Some((criterion, width, sol));
        }
    }
    let (_, width, sol) = best.ok_or_else(|| {
        Error::invalid_option("widths", "[]", "KP: give at least one ridge width".into())
    })?;
    let converged = sol.converged;
    let a0 = if options.reversible { sol.x[0] } else { 0.0 };
    let weights = sol.x[first..first + kernels].to_vec();
    let model = Kp::new(thresholds, width, weights, a0, sol.x[p - 1], o).map_err(|e| {
        Error::NotExciting {
            channel: "u".into(),
            reason: format!("no KP operator fits these data ({e})"),
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
        iterations,
        options.widths.len(),
        converged,
        start,
    ))
}

/// The largest grid: 5050 kernels, a Gram matrix of 200 MB.
const MAX_LEVELS: usize = 100;

/// Refuses options out of range, naming the option.
fn check_options(options: &KpOptions) -> Result<()> {
    if options.levels == 0 || options.levels > MAX_LEVELS {
        return Err(Error::invalid_option(
            "levels",
            options.levels,
            format!(
                "KP: levels = {}; give 1..={MAX_LEVELS} grid intervals",
                options.levels
            ),
        ));
    }
    if !(options.lambda >= 0.0 && options.lambda.is_finite()) {
        return Err(Error::invalid_option(
            "lambda",
            options.lambda,
            format!(
                "KP: lambda = {}; give a finite smoothness penalty >= 0",
                options.lambda
            ),
        ));
    }
    if options.widths.is_empty() {
        return Err(Error::invalid_option(
            "widths",
            "[]",
            "KP: give at least one candidate ridge width".into(),
        ));
    }
    if let Some(&w) = options
        .widths
        .iter()
        .find(|w| !(w.is_finite() && **w > 0.0))
    {
        return Err(Error::invalid_option(
            "widths",
            w,
            format!(
                "KP: ridge width {w} (relative to the input range); each must be finite and > 0"
            ),
        ));
    }
    Ok(())
}

/// The normal equations of the regressors [x, ξ_kernels, 1] over the data, the kernels
/// first run through the declared `history` (empty: every kernel down).
fn normal_equations(
    thresholds: &[f64],
    width: f64,
    history: &[f64],
    x: &[f64],
    v: &[f64],
    reversible: bool,
) -> (DMatrix<f64>, DVector<f64>, f64, usize) {
    let first = usize::from(reversible);
    let kernels = thresholds.len() * (thresholds.len() + 1) / 2;
    let p = first + kernels + 1;
    let mut acc = GramAccumulator::new(p);
    let mut states = KernelStates::new(thresholds, width);
    for &xk in history {
        states.advance(xk);
    }
    let mut row = vec![0.0; p];
    row[p - 1] = 1.0;
    for (&xk, &vk) in x.iter().zip(v) {
        states.advance(xk);
        if reversible {
            row[0] = xk;
        }
        row[first..p - 1].copy_from_slice(states.values());
        acc.push(&row, vk);
    }
    acc.finish()
}

/// ‖v − Φθ‖² + penalty = vᵀv − 2bᵀθ + θᵀG_penθ.
fn penalised_error(g_pen: &DMatrix<f64>, b: &DVector<f64>, yy: f64, theta: &[f64]) -> f64 {
    let t = DVector::from_column_slice(theta);
    (yy - 2.0 * b.dot(&t) + t.dot(&(g_pen * &t))).max(0.0)
}

/// Adds λ̃·L to the weight block, L the graph Laplacian of neighbouring kernels (same row or
/// same column of the triangle).
fn add_smoothness(g: &mut DMatrix<f64>, levels: usize, first: usize, lambda: f64) {
    if lambda == 0.0 {
        return;
    }
    let kernels = levels * (levels + 1) / 2;
    let trace: f64 = (first..first + kernels).map(|i| g[(i, i)]).sum();
    let l = lambda * trace / kernels as f64;
    let index = |i: usize, j: usize| i * (i + 1) / 2 + j;
    let mut couple = |a: usize, b: usize| {
        let (a, b) = (first + a, first + b);
        g[(a, a)] += l;
        g[(b, b)] += l;
        g[(a, b)] -= l;
        g[(b, a)] -= l;
    };
    for i in 0..levels {
        for j in 0..=i {
            if j < i {
                couple(index(i, j), index(i, j + 1));
            }
            if i + 1 < levels {
                couple(index(i, j), index(i + 1, j));
            }
        }
    }
}

impl Identify for Kp {
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
        let settings = |levels: usize,
                        orientation: Option<Orientation>,
                        initial_state: Option<InitialStateUsed>| KpOptions {
            levels,
            lambda: options.lambda,
            orientation,
            initial_state,
            ..KpOptions::default()
        };
        // The ridge width is chosen with the structure, from the first start; the refits of
        // `estimate` from the histories keep it (a quarter of the work each).
        let fit_from = |u: &[f64], y: &[f64], mut settings: KpOptions, start: Fit<Kp>| {
            if let Some(first) = start.first {
                let (x, _) = first.model.orientation().core_data(u, y);
                let (lower, upper) = settings.range.unwrap_or_else(|| range(&x));
                settings.widths = vec![first.model.width() / (upper - lower)];
            }
            fit(u, y, &settings)
        };
        if options.choose_grid {
            let o = orientation(u, y, given)?;
            return choose_grid(u, y, GRID_WORK_BOUND, request, |u, y, n, start| {
                fit_from(u, y, settings(n, Some(o), start.state), start)
            });
        }
        fit_initial_state(request, u, |start| {
            fit_from(u, y, settings(options.grid, given, start.state), start)
        })
    }
}
