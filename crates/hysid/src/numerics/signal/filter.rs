//! Preprocessing as pure functions, compatible with MATLAB: `butter`, `filter`, `filtfilt`,
//! `gradient`, mean removal.
//!
//! * [`butter`]: digital Butterworth low-pass by the bilinear transform with frequency
//!   prewarping, from the analog prototype's poles (MATLAB `butter(n, Wn)`, Wn relative to
//!   the Nyquist frequency).
//! * [`filtfilt`]: zero-phase forward–backward filtering as MATLAB's `filtfilt`: the record is
//!   extended at both ends by odd reflection of 3·(nfilt − 1) samples, and each pass starts
//!   from the filter's steady-state initial conditions scaled by the first sample.
//! * [`gradient`]: MATLAB's `gradient`: central differences inside, one-sided at the ends.
//! * [`cheby1`], [`decimate`]: MATLAB's `cheby1` and `decimate(x, r)` with its default
//!   8th-order Chebyshev type I filter.
//!
//! The reference values of the tests come from SciPy (`scipy.signal.butter`, `filtfilt` with
//! `padtype='odd', padlen=3*(max(len(a), len(b))-1)`, `numpy.gradient`), which implement the
//! same definitions; the generator script is `tools/reference/filters.py`.

use crate::{Error, Result};
use nalgebra::{Complex, DMatrix, DVector};

/// A digital filter's transfer-function coefficients, b(z)/a(z) with a₀ = 1.
#[derive(Clone, Debug, PartialEq)]
pub struct TransferFunction {
    /// Numerator coefficients b0, b1, ….
    pub b: Vec<f64>,
    /// Denominator coefficients 1, a1, ….
    pub a: Vec<f64>,
}

/// The `order`-th order Butterworth low-pass with cut-off `wn` relative to the Nyquist
/// frequency (0 < wn < 1), as MATLAB's `butter(order, wn)`.
///
/// ```
/// // 4th order, 100 Hz at 1 kHz: Wn = 100/500.
/// let tf = hysid::numerics::signal::butter(4, 0.2).unwrap();
/// let dc: f64 = tf.b.iter().sum::<f64>() / tf.a.iter().sum::<f64>();
/// assert!((dc - 1.0).abs() < 1e-12);
/// ```
pub fn butter(order: usize, wn: f64) -> Result<TransferFunction> {
    check_design(order, wn, "butter")?;
    let n = order as f64;
    let poles: Vec<Complex<f64>> = (0..order)
        .map(|k| {
            let angle = std::f64::consts::PI * (2.0 * k as f64 + n + 1.0) / (2.0 * n);
            Complex::new(angle.cos(), angle.sin())
        })
        .collect();
    Ok(bilinear_lowpass(&poles, 1.0, wn))
}

/// The `order`-th order Chebyshev type I low-pass with `ripple_db` decibels of pass-band
/// ripple and pass-band edge `wn` relative to Nyquist, as MATLAB's `cheby1(order, rp, wn)`.
pub fn cheby1(order: usize, ripple_db: f64, wn: f64) -> Result<TransferFunction> {
    check_design(order, wn, "cheby1")?;
    if ripple_db.is_nan() || ripple_db <= 0.0 {
        return Err(Error::invalid_option(
            "ripple_db",
            ripple_db,
            format!("cheby1 needs a positive ripple in dB, got {ripple_db}"),
        ));
    }
    let n = order as f64;
    let eps = (10f64.powf(ripple_db / 10.0) - 1.0).sqrt();
    let mu = (1.0 / eps).asinh() / n;
    let poles: Vec<Complex<f64>> = (1..=order)
        .map(|k| {
            let theta = std::f64::consts::PI * (2.0 * k as f64 - 1.0) / (2.0 * n);
            Complex::new(-mu.sinh() * theta.sin(), mu.cosh() * theta.cos())
        })
        .collect();
    // Unit gain at DC for odd orders, the ripple floor 1/√(1 + ε²) for even ones.
    let prototype_gain = poles
        .iter()
        .fold(Complex::new(1.0, 0.0), |g, p| g * (-p))
        .re;
    let gain = if order.is_multiple_of(2) {
        prototype_gain / (1.0 + eps * eps).sqrt()
    } else {
        prototype_gain
    };
    Ok(bilinear_lowpass(&poles, gain, wn))
}

fn check_design(order: usize, wn: f64, name: &str) -> Result<()> {
    if order == 0 || !(wn > 0.0 && wn < 1.0) {
        return Err(Error::invalid_option("cutoff", wn, format!(
            "{name} needs an order >= 1 and a cut-off strictly between 0 and 1 (relative to Nyquist), got order {order}, cut-off {wn}"
        )));
    }
    Ok(())
}

/// The digital low-pass of an all-pole analog prototype with unit cut-off (poles, gain):
/// frequency-scaled to the prewarped cut-off, then the bilinear transform z = (1 + s)/(1 − s),
/// which puts every zero at z = −1.
fn bilinear_lowpass(prototype: &[Complex<f64>], prototype_gain: f64, wn: f64) -> TransferFunction {
    let order = prototype.len();
    let warped = (std::f64::consts::FRAC_PI_2 * wn).tan();
    let one = Complex::new(1.0, 0.0);
    let poles: Vec<Complex<f64>> = prototype.iter().map(|p| p * warped).collect();
    let z_poles: Vec<Complex<f64>> = poles.iter().map(|p| (one + p) / (one - p)).collect();
    let gain = poles
        .iter()
        .fold(
            Complex::new(prototype_gain * warped.powi(order as i32), 0.0),
            |g, p| g / (one - p),
        )
        .re;
    let a = real_polynomial(&z_poles);
    let b = real_polynomial(&vec![-one; order])
        .iter()
        .map(|c| c * gain)
        .collect();
    TransferFunction { b, a }
}

/// Coefficients of Π(z − rᵢ) in descending powers (roots in conjugate pairs or real).
fn real_polynomial(roots: &[Complex<f64>]) -> Vec<f64> {
    let mut c = vec![Complex::new(1.0, 0.0)];
    for r in roots {
        let mut next = vec![Complex::new(0.0, 0.0); c.len() + 1];
        for (i, ci) in c.iter().enumerate() {
            next[i] += ci;
            next[i + 1] -= ci * r;
        }
        c = next;
    }
    c.iter().map(|v| v.re).collect()
}

/// Direct-form II transposed filtering (MATLAB `filter(b, a, x, zi)`), from the state `zi`
/// (length max(len a, len b) − 1).
pub fn filter(tf: &TransferFunction, x: &[f64], zi: &[f64]) -> Vec<f64> {
    let n = tf.a.len().max(tf.b.len());
    let coef = |v: &[f64], i: usize| v.get(i).copied().unwrap_or(0.0) / tf.a[0];
    let mut z = zi.to_vec();
    z.resize(n - 1, 0.0);
    x.iter()
        .map(|&xi| {
            let y = coef(&tf.b, 0) * xi + z.first().copied().unwrap_or(0.0);
            for i in 0..n - 1 {
                let next = z.get(i + 1).copied().unwrap_or(0.0);
                z[i] = coef(&tf.b, i + 1) * xi + if i + 1 < n - 1 { next } else { 0.0 }
                    - coef(&tf.a, i + 1) * y;
            }
            y
        })
        .collect()
}

/// The steady-state initial conditions of `filter` for a unit step input (MATLAB's
/// `filtfilt` computes the same; SciPy's `lfilter_zi`).
pub fn steady_state_initial_conditions(tf: &TransferFunction) -> Vec<f64> {
    let n = tf.a.len().max(tf.b.len());
    let a0 = tf.a[0];
    let coef = |v: &[f64], i: usize| v.get(i).copied().unwrap_or(0.0) / a0;
    let m = n - 1;
    if m == 0 {
        return Vec::new();
    }
    // (I − Aᵀ-companion) zi = b[1:] − a[1:]·b0.
    let mut lhs = DMatrix::<f64>::identity(m, m);
    for i in 0..m {
        lhs[(i, 0)] += coef(&tf.a, i + 1);
        if i + 1 < m {
            lhs[(i, i + 1)] -= 1.0;
        }
    }
    let rhs = DVector::from_fn(m, |i, _| {
        coef(&tf.b, i + 1) - coef(&tf.a, i + 1) * coef(&tf.b, 0)
    });
    lhs.lu()
        .solve(&rhs)
        .map(|v| v.iter().copied().collect())
        .unwrap_or_else(|| vec![0.0; m])
}

/// Zero-phase filtering as MATLAB's `filtfilt` (see the module docs). Errors when the record
/// is not longer than the 3·(nfilt − 1) samples of the end extension.
pub fn filtfilt(tf: &TransferFunction, x: &[f64]) -> Result<Vec<f64>> {
    let nfilt = tf.a.len().max(tf.b.len());
    let nfact = 3 * (nfilt - 1);
    if x.len() <= nfact {
        return Err(Error::InvalidData(format!(
            "filtfilt needs more than {nfact} samples for this filter, got {}",
            x.len()
        )));
    }
    let n = x.len();
    let mut ext = Vec::with_capacity(n + 2 * nfact);
    ext.extend((1..=nfact).rev().map(|i| 2.0 * x[0] - x[i]));
    ext.extend_from_slice(x);
    ext.extend((1..=nfact).map(|i| 2.0 * x[n - 1] - x[n - 1 - i]));
    let zi = steady_state_initial_conditions(tf);
    let scaled = |v: f64| -> Vec<f64> { zi.iter().map(|z| z * v).collect() };
    let forward = filter(tf, &ext, &scaled(ext[0]));
    let reversed: Vec<f64> = forward.iter().rev().copied().collect();
    let backward = filter(tf, &reversed, &scaled(reversed[0]));
    Ok(backward.iter().rev().skip(nfact).take(n).copied().collect())
}

/// MATLAB's `decimate(x, r)` with its default filter: an 8th-order Chebyshev type I
/// low-pass (0.05 dB ripple, edge 0.8/r of Nyquist) applied by [`filtfilt`], then every r-th
/// sample, aligned so that the last sample is kept (MATLAB's `nbeg`).
pub fn decimate(x: &[f64], r: usize) -> Result<Vec<f64>> {
    if r <= 1 {
        return Ok(x.to_vec());
    }
    let tf = cheby1(8, 0.05, 0.8 / r as f64)?;
    let filtered = filtfilt(&tf, x)?;
    let n_out = x.len().div_ceil(r);
    let first = x.len() + r - 1 - r * n_out;
    Ok(filtered.iter().skip(first).step_by(r).copied().collect())
}

/// MATLAB's `gradient(x, h)`: central differences inside, one-sided differences at the ends.
pub fn gradient(x: &[f64], h: f64) -> Vec<f64> {
    let n = x.len();
    match n {
        0 => Vec::new(),
        1 => vec![0.0],
        _ => (0..n)
            .map(|i| {
                if i == 0 {
                    (x[1] - x[0]) / h
                } else if i == n - 1 {
                    (x[n - 1] - x[n - 2]) / h
                } else {
                    (x[i + 1] - x[i - 1]) / (2.0 * h)
                }
            })
            .collect(),
    }
}

/// The record with its mean removed.
pub fn remove_mean(x: &[f64]) -> Vec<f64> {
    let m = crate::numerics::metrics::mean(x);
    x.iter().map(|v| v - m).collect()
}
