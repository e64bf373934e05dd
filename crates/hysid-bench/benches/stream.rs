//! Criterion benchmarks of the library's streaming models (`hysid::model::stream`): the time
//! of one `Stepper::step` (and one `Compensator::step`) in the real-time loop a controller
//! runs, for the deployment issue's three reference models — a PI operator with 20 play
//! operators, a 20-level (210-cell) Preisach plane, the Bouc–Wen grey-box oscillator (RK4,
//! 4 sub-steps, zero-order hold) — and every operator family's registry example.
//!
//! Criterion's throughput is one element per step, so its "elem/s" is steps per second.
//! The exported C code's figures come from `bench/export_steps.sh`.
//!
//! Run with `cargo bench -p hysid-bench --bench stream`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use hysid::model::greybox::models;
use hysid::model::greybox::{InputInterpolation, Integrator, Simulation};
use hysid::model::operators::{OperatorModel, Orientation, PrandtlIshlinskii, Preisach};
use hysid::model::saved::FittedModel;
use std::hint::black_box;
use std::time::Duration;

/// Samples per measured batch.
const N: usize = 10_000;

/// A decaying oscillation with nested minor loops, within ±2.5.
fn input() -> Vec<f64> {
    (0..N)
        .map(|k| {
            let t = k as f64 / N as f64;
            2.0 * (1.0 - 0.5 * t) * (40.0 * t).sin() + 0.3 * (370.0 * t).sin()
        })
        .collect()
}

fn operator(model: OperatorModel) -> FittedModel {
    let n = model.as_operator().parameters().len();
    FittedModel::operator(model, vec![f64::NAN; n])
}

/// The reference models of the deployment issue's real-time goals.
fn reference_models() -> Vec<(&'static str, FittedModel)> {
    let r: Vec<f64> = (1..=20).map(|i| 0.1 * i as f64).collect();
    let a: Vec<f64> = (0..20).map(|i| 0.05 + 0.01 * i as f64).collect();
    let pi = PrandtlIshlinskii::new(0.8, a, r, 0.0, Orientation::default()).unwrap();
    let w: Vec<f64> = (0..210).map(|k| 0.01 + 0.001 * (k % 13) as f64).collect();
    let preisach = Preisach::new(-2.5, 2.5, 20, w, 0.2, 0.0, Orientation::default()).unwrap();
    let bouc_wen = models::by_kind("bouc_wen").unwrap();
    let parameters = bouc_wen.parameters();
    let p = parameters.len();
    let grey_box = FittedModel::GreyBox {
        kind: "bouc_wen".into(),
        parameters,
        std: vec![f64::NAN; p],
        simulation: Simulation {
            integrator: Integrator::Rk4 { substeps: 4 },
            interpolation: InputInterpolation::ZeroOrderHold,
        },
        initial_state: vec![0.0; bouc_wen.states().len()],
    };
    vec![
        ("pi_20_plays", operator(OperatorModel::Pi(pi))),
        (
            "preisach_20x20",
            operator(OperatorModel::Preisach(preisach)),
        ),
        ("bouc_wen_greybox_rk4_4", grey_box),
    ]
}

/// Steps `model`'s stepper (and its compensator, when it has one) through the input.
fn bench_model(c: &mut Criterion, name: &str, model: &FittedModel, u: &[f64]) {
    let mut group = c.benchmark_group("stream");
    group.throughput(Throughput::Elements(u.len() as u64));
    // The Bouc–Wen oscillator's input is a force of a few newtons; the operators' inputs are
    // the signal itself.
    let ts = 1.0 / 750.0;
    let mut stepper = model.stepper(ts, Some(0.0)).unwrap();
    let mut y = [0.0];
    group.bench_function(format!("{name}/step"), |b| {
        b.iter(|| {
            stepper.reset();
            for &uk in u {
                stepper.step(black_box(&[uk]), &mut y).unwrap();
            }
            black_box(y[0])
        })
    });
    if let Ok(mut compensator) = model.compensator(ts) {
        // References the model reaches: its own output on the input.
        let r = model.simulate(&[u], ts, Some(0.0)).unwrap().remove(0);
        group.bench_function(format!("{name}/compensate"), |b| {
            b.iter(|| {
                compensator.reset();
                let mut last = 0.0;
                for &rk in &r {
                    last = compensator.step(black_box(rk)).unwrap().u;
                }
                black_box(last)
            })
        });
    }
    group.finish();
}

fn streams(c: &mut Criterion) {
    let u = input();
    for (name, model) in reference_models() {
        bench_model(c, name, &model, &u);
    }
    for example in OperatorModel::examples().unwrap() {
        let name = format!("example_{}", example.family().name());
        bench_model(c, &name, &operator(example), &u);
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    targets = streams
}
criterion_main!(benches);
