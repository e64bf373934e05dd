//! Criterion benchmarks of the cascade: one simulation, one set of normal equations (the
//! Jacobian work of one Levenberg–Marquardt iteration) and one full identification.
//!
//! Run with `cargo bench -p hysid --bench cascade`.

use criterion::{criterion_group, criterion_main, Criterion};
use hysid::experiments::voros::CascadeExample;
use hysid::identify::cascade::{CascadeIdentification, CascadeStructure};
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

criterion_group!(benches, simulation, normal_equations, identification);
criterion_main!(benches);
