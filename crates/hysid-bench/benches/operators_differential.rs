//! Criterion benchmarks of the differential hysteresis operators (Jiles–Atherton, Bouc–Wen,
//! Duhem, Dahl): simulation of 50 000 samples of a decaying sine with nested minor loops, and
//! one fit of each family from the data alone (5 000 samples; Jiles–Atherton on 2 000).
//!
//! Run with `cargo bench -p hysid-bench --bench operators_differential`.

use criterion::{criterion_group, criterion_main, Criterion};
use hysid::identify::operators::{bouc_wen, dahl, duhem, jiles_atherton};
use hysid::model::operators::{BoucWen, Dahl, Duhem, HysteresisOperator, JilesAtherton};
use std::hint::black_box;

/// A·((1 − 0.7t)·sin 6πt + 0.25·sin 34πt), t ∈ [0, 1): big loops with nested minor loops.
fn nested_loops(n: usize, amplitude: f64) -> Vec<f64> {
    let tau = std::f64::consts::TAU;
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            amplitude * ((1.0 - 0.7 * t) * (tau * 3.0 * t).sin() + 0.25 * (tau * 17.0 * t).sin())
        })
        .collect()
}

fn operators() -> Vec<(Box<dyn HysteresisOperator>, f64)> {
    vec![
        (
            Box::new(JilesAtherton::new(2.5e5, 8.0, 5.0, 0.3, 5e-6).unwrap()),
            60.0,
        ),
        (
            Box::new(BoucWen::new(0.8, 1.2, 2.0, 0.5, 1.0).unwrap()),
            1.5,
        ),
        (Box::new(Duhem::new(3.0, 1.5, 0.2, 0.4).unwrap()), 1.5),
        (Box::new(Dahl::new(12.0, 2.0, 1.8).unwrap()), 1.0),
    ]
}

fn simulation(c: &mut Criterion) {
    let mut group = c.benchmark_group("simulate 50 000 samples");
    for (op, amplitude) in operators() {
        let u = nested_loops(50_000, amplitude);
        group.bench_function(op.family(), |b| {
            b.iter(|| black_box(op.simulate(&u).unwrap()))
        });
    }
    group.finish();
}

fn fits(c: &mut Criterion) {
    let mut group = c.benchmark_group("fit from the data");
    group.sample_size(10);
    let ops = operators();
    let data = |i: usize, n: usize| {
        let u = nested_loops(n, ops[i].1);
        let y = ops[i].0.simulate(&u).unwrap();
        (u, y)
    };
    let (u, y) = data(0, 2_000);
    group.bench_function("jiles-atherton (2 000 samples)", |b| {
        b.iter(|| black_box(jiles_atherton::fit(&u, &y, &Default::default()).unwrap()))
    });
    let (u, y) = data(1, 5_000);
    group.bench_function("bouc-wen (5 000 samples)", |b| {
        b.iter(|| black_box(bouc_wen::fit(&u, &y, &Default::default()).unwrap()))
    });
    let (u, y) = data(2, 5_000);
    group.bench_function("duhem (5 000 samples)", |b| {
        b.iter(|| black_box(duhem::fit(&u, &y, &Default::default()).unwrap()))
    });
    let (u, y) = data(3, 5_000);
    group.bench_function("dahl (5 000 samples)", |b| {
        b.iter(|| black_box(dahl::fit(&u, &y, &Default::default()).unwrap()))
    });
    group.finish();
}

criterion_group!(benches, simulation, fits);
criterion_main!(benches);
