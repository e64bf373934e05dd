//! Every command writes its outputs through one transaction (`hysid::io::atomic::OutputSet`):
//! registered before any work, refused when one equals an input, renamed into place together
//! at the end — a failed run leaves neither a file nor a temporary.

use crate::common::{hysid, Assert, IDENTIFY_CASCADE};
use std::fs;
use std::path::Path;
use tempfile::TempDir;

/// The sorted names of the entries of `dir`.
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn example_data(dir: &Path) -> std::path::PathBuf {
    let data = dir.join("ex1.csv");
    hysid()
        .args(["generate", "voros", "--example", "1", "--csv"])
        .arg(&data)
        .assert()
        .success();
    data
}

#[test]
fn an_unwritable_second_output_leaves_no_file_and_no_temporary() {
    let tmp = TempDir::new().unwrap();
    let dir = tmp.path();
    let data = example_data(dir);
    hysid()
        .args(IDENTIFY_CASCADE)
        .arg("--data")
        .arg(&data)
        .arg("--json")
        .arg(dir.join("report.json"))
        .arg("--plots")
        .arg(dir.join("plots"))
        .arg("--model-out")
        .arg(dir.join("missing/model.json"))
        .assert()
        .failure()
        .stderr_contains("does not exist");
    assert_eq!(entries(dir), ["ex1.csv"]);
}

#[test]
fn an_output_equal_to_an_input_is_refused_before_computing() {
    let tmp = TempDir::new().unwrap();
    let dir = tmp.path();
    let data = example_data(dir);
    let before = fs::read(&data).unwrap();
    hysid()
        .args(IDENTIFY_CASCADE)
        .arg("--data")
        .arg(&data)
        .arg("--json")
        .arg(&data)
        .assert()
        .failure()
        .stderr_contains("is also an input")
        // Refused at registration: the fit never started.
        .stdout_lacks("Cascade");
    assert_eq!(fs::read(&data).unwrap(), before);
    assert_eq!(entries(dir), ["ex1.csv"]);
}

#[test]
fn all_outputs_of_a_run_appear_together() {
    let tmp = TempDir::new().unwrap();
    let dir = tmp.path();
    let data = example_data(dir);
    hysid()
        .current_dir(dir)
        .args(IDENTIFY_CASCADE)
        .args(["--data", "ex1.csv", "--json", "report.json"])
        .args(["--model-out", "model.json", "--plots", "plots"])
        .assert()
        .success();
    assert_eq!(
        entries(dir),
        ["ex1.csv", "model.json", "plots", "report.json"]
    );
    let plots = entries(&dir.join("plots"));
    for name in ["input.svg", "loops.svg", "output.svg"] {
        assert!(plots.iter().any(|p| p == name), "{name} missing: {plots:?}");
    }
    assert!(data.is_file());
}

#[test]
fn the_rig_replaces_an_existing_data_directory_all_or_nothing() {
    let tmp = TempDir::new().unwrap();
    let dir = tmp.path();
    let rig = dir.join("rig");
    fs::create_dir(&rig).unwrap();
    fs::write(rig.join("old.txt"), "from an earlier run").unwrap();
    // A failing run leaves the directory as it was.
    hysid()
        .args(["actuator", "rig", "--noise", "-1", "--data-out"])
        .arg(&rig)
        .assert()
        .failure();
    assert_eq!(entries(&rig), ["old.txt"]);
    // A successful one replaces it whole, with no temporary left beside it.
    hysid()
        .args(["actuator", "rig", "--data-out"])
        .arg(&rig)
        .assert()
        .success();
    let mut expected: Vec<String> = (1..=8).map(|k| format!("dataset{k}.csv")).collect();
    expected.push("rig.json".into());
    assert_eq!(entries(&rig), expected);
    assert_eq!(entries(dir), ["rig"]);
}
