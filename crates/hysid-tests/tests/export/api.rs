//! The API's refusals, the interface and the determinism of the generated files.

use crate::cases;
use hysid::export::{c_code, export, ExportOptions, Target};
use hysid::model::saved::{FittedCascade, FittedGreyBox, FittedOperatorCascade};

#[test]
fn an_invalid_name_is_refused() {
    let file = cases::named_pi();
    for name in ["", "1pi", "pi-model", "static", "fn", "x y"] {
        let e = c_code(&file, name, &ExportOptions::default()).expect_err(name);
        assert!(e.to_string().contains("C identifier"), "{name}: {e}");
    }
}

#[test]
fn exporting_twice_gives_identical_files() {
    let file = cases::named_pi();
    for target in [Target::C, Target::Rust] {
        let options = ExportOptions::default();
        let a = export(&file, target, "stage", &options).expect("export");
        let b = export(&file, target, "stage", &options).expect("export");
        assert_eq!(a, b, "{target:?}");
    }
}

#[test]
fn the_interface_names_the_columns_and_the_sample_time() {
    let file = cases::named_pi();
    let forward = c_code(&file, "stage", &ExportOptions::default()).expect("c");
    assert_eq!(forward.interface.inputs, ["voltage"]);
    assert_eq!(forward.interface.outputs, ["position"]);
    assert_eq!(forward.interface.sample_time, 1e-4);
    assert!(forward.header.contains("#define stage_SAMPLE_TIME 0.0001"));
    let options = ExportOptions {
        inverse: true,
        ..ExportOptions::default()
    };
    let inverse = c_code(&file, "stage", &options).expect("c");
    assert_eq!(inverse.interface.inputs, ["position_reference"]);
    assert_eq!(inverse.interface.outputs, ["voltage"]);
    let names: Vec<&str> = inverse
        .interface
        .parameters
        .iter()
        .map(|p| p.0.as_str())
        .collect();
    assert_eq!(names.first(), Some(&"a0"));
    let disagreeing = ExportOptions {
        sample_time: Some(1e-3),
        ..ExportOptions::default()
    };
    let e = c_code(&file, "stage", &disagreeing).expect_err("a disagreeing --ts");
    assert!(
        names_ts(&e) && e.to_string().contains("sample time is"),
        "{e}"
    );
}

#[test]
fn a_rate_independent_operator_exports_without_a_sample_time_and_a_cascade_does_not() {
    let mut file = cases::named_pi();
    file.sample_time = None;
    let code = c_code(&file, "stage", &ExportOptions::default()).expect("c");
    assert_eq!(code.interface.sample_time, 0.0);
    let cascade = hysid::model::OperatorCascade::new(
        hysid::model::operators::OperatorModel::examples()
            .expect("examples")
            .remove(0),
        cases::block(),
    )
    .expect("cascade");
    let n = cascade.parameters().len();
    let file = hysid::model::saved::FittedModel::OperatorCascade(FittedOperatorCascade {
        model: cascade,
        std: vec![f64::NAN; n],
    })
    .to_file();
    let e = c_code(&file, "stage", &ExportOptions::default()).expect_err("no sample time");
    assert!(
        names_ts(&e) && e.to_string().contains("no sample_time"),
        "{e}"
    );
}

/// The error is about the sample-time option (`--ts` on the command line, `ts=` in Python).
fn names_ts(e: &hysid::Error) -> bool {
    matches!(e, hysid::Error::InvalidOption { option, .. } if option == "ts")
}

#[test]
fn a_compensator_is_refused_for_a_model_without_an_inverse_and_a_non_minimum_phase_cascade() {
    let op = hysid::model::operators::OperatorModel::examples()
        .expect("examples")
        .remove(0);
    let block = hysid::model::LinearBlock::new(vec![-0.5], vec![1.0, 2.0], 1).expect("block");
    let cascade = hysid::model::OperatorCascade::new(op, block).expect("cascade");
    let n = cascade.parameters().len();
    let file = hysid::model::saved::FittedModel::OperatorCascade(FittedOperatorCascade {
        model: cascade,
        std: vec![f64::NAN; n],
    })
    .to_file();
    let options = ExportOptions {
        inverse: true,
        sample_time: Some(1e-3),
        ..ExportOptions::default()
    };
    let e = c_code(&file, "stage", &options).expect_err("non-minimum-phase");
    assert!(e.to_string().contains("minimum phase"), "{e}");
    let ch = hysid::model::ColemanHodgdon::general(2.0, 1.0, 0.3, 0.4, 0.1, 0.5).expect("ch");
    let cascade = hysid::model::HysteresisCascade::new(ch, cases::block()).expect("cascade");
    let n = cascade.params().len();
    let file = hysid::model::saved::FittedModel::Cascade(FittedCascade {
        model: cascade,
        std: vec![f64::NAN; n],
    })
    .to_file();
    let e = c_code(&file, "stage", &options).expect_err("no inverse");
    assert!(e.to_string().contains("not invertible"), "{e}");
    let e = export(&file, Target::Fmu, "stage", &options).expect_err("fmu");
    assert!(!e.to_string().is_empty());
}

/// The Bouc–Wen oscillator saved with `simulation`.
fn bouc_wen(simulation: hysid::model::greybox::Simulation) -> hysid::model::saved::ModelFile {
    use hysid::model::greybox::models::GreyBoxKind;
    let model = GreyBoxKind::BoucWen.model();
    let parameters = model.parameters();
    hysid::model::saved::FittedModel::GreyBox(FittedGreyBox {
        kind: "bouc_wen".into(),
        std: vec![f64::NAN; parameters.len()],
        parameters,
        simulation,
        initial_state: vec![0.0; 3],
    })
    .to_file()
}

#[test]
fn grey_box_exports_refuse_band_limited_a_non_mechanical_newmark_and_a_compensator_in_one_line() {
    use hysid::model::greybox::{InputInterpolation, Integrator, Simulation};
    let with_ts = ExportOptions {
        sample_time: Some(1e-3),
        ..ExportOptions::default()
    };
    let band_limited = bouc_wen(Simulation {
        integrator: Integrator::Rk4 { substeps: 4 },
        interpolation: InputInterpolation::BandLimited,
    });
    let e = c_code(&band_limited, "bw", &with_ts).expect_err("band-limited");
    let text = e.to_string();
    assert!(
        text.contains("band-limited") && text.contains("\"linear\"") && !text.contains('\n'),
        "{text}"
    );
    let newmark = Simulation {
        integrator: Integrator::Newmark { substeps: 2 },
        interpolation: InputInterpolation::ZeroOrderHold,
    };
    assert!(c_code(&bouc_wen(newmark), "bw", &with_ts).is_ok());
    // Newmark where the library refuses it: a model without a mechanical layout, in the
    // library's words.
    let file = crate::greybox::equations(crate::greybox::TIMED, newmark).to_file();
    let e = c_code(&file, "eq", &with_ts).expect_err("Newmark without a mechanical layout");
    assert!(
        e.to_string().contains("second-order mechanical") && !e.to_string().contains('\n'),
        "{e}"
    );
    let rk4 = bouc_wen(Simulation::default());
    let inverse = ExportOptions {
        inverse: true,
        ..with_ts.clone()
    };
    let e = c_code(&rk4, "bw", &inverse).expect_err("no compensator");
    assert!(e.to_string().contains("not invertible"), "{e}");
    let e = c_code(&rk4, "bw", &ExportOptions::default()).expect_err("no sample time");
    assert!(names_ts(&e), "{e}");
    assert!(c_code(&rk4, "bw", &with_ts).is_ok());
}

/// Every exported step states its worst case in its header (docs/export.md, "A bounded
/// step"), and the 20 × 20 Preisach compensator's is 13 trial steps (1 at the grid's end,
/// ⌈log₂ 22⌉ = 5 over the levels, 6 over the memory's corners, 1 at the midpoint).
#[test]
fn every_header_states_the_steps_worst_case() {
    let mut all = cases::pi();
    all.extend(cases::sized());
    for case in all.iter().filter(|c| !c.name.ends_with("_beyond")) {
        let code = c_code(&case.file, &case.name, &case.options)
            .unwrap_or_else(|e| panic!("{}: {e}", case.name));
        assert!(
            code.header
                .contains("Worst case, for every input sequence:"),
            "{}: no worst case in the header",
            case.name
        );
    }
    let preisach = all
        .iter()
        .find(|c| c.name == "size_preisach_20_inverse")
        .expect("the sized Preisach compensator");
    let header = c_code(&preisach.file, &preisach.name, &preisach.options)
        .expect("export")
        .header
        .replace("\n * ", " ");
    assert!(
        header.contains("The Preisach inverse takes at most 13 trial steps a step"),
        "{header}"
    );
}
