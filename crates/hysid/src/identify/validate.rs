//! Model validation: residual analysis (MATLAB `resid`) and the one-at-a-time parameter
//! sensitivity table of Gunnar et al. (2006, Table III).
//!
//! # Residual analysis
//!
//! With residuals ε(t) = y(t) − ŷ(t) over N samples and input u, the normalised sample
//! auto-correlation r_ε(τ) = R_ε(τ)/R_ε(0), τ = 0…M, and cross-correlation
//! r_εu(τ) = R_εu(τ)/√(R_ε(0)R_u(0)), τ = −M…M (R_εu(τ) = (1/N)Σ ε(t+τ)u(t), u with its mean
//! removed). For white residuals independent of the input, every value but r_ε(0) lies
//! within ±2.576/√N with probability 0.99 — the 99 % band (Ljung, System Identification,
//! 2nd ed., §16.6).

use crate::data::IdData;
use crate::identify::OutputErrorModel;
use crate::model::ParameterSet;
use crate::numerics::metrics;
use crate::Result;
use serde::Serialize;

/// The 99 % quantile of the standard normal distribution (two-sided).
const Z99: f64 = 2.575_829_3;

/// Residual correlations of one experiment and output.
#[derive(Clone, Debug, Serialize)]
pub struct ResidualAnalysis {
    /// Largest lag M.
    pub max_lag: usize,
    /// r_ε(τ), τ = 0…M.
    pub autocorrelation: Vec<f64>,
    /// r_εu(τ) per input channel, τ = −M…M.
    pub cross_correlation: Vec<Vec<f64>>,
    /// Half-width of the 99 % band, 2.576/√N.
    pub band: f64,
    /// Number of auto-correlation values (τ ≥ 1) outside the band.
    pub auto_outside: usize,
    /// Number of cross-correlation values outside the band, per input.
    pub cross_outside: Vec<usize>,
}

/// Residual analysis of the simulated output `yhat` against output channel `output` of
/// experiment `exp` (see the module docs).
pub fn residual_analysis(
    data: &IdData,
    exp: usize,
    output: usize,
    yhat: &[f64],
    max_lag: usize,
) -> ResidualAnalysis {
    let e = data.experiment(exp);
    let residual: Vec<f64> = e
        .output(output)
        .iter()
        .zip(yhat)
        .map(|(y, h)| y - h)
        .collect();
    let n = residual.len();
    let m = max_lag.min(n.saturating_sub(1));
    let centred = |s: &[f64]| -> Vec<f64> {
        let mean = metrics::mean(s);
        s.iter().map(|v| v - mean).collect()
    };
    let eps = centred(&residual);
    let r0 = correlation(&eps, &eps, 0);
    let autocorrelation: Vec<f64> = (0..=m)
        .map(|tau| correlation(&eps, &eps, tau as i64) / r0)
        .collect();
    let band = Z99 / (n as f64).sqrt();
    let cross_correlation: Vec<Vec<f64>> = (0..data.input_channels().len())
        .map(|c| {
            let u = centred(e.input(c));
            let scale = (r0 * correlation(&u, &u, 0)).sqrt();
            (-(m as i64)..=m as i64)
                .map(|tau| correlation(&eps, &u, tau) / scale)
                .collect()
        })
        .collect();
    ResidualAnalysis {
        max_lag: m,
        auto_outside: autocorrelation
            .iter()
            .skip(1)
            .filter(|r| r.abs() > band)
            .count(),
        cross_outside: cross_correlation
            .iter()
            .map(|c| c.iter().filter(|r| r.abs() > band).count())
            .collect(),
        autocorrelation,
        cross_correlation,
        band,
    }
}

/// (1/N) Σ a(t + τ) b(t) over the overlapping samples.
fn correlation(a: &[f64], b: &[f64], tau: i64) -> f64 {
    let n = a.len() as i64;
    let (start, end) = (0.max(-tau), n.min(n - tau));
    (start..end)
        .map(|t| a[(t + tau) as usize] * b[t as usize])
        .sum::<f64>()
        / n as f64
}

/// One row of the sensitivity table: the change of fit % when one parameter is perturbed.
#[derive(Clone, Debug, Serialize)]
pub struct SensitivityRow {
    /// The parameter.
    pub name: String,
    /// Change of fit % per experiment (first output) for +perturbation.
    pub up: Vec<f64>,
    /// Change of fit % per experiment (first output) for −perturbation.
    pub down: Vec<f64>,
}

/// The one-at-a-time sensitivity table of Gunnar et al. (2006, Table III): every free
/// parameter of `params` is multiplied by (1 ± `relative`) in turn and the change of fit %
/// with respect to the nominal model is recorded for every experiment. A perturbation that
/// cannot be simulated gives NaN.
pub fn sensitivity_table(
    model: &dyn OutputErrorModel,
    data: &IdData,
    params: &ParameterSet,
    relative: f64,
) -> Result<Vec<SensitivityRow>> {
    let nominal = fits(model, data, &params.values())?;
    let rows = params
        .free_indices()
        .into_iter()
        .map(|i| {
            let shifted = |sign: f64| -> Vec<f64> {
                let mut theta = params.values();
                theta[i] *= 1.0 + sign * relative;
                match fits(model, data, &theta) {
                    Ok(f) => f.iter().zip(&nominal).map(|(a, b)| a - b).collect(),
                    Err(_) => vec![f64::NAN; nominal.len()],
                }
            };
            SensitivityRow {
                name: params.get(i).name.clone(),
                up: shifted(1.0),
                down: shifted(-1.0),
            }
        })
        .collect();
    Ok(rows)
}

/// fit % of the first output of every experiment for the parameter vector θ.
pub fn fits(model: &dyn OutputErrorModel, data: &IdData, theta: &[f64]) -> Result<Vec<f64>> {
    (0..data.n_experiments())
        .map(|e| experiment_fit(model, data, e, theta))
        .collect()
}

/// fit % of the first output of experiment `e` for the parameter vector θ.
pub fn experiment_fit(
    model: &dyn OutputErrorModel,
    data: &IdData,
    e: usize,
    theta: &[f64],
) -> Result<f64> {
    let exp = &data.experiments()[e];
    let mut y = vec![vec![0.0; exp.len()]; model.n_outputs()];
    model.simulate(theta, data, e, &mut y)?;
    Ok(metrics::fit_percent(exp.output(0), &y[0]))
}
