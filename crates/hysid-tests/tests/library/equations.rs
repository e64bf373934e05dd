//! Equation-file models (`examples/equations/*.toml`) in the grey-box engine: the same fit and
//! the same forward sensitivities as the built-in models they transcribe, sensitivities
//! against finite differences, a Duffing round trip with and without noise, the cascaded
//! tanks benchmark, and the saved-model round trip.

use hysid::data::{CsvSpec, IdData};
use hysid::identify::greybox::{GreyBox, GreyBoxEstimation, InitialStates};
use hysid::identify::OutputErrorModel;
use hysid::model::greybox::equation_model::EquationStateSpace;
use hysid::model::greybox::models::{ActuatorFixed, BoucWen};
use hysid::model::greybox::native::Evaluator;
use hysid::model::greybox::simulate::{simulate, InputTrack};
use hysid::model::greybox::{InputInterpolation, Integrator, Simulation, StateSpaceModel};
use hysid::model::saved::FittedEquations;
use hysid::model::saved::{FittedModel, SavedModel};
use hysid::model::ParameterSet;
use hysid::numerics::signal::{gaussian_noise, multisine};
use hysid::numerics::Control;
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn example(name: &str) -> EquationStateSpace {
    EquationStateSpace::load(&root().join(format!("examples/equations/{name}.toml"))).unwrap()
}

fn csv(path: &str, input: &str, output: &str) -> IdData {
    let spec = CsvSpec {
        inputs: vec![input.into()],
        outputs: vec![output.into()],
        time: None,
        ts: None,
        ..CsvSpec::default()
    };
    IdData::from_csv(&root().join(path), &spec).unwrap()
}

fn rk4(substeps: usize, interpolation: InputInterpolation) -> Simulation {
    Simulation {
        integrator: Integrator::Rk4 { substeps },
        interpolation,
    }
}

/// The output and its sensitivities to the parameters `free` (indices into the structure's
/// parameter vector), one row per sample.
fn sensitivities(
    gb: &GreyBox,
    data: &IdData,
    theta: &[f64],
    free: &[usize],
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let n = data.n_samples();
    let (mut y, mut s) = (vec![0.0; n], vec![vec![0.0; free.len()]; n]);
    gb.simulate_sensitivities(theta, data, 0, free, &mut |k, yk, dy| {
        y[k] = yk[0];
        s[k].copy_from_slice(dy);
        std::ops::ControlFlow::Continue(())
    })
    .expect("analytic sensitivities")
    .unwrap();
    (y, s)
}

/// Free parameters of the structure: the model's free ones and every initial state.
fn free_of(gb: &GreyBox) -> Vec<usize> {
    let params = gb.parameters();
    let p = gb.model().parameters().len();
    (0..params.len())
        .filter(|&i| !params.get(i).fixed || i >= p)
        .collect()
}

/// One benchmark-like multisine period (5–150 Hz, RMS 50 N, 750 Hz) for Bouc–Wen.
fn bouc_wen_case() -> (IdData, Vec<f64>) {
    let u = multisine(512, 1, 750.0, 5.0, 150.0, 50.0, 3).unwrap();
    let data = IdData::siso(1.0 / 750.0, "u", u, "y", vec![0.0; 512]).unwrap();
    (data, vec![1e-4, 0.01, 3.0])
}

/// The actuator driven so that the motor never stops: from 2 rad/s with the hysteresis torque
/// saturated (x4 = A/α), the torque that keeps x1 = 2t moving quasi-statically,
/// τ = Fc + 2 Fv + A/α + k1·2t + k2·(2t)³ (nominal parameters), over 0.5 s at 1 kHz.
fn actuator_case() -> (IdData, Vec<f64>) {
    let th = ActuatorFixed.parameters().values();
    let (fv, fc, k1, k2, alpha, a) = (th[1], th[2], th[3], th[4], th[5], th[6]);
    let ts = 1e-3;
    let u: Vec<f64> = (0..500)
        .map(|k| {
            let x = 2.0 * k as f64 * ts;
            fc + 2.0 * fv + a / alpha + k1 * x + k2 * x * x * x
        })
        .collect();
    let data = IdData::siso(ts, "tau", u, "x1", vec![0.0; 500]).unwrap();
    (data, vec![0.0, 2.0, a / alpha])
}

/// The velocity state (index `v`) at every sample of a simulation of `model`.
fn velocities(model: &dyn StateSpaceModel, data: &IdData, x0: &[f64], v: usize) -> Vec<f64> {
    let sim = rk4(4, InputInterpolation::Linear);
    let track = InputTrack::new(&[data.experiment(0).input(0)], &sim).unwrap();
    let theta = model.parameters().values();
    let mut out = Vec::new();
    simulate(
        model,
        &theta,
        x0,
        &track,
        data.ts(),
        sim.integrator,
        |_, x| out.push(x[v]),
    )
    .unwrap();
    out
}

fn bind(model: Arc<dyn StateSpaceModel>, data: &IdData, x0: &[f64]) -> GreyBox {
    let initial = InitialStates {
        values: vec![x0.to_vec()],
        estimated: vec![true; x0.len()],
    };
    GreyBox::new(model, data, rk4(4, InputInterpolation::Linear), initial).unwrap()
}

/// The largest |a − b| over the largest |b|, column by column, over all columns.
fn worst_relative(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    (0..b[0].len())
        .map(|c| {
            let scale = b.iter().map(|r| r[c].abs()).fold(0.0, f64::max).max(1e-300);
            a.iter()
                .zip(b)
                .map(|(x, y)| (x[c] - y[c]).abs())
                .fold(0.0, f64::max)
                / scale
        })
        .fold(0.0, f64::max)
}

/// The equation files of Bouc–Wen and of the actuator give the built-in models' forward
/// sensitivities (parameters and initial states) to rounding, on simulations where the
/// actuator's motor never stops (where the built-in model's stick–slip handling and the
/// file's plain sign() coincide).
#[test]
fn sensitivities_equal_the_built_in_models() {
    let (bw_data, bw_x0) = bouc_wen_case();
    let (act_data, act_x0) = actuator_case();
    let v = velocities(&ActuatorFixed, &act_data, &act_x0, 1);
    let slowest = v.iter().fold(f64::INFINITY, |m, x| m.min(*x));
    assert!(slowest > 0.5, "the motor must keep moving: {slowest} rad/s");
    // (built-in model, its equation file, record, initial state)
    type Case = (
        Arc<dyn StateSpaceModel>,
        Arc<dyn StateSpaceModel>,
        IdData,
        Vec<f64>,
    );
    let cases: Vec<Case> = vec![
        (
            Arc::new(BoucWen),
            Arc::new(example("bouc_wen")),
            bw_data,
            bw_x0,
        ),
        (
            Arc::new(ActuatorFixed),
            Arc::new(example("actuator_fixed")),
            act_data,
            act_x0,
        ),
    ];
    for (builtin, file, data, x0) in cases {
        assert_eq!(builtin.parameters().names(), file.parameters().names());
        let (gb_b, gb_f) = (bind(builtin.clone(), &data, &x0), bind(file, &data, &x0));
        let theta = gb_b.parameters().values();
        let free = free_of(&gb_b);
        assert_eq!(free, free_of(&gb_f));
        let (yb, sb) = sensitivities(&gb_b, &data, &theta, &free);
        let (yf, sf) = sensitivities(&gb_f, &data, &theta, &free);
        let ys = yb.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let dy = yb
            .iter()
            .zip(&yf)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            dy <= 1e-12 * ys,
            "{}: outputs differ by {dy:e}",
            builtin.kind()
        );
        let worst = worst_relative(&sf, &sb);
        // Rounding only: the two evaluate the same expressions in a different order.
        assert!(
            worst <= 1e-7,
            "{}: sensitivities differ by {worst:e}",
            builtin.kind()
        );
    }
}

/// The cascaded tanks through all their regimes: 3.5 V ± 3.2 V on the pump (below its dead
/// zone u0 = 0.5 V at the troughs, overflowing the upper tank at the crests), 512 samples
/// of 4 s.
fn tanks_case() -> (IdData, Vec<f64>) {
    let u: Vec<f64> = (0..512)
        .map(|k| 3.5 + 3.2 * (std::f64::consts::TAU * k as f64 / 128.0).sin())
        .collect();
    (
        IdData::siso(4.0, "u", u, "y", vec![0.0; 512]).unwrap(),
        vec![5.0, 5.2],
    )
}

/// A Duffing record: a 0.05–2 Hz multisine of RMS 1 N at 20 Hz, 2048 samples.
fn duffing_input(seed: u64) -> IdData {
    let u = multisine(2048, 1, 20.0, 0.05, 2.0, 1.0, seed).unwrap();
    IdData::siso(0.05, "u", u, "y", vec![0.0; 2048]).unwrap()
}

/// ∂y/∂θᵢ of the simulation `sim` at θ by Ridders' extrapolation of central differences
/// (C.J.F. Ridders, "Accurate computation of F′(x) and F′(x)F″(x)", Advances in Engineering
/// Software 4(2), 1982): D(h) = (y(θ + h eᵢ) − y(θ − h eᵢ))/2h for h = h₀, h₀/1.4, h₀/1.4², …
/// is extrapolated to h → 0 in a Neville tableau (D(h) = D + c₂h² + c₄h⁴ + …, so each
/// column cancels one more power), and the entry whose change from its neighbours is the
/// smallest is kept. This picks the step per parameter: large enough that the rounding
/// error ε·|y|/h stays small even for a column that is tiny against |y|/|θ|, small enough
/// for the truncation error, without hand tuning. Returns the derivative and the
/// tableau's error estimate (largest absolute change).
fn ridders(sim: &dyn Fn(&[f64]) -> Vec<f64>, theta: &[f64], i: usize, h0: f64) -> (Vec<f64>, f64) {
    const SHRINK: f64 = 1.4;
    const LEVELS: usize = 10;
    let central = |h: f64| {
        let (mut hi, mut lo) = (theta.to_vec(), theta.to_vec());
        hi[i] += h;
        lo[i] -= h;
        let (a, b) = (sim(&hi), sim(&lo));
        a.iter()
            .zip(&b)
            .map(|(p, q)| (p - q) / (2.0 * h))
            .collect::<Vec<f64>>()
    };
    let gap = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()))
    };
    let mut h = h0;
    // tableau[j]: the row of the previous step size, extrapolated j times.
    let mut previous: Vec<Vec<f64>> = vec![central(h)];
    let (mut best, mut error) = (previous[0].clone(), f64::INFINITY);
    for _ in 1..LEVELS {
        h /= SHRINK;
        let mut row = vec![central(h)];
        let mut factor = SHRINK * SHRINK;
        for j in 1..=previous.len() {
            let next: Vec<f64> = row[j - 1]
                .iter()
                .zip(&previous[j - 1])
                .map(|(a, b)| (a * factor - b) / (factor - 1.0))
                .collect();
            factor *= SHRINK * SHRINK;
            let change = gap(&next, &row[j - 1]).max(gap(&next, &previous[j - 1]));
            if change <= error {
                error = change;
                best = next.clone();
            }
            row.push(next);
        }
        let last = previous.len();
        // Higher orders stopped helping: rounding has taken over.
        if gap(&row[last], &previous[last - 1]) >= 2.0 * error {
            break;
        }
        previous = row;
    }
    (best, error)
}

/// The reference derivative of column `i`: Ridders' extrapolation from first steps of
/// 10⁻², 10⁻³, 10⁻⁴ and 10⁻⁵ of max(|θᵢ|, 0.01), whichever estimates the smallest error.
/// Several are tried because y(θ) is only piecewise smooth: a large step can cross a kink
/// of a non-smooth model (Bouc–Wen's |ẏ| and |z| switch at a stage of another RK4 step), or
/// leave the region where the curvature is moderate (the actuator's inertia column), and the
/// tableau then reports a large error, while a small step suffers rounding on a column
/// that is tiny against |y|/|θ|.
fn fd_reference(sim: &dyn Fn(&[f64]) -> Vec<f64>, theta: &[f64], i: usize) -> (Vec<f64>, f64) {
    let scale = theta[i].abs().max(1e-2);
    [1e-2, 1e-3, 1e-4, 1e-5]
        .iter()
        .map(|h| ridders(sim, theta, i, h * scale))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("four steps")
}

/// Every example's forward sensitivities (parameters and initial states) equal the
/// derivative of the same simulation by extrapolated central differences
/// ([`fd_reference`]) to 1e-6, column by column in the max norm: ‖S_fd − S‖∞ ≤ 1e-6·‖S‖∞
/// for each parameter column. Plain central differences at one step do not reach this on
/// the actuator: its test record drives the motor quasi-statically, so the output hardly
/// depends on the inertia J (J·∂y/∂J ≈ 1e-5 of |y|) — at a relative step of 1e-6 the
/// rounding error ε·|y|/h is 1e-5 of that column, at 1e-4 the truncation error is 3e-3 of
/// it. The exact sensitivities were right; the reference was not accurate enough.
#[test]
fn sensitivities_of_every_example_match_finite_differences() {
    let (bw, bw_x0) = bouc_wen_case();
    let (act, act_x0) = actuator_case();
    let (tanks, tanks_x0) = tanks_case();
    let upper = velocities(&example("cascaded_tanks"), &tanks, &tanks_x0, 0);
    let brim = upper.iter().filter(|&&x1| x1 > 10.0).count();
    assert!(brim > 10, "the upper tank must overflow: {brim} samples");
    let cases = [
        ("duffing", duffing_input(1), vec![0.1, 0.0]),
        ("bouc_wen", bw, bw_x0),
        ("actuator_fixed", act, act_x0),
        ("cascaded_tanks", tanks, tanks_x0),
        ("backlash_first_order", backlash_record(3), vec![0.05, 0.0]),
    ];
    for (name, data, x0) in cases {
        let model = Arc::new(example(name));
        let gb = bind(model, &data, &x0);
        let mut theta = gb.parameters().values();
        if name == "duffing" {
            theta[3] = 0.5; // k3: exercise the cubic term
        }
        let free = free_of(&gb);
        let (_, analytic) = sensitivities(&gb, &data, &theta, &free);
        let n = data.n_samples();
        let sim = |th: &[f64]| {
            let mut y = vec![vec![0.0; n]];
            gb.simulate(th, &data, 0, &mut y).unwrap();
            y.remove(0)
        };
        let mut fd = vec![vec![0.0; free.len()]; n];
        for (c, &i) in free.iter().enumerate() {
            let (column, estimate) = fd_reference(&sim, &theta, i);
            let size = analytic.iter().fold(0.0f64, |m, r| m.max(r[c].abs()));
            // The reference must itself be good to a fifth of the tolerance.
            assert!(
                estimate <= 2e-7 * size,
                "{name} column {c}: reference error {estimate:e} of {size:e}"
            );
            for (row, v) in fd.iter_mut().zip(column) {
                row[c] = v;
            }
        }
        let worst = worst_relative(&fd, &analytic);
        println!("{name}: worst column difference to extrapolated differences {worst:.1e}");
        assert!(worst <= 1e-6, "{name}: {worst:e}");
    }
}

/// Duffing's true parameters (m, c, k, k3).
const DUFFING: [f64; 4] = [1.0, 0.2, 1.5, 0.8];

/// The Duffing record of `seed` simulated with [`DUFFING`] from rest, with noise of
/// `noise_std`·rms(y) added (seeded).
fn duffing_record(seed: u64, relative_noise: f64) -> IdData {
    let input = duffing_input(seed);
    let model = example("duffing");
    let gb = GreyBox::new(
        Arc::new(model),
        &input,
        rk4(4, InputInterpolation::ZeroOrderHold),
        InitialStates::at_rest(2, 1),
    )
    .unwrap();
    let mut theta = DUFFING.to_vec();
    theta.extend([0.0, 0.0]);
    let mut y = vec![vec![0.0; input.n_samples()]];
    gb.simulate(&theta, &input, 0, &mut y).unwrap();
    let rms = (y[0].iter().map(|v| v * v).sum::<f64>() / y[0].len() as f64).sqrt();
    let noise = gaussian_noise(y[0].len(), relative_noise * rms, 1000 + seed).unwrap();
    let noisy: Vec<f64> = y[0].iter().zip(&noise).map(|(a, e)| a + e).collect();
    IdData::siso(
        input.ts(),
        "u",
        input.experiment(0).input(0).to_vec(),
        "y",
        noisy,
    )
    .unwrap()
}

/// Fits Duffing (all four parameters free) from 30 % off the truth.
fn fit_duffing(data: &IdData) -> (Vec<f64>, Vec<f64>) {
    let model = example("duffing");
    let mut start: ParameterSet = model.parameters();
    for (i, f) in [1.3, 0.7, 1.3, 0.7].iter().enumerate() {
        start.get_mut(i).value = DUFFING[i] * f;
    }
    let fit = GreyBoxEstimation {
        simulation: rk4(4, InputInterpolation::ZeroOrderHold),
        ..Default::default()
    }
    .estimate(
        Arc::new(model),
        data,
        &start,
        InitialStates::at_rest(2, 1),
        &mut |_| Control::Continue,
    )
    .unwrap();
    (
        fit.fit.parameters.values()[..4].to_vec(),
        fit.fit.std()[..4].to_vec(),
    )
}

/// Noise-free, Duffing's parameters come back to 1e-8; at an SNR of 40 dB (noise 1 % of the
/// output's RMS) at least 90 % of the (seed, parameter) pairs over 5 seeds lie within 3σ of
/// the truth.
#[test]
#[ignore = "long (several seconds): run by `cargo test --release -- --ignored` and CI"]
fn duffing_parameters_are_recovered() {
    let (clean, _) = fit_duffing(&duffing_record(1, 0.0));
    for (e, t) in clean.iter().zip(DUFFING) {
        assert!(((e - t) / t).abs() < 1e-8, "clean: {clean:?}");
    }
    let mut inside = 0;
    let mut total = 0;
    for seed in 1..=5 {
        let (est, std) = fit_duffing(&duffing_record(seed, 0.01));
        for i in 0..4 {
            total += 1;
            inside += usize::from((est[i] - DUFFING[i]).abs() <= 3.0 * std[i]);
            assert!(
                std[i] > 0.0 && std[i] < 0.05 * DUFFING[i],
                "seed {seed}: {std:?}"
            );
        }
    }
    assert!(10 * inside >= 9 * total, "{inside} of {total} within 3σ");
}

/// Cascaded tanks: fitted on the estimation record (initial levels estimated), simulated on
/// the validation record from the same initial state, as the benchmark prescribes; the
/// validation RMSE this reaches, 0.338 V (published: best linear approximation 0.75 V, best
/// black-box 0.34 V, grey-box with overflow 0.18 V). The pump's dead zone u0 (fitted
/// 0.79 V) and the estimated overflow level are what bring it down from 0.515 V.
#[test]
#[ignore = "long (several seconds): run by `cargo test --release -- --ignored` and CI"]
fn cascaded_tanks_validation_rmse() {
    let est = csv("data/cascaded-tanks/estimation.csv", "u_V", "y_V");
    let val = csv("data/cascaded-tanks/validation.csv", "u_V", "y_V");
    let model = example("cascaded_tanks");
    let initial = InitialStates::of_equations(&model, 1, &[]);
    let simulation = rk4(4, InputInterpolation::ZeroOrderHold);
    let fit = GreyBoxEstimation {
        simulation,
        starts: 8,
        seed: 1,
        ..Default::default()
    }
    .estimate(
        Arc::new(model.clone()),
        &est,
        &model.parameters(),
        initial,
        &mut |_| Control::Continue,
    )
    .unwrap();
    let values = fit.fit.parameters.values();
    let p = model.parameters().len();
    let fitted = FittedModel::Equations(FittedEquations {
        equations: model.source().to_string(),
        parameters: {
            let mut ps = model.parameters();
            ps.set_values(&values[..p]);
            ps
        },
        std: fit.fit.std()[..p].to_vec(),
        simulation,
        initial_state: values[p..p + 2].to_vec(),
        evaluator: hysid::model::greybox::native::Evaluator::Auto,
    });
    let y = fitted
        .simulate(&[val.experiment(0).input(0)], val.ts(), None)
        .unwrap();
    let measured = val.experiment(0).output(0);
    let rmse = (y[0]
        .iter()
        .zip(measured)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        / measured.len() as f64)
        .sqrt();
    println!(
        "cascaded tanks: estimation RMSE {:.4} V, validation RMSE {rmse:.4} V, θ = {values:?}",
        fit.fit.mse[0][0].sqrt()
    );
    assert!((rmse - 0.3384).abs() < 0.005, "validation RMSE {rmse} V");
}

/// A fitted equation model saved to JSON comes back equal and simulates the same outputs.
#[test]
fn saved_equation_models_round_trip() {
    let model = example("duffing");
    let fitted = FittedModel::Equations(FittedEquations {
        equations: model.source().to_string(),
        parameters: {
            let mut ps = model.parameters();
            ps.set_values(&DUFFING);
            ps
        },
        std: vec![0.01, 0.02, f64::NAN, 0.04],
        simulation: rk4(4, InputInterpolation::ZeroOrderHold),
        initial_state: vec![0.0, 0.0],
        evaluator: hysid::model::greybox::native::Evaluator::Auto,
    });
    let json = serde_json::to_string(&fitted.to_file()).unwrap();
    assert!(json.contains("\"kind\":\"equations\"") && json.contains("\"equations\":\"#"));
    let back = FittedModel::from_file(&serde_json::from_str(&json).unwrap()).unwrap();
    let data = duffing_record(2, 0.0);
    let u = [data.experiment(0).input(0)];
    let (a, b) = (
        fitted.simulate(&u, data.ts(), None).unwrap(),
        back.simulate(&u, data.ts(), None).unwrap(),
    );
    assert_eq!(a, b);
    let truth = data.experiment(0).output(0);
    assert!(a[0].iter().zip(truth).all(|(x, y)| (x - y).abs() < 1e-12));
    // A corrupted text is reported with its line and column.
    let mut file = fitted.to_file();
    let SavedModel::Equations(saved) = &mut file.model else {
        panic!("not an equations model: {}", file.kind())
    };
    saved.equations = model.source().replace("c*v", "cc*v");
    let e = FittedModel::from_file(&file).unwrap_err().to_string();
    assert!(
        e.contains("line ") && e.contains("unknown name 'cc'"),
        "{e}"
    );
}

/// The discrete-time backlash example's true parameters (r, a, b).
const BACKLASH: [f64; 3] = [0.2, 0.9, 0.1];

/// A record for the discrete backlash model: a 0.2–5 Hz multisine of RMS 1 rad at 100 Hz
/// (reversals of every size, so the play engages and releases), 1024 samples, with the
/// output simulated at [`BACKLASH`] from rest.
fn backlash_record(seed: u64) -> IdData {
    let u = multisine(1024, 1, 100.0, 0.2, 5.0, 1.0, seed).unwrap();
    let input = IdData::siso(0.01, "u", u.clone(), "y", vec![0.0; 1024]).unwrap();
    let gb = GreyBox::new(
        Arc::new(example("backlash_first_order")),
        &input,
        Simulation::default(),
        InitialStates::at_rest(2, 1),
    )
    .unwrap();
    let mut theta = BACKLASH.to_vec();
    theta.extend([0.0, 0.0]);
    let mut y = vec![vec![0.0; 1024]];
    gb.simulate(&theta, &input, 0, &mut y).unwrap();
    IdData::siso(0.01, "u", u, "y", y.remove(0)).unwrap()
}

/// The discrete-time file runs its recursion: the simulated output equals the recursion
/// written out by hand, whatever the integrator; fitted from 30 % off (all three parameters
/// free, noise-free), the parameters come back to 1e-8; the saved fit simulates the same.
#[test]
fn discrete_backlash_round_trip() {
    let data = backlash_record(7);
    let u = data.experiment(0).input(0);
    let (r, a, b) = (BACKLASH[0], BACKLASH[1], BACKLASH[2]);
    let (mut z, mut x) = (0.0f64, 0.0f64);
    for (k, y) in data.experiment(0).output(0).iter().enumerate() {
        assert!((y - x).abs() <= 1e-15, "sample {k}: {y} against {x}");
        z = (u[k] - r).max((u[k] + r).min(z));
        x = a * x + b * z;
    }
    let model = example("backlash_first_order");
    let mut start = model.parameters();
    start.set_values(&[r * 1.3, a * 0.9, b * 1.3]);
    let fit = GreyBoxEstimation {
        simulation: rk4(1, InputInterpolation::ZeroOrderHold),
        ..Default::default()
    }
    .estimate(
        Arc::new(model.clone()),
        &data,
        &start,
        InitialStates::of_equations(&model, 1, &[]),
        &mut |_| Control::Continue,
    )
    .unwrap();
    let got = fit.fit.parameters.values();
    println!("backlash round trip: {got:?}");
    for (e, t) in got.iter().zip(BACKLASH) {
        assert!(((e - t) / t).abs() < 1e-8, "{got:?}");
    }
    let fitted = FittedModel::Equations(FittedEquations {
        equations: model.source().to_string(),
        parameters: {
            let mut ps = model.parameters();
            ps.set_values(&got[..3]);
            ps
        },
        std: vec![0.0; 3],
        simulation: rk4(1, InputInterpolation::ZeroOrderHold),
        initial_state: vec![0.0, 0.0],
        evaluator: hysid::model::greybox::native::Evaluator::Auto,
    });
    let json = serde_json::to_string(&fitted.to_file()).unwrap();
    let back = FittedModel::from_file(&serde_json::from_str(&json).unwrap()).unwrap();
    let y = back.simulate(&[u], data.ts(), None).unwrap();
    let worst = y[0]
        .iter()
        .zip(data.experiment(0).output(0))
        .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
    assert!(worst < 1e-9, "saved model: {worst:e}");
}

/// The equation file of Bouc–Wen, fitted to the benchmark's training record with the
/// benchmark command's settings (nominal start, 8 starts, seed 1, RK4 × 4, band-limited
/// input), gives the built-in model's parameters to 1e-6.
#[test]
#[ignore = "long (several seconds): run by `cargo test --release -- --ignored` and CI"]
fn bouc_wen_file_fit_equals_the_built_in_fit() {
    let data = csv("data/bouc-wen/train_multisine_5periods.csv", "u_N", "y_m");
    let estimation = GreyBoxEstimation {
        simulation: rk4(4, InputInterpolation::BandLimited),
        starts: 8,
        seed: 1,
        ..Default::default()
    };
    let fit = |model: Arc<dyn StateSpaceModel>| {
        let start = model.parameters();
        estimation
            .estimate(
                model,
                &data,
                &start,
                InitialStates::at_rest(3, 1),
                &mut |_| Control::Continue,
            )
            .unwrap()
    };
    let builtin = fit(Arc::new(BoucWen));
    let file = fit(Arc::new(example("bouc_wen")));
    println!(
        "Bouc–Wen training fit: built-in {:.2} s, equation file {:.2} s",
        builtin.elapsed_s, file.elapsed_s
    );
    let (a, b) = (
        builtin.fit.parameters.values(),
        file.fit.parameters.values(),
    );
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        assert!(
            (x - y).abs() <= 1e-6 * x.abs().max(1e-12),
            "{}: built-in {x}, file {y}",
            builtin.fit.parameters.get(i).name
        );
    }
}

/// The performance issue's user-model route: the Bouc–Wen equation file fitted to the
/// benchmark's training record from every free parameter at twice its nominal value (one
/// start, RK4 × 4, band-limited input), run as native code (compiled by the C compiler) and
/// by the tape interpreter, against the built-in model from
/// the same start. Native and tape give the same estimates to the bit; the file gives the
/// built-in's to 1e-9 relative.
#[test]
#[ignore = "long (several seconds): run by `cargo test --release -- --ignored` and CI"]
fn bouc_wen_file_fit_from_twice_nominal_is_the_built_in_fit_native_or_taped() {
    let data = csv("data/bouc-wen/train_multisine_5periods.csv", "u_N", "y_m");
    let estimation = GreyBoxEstimation {
        simulation: rk4(4, InputInterpolation::BandLimited),
        starts: 1,
        ..Default::default()
    };
    let fit = |model: Arc<dyn StateSpaceModel>| {
        let mut start = model.parameters();
        let twice: Vec<f64> = start
            .iter()
            .map(|p| if p.fixed { p.value } else { 2.0 * p.value })
            .collect();
        start.set_values(&twice);
        estimation
            .estimate(
                model,
                &data,
                &start,
                InitialStates::at_rest(3, 1),
                &mut |_| Control::Continue,
            )
            .unwrap()
            .fit
            .parameters
            .values()
    };
    let builtin = fit(Arc::new(BoucWen));
    let tape = fit(Arc::new(
        example("bouc_wen").with_evaluator(Evaluator::Tape),
    ));
    // Native code where this machine has the route (the C compiler's).
    for evaluator in [Evaluator::Cc] {
        if evaluator.backends().iter().any(|b| !b.available()) {
            continue;
        }
        let native = fit(Arc::new(example("bouc_wen").with_evaluator(evaluator)));
        for (i, ((b, n), t)) in builtin.iter().zip(&native).zip(&tape).enumerate() {
            assert_eq!(
                n.to_bits(),
                t.to_bits(),
                "parameter {i}: {evaluator:?} {n}, tape {t}"
            );
            assert!(
                (b - n).abs() <= 1e-9 * b.abs(),
                "parameter {i}: built-in {b}, file {n}"
            );
        }
    }
}
