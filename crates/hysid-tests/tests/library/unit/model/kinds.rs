//! The registry of model kinds (`hysid::model::kinds`): one module per kind and one line of
//! `model_kinds!` give the kind everything `hysid.model/1` needs — its name in
//! `MODEL_KINDS`, its branch of the JSON Schema, its reading with the path of a bad key named.

use hysid::model::greybox::models::GreyBoxKind;
use hysid::model::kinds::{ch_cascade, coleman_hodgdon, ModelKind};
use hysid::model::saved::FittedHysteresis;
use hysid::model::saved::{FittedModel, ModelFile, SavedModel, MODEL_KINDS};
use hysid::model::ChForm;
use hysid::report::model_schema;
use serde_json::json;
use std::path::Path;

/// The directory of the kinds' modules.
fn kinds_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../hysid/src/model/kinds")
}

#[test]
fn every_kind_is_one_module_and_one_line_of_the_list() {
    // The list generates the kind table, in its order, and the schema's branches.
    let schema = model_schema();
    let branches: Vec<&str> = schema["anyOf"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["properties"]["kind"]["const"].as_str().unwrap())
        .collect();
    assert_eq!(branches, MODEL_KINDS);
    // Each kind has its module (the four built-in grey-box kinds share `grey_box.rs`), and
    // each module of the directory is a kind's.
    let grey_box: Vec<&str> = GreyBoxKind::ALL.iter().map(|k| k.name()).collect();
    for kind in MODEL_KINDS {
        let module = if grey_box.contains(&kind) {
            "grey_box"
        } else {
            kind
        };
        assert!(
            kinds_dir().join(format!("{module}.rs")).is_file(),
            "kind {kind} has no module kinds/{module}.rs"
        );
    }
    let list = std::fs::read_to_string(kinds_dir().join("mod.rs")).unwrap();
    for entry in std::fs::read_dir(kinds_dir()).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        let module = name.trim_end_matches(".rs");
        if module != "mod" {
            assert!(
                list.contains(&format!("=> {module}::")),
                "kinds/{name} is in no line of model_kinds!"
            );
        }
    }
}

#[test]
fn a_kind_reads_and_writes_its_own_file() {
    // The kind's `File` is its serde form: a file of the kind is the tag and those keys.
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/models/coleman_hodgdon_ch4.model.json");
    let model = ModelFile::load(&path).unwrap().model;
    let SavedModel::ColemanHodgdon(file) = &model else {
        panic!("not a coleman_hodgdon file: {}", model.kind())
    };
    assert_eq!(file.hysteresis, ChForm::Saturated4);
    let fitted = coleman_hodgdon::ColemanHodgdonKind::fitted(file).unwrap();
    assert!(matches!(
        fitted,
        FittedModel::Hysteresis(FittedHysteresis { .. })
    ));
    assert_eq!(fitted.to_file().model.kind(), "coleman_hodgdon");
    let value = serde_json::to_value(&model).unwrap();
    assert_eq!(value["kind"], "coleman_hodgdon");
    assert_eq!(serde_json::from_value::<SavedModel>(value).unwrap(), model);
    // The registry's dispatch finds the kind's parameters.
    assert_eq!(model.parameters(), &file.parameters[..]);
    assert_eq!(
        <ch_cascade::ChCascadeKind as ModelKind>::parameters(&ch_cascade::ChCascadeFile {
            parameters: file.parameters.clone(),
            hysteresis: ChForm::Saturated4,
            delay: 1,
        }),
        &file.parameters[..]
    );
}

#[test]
fn a_bad_value_deep_in_a_kind_is_named_by_its_path() {
    let mut object = json!({
        "schema": "hysid.model/1", "kind": "ch_cascade", "hysteresis": "ch4", "delay": 1,
        "parameters": [
            {"name": "alpha", "value": 0.3, "std": null, "unit": "", "fixed": false,
             "lower": null, "upper": null}
        ]
    });
    object["parameters"][0]["value"] = json!("high");
    let e = serde_json::from_value::<ModelFile>(object.clone())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("the ch_cascade model: \"parameters\"[0].\"value\": invalid type"),
        "{e}"
    );
    object["parameters"][0]["value"] = json!(0.3);
    object["delay"] = json!(-1);
    let e = serde_json::from_value::<ModelFile>(object)
        .unwrap_err()
        .to_string();
    assert!(e.contains("the ch_cascade model: \"delay\": "), "{e}");
}

#[test]
fn every_fitted_struct_is_one_line_of_the_list_with_its_run_time_and_its_export() {
    // The lines of `fitted_kinds!`: `Variant => $crate::model::kinds::<module>::<Struct>,`.
    let list = std::fs::read_to_string(kinds_dir().join("mod.rs")).unwrap();
    let export = std::fs::read_to_string(kinds_dir().join("../../export/kinds.rs")).unwrap();
    let lines: Vec<(String, String)> = list
        .lines()
        .filter_map(|line| {
            let rest = line.trim().split("=> $crate::model::kinds::").nth(1)?;
            let (module, name) = rest.trim_end_matches(',').split_once("::")?;
            Some((module.to_string(), name.to_string()))
        })
        .collect();
    assert_eq!(lines.len(), 6, "the lines of fitted_kinds!: {lines:?}");
    for (module, name) in &lines {
        let text = std::fs::read_to_string(kinds_dir().join(format!("{module}.rs"))).unwrap();
        assert!(
            text.contains(&format!("pub struct {name} {{")),
            "{name} is not defined in kinds/{module}.rs"
        );
        assert!(
            text.contains(&format!("impl FittedKind for {name} {{")),
            "{name} does not implement FittedKind in kinds/{module}.rs"
        );
        assert!(
            export.contains(&format!("impl ExportKind for {name} {{")),
            "{name} has no export (impl ExportKind in export/kinds.rs)"
        );
    }
}

#[test]
fn every_fixture_model_saves_through_its_kind_as_it_reads() {
    // Each model file of the fixtures: read, rebuilt through the registry, saved again by its
    // kind's struct (behind the record processing, if any) — the same model as the file's.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/models");
    let mut kinds = std::collections::BTreeSet::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if !path.to_string_lossy().ends_with(".model.json") {
            continue;
        }
        let file = ModelFile::load(&path).unwrap();
        let fitted = FittedModel::from_file(&file).unwrap();
        let inner = match &fitted {
            FittedModel::Prefiltered { model, .. } | FittedModel::InverseDynamics { model, .. } => {
                assert!(fitted.as_kind().is_none());
                model.as_ref()
            }
            kind => kind,
        };
        let kind = inner.as_kind().expect("a model of one kind");
        let saved = kind.saved();
        assert_eq!(saved.kind(), file.model.kind(), "{}", path.display());
        assert_eq!(
            saved.parameters().len(),
            file.model.parameters().len(),
            "{}",
            path.display()
        );
        for (s, f) in saved.parameters().iter().zip(file.model.parameters()) {
            assert_eq!((&s.name, s.value), (&f.name, f.value), "{}", path.display());
        }
        assert_eq!(fitted.to_file().model, saved, "{}", path.display());
        kinds.insert(saved.kind().to_string());
    }
    // Every kind this version reads has a fixture.
    for kind in MODEL_KINDS {
        assert!(kinds.contains(kind), "no fixture model of kind {kind}");
    }
}
