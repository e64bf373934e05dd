//! Criterion benchmarks of the actuator work of Gunnar et al. (2006): the virtual rig's eight
//! experiments, one simulation with forward sensitivities of the actuator model, the three
//! steps on them (step 1, step 2, the four output-error fits of step 3 and the tables), and
//! the EMPS inverse-dynamics least squares (docs/benchmarks.md §2.2).
//!
//! Run with `cargo bench -p hysid-bench --bench actuator`.

use criterion::{criterion_group, criterion_main, Criterion};
use hysid::data::{Channel, CsvSpec, Experiment, IdData};
use hysid::experiments::actuator_rig::Rig;
use hysid::identify::actuator::{Record, ThreeSteps};
use hysid::identify::greybox::{GreyBox, InitialStates};
use hysid::identify::output_error::OutputErrorProblem;
use hysid::identify::rigid_body::RigidBodyLs;
use hysid::model::greybox::models::ActuatorFixed;
use hysid::model::greybox::{InputInterpolation, Integrator, Simulation, StateSpaceModel};
use hysid::numerics::levenberg_marquardt::LeastSquaresProblem;
use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::Path;
use std::sync::Arc;

fn records(rig: &Rig) -> BTreeMap<usize, Record> {
    rig.data_sets().unwrap()
}

fn bench(c: &mut Criterion) {
    let rig = Rig::default();
    c.bench_function("rig: the eight data sets (77 s of data at 1 kHz)", |b| {
        b.iter(|| black_box(rig.records().unwrap()))
    });
    let data = records(&rig);
    sensitivities(c, &data[&8]);
    let steps = ThreeSteps::default();
    let mut group = c.benchmark_group("three steps");
    group.sample_size(10);
    group.bench_function("all steps, four step-3 models, tables", |b| {
        b.iter(|| black_box(steps.run(&data).unwrap()))
    });
    group.finish();
    let spec = CsvSpec {
        inputs: vec!["vir_V".into()],
        outputs: vec!["qm_m".into()],
        time: None,
        ts: None,
        ..CsvSpec::default()
    };
    let emps = IdData::from_csv(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/emps/DATA_EMPS.csv"),
        &spec,
    )
    .unwrap();
    let exp = emps.experiment(0);
    let ls = RigidBodyLs::emps();
    c.bench_function(
        "EMPS inverse-dynamics least squares (24 841 samples)",
        |b| b.iter(|| black_box(ls.estimate(exp.output(0), exp.input(0), emps.ts()).unwrap())),
    );
}

/// One simulation with forward sensitivities of the saddle-fixed actuator (RK4 ×10,
/// stick–slip events) on data set 8: the Jacobian work of one step-3 iteration.
fn sensitivities(c: &mut Criterion, record: &Record) {
    let data = IdData::new(
        record.ts,
        vec![Channel::new("tau")],
        vec![Channel::new("x1")],
        vec![Experiment::new(
            "set 8",
            vec![record.torque.clone()],
            vec![record.angle.clone()],
        )
        .unwrap()],
    )
    .unwrap();
    let simulation = Simulation {
        integrator: Integrator::Rk4 { substeps: 10 },
        interpolation: InputInterpolation::ZeroOrderHold,
    };
    let gb = GreyBox::new(
        Arc::new(ActuatorFixed),
        &data,
        simulation,
        InitialStates::at_rest(3, 1),
    )
    .unwrap();
    let mut theta = ActuatorFixed.parameters().values();
    theta.extend([0.0; 3]);
    let problem = OutputErrorProblem::new(&gb, &data, vec![1.0], 0).unwrap();
    let free = ActuatorFixed.parameters().free_indices();
    let name = format!(
        "actuator normal equations (forward sensitivities), data set 8, {} samples",
        data.n_samples()
    );
    c.bench_function(&name, |b| {
        b.iter(|| {
            black_box(
                problem
                    .normal_equations(black_box(&theta), &free)
                    .unwrap()
                    .unwrap(),
            )
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
