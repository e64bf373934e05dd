//! Command-line tests: the commands work end to end, and bad input gives one clear line on
//! stderr, a non-zero exit, no panic and no output file.

use crate::common::{hysid, read_json, Assert};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use tempfile::TempDir;

/// The entry of parameter `name` in a report's `model.parameters`.
fn param<'a>(report: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    report["model"]["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == name)
        .unwrap_or_else(|| panic!("no parameter {name} in {report}"))
}

/// Writes a CSV file with the given header and rows.
fn csv(dir: &Path, name: &str, header: &str, rows: &[String]) -> PathBuf {
    let path = dir.join(name);
    let mut text = format!("{header}\n");
    for r in rows {
        text.push_str(r);
        text.push('\n');
    }
    fs::write(&path, text).unwrap();
    path
}

/// Example 1's data (noise-free) written by `hysid generate voros`.
fn example_data(dir: &Path, noise_free: bool) -> PathBuf {
    let path = dir.join("ex1.csv");
    let mut cmd = hysid();
    cmd.args(["generate", "voros", "--example", "1", "--csv"])
        .arg(&path);
    if noise_free {
        cmd.arg("--noise-free");
    }
    cmd.assert().success();
    path
}

/// `hysid identify cascade` on `data` with Example 1's structure.
fn identify_cascade(data: &Path) -> Command {
    let mut cmd = hysid();
    cmd.args([
        "identify",
        "cascade",
        "--input",
        "x",
        "--output",
        "y",
        "--hysteresis",
        "ch4",
    ])
    .args(["--na", "2", "--nb", "2", "--delay", "1", "--data"])
    .arg(data);
    cmd
}

/// Example 1's noise-free data and the model file identified from it.
fn identified_example(dir: &Path) -> (PathBuf, PathBuf) {
    let data = example_data(dir, true);
    let model = dir.join("model.json");
    identify_cascade(&data)
        .arg("--model-out")
        .arg(&model)
        .assert()
        .success();
    (data, model)
}

/// Runs `hysid identify cascade` on `data` expecting failure; returns stderr.
fn identify_fails(data: &Path, json: &Path) -> String {
    let out = identify_cascade(data)
        .arg("--json")
        .arg(json)
        .assert()
        .failure()
        .get_output()
        .clone();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected one line, got: {stderr}");
    assert!(lines[0].starts_with("error: "), "{stderr}");
    assert!(!json.exists(), "a report was written despite the error");
    stderr
}

fn rows(n: usize, f: impl Fn(usize) -> String) -> Vec<String> {
    (0..n).map(f).collect()
}

#[test]
fn demo_reports_every_parameter_and_writes_plots() {
    let dir = TempDir::new().unwrap();
    let json = dir.path().join("report.json");
    let out = hysid()
        .args([
            "demo",
            "voros",
            "--example",
            "1",
            "--uncertainty",
            "asymptotic",
            "--plots",
        ])
        .arg(dir.path())
        .arg("--json")
        .arg(&json)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let stdout = String::from_utf8(out).unwrap();
    for name in [
        "alpha",
        "m1",
        "c1",
        "d",
        "b2",
        "a1",
        "a2",
        "fit",
        "paper iteration",
    ] {
        assert!(stdout.contains(name), "missing {name} in:\n{stdout}");
    }
    let report = read_json(&json);
    assert_eq!(report["model"]["kind"], "ch_cascade");
    assert!(param(&report, "alpha")["value"].as_f64().unwrap() > 0.29);
    assert!(param(&report, "alpha")["std"].as_f64().unwrap() > 0.0);
    assert_eq!(param(&report, "b1")["value"], 1.0);
    assert!(param(&report, "b1")["fixed"].as_bool().unwrap());
    assert!(param(&report, "b1")["std"].is_null());
    assert!(param(&report, "a2")["value"].is_f64());
    for (section, key) in [
        ("fit", "fit_percent"),
        ("fit", "rmse"),
        ("search", "iterations"),
        ("search", "termination"),
        ("search", "elapsed_s"),
    ] {
        assert!(!report[section][key].is_null(), "missing {section}.{key}");
    }
    assert!(report["fit"]["fit_percent"].as_f64().unwrap() > 97.0);
    for plot in [
        "loops.svg",
        "input.svg",
        "output.svg",
        "paper_iteration.svg",
        "output_error_iterations.svg",
    ] {
        assert!(
            dir.path().join("voros-example1").join(plot).exists(),
            "{plot}"
        );
    }
}

#[test]
fn identified_model_file_simulates_the_data() {
    let dir = TempDir::new().unwrap();
    let (data, model) = identified_example(dir.path());
    let report = dir.path().join("sim.json");
    let sim = dir.path().join("sim.csv");
    hysid()
        .args(["simulate", "--input", "x", "--output", "y", "--model"])
        .arg(&model)
        .arg("--data")
        .arg(&data)
        .arg("--json")
        .arg(&report)
        .arg("--csv")
        .arg(&sim)
        .assert()
        .success();
    let report = read_json(&report);
    assert!(
        report["fit"]["fit_percent"].as_f64().unwrap() > 99.9999,
        "{report}"
    );
    assert!(fs::read_to_string(&sim)
        .unwrap()
        .starts_with("x,simulated,y"));
}

#[test]
fn hysteresis_alone_is_identified_from_a_csv_file() {
    let dir = TempDir::new().unwrap();
    // A hysteresis record: the examples' input through a known 6-parameter hysteresis.
    let h = hysid::model::ColemanHodgdon::general(0.4, 1.2, 0.15, 0.6, 0.1, 2.0).unwrap();
    let x = hysid::experiments::voros::CascadeExample::example2()
        .generate(1, false)
        .unwrap()
        .x;
    let y = h.simulate(&x, 0.0).unwrap();
    let data = csv(
        dir.path(),
        "h.csv",
        "u,v",
        &rows(x.len(), |i| format!("{},{}", x[i], y[i])),
    );
    let json = dir.path().join("h.json");
    hysid()
        .args([
            "identify",
            "hysteresis",
            "--input",
            "u",
            "--output",
            "v",
            "--hysteresis",
            "ch6",
            "--data",
        ])
        .arg(&data)
        .arg("--json")
        .arg(&json)
        .assert()
        .success();
    let report = read_json(&json);
    assert_eq!(report["model"]["kind"], "coleman_hodgdon");
    let d = param(&report, "d")["value"].as_f64().unwrap();
    assert!((d - 2.0).abs() < 1e-6, "{d}");
}

/// The one-line error of `hysid identify cascade` on a CSV file with `header` and `rows`.
fn bad_input_error(header: &str, rows: Vec<String>) -> String {
    let dir = TempDir::new().unwrap();
    let data = csv(dir.path(), "a.csv", header, &rows);
    identify_fails(&data, &dir.path().join("r.json"))
}

/// `n` rows "i,i", with row `bad` replaced by `text`.
fn ramp_with(n: usize, bad: usize, text: &str) -> Vec<String> {
    rows(n, |i| {
        if i == bad {
            text.to_string()
        } else {
            format!("{i},{i}")
        }
    })
}

#[test]
fn missing_column_is_a_one_line_error() {
    let err = bad_input_error("x,z", ramp_with(100, usize::MAX, ""));
    assert!(
        err.contains("no column named 'y'") && err.contains("x, z"),
        "{err}"
    );
}

#[test]
fn nan_is_a_one_line_error() {
    let err = bad_input_error("x,y", ramp_with(100, 42, "nan,1"));
    assert!(err.contains("not finite") && err.contains("42"), "{err}");
}

#[test]
fn non_numeric_cell_is_a_one_line_error() {
    let err = bad_input_error("x,y", ramp_with(100, 7, "1,abc"));
    assert!(
        err.contains("'abc' is not a number") && err.contains("line 9"),
        "{err}"
    );
}

#[test]
fn empty_file_is_a_one_line_error() {
    let dir = TempDir::new().unwrap();
    let data = dir.path().join("empty.csv");
    fs::write(&data, "").unwrap();
    let err = identify_fails(&data, &dir.path().join("r.json"));
    assert!(err.contains("empty"), "{err}");
}

#[test]
fn fewer_samples_than_parameters_is_a_one_line_error() {
    let err = bad_input_error("x,y", rows(6, |i| format!("{},{}", i as f64 * 0.3, i)));
    assert!(err.contains("too few samples"), "{err}");
}

#[test]
fn constant_input_is_a_one_line_error() {
    let err = bad_input_error(
        "x,y",
        rows(500, |i| format!("1.5,{}", (i as f64 * 0.1).sin())),
    );
    assert!(err.contains("does not excite"), "{err}");
}

#[test]
fn input_too_fast_for_the_model_is_a_one_line_error() {
    let dir = TempDir::new().unwrap();
    let (_, model) = identified_example(dir.path());
    // Steps of 10 per sample: α·|Δx| = 3 with α = 0.3.
    let fast = csv(
        dir.path(),
        "fast.csv",
        "x",
        &rows(50, |i| {
            format!("{}", if i.is_multiple_of(2) { -5.0 } else { 5.0 })
        }),
    );
    let out_csv = dir.path().join("sim.csv");
    let out = hysid()
        .args(["simulate", "--input", "x", "--model"])
        .arg(&model)
        .arg("--data")
        .arg(&fast)
        .arg("--csv")
        .arg(&out_csv)
        .assert()
        .failure()
        .get_output()
        .stderr
        .clone();
    let err = String::from_utf8(out).unwrap();
    assert!(
        err.contains("too fast") && err.contains("sample 1"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1);
    assert!(!out_csv.exists());
}

#[test]
fn unknown_hysteresis_form_and_bad_model_file_are_one_line_errors() {
    let dir = TempDir::new().unwrap();
    let data = example_data(dir.path(), true);
    let out = hysid()
        .args([
            "identify",
            "cascade",
            "--input",
            "x",
            "--output",
            "y",
            "--hysteresis",
            "ch5",
        ])
        .args(["--na", "2", "--nb", "2", "--delay", "1", "--data"])
        .arg(&data)
        .assert()
        .failure()
        .get_output()
        .stderr
        .clone();
    assert!(String::from_utf8(out).unwrap().contains("use ch4"));
    let bad = dir.path().join("bad.json");
    fs::write(&bad, "{\"kind\": 3}").unwrap();
    let out = hysid()
        .args(["simulate", "--input", "x", "--model"])
        .arg(&bad)
        .arg("--data")
        .arg(&data)
        .assert()
        .failure()
        .get_output()
        .stderr
        .clone();
    let err = String::from_utf8(out).unwrap();
    assert!(
        err.contains("not a hysid.model/1 model file") && err.lines().count() == 1,
        "{err}"
    );
}

/// The benchmark's training record, vendored in `data/`.
fn bouc_wen_train() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/bouc-wen/train_multisine_5periods.csv")
}

#[test]
fn benchmark_fits_the_training_record_and_scores_a_generated_test_set() {
    let dir = TempDir::new().unwrap();
    let test = dir.path().join("test.csv");
    hysid()
        .args([
            "benchmark",
            "bouc-wen",
            "generate",
            "--signal",
            "multisine",
            "--periods",
            "1",
            "--csv",
        ])
        .arg(&test)
        .assert()
        .success();
    let json = dir.path().join("bw.json");
    hysid()
        .args(["benchmark", "bouc-wen", "--start-factor", "2", "--train"])
        .arg(bouc_wen_train())
        .arg("--test")
        .arg(&test)
        .arg("--json")
        .arg(&json)
        .assert()
        .success();
    let report = read_json(&json);
    assert_eq!(report["model"]["kind"], "bouc_wen");
    let alpha = param(&report, "alpha")["value"].as_f64().unwrap();
    assert!((alpha / 5e4 - 1.0).abs() < 0.01, "{alpha}");
    let e_rms = report["validation"][0]["e_rms"].as_f64().unwrap();
    assert!(e_rms < 1e-5, "{e_rms}");
    for (section, key) in [
        ("fit", "fit_percent"),
        ("fit", "rmse"),
        ("search", "iterations"),
        ("search", "termination"),
        ("search", "elapsed_s"),
    ] {
        assert!(!report[section][key].is_null(), "missing {section}.{key}");
    }
}

#[test]
fn greybox_fit_writes_a_model_that_simulate_loads() {
    let dir = TempDir::new().unwrap();
    let model = dir.path().join("bw.json");
    let out = hysid()
        .args([
            "greybox", "fit", "--model", "bouc-wen", "--input", "u_N", "--output", "y_m",
        ])
        .args([
            "--interpolation",
            "band-limited",
            "--substeps",
            "4",
            "--sensitivity",
            "--data",
        ])
        .arg(bouc_wen_train())
        .arg("--model-out")
        .arg(&model)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let stdout = String::from_utf8(out).unwrap();
    assert!(
        stdout.contains("change of fit %") && stdout.contains("beta_delta"),
        "{stdout}"
    );
    let json = dir.path().join("sim.json");
    hysid()
        .args(["simulate", "--input", "u_N", "--output", "y_m", "--model"])
        .arg(&model)
        .arg("--data")
        .arg(bouc_wen_train())
        .arg("--json")
        .arg(&json)
        .assert()
        .success();
    let report = read_json(&json);
    let rmse = report["fit"]["rmse"].as_f64().unwrap();
    assert!((rmse - 7.37e-6).abs() < 0.3e-6, "{rmse}");
}

/// `hysid greybox fit` expecting failure: the one line on stderr.
fn greybox_fails(data: &Path, extra: &[&str]) -> String {
    let out = hysid()
        .args([
            "greybox", "fit", "--model", "bouc-wen", "--input", "u_N", "--output", "y_m", "--data",
        ])
        .arg(data)
        .args(extra)
        .assert()
        .failure()
        .get_output()
        .stderr
        .clone();
    let err = String::from_utf8(out).unwrap();
    assert!(
        !err.contains("panicked") && err.lines().count() == 1 && err.starts_with("error: "),
        "{err}"
    );
    err
}

#[test]
fn greybox_bad_input_and_numerical_trouble_are_one_line_errors() {
    let dir = TempDir::new().unwrap();
    let nan = csv(
        dir.path(),
        "nan.csv",
        "t_s,u_N,y_m",
        &rows(100, |i| {
            if i == 5 {
                "0.1,nan,0".into()
            } else {
                format!("{},{i},0", i as f64 / 750.0)
            }
        }),
    );
    assert!(greybox_fails(&nan, &[]).contains("not finite"));
    let train = bouc_wen_train();
    let err = greybox_fails(&train, &["--init", "cL=-5"]);
    assert!(err.contains("cL") && err.contains("bounds"), "{err}");
    let err = greybox_fails(&train, &["--init", "mL=1e-3", "--init", "kL=1e9"]);
    assert!(
        err.contains("cannot be simulated from its initial parameters"),
        "{err}"
    );
    let err = greybox_fails(&train, &["--init", "mass=3"]);
    assert!(err.contains("no parameter named 'mass'"), "{err}");
    // A measured output that never moves: nothing to fit (was an "exact fit" or -inf %).
    let flat = csv(
        dir.path(),
        "flat.csv",
        "t_s,u_N,y_m",
        &rows(2000, |i| {
            format!("{},{},0", i as f64 / 750.0, (i as f64 * 0.05).sin())
        }),
    );
    let err = greybox_fails(&flat, &[]);
    assert!(err.contains("output 'y_m' is constant"), "{err}");
}

/// A report, model or CSV destination that cannot be written is refused before any work
/// (one line naming it, nothing written), not after a long fit.
#[test]
fn unwritable_destinations_are_refused_before_the_work() {
    let dir = TempDir::new().unwrap();
    let data = example_data(dir.path(), true);
    let nowhere = dir.path().join("no-such-dir");
    let check = |cmd: &mut Command, what: &Path| {
        let out = cmd.assert().failure().get_output().clone();
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert!(
            stderr.lines().count() == 1
                && stderr.contains(&what.display().to_string())
                && !stderr.contains("panicked"),
            "{stderr}"
        );
        // Refused at once: nothing was printed on stdout.
        assert!(
            out.stdout.is_empty(),
            "{}",
            String::from_utf8_lossy(&out.stdout)
        );
    };
    let json = nowhere.join("r.json");
    check(identify_cascade(&data).arg("--json").arg(&json), &json);
    let model = nowhere.join("m.json");
    check(
        identify_cascade(&data).arg("--model-out").arg(&model),
        &model,
    );
    // A directory where a file is expected.
    check(
        identify_cascade(&data).arg("--json").arg(dir.path()),
        dir.path(),
    );
    let csv_out = nowhere.join("x.csv");
    check(
        hysid()
            .args(["generate", "voros", "--example", "1", "--csv"])
            .arg(&csv_out),
        &csv_out,
    );
    check(
        hysid()
            .args(["demo", "actuator", "--json"])
            .arg(&json)
            .arg("--plots")
            .arg(dir.path().join("demo")),
        &json,
    );
    assert!(!nowhere.exists());
}

/// A MATLAB .mat file (the piezo record, written by tools/reference/mat_fixture.py) gives
/// the same identification as the CSV record it was made from — a matrix column picked as
/// record(:,3) included; a bad variable is one line naming the file.
#[test]
fn mat_files_identify_like_the_csv_record() {
    let dir = TempDir::new().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let identify = |data: PathBuf, output: &str, json: &Path| {
        hysid()
            .args(["identify", "hysteresis", "--input", "voltage_V", "--output"])
            .arg(output)
            .args(["--hysteresis", "ch6", "--data"])
            .arg(data)
            .arg("--json")
            .arg(json)
            .assert()
            .success();
        let text = fs::read_to_string(json).unwrap();
        serde_json::from_str::<serde_json::Value>(&text).unwrap()
    };
    let mat = root.join("crates/hysid-tests/tests/data/piezo_150V_1Hz.mat");
    let from_mat = identify(mat.clone(), "record(:,3)", &dir.path().join("m.json"));
    let from_csv = identify(
        root.join("data/piezo/piezo_150V_1Hz.csv"),
        "displacement_um",
        &dir.path().join("c.json"),
    );
    assert_eq!(
        from_mat["model"]["parameters"],
        from_csv["model"]["parameters"]
    );
    assert!(from_mat["fit"]["fit_percent"].as_f64().unwrap() > 99.0);
    let out = hysid()
        .args([
            "identify",
            "hysteresis",
            "--input",
            "volts",
            "--output",
            "z",
        ])
        .args(["--hysteresis", "ch6", "--data"])
        .arg(&mat)
        .assert()
        .failure()
        .get_output()
        .clone();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.lines().count() == 1 && stderr.contains("no numeric variable named 'volts'"),
        "{stderr}"
    );
}
