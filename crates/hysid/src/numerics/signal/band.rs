//! How much of a record's energy lies high in the band: the statistic behind the hint that a
//! band-limited input should not be held between samples (`identify::greybox::hold_check`).

/// The fraction of the energy of `x` (mean removed, Hann-windowed) at frequencies above
/// `fraction` of the Nyquist frequency, from the one-sided DFT energy spectrum: with
/// E_k = |X_k|², k = 0 … ⌊n/2⌋, it is Σ_{k > fraction·n/2} E_k / Σ_{k ≥ 1} E_k.
///
/// The Hann window keeps the leakage of a record that is not an integer number of periods
/// (its sidelobes fall as 1/f³) from posing as high-frequency energy. A record of fewer than
/// four samples, or a constant one, gives 0.
///
/// ```
/// use hysid::numerics::signal::high_band_fraction;
/// let slow: Vec<f64> = (0..1000).map(|t| (0.05 * t as f64).sin()).collect();
/// assert!(high_band_fraction(&slow, 0.5) < 1e-6);
/// let alternating: Vec<f64> = (0..1000).map(|t| if t % 2 == 0 { 1.0 } else { -1.0 }).collect();
/// assert!(high_band_fraction(&alternating, 0.5) > 0.99);
/// ```
pub fn high_band_fraction(x: &[f64], fraction: f64) -> f64 {
    let n = x.len();
    if n < 4 {
        return 0.0;
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    let windowed: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(t, v)| {
            let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * t as f64 / n as f64).cos();
            (v - mean) * w
        })
        .collect();
    let energy = hysid_spectral::energy_spectrum(&windowed);
    let cut = fraction * n as f64 / 2.0;
    let (mut high, mut total) = (0.0, 0.0);
    for (k, e) in energy.iter().enumerate().skip(1) {
        total += e;
        if k as f64 > cut {
            high += e;
        }
    }
    if total > 0.0 {
        high / total
    } else {
        0.0
    }
}
