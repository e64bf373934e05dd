//! `--envelope` end to end (issue 38, item 3): on a magnet-like record whose static curve
//! saturates, the default PI chooses a cubic static envelope, saves it, `hysid simulate`
//! reproduces the fit, `hysid compensate` gives commands that `simulate` turns back into the
//! reference, and `hysid export` writes the envelope's helper; a non-PI family refuses the
//! flag in one line (exit 2). Likewise the generalised PI's static map: its dead zones are
//! chosen unless `--dead-zones` gives them.

use crate::common::{fails_with, hysid, read_json, Assert};
use std::fs;
use std::path::{Path, PathBuf};
use tempfile::TempDir;

/// A current through major and minor loops (600 samples), the field the sum of two narrow
/// plays beside a saturating tanh of the current.
fn magnet(dir: &Path) -> PathBuf {
    let mut u = Vec::new();
    for (k, amplitude) in [(0usize, 165.0f64), (1, 120.0), (2, 60.0), (3, 165.0)] {
        for j in 0..150 {
            let phase = 2.0 * std::f64::consts::PI * j as f64 / 150.0;
            u.push(amplitude * phase.sin() + if k == 2 { 40.0 } else { 0.0 });
        }
    }
    let mut plays = [0.0f64; 2];
    let mut text = String::from("u,y\n");
    for &x in &u {
        for (z, r) in plays.iter_mut().zip([0.8, 2.0]) {
            *z = (x - r).max((x + r).min(*z));
        }
        let y = 1.5 * (x / 110.0).tanh() + 0.004 * (plays[0] + plays[1]);
        text.push_str(&format!("{x},{y}\n"));
    }
    let path = dir.join("magnet.csv");
    fs::write(&path, text).unwrap();
    path
}

fn columns(text: &str, names: &[&str]) -> Vec<Vec<f64>> {
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let at: Vec<usize> = names
        .iter()
        .map(|n| header.iter().position(|h| h == n).unwrap())
        .collect();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    at.iter()
        .map(|&i| rows.iter().map(|r| r[i]).collect())
        .collect()
}

fn simulate(model: &Path, data: &Path, report: &Path) -> f64 {
    hysid()
        .args(["simulate", "--model"])
        .arg(model)
        .arg("--data")
        .arg(data)
        .args(["--input", "u", "--output", "y", "-q", "--json"])
        .arg(report)
        .assert()
        .success();
    read_json(report)["fit"]["fit_percent"].as_f64().unwrap()
}

#[test]
fn a_saturating_record_gets_an_envelope_that_simulates_compensates_and_exports() {
    let dir = TempDir::new().unwrap();
    let data = magnet(dir.path());
    let fit = |envelope: &str, name: &str| {
        let (model, report) = (
            dir.path().join(format!("{name}.json")),
            dir.path().join(format!("{name}-report.json")),
        );
        hysid()
            .args([
                "identify",
                "operator",
                "--family",
                "pi",
                "--envelope",
                envelope,
            ])
            .arg("--data")
            .arg(&data)
            .args(["--input", "u", "--output", "y", "-q", "--json"])
            .arg(&report)
            .arg("--model-out")
            .arg(&model)
            .assert()
            .success();
        (model, read_json(&report))
    };
    let (model, report) = fit("auto", "auto");
    let (_, plays_only) = fit("none", "none");
    let chosen = report["details"]["model_size"]["chosen"].as_str().unwrap();
    assert!(chosen.ends_with("+ envelope"), "{chosen}");
    let fitted = report["fit"]["fit_percent"].as_f64().unwrap();
    let without = plays_only["fit"]["fit_percent"].as_f64().unwrap();
    // a cubic follows this tanh (to 0.9 of its saturation) to about 1 %
    assert!(
        fitted > 98.5 && fitted > without + 2.0,
        "{fitted} vs {without}"
    );
    let saved = read_json(&model);
    let envelope = &saved["operator"]["envelope"];
    assert_eq!(envelope["slopes"].as_array().unwrap().len(), 3, "{saved}");
    // the saved model simulates the record to the fit's own figure
    let again = simulate(&model, &data, &dir.path().join("s.json"));
    assert!((again - fitted).abs() < 1e-9, "{again} vs {fitted}");
    // the compensator's commands give the reference back: the model's own output (every
    // sample reachable within the recorded input range, the commands' limits)
    let simulated = dir.path().join("simulated.csv");
    hysid()
        .args(["simulate", "--model"])
        .arg(&model)
        .arg("--data")
        .arg(&data)
        .args(["--input", "u", "-q", "--csv"])
        .arg(&simulated)
        .assert()
        .success();
    let own = columns(
        &fs::read_to_string(&simulated).unwrap(),
        &["u", "simulated"],
    );
    let mut reference = String::from("u,y\n");
    for (a, b) in own[0].iter().zip(&own[1]) {
        reference.push_str(&format!("{a},{b}\n"));
    }
    let reference_path = dir.path().join("reference.csv");
    fs::write(&reference_path, reference).unwrap();
    let commands = dir.path().join("commands.csv");
    hysid()
        .args(["compensate", "--model"])
        .arg(&model)
        .arg("--data")
        .arg(&reference_path)
        .args(["--reference", "y", "-q", "--csv"])
        .arg(&commands)
        .assert()
        .success();
    let text = fs::read_to_string(&commands).unwrap();
    let got = columns(&text, &["u", "reference"]);
    let mut back = String::from("u,y\n");
    for (a, b) in got[0].iter().zip(&got[1]) {
        back.push_str(&format!("{a},{b}\n"));
    }
    let back_path = dir.path().join("back.csv");
    fs::write(&back_path, back).unwrap();
    let followed = simulate(&model, &back_path, &dir.path().join("b.json"));
    assert!(followed > 99.999, "{followed}");
    // the exported C carries the envelope's helper
    let out = dir.path().join("exported");
    hysid()
        .args(["export", "--model"])
        .arg(&model)
        .args(["--target", "c", "--name", "magnet", "--out"])
        .arg(&out)
        .assert()
        .success();
    let code = fs::read_to_string(out.join("magnet.c")).unwrap();
    assert!(
        code.contains("envelope"),
        "the export has no envelope helper"
    );
}

#[test]
fn the_envelope_flag_is_a_pi_option() {
    let dir = TempDir::new().unwrap();
    let data = magnet(dir.path());
    let err = fails_with(
        hysid()
            .args([
                "identify",
                "operator",
                "--family",
                "gpi",
                "--envelope",
                "cubic",
            ])
            .arg("--data")
            .arg(&data)
            .args(["--input", "u", "--output", "y"]),
        2,
    );
    assert!(err.contains("--envelope applies to pi, not gpi"), "{err}");
}

/// `--dead-zones`: without it the generalised PI chooses its dead zones with its thresholds
/// (labels `"…, m dead zones"` / `"…, m quantile dead zones"`) and fits the saturating
/// record better than the fixed four of `--dead-zones 4`, whose candidates carry none.
#[test]
fn the_generalised_pis_dead_zones_are_chosen_unless_given() {
    let dir = TempDir::new().unwrap();
    let data = magnet(dir.path());
    let fit = |extra: &[&str], name: &str| {
        let report = dir.path().join(name);
        hysid()
            .args(["identify", "operator", "--family", "gpi", "--data"])
            .arg(&data)
            .args(["--input", "u", "--output", "y", "-q", "--json"])
            .arg(&report)
            .args(extra)
            .assert()
            .success();
        read_json(&report)
    };
    let chosen = fit(&[], "chosen.json");
    let size = &chosen["details"]["model_size"];
    assert!(
        size["chosen"].as_str().unwrap().contains("dead zones"),
        "{size}"
    );
    let fixed = fit(&["--dead-zones", "4"], "fixed.json");
    let candidates = fixed["details"]["model_size"]["candidates"]
        .as_array()
        .unwrap();
    assert!(!candidates.is_empty());
    assert!(candidates
        .iter()
        .all(|c| !c["size"].as_str().unwrap().contains("dead zones")));
    let percent = |r: &serde_json::Value| r["fit"]["fit_percent"].as_f64().unwrap();
    assert!(
        percent(&chosen) >= percent(&fixed),
        "{} against {}",
        percent(&chosen),
        percent(&fixed)
    );
}
