//! `hysid identify cascade --hysteresis FAMILY` with an operator family: a simulated backlash
//! cascade is recovered, its model file simulates to the report's fit, bad names are one line.

use crate::common::{hysid, read_json, Assert};
use hysid::model::operators::{Backlash, Orientation};
use hysid::model::{LinearBlock, OperatorCascade, OperatorModel};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use tempfile::TempDir;

fn json(path: &Path) -> serde_json::Value {
    read_json(path)
}

/// Backlash (g = 1.7, r = 0.437, c = −0.3) followed by y(t) = 1.2 y(t−1) − 0.5 y(t−2) +
/// v(t−1) + 0.4 v(t−2), driven by a decaying oscillation with minor loops; written exactly.
fn backlash_record(dir: &Path) -> PathBuf {
    let u: Vec<f64> = (0..3000)
        .map(|k| {
            let t = k as f64 / 3000.0;
            3.0 * (1.0 - 0.7 * t) * (29.0 * t).sin() + 0.8 * (113.0 * t).sin()
        })
        .collect();
    let op = Backlash::new(1.7, 0.437, -0.3, Orientation::default()).unwrap();
    let linear = LinearBlock::new(vec![-1.2, 0.5], vec![1.0, 0.4], 1).unwrap();
    let truth = OperatorCascade::new(OperatorModel::Backlash(op), linear).unwrap();
    let y = truth.simulate(&u).unwrap().y;
    let mut text = String::from("u,y\n");
    for (a, b) in u.iter().zip(&y) {
        text.push_str(&format!("{a},{b}\n"));
    }
    let path = dir.join("backlash.csv");
    fs::write(&path, text).unwrap();
    path
}

fn identify(data: &Path, family: &str) -> Command {
    let mut cmd = hysid();
    cmd.args(["identify", "cascade", "--input", "u", "--output", "y"])
        .args([
            "--hysteresis",
            family,
            "--na",
            "2",
            "--nb",
            "2",
            "--delay",
            "1",
        ])
        .arg("--data")
        .arg(data);
    cmd
}

#[test]
fn backlash_cascade_is_recovered_and_its_model_file_simulates() {
    let dir = TempDir::new().unwrap();
    let data = backlash_record(dir.path());
    let (report, model) = (dir.path().join("r.json"), dir.path().join("m.json"));
    identify(&data, "backlash")
        .arg("--json")
        .arg(&report)
        .arg("--model-out")
        .arg(&model)
        .assert()
        .success();
    let r = json(&report);
    assert_eq!(r["model"]["kind"], "operator_cascade");
    let params = r["model"]["parameters"].as_array().unwrap();
    let truth = [
        ("g", 1.7),
        ("r", 0.437),
        ("c", -0.3),
        ("a1", -1.2),
        ("a2", 0.5),
        ("b1", 1.0),
        ("b2", 0.4),
    ];
    assert_eq!(params.len(), truth.len());
    for (p, (name, value)) in params.iter().zip(truth) {
        assert_eq!(p["name"], name);
        let est = p["value"].as_f64().unwrap();
        assert!((est - value).abs() <= 1e-6 * value.abs(), "{name}: {est}");
    }
    let fit = r["fit"]["fit_percent"].as_f64().unwrap();
    let sim = dir.path().join("sim.json");
    hysid()
        .args(["simulate", "--input", "u", "--output", "y", "--model"])
        .arg(&model)
        .arg("--data")
        .arg(&data)
        .arg("--json")
        .arg(&sim)
        .assert()
        .success();
    let simulated = json(&sim)["fit"]["fit_percent"].as_f64().unwrap();
    assert!(
        (simulated - fit).abs() <= 1e-9 * fit.abs(),
        "{simulated} vs {fit}"
    );
}

#[test]
fn unknown_family_and_misplaced_options_are_one_line_errors() {
    let dir = TempDir::new().unwrap();
    let data = backlash_record(dir.path());
    for (family, extra, expected) in [
        ("hammerstein", vec![], "unknown --hysteresis 'hammerstein'"),
        ("pi", vec!["--grid", "5"], "--grid applies to preisach"),
        (
            "backlash",
            vec!["--thresholds", "5"],
            "--thresholds applies to",
        ),
        (
            "pi",
            vec!["--uncertainty", "bootstrap"],
            "use --uncertainty asymptotic",
        ),
    ] {
        let out = identify(&data, family).args(extra).output().unwrap();
        assert!(!out.status.success());
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(err.contains(expected), "{err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}
