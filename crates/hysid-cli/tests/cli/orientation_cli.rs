//! `--orientation` and the detected orientation end to end (issue 38, item 1): an open
//! record of several runs is fitted by `identify operator --family pi` the right way round,
//! a given orientation is honoured and reported as given, and a record too short to tell is
//! one line naming the flag.

use crate::common::{hysid, read_json, Assert};
use hysid::model::operators::{HysteresisOperator, Orientation, PrandtlIshlinskii};
use std::fs;
use std::path::{Path, PathBuf};
use tempfile::TempDir;

/// Two runs of a counter-clockwise PI operator (each from its own initial state, its own
/// range), concatenated, cut open: the record ends at another input than it started, and its
/// output sits far from 0, so the whole path's integral ∮ y du is the static curve's.
fn open_record() -> (Vec<f64>, Vec<f64>) {
    let mut runs = Vec::new();
    for (c, a, n) in [(0.0, 1.0, 700), (0.4, 0.5, 500)] {
        let ur: Vec<f64> = (0..n)
            .map(|k| {
                let t = k as f64 / n as f64;
                c + a * (1.0 - 0.4 * t) * (2.0 * std::f64::consts::PI * 3.3 * t).sin()
            })
            .collect();
        runs.push(ur);
    }
    let (from, to) = (37, runs[0].len() + runs[1].len() - 61);
    let all: Vec<f64> = runs.concat();
    // the output's offset has the sign of the net input travel: ∮ y du > 0, "clockwise"
    let offset = 5.0 * (all[to - 1] - all[from]).signum();
    let pi = PrandtlIshlinskii::new(
        0.6,
        vec![0.5, 0.3, 0.2, 0.1],
        vec![0.05, 0.12, 0.2, 0.3],
        offset,
        Orientation::COUNTER_CLOCKWISE,
    )
    .unwrap();
    let y: Vec<f64> = runs
        .iter()
        .flat_map(|ur| pi.simulate(ur).unwrap())
        .collect();
    (all[from..to].to_vec(), y[from..to].to_vec())
}

fn write(dir: &Path, name: &str, u: &[f64], y: &[f64]) -> PathBuf {
    let path = dir.join(name);
    let mut text = String::from("u,y\n");
    for (a, b) in u.iter().zip(y) {
        text.push_str(&format!("{a},{b}\n"));
    }
    fs::write(&path, text).unwrap();
    path
}

/// fit % of the least-squares straight line y ≈ a·u + b.
fn line_fit_percent(u: &[f64], y: &[f64]) -> f64 {
    let n = u.len() as f64;
    let (mu, my) = (u.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let suu: f64 = u.iter().map(|a| (a - mu).powi(2)).sum();
    let suy: f64 = u.iter().zip(y).map(|(a, b)| (a - mu) * (b - my)).sum();
    let slope = suy / suu;
    let res: f64 = u
        .iter()
        .zip(y)
        .map(|(a, b)| (b - my - slope * (a - mu)).powi(2))
        .sum();
    let tot: f64 = y.iter().map(|b| (b - my).powi(2)).sum();
    100.0 * (1.0 - (res / tot).sqrt())
}

fn identify(data: &Path, report: &Path, extra: &[&str]) -> serde_json::Value {
    hysid()
        .args(["identify", "operator", "--family", "pi", "--data"])
        .arg(data)
        .args(["--input", "u", "--output", "y", "--json"])
        .arg(report)
        .args(extra)
        .assert()
        .success();
    read_json(report)
}

#[test]
fn open_multi_run_record_fits_and_a_given_orientation_is_honoured() {
    let dir = TempDir::new().unwrap();
    let (u, y) = open_record();
    let path_area: f64 = (1..u.len())
        .map(|k| 0.5 * (y[k] + y[k - 1]) * (u[k] - u[k - 1]))
        .sum();
    assert!(
        path_area > 0.0,
        "the record must fool the path integral (it says clockwise)"
    );
    let data = write(dir.path(), "open.csv", &u, &y);
    let r = identify(&data, &dir.path().join("detected.json"), &[]);
    let fit = r["fit"]["fit_percent"].as_f64().unwrap();
    let line = line_fit_percent(&u, &y);
    // the residual a fifth of the straight line's, or less
    assert!(
        fit > 98.0 && 100.0 - fit < (100.0 - line) / 5.0,
        "fit {fit} %, line {line} %"
    );
    assert_eq!(r["details"]["orientation"], "ccw");
    assert_eq!(r["details"]["orientation_source"], "detected");
    assert_eq!(
        r["model"]["operator"]["orientation"],
        serde_json::json!({"inverse": false, "decreasing": false}),
        "{}",
        r["model"]
    );

    let r = identify(
        &data,
        &dir.path().join("given.json"),
        &["--orientation", "cw"],
    );
    assert_eq!(r["details"]["orientation"], "cw");
    assert_eq!(r["details"]["orientation_source"], "given");
    assert_eq!(
        r["model"]["operator"]["orientation"],
        serde_json::json!({"inverse": true, "decreasing": false})
    );
    let wrong = r["fit"]["fit_percent"].as_f64().unwrap();
    eprintln!("PI on the open record: detected (ccw) {fit:.2} %, cw as the path integral read it {wrong:.2} %, straight line {line:.2} %");
    assert!(
        wrong < fit,
        "the wrong orientation fits worse: {wrong} vs {fit}"
    );

    // compare reports the record's orientation and each family's
    let report = dir.path().join("compare.json");
    hysid()
        .args(["compare", "--families", "pi,backlash", "--data"])
        .arg(&data)
        .args(["--input", "u", "--output", "y", "--json"])
        .arg(&report)
        .assert()
        .success();
    let r = read_json(&report);
    assert_eq!(r["details"]["orientation"], "ccw");
    assert_eq!(r["details"]["orientation_source"], "detected");
    for row in r["details"]["families"].as_array().unwrap() {
        assert_eq!(row["orientation"], "ccw", "{row}");
    }
}

#[test]
fn a_record_too_short_to_tell_names_the_flag() {
    let dir = TempDir::new().unwrap();
    let u: Vec<f64> = (0..40).map(|k| k as f64 / 40.0).collect();
    let y: Vec<f64> = u.iter().map(|v| 2.0 * v + 0.1).collect();
    let data = write(dir.path(), "ramp.csv", &u, &y);
    let err = error_line(
        hysid()
            .args(["identify", "operator", "--family", "pi", "--data"])
            .arg(&data)
            .args(["--input", "u", "--output", "y"]),
    );
    assert!(err.contains("--orientation ccw|cw"), "{err}");
    // a bad value is refused before any file is read
    let err = error_line(hysid().args([
        "identify",
        "operator",
        "--family",
        "pi",
        "--data",
        "/nonexistent.csv",
        "--input",
        "u",
        "--output",
        "y",
        "--orientation",
        "up",
    ]));
    assert!(err.contains("orientation"), "{err}");
}

/// Runs `cmd`, expects a failure with exactly one "error:" line on stderr and no panic.
fn error_line(cmd: &mut std::process::Command) -> String {
    let out = cmd.output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    errors[0].to_string()
}
