//! The discrete Fourier transforms hysid needs, behind plain `f64` slices.
//!
//! Why a crate of its own: rustfft's planner is generic over the float type and carries
//! scalar, SSE and AVX algorithms for every length. A generic dependency is compiled into
//! the crate that instantiates it, so calling the planner from the `hysid` library made
//! rustfft a quarter of that library's machine code, compiled once for the library and once
//! more for its unit tests. Here it is instantiated once, for `f64`, and `hysid` calls a
//! non-generic function.

use rustfft::num_complex::Complex;
use rustfft::FftPlanner;

/// The band-limited interpolation of a periodic record `x` (length n) at `factor` points per
/// sample (length m = n·factor).
///
/// With X = DFT(x), the longer spectrum Y keeps X's positive frequencies 0 … ⌊n/2⌋ and its
/// negative ones −1 … −(n − ⌊n/2⌋ − 1) and is zero in between; for even n the Nyquist bin
/// X_{n/2} belongs to both halves and is split equally between them, so that a real record
/// stays real. The result is y = IDFT_m(Y)/n, which passes through x at every `factor`-th
/// point: the trigonometric interpolation of the record (e.g. Oppenheim & Schafer,
/// *Discrete-Time Signal Processing*, 3rd ed., §4.6, interpolation by zero-padding the DFT).
///
/// A record shorter than two samples, or `factor` ≤ 1, is returned unchanged.
pub fn band_limited_upsample(x: &[f64], factor: usize) -> Vec<f64> {
    let n = x.len();
    if n < 2 || factor <= 1 {
        return x.to_vec();
    }
    let m = n * factor;
    let mut planner = FftPlanner::<f64>::new();
    let mut spectrum: Vec<Complex<f64>> = x.iter().map(|&v| Complex::new(v, 0.0)).collect();
    planner.plan_fft_forward(n).process(&mut spectrum);
    let mut padded = vec![Complex::new(0.0, 0.0); m];
    let half = n / 2;
    padded[..=half].copy_from_slice(&spectrum[..=half]);
    for k in 1..n - half {
        padded[m - k] = spectrum[n - k];
    }
    if n.is_multiple_of(2) {
        // The Nyquist bin belongs to both halves of the longer spectrum.
        let nyquist = spectrum[half] * 0.5;
        padded[half] = nyquist;
        padded[m - half] = nyquist;
    }
    planner.plan_fft_inverse(m).process(&mut padded);
    padded.iter().map(|c| c.re / n as f64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sine of 3 periods per record is band-limited: its interpolation is the sine itself.
    fn sine_test(n: usize, factor: usize) {
        let f = |t: f64| (2.0 * std::f64::consts::PI * 3.0 * t / n as f64).sin() + 0.5;
        let x: Vec<f64> = (0..n).map(|k| f(k as f64)).collect();
        let up = band_limited_upsample(&x, factor);
        assert_eq!(up.len(), n * factor);
        for (i, v) in up.iter().enumerate() {
            assert!((v - f(i as f64 / factor as f64)).abs() < 1e-12, "{n} {i}");
        }
    }

    #[test]
    fn reproduces_a_periodic_sine_at_even_and_odd_lengths() {
        sine_test(64, 8);
        sine_test(63, 3);
    }

    #[test]
    fn the_nyquist_bin_is_split_so_the_alternating_record_stays_real_and_exact() {
        // x_k = (−1)^k is the Nyquist cosine; its interpolation is cos(π t).
        let x = [1.0, -1.0, 1.0, -1.0];
        let up = band_limited_upsample(&x, 2);
        let expected = [1.0, 0.0, -1.0, 0.0, 1.0, 0.0, -1.0, 0.0];
        for (v, e) in up.iter().zip(expected) {
            assert!((v - e).abs() < 1e-15);
        }
    }

    #[test]
    fn short_records_and_unit_factors_are_returned_unchanged() {
        assert_eq!(band_limited_upsample(&[2.5], 4), vec![2.5]);
        assert_eq!(band_limited_upsample(&[1.0, 2.0], 1), vec![1.0, 2.0]);
    }
}
