//! Writes the records of the differential-operator benchmark (`bench/operator_fits.sh`) and
//! of the driver's accuracy tests (`crates/hysid-tests/tests/library/unit/identify/operators/`):
//! for each case a training record `NAME.csv` and a validation record `NAME_val.csv`
//! (columns u, y), 20 000 samples each, output noise at 40 dB SNR, seeded. The same
//! definitions are the tests' (`differential_cases.rs` there).
//!
//! Cases: `bouc-wen`, `duhem`, `dahl`, `jiles-atherton` (each family's own operator), and
//! `bouc-wen-asym` (a piezo-form Bouc–Wen loop with an extra asymmetry term δ·u in the rate,
//! which the symmetric Bouc–Wen can only approximate).
//!
//! Run: `cargo run --release -p hysid --example differential_records -- OUT_DIR`.

use hysid::model::operators::differential::{self, InputOde};
use hysid::model::operators::{
    BoucWen, Dahl, Duhem, HysteresisOperator, JilesAtherton, LoopOrientation,
};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use rand_distr::Normal;
use std::fmt::Write;

const N: usize = 20_000;
const TAU: f64 = std::f64::consts::TAU;

/// Training input: a decaying sine with a faster ripple that reverses inside the big loops.
fn training(amplitude: f64) -> Vec<f64> {
    (0..N)
        .map(|k| {
            let t = k as f64 / N as f64;
            amplitude * ((1.0 - 0.7 * t) * (TAU * 3.0 * t).sin() + 0.25 * (TAU * 17.0 * t).sin())
        })
        .collect()
}

/// Validation input: a growing sine with another ripple.
fn validation(amplitude: f64) -> Vec<f64> {
    (0..N)
        .map(|k| {
            let t = k as f64 / N as f64;
            amplitude
                * ((0.4 + 0.6 * t) * (TAU * 2.5 * t + 0.4).sin()
                    + 0.2 * (TAU * 13.0 * t + 1.0).sin())
        })
        .collect()
}

fn with_noise(y: &[f64], seed: u64) -> Vec<f64> {
    let sd = hysid::numerics::metrics::std_dev(y) * 10f64.powf(-40.0 / 20.0);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let normal = Normal::new(0.0, sd).unwrap();
    y.iter().map(|v| v + rng.sample(normal)).collect()
}

/// dw/du = 1 − (β·sign(du·w) + γ)|w| + δ·u, y = k_x·u + k_w·w (module doc).
struct AsymmetricBoucWen {
    kx: f64,
    kw: f64,
    beta: f64,
    gamma: f64,
    delta: f64,
}

impl InputOde for AsymmetricBoucWen {
    fn slope(&self, u: f64, w: f64, d: f64) -> f64 {
        let s = if d * w >= 0.0 { 1.0 } else { -1.0 };
        1.0 - (self.beta * s + self.gamma) * w.abs() + self.delta * u
    }
    fn output(&self, u: f64, w: f64) -> f64 {
        self.kx * u + self.kw * w
    }
    fn initial_state(&self) -> f64 {
        0.0
    }
    fn state_scale(&self) -> f64 {
        1.0 / (self.beta + self.gamma)
    }
    fn max_substep(&self) -> f64 {
        0.25 / (self.beta + self.gamma)
    }
    fn inversion_span(&self) -> f64 {
        1e3
    }
}

/// A plant: input to noise-free output.
type Plant = Box<dyn Fn(&[f64]) -> Vec<f64>>;

fn write(dir: &str, name: &str, u: &[f64], y: &[f64]) {
    let mut text = String::from("u,y\n");
    for (u, y) in u.iter().zip(y) {
        writeln!(text, "{u},{y}").unwrap();
    }
    std::fs::write(format!("{dir}/{name}.csv"), text).unwrap();
}

fn main() {
    let dir = std::env::args().nth(1).unwrap_or_else(|| ".".into());
    std::fs::create_dir_all(&dir).unwrap();
    let mut bw = BoucWen::new(0.8, 1.2, 2.0, 0.5, 1.0).unwrap();
    bw.w0 = 0.05;
    let mut duhem = Duhem::new(3.0, 1.5, 0.2, 0.4).unwrap();
    duhem.y0 = -0.1;
    let mut dahl = Dahl::new(12.0, 2.0, 1.8).unwrap();
    dahl.f0 = 0.3;
    dahl.orientation = LoopOrientation::CounterClockwise;
    let mut ja = JilesAtherton::new(2.5e5, 8.0, 5.0, 0.3, 5e-6).unwrap();
    ja.m0 = 1e4;
    let asym = AsymmetricBoucWen {
        kx: 1.0,
        kw: -0.6,
        beta: 2.0,
        gamma: 0.4,
        delta: 0.5,
    };
    let cases: Vec<(&str, Plant, f64, u64)> = vec![
        (
            "bouc-wen",
            Box::new(move |u| bw.simulate(u).unwrap()),
            1.5,
            1,
        ),
        (
            "duhem",
            Box::new(move |u| duhem.simulate(u).unwrap()),
            1.5,
            2,
        ),
        ("dahl", Box::new(move |u| dahl.simulate(u).unwrap()), 1.0, 3),
        (
            "jiles-atherton",
            Box::new(move |u| ja.simulate(u).unwrap()),
            60.0,
            4,
        ),
        (
            "bouc-wen-asym",
            Box::new(move |u| differential::simulate(&asym, u).unwrap()),
            1.5,
            5,
        ),
    ];
    for (name, plant, amplitude, seed) in cases {
        let u = training(amplitude);
        write(&dir, name, &u, &with_noise(&plant(&u), seed));
        let v = validation(amplitude);
        write(
            &dir,
            &format!("{name}_val"),
            &v,
            &with_noise(&plant(&v), seed + 100),
        );
    }
}
