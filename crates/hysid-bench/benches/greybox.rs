//! Criterion benchmarks of the grey-box engine on the Bouc–Wen benchmark's training record
//! (40 960 samples): one simulation, one set of normal equations (the Jacobian work of one
//! Levenberg–Marquardt iteration), the full fit from one start and from 8 starts.
//!
//! Run with `cargo bench -p hysid-bench --bench greybox`.

use criterion::{criterion_group, criterion_main, Criterion};
use hysid::data::{CsvSpec, IdData};
use hysid::identify::greybox::{GreyBox, GreyBoxEstimation, InitialStates};
use hysid::identify::output_error::OutputErrorProblem;
use hysid::identify::OutputErrorModel;
use hysid::model::greybox::models::BoucWen;
use hysid::model::greybox::{InputInterpolation, Integrator, Simulation, StateSpaceModel};
use hysid::numerics::levenberg_marquardt::LeastSquaresProblem;
use hysid::numerics::Control;
use std::hint::black_box;
use std::path::Path;
use std::sync::Arc;

fn train() -> IdData {
    let spec = CsvSpec {
        inputs: vec!["u_N".into()],
        outputs: vec!["y_m".into()],
        time: None,
        ts: None,
        ..CsvSpec::default()
    };
    IdData::from_csv(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../data/bouc-wen/train_multisine_5periods.csv"),
        &spec,
    )
    .unwrap()
}

fn simulation() -> Simulation {
    Simulation {
        integrator: Integrator::Rk4 { substeps: 4 },
        interpolation: InputInterpolation::BandLimited,
    }
}

fn bouc_wen(c: &mut Criterion) {
    let data = train();
    let gb = GreyBox::new(
        Arc::new(BoucWen),
        &data,
        simulation(),
        InitialStates::at_rest(3, 1),
    )
    .unwrap();
    let mut theta = BoucWen.parameters().values();
    theta.extend([0.0; 3]);
    c.bench_function("Bouc-Wen simulation, 40960 samples, RK4 x4", |b| {
        b.iter(|| {
            let mut y = vec![vec![0.0; data.n_samples()]];
            gb.simulate(black_box(&theta), &data, 0, &mut y).unwrap();
            black_box(y)
        })
    });
    let problem = OutputErrorProblem::new(&gb, &data, vec![1.0], 0).unwrap();
    let free: Vec<usize> = (0..6).collect();
    c.bench_function(
        "Bouc-Wen normal equations (forward sensitivities), 40960 samples",
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
    let mut group = c.benchmark_group("fit");
    group.sample_size(10);
    let mut start = BoucWen.parameters();
    for i in start.free_indices() {
        start.get_mut(i).value *= 2.0;
    }
    let single = GreyBoxEstimation {
        simulation: simulation(),
        ..Default::default()
    };
    // What `hysid benchmark bouc-wen --start-factor 2 --starts 1` does.
    group.bench_function("Bouc-Wen training record from x2, 1 start", |b| {
        b.iter(|| {
            black_box(
                single
                    .estimate(
                        Arc::new(BoucWen),
                        &data,
                        &start,
                        InitialStates::at_rest(3, 1),
                        &mut |_| Control::Continue,
                    )
                    .unwrap(),
            )
        })
    });
    let estimation = GreyBoxEstimation {
        simulation: simulation(),
        starts: 8,
        seed: 1,
        ..Default::default()
    };
    group.bench_function("Bouc-Wen training record from x2, 8 starts", |b| {
        b.iter(|| {
            black_box(
                estimation
                    .estimate(
                        Arc::new(BoucWen),
                        &data,
                        &start,
                        InitialStates::at_rest(3, 1),
                        &mut |_| Control::Continue,
                    )
                    .unwrap(),
            )
        })
    });
    group.finish();
}

criterion_group!(benches, bouc_wen);
criterion_main!(benches);
