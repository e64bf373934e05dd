//! The exit-code table (0 success, 1 bad input, 2 usage, 3 numerical failure, 4 I/O) and
//! one-line errors, usage errors included; `simulate`'s all-or-nothing outputs.

use crate::common::{fails_with, hysid, read_json, Assert};
use std::fs;
use std::path::Path;

/// Example 1 data, `samples` long, written to `dir/data.csv`.
fn example_data(dir: &Path, samples: &str) -> std::path::PathBuf {
    let data = dir.join("data.csv");
    hysid()
        .args(["generate", "voros", "--samples", samples, "--csv"])
        .arg(&data)
        .assert()
        .success();
    data
}

/// A ch_cascade model file with the linear block A(q⁻¹) = 1 + a1 q⁻¹ + a2 q⁻².
fn model_file(dir: &Path, a1: f64, a2: f64) -> std::path::PathBuf {
    let path = dir.join("model.json");
    let p = |name: &str, value: f64, fixed: bool| {
        format!(
            r#"{{"name": "{name}", "value": {value}, "std": null, "unit": "", "fixed": {fixed}, "lower": null, "upper": null}}"#
        )
    };
    let parameters = [
        p("alpha", 0.3, false),
        p("m1", 1.0, false),
        p("c1", 0.5, false),
        p("d", 3.0, false),
        p("b1", 1.0, true),
        p("b2", 0.5, false),
        p("a1", a1, false),
        p("a2", a2, false),
    ]
    .join(", ");
    let text = format!(
        r#"{{"schema": "hysid.model/1", "kind": "ch_cascade", "hysteresis": "ch4", "delay": 1, "parameters": [{parameters}]}}"#
    );
    fs::write(&path, text).unwrap();
    path
}

#[test]
fn help_and_version_print_normally_with_exit_0() {
    let out = hysid().arg("--help").output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8(out.stdout).unwrap().contains("Usage:"));
    let out = hysid()
        .args(["identify", "cascade", "--help"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8(out.stdout).unwrap().contains("--delay"));
    let out = hysid().arg("--version").output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8(out.stdout).unwrap().starts_with("hysid "));
}

#[test]
fn usage_errors_are_one_line_with_exit_2_and_point_to_help() {
    let line = fails_with(
        hysid().args([
            "identify",
            "cascade",
            "--data",
            "x.csv",
            "--input",
            "x",
            "--output",
            "y",
            "--hysteresis",
            "ch4",
            "--na",
            "2",
            "--nb",
            "2",
            "--delay",
            "abc",
        ]),
        2,
    );
    assert!(
        line.contains("'abc'")
            && line.contains("--delay")
            && line.contains("'hysid identify cascade --help'"),
        "{line}"
    );
    let line = fails_with(hysid().args(["simulate", "--data", "x.csv"]), 2);
    assert!(
        line.contains("--model") && line.contains("hysid simulate --help"),
        "{line}"
    );
    let line = fails_with(hysid().arg("frobnicate"), 2);
    assert!(line.contains("'frobnicate'"), "{line}");
    let line = fails_with(&mut hysid(), 2);
    assert!(line.contains("hysid --help"), "{line}");
    let line = fails_with(hysid().arg("demo"), 2);
    assert!(line.contains("'hysid demo --help'"), "{line}");
}

#[test]
fn a_missing_file_is_io_exit_4_and_bad_data_exit_1() {
    let dir = tempfile::tempdir().unwrap();
    let model = model_file(dir.path(), -0.6, 0.2);
    let line = fails_with(
        hysid()
            .args(["simulate", "--input", "x", "--model"])
            .arg(&model)
            .arg("--data")
            .arg(dir.path().join("missing.csv")),
        4,
    );
    assert!(line.contains("missing.csv"), "{line}");
    let empty = dir.path().join("empty.csv");
    fs::write(&empty, "").unwrap();
    fails_with(
        hysid()
            .args(["simulate", "--input", "x", "--model"])
            .arg(&model)
            .arg("--data")
            .arg(&empty),
        1,
    );
}

#[test]
fn a_diverging_simulation_is_a_numerical_failure_exit_3_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let data = example_data(dir.path(), "2000");
    // Poles of modulus √2.5: the output overflows within the record.
    let model = model_file(dir.path(), -3.0, 2.5);
    let csv = dir.path().join("sim.csv");
    fs::write(&csv, "previous").unwrap();
    fails_with(
        hysid()
            .args(["simulate", "--input", "x", "--output", "y", "--model"])
            .arg(&model)
            .arg("--data")
            .arg(&data)
            .arg("--csv")
            .arg(&csv)
            .arg("--json")
            .arg(dir.path().join("r.json")),
        3,
    );
    assert_eq!(fs::read_to_string(&csv).unwrap(), "previous");
    let mut names: Vec<String> = fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["data.csv", "model.json", "sim.csv"]);
}

#[test]
fn simulate_refuses_to_write_over_its_input_and_commits_both_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let data = example_data(dir.path(), "300");
    let model = model_file(dir.path(), -0.6, 0.2);
    let before = fs::read(&data).unwrap();
    let line = fails_with(
        hysid()
            .args(["simulate", "--input", "x", "--model"])
            .arg(&model)
            .arg("--data")
            .arg(&data)
            .arg("--json")
            .arg(dir.path().join(".").join("data.csv")),
        2,
    );
    assert!(line.contains("is also an input"), "{line}");
    assert_eq!(fs::read(&data).unwrap(), before);
    let (csv, json) = (dir.path().join("sim.csv"), dir.path().join("r.json"));
    hysid()
        .args(["simulate", "--input", "x", "--output", "y", "--model"])
        .arg(&model)
        .arg("--data")
        .arg(&data)
        .arg("--csv")
        .arg(&csv)
        .arg("--json")
        .arg(&json)
        .assert()
        .success();
    let report = read_json(&json);
    assert_eq!(report["data"]["samples"], 300);
    // The true model on its own noisy data: the fit is that of Example 1 (SNR 50).
    let fit = report["fit"]["fit_percent"].as_f64().unwrap();
    assert!(fit > 90.0 && fit < 100.0, "{fit}");
    assert_eq!(fs::read_to_string(&csv).unwrap().lines().count(), 301);
    assert!(!fs::read_dir(dir.path()).unwrap().any(|e| e
        .unwrap()
        .file_name()
        .to_string_lossy()
        .contains("hysid-tmp")));
}

/// `identify hysteresis` (ch4) on `data`, its report written to `report`.
fn ch4_fit(data: &Path, report: &Path) -> std::process::Command {
    let mut cmd = hysid();
    cmd.args(["identify", "hysteresis", "--hysteresis", "ch4", "--data"])
        .arg(data)
        .args(["--input", "x", "--output", "y", "--json"])
        .arg(report);
    cmd
}

/// A closed stdout (the report piped into `head -1`, which has exited) loses the human
/// report's text, not the run: the exit code is the run's, stderr holds no fault, and the
/// files are written; with stderr closed too (progress, warnings and the report all lost),
/// the same.
#[test]
fn a_closed_stdout_loses_the_report_text_not_the_run() {
    use std::process::Stdio;
    let dir = tempfile::tempdir().unwrap();
    let data = example_data(dir.path(), "300");
    let report = dir.path().join("report.json");
    let mut child = ch4_fit(&data, &report)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // the reader goes away before the run has printed anything
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(!stderr.contains("internal fault"), "{stderr}");
    assert_eq!(read_json(&report)["schema"], "hysid.report/1");

    fs::remove_file(&report).unwrap();
    let mut child = ch4_fit(&data, &report)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    drop(child.stderr.take());
    assert_eq!(child.wait().unwrap().code(), Some(0));
    assert_eq!(read_json(&report)["schema"], "hysid.report/1");
}

/// A stdout that fails otherwise (a full disk) is an I/O error, exit 4, after the result
/// files are written.
#[test]
fn a_full_stdout_is_an_io_error_after_the_files_are_written() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let data = example_data(dir.path(), "300");
    let report = dir.path().join("report.json");
    let out = ch4_fit(&data, &report)
        .arg("-q")
        .stdout(fs::File::create(full).unwrap())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(4), "{stderr}");
    assert!(stderr.contains("writing the report to stdout"), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert_eq!(read_json(&report)["schema"], "hysid.report/1");
}
