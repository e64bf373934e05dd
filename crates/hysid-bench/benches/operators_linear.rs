//! Criterion benchmarks of the linear-in-weights hysteresis operators: simulation of each
//! family on 50 000 samples, the PI analytic inverse, and the PI (10 thresholds) and Preisach
//! (20 levels, 210 cells) fits on 50 000 samples.
//!
//! Run with `cargo bench -p hysid-bench --bench operators_linear`.

use criterion::{criterion_group, criterion_main, Criterion};
use hysid::identify::operators::{pi, preisach};
use hysid::model::operators::{
    Backlash, DeadZones, GeneralizedPi, HysteresisOperator, MaxwellSlip, Orientation,
    PrandtlIshlinskii, Preisach,
};
use std::hint::black_box;
use std::time::Duration;

const N: usize = 50_000;

/// A decaying oscillation with nested minor loops.
fn input() -> Vec<f64> {
    (0..N)
        .map(|k| {
            let t = k as f64 / N as f64;
            2.0 * (1.0 - 0.8 * t) * (120.0 * t).sin() + 0.4 * (610.0 * t).sin()
        })
        .collect()
}

fn pi_model() -> PrandtlIshlinskii {
    let r: Vec<f64> = (1..=10).map(|i| 0.2 * i as f64).collect();
    let a: Vec<f64> = (0..10).map(|i| 0.1 + 0.02 * i as f64).collect();
    PrandtlIshlinskii::new(0.8, a, r, 0.0, Orientation::default()).unwrap()
}

fn preisach_model() -> Preisach {
    let w: Vec<f64> = (0..210).map(|k| 0.01 + 0.001 * (k % 13) as f64).collect();
    Preisach::new(-2.5, 2.5, 20, w, 0.2, 0.0, Orientation::default()).unwrap()
}

fn simulations(c: &mut Criterion) {
    let u = input();
    let ops: Vec<Box<dyn HysteresisOperator>> = vec![
        Box::new(Backlash::new(1.5, 0.3, 0.0, Orientation::default()).unwrap()),
        Box::new(pi_model()),
        Box::new(GeneralizedPi::new(
            pi_model(),
            DeadZones::new(1.0, vec![(1.0, 0.3), (2.0, 0.2)], vec![(-1.0, -0.2)]).unwrap(),
            Orientation::default(),
        )),
        Box::new(preisach_model()),
        Box::new(
            MaxwellSlip::new(
                1.0,
                vec![1.0; 10],
                (1..=10).map(|i| 0.1 * i as f64).collect(),
                0.0,
                Orientation::default(),
            )
            .unwrap(),
        ),
    ];
    let mut group = c.benchmark_group("operator simulation, 50 000 samples");
    group.measurement_time(Duration::from_secs(3));
    for op in &ops {
        group.bench_function(op.family(), |b| {
            b.iter(|| black_box(op.simulate(black_box(&u)).unwrap()))
        });
    }
    let pi = pi_model();
    let reference = pi.simulate(&u).unwrap();
    group.bench_function("pi analytic inverse", |b| {
        b.iter(|| black_box(pi.invert(black_box(&reference)).unwrap()))
    });
    group.finish();
}

fn fits(c: &mut Criterion) {
    let u = input();
    let y_pi = pi_model().simulate(&u).unwrap();
    let y_pr = preisach_model().simulate(&u).unwrap();
    let mut group = c.benchmark_group("operator fit, 50 000 samples");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(5));
    group.bench_function("pi, 10 thresholds", |b| {
        b.iter(|| black_box(pi::fit(&u, &y_pi, &pi::PiOptions::default()).unwrap()))
    });
    group.bench_function("preisach, 20 levels (210 cells)", |b| {
        b.iter(|| {
            black_box(preisach::fit(&u, &y_pr, &preisach::PreisachOptions::default()).unwrap())
        })
    });
    group.finish();
}

criterion_group!(benches, simulations, fits);
criterion_main!(benches);
