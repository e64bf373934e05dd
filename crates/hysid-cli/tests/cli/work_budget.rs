//! The work budget is honest: the estimate a command checks before it starts
//! (`search.estimated_model_steps`) is within 3× of the work it then counts
//! (`search.model_steps`), on small runs of the README's commands.

use crate::common::{hysid, read_json, Assert, IDENTIFY_CASCADE};
use std::path::{Path, PathBuf};
use tempfile::TempDir;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(name)
}

fn root(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(name)
}

/// The counted and the estimated model steps of the report at `path`, checked within 3×.
fn assert_honest(path: &Path) -> (u64, u64) {
    let report = read_json(path);
    let search = &report["search"];
    let counted = search["model_steps"].as_u64().expect("model_steps");
    let estimated = search["estimated_model_steps"]
        .as_u64()
        .expect("estimated_model_steps");
    let ratio = counted as f64 / estimated as f64;
    assert!(
        (1.0 / 3.0..=3.0).contains(&ratio),
        "{}: counted {counted}, estimated {estimated}, ratio {ratio}",
        report["command"]
    );
    (counted, estimated)
}

#[test]
fn identify_cascade_estimate_within_3x() {
    let dir = TempDir::new().unwrap();
    let csv = dir.path().join("v.csv");
    hysid()
        .args(["generate", "voros", "--example", "1", "--csv"])
        .arg(&csv)
        .arg("-q")
        .assert()
        .success();
    let json = dir.path().join("r.json");
    hysid()
        .args(IDENTIFY_CASCADE)
        .arg("--data")
        .arg(&csv)
        .arg("--json")
        .arg(&json)
        .arg("-q")
        .assert()
        .success();
    assert_honest(&json);
}

#[test]
fn greybox_fit_estimate_within_3x() {
    let dir = TempDir::new().unwrap();
    let json = dir.path().join("r.json");
    hysid()
        .args(["greybox", "fit", "--model-file"])
        .arg(root("examples/equations/cascaded_tanks.toml"))
        .arg("--data")
        .arg(data("cascaded-tanks/estimation.csv"))
        .args(["--input", "u_V", "--output", "y_V"])
        .args([
            "--starts",
            "8",
            "--seed",
            "1",
            "--substeps",
            "4",
            "-q",
            "--json",
        ])
        .arg(&json)
        .assert()
        .success();
    assert_honest(&json);
}

#[test]
fn benchmark_bouc_wen_estimate_within_3x() {
    let dir = TempDir::new().unwrap();
    let json = dir.path().join("r.json");
    hysid()
        .args(["benchmark", "bouc-wen", "--train"])
        .arg(data("bouc-wen/train_multisine_5periods.csv"))
        .args(["--start-factor", "2", "-q", "--json"])
        .arg(&json)
        .assert()
        .success();
    assert_honest(&json);
}

/// `identify operator` has no budget check (its fits are a few simulations of the record);
/// it still reports the work it performed.
#[test]
fn identify_operator_counts_its_work() {
    let dir = TempDir::new().unwrap();
    let json = dir.path().join("r.json");
    hysid()
        .args(["identify", "operator", "--family", "gpi", "--data"])
        .arg(data("piezo/piezo_150V_1Hz.csv"))
        .args([
            "--input",
            "voltage_V",
            "--output",
            "displacement_um",
            "-q",
            "--json",
        ])
        .arg(&json)
        .assert()
        .success();
    let search = &read_json(&json)["search"];
    assert!(search["model_steps"].as_u64().unwrap() > 0, "{search}");
    assert!(search.get("estimated_model_steps").is_none(), "{search}");
}
