//! The switching function h as an internal variable of output-error fits.
//!
//! # Why
//!
//! In the discrete Coleman–Hodgdon recursion the material function g takes the value c1 or c2
//! according to h(t) = (|x(t)| > d). The simulated output therefore jumps whenever d crosses a
//! sample's |x(t)|: the output-error criterion is a fine staircase in d, smooth only inside
//! each interval between consecutive sample magnitudes. A Gauss–Newton step judged on jumps
//! its linear model cannot see stalls. Two measures make the fit reach the true minimum:
//!
//! 1. **Fixed point on h** (the internal-variable idea of Vörös 2015 applied to the output
//!    error): hold h fixed, which makes the criterion smooth (d still moves the outer segment
//!    of f), fit, re-classify the samples with the new d̂, repeat until the classification
//!    no longer changes. A cycle, or a re-classification that does not lower the true
//!    criterion, ends the loop with the best classification by the true criterion.
//! 2. **Interval scan**: the criterion restricted to one interval of d is smooth and equals
//!    the frozen-h criterion there, so fitting with d bounded to each of a set of intervals
//!    around d̂ (a coarse pass over d̂ ± 3s, then every neighbour of the best) and keeping the
//!    best minimises the true, discontinuous criterion locally (the fits of one pass are
//!    independent and run in parallel; their results are kept in the pass's order). On
//!    noise-free data only the true interval fits exactly, which is what recovers every
//!    parameter to working precision.

use super::output_error::{FitStart, OutputError, OutputErrorFit, OutputErrorModel};
use crate::data::IdData;
use crate::model::ParameterSet;
use crate::numerics::levenberg_marquardt::{Control, IterationRecord, LmReport};
use crate::Result;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::sync::Mutex;

/// The switching h(t) = (|x(t)| > d) of every experiment, held fixed during a fit.
pub type Switching = Vec<Vec<bool>>;

/// The switching of every experiment's input channel 0 for threshold `d`.
pub fn classify(data: &IdData, d: f64) -> Switching {
    data.experiments()
        .iter()
        .map(|e| e.input(0).iter().map(|x| x.abs() > d).collect())
        .collect()
}

/// What the data say about the threshold d (see the module docs).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ThresholdPosterior {
    /// Lower end of the switching interval that contains d̂ (the largest sample magnitude ≤ d̂).
    pub lower: f64,
    /// Upper end (the smallest sample magnitude > d̂; +∞ above all samples).
    pub upper: f64,
    /// The asymptotic standard deviation s of the smooth part.
    pub smooth_std: f64,
    /// Mean of N(d̂, s²) truncated to [lower, upper).
    pub mean: f64,
    /// Standard deviation of that truncated normal.
    pub std: f64,
}

/// The truncated-normal description of d (see the module docs) for the estimate `d_hat` with
/// smooth standard deviation `smooth_std`.
pub fn threshold_posterior(data: &IdData, d_hat: f64, smooth_std: f64) -> ThresholdPosterior {
    // The neighbouring magnitudes by one pass (no sort: records can be long), in eight
    // lanes (a maximum and a minimum do not depend on the order).
    let (mut lower, mut upper) = ([0.0f64; 8], [f64::INFINITY; 8]);
    for e in data.experiments() {
        let x = e.input(0).get(1..).unwrap_or_default();
        let chunks = x.chunks_exact(8);
        for (i, v) in chunks.remainder().iter().enumerate() {
            neighbours(v.abs(), d_hat, &mut lower[i], &mut upper[i]);
        }
        for chunk in chunks {
            for ((v, lower), upper) in chunk.iter().zip(&mut lower).zip(&mut upper) {
                neighbours(v.abs(), d_hat, lower, upper);
            }
        }
    }
    let lower = lower.into_iter().fold(0.0, f64::max);
    let upper = upper.into_iter().fold(f64::INFINITY, f64::min);
    let (mean, std) = truncated_normal(d_hat, smooth_std, lower, upper);
    ThresholdPosterior {
        lower,
        upper,
        smooth_std,
        mean,
        std,
    }
}

/// Widens `lower` (the largest magnitude ≤ d̂) or narrows `upper` (the smallest one above) by
/// the magnitude `m`; a NaN changes neither.
#[inline(always)]
fn neighbours(m: f64, d_hat: f64, lower: &mut f64, upper: &mut f64) {
    if m <= d_hat {
        if m > *lower {
            *lower = m;
        }
    } else if m < *upper {
        *upper = m;
    }
}

/// Moves d to the mean of its [`threshold_posterior`] and the other free parameters to their
/// conditional optimum for that d (−H_oo⁻¹H_od·Δd with H = JᵀJ, exact for the locally
/// quadratic smooth part), each kept within its bounds; one simulation refreshes the fit
/// statistics, the covariance is kept (a moved point that cannot be simulated keeps the fit
/// unmoved). `d_index` is the position of d in the parameter vector.
pub fn place_threshold<M: OutputErrorModel>(
    make: &dyn Fn(Option<Switching>) -> M,
    data: &IdData,
    fit: OutputErrorFit,
    d_index: usize,
) -> Result<(OutputErrorFit, ThresholdPosterior)> {
    let d_hat = fit.parameters.get(d_index).value;
    let threshold = threshold_posterior(data, d_hat, fit.std()[d_index]);
    if threshold.mean == d_hat {
        return Ok((fit, threshold));
    }
    let mut theta = fit.parameters.values();
    for (i, delta) in conditional_shift(&fit.report, d_index, threshold.mean - d_hat) {
        // the quadratic model knows nothing of the bounds (α > 0 near 0 on a slow record)
        let p = fit.parameters.get(i);
        theta[i] = (theta[i] + delta).clamp(p.min, p.max);
    }
    theta[d_index] = threshold.mean;
    // A moved point the model cannot simulate leaves the fit where it is: d̂ is then its
    // own estimate, beside the posterior mean reported.
    match fit
        .clone()
        .at(&make(Some(classify(data, threshold.mean))), data, &theta)
    {
        Ok(moved) => Ok((moved, threshold)),
        Err(_) => Ok((fit, threshold)),
    }
}

/// The change of the other free parameters that keeps the quadratic model of the criterion
/// at its conditional minimum when parameter `fixed` moves by `delta`: −H_oo⁻¹H_od·delta.
fn conditional_shift(report: &LmReport, fixed: usize, delta: f64) -> Vec<(usize, f64)> {
    let Some(kd) = report.free.iter().position(|&i| i == fixed) else {
        return Vec::new();
    };
    let others: Vec<usize> = (0..report.free.len()).filter(|&k| k != kd).collect();
    let h = &report.jtj;
    let h_oo = DMatrix::from_fn(others.len(), others.len(), |r, c| h[(others[r], others[c])]);
    let h_od = DVector::from_fn(others.len(), |r, _| h[(others[r], kd)]);
    match h_oo.cholesky() {
        Some(chol) => {
            let step = chol.solve(&h_od) * (-delta);
            others
                .iter()
                .zip(step.iter())
                .map(|(&k, &s)| (report.free[k], s))
                .collect()
        }
        None => Vec::new(),
    }
}

/// Mean and standard deviation of N(μ, s²) truncated to [a, b].
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn truncated_normal(mu: f64, s: f64, a: f64, b: f64) -> (f64, f64) {
    if s.is_nan() || s <= 0.0 || !s.is_finite() {
        return (mu.clamp(a, b), 0.0);
    }
    if b.is_finite() {
        return truncated_moments_by_quadrature(mu, s, a, b);
    }
    // Half-infinite interval [a, ∞): the closed form (inverse Mills ratio).
    let za = (a - mu) / s;
    let tail = 1.0 - normal_cdf(za);
    if tail < 1e-300 {
        return (a, 0.0);
    }
    let lambda = normal_pdf(za) / tail;
    let var = s * s * (1.0 + za * lambda - lambda * lambda);
    (mu + s * lambda, var.max(0.0).sqrt())
}

/// Moments of the truncated normal on a finite [a, b] by composite Simpson quadrature of the
/// density relative to its largest value on the interval; no cancellation, whatever the ratio
/// of the interval to s (closed forms lose all digits when the interval is narrow).
fn truncated_moments_by_quadrature(mu: f64, s: f64, a: f64, b: f64) -> (f64, f64) {
    const PANELS: usize = 256;
    // Beyond 12 s from the peak the density is below e^-72 of its maximum: leave it out, so a
    // narrow normal inside a wide interval is still resolved by the panels.
    let peak = mu.clamp(a, b);
    let (a, b) = (a.max(peak - 12.0 * s), b.min(peak + 12.0 * s));
    let log_density = |x: f64| -0.5 * (((x - mu) / s).powi(2) - ((peak - mu) / s).powi(2));
    let h = (b - a) / PANELS as f64;
    let (mut m0, mut m1, mut m2) = (0.0, 0.0, 0.0);
    for i in 0..=PANELS {
        let w = if i == 0 || i == PANELS {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let x = a + i as f64 * h;
        let f = w * log_density(x).exp();
        let dx = x - peak;
        m0 += f;
        m1 += f * dx;
        m2 += f * dx * dx;
    }
    if m0 <= 0.0 {
        return (peak, 0.0);
    }
    let mean = m1 / m0;
    ((peak + mean), (m2 / m0 - mean * mean).max(0.0).sqrt())
}

fn normal_pdf(z: f64) -> f64 {
    (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt()
}

/// Φ(z) through erfc (Chebyshev fit of Press et al., Numerical Recipes §6.2, relative error
/// below 1.2e-7 everywhere; ample for a standard deviation).
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn normal_cdf(z: f64) -> f64 {
    0.5 * erfc(-z / std::f64::consts::SQRT_2)
}

fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// An output-error fit whose switching function was re-estimated.
#[derive(Clone, Debug)]
pub struct SwitchedFit {
    /// The best fit found.
    pub fit: OutputErrorFit,
    /// Number of output-error fits run.
    pub fits: usize,
    /// True when the estimated d reproduces the classification it was fitted with.
    pub consistent: bool,
}

/// Output-error fit with h re-estimated (see the module docs); `scan` intervals on each side
/// of d̂ are tried afterwards (0 for none).
///
/// `make(Some(h))` builds the model with the switching frozen at h, `make(None)` with the
/// switching following d. `params` must contain a parameter named `d`.
pub fn fit_with_switching_updates<M: OutputErrorModel>(
    make: &(dyn Fn(Option<Switching>) -> M + Sync),
    data: &IdData,
    params: &ParameterSet,
    estimator: &OutputError,
    scan: usize,
    callback: &mut dyn FnMut(&IterationRecord) -> Control,
) -> Result<SwitchedFit> {
    let fixed_point = fixed_point(make, data, params, estimator, callback)?;
    if scan == 0 {
        return Ok(fixed_point);
    }
    let scanned = scan_intervals(make, data, &fixed_point.fit, estimator, scan)?;
    Ok(match scanned {
        Some((fit, fits))
            if fit.report.cost < fixed_point.fit.report.cost || !fixed_point.consistent =>
        {
            SwitchedFit {
                fit,
                fits: fixed_point.fits + fits,
                consistent: true,
            }
        }
        Some((_, fits)) => SwitchedFit {
            fits: fixed_point.fits + fits,
            ..fixed_point
        },
        None => fixed_point,
    })
}

/// Step 1 of the module docs.
fn fixed_point<M: OutputErrorModel>(
    make: &(dyn Fn(Option<Switching>) -> M + Sync),
    data: &IdData,
    params: &ParameterSet,
    estimator: &OutputError,
    callback: &mut dyn FnMut(&IterationRecord) -> Control,
) -> Result<SwitchedFit> {
    const MAX_UPDATES: usize = 30;
    let d_index = params.index_of("d")?;
    let mut current = params.clone();
    let mut h = classify(data, current.get(d_index).value);
    let mut visited: Vec<Switching> = Vec::new();
    let mut best: Option<(f64, OutputErrorFit)> = None;
    let mut start = None;
    for update in 1..=MAX_UPDATES {
        let model = make(Some(h.clone()));
        let ahead = NextStart::new(estimator, make, data, (&current, &h), d_index);
        let companion = |theta: &[f64], threads: usize| ahead.compute(theta, threads);
        let fit = estimator.estimate_beside(
            &model,
            data,
            &current,
            start.take(),
            Some(&companion),
            callback,
        )?;
        // A long record's fit has usually classified the samples by its final d and
        // computed the next start there beside its last trial pass already.
        let (h_new, start_ahead) = match ahead.take(&fit.parameters.values()) {
            Some(computed) => (computed.switching, computed.start),
            None => (classify(data, fit.parameters.get(d_index).value), None),
        };
        if h_new == h {
            return Ok(SwitchedFit {
                fit,
                fits: update,
                consistent: true,
            });
        }
        // The true criterion at the estimate is the next fit's criterion at its start (the
        // switching re-classified by the estimated d is the one that fit holds fixed). On a
        // long record that start's pass is the next fit's first anyway: its S is the value
        // wanted, and the pass is handed on; otherwise one simulation gives it.
        start = match start_ahead {
            Some(computed) => computed?,
            None => estimator.start(&make(Some(h_new.clone())), data, &fit.parameters)?,
        };
        let actual = match &start {
            Some(start) => start.cost(),
            None => true_cost(&make(None), data, &fit.parameters.values())?,
        };
        // Re-classifying must pay: once the true criterion stops falling, the best
        // classification so far stands (long records otherwise creep through many nearly
        // equal classifications).
        if best.as_ref().is_some_and(|(c, _)| actual >= *c) {
            break;
        }
        // The fit itself is kept, not copied: its simulated outputs are a record's length.
        current = fit.parameters.clone();
        best = Some((actual, fit));
        visited.push(std::mem::replace(&mut h, h_new));
        if visited.contains(&h) {
            break;
        }
    }
    let (_, fit) = best.expect("at least one fit ran");
    Ok(SwitchedFit {
        fit,
        fits: visited.len(),
        consistent: false,
    })
}

/// The next fit's start (`OutputError::start` with the switching re-classified by the
/// estimated d), computed beside a fit's trial pass that is likely its last (see
/// [`Companion`](super::output_error::Companion)): the same function of the same θ, so the
/// same result as when computed after the fit, found earlier.
struct NextStart<'a, M> {
    estimator: &'a OutputError,
    make: &'a (dyn Fn(Option<Switching>) -> M + Sync),
    data: &'a IdData,
    /// The fit's start and its frozen switching.
    current: &'a ParameterSet,
    h: &'a Switching,
    d_index: usize,
    /// What was computed at the last trial point tried.
    at: Mutex<Option<Computed>>,
}

/// What [`NextStart`] computed at one trial point.
struct Computed {
    theta: Vec<f64>,
    /// The switching that θ's d classifies.
    switching: Switching,
    /// The start there (`OutputError::start`'s result); None when the switching is the
    /// fit's own.
    start: Option<Result<Option<FitStart>>>,
}

impl<'a, M: OutputErrorModel> NextStart<'a, M> {
    fn new(
        estimator: &'a OutputError,
        make: &'a (dyn Fn(Option<Switching>) -> M + Sync),
        data: &'a IdData,
        (current, h): (&'a ParameterSet, &'a Switching),
        d_index: usize,
    ) -> Self {
        Self {
            estimator,
            make,
            data,
            current,
            h,
            d_index,
            at: Mutex::new(None),
        }
    }

    /// The switching that the trial point `theta`'s d classifies, and the start there on at
    /// most `threads` threads unless that switching is the fit's own (the fixed point is
    /// then reached and needs no start).
    fn compute(&self, theta: &[f64], threads: usize) {
        let h_next = classify(self.data, theta[self.d_index]);
        let start = (h_next != *self.h).then(|| {
            let mut at = self.current.clone();
            at.set_values(theta);
            let model = (self.make)(Some(h_next.clone()));
            self.estimator.start_on(&model, self.data, &at, threads)
        });
        *self.at.lock().unwrap_or_else(|e| e.into_inner()) = Some(Computed {
            theta: theta.to_vec(),
            switching: h_next,
            start,
        });
    }

    /// The switching and the start computed at exactly `theta`, if any (no start when the
    /// switching is the fit's own).
    fn take(&self, theta: &[f64]) -> Option<Computed> {
        let computed = self.at.lock().unwrap_or_else(|e| e.into_inner()).take()?;
        (computed.theta == theta).then_some(computed)
    }
}

/// Step 2 of the module docs. A coarse pass fits up to [`COARSE_INTERVALS`] intervals spread
/// over d̂ ± 3s (s the smooth standard deviation of d), because with noise the criterion over
/// the intervals can hold a plateau a purely local search would not leave; a fine pass then
/// tries every interval within `scan` of the best, re-centred while the best lies at the edge.
/// Returns the best fit and the number of fits.
fn scan_intervals<M: OutputErrorModel>(
    make: &dyn Fn(Option<Switching>) -> M,
    data: &IdData,
    start: &OutputErrorFit,
    estimator: &OutputError,
    scan: usize,
) -> Result<Option<(OutputErrorFit, usize)>> {
    const MAX_ROUNDS: usize = 6;
    let params = &start.parameters;
    let d_index = params.index_of("d")?;
    let edges = magnitudes(data);
    if edges.len() < 2 {
        return Ok(None);
    }
    let d_hat = params.get(d_index).value;
    let radius = 3.0 * start.std()[d_index];
    let mut results: Vec<(usize, OutputErrorFit)> = Vec::new();
    // The fits of one pass are independent: they run in parallel, and their results join in
    // the order of the pass, as when fitted one after the other.
    let try_intervals = |intervals: &mut dyn Iterator<Item = usize>,
                         results: &mut Vec<(usize, OutputErrorFit)>| {
        let jobs: Vec<(usize, M, ParameterSet)> = intervals
            .filter(|i| !results.iter().any(|(done, _)| done == i))
            .filter_map(|i| {
                let (model, params) = interval_problem(make, data, params, &edges, i, d_index)?;
                Some((i, model, params))
            })
            .collect();
        let fits: Vec<Option<OutputErrorFit>> = jobs
            .par_iter()
            .map(|(_, model, params)| {
                estimator
                    .estimate(model, data, params, &mut |_| Control::Continue)
                    .ok()
            })
            .collect();
        for ((i, _, _), fit) in jobs.into_iter().zip(fits) {
            if let Some(fit) = fit {
                results.push((i, fit));
            }
        }
    };
    if radius.is_finite() && radius > 0.0 {
        let lo = interval_of(&edges, d_hat - radius);
        let hi = interval_of(&edges, d_hat + radius);
        let stride = ((hi - lo) / COARSE_INTERVALS).max(1);
        try_intervals(&mut (lo..=hi).step_by(stride), &mut results);
    }
    let mut centre = best_of(&results).unwrap_or_else(|| interval_of(&edges, d_hat));
    for _ in 0..MAX_ROUNDS {
        let lo = centre.saturating_sub(scan).max(1);
        let hi = (centre + scan).min(edges.len() - 1);
        try_intervals(&mut (lo..=hi), &mut results);
        let Some(best) = best_of(&results) else {
            return Ok(None);
        };
        let at_edge = (best == lo && lo > 1) || (best == hi && hi < edges.len() - 1);
        if !at_edge {
            break;
        }
        centre = best;
    }
    let fits = results.len();
    Ok(results
        .into_iter()
        .min_by(|a, b| a.1.report.cost.total_cmp(&b.1.report.cost))
        .map(|(_, fit)| (fit, fits)))
}

/// Intervals tried by the coarse pass of the interval scan.
const COARSE_INTERVALS: usize = 12;

/// The interval with the lowest criterion among the fitted ones.
fn best_of(results: &[(usize, OutputErrorFit)]) -> Option<usize> {
    results
        .iter()
        .min_by(|a, b| a.1.report.cost.total_cmp(&b.1.report.cost))
        .map(|(i, _)| *i)
}

/// The model with h frozen for d in [edges[i−1], edges[i]) and the start with d bounded to
/// that interval; None when the interval is empty within the bounds of d.
fn interval_problem<M: OutputErrorModel>(
    make: &dyn Fn(Option<Switching>) -> M,
    data: &IdData,
    start: &ParameterSet,
    edges: &[f64],
    i: usize,
    d_index: usize,
) -> Option<(M, ParameterSet)> {
    let (lo, hi) = (edges[i - 1], edges[i] - edges[i].abs() * 1e-14);
    if hi.is_nan() || hi <= lo {
        return None;
    }
    let mut params = start.clone();
    let d = params.get_mut(d_index);
    d.min = lo.max(d.min);
    d.max = hi.min(d.max);
    if d.min.is_nan() || d.min >= d.max {
        return None;
    }
    d.value = d.value.clamp(d.min, d.max);
    let h = classify(data, 0.5 * (lo + hi));
    Some((make(Some(h)), params))
}

/// Sorted distinct |x(t)|, t ≥ 1, over all experiments: the edges of the intervals of d inside
/// which the classification is constant.
fn magnitudes(data: &IdData) -> Vec<f64> {
    let mut m: Vec<f64> = data
        .experiments()
        .iter()
        .flat_map(|e| e.input(0).iter().skip(1).map(|x| x.abs()))
        .collect();
    m.sort_by(f64::total_cmp);
    m.dedup();
    m
}

/// Index i of the interval [edges[i−1], edges[i]) that contains d (clamped to 1…len−1).
fn interval_of(edges: &[f64], d: f64) -> usize {
    edges
        .partition_point(|&e| e <= d)
        .clamp(1, edges.len().saturating_sub(1).max(1))
}

/// The output-error sum of squares of `model` at `theta` over output 0 of every experiment.
pub fn true_cost(model: &dyn OutputErrorModel, data: &IdData, theta: &[f64]) -> Result<f64> {
    let mut total = 0.0;
    for (e, exp) in data.experiments().iter().enumerate() {
        let mut y = vec![vec![0.0; exp.len()]];
        model.simulate(theta, data, e, &mut y)?;
        total += exp
            .output(0)
            .iter()
            .zip(&y[0])
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>();
    }
    Ok(total)
}
