//! Criterion benchmarks of the cascade: one simulation, one set of normal equations (the
//! Jacobian work of one Levenberg–Marquardt iteration), one point of the global (α, d) grid
//! on 10⁶ samples, the thresholds of one α scored one and four at a time on the 10⁴-sample
//! window, and full identifications (the examples, and 10⁶ samples as
//! `hysid identify cascade` runs them).
//!
//! Run with `cargo bench -p hysid-bench --bench cascade`.

use criterion::{criterion_group, criterion_main, Criterion};
use hysid::experiments::voros::CascadeExample;
use hysid::identify::cascade::{CascadeIdentification, CascadeStructure};
use hysid::identify::grid_regression::{EquationError, BATCH};
use hysid::identify::output_error::OutputErrorProblem;
use hysid::numerics::levenberg_marquardt::LeastSquaresProblem;
use hysid::numerics::Control;
use std::hint::black_box;

fn simulation(c: &mut Criterion) {
    let ex = CascadeExample::example1().extended(1_000_000);
    let x = ex.generate(1, false).unwrap().x;
    c.bench_function("cascade simulation, 1e6 samples", |b| {
        b.iter(|| black_box(ex.truth.simulate_unchecked(black_box(&x))))
    });
}

fn normal_equations(c: &mut Criterion) {
    let ex = CascadeExample::example1().extended(1_000_000);
    let data = ex.generate(1, true).unwrap().id_data().unwrap();
    let structure = CascadeStructure {
        form: ex.truth.hysteresis.form(),
        na: 2,
        nb: 2,
        delay: 1,
        switching: None,
    };
    let problem = OutputErrorProblem::new(&structure, &data, vec![1.0], 0).unwrap();
    let theta = ex.truth.params();
    let free: Vec<usize> = (0..theta.len()).collect();
    c.bench_function(
        "cascade normal equations (analytic Jacobian), 1e6 samples",
        |b| {
            b.iter(|| {
                black_box(
                    problem
                        .normal_equations(black_box(&theta), &free)
                        .unwrap()
                        .unwrap(),
                )
            })
        },
    );
}

fn identification(c: &mut Criterion) {
    let mut group = c.benchmark_group("identification");
    group.sample_size(10);
    for n in [1u8, 2] {
        let ex = CascadeExample::number(n).unwrap();
        let data = ex.generate(1, true).unwrap().id_data().unwrap();
        let lin = &ex.truth.linear;
        let id =
            CascadeIdentification::new(ex.truth.hysteresis.form(), lin.na(), lin.nb(), lin.delay())
                .initial(ex.initial.clone());
        group.bench_function(format!("Example {n}, SNR 50, asymptotic std"), |b| {
            b.iter(|| black_box(id.estimate(&data, &mut |_| Control::Continue).unwrap()))
        });
    }
    group.finish();
}

fn grid_point(c: &mut Criterion) {
    let ex = CascadeExample::example1().extended(1_000_000);
    let gen = ex.generate(1, true).unwrap();
    let h = &ex.truth.hysteresis;
    let regression = EquationError::new(h.form(), 2, 2, 1, &gen.x, &gen.y);
    let mut scratch = regression.scratch();
    c.bench_function("cascade grid point (equation error), 1e6 samples", |b| {
        b.iter(|| {
            black_box(
                regression
                    .cost(black_box(h.alpha()), black_box(h.d()), &mut scratch)
                    .unwrap(),
            )
        })
    });
}

/// Stage A of the global search scores every threshold of one α: one point at a time against
/// four at a time (their ψ recursions interleaved), on the identification's 10⁴-sample window.
fn grid_thresholds(c: &mut Criterion) {
    let ex = CascadeExample::example1().extended(10_000);
    let gen = ex.generate(1, true).unwrap();
    let h = &ex.truth.hysteresis;
    let regression = EquationError::new(h.form(), 2, 2, 1, &gen.x, &gen.y);
    let mut scratch = regression.scratch();
    let ds: Vec<f64> = (1..=64).map(|j| 2.0 * h.d() * j as f64 / 65.0).collect();
    let mut group = c.benchmark_group("cascade grid, 64 thresholds of one alpha, 1e4 samples");
    group.bench_function("one at a time", |b| {
        b.iter(|| {
            for &d in &ds {
                black_box(regression.cost(black_box(h.alpha()), d, &mut scratch));
            }
        })
    });
    group.bench_function("four at a time", |b| {
        b.iter(|| {
            for batch in ds.chunks(BATCH) {
                black_box(regression.costs(black_box(h.alpha()), batch, &mut scratch));
            }
        })
    });
    group.finish();
}

fn identification_1e6(c: &mut Criterion) {
    let mut group = c.benchmark_group("identification");
    group.sample_size(10);
    let ex = CascadeExample::example1().extended(1_000_000);
    let data = ex.generate(1, true).unwrap().id_data().unwrap();
    let id = CascadeIdentification::new(ex.truth.hysteresis.form(), 2, 2, 1);
    group.bench_function(
        "Example 1 pattern, 1e6 samples, SNR 50, no initial values",
        |b| b.iter(|| black_box(id.estimate(&data, &mut |_| Control::Continue).unwrap())),
    );
    group.finish();
}

criterion_group!(
    benches,
    simulation,
    normal_equations,
    grid_point,
    grid_thresholds,
    identification,
    identification_1e6
);
criterion_main!(benches);
