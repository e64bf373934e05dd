//! Global stage for the hysteresis cascade: a grid over (α, d) with an over-parameterised
//! linear regression at every grid point.
//!
//! # Why
//!
//! The key-term-separation iteration and the output-error fit are local methods: from a rough
//! start they can stall or settle in a wrong minimum (docs/models/coleman-hodgdon-cascade.md
//! §8). This stage needs no starting values at all.
//!
//! # Method (DERIVED; docs/models/coleman-hodgdon-cascade.md §9)
//!
//! For fixed α and d the switching h(t) and the decay factor (1 − α|Δx(t)|) are known, and the
//! hysteresis output is *linear* in the remaining parameters ℓ = (m1, m2, c1, c2) (ch4: m1, c1):
//!
//! ```text
//! v(t) = Σᵢ ℓᵢ ψᵢ(t),      ψᵢ(t) = (1 − α|Δx(t)|) ψᵢ(t−1) + uᵢ(t),  ψᵢ(0) = 0
//! u_m1 = α|Δx|(x(1−h) + d·sgn(x)h),   u_m2 = α|Δx|(x·h − d·sgn(x)h),
//! u_c1 = (1−h)Δx,                      u_c2 = h·Δx
//! ```
//!
//! so A(q⁻¹)y(t) = Σⱼ bⱼ v(t−k−j+1) is linear in a, and bilinear in b and ℓ. Replacing the
//! products bⱼℓᵢ by free coefficients βⱼᵢ gives an ordinary least-squares problem
//! (over-parameterisation, Bai 1998). The rank-one factorisation of the m × |ℓ| matrix β by
//! SVD, β ≈ σ u vᵀ, returns b = u/u₁ (so b1 = 1) and ℓ = σ u₁ v.
//!
//! With output noise the equation-error estimates of a (and through them b, ℓ) are biased,
//! badly so when the linear block is slow or nearly cancels a pole with a zero (Example 2).
//! The equation-error *cost* still ranks the grid points well, so the search runs in two
//! stages: (A) plain least squares over the whole grid, ranked by equation error; (B) from
//! the best `refine` distinct points, a local Nelder–Mead search of the equation-error cost in
//! (ln α, d), then simplified refined instrumental-variable iterations (SRIV) — the
//! signals are prefiltered by 1/Â and the lagged outputs in the instruments are replaced by
//! the noise-free model output, which makes the estimate consistent under output noise
//! (Young 1976) — and a ranking by the **output-error** cost of the resulting cascade
//! (a plain simulation). The best few points
//! are returned for local refinement. The cost is sharp in d, so the grid in d is
//! fine (default 64 points over the input range) and the local refinement does the rest.
//!
//! References: P. C. Young, "Some observations on instrumental variable methods of
//! time-series analysis", Int. J. Control 23(5), 1976; E.-W. Bai, "An optimal two-stage identification algorithm for
//! Hammerstein–Wiener nonlinear systems", Automatica 34(3), 1998 (over-parameterisation and
//! rank-one factorisation).

use super::grid_regression::{self, EquationError};
use crate::model::{ChForm, ColemanHodgdon, HysteresisCascade, LinearBlock};
use crate::numerics::nelder_mead::nelder_mead;
use crate::numerics::Observer;
use crate::{Error, Result};
use nalgebra::DMatrix;
use rayon::prelude::*;

/// Settings of the (α, d) grid.
#[derive(Clone, Debug)]
pub struct GlobalSearch {
    /// Hysteresis form.
    pub form: ChForm,
    /// Order n of A.
    pub na: usize,
    /// Number m of B coefficients.
    pub nb: usize,
    /// Delay k ≥ 1.
    pub delay: usize,
    /// Grid points in α (log-spaced).
    pub alpha_points: usize,
    /// Grid points in d (uniform over (0, max|x|)).
    pub d_points: usize,
    /// Number of distinct grid points (best by equation error) refined locally.
    pub refine: usize,
    /// Refined instrumental-variable iterations per refined point.
    pub refined_iv: usize,
    /// Number of best grid points returned.
    pub keep: usize,
}

/// One scored grid point.
#[derive(Clone, Debug)]
pub struct GridCandidate {
    /// The cascade estimated at this grid point.
    pub cascade: HysteresisCascade,
    /// Equation-error sum of squares of the over-parameterised regression.
    pub equation_cost: f64,
    /// Output-error sum of squares of the cascade's simulation.
    pub output_cost: f64,
}

impl GlobalSearch {
    /// Defaults: 16 α values, 64 d values, 8 distinct points refined (local search, 4
    /// refined-IV iterations), keep the 6 best.
    pub fn new(form: ChForm, na: usize, nb: usize, delay: usize) -> Self {
        Self {
            form,
            na,
            nb,
            delay,
            alpha_points: 16,
            d_points: 64,
            refine: 8,
            refined_iv: 4,
            keep: 6,
        }
    }

    /// Scores the whole grid on the record (x, y) and returns the best points, best first
    /// (by output-error cost), at most one per d-α neighbourhood.
    pub fn search(&self, x: &[f64], y: &[f64]) -> Result<Vec<GridCandidate>> {
        self.search_observed(x, y, &Observer::none())
    }

    /// [`search`](Self::search), asking `observer` before every batch of grid points (at most
    /// [`grid_regression::BATCH`]) and every local refinement: once it answers
    /// [`Control::Stop`](crate::numerics::Control::Stop) the remaining points are skipped and
    /// the best of those scored are returned (how a time limit is honoured). Errors with
    /// [`Error::Cancelled`] when it stops the grid before any point was scored.
    pub fn search_observed(
        &self,
        x: &[f64],
        y: &[f64],
        observer: &Observer,
    ) -> Result<Vec<GridCandidate>> {
        let grid = self.grid(x)?;
        // Stage A: plain equation error over the whole grid. Its *cost* ranks (α, d) well even
        // with output noise; its linear estimates are what the noise biases.
        // The points of one α are scored a few at a time (their ψ recursions interleaved,
        // see `grid_regression`), each batch's in grid order.
        let regression = EquationError::new(self.form, self.na, self.nb, self.delay, x, y);
        let batches: Vec<&[(f64, f64)]> = grid
            .chunk_by(|a, b| a.0 == b.0)
            .flat_map(|same_alpha| same_alpha.chunks(grid_regression::BATCH))
            .collect();
        let mut ranked: Vec<(f64, f64, f64)> = batches
            .par_iter()
            .enumerate()
            .map_init(
                || regression.scratch(),
                |s, (i, batch)| {
                    let mut scored = [None; grid_regression::BATCH];
                    // The first batch is scored even then: a stopped search keeps a result.
                    if i > 0 && observer.should_stop("grid") {
                        return scored;
                    }
                    let ds: [f64; grid_regression::BATCH] =
                        std::array::from_fn(|k| batch.get(k).map_or(0.0, |&(_, d)| d));
                    let costs = regression.costs(batch[0].0, &ds[..batch.len()], s);
                    for ((out, &(alpha, d)), cost) in scored.iter_mut().zip(*batch).zip(costs) {
                        *out = cost.map(|cost| (alpha, d, cost));
                    }
                    scored
                },
            )
            .flat_map_iter(|scored| scored.into_iter().flatten())
            .collect();
        if ranked.is_empty() && observer.should_stop("grid") {
            return Err(Error::Cancelled(
                "the time limit was reached before any (alpha, d) grid point was scored; allow more time".into(),
            ));
        }
        if ranked.is_empty() {
            return Err(Error::Singular(
                "no (alpha, d) grid point gives a solvable regression; the input does not excite the cascade".into(),
            ));
        }
        ranked.sort_by(|a, b| a.2.total_cmp(&b.2));
        let starts = self.distinct_points(&ranked, x);
        // Stage B: the equation-error cost minimised locally in (ln α, d) from each distinct
        // good grid point, then refined instrumental variables there, scored by output error.
        let mut scored: Vec<GridCandidate> = starts
            .par_iter()
            .enumerate()
            .filter_map(|(i, &(alpha, d))| {
                // The best-ranked point is refined even then: a stopped search still has
                // a candidate.
                if i > 0 && observer.should_stop("grid refinement") {
                    return None;
                }
                let (alpha, d) = self.local_minimum(x, y, alpha, d);
                self.evaluate(x, y, alpha, d)
            })
            .collect();
        scored.sort_by(|a, b| a.output_cost.total_cmp(&b.output_cost));
        Ok(self.distinct_best(scored))
    }

    /// The (α, d) grid: α log-spaced up to the rate limit 1/max|Δx|, d uniform in (0, max|x|).
    pub fn grid(&self, x: &[f64]) -> Result<Vec<(f64, f64)>> {
        let max_dx = x
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f64::max);
        let max_x = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if max_dx == 0.0 || max_x == 0.0 {
            return Err(Error::NotExciting {
                channel: "input".into(),
                reason: "it is constant; drive it with periodic signals of several amplitudes"
                    .into(),
            });
        }
        let alpha_hi = 1.0 / max_dx;
        let alpha_lo = (0.05 / max_x).min(0.1 * alpha_hi);
        let na = self.alpha_points.max(2);
        let nd = self.d_points.max(2);
        let mut grid = Vec::with_capacity(na * nd);
        for i in 0..na {
            let alpha = alpha_lo * (alpha_hi / alpha_lo).powf(i as f64 / (na - 1) as f64);
            for j in 1..=nd {
                grid.push((alpha, max_x * j as f64 / (nd + 1) as f64));
            }
        }
        Ok(grid)
    }

    /// Up to `refine` grid points, best first, none within a grid cell or two of a better one.
    fn distinct_points(&self, ranked: &[(f64, f64, f64)], x: &[f64]) -> Vec<(f64, f64)> {
        let grid = self.grid(x).unwrap_or_default();
        let (alpha_step, d_step) = grid_steps(&grid, self.d_points);
        let mut kept: Vec<(f64, f64)> = Vec::new();
        for &(alpha, d, _) in ranked {
            let near = kept.iter().any(|&(ka, kd)| {
                (alpha / ka).ln().abs() < 1.5 * alpha_step && (d - kd).abs() < 2.5 * d_step
            });
            if !near {
                kept.push((alpha, d));
            }
            if kept.len() >= self.refine {
                break;
            }
        }
        kept
    }

    /// Nelder–Mead on the equation-error cost in (ln α, d) from a grid point, α kept below
    /// the rate limit and d inside (0, max|x|).
    fn local_minimum(&self, x: &[f64], y: &[f64], alpha: f64, d: f64) -> (f64, f64) {
        let grid = self.grid(x).unwrap_or_default();
        let (alpha_step, d_step) = grid_steps(&grid, self.d_points);
        let alpha_max = grid.iter().map(|g| g.0).fold(0.0, f64::max);
        let d_max = d_step * (self.d_points + 1) as f64;
        let regression = EquationError::new(self.form, self.na, self.nb, self.delay, x, y);
        let scratch = std::cell::RefCell::new(regression.scratch());
        let cost = |p: &[f64]| {
            let (a, dd) = (p[0].exp(), p[1]);
            if a > alpha_max || dd <= 0.0 || dd >= d_max {
                return f64::INFINITY;
            }
            regression
                .cost(a, dd, &mut scratch.borrow_mut())
                .unwrap_or(f64::INFINITY)
        };
        let (best, _) = nelder_mead(
            cost,
            &[alpha.ln(), d],
            &[0.5 * alpha_step, 0.5 * d_step],
            60,
            1e-9,
        );
        (best[0].exp(), best[1])
    }

    /// Evaluates one grid point; None when its regression is singular or the result unusable.
    pub fn evaluate(&self, x: &[f64], y: &[f64], alpha: f64, d: f64) -> Option<GridCandidate> {
        let psi = basis_signals(self.form, x, alpha, d);
        let (mut theta, equation_cost) = self.overparameterised_fit(y, &psi)?;
        // Every iterate is a candidate: the refined-IV iteration usually improves the linear
        // estimates, but it can also wander to an unstable denominator.
        let mut best = self.scored(x, y, &theta, alpha, d, equation_cost);
        for _ in 0..self.refined_iv {
            let Some(next) = self.refined_iv_step(y, &psi, &theta) else {
                break;
            };
            theta = next;
            if let Some(c) = self.scored(x, y, &theta, alpha, d, equation_cost) {
                if best.as_ref().is_none_or(|b| c.output_cost < b.output_cost) {
                    best = Some(c);
                }
            }
        }
        best
    }

    /// The cascade of an over-parameterised estimate with its output-error cost; None when it
    /// cannot be factorised or its simulation is not finite.
    fn scored(
        &self,
        x: &[f64],
        y: &[f64],
        theta: &[f64],
        alpha: f64,
        d: f64,
        equation_cost: f64,
    ) -> Option<GridCandidate> {
        let cascade = self.factorise(theta, alpha, d)?;
        let sim = cascade.simulate_unchecked(x);
        let output_cost: f64 = y.iter().zip(&sim.y).map(|(a, b)| (a - b).powi(2)).sum();
        output_cost.is_finite().then_some(GridCandidate {
            cascade,
            equation_cost,
            output_cost,
        })
    }

    /// One iteration of the simplified refined instrumental-variable method (SRIV, Young
    /// 1976): the regressors and the output are prefiltered by 1/Â, and the lagged outputs in
    /// the instruments are replaced by the noise-free output x̂ of the current model, which
    /// makes the estimate consistent under output noise. None when Â is unstable or the
    /// instrument matrix is singular.
    fn refined_iv_step(&self, y: &[f64], psi: &[Vec<f64>], theta: &[f64]) -> Option<Vec<f64>> {
        let a = &theta[..self.na];
        if !LinearBlock::new(a.to_vec(), vec![1.0], 1).ok()?.is_stable() {
            return None;
        }
        let nl = psi.len();
        let t0 = self.na.max(self.delay + self.nb - 1);
        // Noise-free model output x̂ = (Σ βⱼᵢ q^{−k−j+1} ψᵢ)/Â.
        let drive: Vec<f64> = (0..y.len())
            .map(|t| {
                let mut acc = 0.0;
                for j in 0..self.nb {
                    if let Some(s) = t.checked_sub(self.delay + j) {
                        for (i, p) in psi.iter().enumerate() {
                            acc += theta[self.na + j * nl + i] * p[s];
                        }
                    }
                }
                acc
            })
            .collect();
        let xhat = filter_ar(&drive, a);
        let yf = filter_ar(y, a);
        let xf = filter_ar(&xhat, a);
        let psif: Vec<Vec<f64>> = psi.iter().map(|p| filter_ar(p, a)).collect();
        let phi = self.regressors(&yf, &psif, t0);
        let zeta = self.regressors(&xf, &psif, t0);
        let target = nalgebra::DVector::from_column_slice(&yf[t0..]);
        let m = zeta.tr_mul(&phi);
        let rhs = zeta.tr_mul(&target);
        let solved = m.lu().solve(&rhs)?;
        solved
            .iter()
            .all(|v| v.is_finite())
            .then(|| solved.iter().copied().collect())
    }

    /// The regressor matrix [−s(t−1…n), ψᵢ(t−k−j+1)] for rows t ≥ t0.
    fn regressors(&self, s: &[f64], psi: &[Vec<f64>], t0: usize) -> DMatrix<f64> {
        let nl = psi.len();
        let cols = self.na + self.nb * nl;
        DMatrix::from_fn(s.len() - t0, cols, |r, c| {
            let t = r + t0;
            if c < self.na {
                -s[t - c - 1]
            } else {
                let j = (c - self.na) / nl;
                let i = (c - self.na) % nl;
                psi[i][t - self.delay - j]
            }
        })
    }

    /// Least squares of y(t) on [−y(t−1…n), ψᵢ(t−k−j+1) for j = 1…m, i ∈ ℓ] through the
    /// normal equations (the grid evaluates hundreds of points, and the column scaling keeps
    /// them well conditioned). Returns θ = [a…, β₁₁, β₁₂, …] and the residual sum of squares.
    fn overparameterised_fit(&self, y: &[f64], psi: &[Vec<f64>]) -> Option<(Vec<f64>, f64)> {
        let nl = psi.len();
        let cols = self.na + self.nb * nl;
        let t0 = self.na.max(self.delay + self.nb - 1);
        let rows = y.len().checked_sub(t0)?;
        if rows <= cols {
            return None;
        }
        let phi = self.regressors(y, psi, t0);
        let scale: Vec<f64> = (0..cols).map(|c| phi.column(c).norm()).collect();
        if scale.iter().any(|&s| s == 0.0 || !s.is_finite()) {
            return None;
        }
        let target = nalgebra::DVector::from_column_slice(&y[t0..]);
        let mut ata = phi.tr_mul(&phi);
        let mut atb = phi.tr_mul(&target);
        for i in 0..cols {
            atb[i] /= scale[i];
            for j in 0..cols {
                ata[(i, j)] /= scale[i] * scale[j];
            }
        }
        let solved = ata.cholesky()?.solve(&atb);
        let theta: Vec<f64> = solved.iter().zip(&scale).map(|(t, s)| t / s).collect();
        let fitted = &phi * nalgebra::DVector::from_column_slice(&theta);
        let cost = (target - fitted).norm_squared();
        Some((theta, cost))
    }

    /// Rank-one factorisation of β into b (b1 = 1) and ℓ; builds the cascade.
    fn factorise(&self, theta: &[f64], alpha: f64, d: f64) -> Option<HysteresisCascade> {
        let nl = material_count(self.form);
        let beta = DMatrix::from_fn(self.nb, nl, |j, i| theta[self.na + j * nl + i]);
        // Dominant right singular vector from the eigenvectors of βᵀβ: nalgebra's SVD loses
        // digits in the left vectors of nearly rank-one matrices, which is exactly our case.
        let eig = (beta.transpose() * &beta).symmetric_eigen();
        let v = eig.eigenvectors.column(eig.eigenvalues.imax()).into_owned();
        let w = &beta * &v;
        if w[0].abs() < 1e-8 * w.amax() {
            return None;
        }
        let b: Vec<f64> = w.iter().map(|wj| wj / w[0]).collect();
        let l: Vec<f64> = v.iter().map(|vi| w[0] * vi).collect();
        let hysteresis = match self.form {
            ChForm::Saturated4 => ColemanHodgdon::saturated(alpha, l[0], l[1], d),
            ChForm::General6 => ColemanHodgdon::general(alpha, l[0], l[1], l[2], l[3], d),
        }
        .ok()?;
        let linear = LinearBlock::new(theta[..self.na].to_vec(), b, self.delay).ok()?;
        HysteresisCascade::new(hysteresis, linear).ok()
    }

    /// Keeps the best candidates whose (log α, d) differ by more than a grid cell from each
    /// better one, so the refinement explores distinct basins.
    fn distinct_best(&self, sorted: Vec<GridCandidate>) -> Vec<GridCandidate> {
        let mut kept: Vec<GridCandidate> = Vec::new();
        let d_cell = sorted
            .iter()
            .map(|c| c.cascade.hysteresis.d())
            .fold(0.0, f64::max)
            / self.d_points.max(1) as f64;
        for c in sorted {
            let (a, d) = (c.cascade.hysteresis.alpha(), c.cascade.hysteresis.d());
            let near = kept.iter().any(|k| {
                let (ka, kd) = (k.cascade.hysteresis.alpha(), k.cascade.hysteresis.d());
                (a / ka).ln().abs() < 0.3 && (d - kd).abs() < 2.5 * d_cell
            });
            if !near {
                kept.push(c);
            }
            if kept.len() >= self.keep {
                break;
            }
        }
        kept
    }
}

/// The grid's step in ln α and in d.
fn grid_steps(grid: &[(f64, f64)], d_points: usize) -> (f64, f64) {
    let alpha_min = grid.iter().map(|g| g.0).fold(f64::INFINITY, f64::min);
    let alpha_max = grid.iter().map(|g| g.0).fold(0.0, f64::max);
    let n_alpha = grid.len() / d_points.max(1);
    let alpha_step = (alpha_max / alpha_min).ln() / (n_alpha.max(2) - 1) as f64;
    let d_step = grid.iter().map(|g| g.1).fold(f64::INFINITY, f64::min);
    (alpha_step, d_step)
}

/// z(t) = s(t) − Σ aᵢ z(t−i): the signal filtered by 1/A(q⁻¹), from rest.
fn filter_ar(s: &[f64], a: &[f64]) -> Vec<f64> {
    let mut z = vec![0.0; s.len()];
    for t in 0..s.len() {
        let mut acc = s[t];
        for (i, ai) in a.iter().enumerate() {
            if let Some(past) = t.checked_sub(i + 1) {
                acc -= ai * z[past];
            }
        }
        z[t] = acc;
    }
    z
}

/// Number of material-function coefficients ℓ that enter linearly (4 or 2).
fn material_count(form: ChForm) -> usize {
    match form {
        ChForm::Saturated4 => 2,
        ChForm::General6 => 4,
    }
}

/// The basis signals ψᵢ (see the module docs) for fixed α and d.
pub fn basis_signals(form: ChForm, x: &[f64], alpha: f64, d: f64) -> Vec<Vec<f64>> {
    let nl = material_count(form);
    if x.is_empty() {
        return vec![Vec::new(); nl];
    }
    let mut psi = vec![0.0; nl * x.len()];
    let mut decay = vec![0.0; x.len()];
    grid_regression::basis_signals(form, x, alpha, d, &mut psi, &mut decay);
    psi.chunks_exact(x.len()).map(<[f64]>::to_vec).collect()
}
