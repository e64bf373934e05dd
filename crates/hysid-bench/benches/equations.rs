//! Criterion benchmark of equation-file models against the built-in ones: one simulation
//! with forward sensitivities (RK4 × 4, band-limited input, the six free parameters) of the
//! Bouc–Wen oscillator on the benchmark's training record (40 960 samples), once with the
//! hand-written `BoucWen` and once with `examples/equations/bouc_wen.toml` evaluated from
//! its compiled tape; and a discrete-time equation file
//! (`examples/equations/backlash_first_order.toml`, the recursion with its chain-rule
//! sensitivities, three free parameters) on a 40 960-sample multisine.
//!
//! Run with `cargo bench -p hysid-bench --bench equations`.

use criterion::{criterion_group, criterion_main, Criterion};
use hysid::data::{CsvSpec, IdData};
use hysid::identify::greybox::{GreyBox, InitialStates};
use hysid::identify::OutputErrorModel;
use hysid::model::greybox::equation_model::EquationStateSpace;
use hysid::model::greybox::models::BoucWen;
use hysid::model::greybox::{InputInterpolation, Integrator, Simulation, StateSpaceModel};
use std::hint::black_box;
use std::path::Path;
use std::sync::Arc;

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

fn train() -> IdData {
    let spec = CsvSpec {
        inputs: vec!["u_N".into()],
        outputs: vec!["y_m".into()],
        time: None,
        ts: None,
        ..CsvSpec::default()
    };
    IdData::from_csv(
        &root().join("data/bouc-wen/train_multisine_5periods.csv"),
        &spec,
    )
    .unwrap()
}

fn sensitivities(c: &mut Criterion) {
    let data = train();
    let simulation = Simulation {
        integrator: Integrator::Rk4 { substeps: 4 },
        interpolation: InputInterpolation::BandLimited,
    };
    let file = EquationStateSpace::load(&root().join("examples/equations/bouc_wen.toml")).unwrap();
    let models: [(&str, Arc<dyn StateSpaceModel>); 2] = [
        ("built-in", Arc::new(BoucWen)),
        ("equation file", Arc::new(file)),
    ];
    let mut group =
        c.benchmark_group("Bouc-Wen simulation with sensitivities, 40960 samples, RK4 x4");
    group.sample_size(20);
    for (label, model) in models {
        let gb = GreyBox::new(model, &data, simulation, InitialStates::at_rest(3, 1)).unwrap();
        let theta = gb.parameters().values();
        let free: Vec<usize> = (0..6).collect();
        group.bench_function(label, |b| {
            b.iter(|| {
                let mut last = 0.0;
                gb.simulate_sensitivities(black_box(&theta), &data, 0, &free, &mut |_, y, s| {
                    last += y[0] + s[0];
                    std::ops::ControlFlow::Continue(())
                })
                .unwrap()
                .unwrap();
                black_box(last)
            })
        });
    }
    group.finish();
}

/// The discrete-time backlash file: one recursion with sensitivities to (r, a, b).
fn discrete(c: &mut Criterion) {
    let n = 40_960;
    let u = hysid::numerics::signal::multisine(n, 1, 100.0, 0.2, 5.0, 1.0, 1).unwrap();
    let data = IdData::siso(0.01, "u", u, "y", vec![0.0; n]).unwrap();
    let file =
        EquationStateSpace::load(&root().join("examples/equations/backlash_first_order.toml"))
            .unwrap();
    let gb = GreyBox::new(
        Arc::new(file),
        &data,
        Simulation::default(),
        InitialStates::at_rest(2, 1),
    )
    .unwrap();
    let theta = gb.parameters().values();
    let free: Vec<usize> = (0..3).collect();
    let mut group =
        c.benchmark_group("Discrete-time equation file with sensitivities, 40960 samples");
    group.sample_size(20);
    group.bench_function("backlash_first_order", |b| {
        b.iter(|| {
            let mut last = 0.0;
            gb.simulate_sensitivities(black_box(&theta), &data, 0, &free, &mut |_, y, s| {
                last += y[0] + s[0];
                std::ops::ControlFlow::Continue(())
            })
            .unwrap()
            .unwrap();
            black_box(last)
        })
    });
    group.finish();
}

criterion_group!(benches, sensitivities, discrete);
criterion_main!(benches);
