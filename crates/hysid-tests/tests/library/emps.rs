//! Step 1 on real data: the EMPS positioning system's inverse-dynamics least squares with the
//! published preprocessing reproduces the published reference model (docs/benchmarks.md §2.2).

use hysid::data::{CsvSpec, IdData};
use hysid::identify::rigid_body::RigidBodyLs;
use std::path::Path;

#[test]
fn emps_reference_model_is_reproduced() {
    let spec = CsvSpec {
        inputs: vec!["vir_V".into()],
        outputs: vec!["qm_m".into()],
        time: Some("t_s".into()),
        ts: None,
        ..CsvSpec::default()
    };
    let data = IdData::from_csv(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/emps/DATA_EMPS.csv"),
        &spec,
    )
    .unwrap();
    let exp = data.experiment(0);
    let est = RigidBodyLs::emps()
        .estimate(exp.output(0), exp.input(0), data.ts())
        .unwrap();
    let published = [
        (95.1089, 0.005),
        (203.5034, 0.005),
        (20.3935, 0.005),
        (-3.1648, 0.02),
    ];
    for ((name, got), (want, tol)) in est.names.iter().zip(&est.values).zip(published) {
        assert!(((got - want) / want).abs() < tol, "{name}: {got} vs {want}");
    }
    assert!(
        (est.relative_error_percent - 4.0834).abs() < 0.2,
        "{}",
        est.relative_error_percent
    );
    // Published relative standard deviations [%] and condition number.
    for (got, want) in est
        .relative_std_percent
        .iter()
        .zip([0.1141, 0.5631, 0.4964, 1.4021])
    {
        assert!(
            (got / want - 1.0).abs() < 0.05,
            "relative std {got} vs {want}"
        );
    }
    assert!(
        (est.condition_number_unscaled / 25.99 - 1.0).abs() < 0.01,
        "{}",
        est.condition_number_unscaled
    );
}
