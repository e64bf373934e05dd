//! Fit metrics and information criteria.
//!
//! * fit % (Gunnar et al. 2006, eq. 14; MATLAB `compare`): 100·(1 − ‖y − ŷ‖₂ / ‖y − ȳ‖₂)
//! * RMSE = sqrt(mean((y − ŷ)²)); NRMSE = ‖y − ŷ‖₂ / ‖y − ȳ‖₂
//! * FPE = V·(1 + p/N)/(1 − p/N), with the loss V = mean squared residual (Akaike)
//! * AIC = N·ln V + 2p + N·(ln 2π + 1) (MATLAB's `aic` for one output)
//!
//! The sums of squares behind fit %, NRMSE and MSE run over eight partial sums (value i goes
//! to sum i mod 8, the sums are then added pairwise): independent chains, so a 10⁶-sample
//! record is summed at the machine's rate rather than one addition's latency per value, and
//! in a fixed order, so the figures are reproducible. The mean and standard deviation keep
//! one running sum: they shift and scale data (mean removal, noise levels), whose rounding
//! every later figure inherits.

/// Σ f(aᵢ, bᵢ) over the common length, in the order of the module docs.
#[inline(always)]
fn sum_pairs(a: &[f64], b: &[f64], f: impl Fn(f64, f64) -> f64) -> f64 {
    let [sum] = sums_of_pairs(a, b, |x, y| [f(x, y)]);
    sum
}

/// The K sums Σ fₖ(aᵢ, bᵢ) over the common length from one pass, each in the order of the
/// module docs.
#[inline(always)]
fn sums_of_pairs<const K: usize>(
    a: &[f64],
    b: &[f64],
    f: impl Fn(f64, f64) -> [f64; K],
) -> [f64; K] {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut lanes = [[0.0; 8]; K];
    let mut add = |lane: usize, x: f64, y: f64| {
        for (sum, value) in lanes.iter_mut().zip(f(x, y)) {
            sum[lane] += value;
        }
    };
    let (a8, b8) = (a.chunks_exact(8), b.chunks_exact(8));
    let (a_tail, b_tail) = (a8.remainder(), b8.remainder());
    for (x, y) in a8.zip(b8) {
        for (lane, (x, y)) in x.iter().zip(y).enumerate() {
            add(lane, *x, *y);
        }
    }
    for (lane, (x, y)) in a_tail.iter().zip(b_tail).enumerate() {
        add(lane, *x, *y);
    }
    lanes.map(|[s0, s1, s2, s3, s4, s5, s6, s7]| ((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7)))
}

/// Arithmetic mean (0 for an empty slice), summed in order: it shifts data (mean removal),
/// so its rounding is kept as it always was.
pub fn mean(y: &[f64]) -> f64 {
    if y.is_empty() {
        0.0
    } else {
        y.iter().sum::<f64>() / y.len() as f64
    }
}

/// Population standard deviation (divides by N), summed in order like [`mean`].
pub fn std_dev(y: &[f64]) -> f64 {
    let m = mean(y);
    (y.iter().map(|v| (v - m).powi(2)).sum::<f64>() / y.len().max(1) as f64).sqrt()
}

/// NRMSE = ‖y − ŷ‖₂ / ‖y − ȳ‖₂ (infinite when y is constant and ŷ ≠ y).
pub fn nrmse(y: &[f64], yhat: &[f64]) -> f64 {
    nrmse_of(squares(y, yhat))
}

/// ‖y − ŷ‖₂² and ‖y − ȳ‖₂² over the common length, in one pass after the mean (each summed
/// as the module docs say, so each is what a pass of its own gives).
fn squares(y: &[f64], yhat: &[f64]) -> (f64, f64) {
    let m = mean(y);
    let [err, var] = sums_of_pairs(y, yhat, |a, b| [(a - b).powi(2), (a - m).powi(2)]);
    (err, var)
}

/// NRMSE from ‖y − ŷ‖₂² and ‖y − ȳ‖₂².
fn nrmse_of((err, var): (f64, f64)) -> f64 {
    if err == 0.0 {
        0.0
    } else {
        (err / var).sqrt()
    }
}

/// [`fit_percent`] and [`mse`] of one output, from one pass over y and ŷ after the mean:
/// the same values as the two functions give.
pub fn fit_percent_and_mse(y: &[f64], yhat: &[f64]) -> (f64, f64) {
    let (err, var) = squares(y, yhat);
    let fit = 100.0 * (1.0 - nrmse_of((err, var)));
    (fit, err / y.len().max(1) as f64)
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
    sum_pairs(y, yhat, |a, b| (a - b).powi(2)) / n
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

/// The largest f(aᵢ, bᵢ) over the common length, and 0: the same as folding with
/// `f64::max` (NaN values are passed over either way), in eight lanes so that a long
/// record's scan runs at the machine's rate; a maximum does not depend on the order.
pub fn largest(a: &[f64], b: &[f64], f: impl Fn(f64, f64) -> f64) -> f64 {
    let n = a.len().min(b.len());
    let (a8, b8) = (a[..n].chunks_exact(8), b[..n].chunks_exact(8));
    let mut lanes = [0.0f64; 8];
    for (x, y) in a8.remainder().iter().zip(b8.remainder()) {
        lanes[0] = lanes[0].max(f(*x, *y));
    }
    for (x, y) in a8.zip(b8) {
        for ((lane, x), y) in lanes.iter_mut().zip(x).zip(y) {
            let v = f(*x, *y);
            // `v > lane` keeps the lane for a NaN, as f64::max does, and vectorises.
            if v > *lane {
                *lane = v;
            }
        }
    }
    lanes.into_iter().fold(0.0, f64::max)
}

/// max |yᵢ| (0 when empty), by [`largest`].
pub fn max_abs(y: &[f64]) -> f64 {
    largest(y, y, |v, _| v.abs())
}
