//! The saved-model file `hysid.model/1` against its fixtures (`tests/fixtures/models`, one
//! file of every kind and variant written by commit 4977487, each with the output `hysid
//! simulate` gave for it; see the README there): every fixture loads, simulates
//! bit-identically to its stored output and writes back the same model object, and broken
//! copies are refused with one line naming the kind and the key.

use hysid::data::{CsvSpec, IdData};
use hysid::model::kinds::coleman_hodgdon::ColemanHodgdonFile;
use hysid::model::saved::FittedGreyBox;
use hysid::model::saved::{FittedModel, ModelFile, SavedModel, MODEL_KINDS};
use hysid::report::simulate_report;
use serde_json::{json, Value};
use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

fn fixture_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/models")
}

/// One line of `manifest.txt`: the model file (or report), the record it is simulated on,
/// the record's input and output columns, and the stored `hysid simulate --csv` output.
struct Fixture {
    name: String,
    model: PathBuf,
    record: PathBuf,
    input: String,
    output: String,
    expected: PathBuf,
    is_report: bool,
}

fn fixtures() -> Vec<Fixture> {
    let dir = fixture_dir();
    let manifest = fs::read_to_string(dir.join("manifest.txt")).unwrap();
    manifest
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let f: Vec<&str> = line.split_whitespace().collect();
            assert_eq!(f.len(), 4, "manifest line '{line}'");
            let (name, is_report) = match f[0].strip_suffix(".model.json") {
                Some(name) => (name, false),
                None => (f[0].strip_suffix(".report.json").unwrap(), true),
            };
            Fixture {
                name: name.to_string(),
                model: dir.join(f[0]),
                record: dir.join(f[1]),
                input: f[2].to_string(),
                output: f[3].to_string(),
                expected: dir.join(format!("{name}.expected.csv")),
                is_report,
            }
        })
        .collect()
}

/// The model object of a fixture (a report's `model`).
fn model_object(f: &Fixture) -> Value {
    let value: Value = serde_json::from_str(&fs::read_to_string(&f.model).unwrap()).unwrap();
    if f.is_report {
        value["model"].clone()
    } else {
        value
    }
}

/// The model object of the fixture `file` (a model file of this folder).
fn object_of(file: &str) -> Value {
    serde_json::from_str(&fs::read_to_string(fixture_dir().join(file)).unwrap()).unwrap()
}

/// The header and columns of a CSV written by `hysid simulate --csv`.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let mut columns = vec![Vec::new(); header.len()];
    for line in lines {
        for (c, v) in columns.iter_mut().zip(line.split(',')) {
            // The writer writes the shortest text that reads back to the same f64.
            c.push(v.parse::<f64>().unwrap());
        }
    }
    (header, columns)
}

#[test]
fn every_fixture_loads_and_simulates_bit_identically() {
    let all = fixtures();
    assert!(all.len() >= 36, "{} fixtures", all.len());
    let mut kinds = BTreeSet::new();
    let (mut prefiltered, mut inverse_dynamics) = (0, 0);
    for f in &all {
        let model = FittedModel::load(&f.model)
            .unwrap_or_else(|e| panic!("{}: does not load: {e}", f.name));
        let file = model.to_file();
        kinds.insert(file.kind().to_string());
        prefiltered += usize::from(file.prefilter.is_some());
        inverse_dynamics += usize::from(file.inverse_dynamics.is_some());
        let spec = CsvSpec {
            inputs: vec![f.input.clone()],
            outputs: vec![f.output.clone()],
            time: None,
            ts: None,
            ..CsvSpec::default()
        };
        let data = IdData::from_file(&f.record, &spec).unwrap();
        let (_, predictions) = simulate_report(&model, &[(f.name.clone(), &data)])
            .unwrap_or_else(|e| panic!("{}: does not simulate: {e}", f.name));
        let p = &predictions[0];
        let (header, expected) = read_csv(&f.expected);
        assert_eq!(header, [f.input.as_str(), "simulated", f.output.as_str()]);
        let got = [&p.inputs[0], &p.outputs[0], p.measured.as_ref().unwrap()];
        for ((column, want), got) in header.iter().zip(&expected).zip(got) {
            assert_eq!(want.len(), got.len(), "{}: {column}: length", f.name);
            if let Some(k) = (0..want.len()).find(|&k| want[k].to_bits() != got[k].to_bits()) {
                panic!(
                    "{}: {column}[{k}] = {:e}, the fixture has {:e}",
                    f.name, got[k], want[k]
                );
            }
        }
    }
    for kind in MODEL_KINDS {
        assert!(kinds.contains(kind), "no fixture of kind {kind}");
    }
    assert!(prefiltered >= 1 && inverse_dynamics >= 1);
}

#[test]
fn every_fixture_writes_back_its_model_object() {
    for f in fixtures() {
        let object = model_object(&f);
        let written = FittedModel::load(&f.model).unwrap().to_file();
        assert_eq!(
            serde_json::to_value(&written).unwrap(),
            object,
            "{}: the model object written back differs",
            f.name
        );
        if !f.is_report {
            // The same text: keys in the same order, numbers written alike.
            let text = fs::read_to_string(&f.model).unwrap();
            assert_eq!(
                serde_json::to_string_pretty(&written).unwrap(),
                text.trim_end(),
                "{}",
                f.name
            );
        }
        // The file itself reads and writes back unchanged.
        let file: ModelFile = serde_json::from_value(object.clone()).unwrap();
        assert_eq!(file, written, "{}", f.name);
        assert_eq!(serde_json::to_value(&file).unwrap(), object, "{}", f.name);
    }
}

/// The error of loading `object` from a file: one line, returned.
fn refusal(object: &Value) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.json");
    fs::write(&path, serde_json::to_string_pretty(object).unwrap()).unwrap();
    let e = match FittedModel::load(&path) {
        Ok(_) => panic!("loaded: {object}"),
        Err(e) => e.to_string(),
    };
    assert_eq!(e.lines().count(), 1, "{e}");
    e
}

/// `object` with `key` set to `value` (or removed, for None).
fn with(object: &Value, key: &str, value: Option<Value>) -> Value {
    let mut o = object.clone();
    let map = o.as_object_mut().unwrap();
    match value {
        Some(v) => map.insert(key.into(), v),
        None => map.remove(key),
    };
    o
}

#[test]
fn an_unknown_key_is_refused_naming_it_and_the_kind() {
    for (file, kind) in [
        ("ch_cascade_ch4.model.json", "ch_cascade"),
        ("coleman_hodgdon_ch4.model.json", "coleman_hodgdon"),
        ("operator_pi.model.json", "operator"),
        ("operator_cascade_pi.model.json", "operator_cascade"),
        ("bouc_wen.model.json", "bouc_wen"),
        ("equations_bouc_wen.model.json", "equations"),
        ("actuator_fixed_prefilter.model.json", "actuator_fixed"),
        ("rigid_body_inverse_dynamics.model.json", "rigid_body"),
    ] {
        let e = refusal(&with(&object_of(file), "colour", Some(json!("blue"))));
        assert!(
            e.contains("unknown field `colour`") && e.contains(&format!("the {kind} model")),
            "{file}: {e}"
        );
    }
    // A key of another kind is not this kind's.
    let cascade = object_of("ch_cascade_ch4.model.json");
    let e = refusal(&with(&cascade, "initial_state", Some(json!([0.0]))));
    assert!(
        e.contains("unknown field `initial_state`") && e.contains("ch_cascade"),
        "{e}"
    );
    let e = refusal(&with(&cascade, "initial_output", Some(json!("zero"))));
    assert!(e.contains("`initial_output`"), "{e}");
    // Inside the structure too.
    let mut bw = object_of("bouc_wen.model.json");
    bw["simulation"]["substep"] = json!(3);
    let e = refusal(&bw);
    assert!(e.contains("unknown field `substep`"), "{e}");
    let mut pf = object_of("actuator_fixed_prefilter.model.json");
    pf["prefilter"]["cutoff"] = json!(3);
    let e = refusal(&pf);
    assert!(e.contains("\"prefilter\"") && e.contains("`cutoff`"), "{e}");
    let mut p = object_of("coleman_hodgdon_ch4.model.json");
    p["parameters"][0]["sd"] = json!(1.0);
    let e = refusal(&p);
    assert!(e.contains("unknown field `sd`"), "{e}");
    // In a report's model.
    let mut report = object_of("report_ch_cascade.report.json");
    report["model"]["colour"] = json!("blue");
    let e = refusal(&report);
    assert!(e.contains("unknown field `colour`"), "{e}");
}

#[test]
fn a_missing_required_key_is_refused_naming_it_and_the_kind() {
    for (file, kind, key) in [
        ("ch_cascade_ch4.model.json", "ch_cascade", "delay"),
        ("ch_cascade_ch4.model.json", "ch_cascade", "hysteresis"),
        (
            "coleman_hodgdon_ch4.model.json",
            "coleman_hodgdon",
            "hysteresis",
        ),
        (
            "operator_cascade_pi.model.json",
            "operator_cascade",
            "delay",
        ),
        (
            "operator_cascade_pi.model.json",
            "operator_cascade",
            "operator",
        ),
        ("operator_pi.model.json", "operator", "family"),
        ("operator_pi.model.json", "operator", "operator"),
        ("equations_bouc_wen.model.json", "equations", "equations"),
        ("bouc_wen.model.json", "bouc_wen", "parameters"),
        ("actuator_free.model.json", "actuator_free", "parameters"),
    ] {
        let object = object_of(file);
        for broken in [
            with(&object, key, None),
            with(&object, key, Some(Value::Null)),
        ] {
            let e = refusal(&broken);
            assert!(
                e.contains(&format!("`{key}`")) && e.contains(kind),
                "{file} without {key}: {e}"
            );
        }
    }
    // A value of the wrong type, named by its key.
    for (file, key, value) in [
        ("ch_cascade_ch4.model.json", "delay", json!("one")),
        ("ch_cascade_ch4.model.json", "hysteresis", json!("ch5")),
        (
            "coleman_hodgdon_ch4.model.json",
            "initial_output",
            json!("first"),
        ),
        ("operator_pi.model.json", "family", json!(7)),
        ("bouc_wen.model.json", "initial_state", json!("zero")),
        ("bouc_wen.model.json", "parameters", json!([{"name": "mL"}])),
    ] {
        let e = refusal(&with(&object_of(file), key, Some(value)));
        assert!(e.contains(&format!("\"{key}\"")), "{file}, {key}: {e}");
    }
    let e = refusal(&with(&object_of("bouc_wen.model.json"), "schema", None));
    assert!(e.contains("`schema`"), "{e}");
    let e = refusal(&with(&object_of("bouc_wen.model.json"), "kind", None));
    assert!(e.contains("`kind`"), "{e}");
    // A parameter record the kind needs.
    let mut cascade = object_of("ch_cascade_ch4.model.json");
    cascade["parameters"].as_array_mut().unwrap().remove(0);
    let e = refusal(&cascade);
    assert!(
        e.contains("parameter 'alpha' is missing from the ch_cascade model"),
        "{e}"
    );
}

#[test]
fn a_wrong_kind_is_refused() {
    let cascade = object_of("ch_cascade_ch4.model.json");
    let e = refusal(&with(&cascade, "kind", Some(json!("ch_casade"))));
    assert!(
        e.contains("unknown model kind 'ch_casade'") && e.contains("operator_cascade"),
        "{e}"
    );
    let e = refusal(&with(&cascade, "kind", Some(json!(3))));
    assert!(e.contains("\"kind\" is 3"), "{e}");
    // Another kind's name: its keys do not fit.
    let e = refusal(&with(&cascade, "kind", Some(json!("coleman_hodgdon"))));
    assert!(
        e.contains("the coleman_hodgdon model") && e.contains("`delay`"),
        "{e}"
    );
    let e = refusal(&with(&cascade, "kind", Some(json!("operator_cascade"))));
    assert!(e.contains("the operator_cascade model"), "{e}");
    let bw = object_of("bouc_wen.model.json");
    let e = refusal(&with(&bw, "kind", Some(json!("rigid_body"))));
    assert!(
        e.contains("parameter 'M' is missing from the rigid_body model"),
        "{e}"
    );
    let e = refusal(&with(&bw, "kind", Some(json!("python"))));
    assert!(e.contains("unknown model kind 'python'"), "{e}");
}

#[test]
fn keys_written_out_as_null_read_as_left_out() {
    // As files written by hand (the Python tests' do) spell out the keys that do not apply.
    let bw = object_of("bouc_wen.model.json");
    let mut spelled = bw.clone();
    for key in [
        "hysteresis",
        "delay",
        "initial_output",
        "equations",
        "prefilter",
    ] {
        spelled[key] = Value::Null;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.json");
    fs::write(&path, spelled.to_string()).unwrap();
    let model = FittedModel::load(&path).unwrap();
    assert_eq!(serde_json::to_value(model.to_file()).unwrap(), bw);
    // Optional keys of the kind: their documented defaults.
    let ch = object_of("coleman_hodgdon_ch4.model.json");
    let file: ModelFile =
        serde_json::from_value(with(&ch, "initial_output", Some(Value::Null))).unwrap();
    assert!(matches!(
        file.model,
        SavedModel::ColemanHodgdon(ColemanHodgdonFile {
            initial_output: None,
            ..
        })
    ));
    FittedModel::from_file(&file).unwrap();
}

#[test]
fn a_key_given_twice_is_refused() {
    let text = fs::read_to_string(fixture_dir().join("ch_cascade_ch4.model.json")).unwrap();
    let twice = text.replacen("\"delay\": 1", "\"delay\": 1, \"delay\": 2", 1);
    assert_ne!(twice, text);
    let e = serde_json::from_str::<ModelFile>(&twice)
        .unwrap_err()
        .to_string();
    assert!(e.contains("duplicate field `delay`"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.json");
    fs::write(&path, &twice).unwrap();
    let e = FittedModel::load(&path).unwrap_err().to_string();
    assert!(
        e.contains("duplicate field `delay`") && e.lines().count() == 1,
        "{e}"
    );
    // In a report's model too.
    let report = fs::read_to_string(fixture_dir().join("report_ch_cascade.report.json")).unwrap();
    let twice = report.replacen("\"delay\": 1", "\"delay\": 1, \"delay\": 2", 1);
    assert_ne!(twice, report);
    fs::write(&path, &twice).unwrap();
    let e = FittedModel::load(&path).unwrap_err().to_string();
    assert!(e.contains("duplicate field `delay`"), "{e}");
}

#[test]
fn a_grey_box_model_of_the_user_is_written_under_its_own_kind_and_not_read_back() {
    use hysid::model::greybox::models::GreyBoxKind;
    use hysid::model::greybox::Simulation;
    // The built-in kinds: their names are their models' own kinds and parse back, with the
    // command line's dashes too.
    for kind in GreyBoxKind::ALL {
        assert_eq!(kind.model().kind(), kind.name());
        assert_eq!(GreyBoxKind::parse(kind.name()), Some(kind));
        assert_eq!(
            GreyBoxKind::parse(&kind.name().replace('_', "-")),
            Some(kind)
        );
    }
    assert_eq!(GreyBoxKind::parse("duffing"), None);
    // A model of the user's own (e.g. Python callbacks) under the kind it gives itself.
    let model = GreyBoxKind::RigidBody.model();
    let parameters = model.parameters();
    let fitted = FittedModel::GreyBox(FittedGreyBox {
        kind: "python".into(),
        std: vec![f64::NAN; parameters.len()],
        parameters,
        simulation: Simulation::default(),
        initial_state: vec![0.0; model.states().len()],
    });
    let file = fitted.to_file();
    assert_eq!(file.kind(), "python");
    let value = serde_json::to_value(&file).unwrap();
    let keys: BTreeSet<&str> = value
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    assert_eq!(
        keys,
        BTreeSet::from([
            "schema",
            "kind",
            "parameters",
            "simulation",
            "initial_state"
        ])
    );
    assert_eq!(value["kind"], "python");
    let e = refusal(&value);
    assert!(e.contains("unknown model kind 'python'"), "{e}");
    // The same model under its built-in kind is a rigid_body file.
    let FittedModel::GreyBox(FittedGreyBox {
        parameters,
        std,
        simulation,
        initial_state,
        ..
    }) = fitted
    else {
        unreachable!()
    };
    let builtin = FittedModel::GreyBox(FittedGreyBox {
        kind: "rigid_body".into(),
        parameters,
        std,
        simulation,
        initial_state,
    });
    assert!(matches!(builtin.to_file().model, SavedModel::RigidBody(_)));
}

#[test]
fn input_range_round_trips_gives_the_default_limits_and_is_optional() {
    use hysid::data::IdData;
    use hysid::model::limits::Limits;
    use hysid::model::operators::OperatorModel;
    use hysid::model::saved::{FittedModel, ModelFile};
    let op = OperatorModel::examples().unwrap().remove(0);
    let n = op.as_operator().parameters().len();
    let file = FittedModel::operator(op, vec![f64::NAN; n]).to_file();
    let u = vec![0.5, -2.0, 3.0, 1.0];
    let data = IdData::siso(1e-3, "u", u.clone(), "y", u).unwrap();
    let ranged = file.clone().with_input_range(&data);
    assert_eq!(ranged.input_range, Some(vec![[-2.0, 3.0]]));
    let text = serde_json::to_string(&ranged).unwrap();
    assert!(text.contains("\"input_range\":[[-2.0,3.0]]"), "{text}");
    let back: ModelFile = serde_json::from_str(&text).unwrap();
    assert_eq!(back.limits(), Some(Limits::new(-2.0, 3.0).unwrap()));
    // A file of an earlier version: no range, no limits, the same model.
    let old: ModelFile = serde_json::from_str(&serde_json::to_string(&file).unwrap()).unwrap();
    assert_eq!((old.input_range.clone(), old.limits()), (None, None));
    // A range that is not [min, max] is refused in one line.
    let bad = text.replace("[[-2.0,3.0]]", "[[3.0,-2.0]]");
    let err = serde_json::from_str::<ModelFile>(&bad)
        .unwrap_err()
        .to_string();
    assert!(err.contains("input_range") && !err.contains('\n'), "{err}");
}
