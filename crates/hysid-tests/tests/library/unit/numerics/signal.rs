//! Tests of `hysid::numerics::signal`.

use hysid::numerics::signal::*;

#[test]
fn triangle_increment_is_four_amplitudes_per_period() {
    let x = triangle_schedule(
        40,
        &[Segment {
            len: 80,
            amplitude: 5.0,
        }],
    )
    .unwrap();
    for w in x.windows(2) {
        assert!(((w[1] - w[0]).abs() - 0.5).abs() < 1e-12);
    }
    assert_eq!(x[10], 5.0);
    assert_eq!(x[30], -5.0);
}

#[test]
fn decimation_keeps_the_passband_and_removes_the_aliases() {
    let n = 20_000;
    let slow: Vec<f64> = (0..n)
        .map(|k| (std::f64::consts::TAU * 0.002 * k as f64).sin())
        .collect();
    let fast: Vec<f64> = (0..n)
        .map(|k| (std::f64::consts::TAU * 0.2 * k as f64).sin())
        .collect();
    let mixed: Vec<f64> = slow.iter().zip(&fast).map(|(a, b)| a + b).collect();
    let d = decimate_fir(&mixed, 10);
    for (k, v) in d.iter().enumerate().skip(30).take(1900) {
        assert!(
            (v - slow[10 * k]).abs() < 2e-3,
            "{k}: {v} vs {}",
            slow[10 * k]
        );
    }
}

#[test]
fn noise_is_seeded_and_has_the_asked_snr() {
    let y: Vec<f64> = (0..20000).map(|t| (t as f64 * 0.01).sin()).collect();
    let (a, std) = add_noise_snr(&y, 50.0, 7).unwrap();
    let (b, _) = add_noise_snr(&y, 50.0, 7).unwrap();
    assert_eq!(a, b);
    let noise: Vec<f64> = a.iter().zip(&y).map(|(p, q)| p - q).collect();
    let ratio = hysid::numerics::metrics::std_dev(&noise) / std;
    assert!((ratio - 1.0).abs() < 0.03, "{ratio}");
    let u = uniform_noise(1000, 0.2, 3).unwrap();
    assert!(u.iter().all(|v| v.abs() <= 0.2));
}

/// A random staircase of `n` samples holding each Gaussian level for `hold` samples.
fn staircase(n: usize, hold: usize, seed: u64) -> Vec<f64> {
    let levels = gaussian_noise(n / hold + 1, 1.0, seed).unwrap();
    (0..n).map(|t| levels[t / hold]).collect()
}

/// A band-limited multisine (5–150 Hz at 750 Hz: up to 0.4 of Nyquist) has no energy above
/// half the Nyquist frequency but leakage, a whole number of periods or not; a staircase held
/// for 1 to 100 samples has more than the 10⁻³ of the grey-box hold check, a constant none.
#[test]
fn high_band_fraction_separates_multisines_from_staircases() {
    let u = multisine(4096, 2, 750.0, 5.0, 150.0, 50.0, 3).unwrap();
    let whole = high_band_fraction(&u, 0.5);
    let part = high_band_fraction(&u[..3000], 0.5);
    eprintln!("multisine: {whole:.2e} (whole periods), {part:.2e} (3000 samples)");
    assert!(whole < 1e-12 && part < 1e-6, "{whole} {part}");
    for (hold, low) in [(1, 0.3), (10, 5e-3), (100, 1.1e-3)] {
        let x = staircase(20_000, hold, 7);
        let f = high_band_fraction(&x, 0.5);
        eprintln!("staircase held {hold}: {f:.2e}");
        assert!(f > low, "held {hold}: {f}");
    }
    assert_eq!(high_band_fraction(&[2.0; 100], 0.5), 0.0);
    assert_eq!(high_band_fraction(&[1.0, 2.0], 0.5), 0.0);
}
