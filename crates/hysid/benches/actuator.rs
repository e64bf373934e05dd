//! Criterion benchmarks of the actuator work of Gunnar et al. (2006): the virtual rig's eight
//! experiments, the three steps on them (step 1, step 2, the four output-error fits of step 3
//! and the tables), and the EMPS inverse-dynamics least squares (docs/benchmarks.md §2.2).
//!
//! Run with `cargo bench -p hysid --bench actuator`.

use criterion::{criterion_group, criterion_main, Criterion};
use hysid::data::{CsvSpec, IdData};
use hysid::experiments::actuator_rig::Rig;
use hysid::identify::actuator::{Record, ThreeSteps};
use hysid::identify::rigid_body::RigidBodyLs;
use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::Path;

fn records(rig: &Rig) -> BTreeMap<usize, Record> {
    rig.data_sets().unwrap()
}

fn bench(c: &mut Criterion) {
    let rig = Rig::default();
    c.bench_function("rig: the eight data sets (77 s of data at 1 kHz)", |b| {
        b.iter(|| black_box(rig.records().unwrap()))
    });
    let data = records(&rig);
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

criterion_group!(benches, bench);
criterion_main!(benches);
