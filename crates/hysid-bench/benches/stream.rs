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
use hysid::model::saved::FittedModel;
use hysid_bench::{stream_input, stream_models, STREAM_SAMPLES, STREAM_TS};
use std::hint::black_box;
use std::time::Duration;

/// Steps `model`'s stepper (and its compensator, when it has one) through the input.
fn bench_model(c: &mut Criterion, name: &str, model: &FittedModel, u: &[f64]) {
    let mut group = c.benchmark_group("stream");
    group.throughput(Throughput::Elements(u.len() as u64));
    // The Bouc–Wen oscillator's input is a force of a few newtons; the operators' inputs are
    // the signal itself.
    let ts = STREAM_TS;
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
    let u: Vec<f64> = (0..STREAM_SAMPLES).map(stream_input).collect();
    for (name, model) in stream_models() {
        bench_model(c, &name, &model, &u);
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
