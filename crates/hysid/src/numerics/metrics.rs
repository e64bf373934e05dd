//! Fit metrics and information criteria.
//!
//! * fit % (Gunnar et al. 2006, eq. 14; MATLAB `compare`): 100·(1 − ‖y − ŷ‖₂ / ‖y − ȳ‖₂)
//! * RMSE = sqrt(mean((y − ŷ)²)); NRMSE = ‖y − ŷ‖₂ / ‖y − ȳ‖₂
//! * FPE = V·(1 + p/N)/(1 − p/N), with the loss V = mean squared residual (Akaike)
//! * AIC = N·ln V + 2p + N·(ln 2π + 1) (MATLAB's `aic` for one output)

/// Arithmetic mean (0 for an empty slice).
pub fn mean(y: &[f64]) -> f64 {
    if y.is_empty() {
        0.0
    } else {
        y.iter().sum::<f64>() / y.len() as f64
    }
}

/// Population standard deviation (divides by N).
pub fn std_dev(y: &[f64]) -> f64 {
    let m = mean(y);
    (y.iter().map(|v| (v - m).powi(2)).sum::<f64>() / y.len().max(1) as f64).sqrt()
}

/// NRMSE = ‖y − ŷ‖₂ / ‖y − ȳ‖₂ (infinite when y is constant and ŷ ≠ y).
pub fn nrmse(y: &[f64], yhat: &[f64]) -> f64 {
    let m = mean(y);
    let err: f64 = y.iter().zip(yhat).map(|(a, b)| (a - b).powi(2)).sum();
    let var: f64 = y.iter().map(|a| (a - m).powi(2)).sum();
    if err == 0.0 {
        0.0
    } else {
        (err / var).sqrt()
    }
}

/// fit % = 100·(1 − ‖y − ŷ‖₂ / ‖y − ȳ‖₂) (Gunnar et al. 2006 eq. 14; MATLAB `compare`).
///
/// ```
/// let y = [1.0, 2.0, 3.0];
/// assert_eq!(hysid::numerics::metrics::fit_percent(&y, &y), 100.0);
/// assert_eq!(hysid::numerics::metrics::fit_percent(&y, &[2.0, 2.0, 2.0]), 0.0);
/// ```
pub fn fit_percent(y: &[f64], yhat: &[f64]) -> f64 {
    100.0 * (1.0 - nrmse(y, yhat))
}

/// Root-mean-square error.
pub fn rmse(y: &[f64], yhat: &[f64]) -> f64 {
    mse(y, yhat).sqrt()
}

/// Mean squared error.
pub fn mse(y: &[f64], yhat: &[f64]) -> f64 {
    let n = y.len().max(1) as f64;
    y.iter()
        .zip(yhat)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        / n
}

/// Akaike's final prediction error FPE = V·(1 + p/N)/(1 − p/N) for loss V, N samples and
/// p estimated parameters (infinite when p ≥ N).
pub fn fpe(loss: f64, n: usize, p: usize) -> f64 {
    let ratio = p as f64 / n as f64;
    if ratio >= 1.0 {
        f64::INFINITY
    } else {
        loss * (1.0 + ratio) / (1.0 - ratio)
    }
}

/// Akaike's information criterion N·ln V + 2p + N·(ln 2π + 1) for one output (MATLAB `aic`).
pub fn aic(loss: f64, n: usize, p: usize) -> f64 {
    let n = n as f64;
    n * loss.ln() + 2.0 * p as f64 + n * ((2.0 * std::f64::consts::PI).ln() + 1.0)
}
