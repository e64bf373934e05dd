//! The Coleman–Hodgdon hysteresis alone, identified from its measured input and output.
//!
//! # Method
//!
//! 1. **Profile over d.** For a fixed threshold d the switching function h is known and the
//!    separated model (docs/models/coleman-hodgdon-cascade.md §5) is linear in α·m1, α·m2,
//!    α, c1, c2 once θ3 is tied to d, θ3 = (θ1 − θ2)·d:
//!
//!    ```text
//!    Δy = αm1·|Δx|(x(1−h) + d·sgn(x)h) + αm2·|Δx|(x·h − d·sgn(x)h) − α·|Δx|y(t−1) + c1(1−h)Δx + c2·hΔx
//!    ```
//!
//!    (ch4: drop the m2 and c2 terms). A grid over d refined by golden-section search picks the
//!    d with the smallest equation error: no starting value is needed.
//!
//!    The regression only starts the search, and α̂ ≤ 0 is no model. A few rows the
//!    hysteresis does not explain can force that at every d: on a measured piezo record the
//!    input jumps 0 → −87 V in one sample while the sensor reports the displacement a sample
//!    later, so that row reads "|Δx| = 87, Δy ≈ 0" with regressors hundreds of times the
//!    others', and the transient after it adds rows with Δy of several µm. The profile then
//!    tries, in order, until some grid point gives α̂ > 0:
//!    * plain least squares (the cost its residual sum of squares) — every record it can
//!      start gives the same numbers as before this fallback existed;
//!    * **trimmed** least squares: refitted on the rows with |r| ≤ 5σ̂, σ̂ = 1.4826·median|r|,
//!      the cost the truncated quadratic Σ min(r², (5σ̂)²) over every row;
//!    * trimmed with **α held** at 1/max|x| (the gap y − f closes over about one input
//!      amplitude of travel; at most the rate limit): Δy + α|Δx|y(t−1) is regressed on the
//!      other columns.
//!
//!    The profile's costs take θ̂ from the streamed QR of [Φ Δy] (no covariance; the
//!    estimate to rounding), and the trimmed fits' median from a selection rather than a
//!    sort; the regression at the chosen d is solved in full. On the 50 001-sample piezo
//!    record, whose profile reaches the α-held stage, that is some 1 000 solves.
//!
//!    Every step is unchanged when x changes units (x' = x/s maps α, m, c to s·α, s·m, s·c
//!    and d to d/s; the grid and the held α follow max|x|). An offset of x is *not* a change
//!    of units for this model: f is odd about x = 0 and the central segment is |x| ≤ d, so
//!    the origin of x is part of the model and the input is never centred. (For an input
//!    that never crosses 0, x' = x + c with y' = y + m1·c is the same hysteresis with
//!    d' = d + c.)
//! 2. **Separated regression with the switching function re-estimated** (Vörös 2015): least
//!    squares on the free 6- (or 4-) parameter separated form with h from the current d̂,
//!    then d̂ = θ3/(θ1 − θ2) (ch4: θ2/θ1), repeated until d̂ settles. Where it does not
//!    (d̂ leaves the input range, no model, or the free form's columns are dependent: a
//!    record whose input passes d at a sample or two), the profile's constrained solution
//!    at its d̂ stands.
//! 3. **Output-error refinement**: Levenberg–Marquardt on the simulated hysteresis output.
//!    The regression uses the *measured* y(t−1) as a regressor, so noise on y biases it
//!    (errors in variables); the output-error fit does not, and gives standard deviations.
//!
//! Several experiments (e.g. loops measured separately) are stacked; each starts from its own
//! measured y(0).

use super::output_error::{
    BlockSink, OutputError, OutputErrorFit, OutputErrorModel, SensitivityBlock, SensitivitySink,
};
use super::switching::{
    fit_with_switching_updates, place_threshold, true_cost, Switching, ThresholdPosterior,
};
use crate::data::IdData;
use crate::model::coleman_hodgdon::switching;
pub use crate::model::coleman_hodgdon::{simulate_switched, InitialOutput};
use crate::model::{ChForm, ColemanHodgdon};
use crate::model::{Parameter, ParameterSet};
use crate::numerics::least_squares::{least_squares, least_squares_estimate, LsSolution};
use crate::numerics::levenberg_marquardt::{Control, IterationRecord, LmConfig};
use crate::numerics::{metrics, Termination};
use crate::{Error, Result};
use nalgebra::{DMatrix, DVector};

/// The hysteresis alone as an output-error model: input channel 0 is x, output channel 0 is y.
#[derive(Clone, Debug)]
pub struct HysteresisStructure {
    /// 4- or 6-parameter form.
    pub form: ChForm,
    /// The initial output of every experiment.
    pub initial: InitialOutput,
    /// When set, the switching h(t) of every experiment is held at these values instead of
    /// following d (see [`fit_with_switching_updates`]).
    pub switching: Option<Switching>,
}

impl HysteresisStructure {
    fn initial_output(&self, data: &IdData, exp: usize) -> f64 {
        match self.initial {
            InitialOutput::Measured => data.experiment(exp).output(0)[0],
            InitialOutput::Zero => 0.0,
        }
    }
}

impl OutputErrorModel for HysteresisStructure {
    fn parameters(&self) -> ParameterSet {
        let names: Vec<String> = self
            .form
            .parameter_names()
            .iter()
            .map(|s| s.to_string())
            .collect();
        let params = names
            .iter()
            .map(|name| {
                let p = Parameter::new(name.clone(), 1.0);
                if name == "alpha" || name == "d" {
                    p.bounds(f64::MIN_POSITIVE, f64::INFINITY)
                } else {
                    p
                }
            })
            .collect();
        ParameterSet::new(params).expect("names of a ChForm are unique")
    }

    fn n_outputs(&self) -> usize {
        1
    }

    fn simulate(&self, theta: &[f64], data: &IdData, exp: usize, y: &mut [Vec<f64>]) -> Result<()> {
        let ch = ColemanHodgdon::from_params(self.form, theta)?;
        let x = data.experiment(exp).input(0);
        let h = self.switching.as_ref().map(|s| s[exp].as_slice());
        y[0] = simulate_switched(&ch, x, self.initial_output(data, exp), h);
        check_finite(&y[0])
    }

    fn simulate_sensitivities(
        &self,
        theta: &[f64],
        data: &IdData,
        exp: usize,
        free: &[usize],
        sink: &mut SensitivitySink<'_>,
    ) -> Option<Result<()>> {
        let mut row = vec![0.0; free.len()];
        Some(self.sensitivity_pass(theta, data, exp, |t, v, s| {
            for (r, &i) in row.iter_mut().zip(free) {
                *r = s[i];
            }
            // The recursion runs to the end: the sink ignores what follows a Break.
            let _ = sink(t, &[v], &row);
        }))
    }

    /// The rows of [`simulate_sensitivities`](Self::simulate_sensitivities), the same bit
    /// for bit, handed over 512 at a time (the estimator then sums them with its
    /// block kernels instead of row by row).
    fn simulate_sensitivity_blocks(
        &self,
        theta: &[f64],
        data: &IdData,
        exp: usize,
        free: &[usize],
        _threads: usize,
        sink: &mut BlockSink<'_>,
    ) -> Option<Result<()>> {
        let width = 1 + free.len();
        let mut rows = Vec::with_capacity(BLOCK_ROWS * width);
        let mut start = 0;
        let mut hand_over = |start: usize, rows: &mut Vec<f64>| {
            sink(&SensitivityBlock { start, rows, width });
            rows.clear();
        };
        let pass = self.sensitivity_pass(theta, data, exp, |t, v, s| {
            if rows.is_empty() {
                start = t;
            }
            rows.push(v);
            rows.extend(free.iter().map(|&i| s[i]));
            if rows.len() == BLOCK_ROWS * width {
                hand_over(start, &mut rows);
            }
        });
        if !rows.is_empty() {
            hand_over(start, &mut rows);
        }
        Some(pass)
    }
}

impl HysteresisStructure {
    /// The recursion over experiment `exp` with every sensitivity
    /// ([`hysteresis_sensitivities`]), `on_sample(t, v(t), s(t))` for each sample; errors
    /// when θ is no model or the output is not finite (at the first such sample).
    fn sensitivity_pass(
        &self,
        theta: &[f64],
        data: &IdData,
        exp: usize,
        mut on_sample: impl FnMut(usize, f64, &[f64]),
    ) -> Result<()> {
        let ch = ColemanHodgdon::from_params(self.form, theta)?;
        let x = data.experiment(exp).input(0);
        let h = self.switching.as_ref().map(|s| s[exp].as_slice());
        let mut failed = None;
        hysteresis_sensitivities(&ch, x, self.initial_output(data, exp), h, |t, v, s| {
            if !v.is_finite() && failed.is_none() {
                failed = Some(t);
            }
            on_sample(t, v, s);
        });
        match failed {
            None => Ok(()),
            Some(index) => Err(diverged(index)),
        }
    }
}

/// Rows per block of [`HysteresisStructure`]'s sensitivity pass.
const BLOCK_ROWS: usize = 512;

/// Runs the hysteresis recursion and its parameter sensitivities s(t) = ∂v(t)/∂θ together,
/// calling `on_sample(t, v(t), s(t))` for every sample. s(0) = 0 (v(0) does not depend on θ).
///
/// s(t) = (1 − α|Δx|)·s(t−1) + ∂(D)/∂θ with the switching held fixed inside each piece
/// (see [`ColemanHodgdon::step_partials`]); `h` holds the switching fixed when given.
pub fn hysteresis_sensitivities(
    ch: &ColemanHodgdon,
    x: &[f64],
    v0: f64,
    h: Option<&[bool]>,
    on_sample: impl FnMut(usize, f64, &[f64]),
) {
    match ch.form() {
        ChForm::Saturated4 => sensitivities_of::<4>(ch, x, v0, h, on_sample),
        ChForm::General6 => sensitivities_of::<6>(ch, x, v0, h, on_sample),
    }
}

/// [`hysteresis_sensitivities`] for a form of `N` parameters: s(t) and the step's partials
/// in fixed-size arrays, which the recursion keeps in registers instead of a store and a
/// load per sample on its chain.
fn sensitivities_of<const N: usize>(
    ch: &ColemanHodgdon,
    x: &[f64],
    v0: f64,
    h: Option<&[bool]>,
    mut on_sample: impl FnMut(usize, f64, &[f64]),
) {
    let mut s = [0.0; N];
    let mut partial = [0.0; N];
    let mut v = v0;
    if x.is_empty() {
        return;
    }
    on_sample(0, v, &s);
    for t in 1..x.len() {
        let outside = ch.outside_at(x, t, h);
        let factor = ch.step_partials_in(v, x[t - 1], x[t], outside, &mut partial);
        v = ch.step_in(v, x[t - 1], x[t], outside);
        for (sk, pk) in s.iter_mut().zip(&partial) {
            *sk = factor * *sk + pk;
        }
        on_sample(t, v, &s);
    }
}

/// The bounds the data put on a hysteresis parameter: α in (0, 1/max|Δx|] (the rate limit
/// of (D)) and d in [10⁻⁹·max|x|, max|x|] (beyond the input range no sample ever switches, so
/// the data say nothing about d); other parameters are free.
pub(crate) fn bounded_parameter(name: &str, value: f64, data: &IdData) -> Parameter {
    let p = Parameter::new(name, value);
    match name {
        "alpha" => p.bounds(f64::MIN_POSITIVE, alpha_max(data)),
        "d" => {
            let max_x = max_abs_input(data);
            p.bounds(1e-9 * max_x, max_x)
        }
        _ => p,
    }
}

/// The hysteresis parameters `values` with the bounds of [`bounded_parameter`].
pub(crate) fn bounded_hysteresis_parameters(
    form: ChForm,
    values: &[f64],
    data: &IdData,
) -> ParameterSet {
    let params = form
        .parameter_names()
        .iter()
        .zip(values)
        .map(|(&name, &value)| bounded_parameter(name, value, data))
        .collect();
    ParameterSet::new(params).expect("names of a ChForm are unique")
}

pub(crate) fn check_finite(y: &[f64]) -> Result<()> {
    match y.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(index) => Err(diverged(index)),
    }
}

fn diverged(index: usize) -> Error {
    Error::Diverged {
        index,
        reason: "the simulated output is not finite".into(),
    }
}

/// The largest admissible α: (1 − 10⁻⁹)/max|Δx|, inside the rate limit α·|Δx(t)| < 1 of the
/// discrete recursion with a margin for rounding, so an estimate on the bound is valid.
pub(crate) fn alpha_max(data: &IdData) -> f64 {
    (1.0 - 1e-9) / max_increment(data)
}

/// Largest |Δx| over all experiments' input channel 0.
pub(crate) fn max_increment(data: &IdData) -> f64 {
    data.experiments()
        .iter()
        .map(|e| {
            let x = e.input(0);
            let n = x.len().saturating_sub(1);
            metrics::largest(&x[x.len() - n..], &x[..n], |a, b| (a - b).abs())
        })
        .fold(0.0, f64::max)
}

/// Largest |x| over all experiments' input channel 0.
pub(crate) fn max_abs_input(data: &IdData) -> f64 {
    data.experiments()
        .iter()
        .map(|e| metrics::max_abs(e.input(0)))
        .fold(0.0, f64::max)
}

/// Result of the separated regression.
#[derive(Clone, Debug)]
pub struct SeparatedFit {
    /// The hysteresis recovered from the separated parameters.
    pub model: ColemanHodgdon,
    /// The last least-squares solution (separated parameters, their covariance).
    pub ls: LsSolution,
    /// d̂ after each re-estimation of the switching function (the first is the profile's).
    pub d_history: Vec<f64>,
    /// Why the switching re-estimation stopped.
    pub termination: Termination,
}

/// The complete hysteresis-alone identification.
#[derive(Clone, Debug)]
pub struct HysteresisFit {
    /// Steps 1–2: profile and separated regression.
    pub separated: SeparatedFit,
    /// Step 3: the output-error refinement (estimate, standard deviations, report).
    pub output_error: OutputErrorFit,
    /// What the data say about the threshold d; the reported d is its mean.
    pub threshold: ThresholdPosterior,
    /// The final model.
    pub model: ColemanHodgdon,
    /// Wall-clock time.
    pub elapsed_s: f64,
}

impl HysteresisFit {
    /// Reported standard deviations ([`ChForm::parameter_names`] order): asymptotic, with
    /// the truncated-normal one for d (see [`super::switching`]).
    pub fn std(&self) -> Vec<f64> {
        let mut std = self.output_error.std().to_vec();
        let d = std.len() - 1;
        std[d] = self.threshold.std;
        std
    }
}

/// Settings of the hysteresis-alone identification.
#[derive(Clone, Debug)]
pub struct HysteresisIdentification {
    /// 4- or 6-parameter form.
    pub form: ChForm,
    /// The initial output of the simulated hysteresis.
    pub initial: InitialOutput,
    /// Grid points of the d profile.
    pub profile_points: usize,
    /// Maximum re-estimations of the switching function.
    pub max_switching_iterations: usize,
    /// Intervals of d tried on each side of d̂ (see [`switching`](super::switching)).
    pub scan: usize,
    /// Output-error settings.
    pub lm: LmConfig,
    /// ch6 only: start the output-error fit from the nested ch4 fit (m2 = c2 = 0) when its
    /// simulated squared error is below the separated regression's
    /// ([`HysteresisIdentification::better_start`]). Off in the published recipe
    /// ([`HysteresisIdentification::new`]); on in the hysteresis zoo's `ch6` family.
    pub nested_start: bool,
}

impl HysteresisIdentification {
    /// Defaults: 60-point d profile, 50 switching iterations, tight LM tolerances.
    pub fn new(form: ChForm) -> Self {
        Self {
            form,
            initial: InitialOutput::Measured,
            profile_points: 60,
            max_switching_iterations: 50,
            scan: 6,
            // The published figures of the hysteresis fits come from the improvement rule.
            lm: LmConfig::improvement_rule(),
            nested_start: false,
        }
    }

    /// The start of the ch6 output-error fit: `separated` (the separated regression's
    /// parameters) or the nested ch4 fit's (α, m1, 0, c1, 0, d), whichever simulates the
    /// record with the smaller squared error. ch4 is ch6 with m2 = c2 = 0, so the fit then
    /// starts no worse than the smaller model ends: on records far from the piecewise-linear
    /// material functions (a piezo stack's loop) the separated regression's equation error
    /// can start the search in a valley where α → 0 and m1, m2 → ∞, which it then creeps
    /// along to the iteration limit. A failed ch4 fit keeps `separated`.
    pub fn better_start(&self, data: &IdData, separated: Vec<f64>) -> Vec<f64> {
        let smaller = HysteresisIdentification {
            form: ChForm::Saturated4,
            nested_start: false,
            ..self.clone()
        };
        let Ok(nested) = smaller.estimate(data, &mut |_| Control::Continue) else {
            return separated;
        };
        let p = nested.model.params();
        let candidate = vec![p[0], p[1], 0.0, p[2], 0.0, p[3]];
        let model = HysteresisStructure {
            form: self.form,
            initial: self.initial,
            switching: None,
        };
        match (
            true_cost(&model, data, &separated),
            true_cost(&model, data, &candidate),
        ) {
            (Ok(a), Ok(b)) if b < a => candidate,
            (Err(_), Ok(_)) => candidate,
            _ => separated,
        }
    }

    /// Identifies the hysteresis from input channel 0 (x) and output channel 0 (y) of `data`.
    pub fn estimate(
        &self,
        data: &IdData,
        callback: &mut dyn FnMut(&IterationRecord) -> Control,
    ) -> Result<HysteresisFit> {
        let clock = std::time::Instant::now();
        check_excitation(data, self.form.n_params())?;
        let separated = self.separated_regression(data)?;
        let structure = |switching| HysteresisStructure {
            form: self.form,
            initial: self.initial,
            switching,
        };
        let alpha_max = alpha_max(data);
        let mut start = separated.model.params();
        start[0] = start[0].min(alpha_max);
        if self.nested_start && self.form == ChForm::General6 {
            start = self.better_start(data, start);
        }
        let mut params = bounded_hysteresis_parameters(self.form, &start, data);
        for k in 0..params.len() {
            let p = params.get_mut(k);
            p.value = p.value.clamp(p.min, p.max);
        }
        let estimator = OutputError {
            config: self.lm.clone(),
            ..OutputError::default()
        };
        let switched =
            fit_with_switching_updates(&structure, data, &params, &estimator, self.scan, callback)?;
        let d_index = self.form.n_params() - 1;
        let (output_error, threshold) = place_threshold(&structure, data, switched.fit, d_index)?;
        let model = ColemanHodgdon::from_params(self.form, &output_error.parameters.values())?;
        if !(model.alpha() > 0.0 && model.alpha() <= alpha_max) {
            return Err(rate_error(data, model.alpha()));
        }
        Ok(HysteresisFit {
            separated,
            output_error,
            threshold,
            model,
            elapsed_s: clock.elapsed().as_secs_f64(),
        })
    }

    /// Steps 1–2: the d profile, then the separated regression with the switching function
    /// re-estimated until d̂ settles.
    pub fn separated_regression(&self, data: &IdData) -> Result<SeparatedFit> {
        let (d0, profile) = self.profile_d(data)?;
        let mut d = d0;
        let mut d_history = vec![d0];
        let mut best: Option<(ColemanHodgdon, LsSolution)> = None;
        let mut termination = Termination::MaxIterations;
        let d_max = max_abs_input(data);
        for _ in 0..self.max_switching_iterations {
            let (phi, dy) = separated_rows(data, self.form, d);
            // Few samples beyond d can leave the free form's outer columns dependent where
            // the profile's tied ones are not: the profile's solution then stands.
            let ls = match least_squares(&phi, &dy, self.form_regressor_names()) {
                Ok(ls) => ls,
                Err(e) => {
                    termination = Termination::Diverged {
                        reason: e.to_string(),
                    };
                    break;
                }
            };
            let theta: Vec<f64> = ls.theta.iter().copied().collect();
            let model = match ColemanHodgdon::from_separated(self.form, &theta) {
                Ok(m) if m.d() < d_max => m,
                Ok(m) => {
                    termination = Termination::Diverged {
                        reason: format!("d = {} left the input range (max |x| = {d_max})", m.d()),
                    };
                    break;
                }
                Err(e) => {
                    termination = Termination::Diverged {
                        reason: e.to_string(),
                    };
                    break;
                }
            };
            let change = (model.d() - d).abs() / d;
            d = model.d();
            d_history.push(d);
            best = Some((model, ls));
            if change < 1e-10 || same_switching(data, d, d_history[d_history.len() - 2]) {
                termination = Termination::Converged { change };
                break;
            }
        }
        let (model, ls) = match best {
            Some(b) if termination.converged() => b,
            // The re-estimation wandered off: keep the profile's constrained solution.
            _ => {
                let (model, ls, _) = constrained_fit(data, self.form, d0, profile)?;
                (model, ls)
            }
        };
        Ok(SeparatedFit {
            model,
            ls,
            d_history,
            termination,
        })
    }

    fn form_regressor_names(&self) -> &'static [&'static str] {
        match self.form {
            ChForm::Saturated4 => &["|dx|x(1-h)", "|dx|sgn(x)h", "-|dx|y", "(1-h)dx"],
            ChForm::General6 => &[
                "|dx|x(1-h)",
                "|dx|x h",
                "|dx|sgn(x)h",
                "-|dx|y",
                "(1-h)dx",
                "h dx",
            ],
        }
    }

    /// The d with the smallest equation error of the constrained regression: a grid over
    /// (0, max|x|) refined by golden-section search around the best grid point.
    ///
    /// Tries the [`Profile`]s in order (plain least squares, trimmed, trimmed with α held)
    /// and keeps the first for which some grid point gives a model (α̂ > 0); returns d̂ and
    /// that profile. See the module docs, step 1.
    fn profile_d(&self, data: &IdData) -> Result<(f64, Profile)> {
        let d_max = max_abs_input(data);
        let n = self.profile_points.max(5);
        let grid: Vec<f64> = (1..=n).map(|i| d_max * i as f64 / (n + 1) as f64).collect();
        let step = d_max / (n + 1) as f64;
        let profiles = [
            Profile::Plain,
            Profile::Trimmed { alpha: None },
            Profile::Trimmed {
                alpha: Some(held_alpha(data)),
            },
        ];
        for profile in profiles {
            let cost = |d: f64| constrained_cost(data, self.form, d, profile);
            let costs: Vec<f64> = grid.iter().map(|&d| cost(d)).collect();
            let (best, &best_cost) = costs
                .iter()
                .enumerate()
                .min_by(|a, b| a.1.total_cmp(b.1))
                .expect("grid is not empty");
            if best_cost.is_finite() {
                let d = golden_section(cost, grid[best] - step, grid[best] + step, 40);
                return Ok((d, profile));
            }
        }
        Err(Error::Singular(
            "no threshold d gives a solvable regression with α > 0; the input does not excite the hysteresis"
                .into(),
        ))
    }
}

/// Errors unless every experiment's input moves and the data hold enough samples.
pub(crate) fn check_excitation(data: &IdData, n_params: usize) -> Result<()> {
    let name = data
        .input_channels()
        .first()
        .map_or("x".to_string(), |c| c.name.clone());
    if max_increment(data) == 0.0 {
        return Err(Error::NotExciting {
            channel: name,
            reason: "it is constant, so the hysteresis never moves; drive it with periodic signals of several amplitudes".into(),
        });
    }
    let needed = 3 * n_params + 10;
    if data.n_samples() < needed {
        return Err(Error::TooFewSamples {
            samples: data.n_samples(),
            parameters: n_params,
            needed,
        });
    }
    Ok(())
}

pub(crate) fn rate_error(data: &IdData, alpha: f64) -> Error {
    let (index, dx) = data.experiments()[0]
        .input(0)
        .windows(2)
        .enumerate()
        .map(|(t, w)| (t + 1, w[1] - w[0]))
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .unwrap_or((0, 0.0));
    Error::RateLimit {
        index,
        alpha,
        dx,
        product: alpha * dx.abs(),
    }
}

/// True when thresholds `a` and `b` give the same switching function on every sample.
fn same_switching(data: &IdData, a: f64, b: f64) -> bool {
    data.experiments().iter().all(|e| {
        e.input(0)
            .iter()
            .all(|&x| switching(x, a) == switching(x, b))
    })
}

/// Rows of the free separated regression Δy(t) = φ_h(t)ᵀθ_h for threshold `d`.
fn separated_rows(data: &IdData, form: ChForm, d: f64) -> (DMatrix<f64>, Vec<f64>) {
    regression_rows(data, form, d, form.n_params(), |full, dy, row| {
        row.copy_from_slice(full);
        dy
    })
}

/// The rows of a regression at threshold `d`, one per sample t ≥ 1 of every experiment:
/// `make(φ_h(t), Δy(t), row)` writes the row's `columns` regressors from the free separated
/// ones and returns its target.
fn regression_rows(
    data: &IdData,
    form: ChForm,
    d: f64,
    columns: usize,
    make: impl Fn(&[f64], f64, &mut [f64]) -> f64,
) -> (DMatrix<f64>, Vec<f64>) {
    let rows = data.experiments().iter().map(|e| e.len() - 1).sum();
    let mut phi = DMatrix::zeros(rows, columns);
    let mut dy = Vec::with_capacity(rows);
    let mut full = vec![0.0; form.n_params()];
    let mut row = vec![0.0; columns];
    for e in data.experiments() {
        let (x, y) = (e.input(0), e.output(0));
        for t in 1..x.len() {
            ColemanHodgdon::separated_regressor(form, d, x[t - 1], x[t], y[t - 1], &mut full);
            let r = dy.len();
            dy.push(make(&full, y[t] - y[t - 1], &mut row));
            for (k, v) in row.iter().enumerate() {
                phi[(r, k)] = *v;
            }
        }
    }
    (phi, dy)
}

/// How the constrained regression of the d profile is solved (module docs, step 1).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Profile {
    /// Least squares on every row; the cost is the residual sum of squares.
    Plain,
    /// Least squares on the rows whose residual is within [`TRIM`] robust standard
    /// deviations, the cost a truncated quadratic; α held at `alpha` when given.
    Trimmed { alpha: Option<f64> },
}

impl Profile {
    /// The α the regression is held at, if any.
    fn held_alpha(self) -> Option<f64> {
        match self {
            Profile::Trimmed { alpha } => alpha,
            Profile::Plain => None,
        }
    }
}

/// Rows whose equation error exceeds TRIM·σ̂ (σ̂ = 1.4826·median|r|) leave the trimmed fit.
const TRIM: f64 = 5.0;

/// The α at which the trimmed profile is held when even the trimmed regression gives α̂ ≤ 0
/// for every d: 1/max|x| (the gap to f closes over about one input amplitude of travel), at
/// most [`alpha_max`]. It scales as α does when x changes units.
fn held_alpha(data: &IdData) -> f64 {
    (1.0 / max_abs_input(data)).min(alpha_max(data))
}

/// The regression with θ3 tied to d (see the module docs), solved as `profile` says;
/// returns the model, the fit and the profile cost. Errors when the least squares fail or
/// the estimate is no model (α̂ ≤ 0).
///
/// With α held, its column −|Δx|y(t−1) moves to the left side,
/// Δy + α|Δx|y(t−1) = αm1·(…) + αm2·(…) + c1(1−h)Δx + c2·hΔx.
fn constrained_fit(
    data: &IdData,
    form: ChForm,
    d: f64,
    profile: Profile,
) -> Result<(ColemanHodgdon, LsSolution, f64)> {
    let (phi, dy) = constrained_rows(data, form, d, profile.held_alpha());
    let (ls, cost) = match profile {
        Profile::Plain => {
            let ls = least_squares(&phi, &dy, &[])?;
            let cost = ls.residual_ss;
            (ls, cost)
        }
        Profile::Trimmed { .. } => trimmed(&phi, &dy, |phi, dy| {
            let ls = least_squares(phi, dy, &[])?;
            let theta = ls.theta.clone();
            Ok((ls, theta))
        })?,
    };
    let model = constrained_model(form, d, ls.theta.as_slice(), profile.held_alpha())?;
    Ok((model, ls, cost))
}

/// The cost of [`constrained_fit`] at d, +∞ where it errors: what the d profile minimises.
/// θ̂ comes from the streamed QR of [Φ Δy] (`least_squares_estimate`: no covariance, the
/// estimate to rounding), the cost as `constrained_fit` forms it.
fn constrained_cost(data: &IdData, form: ChForm, d: f64, profile: Profile) -> f64 {
    let held = profile.held_alpha();
    let (phi, dy) = constrained_rows(data, form, d, held);
    let solved = match profile {
        Profile::Plain => least_squares_estimate(&phi, &dy, &[]),
        Profile::Trimmed { .. } => trimmed(&phi, &dy, |phi, dy| {
            let (theta, _) = least_squares_estimate(phi, dy, &[])?;
            Ok((theta.clone(), theta))
        }),
    };
    match solved {
        Ok((theta, cost)) if constrained_model(form, d, theta.as_slice(), held).is_ok() => cost,
        _ => f64::INFINITY,
    }
}

/// The rows of the constrained regression at d: the columns that tie θ3 = (θ1 − θ2)·d
/// (ch6) or θ2 = θ1·d (ch4), without the α column when α is held at `held` (its term then
/// moves to the left side).
fn constrained_rows(
    data: &IdData,
    form: ChForm,
    d: f64,
    held: Option<f64>,
) -> (DMatrix<f64>, Vec<f64>) {
    let alpha = alpha_column(form);
    let columns = form.n_params() - 1 - usize::from(held.is_some());
    regression_rows(data, form, d, columns, |full, dy, row| {
        let mut tied = [0.0; 5];
        let tied = &mut tied[..form.n_params() - 1];
        match form {
            ChForm::General6 => {
                tied[0] = full[0] + d * full[2];
                tied[1] = full[1] - d * full[2];
                tied[2..].copy_from_slice(&full[3..]);
            }
            ChForm::Saturated4 => {
                tied[0] = full[0] + d * full[1];
                tied[1..].copy_from_slice(&full[2..]);
            }
        }
        // the tied α column is alpha − 1 (θ3 left the free form's list before it)
        let kept = tied
            .iter()
            .enumerate()
            .filter(|&(k, _)| held.is_none() || k != alpha - 1);
        for (cell, (_, v)) in row.iter_mut().zip(kept) {
            *cell = *v;
        }
        match held {
            Some(a) => dy - a * full[alpha],
            None => dy,
        }
    })
}

/// The column of α (−|Δx|y(t−1)) in the free separated regression.
fn alpha_column(form: ChForm) -> usize {
    match form {
        ChForm::General6 => 3,
        ChForm::Saturated4 => 2,
    }
}

/// The model of the constrained regression's estimate `theta` at d (α re-inserted when
/// held); errors when it is no model (α̂ ≤ 0).
fn constrained_model(
    form: ChForm,
    d: f64,
    theta: &[f64],
    held: Option<f64>,
) -> Result<ColemanHodgdon> {
    let mut t = theta.to_vec();
    if let Some(a) = held {
        t.insert(alpha_column(form) - 1, a);
    }
    match form {
        ChForm::General6 => ColemanHodgdon::general(t[2], t[0] / t[2], t[1] / t[2], t[3], t[4], d),
        ChForm::Saturated4 => ColemanHodgdon::saturated(t[1], t[0] / t[1], t[2], d),
    }
}

/// Least squares refitted on the rows with |r| ≤ [`TRIM`]·σ̂ until the kept rows settle (at
/// most 5 refits), σ̂ = 1.4826·median|r| of the current fit over every row, each fit by
/// `solve` (which returns its solution and θ̂). Returns the last solution and the truncated
/// quadratic Σ min(r², (TRIM·σ̂)²) over every row.
fn trimmed<S>(
    phi: &DMatrix<f64>,
    dy: &[f64],
    solve: impl Fn(&DMatrix<f64>, &[f64]) -> Result<(S, DVector<f64>)>,
) -> Result<(S, f64)> {
    let mut keep = vec![true; dy.len()];
    let (mut solution, mut theta) = solve(phi, dy)?;
    let mut refits = 0;
    loop {
        let r: Vec<f64> = (phi * &theta).iter().zip(dy).map(|(p, y)| y - p).collect();
        // the upper median |r|, the element a sort would put at len/2
        let mut abs: Vec<f64> = r.iter().map(|v| v.abs()).collect();
        let middle = abs.len() / 2;
        let (_, &mut median, _) = abs.select_nth_unstable_by(middle, f64::total_cmp);
        let limit = TRIM * 1.4826 * median;
        let next: Vec<bool> = r.iter().map(|v| v.abs() <= limit).collect();
        if limit == 0.0 || next == keep || refits == 5 {
            let cost = r.iter().map(|v| (v * v).min(limit * limit)).sum();
            return Ok((solution, cost));
        }
        keep = next;
        let rows: Vec<usize> = (0..dy.len()).filter(|&i| keep[i]).collect();
        let sub = DMatrix::from_fn(rows.len(), phi.ncols(), |i, j| phi[(rows[i], j)]);
        let sub_dy: Vec<f64> = rows.iter().map(|&i| dy[i]).collect();
        (solution, theta) = solve(&sub, &sub_dy)?;
        refits += 1;
    }
}

/// Golden-section search for a minimum of `f` on [a, b] (`iterations` shrinkings).
pub(crate) fn golden_section(
    f: impl Fn(f64) -> f64,
    mut a: f64,
    mut b: f64,
    iterations: usize,
) -> f64 {
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - r * (b - a);
    let mut d = a + r * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..iterations {
        if fc <= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - r * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + r * (b - a);
            fd = f(d);
        }
    }
    if fc <= fd {
        c
    } else {
        d
    }
}
