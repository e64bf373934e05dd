//! Command limits end to end: a fit records its input range, `hysid compensate` and `hysid
//! export --inverse` limit the command to it (or to `--limits LO:HI`), and a file without it
//! is compensated unlimited with a one-line warning.

use crate::common::{hysid, read_json, Assert};
use std::fs;
use std::path::{Path, PathBuf};
use tempfile::TempDir;

fn piezo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/piezo/piezo_150V_1Hz.csv")
}

/// The commands `hysid compensate` wrote (column u) and its stderr.
fn compensate(model: &Path, reference: &Path, extra: &[&str], dir: &Path) -> (Vec<f64>, String) {
    let csv = dir.join("u.csv");
    let out = hysid()
        .args(["compensate", "--model"])
        .arg(model)
        .arg("--data")
        .arg(reference)
        .args(["--reference", "r", "--csv"])
        .arg(&csv)
        .args(extra)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    let text = fs::read_to_string(&csv).unwrap();
    let u = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    (u, stderr)
}

#[test]
fn compensate_and_export_limit_the_command_to_the_fitted_input_range() {
    let dir = TempDir::new().unwrap();
    let model = dir.path().join("pi.json");
    hysid()
        .args(["identify", "operator", "--family", "pi", "--data"])
        .arg(piezo())
        .args([
            "--input",
            "voltage_V",
            "--output",
            "displacement_um",
            "--model-out",
        ])
        .arg(&model)
        .assert()
        .success();
    let file = read_json(&model);
    let range = &file["input_range"][0];
    let (lo, hi) = (range[0].as_f64().unwrap(), range[1].as_f64().unwrap());
    assert!(lo < hi, "{file}");
    // A reference ten times beyond the displacement's range.
    let reference = dir.path().join("ref.csv");
    let mut text = String::from("t,r\n");
    for k in 0..400 {
        let s = (2.0 * std::f64::consts::PI * 2.0 * k as f64 / 400.0).sin();
        text.push_str(&format!("{k},{}\n", 300.0 * s));
    }
    fs::write(&reference, text).unwrap();
    let (u, stderr) = compensate(&model, &reference, &[], dir.path());
    assert!(
        u.iter().all(|v| lo <= *v && *v <= hi),
        "beyond [{lo}, {hi}]"
    );
    assert!(u.contains(&lo) && u.contains(&hi), "the limits never acted");
    assert!(stderr.contains("clipped"), "{stderr}");
    let (u, _) = compensate(&model, &reference, &["--limits", "10:50"], dir.path());
    assert!(u.iter().all(|v| (10.0..=50.0).contains(v)));
    assert!(u.contains(&10.0) && u.contains(&50.0));
    // A file without input_range: unlimited, with a warning.
    let mut old = file.clone();
    old.as_object_mut().unwrap().remove("input_range");
    let old_path = dir.path().join("old.json");
    fs::write(&old_path, old.to_string()).unwrap();
    let (u, stderr) = compensate(&old_path, &reference, &[], dir.path());
    assert!(u.iter().any(|v| *v > hi), "the old file was limited");
    assert!(stderr.contains("no input_range"), "{stderr}");
    // The export states the limits; --limits without --inverse is a usage error.
    let out = dir.path().join("c");
    hysid()
        .args(["export", "--model"])
        .arg(&model)
        .args([
            "--target",
            "c",
            "--name",
            "stage",
            "--inverse",
            "--limits",
            "-5:90",
            "--out",
        ])
        .arg(&out)
        .assert()
        .success();
    let header = fs::read_to_string(out.join("stage.h")).unwrap();
    assert!(
        header.contains("Command limits: [-5.0, 90.0] (given at export"),
        "{header}"
    );
    assert!(header.contains("size_t stage_faults(const stage_state *s);"));
    let refused = hysid()
        .args(["export", "--model"])
        .arg(&model)
        .args([
            "--target", "c", "--name", "stage", "--limits", "-5:90", "--out",
        ])
        .arg(dir.path().join("d"))
        .output()
        .unwrap();
    assert_eq!(refused.status.code(), Some(2));
    let bad = hysid()
        .args(["export", "--model"])
        .arg(&model)
        .args([
            "--target",
            "c",
            "--name",
            "stage",
            "--inverse",
            "--limits",
            "90:-5",
            "--out",
        ])
        .arg(dir.path().join("e"))
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
}
