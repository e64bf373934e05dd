//! `hysid greybox fit` says when its default zero-order hold misleads: one warning line on
//! stderr naming `--interpolation band-limited`, the same text in the report's `warnings`,
//! on the Bouc–Wen benchmark's band-limited multisine; nothing on a record whose input is
//! really held between samples.

use crate::common::{hysid, read_json, Assert};
use std::fs;
use std::path::{Path, PathBuf};
use tempfile::TempDir;

const HINT: &str = "--interpolation band-limited";

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The first `samples` samples of the benchmark's multisine training record.
fn multisine_head(dir: &Path, samples: usize) -> PathBuf {
    let text =
        fs::read_to_string(root().join("data/bouc-wen/train_multisine_5periods.csv")).unwrap();
    let head: Vec<&str> = text.lines().take(samples + 1).collect();
    let path = dir.join("multisine.csv");
    fs::write(&path, head.join("\n") + "\n").unwrap();
    path
}

/// `hysid greybox fit` of the Bouc–Wen equation file on `data` with `extra` options; the
/// outcome's stderr and the report.
fn fit(dir: &Path, data: &Path, extra: &[&str]) -> (String, serde_json::Value) {
    let report = dir.join("report.json");
    let outcome = hysid()
        .args(["greybox", "fit", "--model-file"])
        .arg(root().join("examples/equations/bouc_wen.toml"))
        .arg("--data")
        .arg(data)
        .args([
            "--input",
            "u_N",
            "--output",
            "y_m",
            "--max-iterations",
            "10",
            "-q",
        ])
        .args(extra)
        .arg("--json")
        .arg(&report)
        .assert()
        .success();
    let stderr = String::from_utf8_lossy(&outcome.get_output().stderr).into_owned();
    (stderr, read_json(&report))
}

/// 2048 samples of the band-limited multisine (5–150 Hz at 750 Hz) fitted with the default
/// hold: one warning line, the same text in the report; with band-limited interpolation
/// none (and a ten times smaller RMSE).
#[test]
fn default_hold_on_a_band_limited_record_warns() {
    let dir = TempDir::new().unwrap();
    let data = multisine_head(dir.path(), 2048);
    let (stderr, held) = fit(dir.path(), &data, &[]);
    let lines: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("warning:"))
        .collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    assert!(lines[0].contains(HINT), "{stderr}");
    let warnings = held["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1);
    assert_eq!(
        format!("warning: {}", warnings[0].as_str().unwrap()),
        lines[0]
    );
    assert_eq!(held["details"]["hold_check"]["fires"], true);

    let (stderr, band) = fit(dir.path(), &data, &["--interpolation", "band-limited"]);
    assert!(!stderr.contains(HINT), "{stderr}");
    assert_eq!(band["warnings"].as_array().unwrap().len(), 0);
    let (h, b) = (
        held["fit"]["rmse"].as_f64().unwrap(),
        band["fit"]["rmse"].as_f64().unwrap(),
    );
    assert!(h > 5.0 * b, "held {h}, band-limited {b}");
}

/// A random staircase input (levels held 8 samples) and the output the fitted model gives
/// it under zero-order hold: the default fit of that record does not warn.
#[test]
fn default_hold_on_a_held_record_is_silent() {
    let dir = TempDir::new().unwrap();
    let data = multisine_head(dir.path(), 2048);
    // A model to simulate with: the band-limited fit, switched to zero-order hold.
    let model = dir.path().join("model.json");
    hysid()
        .args(["greybox", "fit", "--model-file"])
        .arg(root().join("examples/equations/bouc_wen.toml"))
        .arg("--data")
        .arg(&data)
        .args([
            "--input",
            "u_N",
            "--output",
            "y_m",
            "--max-iterations",
            "10",
            "-q",
        ])
        .args(["--interpolation", "band-limited", "--model-out"])
        .arg(&model)
        .assert()
        .success();
    let mut saved = read_json(&model);
    saved["simulation"]["interpolation"] = "zero_order_hold".into();
    fs::write(&model, saved.to_string()).unwrap();

    // Levels of RMS about 50 N (a fixed linear congruential sequence), 8 samples each.
    let n = 2048;
    let mut state: u64 = 12345;
    let levels: Vec<f64> = (0..n / 8)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 173.0
        })
        .collect();
    let stairs = dir.path().join("stairs.csv");
    let mut text = String::from("t_s,u_N\n");
    for t in 0..n {
        text += &format!("{},{}\n", t as f64 / 750.0, levels[t / 8]);
    }
    fs::write(&stairs, text).unwrap();
    let simulated = dir.path().join("simulated.csv");
    hysid()
        .args(["simulate", "--model"])
        .arg(&model)
        .arg("--data")
        .arg(&stairs)
        .args(["--input", "u_N", "-q", "--csv"])
        .arg(&simulated)
        .assert()
        .success();
    let mut record = String::from("t_s,u_N,y_m\n");
    for (t, line) in fs::read_to_string(&simulated)
        .unwrap()
        .lines()
        .skip(1)
        .enumerate()
    {
        record += &format!("{},{line}\n", t as f64 / 750.0);
    }
    let held = dir.path().join("held.csv");
    fs::write(&held, record).unwrap();

    let (stderr, report) = fit(dir.path(), &held, &[]);
    assert!(!stderr.contains(HINT), "{stderr}");
    assert_eq!(report["warnings"].as_array().unwrap().len(), 0);
    let check = &report["details"]["hold_check"];
    assert_eq!(check["fires"], false);
    assert!(
        check["high_band_fraction"].as_f64().unwrap() > 1e-2,
        "{check}"
    );
}
