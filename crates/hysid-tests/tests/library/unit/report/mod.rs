//! Tests of `hysid::report`.

mod plot;
mod rigid_body;

use hysid::report::*;

#[test]
fn an_empty_report_has_every_key_and_nulls() {
    let v = serde_json::to_value(Report::new("simulate")).unwrap();
    let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    for k in [
        "schema",
        "command",
        "version",
        "data",
        "model",
        "fit",
        "search",
        "uncertainty",
        "validation",
        "details",
        "warnings",
    ] {
        assert!(keys.contains(&k), "{k} missing");
    }
    assert!(v["fit"].is_null() && v["model"].is_null());
    assert_eq!(v["warnings"], serde_json::json!([]));
}

#[test]
fn published_schemas_are_up_to_date() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/schema");
    for (file, schema) in [
        ("hysid.report.v1.json", report_schema()),
        ("hysid.model.v1.json", model_schema()),
    ] {
        let text = serde_json::to_string_pretty(&schema).unwrap() + "\n";
        let path = root.join(file);
        if std::env::var_os("HYSID_WRITE_SCHEMA").is_some() {
            std::fs::create_dir_all(&root).unwrap();
            std::fs::write(&path, &text).unwrap();
        }
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        assert_eq!(
            committed,
            text,
            "{} is out of date: run HYSID_WRITE_SCHEMA=1 cargo test --release -p hysid-tests --test library published_schemas",
            path.display()
        );
    }
}

#[test]
fn non_finite_figures_are_refused() {
    let y = [1.0, 2.0, 3.0];
    let bad = [1.0, f64::NAN, 3.0];
    assert!(FitSummary::of(&["e1".into()], &[&y], &[&bad]).is_err());
    assert!(ValidationEntry::of("t".into(), &y, &bad, None).is_err());
}
