//! Bring your own grey-box model: a piezo-driven stage written as a [`StateSpaceModel`],
//! simulated, then identified from noisy data by output error — MATLAB's `idnlgrey` +
//! `nlgreyest` + `present` in a page of Rust.
//!
//! The stage: a mass on a flexure, driven by a piezo stack whose force carries a Dhaouadi
//! (Duhem) hysteresis term h,
//!
//! ```text
//! m ẍ + c ẋ + k x + h = g·u,      ḣ = A ẋ − α |ẋ| h,      y = x
//! ```
//!
//! (Dhaouadi, Ghorbel, Gandhi, "A new dynamic model of hysteresis in harmonic drives", IEEE
//! Trans. Industrial Electronics 50(6), 2003; the same hysteresis state as the actuator of
//! Gunnar et al. 2006). The drive gain g is known and held fixed: with it free, m, c, k, A and
//! g could all be scaled together without changing the output.
//!
//! The model gives only f and h — no Jacobians — so the estimator differentiates the
//! simulation numerically, one simulation per free parameter, in parallel.
//!
//! Run with `cargo run --release -p hysid --example own_model`.

use hysid::data::{Channel, IdData};
use hysid::identify::greybox::{GreyBox, GreyBoxEstimation, InitialStates};
use hysid::identify::OutputErrorModel;
use hysid::model::greybox::{Simulation, StateSpaceModel};
use hysid::model::{Parameter, ParameterSet};
use hysid::numerics::signal::{gaussian_noise, multisine};
use hysid::numerics::Control;
use std::sync::Arc;

/// The piezo stage (see the crate docs above). States x = (position, velocity, h).
struct PiezoStage;

impl StateSpaceModel for PiezoStage {
    fn kind(&self) -> &'static str {
        "piezo_stage"
    }

    fn states(&self) -> Vec<Channel> {
        vec![
            Channel::new("x").with_unit("m"),
            Channel::new("xd").with_unit("m/s"),
            Channel::new("h").with_unit("N"),
        ]
    }

    fn inputs(&self) -> Vec<Channel> {
        vec![Channel::new("u").with_unit("V")]
    }

    fn outputs(&self) -> Vec<Channel> {
        vec![Channel::new("x").with_unit("m")]
    }

    /// The true values of this example; bounds keep the search physical.
    fn parameters(&self) -> ParameterSet {
        ParameterSet::new(vec![
            Parameter::new("m", 1e-2).unit("kg").bounds(1e-4, 1.0),
            Parameter::new("c", 5.0).unit("N*s/m").bounds(0.0, 1e3),
            Parameter::new("k", 1.6e4).unit("N/m").bounds(1.0, 1e7),
            Parameter::new("A", 4e3).unit("N/m").bounds(0.0, 1e7),
            Parameter::new("alpha", 2e2).unit("1/m").bounds(0.0, 1e6),
            Parameter::new("g", 1.0).unit("N/V").fixed(true),
        ])
        .expect("distinct names")
    }

    fn rhs(&self, _t: f64, x: &[f64], u: &[f64], theta: &[f64], dx: &mut [f64]) {
        let [m, c, k, a, alpha, g] = [theta[0], theta[1], theta[2], theta[3], theta[4], theta[5]];
        let (pos, vel, h) = (x[0], x[1], x[2]);
        dx[0] = vel;
        dx[1] = (g * u[0] - c * vel - k * pos - h) / m;
        dx[2] = a * vel - alpha * vel.abs() * h;
    }

    fn output(&self, x: &[f64], _u: &[f64], _theta: &[f64], y: &mut [f64]) {
        y[0] = x[0];
    }
}

fn main() -> hysid::Result<()> {
    let model = PiezoStage;
    let truth = model.parameters();

    // Excitation: two periods of a 1–80 Hz random-phase multisine, 60 V RMS, at 2 kHz.
    let fs = 2000.0;
    let u = multisine(4000, 2, fs, 1.0, 80.0, 60.0, 7)?;
    let n = u.len();

    // "Measured" position: the model's response plus 1 % white noise (seeded).
    let input_only = IdData::siso(1.0 / fs, "u", u.clone(), "x", vec![0.0; n])?;
    let structure = GreyBox::new(
        Arc::new(PiezoStage),
        &input_only,
        Simulation::default(),
        InitialStates::at_rest(3, 1),
    )?;
    let mut y = vec![vec![0.0; n]];
    let theta = structure.parameter_set(&truth).values();
    structure.simulate(&theta, &input_only, 0, &mut y)?;
    let rms = (y[0].iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
    let noise = gaussian_noise(n, 0.01 * rms, 8)?;
    let measured: Vec<f64> = y[0].iter().zip(&noise).map(|(a, b)| a + b).collect();
    let data = IdData::siso(1.0 / fs, "u", u, "x", measured)?;

    // Start every free parameter well away from the truth.
    let mut start = truth.clone();
    for (name, factor) in [
        ("m", 1.5),
        ("c", 0.5),
        ("k", 0.7),
        ("A", 2.0),
        ("alpha", 0.5),
    ] {
        start.by_name_mut(name)?.value *= factor;
    }

    let fit = GreyBoxEstimation::default().estimate(
        Arc::new(PiezoStage),
        &data,
        &start,
        InitialStates::at_rest(3, 1),
        &mut |it| {
            eprintln!("  iteration {:>2}: cost {:.4e}", it.iteration, it.cost);
            Control::Continue
        },
    )?;

    // A `present`-like table: truth, start, estimate ± standard deviation.
    let fit = &fit.fit;
    println!(
        "\n{:<6} {:>12} {:>12} {:>12} {:>11}",
        "name", "true", "start", "estimate", "std"
    );
    for (i, p) in fit.parameters.iter().enumerate().take(truth.len()) {
        println!(
            "{:<6} {:>12.5e} {:>12.5e} {:>12.5e} {:>11.3e}{}",
            p.name,
            truth.get(i).value,
            start.get(i).value,
            p.value,
            fit.std()[i],
            if p.fixed { "  (fixed)" } else { "" }
        );
    }
    println!(
        "\nfit {:.3} %, {} iterations, stopped: {}",
        fit.fit_percent[0][0], fit.report.iterations, fit.report.termination
    );
    Ok(())
}
