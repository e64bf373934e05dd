//! Band-limited interpolation: exact on band-limited periodic records, real for real ones.
//! (Integration tests rather than unit tests, so that the test build does not instantiate
//! the FFT planner a second time.)

use hysid_spectral::band_limited_upsample;

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
