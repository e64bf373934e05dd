//! NIST's StRD nonlinear regression problems through the command line: each of the 54 cases
//! (27 problems, NIST's two starts) fitted by `hysid greybox fit --model-file F --data D
//! --input x --output y` and nothing else (Nelson: `--input x1 --input x2 --output y`), the
//! `--json` report read back: at least six correct digits in every parameter against NIST's
//! certified values, three in every standard deviation, and a converged termination. The
//! files are in `data/nist-strd/` (`csv/`, `models/`); the library's test of the same cases
//! is `crates/hysid-tests/tests/library/nist.rs`. The 54 runs take about a second.

use crate::common::{hysid, read_json, Assert};
use std::path::{Path, PathBuf};
use tempfile::TempDir;

const PROBLEMS: [&str; 27] = [
    "Misra1a", "Chwirut2", "Chwirut1", "Lanczos3", "Gauss1", "Gauss2", "DanWood", "Misra1b",
    "Kirby2", "Hahn1", "Nelson", "MGH17", "Lanczos1", "Lanczos2", "Gauss3", "Misra1c", "Misra1d",
    "Roszman1", "ENSO", "MGH09", "Thurber", "BoxBOD", "Rat42", "MGH10", "Eckerle4", "Rat43",
    "Bennett5",
];

/// The cases not certified yet (the list and its reasons: `SHORT` in
/// `crates/hysid-tests/tests/library/nist.rs`); each must still be short.
const SHORT: [(&str, usize); 0] = [];

fn nist() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/nist-strd")
}

/// Certified values and standard deviations of `NAME.dat` (the lines of its "Certified
/// Values" range that start with b).
fn certified(name: &str) -> (Vec<f64>, Vec<f64>) {
    let text = std::fs::read_to_string(nist().join(format!("{name}.dat"))).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let header = lines[..10]
        .iter()
        .find(|l| l.contains("Certified Values"))
        .unwrap();
    let range: Vec<usize> = header
        .split(|c: char| !c.is_ascii_digit())
        .filter_map(|w| w.parse().ok())
        .collect();
    let (mut values, mut std) = (Vec::new(), Vec::new());
    for line in lines[range[0] - 1..range[1]]
        .iter()
        .filter(|l| l.trim_start().starts_with('b'))
    {
        let w: Vec<f64> = line
            .split_once('=')
            .unwrap()
            .1
            .split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect();
        values.push(w[2]);
        std.push(w[3]);
    }
    (values, std)
}

/// Worst correct digits −log10(|e − c|/|c|) over the pairs (15 when equal, 0 when not finite).
fn digits(estimates: &[f64], certified: &[f64]) -> f64 {
    estimates
        .iter()
        .zip(certified)
        .map(|(e, c)| {
            let r = (e - c).abs() / c.abs();
            if !e.is_finite() {
                0.0
            } else if r == 0.0 {
                15.0
            } else {
                (-r.log10()).clamp(0.0, 15.0)
            }
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn every_nist_problem_from_both_starts_through_the_cli() {
    let dir = TempDir::new().unwrap();
    let mut failures = Vec::new();
    for name in PROBLEMS {
        let (values, std) = certified(name);
        for k in [1, 2] {
            let json = dir.path().join(format!("{name}_{k}.json"));
            let mut cmd = hysid();
            cmd.args(["-q", "greybox", "fit", "--model-file"])
                .arg(nist().join(format!("models/{name}_start{k}.toml")))
                .arg("--data")
                .arg(nist().join(format!("csv/{name}.csv")));
            match name {
                "Nelson" => cmd.args(["--input", "x1", "--input", "x2"]),
                _ => cmd.args(["--input", "x"]),
            };
            cmd.args(["--output", "y", "--json"])
                .arg(&json)
                .assert()
                .success();
            let report = read_json(&json);
            let params = report["model"]["parameters"].as_array().unwrap();
            let got = |key: &str| -> Vec<f64> {
                params
                    .iter()
                    .map(|p| p[key].as_f64().unwrap_or(f64::NAN))
                    .collect()
            };
            let (d, s) = (digits(&got("value"), &values), digits(&got("std"), &std));
            let termination = &report["search"]["termination"];
            println!("{name:9} {k}  {d:5.1}  {s:5.1}  {}", termination["message"]);
            let certified_case = d >= 6.0 && s >= 3.0 && termination["converged"] == true;
            if certified_case == SHORT.contains(&(name, k)) {
                failures.push(format!(
                    "{name} start {k}: {d:.1} digits (std {s:.1}), {termination}"
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} cases not as listed in SHORT:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// A model with two inputs and one output is one experiment of `--input x1 --input x2
/// --output y`; a count that does not split into the model's groups is refused in one line.
#[test]
fn two_input_model_takes_its_inputs_as_one_experiment() {
    let dir = TempDir::new().unwrap();
    let json = dir.path().join("nelson.json");
    let model = nist().join("models/Nelson_start2.toml");
    let data = nist().join("csv/Nelson.csv");
    hysid()
        .args(["-q", "greybox", "fit", "--model-file"])
        .arg(&model)
        .arg("--data")
        .arg(&data)
        .args(["--input", "x1", "--input", "x2", "--output", "y", "--json"])
        .arg(&json)
        .assert()
        .success();
    let report = read_json(&json);
    let (values, _) = certified("Nelson");
    let params = report["model"]["parameters"].as_array().unwrap();
    let got: Vec<f64> = params
        .iter()
        .map(|p| p["value"].as_f64().unwrap())
        .collect();
    assert!(digits(&got, &values) >= 6.0, "{got:?}");
    let err = crate::common::one_line_error(
        hysid()
            .args(["greybox", "fit", "--model-file"])
            .arg(&model)
            .arg("--data")
            .arg(&data)
            .args([
                "--input", "x1", "--input", "x2", "--input", "x1", "--output", "y",
            ]),
    );
    assert!(
        err.contains("2 --input and 1 --output per experiment"),
        "{err}"
    );
}
