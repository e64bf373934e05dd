//! Output-error estimation: fit a model's *simulated* output to the measured one.
//!
//! # Criterion
//!
//! For experiments e = 1…E, outputs o = 1…n_y and samples t:
//!
//! ```text
//! V(θ) = Σ_e Σ_o Σ_t w_o² ( y_eo(t) − ŷ_eo(t, θ) )²
//! ```
//!
//! where ŷ is the model output simulated from the measured inputs alone (no measured outputs
//! are fed back). Under white Gaussian output noise this is the maximum-likelihood criterion,
//! which is why it removes the bias that equation-error least squares has when the noise is
//! added to the output (Ljung, System Identification, 2nd ed., §4.2, §7.3). It is minimised by
//! the bounded Levenberg–Marquardt engine of [`crate::numerics::levenberg_marquardt`].
//!
//! A model implements [`OutputErrorModel`]: a parameter specification and a simulator, and
//! optionally analytic output sensitivities ∂ŷ/∂θ that it streams sample by sample. This layer
//! serves discrete-time models (the hysteresis cascade) and continuous-time grey-box models
//! alike: the simulator owns the time discretisation.

use crate::data::IdData;
use crate::model::ParameterSet;
use crate::numerics::levenberg_marquardt::{
    minimize, Control, Covariance, IterationRecord, LeastSquaresProblem, LmConfig, LmReport,
    NormalEquations, Trial,
};
use crate::numerics::{levenberg_marquardt, metrics};
use crate::{Error, Result};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::ops::ControlFlow;
use std::sync::atomic::AtomicUsize;
use std::sync::atomic::Ordering::Relaxed;
use std::sync::{Mutex, OnceLock};

#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub mod gram;
use gram::Accumulator;

pub mod ceiling;
use ceiling::Ceiling;

/// Receives one sample of simulated outputs and their sensitivities:
/// `(t, ŷ(t) [n_y], ∂ŷ(t)/∂θ_free [n_y × n_free, row-major])`. `Break` says the rest of the
/// pass is not needed (a trial point certain to be rejected, see [`ceiling`]): the model may
/// stop there, or go on, the sink then ignoring what follows.
pub type SensitivitySink<'a> = dyn FnMut(usize, &[f64], &[f64]) -> ControlFlow<()> + 'a;

/// Consecutive samples of a single-output model's simulation with its sensitivities: the
/// same rows a [`SensitivitySink`] would see one at a time, handed over in blocks so that the
/// receiver works on a run of rows instead of a call per sample.
pub struct SensitivityBlock<'a> {
    /// Sample index of the block's first row.
    pub start: usize,
    /// The rows `[ŷ(t), ∂ŷ(t)/∂θ_free]` for t = start, start + 1, …, one after the other.
    pub rows: &'a [f64],
    /// Length of a row: 1 + the number of free parameters.
    pub width: usize,
}

impl SensitivityBlock<'_> {
    /// Number of rows (samples) in the block.
    pub fn len(&self) -> usize {
        self.rows.len() / self.width
    }

    /// True when the block has no rows.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// ŷ of row `i` (sample `start + i`).
    pub fn yhat(&self, i: usize) -> f64 {
        self.rows[i * self.width]
    }
}

/// Receives the blocks of [`OutputErrorModel::simulate_sensitivity_blocks`] in sample order.
pub type BlockSink<'a> = dyn FnMut(&SensitivityBlock<'_>) + 'a;

/// A model structure that an output-error estimator can fit.
pub trait OutputErrorModel: Sync {
    /// The parameters (names, units, bounds, fixed flags, default values).
    fn parameters(&self) -> ParameterSet;

    /// Number of outputs the model simulates.
    fn n_outputs(&self) -> usize;

    /// Simulates experiment `exp` of `data` with the full parameter vector `theta`, writing one
    /// vector per output into `y` (each already sized to the experiment's length).
    fn simulate(&self, theta: &[f64], data: &IdData, exp: usize, y: &mut [Vec<f64>]) -> Result<()>;

    /// Optionally simulates experiment `exp` and streams, for every sample, the outputs and
    /// their sensitivities to the parameters `free` (see [`SensitivitySink`]).
    /// `None` (the default) makes the estimator use finite differences.
    fn simulate_sensitivities(
        &self,
        _theta: &[f64],
        _data: &IdData,
        _exp: usize,
        _free: &[usize],
        _sink: &mut SensitivitySink<'_>,
    ) -> Option<Result<()>> {
        None
    }

    /// Optionally the same pass as [`simulate_sensitivities`](Self::simulate_sensitivities)
    /// for a single-output model, streamed in blocks of consecutive samples (see
    /// [`SensitivityBlock`]); the rows must be the same, bit for bit. `threads` is how many
    /// threads the pass may keep busy (1 when another pass runs beside it; a model may
    /// pipeline a long record's pass over 2). `None` (the default) makes the estimator use
    /// the per-sample stream.
    fn simulate_sensitivity_blocks(
        &self,
        _theta: &[f64],
        _data: &IdData,
        _exp: usize,
        _free: &[usize],
        _threads: usize,
        _sink: &mut BlockSink<'_>,
    ) -> Option<Result<()>> {
        None
    }

    /// Whether the estimator should compute the sensitivities together with the residuals at
    /// every trial point (see \[`Speculation`\]). Worth it when a simulation with sensitivities
    /// costs little more than one without and most trial points are accepted, as for the
    /// continuous-time grey-box models; `false` (the default) keeps trial points cheap.
    fn speculative_sensitivities(&self) -> bool {
        false
    }

    /// Model steps one sample of a simulation costs (integration sub-steps times the
    /// evaluations of the equations per sub-step), for the work count of
    /// [`budget::count`](super::budget::count); 1 (the default) for a recursion.
    fn steps_per_sample(&self) -> u64 {
        1
    }

    /// Whether the output ŷ of the sensitivity pass ([`simulate_sensitivities`] and
    /// [`simulate_sensitivity_blocks`]) is bit for bit the output of [`simulate`] at the same
    /// θ. Then a long record's trial points take their residuals from that pass, whose
    /// normal equations serve the step that follows (see [`OutputErrorProblem::overlap`]),
    /// and no plain simulation runs beside it. `false` (the default) when unsure.
    ///
    /// [`simulate_sensitivities`]: Self::simulate_sensitivities
    /// [`simulate_sensitivity_blocks`]: Self::simulate_sensitivity_blocks
    /// [`simulate`]: Self::simulate
    fn pass_output_is_simulation(&self) -> bool {
        false
    }
}

/// Settings of the output-error estimator (MATLAB `nlgreyestOptions`).
#[derive(Clone, Debug, Default)]
pub struct OutputError {
    /// Levenberg–Marquardt settings (iterations, tolerances).
    pub config: LmConfig,
    /// Weight per output (default 1 for every output).
    pub output_weights: Option<Vec<f64>>,
    /// Number of initial samples of each experiment left out of the criterion (transients
    /// from unknown initial conditions).
    pub skip: usize,
}

/// A fitted output-error model and its report (MATLAB `present`).
#[derive(Clone, Debug)]
pub struct OutputErrorFit {
    /// The parameters with their estimated values.
    pub parameters: ParameterSet,
    /// Covariance, standard deviations and correlations.
    pub covariance: Covariance,
    /// fit % per experiment and output.
    pub fit_percent: Vec<Vec<f64>>,
    /// Mean squared error per experiment and output.
    pub mse: Vec<Vec<f64>>,
    /// Loss V = S/N (mean squared weighted residual).
    pub loss: f64,
    /// Akaike's final prediction error.
    pub fpe: f64,
    /// Akaike's information criterion.
    pub aic: f64,
    /// The optimiser's report: iterations, evaluations, termination, history, time.
    pub report: LmReport,
    /// Simulated outputs at the estimate, `[experiment][output][t]`.
    pub simulated: Vec<Vec<Vec<f64>>>,
}

impl OutputErrorFit {
    /// Standard deviations of all parameters (0 for fixed ones).
    pub fn std(&self) -> &[f64] {
        &self.covariance.std
    }

    /// The same fit moved to the parameter vector `theta` (e.g. a constrained correction):
    /// outputs, fit % and losses are recomputed by simulating `model`; the covariance and the
    /// optimiser's history are kept. The fit's simulated outputs are written over by the new
    /// simulation (a long record's pages are not faulted in again).
    pub fn at(self, model: &dyn OutputErrorModel, data: &IdData, theta: &[f64]) -> Result<Self> {
        let OutputErrorFit {
            parameters: mut moved_parameters,
            covariance,
            mut report,
            simulated,
            ..
        } = self;
        let weights = vec![1.0; model.n_outputs()];
        let problem = OutputErrorProblem::new(model, data, weights, 0)?;
        problem.recycle(simulated);
        report.theta = theta.to_vec();
        report.cost = problem.plain_cost(theta)?;
        moved_parameters.set_values(theta);
        let mut moved = summarize(&problem, moved_parameters, report)?;
        moved.covariance = covariance;
        Ok(moved)
    }
}

/// The normal equations at the start of a fit, computed ahead of it by
/// [`OutputError::start`].
pub struct FitStart {
    theta: Vec<f64>,
    free: Vec<usize>,
    system: NormalEquations,
}

impl FitStart {
    /// S = Σ r² at the start: the fit's criterion there.
    pub fn cost(&self) -> f64 {
        self.system.cost
    }
}

impl OutputError {
    /// Default settings: 100 iterations, tight tolerances.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the maximum number of iterations.
    pub fn max_iterations(mut self, n: usize) -> Self {
        self.config.max_iterations = n;
        self
    }

    /// Sets the relative-improvement tolerance (paper 2: 1e-4, i.e. 0.01 %).
    pub fn improvement_tolerance(mut self, tol: f64) -> Self {
        self.config.improvement_tolerance = tol;
        self
    }

    /// Sets the number of initial samples left out of the criterion.
    pub fn skip(mut self, samples: usize) -> Self {
        self.skip = samples;
        self
    }

    /// Fits `model` to `data` from the initial values, bounds and fixed flags in `params`.
    /// `callback` sees every accepted iteration and may stop the search.
    pub fn estimate(
        &self,
        model: &dyn OutputErrorModel,
        data: &IdData,
        params: &ParameterSet,
        callback: &mut dyn FnMut(&IterationRecord) -> Control,
    ) -> Result<OutputErrorFit> {
        self.estimate_from(model, data, params, None, callback)
    }

    /// The normal equations a fit of `model` from `params` starts with, computed ahead of
    /// the fit, when the fit would pipeline its passes over a long record (see
    /// [`OutputErrorProblem::overlap`]); `None` otherwise. Their S is the criterion at the
    /// start, so a caller that needs that value before deciding to fit gets it from the pass
    /// the fit needs anyway, and hands the start to [`estimate_from`](Self::estimate_from).
    pub fn start(
        &self,
        model: &dyn OutputErrorModel,
        data: &IdData,
        params: &ParameterSet,
    ) -> Result<Option<FitStart>> {
        self.start_on(model, data, params, PASS_THREADS)
    }

    /// [`start`](Self::start) with a pass that keeps at most `threads` threads busy (the
    /// same normal equations: only the work's spread changes).
    pub fn start_on(
        &self,
        model: &dyn OutputErrorModel,
        data: &IdData,
        params: &ParameterSet,
        threads: usize,
    ) -> Result<Option<FitStart>> {
        let (problem, free) = self.problem(model, data, params)?;
        problem.pass_threads.store(threads, Relaxed);
        if !problem.pipelines() {
            return Ok(None);
        }
        let theta = params.values();
        match problem.normal_equations(&theta, &free) {
            Some(system) => Ok(Some(FitStart {
                theta,
                free,
                system: system?,
            })),
            None => Ok(None),
        }
    }

    /// [`estimate`](Self::estimate) with the normal equations at the start computed ahead
    /// by [`start`](Self::start) (counted as the fit's first pass); a start made for other
    /// parameters is ignored.
    pub fn estimate_from(
        &self,
        model: &dyn OutputErrorModel,
        data: &IdData,
        params: &ParameterSet,
        start: Option<FitStart>,
        callback: &mut dyn FnMut(&IterationRecord) -> Control,
    ) -> Result<OutputErrorFit> {
        self.estimate_beside(model, data, params, start, None, callback)
    }

    /// [`estimate_from`](Self::estimate_from) with a [`Companion`] run beside the trial
    /// passes that are likely the fit's last (a pipelining fit's only; others ignore it).
    /// The fit is the same either way.
    pub fn estimate_beside(
        &self,
        model: &dyn OutputErrorModel,
        data: &IdData,
        params: &ParameterSet,
        start: Option<FitStart>,
        companion: Option<Companion<'_>>,
        callback: &mut dyn FnMut(&IterationRecord) -> Control,
    ) -> Result<OutputErrorFit> {
        let (mut problem, free) = self.problem(model, data, params)?;
        problem.companion = companion;
        if let Some(start) = start {
            problem.seed(start);
        }
        if problem.n_residuals() <= free.len() {
            return Err(Error::TooFewSamples {
                samples: problem.n_residuals(),
                parameters: free.len(),
                needed: free.len() + 1,
            });
        }
        let lower: Vec<f64> = params.iter().map(|p| p.min).collect();
        let upper: Vec<f64> = params.iter().map(|p| p.max).collect();
        let mut report = minimize(
            &problem,
            &params.values(),
            &free,
            &lower,
            &upper,
            &self.config,
            callback,
        )?;
        problem.count_simulations(&mut report);
        let mut parameters = params.clone();
        parameters.set_values(&report.theta);
        summarize(&problem, parameters, report)
    }

    /// The least-squares problem of a fit of `model` from `params`, set up for the record's
    /// length, and the free parameters.
    fn problem<'a>(
        &self,
        model: &'a dyn OutputErrorModel,
        data: &'a IdData,
        params: &ParameterSet,
    ) -> Result<(OutputErrorProblem<'a>, Vec<usize>)> {
        params.validate()?;
        check_outputs_vary(data)?;
        let mut problem =
            OutputErrorProblem::new(model, data, self.weights(model.n_outputs())?, self.skip)?;
        let free = params.free_indices();
        if model.speculative_sensitivities() {
            problem.speculate(&free);
        } else {
            problem.overlap(&free);
        }
        Ok((problem, free))
    }

    fn weights(&self, n_outputs: usize) -> Result<Vec<f64>> {
        match &self.output_weights {
            None => Ok(vec![1.0; n_outputs]),
            Some(w) if w.len() == n_outputs && w.iter().all(|v| v.is_finite() && *v > 0.0) => {
                Ok(w.clone())
            }
            Some(w) => Err(Error::invalid_option(
                "output_weights",
                format!("{w:?}"),
                format!("need {n_outputs} positive output weights, got {w:?}"),
            )),
        }
    }
}

/// Fit statistics at the final point.
fn summarize(
    problem: &OutputErrorProblem<'_>,
    parameters: ParameterSet,
    report: LmReport,
) -> Result<OutputErrorFit> {
    let simulated = problem.simulate_all(&report.theta)?;
    let skip = problem.skip;
    let mut fit_percent = Vec::new();
    let mut mse = Vec::new();
    for (e, sims) in simulated.iter().enumerate() {
        let exp = problem.data.experiment(e);
        let mut fits = Vec::new();
        let mut mses = Vec::new();
        for (o, yhat) in sims.iter().enumerate() {
            let y = &exp.output(o)[skip..];
            let (fit, mse) = metrics::fit_percent_and_mse(y, &yhat[skip..]);
            fits.push(fit);
            mses.push(mse);
        }
        fit_percent.push(fits);
        mse.push(mses);
    }
    let n = report.n_residuals;
    let p = report.free.len();
    let loss = report.cost / n as f64;
    Ok(OutputErrorFit {
        parameters,
        covariance: report.covariance(),
        fit_percent,
        mse,
        loss,
        fpe: metrics::fpe(loss, n, p),
        aic: metrics::aic(loss, n, p),
        report,
        simulated,
    })
}

/// The stacked, weighted residuals of an output-error fit as a least-squares problem.
pub struct OutputErrorProblem<'a> {
    model: &'a dyn OutputErrorModel,
    data: &'a IdData,
    weights: Vec<f64>,
    skip: usize,
    n_residuals: usize,
    /// Σ (w·y)² over the criterion's samples, behind [`cost_floor`]; summed on first use.
    ///
    /// [`cost_floor`]: LeastSquaresProblem::cost_floor
    data_scale: OnceLock<f64>,
    /// An upper bound of `data_scale` from the largest |w·y| (one pass in eight lanes, not
    /// a sequential sum): the floor is summed only when a cost comes near it.
    data_scale_bound: OnceLock<f64>,
    /// The last simulation behind [`residuals`](LeastSquaresProblem::residuals) and its θ:
    /// the fit statistics at the final point (the last accepted trial) reuse it instead of
    /// simulating a long record once more.
    last: Mutex<Option<(Vec<f64>, Simulations)>>,
    speculation: Option<Speculation>,
    /// Normal equations computed beside every trial point's plain simulation (see
    /// [`OVERLAP_RESIDUALS`]).
    overlap: Option<KeptSystem>,
    /// Work the fit's caller runs beside a trial pass that is likely the fit's last (see
    /// [`Companion`]).
    companion: Option<Companion<'a>>,
    /// How many threads a sensitivity pass may keep busy: [`PASS_THREADS`], or 1 while a companion runs
    /// beside it (see [`OutputErrorModel::simulate_sensitivity_blocks`]).
    pass_threads: AtomicUsize,
}

/// Work that a fit's caller needs once the fit has ended, at its final point θ, run on a
/// thread of its own beside the trial pass at θ when that pass is likely the fit's last:
/// its relative predicted decrease is below [`NEAR_MINIMUM`] (quadratic convergence then
/// leaves the next step's far below the improvement tolerance). The switching fixed point
/// (`switching::fixed_point`) computes the next fit's start there, a pass with the switching
/// re-classified by θ's d. Only pipelining fits (one pass at a time over a long record, see
/// [`OutputErrorProblem::overlap`]) run it. The trial pass and the companion's pass then run
/// on one thread each, side by side, instead of one after the other on two threads each. A
/// pipelined pass leaves its two threads waiting on each other part of the time; on this
/// project's two-core machines two single-thread passes side by side take about three
/// quarters of the time of two pipelined ones.
///
/// The companion is called with θ and the number of threads its work may keep busy (one:
/// the trial pass keeps the other).
pub type Companion<'a> = &'a (dyn Fn(&[f64], usize) + Sync);

/// The relative predicted decrease below which a trial point is taken to be a fit's last
/// (see [`Companion`]). The fits that follow a switching update converge quadratically: on
/// the 10⁶-sample example the steps predict 8·10⁻⁶, then 3·10⁻¹⁰ (the last), then
/// 3·10⁻¹⁷ (not taken, below the tolerance of 10⁻¹⁰).
pub const NEAR_MINIMUM: f64 = 1e-6;

/// The threads a sensitivity pass may keep busy when nothing runs beside it: a model may
/// pipeline a long record's pass over two (see
/// [`OutputErrorModel::simulate_sensitivity_blocks`]).
pub const PASS_THREADS: usize = 2;

/// Records at least this long (residuals) get every trial point's normal equations computed
/// with its residuals, kept for the engine's request that follows when the point is accepted
/// ([`OutputErrorProblem::overlap`]).
///
/// For a model whose sensitivity pass outputs its simulation bit for bit, the residuals come
/// from that pass (a [`Speculation`] without split columns); otherwise from a plain simulation
/// run beside the pass ([`rayon::join`], on the core the simulation leaves idle). Either way
/// the residuals are those of the plain simulation and the normal equations those of the
/// model's own pass, so every number is the one the sequential engine computes; only the work
/// and its order in time change. A rejected trial point wastes its normal equations, which is
/// rare from the good starts of long-record fits. Side by side, the engine's evaluation counts
/// are those of its requests; from the pass, the report counts the passes actually run.
const OVERLAP_RESIDUALS: usize = 1 << 16;

/// Normal equations computed ahead of the engine's request, at trial point θ for the free
/// parameters `free`: handed over once, when the engine asks for exactly that point.
struct KeptSystem {
    free: Vec<usize>,
    slot: Mutex<Option<(Vec<f64>, NormalEquations)>>,
}

impl KeptSystem {
    fn new(free: &[usize]) -> Self {
        Self {
            free: free.to_vec(),
            slot: Mutex::new(None),
        }
    }

    /// Keeps `system`, computed at `theta`, in place of whatever was kept.
    fn keep(&self, theta: &[f64], system: NormalEquations) {
        *self.slot.lock().unwrap_or_else(|p| p.into_inner()) = Some((theta.to_vec(), system));
    }

    /// The kept system if it was computed at `theta` for `free`; empties the slot either way
    /// (the engine never asks twice for one point).
    fn take(&self, theta: &[f64], free: &[usize]) -> Option<NormalEquations> {
        let kept = self.slot.lock().unwrap_or_else(|p| p.into_inner()).take();
        kept.filter(|(at, _)| at == theta && self.free == free)
            .map(|(_, system)| system)
    }
}

/// Speculative sensitivities: every trial point is simulated *with* its sensitivities, and the
/// normal equations are kept for the engine's request that follows when the point is accepted.
///
/// Levenberg–Marquardt simulates a trial point, and at an accepted one asks for the normal
/// equations JᵀJ, Jᵀr, which repeat the same simulation with the sensitivities. When most
/// trial points are accepted (a good start, a smooth criterion) computing both in one pass
/// saves a plain simulation per iteration at the price of the sensitivities of the few
/// rejected points. When the search runs alone (not inside a parallel multi-start) and the
/// experiments leave a core idle, the sensitivity columns are split between two threads
/// ([`rayon::join`]), each integrating the state with half of the columns: the state is
/// integrated twice, the sensitivities once. Without the split (`split` false: a long record
/// whose model pipelines its own pass, see [`OVERLAP_RESIDUALS`]) each trial point is one
/// whole pass.
struct Speculation {
    split: bool,
    kept: KeptSystem,
    with_sensitivities: std::sync::atomic::AtomicUsize,
    without: std::sync::atomic::AtomicUsize,
    disabled: std::sync::atomic::AtomicBool,
}

impl Speculation {
    /// Speculation for the parameters `free`, with split columns or not, nothing counted yet.
    fn new(split: bool, free: &[usize]) -> Self {
        Self {
            split,
            kept: KeptSystem::new(free),
            with_sensitivities: 0.into(),
            without: 0.into(),
            disabled: false.into(),
        }
    }
}

/// Simulated outputs `[experiment][output][t]`.
type Simulations = Vec<Vec<Vec<f64>>>;

/// What a speculative pass knows of S at its point.
enum PassCost {
    /// S, summed row by row in the engine's order (no split columns).
    Summed(f64),
    /// To be summed from the residuals the pass wrote (split columns).
    InResiduals,
    /// A lower bound of S above the trial's ceiling: the pass stopped there (see
    /// [`ceiling`]), and the residuals are only partly written.
    Above(f64),
}

impl<'a> OutputErrorProblem<'a> {
    /// Checks that the data suit the model and precomputes the residual layout.
    pub fn new(
        model: &'a dyn OutputErrorModel,
        data: &'a IdData,
        weights: Vec<f64>,
        skip: usize,
    ) -> Result<Self> {
        let ny = model.n_outputs();
        if data.output_channels().len() != ny {
            return Err(Error::CountMismatch {
                model: "the model".into(),
                what: "output channels",
                expected: ny,
                given: data.output_channels().len(),
            });
        }
        let mut n_residuals = 0;
        for exp in data.experiments() {
            if exp.len() <= skip {
                return Err(Error::TooFewSamples {
                    samples: exp.len(),
                    parameters: 0,
                    needed: skip + 1,
                });
            }
            n_residuals += ny * (exp.len() - skip);
        }
        Ok(Self {
            model,
            data,
            weights,
            skip,
            n_residuals,
            data_scale: OnceLock::new(),
            data_scale_bound: OnceLock::new(),
            last: Mutex::new(None),
            speculation: None,
            overlap: None,
            companion: None,
            pass_threads: AtomicUsize::new(PASS_THREADS),
        })
    }

    /// Turns on speculative sensitivities for the parameters `free` (see \[`Speculation`\]) when
    /// the search runs alone and a core is idle for the split columns.
    pub fn speculate(&mut self, free: &[usize]) {
        // On one core a plain simulation is several times cheaper than one with
        // sensitivities, so speculating pays only when the columns can be split.
        if !(self.has_idle_core() && free.len() >= 2) {
            return;
        }
        self.speculation = Some(Speculation::new(true, free));
    }

    /// Turns on, for the parameters `free`, the early normal equations of long records (at
    /// least 2¹⁶ residuals) when a core is idle: each trial point's normal equations are
    /// computed with its residuals, kept for the step that follows when the point is
    /// accepted. When the model's sensitivity pass outputs its simulation bit for bit
    /// ([`OutputErrorModel::pass_output_is_simulation`]) the residuals come from that pass
    /// (speculative sensitivities without split columns: one pass per trial point,
    /// pipelined over the two cores by the model); otherwise from a plain simulation
    /// beside it.
    pub fn overlap(&mut self, free: &[usize]) {
        if !(self.has_idle_core() && self.n_residuals >= OVERLAP_RESIDUALS && !free.is_empty()) {
            return;
        }
        if self.model.pass_output_is_simulation() {
            self.speculation = Some(Speculation::new(false, free));
        } else {
            self.overlap = Some(KeptSystem::new(free));
        }
    }

    /// True when every pass of the fit is one pipelined pass over a long record (see
    /// [`overlap`](Self::overlap)).
    fn pipelines(&self) -> bool {
        self.speculation.as_ref().is_some_and(|s| !s.split)
    }

    /// Hands the start's normal equations computed ahead ([`OutputError::start`], made only
    /// for pipelining fits) to the engine's first request, as a trial pass's are kept; the
    /// fit counts them as one of its passes.
    fn seed(&self, start: FitStart) {
        if let Some(spec) = self
            .speculation
            .as_ref()
            .filter(|s| s.kept.free == start.free)
        {
            spec.with_sensitivities.fetch_add(1, Relaxed);
            spec.kept.keep(&start.theta, start.system);
        }
    }

    /// True when the search runs alone (inside a rayon job, a multi-start, the other core is
    /// busy already) and the experiments, simulated in parallel, leave a core idle.
    fn has_idle_core(&self) -> bool {
        rayon::current_thread_index().is_none()
            && rayon::current_num_threads() > self.data.n_experiments()
    }

    /// Replaces the engine's request counts by the simulations actually run, when trial
    /// points were simulated with their sensitivities (the engine counts requests; a request
    /// for normal equations answered from a trial point's pass simulates nothing).
    fn count_simulations(&self, report: &mut LmReport) {
        if let Some(spec) = &self.speculation {
            let with = spec.with_sensitivities.load(Relaxed);
            let without = spec.without.load(Relaxed);
            report.sensitivity_evaluations = with;
            report.residual_evaluations = without;
            report.function_evaluations = with + without;
        }
    }

    /// Residuals and normal equations of every experiment in one pass per experiment; None
    /// when the model has no analytic sensitivities. Split passes stop once they pass
    /// `ceiling` when given: the normal equations are then zero, for the caller to discard
    /// (it asks the ceiling).
    fn residuals_with_normal_equations(
        &self,
        theta: &[f64],
        free: &[usize],
        split: bool,
        r: Option<&mut [f64]>,
        ceiling: Option<&Ceiling>,
    ) -> Option<Result<NormalEquations>> {
        // Without split columns the pass's outputs are the simulation's (the only way here,
        // see `overlap`): they are kept as the last simulation, which the fit statistics at
        // the final point then reuse instead of simulating once more.
        let mut sims: Simulations = if split {
            Vec::new()
        } else {
            self.simulation_buffers()
        };
        let mut outputs = sims.iter_mut();
        let mut scratch = Vec::new();
        let mut rest = match (r, split) {
            (Some(r), _) => Some(r),
            // The split columns' path writes residuals: into scratch when none are wanted.
            (None, true) => {
                scratch.resize(self.n_residuals, 0.0);
                Some(&mut scratch[..])
            }
            (None, false) => None,
        };
        let mut chunks = Vec::new();
        for e in 0..self.data.n_experiments() {
            let len = self.model.n_outputs() * (self.data.experiment(e).len() - self.skip);
            let chunk = rest.take().map(|all| {
                let (chunk, tail) = all.split_at_mut(len);
                rest = Some(tail);
                chunk
            });
            chunks.push((e, chunk, outputs.next()));
        }
        let parts: Vec<Option<Result<NormalEquations>>> = chunks
            .into_par_iter()
            .map(|(e, chunk, outputs)| match (outputs, chunk) {
                (None, Some(chunk)) => self.experiment_split(theta, free, e, chunk, ceiling),
                (outputs, chunk) => {
                    self.experiment_normal_equations(theta, free, e, chunk, outputs)
                }
            })
            .collect();
        let total = sum_normal_equations(parts);
        if !split && matches!(total, Some(Ok(_))) {
            *self.last.lock().unwrap_or_else(|e| e.into_inner()) = Some((theta.to_vec(), sims));
        }
        total
    }

    /// Buffers for a pass's outputs `[experiment][output][t]`: the last simulation's, which
    /// a new pass makes stale (reused, their pages need not be faulted in again; every value
    /// is written over), else new ones.
    fn simulation_buffers(&self) -> Simulations {
        self.stale_buffers().unwrap_or_else(|| self.new_buffers())
    }

    /// The last simulation's outputs (taken) when they have the shape of this problem's.
    fn stale_buffers(&self) -> Option<Simulations> {
        let ny = self.model.n_outputs();
        let experiments = self.data.experiments();
        let fits = |sims: &Simulations| {
            sims.len() == experiments.len()
                && sims.iter().zip(experiments).all(|(outputs, exp)| {
                    outputs.len() == ny && outputs.iter().all(|y| y.len() == exp.len())
                })
        };
        let last = self.last.lock().unwrap_or_else(|e| e.into_inner()).take();
        last.map(|(_, sims)| sims).filter(fits)
    }

    /// Zeroed outputs `[experiment][output][t]` for this problem's data.
    fn new_buffers(&self) -> Simulations {
        let ny = self.model.n_outputs();
        self.data
            .experiments()
            .iter()
            .map(|exp| vec![vec![0.0; exp.len()]; ny])
            .collect()
    }

    /// One experiment's residuals and normal equations with the sensitivity columns split
    /// between two threads (the Jacobian block is stored, JᵀJ formed by one product). Both
    /// threads stop once the residuals pass `ceiling` when given; the normal equations are
    /// then zero.
    fn experiment_split(
        &self,
        theta: &[f64],
        free: &[usize],
        e: usize,
        r: &mut [f64],
        ceiling: Option<&Ceiling>,
    ) -> Option<Result<NormalEquations>> {
        let (first, second) = free.split_at(free.len() / 2);
        let (a, b) = rayon::join(
            || self.experiment_columns(theta, first, e, Some(&mut *r), ceiling),
            || self.experiment_columns(theta, second, e, None, ceiling),
        );
        let (a, b) = match (a?, b?) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(err), _) | (_, Err(err)) => return Some(Err(err)),
        };
        if ceiling.is_some_and(Ceiling::passed) {
            let p = free.len();
            return Some(Ok(NormalEquations {
                jtj: DMatrix::zeros(p, p),
                jtr: DVector::zeros(p),
                cost: 0.0,
            }));
        }
        let rows = r.len();
        let columns: Vec<&[f64]> = a.chunks_exact(rows).chain(b.chunks_exact(rows)).collect();
        Some(Ok(gram::of_columns(&columns, r)))
    }

    /// The Jacobian columns of one experiment's residuals for the parameters `free`,
    /// column-major, and its residuals into `r` when given (counted into `ceiling`, whose
    /// passing stops the pass, when given too).
    fn experiment_columns(
        &self,
        theta: &[f64],
        free: &[usize],
        e: usize,
        mut r: Option<&mut [f64]>,
        ceiling: Option<&Ceiling>,
    ) -> Option<Result<Vec<f64>>> {
        let p = free.len();
        let exp = self.data.experiment(e);
        let rows = exp.len() - self.skip;
        let mut jac = vec![0.0; rows * self.weights.len() * p];
        let n_rows = rows * self.weights.len();
        let skip = self.skip;
        let weights = &self.weights;
        let mut tally = ceiling.map(Ceiling::tally);
        let mut sink = |t: usize, yhat: &[f64], dyhat: &[f64]| {
            if t < skip {
                return ControlFlow::Continue(());
            }
            if tally.as_ref().is_some_and(|tally| tally.passed()) {
                return ControlFlow::Break(());
            }
            for (o, w) in weights.iter().enumerate() {
                let row = o * rows + t - skip;
                if let Some(r) = r.as_deref_mut() {
                    r[row] = w * (exp.output(o)[t] - yhat[o]);
                    if let Some(tally) = &mut tally {
                        tally.add(r[row]);
                    }
                }
                for k in 0..p {
                    jac[k * n_rows + row] = -w * dyhat[o * p + k];
                }
            }
            ControlFlow::Continue(())
        };
        let outcome = self
            .model
            .simulate_sensitivities(theta, self.data, e, free, &mut sink)?;
        self.count_steps(e, p);
        Some(outcome.map(|()| jac))
    }

    /// Counts one simulation of experiment `e` with `sensitivities` sensitivities in the
    /// process's work count ([`budget::count`](super::budget::count)).
    fn count_steps(&self, e: usize, sensitivities: usize) {
        let samples = u64::try_from(self.data.experiment(e).len()).unwrap_or(u64::MAX);
        let passes = u64::try_from(sensitivities)
            .unwrap_or(u64::MAX)
            .saturating_add(1);
        super::budget::count(
            samples
                .saturating_mul(passes)
                .saturating_mul(self.model.steps_per_sample()),
        );
    }

    /// Simulated outputs of every experiment, `[experiment][output][t]`.
    pub fn simulate_all(&self, theta: &[f64]) -> Result<Vec<Vec<Vec<f64>>>> {
        if let Some(sims) = self.take_last(theta) {
            return Ok(sims);
        }
        let mut sims = match self.stale_buffers() {
            // A model may write only part of its outputs: they start from zero either way.
            Some(mut stale) => {
                stale.par_iter_mut().flatten().for_each(|y| y.fill(0.0));
                stale
            }
            None => self.new_buffers(),
        };
        sims.par_iter_mut().enumerate().try_for_each(|(e, y)| {
            self.count_steps(e, 0);
            self.model.simulate(theta, self.data, e, y)
        })?;
        Ok(sims)
    }

    /// Hands over simulated outputs that no longer match any θ (a fit's that is being moved)
    /// as storage for the next simulation.
    fn recycle(&self, sims: Simulations) {
        // θ = [] matches no parameter vector.
        *self.last.lock().unwrap_or_else(|e| e.into_inner()) = Some((Vec::new(), sims));
    }

    /// The kept simulation when it was made at exactly `theta` (the same θ simulates to the
    /// same outputs, bit for bit).
    fn take_last(&self, theta: &[f64]) -> Option<Simulations> {
        let mut last = self.last.lock().unwrap_or_else(|e| e.into_inner());
        match last.take() {
            Some((at, sims)) if at == theta => Some(sims),
            other => {
                *last = other;
                None
            }
        }
    }

    /// Streams one experiment's sensitivities into normal equations, its residuals into
    /// `residuals` and the pass's outputs ŷ (`[output][t]`) into `outputs` when given.
    fn experiment_normal_equations(
        &self,
        theta: &[f64],
        free: &[usize],
        e: usize,
        mut residuals: Option<&mut [f64]>,
        mut outputs: Option<&mut Vec<Vec<f64>>>,
    ) -> Option<Result<NormalEquations>> {
        let blocks = self.experiment_blocks(
            theta,
            free,
            e,
            residuals.as_deref_mut(),
            outputs.as_deref_mut(),
        );
        if let Some(system) = blocks {
            return Some(system);
        }
        let p = free.len();
        let exp = self.data.experiment(e);
        let rows = exp.len() - self.skip;
        let mut acc = Accumulator::new(p);
        let skip = self.skip;
        let weights = &self.weights;
        let mut sink = |t: usize, yhat: &[f64], dyhat: &[f64]| {
            if let Some(outputs) = outputs.as_deref_mut() {
                for (out, &v) in outputs.iter_mut().zip(yhat) {
                    out[t] = v;
                }
            }
            if t < skip {
                return ControlFlow::Continue(());
            }
            for (o, w) in weights.iter().enumerate() {
                let r = w * (exp.output(o)[t] - yhat[o]);
                if let Some(out) = residuals.as_deref_mut() {
                    out[o * rows + t - skip] = r;
                }
                acc.add_scaled(-w, &dyhat[o * p..(o + 1) * p], r);
            }
            ControlFlow::Continue(())
        };
        let outcome = self
            .model
            .simulate_sensitivities(theta, self.data, e, free, &mut sink)?;
        self.count_steps(e, p);
        Some(outcome.map(|()| acc.finish()))
    }

    /// [`experiment_normal_equations`](Self::experiment_normal_equations) from the model's
    /// block stream, when it has one (single-output models only). The rows, residuals and
    /// their order are those of the per-sample stream, so the result is bit-identical.
    fn experiment_blocks(
        &self,
        theta: &[f64],
        free: &[usize],
        e: usize,
        mut residuals: Option<&mut [f64]>,
        mut outputs: Option<&mut Vec<Vec<f64>>>,
    ) -> Option<Result<NormalEquations>> {
        let [w] = self.weights[..] else {
            return None;
        };
        let y = self.data.experiment(e).output(0);
        let skip = self.skip;
        let mut acc = Accumulator::new(free.len());
        let mut r = Vec::new();
        let mut sink = |block: &SensitivityBlock<'_>| {
            // Rows before `skip` are left out of the criterion.
            let first = skip.saturating_sub(block.start).min(block.len());
            let t0 = block.start + first;
            r.clear();
            r.extend(
                y[t0..block.start + block.len()]
                    .iter()
                    .zip(
                        block.rows[first * block.width..]
                            .iter()
                            .step_by(block.width),
                    )
                    .map(|(y, yhat)| w * (y - yhat)),
            );
            if let Some(out) = residuals.as_deref_mut() {
                out[t0 - skip..t0 - skip + r.len()].copy_from_slice(&r);
            }
            if let Some(outputs) = outputs.as_deref_mut() {
                let out = &mut outputs[0][block.start..block.start + block.len()];
                for (o, row) in out.iter_mut().zip(block.rows.chunks_exact(block.width)) {
                    *o = row[0];
                }
            }
            acc.add_rows(-w, block.rows, block.width, first, &r);
        };
        let threads = self.pass_threads.load(Relaxed);
        let outcome = self
            .model
            .simulate_sensitivity_blocks(theta, self.data, e, free, threads, &mut sink)?;
        self.count_steps(e, free.len());
        Some(outcome.map(|()| acc.finish()))
    }
}

impl LeastSquaresProblem for OutputErrorProblem<'_> {
    fn n_params(&self) -> usize {
        self.model.parameters().len()
    }

    fn n_residuals(&self) -> usize {
        self.n_residuals
    }

    fn residuals(&self, theta: &[f64], r: &mut [f64]) -> Result<()> {
        self.speculative_residuals(theta, r, None).map(|_| ())
    }

    fn trial_cost(&self, theta: &[f64], r: &mut Vec<f64>) -> Result<f64> {
        self.trial_cost_under(theta, r, None)
    }

    fn trial_cost_with(&self, theta: &[f64], r: &mut Vec<f64>, trial: Trial) -> Result<f64> {
        let ceiling = Ceiling::new(trial.ceiling);
        match self.companion {
            Some(companion) if trial.predicted < NEAR_MINIMUM && self.pipelines() => {
                self.pass_threads.store(1, Relaxed);
                let cost = std::thread::scope(|scope| {
                    let beside = scope.spawn(|| companion(theta, 1));
                    let cost = self.trial_cost_under(theta, r, Some(&ceiling));
                    // A panic of the companion is the caller's: it surfaces here.
                    if let Err(panic) = beside.join() {
                        std::panic::resume_unwind(panic);
                    }
                    cost
                });
                self.pass_threads.store(PASS_THREADS, Relaxed);
                cost
            }
            _ => self.trial_cost_under(theta, r, Some(&ceiling)),
        }
    }

    fn residuals_and_cost(&self, theta: &[f64], r: &mut [f64]) -> Result<f64> {
        self.residuals_and_cost_under(theta, r, None)
    }

    fn normal_equations(&self, theta: &[f64], free: &[usize]) -> Option<Result<NormalEquations>> {
        if let Some(system) = self.overlap.as_ref().and_then(|o| o.take(theta, free)) {
            return Some(Ok(system));
        }
        self.speculative_or_direct_normal_equations(theta, free)
    }

    fn cost_floor(&self) -> f64 {
        // Residuals at the 1e-13 relative level are round-off: the fit is exact.
        1e-26 * self.data_scale()
    }

    fn is_exact_fit(&self, cost: f64) -> bool {
        // The bound is at least the sum, so a cost above its floor is above the floor: a
        // fit with real residuals never sums the record (a sequential pass of a
        // millisecond per 10⁶ samples, once per fit).
        cost <= 1e-26 * self.data_scale_bound() && cost <= self.cost_floor()
    }
}

impl OutputErrorProblem<'_> {
    /// Σ (w·y)² over the criterion's samples, outputs one after the other, each summed in
    /// order.
    fn data_scale(&self) -> f64 {
        *self.data_scale.get_or_init(|| {
            self.sum_over_outputs(|y, w| y.iter().map(|v| (w * v).powi(2)).sum::<f64>())
        })
    }

    /// 2·Σ N·(w·max|y|)² over outputs and experiments: at least [`data_scale`] as summed
    /// (each of its N terms is at most (w·max|y|)², and the sum's rounding adds less than
    /// N·ε relative, far below the factor 2 for any record that fits in memory).
    ///
    /// [`data_scale`]: Self::data_scale
    fn data_scale_bound(&self) -> f64 {
        *self.data_scale_bound.get_or_init(|| {
            self.sum_over_outputs(|y, w| {
                let largest = w * metrics::max_abs(y);
                2.0 * y.len() as f64 * largest * largest
            })
        })
    }

    /// Σ `per_output(y, w)` over the experiments and their outputs, in that order: y an
    /// output's samples in the criterion, w its weight.
    fn sum_over_outputs(&self, per_output: impl Fn(&[f64], f64) -> f64) -> f64 {
        let mut total = 0.0;
        for exp in self.data.experiments() {
            for (o, &w) in self.weights.iter().enumerate() {
                total += per_output(&exp.output(o)[self.skip..], w);
            }
        }
        total
    }

    /// [`LeastSquaresProblem::trial_cost`], its pass stopped once it passes `ceiling` when
    /// given (the lower bound of S it reached is then returned; see [`ceiling`]).
    fn trial_cost_under(
        &self,
        theta: &[f64],
        r: &mut Vec<f64>,
        ceiling: Option<&Ceiling>,
    ) -> Result<f64> {
        // A long record's trial point is one pipelined pass (see `overlap`); its S, summed as
        // the engine sums, is all the engine reads, so the residuals are not written out.
        if self.pipelines() && self.data.n_experiments() == 1 {
            if let Some(pass) = self.speculative_pass(theta, None, None) {
                return match pass? {
                    PassCost::Summed(cost) if cost.is_finite() => Ok(cost),
                    _ => Err(Error::Diverged {
                        index: 0,
                        reason: "the criterion is not finite".into(),
                    }),
                };
            }
        }
        r.resize(self.n_residuals, 0.0);
        self.residuals_and_cost_under(theta, r, ceiling)
    }

    /// [`LeastSquaresProblem::residuals_and_cost`], the pass stopped at `ceiling` as in
    /// [`trial_cost_under`](Self::trial_cost_under) (`r` is then partly written).
    fn residuals_and_cost_under(
        &self,
        theta: &[f64],
        r: &mut [f64],
        ceiling: Option<&Ceiling>,
    ) -> Result<f64> {
        // The pass's S is Σ r² summed row by row, the engine's order, when the residuals are
        // one experiment's (several are summed experiment by experiment).
        match self.speculative_residuals(theta, r, ceiling)? {
            Some(PassCost::Above(bound)) => Ok(bound),
            Some(PassCost::Summed(cost)) if self.data.n_experiments() == 1 && cost.is_finite() => {
                Ok(cost)
            }
            _ => levenberg_marquardt::sum_of_squares(r),
        }
    }

    /// The residuals at θ into `r`, from a sensitivity pass when speculating (see
    /// [`speculative_pass`](Self::speculative_pass), which may stop at `ceiling`), else from
    /// a simulation (returns None).
    fn speculative_residuals(
        &self,
        theta: &[f64],
        r: &mut [f64],
        ceiling: Option<&Ceiling>,
    ) -> Result<Option<PassCost>> {
        if let Some(pass) = self.speculative_pass(theta, Some(&mut *r), ceiling) {
            return pass.map(Some);
        }
        if let Some(spec) = &self.speculation {
            spec.without.fetch_add(1, Relaxed);
        }
        self.plain_or_overlapped_residuals(theta, r).map(|()| None)
    }

    /// One speculative pass at θ, its residuals into `r` when given: its normal equations
    /// are kept for the engine's request that follows, and it says what it knows of S (see
    /// [`PassCost`]). A pass with split columns stops once it passes `ceiling` when given;
    /// its normal equations are then not kept. None when not speculating, or when the model
    /// turns out to have no pass.
    fn speculative_pass(
        &self,
        theta: &[f64],
        r: Option<&mut [f64]>,
        ceiling: Option<&Ceiling>,
    ) -> Option<Result<PassCost>> {
        let spec = self
            .speculation
            .as_ref()
            .filter(|s| !s.disabled.load(Relaxed))?;
        let ceiling = ceiling.filter(|_| spec.split);
        let Some(system) =
            self.residuals_with_normal_equations(theta, &spec.kept.free, spec.split, r, ceiling)
        else {
            spec.disabled.store(true, Relaxed);
            return None;
        };
        spec.with_sensitivities.fetch_add(1, Relaxed);
        Some(system.map(|system| {
            if let Some(bound) = ceiling.and_then(Ceiling::lower_bound) {
                return PassCost::Above(bound);
            }
            let cost = match spec.split {
                true => PassCost::InResiduals,
                false => PassCost::Summed(system.cost),
            };
            spec.kept.keep(theta, system);
            cost
        }))
    }

    /// The residuals from a plain simulation, with the normal equations computed beside it
    /// when overlapping (see [`OVERLAP_RESIDUALS`]).
    fn plain_or_overlapped_residuals(&self, theta: &[f64], r: &mut [f64]) -> Result<()> {
        if let Some(overlap) = &self.overlap {
            let (plain, system) = rayon::join(
                || self.plain_residuals(theta, r),
                || self.direct_normal_equations(theta, &overlap.free),
            );
            // A failed pass is left for the engine's own request to meet again.
            if let Some(Ok(system)) = system {
                overlap.keep(theta, system);
            }
            return plain;
        }
        self.plain_residuals(theta, r)
    }

    /// S(θ) = Σ r² from a plain simulation (kept as the last simulation), summed in the
    /// order of the residual vector without writing it out.
    fn plain_cost(&self, theta: &[f64]) -> Result<f64> {
        let mut cost = 0.0;
        self.each_plain_residual(theta, |_, r| cost += r * r)?;
        Ok(cost)
    }

    /// The residuals from a plain simulation (kept as the last simulation).
    fn plain_residuals(&self, theta: &[f64], r: &mut [f64]) -> Result<()> {
        self.each_plain_residual(theta, |k, value| r[k] = value)
    }

    /// Simulates at θ (kept as the last simulation) and hands every residual, with its
    /// index in the stacked residual vector, to `each`, in that order.
    fn each_plain_residual(&self, theta: &[f64], mut each: impl FnMut(usize, f64)) -> Result<()> {
        let sims = self.simulate_all(theta)?;
        let mut k = 0;
        for (e, sim) in sims.iter().enumerate() {
            let exp = self.data.experiment(e);
            for (o, yhat) in sim.iter().enumerate() {
                let w = self.weights[o];
                for (y, yh) in exp.output(o)[self.skip..].iter().zip(&yhat[self.skip..]) {
                    each(k, w * (y - yh));
                    k += 1;
                }
            }
        }
        *self.last.lock().unwrap_or_else(|e| e.into_inner()) = Some((theta.to_vec(), sims));
        Ok(())
    }

    /// The normal equations from the speculative cache or pass when speculating, else
    /// [`direct_normal_equations`](Self::direct_normal_equations).
    fn speculative_or_direct_normal_equations(
        &self,
        theta: &[f64],
        free: &[usize],
    ) -> Option<Result<NormalEquations>> {
        if let Some(spec) = &self.speculation {
            if let Some(system) = spec.kept.take(theta, free) {
                return Some(Ok(system));
            }
            if !spec.disabled.load(Relaxed) {
                spec.with_sensitivities.fetch_add(1, Relaxed);
                if spec.split && spec.kept.free == free {
                    // The start: the engine asks for the normal equations first.
                    return self.residuals_with_normal_equations(theta, free, true, None, None);
                }
            }
        }
        self.direct_normal_equations(theta, free)
    }

    /// The normal equations of every experiment's sensitivity pass, summed.
    fn direct_normal_equations(
        &self,
        theta: &[f64],
        free: &[usize],
    ) -> Option<Result<NormalEquations>> {
        let parts: Vec<Option<Result<NormalEquations>>> = (0..self.data.n_experiments())
            .into_par_iter()
            .map(|e| self.experiment_normal_equations(theta, free, e, None, None))
            .collect();
        sum_normal_equations(parts)
    }
}

/// The sum of the experiments' normal equations; None when any experiment has no analytic
/// sensitivities.
fn sum_normal_equations(
    parts: Vec<Option<Result<NormalEquations>>>,
) -> Option<Result<NormalEquations>> {
    let mut total: Option<NormalEquations> = None;
    for part in parts {
        let part = match part? {
            Ok(p) => p,
            Err(e) => return Some(Err(e)),
        };
        total = Some(match total {
            None => part,
            Some(mut t) => {
                t.jtj += part.jtj;
                t.jtr += part.jtr;
                t.cost += part.cost;
                t
            }
        });
    }
    total.map(Ok)
}

/// A measured output that never changes carries nothing to fit and leaves fit % undefined
/// (its variance is zero): refused rather than reported as an "exact fit".
fn check_outputs_vary(data: &IdData) -> Result<()> {
    for experiment in data.experiments() {
        for (o, channel) in data.output_channels().iter().enumerate() {
            let y = experiment.output(o);
            if let Some(&first) = y.first() {
                if !crate::data::varies(y) {
                    return Err(Error::InvalidData(format!(
                        "output '{}' is constant ({first}) at double precision in experiment '{}': there is nothing to fit and fit % is undefined; check the output column",
                        channel.name,
                        experiment.name()
                    )));
                }
            }
        }
    }
    Ok(())
}
