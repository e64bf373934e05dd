//! Test signals and checks shared by the operators' tests.

use hysid::model::ParameterSet;
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use rand_distr::Normal;

/// A decaying sine with a faster ripple that reverses the direction inside the big loops
/// (nested minor loops): u(t) = A·((1 − 0.7t)·sin 6πt + 0.25·sin 34πt), t ∈ [0, 1).
pub fn nested_loops(n: usize, amplitude: f64) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            let tau = std::f64::consts::TAU;
            amplitude * ((1.0 - 0.7 * t) * (tau * 3.0 * t).sin() + 0.25 * (tau * 17.0 * t).sin())
        })
        .collect()
}

/// A seeded xorshift generator (Marsaglia 2003, shifts 13, 7, 17) of numbers in [0, 1) from
/// the top 53 bits: the same sequence on every machine, for references no model produced.
pub fn xorshift_uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `y` plus white Gaussian noise at the given SNR (dB) relative to y's spread, seeded.
pub fn with_noise(y: &[f64], snr_db: f64, seed: u64) -> Vec<f64> {
    let sd = hysid::numerics::metrics::std_dev(y) * 10f64.powf(-snr_db / 20.0);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let normal = Normal::new(0.0, sd).unwrap();
    y.iter().map(|v| v + rng.sample(normal)).collect()
}

/// Of the fitted parameters that have a standard deviation, how many lie within 3σ of the
/// truth: (inside, with a standard deviation).
pub fn within_three_sigma(
    truth: &ParameterSet,
    fitted: &ParameterSet,
    std: &[Option<f64>],
) -> (usize, usize) {
    let mut counts = (0, 0);
    for ((p, q), s) in truth.iter().zip(fitted.iter()).zip(std) {
        if let Some(s) = s {
            counts.1 += 1;
            counts.0 += usize::from((p.value - q.value).abs() <= 3.0 * s);
        }
    }
    counts
}

/// The driver's training input: [`nested_loops`] (a decaying sine with nested reversals).
pub fn training_input(n: usize, amplitude: f64) -> Vec<f64> {
    nested_loops(n, amplitude)
}

/// The driver's validation input: a growing sine with another ripple,
/// u(t) = A·((0.4 + 0.6t)·sin(5πt + 0.4) + 0.2·sin(26πt + 1)), t ∈ [0, 1).
pub fn validation_input(n: usize, amplitude: f64) -> Vec<f64> {
    let tau = std::f64::consts::TAU;
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            amplitude
                * ((0.4 + 0.6 * t) * (tau * 2.5 * t + 0.4).sin()
                    + 0.2 * (tau * 13.0 * t + 1.0).sin())
        })
        .collect()
}

/// Columns `input` and `output` (0-based) of the CSV file at `path`, relative to this
/// crate's folder, its header row skipped.
fn csv_pair(path: &str, input: usize, output: usize) -> (Vec<f64>, Vec<f64>) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .skip(1)
        .map(|line| {
            let cells: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
            (cells[input], cells[output])
        })
        .unzip()
}

/// The piezo record of `data/piezo` (2 000 samples of the real 150 V, 1 Hz record):
/// (voltage in V, displacement in µm).
pub fn piezo_record() -> (Vec<f64>, Vec<f64>) {
    csv_pair("../../data/piezo/piezo_150V_1Hz.csv", 1, 2)
}

/// Loop `k` (1–4, amplitudes ≈ 8, 16, 40, 80 A/m) of the vendored Mn-Zn ferrite record
/// (`data/ferrite`): (H in A/m, B in T), 129 samples from +Hₘₐₓ down to −Hₘₐₓ and back.
pub fn ferrite_loop(k: usize) -> (Vec<f64>, Vec<f64>) {
    csv_pair(
        "../../data/ferrite/mnzn_ferrite_bh_loops.csv",
        2 * (k - 1),
        2 * k - 1,
    )
}

/// The simulated magnet record of `tests/fixtures/records` (its README): 170 set points,
/// (current in A, field in T).
pub fn magnet_set_points() -> (Vec<f64>, Vec<f64>) {
    csv_pair("tests/fixtures/records/magnet_set_points.csv", 1, 2)
}

/// The linear-in-weights families: their weights solved by NNLS for a fixed structure,
/// their orientation read from the data (`linear_support`).
pub const LINEAR_IN_WEIGHTS: [hysid::identify::operators::Family; 6] = {
    use hysid::identify::operators::Family;
    [
        Family::Pi,
        Family::Gpi,
        Family::MaxwellSlip,
        Family::Backlash,
        Family::Preisach,
        Family::Kp,
    ]
};
