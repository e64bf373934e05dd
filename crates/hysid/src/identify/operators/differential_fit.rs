//! The part common to the fits of the differential operators: checks of the data, the
//! output-error least-squares problem, the multi-start Levenberg–Marquardt search and the
//! [`OperatorFit`] report.
//!
//! The criterion is V(θ) = Σ_t (y_t − Γ_θ\[u\]_t)², the simulated (output-error) residual,
//! minimised by the bounded Levenberg–Marquardt engine
//! ([`crate::numerics::levenberg_marquardt`]) with forward finite-difference sensitivities of
//! the H/u-integration, from each start of a small multi-start; the start with the lowest V
//! wins. Standard deviations are σ²(JᵀJ)⁻¹ at the optimum (Ljung 1999, §9.3).

use super::OperatorFit;
use crate::model::operators::differential::check_signal;
use crate::model::operators::HysteresisOperator;
use crate::model::ParameterSet;
use crate::numerics::levenberg_marquardt::{minimize, LeastSquaresProblem, LmConfig, LmReport};
use crate::numerics::metrics;
use crate::numerics::Observer;
use crate::{Error, Result};
use std::time::Instant;

/// Number of direction reversals of `u` (sign changes of the non-zero increments).
pub fn reversals(u: &[f64]) -> usize {
    let mut last = 0.0;
    let mut count = 0;
    for w in u.windows(2) {
        let d = (w[1] - w[0]).signum();
        if w[1] == w[0] {
            continue;
        }
        if last != 0.0 && d != last {
            count += 1;
        }
        last = d;
    }
    count
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
    if reversals(u) < 1 {
        return Err(Error::NotExciting {
            channel: "input".into(),
            reason: format!(
                "it never reverses direction; a {family} fit needs an ascending and a \
                 descending branch (at least one reversal)"
            ),
        });
    }
    if !crate::data::varies(y) {
        return Err(Error::InvalidData(format!(
            "{family}: the output is constant; there is no loop to fit"
        )));
    }
    Ok(())
}

/// The output-error problem r(θ) = y − ŷ(θ) for a simulator θ ↦ ŷ.
pub struct Simulated<'a> {
    /// The measured output.
    pub y: &'a [f64],
    /// The simulator: full parameter vector to simulated output.
    pub simulate: &'a (dyn Fn(&[f64]) -> Result<Vec<f64>> + Sync),
    /// Number of parameters.
    pub n_params: usize,
}

impl LeastSquaresProblem for Simulated<'_> {
    fn n_params(&self) -> usize {
        self.n_params
    }
    fn n_residuals(&self) -> usize {
        self.y.len()
    }
    fn residuals(&self, theta: &[f64], r: &mut [f64]) -> Result<()> {
        let yhat = (self.simulate)(theta)?;
        for ((r, y), yh) in r.iter_mut().zip(self.y).zip(&yhat) {
            *r = y - yh;
        }
        Ok(())
    }
    fn cost_floor(&self) -> f64 {
        // The integration is accurate to ~1e-10 of the signal's scale: residuals below
        // 1e-9 of the output's spread are an exact fit.
        let s = 1e-9 * metrics::std_dev(self.y);
        self.y.len() as f64 * s * s
    }
}

/// The search box and the free parameters.
pub struct Search {
    /// Indices of the estimated parameters.
    pub free: Vec<usize>,
    /// Lower bounds (full vector).
    pub lower: Vec<f64>,
    /// Upper bounds (full vector).
    pub upper: Vec<f64>,
    /// Levenberg–Marquardt settings.
    pub config: LmConfig,
    /// Sees "start k/N" after every start and "iteration k/max" after every accepted
    /// iteration; its [`Control::Stop`](crate::numerics::Control::Stop) ends the search with
    /// the best start so far (how a time limit is honoured).
    pub observer: Observer,
}

/// The default engine settings of these fits: 200 iterations, tight tolerances.
pub fn default_config() -> LmConfig {
    LmConfig {
        max_iterations: 200,
        improvement_tolerance: 1e-12,
        ..LmConfig::default()
    }
}

/// The outcome of a multi-start search.
pub struct Searched {
    /// The report of the start with the lowest cost.
    pub best: LmReport,
    /// Iterations of all starts together.
    pub iterations: usize,
    /// Criterion evaluations of all starts together.
    pub evaluations: usize,
}

/// Runs the search from every start and keeps the lowest cost; errors only when no start can
/// be simulated.
pub fn best_of(problem: &Simulated<'_>, starts: &[Vec<f64>], search: &Search) -> Result<Searched> {
    let mut best: Option<LmReport> = None;
    let (mut iterations, mut evaluations) = (0, 0);
    let mut first_error = None;
    for (k, start) in starts.iter().enumerate() {
        if k > 0 && search.observer.should_stop("start") {
            break;
        }
        let theta: Vec<f64> = start
            .iter()
            .zip(search.lower.iter().zip(&search.upper))
            .map(|(v, (lo, hi))| v.clamp(*lo, *hi))
            .collect();
        match minimize(
            problem,
            &theta,
            &search.free,
            &search.lower,
            &search.upper,
            &search.config,
            &mut |r| {
                search
                    .observer
                    .report("iteration", r.iteration, search.config.max_iterations)
            },
        ) {
            Ok(report) => {
                iterations += report.iterations;
                evaluations += report.function_evaluations;
                let exact = report.termination == crate::numerics::Termination::ZeroResidual;
                if best.as_ref().is_none_or(|b| report.cost < b.cost) {
                    best = Some(report);
                }
                if exact {
                    // An exact fit cannot be improved on by the other starts.
                    break;
                }
            }
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
        search.observer.report("start", k + 1, starts.len());
    }
    let best = best.ok_or_else(|| {
        first_error
            .unwrap_or_else(|| Error::invalid_option("starts", 0, "no start for the search".into()))
    })?;
    Ok(Searched {
        best,
        iterations,
        evaluations,
    })
}

/// The [`OperatorFit`] of `model` (already holding the estimate) on (u, y).
pub fn report<M: HysteresisOperator>(
    model: M,
    u: &[f64],
    y: &[f64],
    searched: &Searched,
    started: Instant,
) -> Result<OperatorFit<M>> {
    let best = &searched.best;
    let simulated = model.simulate(u)?;
    let parameters: ParameterSet = model.parameters();
    let cov = best.covariance();
    let std = (0..parameters.len())
        .map(|i| {
            let s = cov.std[i];
            (best.free.contains(&i) && s.is_finite()).then_some(s)
        })
        .collect();
    let n = y.len();
    let p = best.free.len();
    let loss = metrics::mse(y, &simulated);
    Ok(OperatorFit {
        model,
        parameters,
        std,
        fit_percent: metrics::fit_percent(y, &simulated),
        rmse: loss.sqrt(),
        loss,
        fpe: metrics::fpe(loss, n, p),
        aic: metrics::aic(loss, n, p),
        simulated,
        iterations: searched.iterations,
        evaluations: searched.evaluations,
        termination: best.termination.clone(),
        elapsed_s: started.elapsed().as_secs_f64(),
    })
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
