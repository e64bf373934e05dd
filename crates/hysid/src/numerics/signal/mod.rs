//! Excitation signals, noise and preprocessing. Every random generator takes a seed and uses
//! the portable xoshiro256++ generator, so a seed gives the same signal on every machine and
//! version. The MATLAB-compatible preprocessing (`butter`, `filter`, `filtfilt`, `gradient`)
//! functions are re-exported here from the `filter` submodule.

mod band;
mod filter;

pub use band::high_band_fraction;

pub use filter::{
    butter, cheby1, decimate, filter, filtfilt, gradient, remove_mean,
    steady_state_initial_conditions, TransferFunction,
};

use crate::{Error, Result};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use rand_distr::{Normal, Uniform};

/// One segment of an amplitude schedule: `len` samples of a triangle of peak `amplitude`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Number of samples in the segment.
    pub len: usize,
    /// Peak amplitude of the triangle in this segment.
    pub amplitude: f64,
}

/// Periodic triangles with one period length and a peak amplitude per segment
/// (Vörös 2015, Section 5: "periodic triangular signals … with different peak amplitudes").
///
/// Each period starts at 0, rises to +A at a quarter period, falls to −A at three quarters and
/// returns to 0, so the increment per sample is 4A/period (the peaks fall on samples only when
/// the period is a multiple of 4). The phase runs on across segments.
///
/// ```
/// use hysid::numerics::signal::{triangle_schedule, Segment};
/// let x = triangle_schedule(8, &[Segment { len: 8, amplitude: 2.0 }]).unwrap();
/// assert_eq!(x, vec![0.0, 1.0, 2.0, 1.0, 0.0, -1.0, -2.0, -1.0]);
/// ```
pub fn triangle_schedule(period: usize, segments: &[Segment]) -> Result<Vec<f64>> {
    if period < 4 {
        return Err(Error::invalid_option(
            "period",
            period,
            format!("triangle period must be at least 4 samples, got {period}"),
        ));
    }
    let mut x = Vec::with_capacity(segments.iter().map(|s| s.len).sum());
    for segment in segments {
        for _ in 0..segment.len {
            x.push(segment.amplitude * unit_triangle(x.len() % period, period));
        }
    }
    Ok(x)
}

/// The unit triangle at phase `k` of `period` samples: 0 → 1 → 0 → −1 → 0.
fn unit_triangle(k: usize, period: usize) -> f64 {
    let quarter = period as f64 / 4.0;
    let k = k as f64;
    if k <= quarter {
        k / quarter
    } else if k <= 3.0 * quarter {
        2.0 - k / quarter
    } else {
        k / quarter - 4.0
    }
}

/// A random-phase multisine: `periods` periods of `period` samples at sampling frequency
/// `fs`, every DFT bin whose frequency lies in [f_lo, f_hi] excited with equal amplitude and
/// a phase uniform on [0, 2π), scaled to the root-mean-square value `rms`. This is the
/// excitation of the Bouc–Wen benchmark (8192 samples per period, 5–150 Hz, RMS 50 N at
/// 750 Hz; Noël & Schoukens 2016).
///
/// ```
/// let u = hysid::numerics::signal::multisine(1024, 2, 750.0, 5.0, 150.0, 50.0, 1).unwrap();
/// let rms = (u.iter().map(|v| v * v).sum::<f64>() / u.len() as f64).sqrt();
/// assert!((rms - 50.0).abs() < 1e-9);
/// assert!((u[0] - u[1024]).abs() < 1e-9); // periodic
/// ```
pub fn multisine(
    period: usize,
    periods: usize,
    fs: f64,
    f_lo: f64,
    f_hi: f64,
    rms: f64,
    seed: u64,
) -> Result<Vec<f64>> {
    let df = fs / period as f64;
    let bins: Vec<usize> = (1..period / 2)
        .filter(|&k| (f_lo..=f_hi).contains(&(k as f64 * df)))
        .collect();
    if bins.is_empty() {
        return Err(Error::invalid_option(
            "band",
            format!("[{f_lo}, {f_hi}]"),
            format!(
            "no frequency bin of a {period}-sample period at {fs} Hz lies in [{f_lo}, {f_hi}] Hz"
        ),
        ));
    }
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let phases: Vec<f64> = bins
        .iter()
        .map(|_| rng.random_range(0.0..std::f64::consts::TAU))
        .collect();
    let one: Vec<f64> = (0..period)
        .map(|t| {
            bins.iter()
                .zip(&phases)
                .map(|(&k, ph)| {
                    (std::f64::consts::TAU * k as f64 * t as f64 / period as f64 + ph).cos()
                })
                .sum()
        })
        .collect();
    let scale = rms / crate::numerics::metrics::std_dev(&one).max(f64::MIN_POSITIVE);
    Ok((0..period * periods)
        .map(|t| scale * one[t % period])
        .collect())
}

/// The linear sine sweep u(t) = A·sin(2π(f0·t + k·t²/2)) at sampling frequency `fs`, `n`
/// samples; the Bouc–Wen benchmark's sweep test is A = 40 N, f0 = 18 Hz, k = 1/6 Hz/s
/// (u = 40 sin(2π(18t + t²/12))), 153 000 samples at 750 Hz.
pub fn sine_sweep(n: usize, fs: f64, amplitude: f64, f0: f64, rate: f64) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / fs;
            amplitude * (std::f64::consts::TAU * (f0 * t + 0.5 * rate * t * t)).sin()
        })
        .collect()
}

/// Decimation by an integer `factor`: a zero-phase low-pass FIR (Hamming-windowed sinc with
/// its cut-off at the new Nyquist frequency, 20·factor + 1 taps, applied centred, the record
/// extended by its end values) followed by keeping every `factor`-th sample, starting with
/// the first. Like MATLAB's `decimate(…, 'fir')`, up to its filter details.
pub fn decimate_fir(x: &[f64], factor: usize) -> Vec<f64> {
    if factor <= 1 || x.is_empty() {
        return x.to_vec();
    }
    let half = 10 * factor;
    let cutoff = 0.5 / factor as f64; // cycles per sample
    let kernel: Vec<f64> = (0..=2 * half)
        .map(|i| {
            let m = i as f64 - half as f64;
            let sinc = if m == 0.0 {
                2.0 * cutoff
            } else {
                (std::f64::consts::TAU * cutoff * m).sin() / (std::f64::consts::PI * m)
            };
            let window = 0.54 - 0.46 * (std::f64::consts::TAU * i as f64 / (2 * half) as f64).cos();
            sinc * window
        })
        .collect();
    let gain: f64 = kernel.iter().sum();
    let at = |i: i64| x[i.clamp(0, x.len() as i64 - 1) as usize];
    (0..x.len())
        .step_by(factor)
        .map(|k| {
            kernel
                .iter()
                .enumerate()
                .map(|(i, w)| w * at(k as i64 + i as i64 - half as i64))
                .sum::<f64>()
                / gain
        })
        .collect()
}

/// `n` samples uniformly distributed on [−half_width, half_width].
pub fn uniform_noise(n: usize, half_width: f64, seed: u64) -> Result<Vec<f64>> {
    if !(half_width >= 0.0 && half_width.is_finite()) {
        return Err(Error::invalid_option(
            "half_width",
            half_width,
            format!("uniform disturbance half-width must be finite and >= 0, got {half_width}"),
        ));
    }
    if half_width == 0.0 {
        return Ok(vec![0.0; n]);
    }
    let dist = Uniform::new_inclusive(-half_width, half_width).map_err(|e| {
        Error::invalid_option(
            "half_width",
            half_width,
            format!("uniform disturbance: {e}"),
        )
    })?;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    Ok((0..n).map(|_| rng.sample(dist)).collect())
}

/// `n` samples of zero-mean Gaussian noise with standard deviation `std`.
pub fn gaussian_noise(n: usize, std: f64, seed: u64) -> Result<Vec<f64>> {
    let dist = Normal::new(0.0, std).map_err(|e| {
        Error::invalid_option("std", std, format!("Gaussian noise with std {std}: {e}"))
    })?;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    Ok((0..n).map(|_| rng.sample(dist)).collect())
}

/// Adds zero-mean Gaussian noise to `y` at a signal-to-noise ratio given as a ratio of
/// standard deviations, SNR = std(y)/std(noise) (Vörös 2015: "the square root of the ratio of
/// output and noise variances"). Returns the noisy signal and the noise std used.
pub fn add_noise_snr(y: &[f64], snr: f64, seed: u64) -> Result<(Vec<f64>, f64)> {
    if !(snr > 0.0 && snr.is_finite()) {
        return Err(Error::invalid_option(
            "snr",
            snr,
            format!("SNR must be finite and > 0, got {snr}"),
        ));
    }
    let std = crate::numerics::metrics::std_dev(y) / snr;
    let noise = gaussian_noise(y.len(), std, seed)?;
    Ok((y.iter().zip(&noise).map(|(a, b)| a + b).collect(), std))
}
