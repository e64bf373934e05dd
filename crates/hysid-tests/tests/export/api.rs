//! The API's refusals, the interface and the determinism of the generated files.

use crate::cases;
use hysid::export::{c_code, export, ExportOptions, Target};

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
    assert!(e.to_string().contains("--ts"), "{e}");
}
