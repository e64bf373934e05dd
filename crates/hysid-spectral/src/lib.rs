//! The discrete Fourier transforms hysid needs, behind plain `f64` slices.
//!
//! Why a crate of its own: rustfft's planner is generic over the float type and carries
//! scalar, SSE and AVX algorithms for every length. A generic dependency is compiled into
//! the crate that instantiates it, so calling the planner from the `hysid` library made
//! rustfft a quarter of that library's machine code, compiled once for the library and once
//! more for its unit tests. Here it is instantiated once, for `f64`, and `hysid` calls a
//! non-generic function.
//!
//! rustfft is built without its SSE and AVX algorithms (`default-features = false` in the
//! workspace manifest): the transforms run once per experiment when an input track is
//! prepared, never inside a fit's loop, so the SIMD kernels bought no measurable time (the
//! Bouc–Wen benchmark fit took the same 0.8 s) and cost 15 s of every fresh build.

use rayon::prelude::*;
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
    // The long transform's plan (most of the work before the transform itself: its
    // twiddle factors) is made on one thread while the other forms the longer spectrum. A
    // plan depends on its length and direction alone, so the transforms are those one
    // planner would make.
    let (inverse, mut padded) = rayon::join(
        || FftPlanner::<f64>::new().plan_fft_inverse(m),
        || {
            let mut spectrum: Vec<Complex<f64>> = x.iter().map(|&v| Complex::new(v, 0.0)).collect();
            FftPlanner::<f64>::new()
                .plan_fft_forward(n)
                .process(&mut spectrum);
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
            padded
        },
    );
    inverse.process(&mut padded);
    padded.par_iter().map(|c| c.re / n as f64).collect()
}

/// The one-sided energy spectrum |X_k|², k = 0 … ⌊n/2⌋, of a real record `x` (length n),
/// X = DFT(x): bin k is the frequency k/n of the sampling rate, the last one (for even n)
/// the Nyquist frequency. An empty record gives an empty spectrum.
pub fn energy_spectrum(x: &[f64]) -> Vec<f64> {
    let n = x.len();
    if n == 0 {
        return Vec::new();
    }
    let mut planner = FftPlanner::<f64>::new();
    let mut spectrum: Vec<Complex<f64>> = x.iter().map(|&v| Complex::new(v, 0.0)).collect();
    planner.plan_fft_forward(n).process(&mut spectrum);
    spectrum[..=n / 2].iter().map(|c| c.norm_sqr()).collect()
}
