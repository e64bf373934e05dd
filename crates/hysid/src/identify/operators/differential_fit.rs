//! The one driver of the differential-operator fits (Bouc–Wen, Duhem, Dahl, Jiles–Atherton):
//! the output-error criterion
//!
//! ```text
//! V(θ) = Σ_t (y_t − Γ_θ[u]_t)²,      Γ_θ: dx/du = F(u, x, δ; θ), ŷ = h(u, x; θ)
//! ```
//!
//! minimised from the data alone. A family says what it is ([`DifferentialFamily`]: its
//! equations, through the model's [`InputOdeSensitivity`]; its search box; the parameters that
//! enter the output linearly for fixed shape; a start grid of shape parameters placed from a
//! cheap characterisation of the loop, [`LoopShape`]); the driver ([`fit`]) does the rest, the
//! same for all:
//!
//! 1. **Decimation.** The operators are rate independent: the state after a monotone stretch
//!    of input depends on its end points only. The record is thinned to every m-th sample *and
//!    every reversal of the input* ([`decimate`]), so the states at the kept samples are those of
//!    the full record (to the integration tolerance); the criterion on them is a subsample of
//!    V. About [`DECIMATED_SAMPLES`] samples remain: the global stages cost a fraction of one
//!    full simulation per trial.
//! 2. **Global start by variable projection** (Golub & Pereyra 1973, 2003). For fixed shape
//!    parameters the output is linear in the family's output parameters (Bouc–Wen's k_x, k_w;
//!    Duhem's a, b, c, y0 — its equation is linear in y and in the forcing; the scales F_c of
//!    Dahl and Mₛ of Jiles–Atherton, whose states scale with them). At every grid point the
//!    basis responses are simulated on the decimated record and the linear parameters solved
//!    by least squares: the grid explores only the few shape parameters, and every point is
//!    scored at its best linear completion.
//! 3. **Local searches on the decimated record** from the best grid points (in parallel;
//!    three times as many when the record is short enough to be kept whole): bounded
//!    Levenberg–Marquardt ([`crate::numerics::levenberg_marquardt`]) with exact
//!    sensitivities, at most 200 iterations each. **The race:** a search still above
//!    [`RACE_FACTOR`] times the best grid start's criterion, or above [`LINE_FACTOR`]² times
//!    a least-squares straight line's, after [`RACE_ITERATIONS`] iterations gives up (it is
//!    not heading for the minimum the fit keeps); a search whose criterion fell by less than
//!    [`STALL_DECREASE`] over its last [`STALL_WINDOW`] iterations has stalled in a valley
//!    and stops there (the refinement takes the best point on: on the real piezo record's
//!    60 % part Jiles–Atherton went from 622 to 385 iterations, one ferrite loop's Bouc–Wen
//!    from 2 106 to 594, every fit % the same to 10⁻³ points). **The line check:** when the best search
//!    (run to its end or given up so) leaves residuals [`LINE_FACTOR`] times the line's, the
//!    record is a loop the family cannot follow (its structure turns the other way,
//!    its saturation cannot take the record's shape): the fit stops there with that reason
//!    ([`Error::OutsideFamily`]) instead of grinding on the full record.
//! 4. **Refinement on the full record** of the best local minimum (and of the runner-up when
//!    its criterion is within [`RIVAL_MARGIN`] of the best but does not agree with it to
//!    [`AGREEMENT`], and its parameters differ: two minima too close to tell apart on the
//!    subsample). Local searches that agree are one minimum found from several starts. A
//!    refinement (of the full record or of a long record's subsample) whose criterion fell
//!    by less than [`REFINE_STALL_DECREASE`] over its last [`STALL_WINDOW`] iterations
//!    stops there without a restart (a valley it would crawl along for hundreds of
//!    iterations; reported as a flat region when the Gauss–Newton model still promises a
//!    decrease). The sensitivities ∂ŷ/∂θ are integrated
//!    in u beside the state ([`simulate_with_sensitivities`]): exact derivatives of the
//!    computed output at the cost of about one simulation, where forward differences need p
//!    further simulations and lose half the digits. The normal equations JᵀJ, Jᵀr are summed
//!    sample by sample, nothing of the record's length is stored. **Long records** (more
//!    than [`MEDIUM_SAMPLES`]) are refined first on their subsample of about
//!    [`MEDIUM_SAMPLES`] (as in stage 1, every reversal kept, at the operator's own
//!    tolerance): the subsample's criterion is a uniform subsample of V, whose minimum is
//!    the full record's up to the noise of the dropped samples, so the refinement converges
//!    there at a fraction of the cost (the real piezo record of 50 001 samples: the
//!    Jiles–Atherton fit took 15 s in 430 iterations on the full record, now 1.7 s for the
//!    same fit %), and the full record then takes at most [`POLISH_ITERATIONS`] iterations to
//!    settle its digits.
//! 5. **Checked convergence.** A Levenberg–Marquardt run may stop when its *damped* steps gain
//!    less than the tolerance, which after many rejected trials (steps into a region where the
//!    model is not defined) says little about the point. At the end the driver asks the
//!    undamped Gauss–Newton model what a step from there still promises (with the active
//!    bounds held, [`expected_improvement`]). A relative decrease above
//!    [`RESTART_THRESHOLD`] restarts the engine from that point, with fresh damping, at most
//!    [`MAX_RESTARTS`] times; a point that still promises more than [`FLAT_THRESHOLD`] is
//!    reported as [`Termination::FlatRegion`], never as converged.
//! 6. **Report** ([`OperatorFit`]): standard deviations σ²(JᵀJ)⁻¹ of the model's own
//!    parameters at the optimum (Ljung 1999, §9.3), the simulated output, fit %, the
//!    iterations and evaluations of every stage together.
//!
//! **Units.** A family whose parameters carry the record's units only through u and y
//! ([`DifferentialFamily::in_record_units`]: Bouc–Wen, Duhem, Dahl) is fitted on the record in units of
//! unit size, u′ = u/sᵤ and y′ = y/s_y with sᵤ, s_y the powers of two nearest the largest
//! |u| and |y| (an exact shift of the binary exponent), and its parameters, their covariance
//! (J C Jᵀ with J = ∂θ/∂θ′), the output and the declared history's turn return in the
//! record's units: the search's tolerances, its damping and its flat-region test then see
//! the same numbers whether a record is in V and µm or in kV and m.
//!
//! A family's search may run in coordinates φ other than the model's θ when that turns its
//! domain into a box (Bouc–Wen: β + γ > 0, β − γ ≥ 0); the map is linear,
//! [`DifferentialFamily::theta_of`] and [`DifferentialFamily::chain`].
//!
//! The observer of the options sees "grid", "start" and "iteration" progress; its
//! [`Control::Stop`] ends the fit with the best point so far and
//! [`Termination::Stopped`] (how a time limit is honoured).
//!
//! References: G. H. Golub, V. Pereyra, "The differentiation of pseudo-inverses and nonlinear
//! least squares problems whose variables separate", SIAM J. Numer. Anal. 10 (1973) 413–432;
//! "Separable nonlinear least squares: the variable projection method and its applications",
//! Inverse Problems 19 (2003) R1–R26. H. G. Bock, "Numerical treatment of inverse problems in
//! chemical reaction kinetics", Springer 1981 (internal numerical differentiation). L. Ljung,
//! *System Identification*, 2nd ed., Prentice Hall 1999.

use super::OperatorFit;
use crate::model::operators::differential::states_with_tolerance;
use crate::model::operators::differential::{
    check_signal, simulate_with_sensitivities, simulate_with_tolerance, InputOdeSensitivity,
    LoopOrientation, MAX_SENSITIVITIES, TOLERANCE,
};
use crate::model::operators::{HysteresisOperator, InitialState, InitialStateUsed};
use crate::numerics::levenberg_marquardt::{
    minimize, Control, LeastSquaresProblem, LmConfig, LmReport, NormalEquations,
};
use crate::numerics::metrics;
use crate::numerics::{Observer, Termination};
use crate::{Error, Result};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::sync::Mutex;
use std::time::Instant;

/// Samples the global stages keep (at least: every reversal of the input is kept too).
pub const DECIMATED_SAMPLES: usize = 800;
/// The integration tolerance of the global stages (the operator's own is
/// [`TOLERANCE`]): a fifth-order step grows as the tolerance's fifth root, so the
/// exploration takes several times fewer steps, and a start needs no more digits.
pub const COARSE_TOLERANCE: f64 = 1e-6;
/// A local minimum whose decimated criterion is within this fraction of the best one's (and
/// not within [`AGREEMENT`]) is refined on the full record too.
pub const RIVAL_MARGIN: f64 = 0.02;
/// Local searches whose decimated criteria agree to this fraction reached the same minimum
/// (their parameters may still differ along a direction the subsample hardly determines).
pub const AGREEMENT: f64 = 1e-6;
/// The relative decrease the Gauss–Newton model may still promise at the end of a run
/// without a restart.
pub const RESTART_THRESHOLD: f64 = 1e-9;
/// Above this relative promise, a point the engine stopped at is a flat region, not a minimum.
pub const FLAT_THRESHOLD: f64 = 1e-6;
/// A record longer than this is refined first on its subsample of about as many samples
/// (every reversal kept, so the states there are the full record's), then polished on the
/// whole record in at most [`POLISH_ITERATIONS`] iterations (module doc, stage 4).
pub const MEDIUM_SAMPLES: usize = 3000;
/// The iterations of the full-record polish after the subsample's refinement. A polish that
/// uses them all ends as converged when the Gauss–Newton model promises at most
/// [`FLAT_THRESHOLD`] of relative decrease there (the fit % cannot move in its sixth digit),
/// as a flat region otherwise. (On the piezo record the Bouc–Wen fit's polish to its
/// tolerance took 181 iterations and 1.0 s, for the same fit % to the third decimal as after
/// 12; the Jiles–Atherton fit's the same fit % after 12 as after 200.)
pub const POLISH_ITERATIONS: usize = 12;
/// A family whose best local search on the decimated record (run to its end, or given up by
/// the race) leaves residuals this many times the root-mean-square of a least-squares
/// straight line's cannot follow the loop
/// (its structure turns the other way, or its saturation cannot take the record's shape): the
/// fit stops there with that reason instead of refining on the full record. (Dahl turned
/// counter-clockwise on the piezo record ends at 0.6 %, a residual 6.5 times the line's,
/// after 230 s; every family that follows a record stays below the line's residual.)
pub const LINE_FACTOR: f64 = 2.0;
/// Iterations a local search on the decimated record takes before the race judges it.
pub const RACE_ITERATIONS: usize = 10;
/// A local search whose criterion after [`RACE_ITERATIONS`] iterations is still above this
/// multiple of the best grid start's (or above [`LINE_FACTOR`]² times a straight line's)
/// gives up: it is not heading for the minimum the fit keeps.
pub const RACE_FACTOR: f64 = 4.0;
/// A local search whose criterion fell by less than [`STALL_DECREASE`] (relative) over its
/// last `STALL_WINDOW` iterations has stalled in a valley: it stops there (the refinement
/// on the full record takes the best such point on).
pub const STALL_WINDOW: usize = 30;
/// See [`STALL_WINDOW`].
pub const STALL_DECREASE: f64 = 1e-3;
/// A refinement (on the full record, or on a long record's subsample) whose criterion fell
/// by less than this (relative) over its last [`STALL_WINDOW`] iterations has stalled in a
/// valley: it stops there, with no restart, reported as a flat region when the Gauss–Newton model still promises more
/// than [`FLAT_THRESHOLD`]. The fit % cannot move in its fifth digit over such a window;
/// the valley would take hundreds of iterations (magnet-like records of 170 set points:
/// Jiles–Atherton's refinements ran their 200 iterations at 2·10⁻⁸ per iteration; the fits
/// took 8.4 and 5.4 s, now 3.9 and 2.1 s, for fit % lower by 0.026 and 0 points).
pub const REFINE_STALL_DECREASE: f64 = 1e-6;
/// Shape points of the grid scored from the descending and ascending states too when the
/// initial state is estimated: the best ones from the family's own start.
pub const HISTORY_POINTS: usize = 12;
/// Restarts of the engine at a point that still promises a decrease.
pub const MAX_RESTARTS: usize = 3;

/// A cheap characterisation of a measured loop, for placing a family's start grid.
#[derive(Clone, Debug, PartialEq)]
pub struct LoopShape {
    /// (min, max) of the input.
    pub u_range: (f64, f64),
    /// (min, max) of the output.
    pub y_range: (f64, f64),
    /// The least-squares line y ≈ slope·u + intercept through the loop.
    pub slope: f64,
    /// See `slope`.
    pub intercept: f64,
    /// The loop's width: the root-mean-square distance of y from that line.
    pub width: f64,
    /// The orientation (sign of the enclosed area).
    pub orientation: LoopOrientation,
    /// The first sample (u\[0\], y\[0\]).
    pub first: (f64, f64),
}

impl LoopShape {
    /// The characterisation of the loop (u, y).
    pub fn of(u: &[f64], y: &[f64]) -> Self {
        let (mu, my) = (metrics::mean(u), metrics::mean(y));
        let (mut suu, mut suy) = (0.0, 0.0);
        for (a, b) in u.iter().zip(y) {
            suu += (a - mu) * (a - mu);
            suy += (a - mu) * (b - my);
        }
        let slope = if suu > 0.0 { suy / suu } else { 0.0 };
        let intercept = my - slope * mu;
        let width = (u
            .iter()
            .zip(y)
            .map(|(a, b)| (b - slope * a - intercept).powi(2))
            .sum::<f64>()
            / u.len().max(1) as f64)
            .sqrt();
        Self {
            u_range: range(u),
            y_range: range(y),
            slope,
            intercept,
            width,
            orientation: LoopOrientation::of_loop(u, y),
            first: (u[0], y[0]),
        }
    }

    /// Half the input's range (at least the smallest positive number).
    pub fn half_span(&self) -> f64 {
        (0.5 * (self.u_range.1 - self.u_range.0)).max(f64::MIN_POSITIVE)
    }
}

/// The responses whose linear combination is the output at one shape point:
/// ŷ = fixed + Σ_j c_j·columns_j.
#[derive(Clone, Debug, Default)]
pub struct Basis {
    /// The part that no linear parameter multiplies (e.g. μ₀·H of a B(H) loop).
    pub fixed: Option<Vec<f64>>,
    /// The responses multiplied by the linear parameters.
    pub columns: Vec<Vec<f64>>,
}

/// What a differential family supplies to the driver (module doc).
///
/// θ is the model's parameter vector in the order of its `parameters()`; φ the search
/// coordinates (θ itself unless the family maps them, linearly, to make its domain a box).
pub trait DifferentialFamily: Sync {
    /// The operator.
    type Model: HysteresisOperator + InputOdeSensitivity + Clone;
    /// The family's name in messages (`bouc-wen`).
    fn name(&self) -> &'static str;
    /// The index in θ of the state at the first sample x₀ (`w0`, `y0`, `f0`, `m0`).
    fn initial_state_index(&self) -> usize;
    /// The operator of θ, or an error where θ leaves the family's domain.
    fn model(&self, theta: &[f64]) -> Result<Self::Model>;
    /// The indices of the estimated parameters (the same in θ and φ).
    fn free(&self) -> Vec<usize>;
    /// The search box (lower, upper) of φ, placed from the loop's characterisation.
    fn bounds(&self, shape: &LoopShape) -> (Vec<f64>, Vec<f64>);
    /// θ of the search coordinates φ (default: φ itself).
    fn theta_of(&self, phi: &[f64]) -> Vec<f64> {
        phi.to_vec()
    }
    /// φ of θ, the inverse of [`theta_of`](Self::theta_of) (default: θ itself).
    fn phi_of(&self, theta: &[f64]) -> Vec<f64> {
        theta.to_vec()
    }
    /// The chain rule of the map: ∂ŷ/∂φ_j = Σ_i ∂ŷ/∂θ_i·∂θ_i/∂φ_j, from `dtheta` into `dphi`
    /// (default: a copy).
    fn chain(&self, dtheta: &[f64], dphi: &mut [f64]) {
        dphi.copy_from_slice(dtheta);
    }
    /// The start grid: shape points (the nonlinear parameters, in the family's own terms),
    /// placed from the loop's characterisation and the (decimated) record.
    fn shape_grid(&self, u: &[f64], y: &[f64], shape: &LoopShape) -> Vec<Vec<f64>>;
    /// The basis responses of one shape point on the input `u`, integrated to the relative
    /// tolerance `tolerance`.
    fn basis(&self, point: &[f64], u: &[f64], tolerance: f64) -> Result<Basis>;
    /// θ of a shape point and the least-squares coefficients of its basis; None when the
    /// coefficients leave the family's domain (a loop of the wrong orientation).
    fn assemble(&self, point: &[f64], coefficients: &[f64]) -> Option<Vec<f64>>;
    /// Why no point of the start grid fits the record (u, y), when none does: what the
    /// record shows that the family's loops cannot, and what to do (default: every start
    /// diverged or turned the wrong way).
    fn unfit_reason(&self, u: &[f64], y: &[f64]) -> String {
        let _ = (u, y);
        NO_START.into()
    }
    /// Whether the family's parameters carry units only through u and y, so that it is
    /// fitted on the record in units of unit size and mapped back by
    /// [`in_record_units`](Self::in_record_units) (module doc, "Units"). False (the
    /// default): fitted in the record's own units (its parameters are physical, as
    /// Jiles–Atherton's μ₀ ties B in T to H in A/m; or its search is unit-free already).
    const UNIT_FREE: bool = false;
    /// θ in the record's units of θ′ fitted on the record in units of unit size (u′ = u/`su`,
    /// y′ = y/`sy`), with its Jacobian ∂θ/∂θ′; None where the family has no such map (the
    /// default, with [`UNIT_FREE`](Self::UNIT_FREE) false).
    fn in_record_units(&self, theta: &[f64], su: f64, sy: f64) -> Option<(Vec<f64>, DMatrix<f64>)> {
        let _ = (theta, su, sy);
        None
    }
}

/// The default [`DifferentialFamily::unfit_reason`].
pub(crate) const NO_START: &str = "every start of its grid diverged or completes to a loop of \
     the wrong orientation; check the loop's orientation (--orientation, Python \
     orientation=) and that the record holds whole loops";

/// The driver's settings (each family's options carry them).
#[derive(Clone, Debug)]
pub struct Settings {
    /// Local searches on the decimated record, from the best grid points.
    pub starts: usize,
    /// Levenberg–Marquardt settings of the full-record refinement.
    pub config: LmConfig,
    /// Sees the "grid", "start" and "iteration" progress; may stop the fit.
    pub observer: Observer,
    /// The initial state: declared (x₀ held: 0, or the state after the declared history run
    /// before the record) or estimated (the demagnetised, descending and ascending starts
    /// scored in the grid, x₀ then free).
    pub initial_state: InitialState,
}

/// The default engine settings of these fits: 200 iterations, a relative improvement
/// tolerance of 1e-10 (the criterion's last digits move the fit % by less than 1e-8 points).
pub fn default_config() -> LmConfig {
    LmConfig {
        max_iterations: 200,
        improvement_tolerance: 1e-10,
        ..LmConfig::default()
    }
}

/// The engine settings of the local searches on the decimated record: they only need to find
/// the basin, the full record settles the digits.
fn local_config(config: &LmConfig) -> LmConfig {
    LmConfig {
        max_iterations: config.max_iterations.min(200),
        improvement_tolerance: config.improvement_tolerance.max(1e-8),
        initial_damping: config.initial_damping * SMALL_DAMPING,
        ..config.clone()
    }
}

/// The factor on the initial damping of the driver's runs. Every run starts at a point that
/// the grid's linear completion or a local search has placed in its basin, where the
/// Gauss–Newton step is the right one; strongly correlated parameters (Jiles–Atherton's Mₛ,
/// a, α) would otherwise take two iterations per decade of damping before the steps become
/// long enough. A step that fails raises the damping again (doubling).
const SMALL_DAMPING: f64 = 1e-5;

/// The engine settings of the full-record refinement: the caller's, with the small damping.
fn refine_config(config: &LmConfig) -> LmConfig {
    LmConfig {
        initial_damping: config.initial_damping * SMALL_DAMPING,
        ..config.clone()
    }
}

/// Checks a record for a fit with `p` parameters: equal lengths, finite samples, at least
/// max(20, 5p) samples, one reversal of the input (an ascending and a descending branch: a
/// measured loop from its tip has exactly one), a non-constant output.
pub fn check_record(family: &str, u: &[f64], y: &[f64], p: usize) -> Result<()> {
    if u.len() != y.len() {
        return Err(Error::InvalidData(format!(
            "{family}: input has {} samples, output {}; give equally long signals",
            u.len(),
            y.len()
        )));
    }
    check_signal("input", u)?;
    check_signal("output", y)?;
    let needed = (5 * p).max(20);
    if u.len() < needed {
        return Err(Error::TooFewSamples {
            samples: u.len(),
            parameters: p,
            needed,
        });
    }
    super::check_reversal(u)?;
    if !crate::data::varies(y) {
        return Err(Error::InvalidData(format!(
            "{family}: the output is constant; there is no loop to fit"
        )));
    }
    Ok(())
}

/// The samples the global stages keep: the first and last, every m-th with
/// m = ⌈N/`target`⌉, and every reversal of the input (the last sample before the direction
/// changes), so that the input between two kept samples is monotone and a rate-independent
/// operator reaches the same state at each kept sample as on the full record. When the
/// reversals alone are more than four times `target` (a noisy input), only every m-th sample
/// is kept and the subsample is approximate.
pub fn decimate(u: &[f64], target: usize) -> Vec<usize> {
    let n = u.len();
    if n <= target.max(2) {
        return (0..n).collect();
    }
    let m = n.div_ceil(target.max(1));
    let mut turning = Vec::new();
    let mut last = 0.0;
    for k in 1..n {
        let d = u[k] - u[k - 1];
        if d == 0.0 {
            continue;
        }
        if last != 0.0 && d.signum() != last {
            turning.push(k - 1);
        }
        last = d.signum();
    }
    let mut keep: Vec<usize> = (0..n).step_by(m).collect();
    keep.push(n - 1);
    if turning.len() <= 4 * target {
        keep.extend(turning);
    }
    keep.sort_unstable();
    keep.dedup();
    keep
}

/// The output-error problem of a family on one record, in the search coordinates φ, with the
/// normal equations from the integrated sensitivities.
///
/// It remembers the last normal equations it computed (the engine's final point is the last
/// one it accepted) and the output of the lowest criterion it evaluated (the final point of a
/// monotone engine), so the driver's check and report cost no further pass over the record.
struct OutputError<'a, F: DifferentialFamily> {
    family: &'a F,
    u: &'a [f64],
    y: &'a [f64],
    n_phi: usize,
    /// Leading samples (a declared history) simulated but not scored.
    skip: usize,
    floor: f64,
    tolerance: f64,
    last_system: Mutex<Option<LastSystem>>,
    best_output: Option<Mutex<BestOutput>>,
}

/// The last normal equations computed: (φ, free, system).
type LastSystem = (Vec<f64>, Vec<usize>, System);
/// The output of the lowest criterion evaluated: (φ, S, ŷ).
type BestOutput = (Vec<f64>, f64, Vec<f64>);

/// The normal equations in φ (for the engine) and JᵀJ in the model's θ (for the covariance).
#[derive(Clone)]
struct System {
    phi: NormalEquations,
    theta_jtj: DMatrix<f64>,
}

impl<'a, F: DifferentialFamily> OutputError<'a, F> {
    /// The problem on (u, y) at the integration tolerance `tolerance`; `keep_output`
    /// remembers the best output (for the report).
    fn new(
        family: &'a F,
        (u, y): (&'a [f64], &'a [f64]),
        n_phi: usize,
        tolerance: f64,
        keep_output: bool,
        skip: usize,
    ) -> Self {
        // The integration is accurate to ~1e-10 of the signal's scale: residuals below 1e-9
        // of the output's spread are an exact fit.
        let s = 1e-9 * metrics::std_dev(&y[skip.min(y.len())..]);
        Self {
            family,
            u,
            y,
            n_phi,
            skip,
            floor: y.len() as f64 * s * s,
            tolerance,
            last_system: Mutex::new(None),
            best_output: keep_output.then(|| Mutex::new((Vec::new(), f64::INFINITY, Vec::new()))),
        }
    }

    fn model(&self, phi: &[f64]) -> Result<F::Model> {
        self.family.model(&self.family.theta_of(phi))
    }

    /// The simulated output at φ and its sum of squared residuals.
    fn output(&self, phi: &[f64]) -> Result<(Vec<f64>, f64)> {
        if let Some(best) = &self.best_output {
            let best = best.lock().expect("not poisoned");
            if best.0 == phi {
                return Ok((best.2.clone(), best.1));
            }
        }
        let yhat = simulate_with_tolerance(&self.model(phi)?, self.u, self.tolerance)?;
        let cost: f64 = self
            .y
            .iter()
            .zip(&yhat)
            .skip(self.skip)
            .map(|(y, h)| (y - h) * (y - h))
            .sum();
        if !cost.is_finite() {
            return Err(Error::Diverged {
                index: 0,
                reason: "a residual is not finite".into(),
            });
        }
        if let Some(best) = &self.best_output {
            let mut best = best.lock().expect("not poisoned");
            if cost < best.1 {
                *best = (phi.to_vec(), cost, yhat.clone());
            }
        }
        Ok((yhat, cost))
    }

    /// JᵀJ, Jᵀr and S at φ for the free coordinates `free`, with JᵀJ in θ too.
    fn system(&self, phi: &[f64], free: &[usize]) -> Result<System> {
        if let Some((p, f, system)) = &*self.last_system.lock().expect("not poisoned") {
            if p == phi && f == free {
                return Ok(system.clone());
            }
        }
        let model = self.model(phi)?;
        let p = free.len();
        let n_theta = model.n_parameters();
        let mut jtj = DMatrix::<f64>::zeros(p, p);
        let mut theta_jtj = DMatrix::<f64>::zeros(p, p);
        let mut jtr = DVector::<f64>::zeros(p);
        let mut cost = 0.0;
        let mut dphi = [0.0; MAX_SENSITIVITIES];
        let (mut row, mut row_theta) = ([0.0; MAX_SENSITIVITIES], [0.0; MAX_SENSITIVITIES]);
        let mut finite = true;
        simulate_with_sensitivities(&model, self.u, self.tolerance, |k, yhat, dtheta| {
            if k < self.skip {
                return;
            }
            let r = self.y[k] - yhat;
            self.family.chain(dtheta, &mut dphi[..n_theta]);
            for (a, &i) in free.iter().enumerate() {
                row[a] = -dphi[i];
                row_theta[a] = -dtheta[i];
            }
            for a in 0..p {
                jtr[a] += row[a] * r;
                for b in 0..=a {
                    jtj[(a, b)] += row[a] * row[b];
                    theta_jtj[(a, b)] += row_theta[a] * row_theta[b];
                }
            }
            cost += r * r;
            finite &= r.is_finite() && row[..p].iter().all(|v| v.is_finite());
        })?;
        if !finite || !cost.is_finite() {
            return Err(Error::Diverged {
                index: 0,
                reason: "non-finite output or sensitivity".into(),
            });
        }
        for a in 0..p {
            for b in 0..a {
                jtj[(b, a)] = jtj[(a, b)];
                theta_jtj[(b, a)] = theta_jtj[(a, b)];
            }
        }
        let system = System {
            phi: NormalEquations { jtj, jtr, cost },
            theta_jtj,
        };
        *self.last_system.lock().expect("not poisoned") =
            Some((phi.to_vec(), free.to_vec(), system.clone()));
        Ok(system)
    }
}

impl<F: DifferentialFamily> LeastSquaresProblem for OutputError<'_, F> {
    fn n_params(&self) -> usize {
        self.n_phi
    }
    fn n_residuals(&self) -> usize {
        self.y.len()
    }
    fn residuals(&self, phi: &[f64], r: &mut [f64]) -> Result<()> {
        let (yhat, _) = self.output(phi)?;
        for (k, ((r, y), yh)) in r.iter_mut().zip(self.y).zip(&yhat).enumerate() {
            *r = if k < self.skip { 0.0 } else { y - yh };
        }
        Ok(())
    }
    fn trial_cost(&self, phi: &[f64], _r: &mut Vec<f64>) -> Result<f64> {
        Ok(self.output(phi)?.1)
    }
    fn normal_equations(&self, phi: &[f64], free: &[usize]) -> Option<Result<NormalEquations>> {
        Some(self.system(phi, free).map(|s| s.phi))
    }
    fn cost_floor(&self) -> f64 {
        self.floor
    }
}

/// The relative decrease of S that the undamped Gauss–Newton step from the point of `system`
/// promises, with the parameters held that sit on a bound the gradient pushes them through:
/// gᵀH⁻¹g/S over the others (0 when nothing can move).
pub fn expected_improvement(
    system: &NormalEquations,
    phi: &[f64],
    free: &[usize],
    lower: &[f64],
    upper: &[f64],
) -> f64 {
    let g = &system.jtr;
    let idx: Vec<usize> = (0..free.len())
        .filter(|&k| {
            let i = free[k];
            !((phi[i] <= lower[i] && g[k] > 0.0) || (phi[i] >= upper[i] && g[k] < 0.0))
        })
        .collect();
    if idx.is_empty() || system.cost <= 0.0 {
        return 0.0;
    }
    let m = idx.len();
    let scale: Vec<f64> = idx
        .iter()
        .map(|&k| system.jtj[(k, k)].max(f64::MIN_POSITIVE).sqrt())
        .collect();
    let h = DMatrix::from_fn(m, m, |r, c| {
        system.jtj[(idx[r], idx[c])] / (scale[r] * scale[c]) + if r == c { 1e-12 } else { 0.0 }
    });
    let gs = DVector::from_fn(m, |r, _| g[idx[r]] / scale[r]);
    match h.cholesky() {
        Some(ch) => gs.dot(&ch.solve(&gs)) / system.cost,
        None => f64::INFINITY,
    }
}

/// One Levenberg–Marquardt run of the driver: its report and whether the observer stopped it.
struct Run {
    report: LmReport,
    stopped: bool,
    /// The search stopped because its criterion stalled (a local search: [`STALL_DECREASE`];
    /// a refinement: [`REFINE_STALL_DECREASE`]).
    stalled: bool,
}

/// The driver's bookkeeping: the search box and the work counted over every stage.
struct Driver<'a, F: DifferentialFamily> {
    family: &'a F,
    settings: &'a Settings,
    free: Vec<usize>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    /// x₀ estimated (free, its start chosen in the grid).
    estimate: bool,
}

impl<F: DifferentialFamily> Driver<'_, F> {
    fn clamp(&self, phi: &[f64]) -> Vec<f64> {
        phi.iter()
            .zip(self.lower.iter().zip(&self.upper))
            .map(|(v, (lo, hi))| v.clamp(*lo, *hi))
            .collect()
    }

    fn run(&self, problem: &OutputError<'_, F>, phi: &[f64], config: &LmConfig) -> Result<Run> {
        self.search(problem, phi, config, None)
    }

    /// [`Driver::run`] that gives up after [`RACE_ITERATIONS`] iterations when its criterion
    /// is still above `ceiling`, or when it stalls ([`STALL_WINDOW`]): the race of the local
    /// searches (module doc stage 3).
    fn run_raced(
        &self,
        problem: &OutputError<'_, F>,
        phi: &[f64],
        config: &LmConfig,
        ceiling: f64,
    ) -> Result<Run> {
        self.search(problem, phi, config, Some(ceiling))
    }

    /// One Levenberg–Marquardt search from `phi`, raced against `ceiling` and stopped when
    /// it stalls by [`STALL_DECREASE`] where one is given (the local searches), else run to
    /// its own termination or a stall by [`REFINE_STALL_DECREASE`] (the refinements); the
    /// observer's stop alone sets [`Run::stopped`].
    fn search(
        &self,
        problem: &OutputError<'_, F>,
        phi: &[f64],
        config: &LmConfig,
        race: Option<f64>,
    ) -> Result<Run> {
        let (mut stopped, mut stalled) = (false, false);
        let observer = &self.settings.observer;
        let mut costs: Vec<f64> = Vec::new();
        let decrease = if race.is_some() {
            STALL_DECREASE
        } else {
            REFINE_STALL_DECREASE
        };
        let report = minimize(
            problem,
            &self.clamp(phi),
            &self.free,
            &self.lower,
            &self.upper,
            config,
            &mut |r| {
                let c = observer.report("iteration", r.iteration, config.max_iterations);
                stopped |= c == Control::Stop;
                if race.is_some_and(|ceiling| r.iteration >= RACE_ITERATIONS && r.cost > ceiling) {
                    return Control::Stop;
                }
                costs.push(r.cost);
                stalled = costs.len() > STALL_WINDOW
                    && r.cost > costs[costs.len() - 1 - STALL_WINDOW] * (1.0 - decrease);
                if stalled {
                    return Control::Stop;
                }
                c
            },
        )?;
        Ok(Run {
            report,
            stopped,
            stalled,
        })
    }

    /// The best linear completion of every grid point on the decimated record from each of
    /// the `starts`, best first, with the start of each.
    fn grid(
        &self,
        u: &[f64],
        y: &[f64],
        points: &[Vec<f64>],
        starts: &[Start],
    ) -> Vec<(f64, Vec<f64>, Start, usize)> {
        let x0 = self.family.initial_state_index();
        let (lo, hi) = range(u);
        let span = (hi - lo).max(f64::MIN_POSITIVE);
        let work: Vec<(usize, Start)> = (0..points.len())
            .flat_map(|i| starts.iter().map(move |s| (i, *s)))
            .collect();
        let mut scored: Vec<(f64, Vec<f64>, Start, usize)> = work
            .par_iter()
            .filter_map(|&(index, start)| {
                let point = &points[index];
                // A history's basis: the record after a turn 2 spans beyond it.
                let turn = match start {
                    Start::History(InitialStateUsed::Descending) => Some(hi + 2.0 * span),
                    Start::History(InitialStateUsed::Ascending) => Some(lo - 2.0 * span),
                    _ => None,
                };
                let path: Vec<f64> = match turn {
                    Some(t) => [u[0], t].iter().chain(u).copied().collect(),
                    None => u.to_vec(),
                };
                let skip = path.len() - u.len();
                let mut basis = self.family.basis(point, &path, COARSE_TOLERANCE).ok()?;
                basis.columns.iter_mut().for_each(|c| {
                    c.drain(..skip);
                });
                if let Some(f) = basis.fixed.as_mut() {
                    f.drain(..skip);
                }
                let target: Vec<f64> = match &basis.fixed {
                    Some(f) => y.iter().zip(f).map(|(y, f)| y - f).collect(),
                    None => y.to_vec(),
                };
                let cols: Vec<&[f64]> = basis.columns.iter().map(Vec::as_slice).collect();
                let (c, sse) = linear_fit(&cols, &target)?;
                let mut theta = self.family.assemble(point, &c)?;
                match start {
                    Start::Zero => theta[x0] = 0.0,
                    Start::History(state) if self.estimate => {
                        // x₀ is the state this model reaches after the history.
                        let model = self.family.model(&theta).ok()?;
                        let turn = state.turning_input(&model, u)?;
                        theta[x0] = *states_with_tolerance(&model, &[u[0], turn, u[0]], TOLERANCE)
                            .ok()?
                            .last()?;
                    }
                    _ => {}
                }
                self.family.model(&theta).ok()?;
                sse.is_finite()
                    .then(|| (sse, self.family.phi_of(&theta), start, index))
            })
            .collect();
        self.settings
            .observer
            .report("grid", work.len(), work.len());
        scored.sort_by(|a, b| a.0.total_cmp(&b.0));
        scored
    }
}

/// Where a grid point's state starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Start {
    /// The family's own grid start (its x₀ as the family places it).
    Own,
    /// x₀ = 0 (declared demagnetised).
    Zero,
    /// After a declared history.
    History(InitialStateUsed),
}

/// Fits `family` to input `u` and output `y` (module doc), in units of unit size where the
/// family maps its parameters back ([`DifferentialFamily::in_record_units`]).
pub fn fit<F: DifferentialFamily>(
    family: &F,
    u: &[f64],
    y: &[f64],
    settings: &Settings,
) -> Result<OperatorFit<F::Model>> {
    let (su, sy) = (unit_scale(u), unit_scale(y));
    if !F::UNIT_FREE || (su, sy) == (1.0, 1.0) {
        return fit_as_given(family, u, y, settings);
    }
    let scaled = |v: &[f64], s: f64| v.iter().map(|x| x / s).collect::<Vec<f64>>();
    let fit = fit_as_given(family, &scaled(u, su), &scaled(y, sy), settings)
        .map_err(|e| error_in_record_units(e, su))?;
    in_record_units(family, fit, su, sy)
}

/// An error of a fit run in units of unit size (inputs u′ = u/`su`) as the record's units
/// state it: a divergence's input position, the integrator's "at u = u′", becomes u′·sᵤ
/// (exact: sᵤ is a power of two); every other error is unit-free or quotes percentages.
pub fn error_in_record_units(e: Error, su: f64) -> Error {
    const AT: &str = "at u = ";
    match e {
        Error::Diverged { index, reason } => {
            let reason = match reason.find(AT) {
                Some(start) => {
                    let rest = &reason[start + AT.len()..];
                    let end = rest.find(':').unwrap_or(rest.len());
                    match rest[..end].parse::<f64>() {
                        Ok(u) => format!("{}{AT}{}{}", &reason[..start], u * su, &rest[end..]),
                        Err(_) => reason,
                    }
                }
                None => reason,
            };
            Error::Diverged { index, reason }
        }
        e => e,
    }
}

/// The fit `fit` on the record in units of unit size (u/`su`, y/`sy`) in the record's units
/// (module doc, "Units").
fn in_record_units<F: DifferentialFamily>(
    family: &F,
    fit: OperatorFit<F::Model>,
    su: f64,
    sy: f64,
) -> Result<OperatorFit<F::Model>> {
    let scaled = fit.model.parameters().values();
    let (theta, jacobian) = family
        .in_record_units(&scaled, su, sy)
        .ok_or_else(|| Error::Unsupported(format!("{}: no unit map", family.name())))?;
    let model = family.model(&theta)?;
    let p = theta.len();
    let c = DMatrix::from_fn(p, p, |i, j| fit.covariance[i][j]);
    let covariance = &jacobian * c * jacobian.transpose();
    let std: Vec<Option<f64>> = (0..p)
        .map(|i| fit.std[i].map(|_| covariance[(i, i)].max(0.0).sqrt()))
        .collect();
    let simulated: Vec<f64> = fit.simulated.iter().map(|v| v * sy).collect();
    let loss = fit.loss * sy * sy;
    let n = simulated.len() as f64;
    Ok(OperatorFit {
        parameters: model.parameters(),
        model,
        covariance: masked_covariance(&covariance, &std),
        std,
        simulated,
        rmse: loss.sqrt(),
        loss,
        // both scale with the loss: FPE by s_y², AIC = N ln V + … by N ln s_y²
        fpe: fit.fpe * sy * sy,
        aic: fit.aic + n * (sy * sy).ln(),
        history_turn: fit.history_turn.map(|t| t * su),
        ..fit
    })
}

/// θᵢ = θ′ᵢ·fᵢ and its (diagonal) Jacobian: the [`DifferentialFamily::in_record_units`] of a
/// family whose every parameter scales by a power of the units.
pub(crate) fn scaled_by(theta: &[f64], factors: &[f64]) -> (Vec<f64>, DMatrix<f64>) {
    let values = theta.iter().zip(factors).map(|(t, f)| t * f).collect();
    let jacobian = DMatrix::from_diagonal(&DVector::from_column_slice(factors));
    (values, jacobian)
}

/// The power of two nearest the largest |v| (1 for a record of zeros): a scale that brings
/// v to unit size exactly (a binary exponent shift, no rounding).
pub(crate) fn unit_scale(v: &[f64]) -> f64 {
    let largest = v
        .iter()
        .filter(|x| x.is_finite())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    if largest > 0.0 && largest.is_finite() {
        2f64.powi(largest.log2().round() as i32)
    } else {
        1.0
    }
}

/// [`fit`] in the record's own units.
fn fit_as_given<F: DifferentialFamily>(
    family: &F,
    u: &[f64],
    y: &[f64],
    settings: &Settings,
) -> Result<OperatorFit<F::Model>> {
    let started = Instant::now();
    let declared = settings.initial_state.declared();
    let x0 = family.initial_state_index();
    let mut free = family.free();
    if declared.is_some() {
        free.retain(|&i| i != x0);
    }
    check_record(family.name(), u, y, free.len())?;
    let shape = LoopShape::of(u, y);
    let (lower, upper) = family.bounds(&shape);
    let driver = Driver {
        family,
        settings,
        free,
        lower,
        upper,
        estimate: declared.is_none(),
    };
    let starts: Vec<Start> = match declared {
        None => vec![
            Start::Own,
            Start::History(InitialStateUsed::Descending),
            Start::History(InitialStateUsed::Ascending),
        ],
        Some(InitialStateUsed::Demagnetised) => vec![Start::Zero],
        Some(state) => vec![Start::History(state)],
    };
    let n_phi = driver.lower.len();
    let observer = &settings.observer;
    let (mut iterations, mut evaluations) = (0, 0);

    // 1–2: decimated record, grid with variable projection.
    let kept = decimate(u, DECIMATED_SAMPLES);
    let ud: Vec<f64> = kept.iter().map(|&k| u[k]).collect();
    let yd: Vec<f64> = kept.iter().map(|&k| y[k]).collect();
    let points = family.shape_grid(&ud, &yd, &shape);
    let grid = if declared.is_none() {
        // The family's own start everywhere, the two histories at the best shape points
        // only (the grid's cost grows by a fraction, not threefold).
        let mut grid = driver.grid(&ud, &yd, &points, &starts[..1]);
        let mut best: Vec<usize> = Vec::new();
        for g in &grid {
            if best.len() == HISTORY_POINTS {
                break;
            }
            if !best.contains(&g.3) {
                best.push(g.3);
            }
        }
        let subset: Vec<Vec<f64>> = best.iter().map(|&i| points[i].clone()).collect();
        grid.extend(driver.grid(&ud, &yd, &subset, &starts[1..]));
        grid.sort_by(|a, b| a.0.total_cmp(&b.0));
        grid
    } else {
        driver.grid(&ud, &yd, &points, &starts)
    };
    evaluations += grid.len();
    if grid.is_empty() {
        return Err(Error::OutsideFamily {
            family: family.name().into(),
            reason: family.unfit_reason(u, y),
        });
    }

    // A declared history: the records with it prepended, its samples not scored; the turn
    // placed for the best grid point's model (module doc of `initial_state`).
    let history = match declared {
        Some(state @ (InitialStateUsed::Descending | InitialStateUsed::Ascending)) => {
            let model = family.model(&family.theta_of(&grid[0].1))?;
            state.turning_input(&model, u).map(|t| (state, t))
        }
        _ => None,
    };
    let prefixed = |v: &[f64], first: f64| -> Vec<f64> {
        match history {
            Some((_, turn)) => [first, turn].iter().chain(v).copied().collect(),
            None => v.to_vec(),
        }
    };
    let (ud, yd) = (prefixed(&ud, ud[0]), prefixed(&yd, yd[0]));
    let (up, yp) = (prefixed(u, u[0]), prefixed(y, y[0]));
    let skip = up.len() - u.len();

    // 3: local searches on the decimated record, in parallel.
    let decimated = OutputError::new(family, (&ud, &yd), n_phi, COARSE_TOLERANCE, false, skip);
    let local = local_config(&settings.config);
    // A record short enough to be kept whole makes every local search cheap: three times
    // as many then (measured loops of a hundred samples have many shallow minima).
    let n_starts = settings.starts.max(1) * if kept.len() == u.len() { 3 } else { 1 };
    let starts: Vec<&Vec<f64>> = grid.iter().take(n_starts).map(|g| &g.1).collect();
    let mut minima: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut stopped = observer.should_stop("start");
    // The race: a search still above RACE_FACTOR times the best start's criterion, or above
    // the line's bound, after RACE_ITERATIONS iterations gives up (its minimum is not the one
    // the fit keeps).
    let line = line_criterion(&ud[skip..], &yd[skip..]);
    let ceiling = (RACE_FACTOR * grid[0].0).min(LINE_FACTOR * LINE_FACTOR * line);
    if !stopped {
        let runs: Vec<Result<Run>> = starts
            .par_iter()
            .map(|phi| driver.run_raced(&decimated, phi, &local, ceiling))
            .collect();
        for run in runs.into_iter().flatten() {
            iterations += run.report.iterations;
            evaluations += run.report.function_evaluations;
            stopped |= run.stopped;
            minima.push((run.report.cost, run.report.theta));
        }
        observer.report("start", starts.len(), starts.len());
    }
    if minima.is_empty() {
        minima.push((grid[0].0, grid[0].1.clone()));
    }
    minima.sort_by(|a, b| a.0.total_cmp(&b.0));
    if !stopped && minima[0].0 > LINE_FACTOR * LINE_FACTOR * line {
        let fit = |cost: f64| {
            100.0 * (1.0 - (cost / (yd.len() - skip) as f64).sqrt() / metrics::std_dev(&yd[skip..]))
        };
        return Err(Error::OutsideFamily {
            family: family.name().into(),
            reason: format!(
                "its best fit ({:.1} %) explains the record less than a straight line does \
                 ({:.1} %) on {} of its samples; the family cannot follow this loop (check \
                 the loop's orientation, --orientation, Python orientation=) — fit another \
                 family",
                fit(minima[0].0),
                fit(line),
                yd.len() - skip,
            ),
        });
    }

    // 4–5: the full record from the best minimum (and a close rival), checked; a long
    // record through its subsample first (stage 4, "long records").
    let full = OutputError::new(family, (&up, &yp), n_phi, TOLERANCE, true, skip);
    let medium = (u.len() > MEDIUM_SAMPLES).then(|| {
        let kept = decimate(u, MEDIUM_SAMPLES);
        let um: Vec<f64> = kept.iter().map(|&k| u[k]).collect();
        let ym: Vec<f64> = kept.iter().map(|&k| y[k]).collect();
        (prefixed(&um, um[0]), prefixed(&ym, ym[0]))
    });
    let medium = medium
        .as_ref()
        .map(|(um, ym)| OutputError::new(family, (um, ym), n_phi, TOLERANCE, true, skip));
    let mut candidates = vec![minima[0].1.clone()];
    if let Some(rival) = minima[1..].iter().find(|m| {
        m.0 > minima[0].0 * (1.0 + AGREEMENT)
            && m.0 <= minima[0].0 * (1.0 + RIVAL_MARGIN)
            && differs(&m.1, &minima[0].1, &driver.free)
    }) {
        candidates.push(rival.1.clone());
    }
    let mut best: Option<(LmReport, Termination)> = None;
    for phi in candidates {
        if stopped || observer.should_stop("start") {
            stopped = true;
            break;
        }
        let config = refine_config(&settings.config);
        let (phi, before) = match &medium {
            Some(medium) => match refine(&driver, medium, &phi, &config, false) {
                Ok((report, _, work, halted)) => {
                    stopped |= halted;
                    (report.theta, work)
                }
                Err(_) => (phi, (0, 0)),
            },
            None => (phi, (0, 0)),
        };
        iterations += before.0;
        evaluations += before.1;
        if stopped {
            break;
        }
        let polish = LmConfig {
            max_iterations: config.max_iterations.min(POLISH_ITERATIONS),
            extra_iterations: 0,
            ..config.clone()
        };
        let config = if medium.is_some() { polish } else { config };
        let Ok((report, termination, work, halted)) =
            refine(&driver, &full, &phi, &config, medium.is_some())
        else {
            continue;
        };
        iterations += work.0;
        evaluations += work.1;
        stopped |= halted;
        if best.as_ref().is_none_or(|b| report.cost < b.0.cost) {
            best = Some((report, termination));
        }
    }
    let (report, termination) = match best {
        Some((report, termination)) => (
            report,
            if stopped {
                Termination::Stopped
            } else {
                termination
            },
        ),
        None => {
            // Stopped before the full record was reached, or no refinement could be
            // simulated: the best decimated point, said so.
            let phi = driver.clamp(&minima[0].1);
            let system = full.system(&phi, &driver.free)?.phi;
            let termination = if stopped {
                Termination::Stopped
            } else {
                Termination::NoDescent
            };
            (lm_report(&phi, &driver.free, system, u.len()), termination)
        }
    };
    let mut fit = report_fit(
        &driver,
        &full,
        &report.theta,
        termination,
        (iterations, evaluations),
        started,
    )?;
    fit.initial_state = Some(declared.unwrap_or(InitialStateUsed::Estimated));
    fit.history_turn = history.map(|(_, turn)| turn);
    Ok(fit)
}

/// The sum of squared residuals of the least-squares straight line y ≈ a + b·u.
fn line_criterion(u: &[f64], y: &[f64]) -> f64 {
    let n = u.len() as f64;
    let (mu, my) = (u.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut suu, mut suy, mut syy) = (0.0, 0.0, 0.0);
    for (&u, &y) in u.iter().zip(y) {
        let (du, dy) = (u - mu, y - my);
        suu += du * du;
        suy += du * dy;
        syy += dy * dy;
    }
    if suu > 0.0 {
        (syy - suy * suy / suu).max(0.0)
    } else {
        syy
    }
}

/// True when two points differ by more than 0.1 % (relative) in a free coordinate.
fn differs(a: &[f64], b: &[f64], free: &[usize]) -> bool {
    free.iter()
        .any(|&i| (a[i] - b[i]).abs() > 1e-3 * a[i].abs().max(b[i].abs()).max(1e-300))
}

/// Levenberg–Marquardt on the full record (or a long record's subsample) from `phi`,
/// restarted where the Gauss–Newton model still promises a decrease (module doc, stage 5):
/// the report, the termination to publish, (iterations, evaluations), and whether the
/// observer stopped it. A `polish` that runs out of iterations ([`POLISH_ITERATIONS`]) and
/// a run that stalled ([`REFINE_STALL_DECREASE`]) are not restarted and are judged by that
/// promise: a flat region above [`FLAT_THRESHOLD`], else converged.
#[allow(clippy::type_complexity)]
fn refine<F: DifferentialFamily>(
    driver: &Driver<'_, F>,
    problem: &OutputError<'_, F>,
    phi: &[f64],
    config: &LmConfig,
    polish: bool,
) -> Result<(LmReport, Termination, (usize, usize), bool)> {
    let (mut iterations, mut evaluations) = (0, 0);
    let mut run = driver.run(problem, phi, config)?;
    let mut restarts = 0;
    loop {
        iterations += run.report.iterations;
        evaluations += run.report.function_evaluations;
        let r = &run.report;
        if run.stopped {
            let t = r.termination.clone();
            return Ok((run.report, t, (iterations, evaluations), true));
        }
        if matches!(
            r.termination,
            Termination::ZeroResidual | Termination::NothingToEstimate
        ) {
            let t = r.termination.clone();
            return Ok((run.report, t, (iterations, evaluations), false));
        }
        let system = problem.system(&r.theta, &driver.free)?.phi;
        let promise = expected_improvement(
            &system,
            &r.theta,
            &driver.free,
            &driver.lower,
            &driver.upper,
        );
        // A stalled refinement is out of iterations in effect: a restart would grind on.
        let out_of_iterations = r.termination == Termination::MaxIterations || run.stalled;
        if promise <= RESTART_THRESHOLD || restarts == MAX_RESTARTS || out_of_iterations {
            // A polish out of iterations, or a stall, is judged by the promise alone.
            let judged = polish || run.stalled;
            let termination = if promise > FLAT_THRESHOLD && (judged || !out_of_iterations) {
                Termination::FlatRegion { expected: promise }
            } else if judged && out_of_iterations {
                Termination::ImprovementBelowTolerance { relative: promise }
            } else {
                r.termination.clone()
            };
            return Ok((run.report, termination, (iterations, evaluations), false));
        }
        restarts += 1;
        let next = driver.run(problem, &r.theta.clone(), config)?;
        if next.report.cost > run.report.cost {
            // Cannot happen with a monotone engine; keep the better point regardless.
            iterations += next.report.iterations;
            evaluations += next.report.function_evaluations;
            let t = Termination::FlatRegion { expected: promise };
            return Ok((run.report, t, (iterations, evaluations), next.stopped));
        }
        run = next;
    }
}

/// An [`LmReport`] holding only a point, its normal equations and the record's length (for
/// the covariance).
fn lm_report(theta: &[f64], free: &[usize], system: NormalEquations, n: usize) -> LmReport {
    LmReport {
        theta: theta.to_vec(),
        free: free.to_vec(),
        cost: system.cost,
        initial_cost: system.cost,
        n_residuals: n,
        iterations: 0,
        function_evaluations: 0,
        residual_evaluations: 0,
        sensitivity_evaluations: 0,
        rejected_trials: 0,
        termination: Termination::NothingToEstimate,
        history: Vec::new(),
        jtj: system.jtj,
        elapsed_s: 0.0,
    }
}

/// The [`OperatorFit`] at the search point `phi`: the covariance from the normal equations in
/// the model's own parameters.
fn report_fit<F: DifferentialFamily>(
    driver: &Driver<'_, F>,
    problem: &OutputError<'_, F>,
    phi: &[f64],
    termination: Termination,
    (iterations, evaluations): (usize, usize),
    started: Instant,
) -> Result<OperatorFit<F::Model>> {
    let theta = driver.family.theta_of(phi);
    let model = driver.family.model(&theta)?;
    let y = &problem.y[problem.skip..];
    let system = problem.system(phi, &driver.free)?;
    let normal = NormalEquations {
        jtj: system.theta_jtj,
        ..system.phi
    };
    let covariance = lm_report(&theta, &driver.free, normal, y.len()).covariance();
    let (mut simulated, _) = problem.output(phi)?;
    let simulated = simulated.split_off(problem.skip);
    // After a declared history the saved x₀ is the state the history leaves at the first
    // sample (a later record re-applies the history; this one simulates the same).
    let model = match problem.skip {
        0 => model,
        _ => {
            let x0 = driver.family.initial_state_index();
            let mut theta = theta.clone();
            theta[x0] = states_with_tolerance(&model, &problem.u[..problem.skip + 1], TOLERANCE)?
                .last()
                .copied()
                .unwrap_or(theta[x0]);
            driver.family.model(&theta)?
        }
    };
    let parameters = model.parameters();
    let std: Vec<Option<f64>> = (0..parameters.len())
        .map(|i| {
            let s = covariance.std[i];
            (driver.free.contains(&i) && s.is_finite()).then_some(s)
        })
        .collect();
    let covariance = masked_covariance(&covariance.matrix, &std);
    let (n, p) = (y.len(), driver.free.len());
    let loss = metrics::mse(y, &simulated);
    Ok(OperatorFit {
        model,
        parameters,
        std,
        covariance,
        fit_percent: metrics::fit_percent(y, &simulated),
        rmse: loss.sqrt(),
        loss,
        fpe: metrics::fpe(loss, n, p),
        aic: metrics::aic(loss, n, p),
        simulated,
        iterations,
        evaluations,
        termination,
        elapsed_s: started.elapsed().as_secs_f64(),
        initial_state: None,
        history_turn: None,
        model_size: None,
    })
}

/// The rows of `matrix` (the parameters' covariance) as p vectors of p, zero in the rows and
/// columns of the parameters without a standard deviation (`std[i]` None).
pub(crate) fn masked_covariance(matrix: &DMatrix<f64>, std: &[Option<f64>]) -> Vec<Vec<f64>> {
    let p = std.len();
    (0..p)
        .map(|i| {
            (0..p)
                .map(|j| {
                    let both = std[i].is_some() && std[j].is_some();
                    if both && i < matrix.nrows() && j < matrix.ncols() {
                        matrix[(i, j)]
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect()
}

/// Least squares of y on the columns `cols` (small dense problem): coefficients and the sum
/// of squared residuals, or None when singular.
pub fn linear_fit(cols: &[&[f64]], y: &[f64]) -> Option<(Vec<f64>, f64)> {
    let p = cols.len();
    let a = nalgebra::DMatrix::from_fn(y.len(), p, |i, j| cols[j][i]);
    let b = nalgebra::DVector::from_column_slice(y);
    let svd = a.clone().svd(true, true);
    let x = svd.solve(&b, 1e-12 * svd.singular_values.max()).ok()?;
    let sse = (a * &x - b).norm_squared();
    (x.iter().all(|v| v.is_finite()) && sse.is_finite()).then(|| (x.iter().copied().collect(), sse))
}

/// (min, max) of a signal.
pub fn range(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        })
}
