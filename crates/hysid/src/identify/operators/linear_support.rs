//! Shared steps of the linear-in-weights recipes: data checks, threshold grids, the Gram
//! matrix accumulated in blocks, NNLS with standard deviations, and the fit report.

use super::OperatorFit;
use crate::model::operators::elementary::{check_signal, oriented_simulate_saturating, Core};
use crate::model::operators::{
    initial_state, HysteresisOperator, InitialState, InitialStateUsed, Orientation,
};
use crate::numerics::metrics;
use crate::numerics::nnls::{nnls_gram, passive_inverse};
use crate::numerics::Termination;
use crate::{Error, Result};
use nalgebra::{DMatrix, DVector};
use std::time::Instant;

/// Checks equal lengths, finite samples, enough samples, a reversal of the input
/// ([`super::check_reversal`]) and a varying output.
pub(crate) fn check_data(u: &[f64], y: &[f64], parameters: usize) -> Result<()> {
    check_signal("u", u)?;
    check_signal("y", y)?;
    if u.len() != y.len() {
        return Err(Error::InvalidData(format!(
            "u has {} samples and y {}; give equal lengths",
            u.len(),
            y.len()
        )));
    }
    let needed = (2 * parameters).max(parameters + 10);
    if u.len() < needed {
        return Err(Error::TooFewSamples {
            samples: u.len(),
            parameters,
            needed,
        });
    }
    super::check_reversal(u)?;
    if !crate::data::varies(y) {
        return Err(Error::NotExciting {
            channel: "y".into(),
            reason: "the output is constant: nothing to fit".into(),
        });
    }
    Ok(())
}

/// (min, max) of a signal.
pub(crate) fn range(x: &[f64]) -> (f64, f64) {
    x.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        })
}

/// The default threshold grid rᵢ = i·(max x − min x)/(2(n + 1)), i = 1 … n: a play of
/// half-width ≥ half the input range would never move after its first reversal.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn threshold_grid(x: &[f64], n: usize) -> Result<Vec<f64>> {
    if n == 0 {
        return Err(Error::invalid_option(
            "thresholds",
            0,
            "the number of thresholds must be >= 1".into(),
        ));
    }
    let (lo, hi) = range(x);
    let span = hi - lo;
    if span.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err(Error::NotExciting {
            channel: "u".into(),
            reason: "the input is constant".into(),
        });
    }
    Ok((1..=n)
        .map(|i| i as f64 * span / (2.0 * (n + 1) as f64))
        .collect())
}

/// The geometric threshold placement rᵢ = r₁·(rₙ/r₁)^((i−1)/(n−1)), i = 1 … n, where the
/// loop lives (MODELS.md §4.8): rₙ = n·R/(2(n + 1)) is the uniform grid's largest threshold
/// (R = max x − min x) and r₁ = min(max(s/4, 10⁻³R), R/(2(n + 1))), s the smallest sweep of
/// the input between two turning points that exceeds 10⁻³R — a play of half-width r moves
/// once a sweep exceeds 2r, so the small plays follow the record's small reversals and a
/// narrow loop (width ≪ R) gets plays near its width instead of a uniform grid's R/(2(n + 1))
/// steps. n = 1 gives the uniform grid.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn geometric_thresholds(x: &[f64], n: usize) -> Result<Vec<f64>> {
    let uniform = threshold_grid(x, n)?;
    if n < 2 {
        return Ok(uniform);
    }
    let (lo, hi) = range(x);
    let span = hi - lo;
    let floor = 1e-3 * span;
    let mut smallest = f64::INFINITY;
    let mut anchor = x[0];
    let mut last = x[0];
    let mut direction = 0.0f64;
    for &v in &x[1..] {
        let d = v - last;
        if d != 0.0 {
            if direction != 0.0 && d.signum() != direction {
                let sweep = (last - anchor).abs();
                if sweep > floor {
                    smallest = smallest.min(sweep);
                }
                anchor = last;
            }
            direction = d.signum();
        }
        last = v;
    }
    let first = (smallest / 4.0).max(floor).min(uniform[0]);
    let top = uniform[n - 1];
    if !(first > 0.0 && first < top) {
        return Ok(uniform);
    }
    let ratio = (top / first).ln() / (n - 1) as f64;
    let mut grid: Vec<f64> = (0..n).map(|i| first * (ratio * i as f64).exp()).collect();
    grid[n - 1] = top;
    if grid.windows(2).all(|w| w[1] > w[0]) {
        Ok(grid)
    } else {
        Ok(uniform)
    }
}

/// ΦᵀΦ, Φᵀy and yᵀy accumulated over blocks of rows (one regressor row per sample), the
/// products done as matrix–matrix multiplications.
pub(crate) struct GramAccumulator {
    block: DMatrix<f64>,
    targets: DVector<f64>,
    filled: usize,
    pub g: DMatrix<f64>,
    pub b: DVector<f64>,
    pub yy: f64,
    pub n: usize,
}

const BLOCK: usize = 2048;

impl GramAccumulator {
    pub fn new(p: usize) -> Self {
        Self {
            block: DMatrix::zeros(p, BLOCK),
            targets: DVector::zeros(BLOCK),
            filled: 0,
            g: DMatrix::zeros(p, p),
            b: DVector::zeros(p),
            yy: 0.0,
            n: 0,
        }
    }

    /// Adds one sample: regressor row `phi`, target `y`.
    pub fn push(&mut self, phi: &[f64], y: f64) {
        self.block.column_mut(self.filled).copy_from_slice(phi);
        self.targets[self.filled] = y;
        self.filled += 1;
        self.yy += y * y;
        self.n += 1;
        if self.filled == BLOCK {
            self.flush();
        }
    }

    fn flush(&mut self) {
        if self.filled == 0 {
            return;
        }
        let c = self.block.columns(0, self.filled);
        let t = self.targets.rows(0, self.filled);
        let ct = c.transpose();
        // only the blocks on and below the diagonal: G is symmetric
        let p = self.g.nrows();
        let step = 64;
        for i0 in (0..p).step_by(step) {
            let ni = step.min(p - i0);
            for j0 in (0..=i0).step_by(step) {
                let nj = step.min(p - j0);
                let mut gij = self.g.view_mut((i0, j0), (ni, nj));
                gij.gemm(1.0, &c.rows(i0, ni), &ct.columns(j0, nj), 1.0);
            }
        }
        self.b.gemv(1.0, &c, &t, 1.0);
        self.filled = 0;
    }

    /// The accumulated normal equations.
    pub fn finish(mut self) -> (DMatrix<f64>, DVector<f64>, f64, usize) {
        self.flush();
        self.g.fill_upper_triangle_with_lower_triangle();
        (self.g, self.b, self.yy, self.n)
    }

    /// Normal equations from whole columns (one vector per regressor).
    pub fn from_columns(
        columns: &[Vec<f64>],
        y: &[f64],
    ) -> (DMatrix<f64>, DVector<f64>, f64, usize) {
        let mut acc = Self::new(columns.len());
        let mut row = vec![0.0; columns.len()];
        for (k, &yk) in y.iter().enumerate() {
            for (r, c) in row.iter_mut().zip(columns) {
                *r = c[k];
            }
            acc.push(&row, yk);
        }
        acc.finish()
    }
}

/// An NNLS solution with its standard deviations and covariance σ²(G_FF)⁻¹ on the free set F.
pub(crate) struct WeightSolution {
    pub x: Vec<f64>,
    pub std: Vec<Option<f64>>,
    /// σ²(G_FF)⁻¹ over all of x, zero in the rows and columns outside F.
    pub covariance: DMatrix<f64>,
    pub iterations: usize,
    pub converged: bool,
}

/// The standard deviations of a fit's parameters and their covariance (zero in the rows and
/// columns of the parameters without a standard deviation), in the model's parameter order.
pub(crate) struct Spread {
    pub std: Vec<Option<f64>>,
    pub covariance: Vec<Vec<f64>>,
}

impl Spread {
    /// The spread of parameters θ = J x with the covariance `c` of x (none where `std[k]`
    /// is None): parameter i is `scale · x_k` for `map[i] = Some((k, scale))`, not estimated
    /// for None, so cov(θᵢ, θⱼ) = sᵢ sⱼ c_{kᵢkⱼ}.
    pub fn mapped(std: &[Option<f64>], c: &DMatrix<f64>, map: &[Option<(usize, f64)>]) -> Self {
        let live = |m: &Option<(usize, f64)>| m.filter(|&(k, _)| std[k].is_some());
        let covariance = map
            .iter()
            .map(|a| {
                map.iter()
                    .map(|b| match (live(a), live(b)) {
                        (Some((i, si)), Some((j, sj))) => si * sj * c[(i, j)],
                        _ => 0.0,
                    })
                    .collect()
            })
            .collect();
        Self {
            std: map
                .iter()
                .map(|m| live(m).and_then(|(k, s)| std[k].map(|v| v * s.abs())))
                .collect(),
            covariance,
        }
    }

    /// The spread of the solution's x, parameter i being `scale · x_k` for
    /// `map[i] = Some((k, scale))` ([`Spread::mapped`]).
    pub fn of(sol: &WeightSolution, map: &[Option<(usize, f64)>]) -> Self {
        Self::mapped(&sol.std, &sol.covariance, map)
    }
}

/// The map of [`Spread::of`] that takes x_k to parameter i unscaled for each `Some(k)`.
pub(crate) fn unscaled(
    indices: impl IntoIterator<Item = Option<usize>>,
) -> Vec<Option<(usize, f64)>> {
    indices.into_iter().map(|k| k.map(|k| (k, 1.0))).collect()
}

/// Solves the normal equations under x ≥ 0 (except the unconstrained variables) and the
/// standard deviations with σ² = RSS/(N − |F|); `penalty` (already in G) is excluded from
/// the RSS by the caller giving the unpenalised `g_plain`.
///
/// The columns are equilibrated first (Jacobi scaling, Golub & Van Loan, *Matrix
/// Computations*, 4th ed., §3.5.2): with D = diag(1/√Gᵢᵢ) the problem D G D x' = D b,
/// x' ≥ 0, has the same solution x = D x' (D > 0 keeps the signs), and a unit diagonal.
/// Regressors in units far apart (an input in kA beside an output's dead zones in µT, a
/// column of ones beside plays of a few mA) otherwise leave the small columns' duals below
/// the active-set method's tolerance, and their weights at zero after no iteration.
pub(crate) fn solve_weights(
    g: &DMatrix<f64>,
    b: &DVector<f64>,
    yy: f64,
    n: usize,
    unconstrained: &[bool],
    g_plain: Option<&DMatrix<f64>>,
) -> Result<WeightSolution> {
    // a column at rounding level of the largest (ε² of its square norm) stays unscaled: a
    // unit diagonal would let its noise in with a large weight
    let largest = (0..b.len()).fold(0.0f64, |m, i| m.max(g[(i, i)]));
    let d: Vec<f64> = (0..b.len())
        .map(|i| {
            let gii = g[(i, i)];
            if gii > f64::EPSILON * f64::EPSILON * largest && gii.is_finite() {
                1.0 / gii.sqrt()
            } else {
                1.0
            }
        })
        .collect();
    let g_scaled = DMatrix::from_fn(g.nrows(), g.ncols(), |i, j| d[i] * g[(i, j)] * d[j]);
    let b_scaled = DVector::from_fn(b.len(), |i, _| d[i] * b[i]);
    let mut sol = nnls_gram(&g_scaled, &b_scaled, unconstrained)?;
    for (x, d) in sol.x.iter_mut().zip(&d) {
        *x *= d;
    }
    let x = DVector::from_column_slice(&sol.x);
    let gp = g_plain.unwrap_or(g);
    let rss = (yy - 2.0 * b.dot(&x) + x.dot(&(gp * &x))).max(0.0);
    let free = sol.passive.iter().filter(|&&p| p).count();
    let sigma2 = if n > free {
        rss / (n - free) as f64
    } else {
        0.0
    };
    let mut std = vec![None; sol.x.len()];
    let mut covariance = DMatrix::zeros(sol.x.len(), sol.x.len());
    if let Some((idx, inv)) = passive_inverse(g, &sol.passive) {
        for (k, &i) in idx.iter().enumerate() {
            std[i] = Some((sigma2 * inv[(k, k)]).max(0.0).sqrt());
            for (l, &j) in idx.iter().enumerate() {
                covariance[(i, j)] = sigma2 * inv[(k, l)];
            }
        }
    }
    Ok(WeightSolution {
        x: sol.x,
        std,
        covariance,
        iterations: sol.iterations,
        converged: sol.converged,
    })
}

/// The core input x of a record with the declared history of `state` prepended, and the
/// number of samples prepended (MODELS.md §4.8, [`initial_state`]): \[x₀, x_turn\] ++ x,
/// x_turn = [`InitialStateUsed::turning_point`] over x's range with the core's memory
/// `reach` (twice its largest threshold, or the extent of its Preisach grid). The core's
/// input rises with u in every orientation (x = u, or x = s·y = G⁻¹\[u\]), so a descent in u
/// is a descent in x. A fit computes its regressors over the path and regresses on the rows
/// after the first `skip`; None or a state held in the structure: x itself.
pub(crate) fn core_path(
    state: Option<InitialStateUsed>,
    x: &[f64],
    reach: f64,
) -> (Vec<f64>, usize) {
    let (lo, hi) = range(x);
    match (
        state.and_then(|s| s.turning_point(lo, hi, reach)),
        x.first(),
    ) {
        (Some(turn), Some(&x0)) => {
            let mut path = vec![x0, turn];
            path.extend_from_slice(x);
            (path, 2)
        }
        _ => (x.to_vec(), 0),
    }
}

/// The declared history a fit of `request` regresses from first: the descending or
/// ascending history; None (the structure's own, demagnetised state) for `demagnetised`
/// and for `estimate`, whose other candidates [`fit_initial_state`] refits.
pub(crate) fn first_state(request: InitialState) -> Option<InitialStateUsed> {
    request
        .declared()
        .filter(|s| *s != InitialStateUsed::Demagnetised)
}

/// What one fit of a structure starts from: the declared history it regresses from (None:
/// the structure's own, demagnetised state), and for the refits of `estimate` the first fit
/// of the same structure, whose choices a family may keep (KP: its ridge width).
pub(crate) struct Fit<'a, M> {
    /// The declared initial state.
    pub state: Option<InitialStateUsed>,
    /// The same structure's first fit, for a refit; None for the first fit.
    pub first: Option<&'a OperatorFit<M>>,
}

/// The fit of one structure from the initial state `request`; `fit` fits it from a
/// [`Fit`] start, first from [`first_state`].
///
/// A declared state keeps the first fit (checked to simulate from its state). `estimate`
/// compares it with the refits from the descending and the ascending histories and keeps
/// the one of least loss on the record (the same parameters, so the loss is the criterion;
/// a tie keeps the demagnetised state). A candidate whose saved model could not simulate
/// its own record from that state (a history beyond the domain of an
/// inverse-parameterised, saturating operator) is dropped.
pub(crate) fn fit_initial_state<M: HysteresisOperator>(
    request: InitialState,
    u: &[f64],
    fit: impl Fn(Fit<M>) -> Result<OperatorFit<M>>,
) -> Result<OperatorFit<M>> {
    let first = fit(Fit {
        state: first_state(request),
        first: None,
    })?;
    if request != InitialState::Estimate {
        if let Some(state) = first.initial_state {
            initial_state::simulate(&first.model, Some(state), u)?;
        }
        return Ok(first);
    }
    let mut best: Option<OperatorFit<M>> = None;
    for state in [InitialStateUsed::Descending, InitialStateUsed::Ascending] {
        let start = Fit {
            state: Some(state),
            first: Some(&first),
        };
        let Ok(refit) = fit(start) else {
            continue;
        };
        let lowest = best.as_ref().map_or(first.loss, |b| b.loss);
        if refit.loss < lowest && initial_state::simulate(&refit.model, Some(state), u).is_ok() {
            best = Some(refit);
        }
    }
    Ok(best.unwrap_or(first))
}

/// Everything a fit reports, from the model and the data, simulated from the declared
/// initial `state` (None: the structure's own).
#[allow(clippy::too_many_arguments)]
pub(crate) fn finish<M: HysteresisOperator + Core>(
    model: M,
    orientation: Orientation,
    state: Option<InitialStateUsed>,
    u: &[f64],
    y: &[f64],
    spread: Spread,
    iterations: usize,
    evaluations: usize,
    converged: bool,
    start: Instant,
) -> OperatorFit<M> {
    let Spread { std, covariance } = spread;
    let simulated = match state {
        Some(state) => {
            let path = initial_state::with_history(&model, state, u);
            let (mut simulated, _) = oriented_simulate_saturating(&model, orientation, &path);
            simulated.split_off(path.len() - u.len())
        }
        None => oriented_simulate_saturating(&model, orientation, u).0,
    };
    let parameters = model.parameters();
    let estimated = std.iter().filter(|s| s.is_some()).count();
    let n = y.len();
    let loss = metrics::mse(y, &simulated);
    let rmse = loss.sqrt();
    let termination = if rmse <= 1e-9 * metrics::std_dev(y) {
        Termination::ZeroResidual
    } else if converged {
        Termination::Converged { change: 0.0 }
    } else {
        Termination::MaxIterations
    };
    OperatorFit {
        fit_percent: metrics::fit_percent(y, &simulated),
        rmse,
        loss,
        fpe: metrics::fpe(loss, n, estimated),
        aic: metrics::aic(loss, n, estimated),
        model,
        parameters,
        std,
        covariance,
        simulated,
        iterations,
        evaluations,
        termination,
        elapsed_s: start.elapsed().as_secs_f64(),
        initial_state: state,
        history_turn: None,
        model_size: None,
    }
}

/// The orientation to fit: the given one or the detected one.
pub(crate) fn orientation(u: &[f64], y: &[f64], given: Option<Orientation>) -> Result<Orientation> {
    check_signal("u", u)?;
    check_signal("y", y)?;
    if u.len() != y.len() {
        return Err(Error::InvalidData(format!(
            "u has {} samples and y {}; give equal lengths",
            u.len(),
            y.len()
        )));
    }
    match given {
        Some(o) => Ok(o),
        None => Orientation::detect(u, y),
    }
}
