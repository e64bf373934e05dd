//! Hardening (issue 9): every numeric option has a range, large requests are estimated and
//! refused before they allocate, no non-finite number is called a success, models refuse
//! invalid physics, progress goes to stderr only, and `--time-limit` stops a search with its
//! best result reported as such.

use crate::common::{fails_with, hysid, read_json, Assert, IDENTIFY_CASCADE};
use std::fs;
use std::path::{Path, PathBuf};

/// Names of the files in `dir`.
fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A rigid body M q̈ + Fv q̇ + Fc sgn q̇ = u (M = 2, Fv = 5, Fc = 1) sampled at 1 kHz, as
/// columns t, q, u; the sample `spike` of q replaced by `value` when given.
fn rigid_body_csv(dir: &Path, spike: Option<(usize, f64)>) -> PathBuf {
    use std::f64::consts::PI;
    let mut text = String::from("t,q,u\n");
    for k in 0..3000 {
        let t = k as f64 * 1e-3;
        let w = 2.0 * PI;
        let mut q = 0.1 * (w * t).sin() + 0.02 * (7.0 * w * t).sin();
        let v = 0.1 * w * (w * t).cos() + 0.14 * w * (7.0 * w * t).cos();
        let a = -0.1 * w * w * (w * t).sin() - 0.98 * w * w * (7.0 * w * t).sin();
        let u = 2.0 * a + 5.0 * v + v.signum();
        if let Some((index, value)) = spike {
            if index == k {
                q = value;
            }
        }
        text += &format!("{t},{q},{u}\n");
    }
    let path = dir.join("rb.csv");
    fs::write(&path, text).unwrap();
    path
}

#[test]
fn out_of_range_options_are_usage_errors_naming_the_option() {
    let dir = tempfile::tempdir().unwrap();
    let data = rigid_body_csv(dir.path(), None);
    let data = data.to_str().unwrap();
    let greybox = |flag: &str, value: &str| {
        let mut cmd = hysid();
        cmd.args([
            "greybox",
            "fit",
            "--model",
            "rigid-body",
            "--data",
            data,
            "--input",
            "u",
            "--output",
            "q",
            // FLAG=VALUE: a negative value is then not taken for a flag.
            &format!("{flag}={value}"),
        ]);
        cmd
    };
    for (flag, value) in [
        ("--substeps", "0"),
        ("--starts", "0"),
        ("--tolerance", "nan"),
        ("--max-iterations", "18446744073709551615"),
        ("--ts", "-1"),
        ("--time-limit", "inf"),
    ] {
        let line = fails_with(&mut greybox(flag, value), 2);
        assert!(line.contains(flag), "{flag} {value}: {line}");
    }
    for value in ["nan", "inf", "1e308", "1e-320", "0"] {
        let line = fails_with(
            hysid().args([
                "rigid-body",
                "ls",
                "--data",
                data,
                "--position",
                "q",
                "--input",
                "u",
                "--gain",
                value,
            ]),
            2,
        );
        assert!(line.contains("--gain"), "{line}");
    }
    for (flag, value) in [
        ("--decimate", "0"),
        ("--border", "1e11"),
        ("--order", "100"),
    ] {
        let line = fails_with(
            hysid().args([
                "rigid-body",
                "ls",
                "--data",
                data,
                "--position",
                "q",
                "--input",
                "u",
                flag,
                value,
            ]),
            2,
        );
        assert!(line.contains(flag), "{line}");
    }
    let line = fails_with(
        hysid().args([
            "benchmark",
            "bouc-wen",
            "generate",
            "--noise",
            "nan",
            "--csv",
            "x.csv",
        ]),
        2,
    );
    assert!(line.contains("--noise"), "{line}");
    // The range is in the help text.
    let help = hysid().args(["greybox", "fit", "--help"]).output().unwrap();
    let help = String::from_utf8(help.stdout).unwrap();
    assert!(help.contains("1..=100000"), "{help}");
    assert!(help.contains("[1e-15, 1)"), "{help}");
}

#[test]
fn requests_beyond_memory_or_the_work_budget_are_refused_before_they_start() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("sweep.csv");
    // 1e8 samples simulated at 20 times the rate: about 160 GB.
    let line = fails_with(
        hysid()
            .args([
                "benchmark",
                "bouc-wen",
                "generate",
                "--signal",
                "sweep",
                "--samples",
                "100000000",
                "--csv",
            ])
            .arg(&csv),
        1,
    );
    assert!(line.contains("GB of memory"), "{line}");
    let data = rigid_body_csv(dir.path(), None);
    let line = fails_with(
        hysid()
            .args(["greybox", "fit", "--model", "rigid-body", "--data"])
            .arg(&data)
            .args(["--input", "u", "--output", "q", "--starts", "100000"]),
        1,
    );
    assert!(
        line.contains("model steps") && line.contains("--allow-long"),
        "{line}"
    );
    assert_eq!(files_in(dir.path()), ["rb.csv"]);
}

#[test]
fn a_sample_near_the_float_limit_is_refused_not_fitted_to_nan() {
    let dir = tempfile::tempdir().unwrap();
    let data = rigid_body_csv(dir.path(), Some((1500, 1e308)));
    let json = dir.path().join("r.json");
    let line = fails_with(
        hysid()
            .args(["rigid-body", "ls", "--data"])
            .arg(&data)
            .args(["--position", "q", "--input", "u", "--json"])
            .arg(&json),
        1,
    );
    assert!(line.contains("overflow"), "{line}");
    assert!(!json.exists());
}

#[test]
fn models_refuse_invalid_physics_when_built() {
    let dir = tempfile::tempdir().unwrap();
    // A rigid body with a negative mass, bounds opened by the file.
    let model = dir.path().join("m.json");
    let p = |name: &str, value: f64| {
        format!(
            r#"{{"name": "{name}", "value": {value}, "std": null, "unit": "", "fixed": false, "lower": null, "upper": null}}"#
        )
    };
    let parameters = [
        p("M", -1.0),
        p("Fv", 1.0),
        p("Fc", 0.1),
        p("offset", 0.0),
        p("gain", 1.0),
    ]
    .join(", ");
    fs::write(
        &model,
        format!(
            r#"{{"schema": "hysid.model/1", "kind": "rigid_body", "parameters": [{parameters}]}}"#
        ),
    )
    .unwrap();
    let data = rigid_body_csv(dir.path(), None);
    let line = fails_with(
        hysid()
            .args(["simulate", "--model"])
            .arg(&model)
            .arg("--data")
            .arg(&data)
            .args(["--input", "u", "--output", "q"]),
        1,
    );
    assert!(line.contains("parameter M = -1"), "{line}");
    // The virtual rig with a negative Coulomb friction: a bad parameter, not bad data.
    let line = fails_with(
        hysid()
            .args(["actuator", "rig", "--truth", "Fc=-1", "--data-out"])
            .arg(dir.path().join("rig")),
        1,
    );
    assert!(line.contains("parameter Fc = -1"), "{line}");
}

#[test]
fn a_time_limit_keeps_the_best_result_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let data = rigid_body_csv(dir.path(), None);
    let json = dir.path().join("r.json");
    let out = hysid()
        .args(["greybox", "fit", "--model", "rigid-body", "--data"])
        .arg(&data)
        .args(["--input", "u", "--output", "q", "--starts", "4"])
        .args(["--time-limit", "1e-6", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.starts_with("warning: the time limit"), "{stderr}");
    let report = read_json(&json);
    assert_eq!(report["search"]["termination"]["code"], "time_limit");
    assert_eq!(report["search"]["termination"]["converged"], false);
}

#[test]
fn a_time_limit_stops_an_operator_fit_and_a_comparison() {
    // The Jiles–Atherton search on the piezo loop takes hundreds of simulations (a second
    // or more); a 10 ms limit stops it at its first accepted iteration.
    let piezo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/piezo/piezo_150V_1Hz.csv");
    let dir = tempfile::tempdir().unwrap();
    for (command, json) in [
        (
            &["identify", "operator", "--family", "jiles-atherton"][..],
            "operator.json",
        ),
        (
            &["compare", "--families", "jiles-atherton,pi"][..],
            "compare.json",
        ),
    ] {
        let json = dir.path().join(json);
        let out = hysid()
            .arg("--quiet")
            .args(command)
            .arg("--data")
            .arg(&piezo)
            .args(["--input", "voltage_V", "--output", "displacement_um"])
            .args(["--time-limit", "0.01", "--json"])
            .arg(&json)
            .output()
            .unwrap();
        let stderr = String::from_utf8(out.stderr).unwrap();
        assert_eq!(out.status.code(), Some(0), "{command:?}: {stderr}");
        assert!(
            stderr
                .lines()
                .any(|l| l.starts_with("warning: the time limit")),
            "{command:?}: {stderr}"
        );
        let report = read_json(&json);
        if command[0] == "compare" {
            // No single search: the family the limit stopped says so in its row.
            let rows = report["details"]["families"].as_array().unwrap();
            let ja = rows
                .iter()
                .find(|r| r["family"] == "jiles-atherton")
                .unwrap();
            assert_eq!(ja["converged"], false, "{ja}");
            assert_eq!(ja["termination"], "stopped by the caller", "{ja}");
            // The families after the stop are not fitted, and say so.
            let pi = rows.iter().find(|r| r["family"] == "pi").unwrap();
            let error = pi["error"].as_str().unwrap();
            assert!(error.contains("before this family was fitted"), "{pi}");
            assert_eq!(report["details"]["stopped"], true);
        } else {
            assert_eq!(report["search"]["termination"]["code"], "time_limit");
        }
    }
}

#[test]
fn a_time_limit_stops_the_cascade_grid_with_a_result() {
    // A limit of 1 µs is over before the grid starts: its first point is still scored and
    // refined, so the run ends with that candidate's fit, marked as stopped.
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data.csv");
    hysid()
        .args(["generate", "voros", "--samples", "20000", "--csv"])
        .arg(&data)
        .assert()
        .success();
    let json = dir.path().join("r.json");
    let out = hysid()
        .arg("--quiet")
        .args(IDENTIFY_CASCADE)
        .arg("--data")
        .arg(&data)
        .args(["--time-limit", "1e-6", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stderr.starts_with("warning: the time limit"), "{stderr}");
    let report = read_json(&json);
    assert_eq!(report["search"]["termination"]["code"], "time_limit");
    assert!(report["fit"]["fit_percent"].as_f64().unwrap().is_finite());
}

#[test]
fn quiet_runs_print_nothing_on_stderr() {
    let dir = tempfile::tempdir().unwrap();
    let data = rigid_body_csv(dir.path(), None);
    let out = hysid()
        .args([
            "--quiet",
            "greybox",
            "fit",
            "--model",
            "rigid-body",
            "--data",
        ])
        .arg(&data)
        .args(["--input", "u", "--output", "q", "--max-iterations", "5"])
        // Linear interpolation: with the default hold, this smooth input and the residuals
        // of 5 iterations set off the hold check's warning (a warning is not progress).
        .args(["--interpolation", "linear"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!out.stdout.is_empty());
}

#[test]
fn the_cascade_estimate_keeps_alpha_inside_the_rate_limit_of_its_data() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data.csv");
    hysid()
        .args(["generate", "voros", "--samples", "400", "--csv"])
        .arg(&data)
        .assert()
        .success();
    // One input sample set to zero: max|Δx| jumps, and α's admissible range shrinks.
    let text = fs::read_to_string(&data).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let x_col = lines[0].split(',').position(|c| c == "x").unwrap();
    let mut row: Vec<String> = lines[200].split(',').map(String::from).collect();
    row[x_col] = "0".into();
    lines[200] = row.join(",");
    fs::write(&data, lines.join("\n") + "\n").unwrap();
    let x: Vec<f64> = lines[1..]
        .iter()
        .map(|l| l.split(',').nth(x_col).unwrap().parse().unwrap())
        .collect();
    let max_dx = x
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    let json = dir.path().join("r.json");
    hysid()
        .args(["--quiet", "identify", "cascade", "--data"])
        .arg(&data)
        .args(["--input", "x", "--output", "y", "--hysteresis", "ch4"])
        .args(["--na", "2", "--nb", "2", "--delay", "1", "--json"])
        .arg(&json)
        .assert()
        .success();
    let report = read_json(&json);
    let alpha = report["model"]["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "alpha")
        .unwrap()["value"]
        .as_f64()
        .unwrap();
    assert!(
        alpha > 0.0 && alpha * max_dx < 1.0,
        "alpha {alpha}, max|dx| {max_dx}"
    );
}
