//! A bounded Levenberg–Marquardt engine for nonlinear least squares, min S(θ) = Σ rᵢ(θ)².
//!
//! # Method
//!
//! Each iteration solves the damped Gauss–Newton system (Marquardt 1963)
//!
//! ```text
//! (JᵀJ + λ·D) δ = −Jᵀr,      D = diag(JᵀJ)  (floored at 1e-12·max diag)
//! ```
//!
//! for the free parameters, where J = ∂r/∂θ. Scaling by diag(JᵀJ) makes the step invariant to
//! the parameters' units. With [`DampingScale::RunningMax`] D is instead the largest
//! diag(JᵀJ) seen so far on the search's path (Moré 1978, §3; the scaling of MINPACK's
//! `lmder`): a parameter whose column shrinks along the path (a saturating exponential, an
//! amplitude heading to zero) keeps the damping it had, so the search does not leap along it. The damping λ follows Nielsen's rule (λ·max(1/3, 1 − (2ρ − 1)³) on
//! success, λ·ν with ν doubling on failure), where ρ is the ratio of the actual to the
//! predicted decrease of S.
//!
//! **Bounds** are handled by a projected step with an active set: a parameter sitting on a
//! bound whose gradient pushes it outward is held for that step, the reduced system is solved
//! and the trial point is projected onto the box. The predicted decrease uses the projected step.
//!
//! **Stopping at a minimum**: a small relative improvement of S ends the search only where
//! the Gauss–Newton step is also small in every free parameter (|δᵢ| ≤ τ·|θᵢ|,
//! [`LmConfig::parameter_tolerance`]); otherwise the search goes on and stops on that test
//! ([`Termination::StepBelowTolerance`]), so a fit that stopped short is never reported as
//! "relative improvement below tolerance". `docs/numerics.md` §1.1 certifies the engine on
//! NIST's reference problems.
//!
//! **Past the iteration limit** ([`LmConfig::extra_iterations`], 0 by default, 900 in the
//! grey-box fits): a search that reaches `max_iterations` while still making progress goes
//! on, for at most `extra_iterations` more, as long as the last k = [`PROGRESS_WINDOW`]
//! accepted iterations lowered S by more than the relative ε_p = [`PROGRESS_DECREASE`],
//!
//! ```text
//! S(θ_{n−k}) − S(θ_n) > ε_p · S(θ_n),
//! ```
//!
//! and it stops as [`Termination::MaxIterations`] once they do not. A long curved valley
//! (NIST's MGH10, Bennett5) is crawled through at a steady rate that this test sees; a
//! search that has stalled is not kept going. A search that stops before the limit is
//! untouched: its iterates are those without the extension, bit for bit.
//!
//! **Restarts** ([`LmConfig::restarts`], 0 by default, 2 in the grey-box fits): a search
//! that ended off a minimum — at the limit after stagnating past `max_iterations` (never at
//! a hard cap: `extra_iterations` = 0), or "converged" on a plateau where a
//! free parameter's column of J has vanished, diag(JᵀJ)ⱼ < [`PLATEAU_COLUMN`]·maxₚₐₜₕ
//! diag(JᵀJ)ⱼ (the parameter no longer acts on the residuals: a saturated exponential,
//! NIST's BoxBOD from its far start, b2 ≈ 115) — searches again from θ₀ with the initial
//! damping λ₀·Rᵏ, R = [`RESTART_DAMPING`], for restart k. A large λ makes the first steps
//! short gradient steps in the metric D (Marquardt 1963: δ → −(λD)⁻¹Jᵀr as λ → ∞), which
//! follow the valley instead of leaping over it onto the plateau; Nielsen's rule then lowers
//! λ by up to 3 per accepted step. The run with the lower S is kept.
//!
//! **Evaporated parameters** (with the restarts): a search that "converged" after moving a
//! free parameter by a factor beyond 1/[`EVAPORATION`] from its start, either way, has let it
//! evaporate to the edge of the model manifold (Transtrum, Machta & Sethna 2011: the typical
//! failure of Levenberg–Marquardt on sloppy models; NIST's MGH10 from its far start, b1 →
//! 10⁻⁵⁰ at S ≈ 1.49·10⁶, where the plateau test sees nothing because b1's column grows).
//! It searches again from θ₀ with each evaporated parameter fenced to
//! [θ₀ⱼ·f, θ₀ⱼ/f], f = [`EVAPORATION_FENCE`], then from where the fenced search ended with
//! the fence off; the run with the lowest S is kept. Both rules act only
//! with the parameter test (`parameter_tolerance` finite), so the improvement rule
//! ([`LmConfig::improvement_rule`]) keeps its bits.
//!
//! **Diverging trials**: a trial point whose residuals cannot be computed (the simulation blows
//! up or errors) counts as a failed step (λ grows) and is reported in
//! [`LmReport::rejected_trials`]; it never aborts the fit.
//!
//! The problem supplies residuals and, optionally, the normal equations JᵀJ, Jᵀr directly
//! (models with analytic sensitivities stream them without storing J, which keeps 10⁶-sample
//! fits in a few MB). Otherwise J is built by forward finite differences, one column per free
//! parameter, in parallel (rayon).
//!
//! Not in the engine: geodesic acceleration (Transtrum & Sethna 2012), which needs Jᵀ times
//! the second directional derivative of the residuals, not available from a problem that
//! streams JᵀJ and Jᵀr. Every NIST reference case is certified without it
//! (`docs/numerics.md` §1.1).
//!
//! References: D. W. Marquardt, "An algorithm for least-squares estimation of nonlinear
//! parameters", SIAM J. Applied Mathematics 11(2), 1963; J. J. Moré, "The Levenberg–Marquardt
//! algorithm: implementation and theory", Lecture Notes in Mathematics 630, Springer, 1978;
//! H. B. Nielsen, "Damping parameter in Marquardt's method", IMM-REP-1999-05, DTU, 1999;
//! J. E. Dennis, R. B. Schnabel, *Numerical Methods for Unconstrained Optimization and
//! Nonlinear Equations*, Prentice Hall, 1983, §7.2; M. K. Transtrum, J. P. Sethna,
//! "Improvements to the Levenberg–Marquardt algorithm for nonlinear least-squares
//! minimization", arXiv:1201.5885, 2012.
//! M. K. Transtrum, B. B. Machta, J. P. Sethna, "Geometry of nonlinear least squares with
//! applications to sloppy models and optimization", Physical Review E 83, 036701, 2011.
//!
//! # Why not the `levenberg-marquardt` crate
//! It needs the whole Jacobian in memory and offers no bounds, per-iteration callback or
//! "expected improvement" stop; every one of those is needed here, and the core algorithm is
//! short.

use super::Termination;
use crate::{Error, Result};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::time::Instant;

/// The normal equations of a least-squares problem at one point, for the free parameters.
#[derive(Clone, Debug)]
pub struct NormalEquations {
    /// JᵀJ (free × free).
    pub jtj: DMatrix<f64>,
    /// Jᵀr (free).
    pub jtr: DVector<f64>,
    /// S = Σ r².
    pub cost: f64,
}

/// What the engine knows of a trial point before its S is computed
/// ([`LeastSquaresProblem::trial_cost_with`]).
#[derive(Clone, Copy, Debug)]
pub struct Trial {
    /// The relative decrease of S the step's quadratic model predicts.
    pub predicted: f64,
    /// The current S: a trial point is accepted only if its S is below this.
    pub ceiling: f64,
}

/// A nonlinear least-squares problem min Σ rᵢ(θ)².
pub trait LeastSquaresProblem: Sync {
    /// Length of the full parameter vector θ (fixed parameters included).
    fn n_params(&self) -> usize;

    /// Number of residuals.
    fn n_residuals(&self) -> usize;

    /// Writes r(θ) into `r` (length [`n_residuals`](Self::n_residuals)). An error, or a
    /// non-finite value, marks θ as a point where the model cannot be evaluated.
    fn residuals(&self, theta: &[f64], r: &mut [f64]) -> Result<()>;

    /// Writes r(θ) into `r` and returns S(θ) = Σ rᵢ², summed in order; an error where the
    /// model cannot be evaluated or a residual is not finite. The default sums the squares of
    /// [`residuals`](Self::residuals); a problem whose residual pass sums them itself, in the
    /// same order, may return that sum and spare the engine a pass over a long record.
    fn residuals_and_cost(&self, theta: &[f64], r: &mut [f64]) -> Result<f64> {
        self.residuals(theta, r)?;
        sum_of_squares(r)
    }

    /// S(θ) at a trial point of an engine that has its normal equations from
    /// [`normal_equations`](Self::normal_equations) and so never reads the residuals
    /// themselves: `r` is scratch, to be sized by whoever needs it (a long record's is
    /// megabytes, not worth touching when unused). The default sizes it and calls
    /// [`residuals_and_cost`](Self::residuals_and_cost).
    fn trial_cost(&self, theta: &[f64], r: &mut Vec<f64>) -> Result<f64> {
        r.resize(self.n_residuals(), 0.0);
        self.residuals_and_cost(theta, r)
    }

    /// [`trial_cost`](Self::trial_cost) with what the engine knows of the trial point (see
    /// [`Trial`]). A small `trial.predicted` says the point is likely the fit's last (an
    /// engine near a minimum converges quadratically): a problem may start work that only the
    /// fit's end needs beside it. The value returned must be `trial_cost`'s, except that once
    /// S(θ) is known to exceed `trial.ceiling` a problem may stop and return any lower bound
    /// of S(θ) above the ceiling: the point is rejected whatever its S. The default does
    /// neither.
    fn trial_cost_with(&self, theta: &[f64], r: &mut Vec<f64>, _trial: Trial) -> Result<f64> {
        self.trial_cost(theta, r)
    }

    /// Optionally the normal equations at θ for the parameters `free`, computed analytically.
    /// `None` (the default) makes the engine use finite differences.
    fn normal_equations(&self, _theta: &[f64], _free: &[usize]) -> Option<Result<NormalEquations>> {
        None
    }

    /// The sum of squares below which the fit is exact to working precision (default 0).
    fn cost_floor(&self) -> f64 {
        0.0
    }

    /// True when S = `cost` is at or below [`cost_floor`](Self::cost_floor). A problem
    /// whose floor takes a pass over a long record to compute may first rule it out with a
    /// cheaper upper bound of the floor (the answer must be the same).
    fn is_exact_fit(&self, cost: f64) -> bool {
        cost <= self.cost_floor()
    }
}

/// S = Σ rᵢ², summed in order: the engine's criterion, or an error at the first residual that
/// is not finite.
pub fn sum_of_squares(r: &[f64]) -> Result<f64> {
    match r.iter().position(|v| !v.is_finite()) {
        None => Ok(r.iter().map(|v| v * v).sum()),
        Some(i) => Err(Error::Diverged {
            index: i,
            reason: "a residual is not finite".into(),
        }),
    }
}

/// One accepted iteration, as passed to the progress callback and kept in the history.
#[derive(Clone, Debug, serde::Serialize)]
pub struct IterationRecord {
    /// Iteration number (1-based).
    pub iteration: usize,
    /// S = Σ r² after the iteration.
    pub cost: f64,
    /// The damping λ used.
    pub lambda: f64,
    /// The full parameter vector after the iteration.
    pub theta: Vec<f64>,
}

/// What a progress callback asks the engine to do next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Control {
    /// Go on.
    Continue,
    /// Stop now and report [`Termination::Stopped`].
    Stop,
}

/// Settings of the engine.
#[derive(Clone, Debug)]
pub struct LmConfig {
    /// Maximum number of iterations (Jacobian evaluations) of a run, unless the search is
    /// still progressing there ([`extra_iterations`](Self::extra_iterations)).
    pub max_iterations: usize,
    /// Stop when the relative decrease of S that the next step predicts, or both the actual
    /// and the predicted decrease of an accepted step, fall below this (Gunnar et al. 2006
    /// use 0.01 % = 1e-4, MATLAB's "expected improvement").
    pub improvement_tolerance: f64,
    /// Stop when the relative step ‖δ‖/(‖θ‖ + tol) falls below this.
    pub step_tolerance: f64,
    /// A small improvement (`improvement_tolerance`) ends the search only at a minimum: when
    /// the Gauss–Newton step δ also satisfies |δᵢ| ≤ τ·|θᵢ| for every free parameter, with
    /// τ = `parameter_tolerance`·√(`improvement_tolerance`/10⁻¹⁰) (the decrease of S is
    /// quadratic in the step, so a looser improvement tolerance asks proportionally less of
    /// the parameters). Otherwise the search goes on until the step passes this test (it then
    /// reports [`Termination::StepBelowTolerance`]) or another rule stops it.
    /// `f64::INFINITY` leaves the improvement test alone.
    pub parameter_tolerance: f64,
    /// Stop when every |cos| between r and a column of J falls below this (MINPACK's gtol).
    pub gradient_tolerance: f64,
    /// Initial damping λ₀ (dimensionless: the damping term is λ·diag(JᵀJ)).
    pub initial_damping: f64,
    /// Relative finite-difference step (times max(|θⱼ|, 1e-3·typical)).
    pub fd_step: f64,
    /// The scale D of the damping term λ·D.
    pub damping_scale: DampingScale,
    /// Iterations past `max_iterations` that a search still making progress may take (0:
    /// `max_iterations` is a hard cap). Past the cap the search goes on only while the last
    /// [`PROGRESS_WINDOW`] iterations lowered S by more than the relative
    /// [`PROGRESS_DECREASE`]; it stops as [`Termination::MaxIterations`] once they do not.
    /// Only the rule with the parameter test (`parameter_tolerance` finite) extends.
    pub extra_iterations: usize,
    /// Restarts of a search that ended without reaching a minimum — at the iteration limit
    /// after stagnating past `max_iterations` (only with `extra_iterations` > 0: a hard cap
    /// is not restarted), or on a plateau where a free parameter's column of J has vanished (below
    /// [`PLATEAU_COLUMN`] of the largest it had on the path, so the parameter no longer acts
    /// on the residuals). Each restart searches again from the start with the damping
    /// [`RESTART_DAMPING`]ᵏ·λ₀ for restart k (ever more cautious first steps), and the run
    /// with the lower S is kept. A converged search that has moved a free parameter beyond
    /// 1/[`EVAPORATION`] times its start searches again with it fenced
    /// ([`EVAPORATION_FENCE`]), then free (the module doc).
    /// Only the rule with the parameter test restarts; 0 never does.
    pub restarts: usize,
}

/// Iterations over which the progress test past `max_iterations` looks back
/// ([`LmConfig::extra_iterations`]).
pub const PROGRESS_WINDOW: usize = 10;
/// The relative decrease of S over [`PROGRESS_WINDOW`] iterations below which a search past
/// `max_iterations` has stagnated ([`LmConfig::extra_iterations`]).
pub const PROGRESS_DECREASE: f64 = 1e-9;
/// A free parameter whose diag(JᵀJ) is below this fraction of the largest it had on the
/// search's path has stopped acting on the residuals ([`LmConfig::restarts`]).
pub const PLATEAU_COLUMN: f64 = 1e-20;
/// The factor on λ₀ of each restart over the run before it ([`LmConfig::restarts`]).
pub const RESTART_DAMPING: f64 = 1e4;
/// A free parameter that a converged search has moved from its start by more than the factor
/// 1/`EVAPORATION` (either way) has evaporated ([`LmConfig::restarts`]).
pub const EVAPORATION: f64 = 1e-20;
/// The fence of an evaporated parameter's second search: [θ₀ⱼ·f, θ₀ⱼ/f] for f =
/// `EVAPORATION_FENCE` ([`LmConfig::restarts`]).
pub const EVAPORATION_FENCE: f64 = 1e-3;

/// The scale D of the damping term λ·D of [`LmConfig`] (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DampingScale {
    /// D = diag(JᵀJ) at the current point (Marquardt 1963).
    Current,
    /// D = the elementwise largest diag(JᵀJ) of the points the search has accepted (Moré
    /// 1978), which the grey-box fits use: it takes NIST's MGH09, Eckerle4 and MGH17 from
    /// their far starts to the certified minimum (`docs/numerics.md` §1.1).
    RunningMax,
}

impl Default for LmConfig {
    fn default() -> Self {
        Self {
            max_iterations: 100,
            improvement_tolerance: 1e-10,
            step_tolerance: 1e-12,
            parameter_tolerance: 1e-7,
            gradient_tolerance: 1e-12,
            initial_damping: 1e-3,
            fd_step: 1e-7,
            damping_scale: DampingScale::Current,
            extra_iterations: 0,
            restarts: 0,
        }
    }
}

impl LmConfig {
    /// The default settings with the improvement test alone (`parameter_tolerance` = ∞), the
    /// stopping rule before the parameter test existed. The recipes whose published figures
    /// are kept to the bit use it: the Bouc–Wen benchmark, the cascade, the hysteresis fit and
    /// the actuator recipe (`docs/numerics.md` §1).
    pub fn improvement_rule() -> Self {
        Self {
            parameter_tolerance: f64::INFINITY,
            ..Self::default()
        }
    }
}

/// Result of a Levenberg–Marquardt run.
#[derive(Clone, Debug)]
pub struct LmReport {
    /// The final full parameter vector.
    pub theta: Vec<f64>,
    /// Indices of the free parameters.
    pub free: Vec<usize>,
    /// Final S = Σ r².
    pub cost: f64,
    /// S at the start.
    pub initial_cost: f64,
    /// Number of residuals N.
    pub n_residuals: usize,
    /// Iterations performed.
    pub iterations: usize,
    /// Residual evaluations (trial points and finite differences).
    pub function_evaluations: usize,
    /// Evaluations of the residuals alone (for a simulated model: simulations without
    /// sensitivities): the start, every trial point, every finite-difference column.
    pub residual_evaluations: usize,
    /// Evaluations of the analytic normal equations (for a simulated model: simulations with
    /// forward sensitivities), one per accepted point and one at the start.
    pub sensitivity_evaluations: usize,
    /// Trial points rejected because the model could not be evaluated there.
    pub rejected_trials: usize,
    /// Why the search stopped.
    pub termination: Termination,
    /// Accepted iterations.
    pub history: Vec<IterationRecord>,
    /// JᵀJ of the free parameters at the final point (for the covariance).
    pub jtj: DMatrix<f64>,
    /// Wall-clock time.
    pub elapsed_s: f64,
}

/// Parameter covariance derived from an [`LmReport`].
#[derive(Clone, Debug)]
pub struct Covariance {
    /// Full-size covariance (zero rows/columns for fixed parameters).
    pub matrix: DMatrix<f64>,
    /// Standard deviations (0 for fixed parameters, NaN when not identifiable).
    pub std: Vec<f64>,
    /// Correlation matrix of the full vector (identity entries for fixed parameters).
    pub correlation: DMatrix<f64>,
    /// Residual variance estimate σ² = S/(N − p_free).
    pub sigma2: f64,
    /// Free parameters that the data cannot determine (singular information matrix).
    pub unidentifiable: Vec<usize>,
}

impl LmReport {
    /// Covariance σ²(JᵀJ)⁻¹ of the free parameters, σ² = S/(N − p), the asymptotic covariance
    /// of an output-error estimate with white residuals (Ljung 1999, §9.3).
    pub fn covariance(&self) -> Covariance {
        let n_theta = self.theta.len();
        let p = self.free.len();
        let sigma2 = self.cost / (self.n_residuals.saturating_sub(p)).max(1) as f64;
        let mut matrix = DMatrix::zeros(n_theta, n_theta);
        let mut unidentifiable = Vec::new();
        if p > 0 {
            let (inv, null) = scaled_inverse(&self.jtj);
            unidentifiable = null.into_iter().map(|k| self.free[k]).collect();
            for (a, &i) in self.free.iter().enumerate() {
                for (b, &j) in self.free.iter().enumerate() {
                    matrix[(i, j)] = sigma2 * inv[(a, b)];
                }
            }
        }
        let std: Vec<f64> = (0..n_theta)
            .map(|i| {
                if unidentifiable.contains(&i) {
                    f64::NAN
                } else {
                    matrix[(i, i)].max(0.0).sqrt()
                }
            })
            .collect();
        let correlation = DMatrix::from_fn(n_theta, n_theta, |i, j| {
            if i == j {
                1.0
            } else if std[i] > 0.0 && std[j] > 0.0 {
                matrix[(i, j)] / (std[i] * std[j])
            } else {
                0.0
            }
        });
        Covariance {
            matrix,
            std,
            correlation,
            sigma2,
            unidentifiable,
        }
    }
}

/// Pseudo-inverse of a symmetric positive semi-definite matrix after scaling it to unit
/// diagonal; also returns the indices that dominate its (numerical) null space.
fn scaled_inverse(a: &DMatrix<f64>) -> (DMatrix<f64>, Vec<usize>) {
    let p = a.nrows();
    let s: Vec<f64> = (0..p)
        .map(|i| a[(i, i)].max(f64::MIN_POSITIVE).sqrt())
        .collect();
    let scaled = DMatrix::from_fn(p, p, |i, j| a[(i, j)] / (s[i] * s[j]));
    let eig = scaled.symmetric_eigen();
    let lmax = eig.eigenvalues.max();
    let mut inv = DMatrix::zeros(p, p);
    let mut null = Vec::new();
    for k in 0..p {
        let l = eig.eigenvalues[k];
        let v = eig.eigenvectors.column(k);
        if l > 1e-13 * lmax {
            inv += v * v.transpose() / l;
        } else {
            let big = v.amax();
            null.extend((0..p).filter(|&i| v[i].abs() > 0.3 * big));
        }
    }
    null.sort_unstable();
    null.dedup();
    (
        DMatrix::from_fn(p, p, |i, j| inv[(i, j)] / (s[i] * s[j])),
        null,
    )
}

/// Minimises Σ r(θ)² from `theta0` over the box [lower, upper] for the parameters in `free`.
///
/// `callback` is called after every accepted iteration; returning [`Control::Stop`] ends the
/// search. Errors only when the model cannot be evaluated at `theta0` (or differentiated
/// there); every later difficulty is a [`Termination`] reason.
pub fn minimize(
    problem: &dyn LeastSquaresProblem,
    theta0: &[f64],
    free: &[usize],
    lower: &[f64],
    upper: &[f64],
    config: &LmConfig,
    callback: &mut dyn FnMut(&IterationRecord) -> Control,
) -> Result<LmReport> {
    let start = Instant::now();
    let mut state = State::new(problem, theta0, free, lower, upper, config)?;
    let mut termination = state.run(callback)?;
    let restarting = config.restarts > 0 && config.parameter_tolerance.is_finite();
    let mut factor = 1.0;
    for _ in 0..config.restarts {
        if !restarting || !state.needs_restart(&termination) {
            break;
        }
        factor *= RESTART_DAMPING;
        let restart_config = LmConfig {
            initial_damping: config.initial_damping * factor,
            ..config.clone()
        };
        let mut again = state.follow_up(theta0, lower, upper, &restart_config)?;
        let again_termination = again.run(callback)?;
        state.adopt(again, again_termination, &mut termination);
    }
    let evaporated = match restarting && termination.converged() {
        true => state.evaporated(theta0),
        false => Vec::new(),
    };
    if !evaporated.is_empty() {
        // Fenced from θ₀, then free from where the fence left the search.
        let (mut fenced_lower, mut fenced_upper) = (lower.to_vec(), upper.to_vec());
        for &j in &evaporated {
            let (a, b) = (theta0[j] * EVAPORATION_FENCE, theta0[j] / EVAPORATION_FENCE);
            fenced_lower[j] = fenced_lower[j].max(a.min(b));
            fenced_upper[j] = fenced_upper[j].min(a.max(b));
        }
        let mut fenced = state.follow_up(theta0, &fenced_lower, &fenced_upper, config)?;
        let fenced_termination = fenced.run(callback)?;
        let from = fenced.theta.clone();
        let mut freed = fenced.follow_up(&from, lower, upper, config)?;
        let mut freed_termination = freed.run(callback)?;
        if fenced.system.cost < freed.system.cost {
            // The free run cannot end above its start; kept for the counters' sake.
            freed.adopt(fenced, fenced_termination, &mut freed_termination);
        }
        state.adopt(freed, freed_termination, &mut termination);
    }
    Ok(state.into_report(termination, start.elapsed().as_secs_f64()))
}

/// The engine's working state.
struct State<'a> {
    problem: &'a dyn LeastSquaresProblem,
    config: &'a LmConfig,
    free: Vec<usize>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    theta: Vec<f64>,
    residuals: Vec<f64>,
    /// The residuals of trial points (reused from step to step: a long record's buffer is
    /// megabytes, page-faulted afresh if allocated per step).
    trial: Vec<f64>,
    /// True while the normal equations come from the problem: the residual values are then
    /// never read, and trial points ask for their cost alone
    /// ([`LeastSquaresProblem::trial_cost`]).
    analytic: bool,
    system: NormalEquations,
    initial_cost: f64,
    lambda: f64,
    nu: f64,
    iterations: usize,
    fevals: usize,
    /// Residual-only evaluations.
    plain_evals: usize,
    /// Analytic normal-equation evaluations.
    sensitivity_evals: usize,
    rejected: usize,
    history: Vec<IterationRecord>,
    /// True once the improvement test has passed at a point where the Gauss–Newton step was
    /// not yet small: the search then stops on the parameter test alone.
    refining: bool,
    /// D of the damping term, per free parameter ([`LmConfig::damping_scale`]).
    scale: Vec<f64>,
    /// The largest diag(JᵀJ) of the accepted points, per free parameter
    /// ([`LmConfig::restarts`]).
    largest: Vec<f64>,
    /// Iterations of the runs before this one ([`LmConfig::restarts`]).
    first: usize,
}

/// Gauss–Newton steps at most at an exact fit ([`State::polish`]).
const POLISH_STEPS: usize = 5;

/// Outcome of one damped step.
enum StepOutcome {
    Accepted { rel_actual: f64, rel_predicted: f64 },
    Rejected,
    TooSmall,
}

impl<'a> State<'a> {
    fn new(
        problem: &'a dyn LeastSquaresProblem,
        theta0: &[f64],
        free: &[usize],
        lower: &[f64],
        upper: &[f64],
        config: &'a LmConfig,
    ) -> Result<Self> {
        // Analytic normal equations carry the cost S(θ₀): the residuals themselves are then
        // not needed, and computing them would cost one more simulation per fit. Their
        // buffers are sized when first needed (a long record's are megabytes).
        let mut residuals = Vec::new();
        let analytic = problem.normal_equations(theta0, free);
        if analytic.is_none() {
            residuals.resize(problem.n_residuals(), 0.0);
            problem
                .residuals(theta0, &mut residuals)
                .map_err(initial_error)?;
            if let Some(i) = residuals.iter().position(|r| !r.is_finite()) {
                return Err(non_finite_start(i));
            }
        }
        let mut state = Self {
            problem,
            config,
            free: free.to_vec(),
            lower: lower.to_vec(),
            upper: upper.to_vec(),
            theta: theta0.to_vec(),
            trial: Vec::new(),
            analytic: analytic.is_some(),
            residuals,
            system: NormalEquations {
                jtj: DMatrix::zeros(0, 0),
                jtr: DVector::zeros(0),
                cost: 0.0,
            },
            initial_cost: 0.0,
            lambda: 0.0,
            nu: 2.0,
            iterations: 0,
            fevals: 0,
            plain_evals: 0,
            sensitivity_evals: 0,
            rejected: 0,
            history: Vec::new(),
            refining: false,
            scale: Vec::new(),
            largest: Vec::new(),
            first: 0,
        };
        state.system = match analytic {
            Some(system) => {
                state.fevals += 1;
                state.sensitivity_evals += 1;
                let system = system.map_err(initial_error)?;
                if !system.cost.is_finite() {
                    return Err(non_finite_start(0));
                }
                system
            }
            None => {
                state.fevals += 1;
                state.plain_evals += 1;
                state.normal_equations()?
            }
        };
        state.initial_cost = state.system.cost;
        state.scale = state.system.jtj.diagonal().iter().copied().collect();
        state.largest = state.scale.clone();
        // D = diag(JᵀJ) carries the scale, so λ itself is dimensionless.
        state.lambda = config.initial_damping;
        Ok(state)
    }

    fn run(
        &mut self,
        callback: &mut dyn FnMut(&IterationRecord) -> Control,
    ) -> Result<Termination> {
        if self.free.is_empty() {
            return Ok(Termination::NothingToEstimate);
        }
        loop {
            if self.problem.is_exact_fit(self.system.cost) {
                self.polish();
                return Ok(Termination::ZeroResidual);
            }
            if self.gradient_is_small() {
                return Ok(Termination::GradientBelowTolerance);
            }
            // MATLAB's "expected improvement": what the next step promises, before paying for
            // a trial simulation; it stops the search only where the parameters have
            // converged too (`LmConfig::parameter_tolerance`).
            let (expected, step) = self.gauss_newton_promise();
            if expected < self.config.improvement_tolerance || self.refining {
                if step <= self.parameter_tolerance() {
                    return Ok(match self.refining {
                        true => Termination::StepBelowTolerance,
                        false => Termination::ImprovementBelowTolerance { relative: expected },
                    });
                }
                self.refining = true;
            }
            if self.iterations - self.first >= self.config.max_iterations && !self.may_go_on() {
                return Ok(Termination::MaxIterations);
            }
            self.iterations += 1;
            let outcome = self.damped_step();
            match outcome {
                StepOutcome::TooSmall => return Ok(Termination::StepBelowTolerance),
                StepOutcome::Rejected => return Ok(Termination::NoDescent),
                StepOutcome::Accepted {
                    rel_actual,
                    rel_predicted,
                } => {
                    let record = IterationRecord {
                        iteration: self.iterations,
                        cost: self.system.cost,
                        lambda: self.lambda,
                        theta: self.theta.clone(),
                    };
                    let control = callback(&record);
                    self.history.push(record);
                    if control == Control::Stop {
                        return Ok(Termination::Stopped);
                    }
                    let tol = self.config.improvement_tolerance;
                    if !self.refining && rel_actual < tol && rel_predicted < tol {
                        if self.gauss_newton_promise().1 <= self.parameter_tolerance() {
                            return Ok(Termination::ImprovementBelowTolerance {
                                relative: rel_actual,
                            });
                        }
                        self.refining = true;
                    }
                }
            }
        }
    }

    /// At an exact fit (S at the problem's rounding floor), Gauss–Newton steps while they
    /// lower S, at most [`POLISH_STEPS`]: the floor is a bound, and S — hence σ² and the
    /// standard deviations, which scale with √S — settles only at the rounding level itself
    /// (NIST's Lanczos1, S ≈ 1.4·10⁻²⁵). Only the rule with the parameter test polishes
    /// ([`LmConfig::parameter_tolerance`] finite); the improvement rule keeps its bits.
    fn polish(&mut self) {
        if !self.config.parameter_tolerance.is_finite() {
            return;
        }
        for _ in 0..POLISH_STEPS {
            let Some(candidate) = self.candidate_with(0.0) else {
                return;
            };
            let mut trial = std::mem::take(&mut self.trial);
            trial.resize(self.problem.n_residuals(), 0.0);
            self.fevals += 1;
            self.plain_evals += 1;
            let cost = self.problem.residuals_and_cost(&candidate, &mut trial);
            let better = matches!(cost, Ok(c) if c < self.system.cost);
            if better {
                let saved = std::mem::replace(&mut self.theta, candidate);
                std::mem::swap(&mut self.residuals, &mut trial);
                match self.normal_equations() {
                    Ok(system) => self.system = system,
                    Err(_) => {
                        self.theta = saved;
                        std::mem::swap(&mut self.residuals, &mut trial);
                        self.trial = trial;
                        return;
                    }
                }
            }
            self.trial = trial;
            if !better {
                return;
            }
        }
    }

    /// A new search from `theta0` in the box [lower, upper] under `config` that carries on
    /// this one's counters and history ([`LmConfig::restarts`]).
    fn follow_up<'b>(
        &mut self,
        theta0: &[f64],
        lower: &[f64],
        upper: &[f64],
        config: &'b LmConfig,
    ) -> Result<State<'b>>
    where
        'a: 'b,
    {
        let mut again = State::new(self.problem, theta0, &self.free, lower, upper, config)?;
        again.iterations = self.iterations;
        again.first = self.iterations;
        again.fevals += self.fevals;
        again.plain_evals += self.plain_evals;
        again.sensitivity_evals += self.sensitivity_evals;
        again.rejected = self.rejected;
        again.history = std::mem::take(&mut self.history);
        Ok(again)
    }

    /// Takes the counters and history of `again`, a [`State::follow_up`] of this search that
    /// ended with `again_termination`, and its point too where its S is lower.
    fn adopt(
        &mut self,
        mut again: State<'_>,
        again_termination: Termination,
        termination: &mut Termination,
    ) {
        if again.system.cost < self.system.cost {
            *termination = again_termination;
            std::mem::swap(&mut self.theta, &mut again.theta);
            self.system = again.system;
            self.scale = again.scale;
            self.largest = again.largest;
        }
        self.iterations = again.iterations;
        self.fevals = again.fevals;
        self.plain_evals = again.plain_evals;
        self.sensitivity_evals = again.sensitivity_evals;
        self.rejected = again.rejected;
        self.history = again.history;
    }

    /// The free parameters that the search has moved from their start by a factor beyond
    /// 1/[`EVAPORATION`] either way (or to zero) ([`LmConfig::restarts`]).
    fn evaporated(&self, theta0: &[f64]) -> Vec<usize> {
        self.free
            .iter()
            .copied()
            .filter(|&j| {
                let (from, to) = (theta0[j].abs(), self.theta[j].abs());
                from > 0.0
                    && from.is_finite()
                    && !(to > from * EVAPORATION && to * EVAPORATION < from)
            })
            .collect()
    }

    /// Past `max_iterations`: true while the search may take another iteration
    /// ([`LmConfig::extra_iterations`]).
    fn may_go_on(&self) -> bool {
        if !self.config.parameter_tolerance.is_finite()
            || self.iterations - self.first
                >= self.config.max_iterations + self.config.extra_iterations
        {
            return false;
        }
        let n = self.history.len();
        if n < self.first + PROGRESS_WINDOW + 1 {
            return false;
        }
        let before = self.history[n - 1 - PROGRESS_WINDOW].cost;
        let now = self.history[n - 1].cost;
        (before - now) > PROGRESS_DECREASE * now
    }

    /// True when a search that ended with `termination` is not at a minimum
    /// ([`LmConfig::restarts`]).
    fn needs_restart(&self, termination: &Termination) -> bool {
        if matches!(termination, Termination::MaxIterations) {
            // Stagnated past the limit; a search held to a hard cap is not restarted.
            return self.config.extra_iterations > 0;
        }
        termination.converged()
            && !matches!(termination, Termination::ZeroResidual)
            && (0..self.free.len())
                .any(|k| self.system.jtj[(k, k)] < PLATEAU_COLUMN * self.largest[k])
    }

    /// τ of [`LmConfig::parameter_tolerance`].
    fn parameter_tolerance(&self) -> f64 {
        self.config.parameter_tolerance * (self.config.improvement_tolerance / 1e-10).sqrt()
    }

    /// The relative decrease of S that the Gauss–Newton step predicts, and the step's largest
    /// relative size maxᵢ |δᵢ|/|θᵢ| over the free parameters not held by a bound (both
    /// infinite when no step can be solved for, so the search goes on and λ adapts).
    fn gauss_newton_promise(&self) -> (f64, f64) {
        // The Gauss–Newton step (λ → 0), unprojected: how far the quadratic model still is
        // from its minimum. The damped step would shrink with λ, and a step clipped by a
        // bound can promise little while other directions still have much to give.
        let Some((idx, delta)) = self.step_vector(1e-12) else {
            return (f64::INFINITY, f64::INFINITY);
        };
        let step = idx
            .iter()
            .zip(delta.iter())
            .map(|(&k, d)| d.abs() / self.theta[self.free[k]].abs().max(f64::MIN_POSITIVE))
            .fold(0.0, f64::max);
        let g = DVector::from_fn(idx.len(), |r, _| self.system.jtr[idx[r]]);
        let h = DMatrix::from_fn(idx.len(), idx.len(), |r, c| {
            self.system.jtj[(idx[r], idx[c])]
        });
        let predicted = -2.0 * delta.dot(&g) - (delta.transpose() * h * &delta)[(0, 0)];
        (predicted / self.system.cost, step)
    }

    /// Tries damped steps with growing λ until one decreases S; recomputes the normal
    /// equations at the new point.
    fn damped_step(&mut self) -> StepOutcome {
        let mut trial = std::mem::take(&mut self.trial);
        let outcome = self.damped_step_with(&mut trial);
        self.trial = trial;
        outcome
    }

    /// [`damped_step`](Self::damped_step) with `trial` as the buffer of trial residuals.
    fn damped_step_with(&mut self, trial: &mut Vec<f64>) -> StepOutcome {
        const MAX_FAILURES: usize = 60;
        for _ in 0..MAX_FAILURES {
            let Some(candidate) = self.candidate() else {
                self.grow_damping();
                continue;
            };
            let step_norm = candidate
                .iter()
                .zip(&self.theta)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                .sqrt();
            let theta_norm = self.theta.iter().map(|v| v * v).sum::<f64>().sqrt();
            let tol = self.config.step_tolerance;
            if step_norm <= tol * (theta_norm + tol) {
                return StepOutcome::TooSmall;
            }
            let predicted = self.predicted_decrease(&candidate);
            self.fevals += 1;
            self.plain_evals += 1;
            let evaluated = match self.analytic {
                true => self.problem.trial_cost_with(
                    &candidate,
                    trial,
                    Trial {
                        predicted: predicted / self.system.cost,
                        ceiling: self.system.cost,
                    },
                ),
                false => {
                    trial.resize(self.problem.n_residuals(), 0.0);
                    self.problem.residuals_and_cost(&candidate, trial)
                }
            };
            let cost = match evaluated {
                Ok(cost) => cost,
                Err(_) => {
                    self.rejected += 1;
                    self.grow_damping();
                    continue;
                }
            };
            let old = self.system.cost;
            let rho = (old - cost) / predicted;
            if cost < old && predicted > 0.0 && rho > 1e-4 {
                // Evaluate the new point's normal equations before committing, so that a
                // failure there is a rejected step, not an abort.
                let saved = std::mem::replace(&mut self.theta, candidate);
                std::mem::swap(&mut self.residuals, trial);
                match self.normal_equations() {
                    Ok(system) => {
                        self.system = system;
                        self.update_scale();
                        self.lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                        self.nu = 2.0;
                        return StepOutcome::Accepted {
                            rel_actual: (old - cost) / old,
                            rel_predicted: predicted / old,
                        };
                    }
                    Err(_) => {
                        self.theta = saved;
                        std::mem::swap(&mut self.residuals, trial);
                        self.rejected += 1;
                    }
                }
            }
            self.grow_damping();
        }
        StepOutcome::Rejected
    }

    fn grow_damping(&mut self) {
        self.lambda *= self.nu;
        self.nu *= 2.0;
    }

    /// D after a new point's normal equations ([`DampingScale`]).
    fn update_scale(&mut self) {
        let diagonal = self.system.jtj.diagonal();
        for (d, &now) in self.largest.iter_mut().zip(diagonal.iter()) {
            *d = d.max(now);
        }
        for (d, &now) in self.scale.iter_mut().zip(diagonal.iter()) {
            *d = match self.config.damping_scale {
                DampingScale::Current => now,
                DampingScale::RunningMax => d.max(now),
            };
        }
    }

    /// The projected trial point for the current λ, or None when the damped system cannot be
    /// factorised.
    fn candidate(&self) -> Option<Vec<f64>> {
        self.candidate_with(self.lambda)
    }

    /// The projected trial point for damping `lambda`.
    fn candidate_with(&self, lambda: f64) -> Option<Vec<f64>> {
        let (idx, delta) = self.step_vector(lambda)?;
        let mut theta = self.theta.clone();
        for (r, &k) in idx.iter().enumerate() {
            let i = self.free[k];
            theta[i] = (theta[i] + delta[r]).clamp(self.lower[i], self.upper[i]);
        }
        theta.iter().all(|v| v.is_finite()).then_some(theta)
    }

    /// The damped step for the free parameters that are not held by an active bound: their
    /// positions in `free` and the step, before projection onto the box.
    fn step_vector(&self, lambda: f64) -> Option<(Vec<usize>, DVector<f64>)> {
        let g = &self.system.jtr;
        let idx: Vec<usize> = (0..self.free.len())
            .filter(|&k| {
                let i = self.free[k];
                let held = (self.theta[i] <= self.lower[i] && g[k] > 0.0)
                    || (self.theta[i] >= self.upper[i] && g[k] < 0.0);
                !held
            })
            .collect();
        if idx.is_empty() {
            return None;
        }
        let jtj = &self.system.jtj;
        let max_diag = (0..self.free.len())
            .map(|k| jtj[(k, k)])
            .fold(0.0, f64::max);
        let floor = 1e-12 * max_diag.max(f64::MIN_POSITIVE);
        let m = idx.len();
        let a = DMatrix::from_fn(m, m, |r, c| {
            let v = jtj[(idx[r], idx[c])];
            if r == c {
                v + lambda * self.scale[idx[r]].max(floor)
            } else {
                v
            }
        });
        let rhs = DVector::from_fn(m, |r, _| -g[idx[r]]);
        let delta = a.cholesky()?.solve(&rhs);
        delta.iter().all(|v| v.is_finite()).then_some((idx, delta))
    }

    /// S − ‖r + Jδ‖² for the step δ = candidate − θ.
    fn predicted_decrease(&self, candidate: &[f64]) -> f64 {
        let delta = DVector::from_iterator(
            self.free.len(),
            self.free.iter().map(|&i| candidate[i] - self.theta[i]),
        );
        -2.0 * delta.dot(&self.system.jtr) - (delta.transpose() * &self.system.jtj * &delta)[(0, 0)]
    }

    fn gradient_is_small(&self) -> bool {
        let s = self.system.cost;
        (0..self.free.len()).all(|k| {
            let col = self.system.jtj[(k, k)];
            col == 0.0
                || self.system.jtr[k].abs() <= self.config.gradient_tolerance * (col * s).sqrt()
        })
    }

    /// The normal equations at the current θ, analytic when the problem offers them.
    fn normal_equations(&mut self) -> Result<NormalEquations> {
        if let Some(system) = self.problem.normal_equations(&self.theta, &self.free) {
            self.fevals += 1;
            self.sensitivity_evals += 1;
            let system = system?;
            if !system.cost.is_finite() {
                return Err(Error::Diverged {
                    index: 0,
                    reason: "non-finite cost".into(),
                });
            }
            return Ok(system);
        }
        if self.analytic {
            // Finite differences need the residuals at θ, which trial costs did not write.
            self.analytic = false;
            self.residuals.resize(self.problem.n_residuals(), 0.0);
            self.problem.residuals(&self.theta, &mut self.residuals)?;
        }
        self.finite_difference_system()
    }

    /// Forward-difference Jacobian, one column per free parameter, computed in parallel.
    fn finite_difference_system(&mut self) -> Result<NormalEquations> {
        let n = self.residuals.len();
        let columns: Vec<Result<Vec<f64>>> = self
            .free
            .par_iter()
            .map(|&i| {
                fd_column(
                    self.problem,
                    &self.theta,
                    &self.residuals,
                    i,
                    self.lower[i],
                    self.upper[i],
                    self.config.fd_step,
                )
            })
            .collect();
        self.fevals += self.free.len();
        self.plain_evals += self.free.len();
        let mut jac = DMatrix::zeros(n, self.free.len());
        for (k, column) in columns.into_iter().enumerate() {
            jac.set_column(k, &DVector::from_vec(column?));
        }
        let r = DVector::from_column_slice(&self.residuals);
        Ok(NormalEquations {
            jtj: jac.tr_mul(&jac),
            jtr: jac.tr_mul(&r),
            cost: r.norm_squared(),
        })
    }

    fn into_report(self, termination: Termination, elapsed_s: f64) -> LmReport {
        LmReport {
            theta: self.theta,
            free: self.free,
            cost: self.system.cost,
            initial_cost: self.initial_cost,
            n_residuals: self.problem.n_residuals(),
            iterations: self.iterations,
            function_evaluations: self.fevals,
            residual_evaluations: self.plain_evals,
            sensitivity_evaluations: self.sensitivity_evals,
            rejected_trials: self.rejected,
            termination,
            history: self.history,
            jtj: self.system.jtj,
            elapsed_s,
        }
    }
}

/// The error of a model that cannot be evaluated at its initial parameters, said so.
fn initial_error(e: Error) -> Error {
    match e {
        Error::Diverged { index, reason } => Error::Diverged {
            index,
            reason: format!("the model cannot be simulated from its initial parameters ({reason})"),
        },
        other => other,
    }
}

/// A non-finite residual at the initial parameters (sample `index`).
fn non_finite_start(index: usize) -> Error {
    Error::Diverged {
        index,
        reason: "the model cannot be simulated from its initial parameters (non-finite output)"
            .into(),
    }
}

/// One forward-difference column ∂r/∂θᵢ, stepping inward when the forward step would leave the
/// box or cannot be evaluated.
fn fd_column(
    problem: &dyn LeastSquaresProblem,
    theta: &[f64],
    r0: &[f64],
    i: usize,
    lower: f64,
    upper: f64,
    rel_step: f64,
) -> Result<Vec<f64>> {
    let h = rel_step * theta[i].abs().max(1e-3);
    let mut r = vec![0.0; r0.len()];
    for step in [h, -h] {
        let moved = theta[i] + step;
        if moved > upper || moved < lower {
            continue;
        }
        let mut t = theta.to_vec();
        t[i] = moved;
        let actual = moved - theta[i];
        if problem.residuals(&t, &mut r).is_ok() && r.iter().all(|v| v.is_finite()) {
            return Ok(r.iter().zip(r0).map(|(a, b)| (a - b) / actual).collect());
        }
    }
    Err(Error::Diverged {
        index: 0,
        reason: format!(
            "cannot differentiate with respect to parameter {i}: the model fails on both sides"
        ),
    })
}
