//! `--initial-state` and the saved state end to end (issue 38, item 2): a Bouc–Wen record
//! that starts in saturation, fitted with a declared descending history, saves it, and
//! `hysid simulate` re-applies it; `--warm-up N` and `--history FILE` set the state from
//! rows that are not scored; a declared history on a family without it is one line.

use crate::common::{hysid, one_line_error, read_json, Assert};
use hysid::model::operators::{
    differential, initial_state, BoucWen, HysteresisOperator, InitialStateUsed, OperatorFamily,
    PrandtlIshlinskii,
};
use std::fs;
use std::path::{Path, PathBuf};
use tempfile::TempDir;

/// A piecewise-linear input through `turns`, 100 samples per unit.
fn through(turns: &[f64]) -> Vec<f64> {
    let mut u = vec![turns[0]];
    for w in turns.windows(2) {
        let n = ((w[1] - w[0]).abs() * 100.0).ceil().max(1.0) as usize;
        u.extend((1..=n).map(|k| w[0] + (w[1] - w[0]) * k as f64 / n as f64));
    }
    u
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

/// The plant's record from the state after a descent from 100 above its first input.
fn saturated(plant: &BoucWen, u: &[f64]) -> Vec<f64> {
    let mut p = plant.clone();
    p.w0 = differential::states(&p, &[u[0], u[0] + 100.0, u[0]]).unwrap()[2];
    p.simulate(u).unwrap()
}

fn simulate(model: &Path, data: &Path, report: &Path, extra: &[&str]) -> f64 {
    hysid()
        .args(["simulate", "--model"])
        .arg(model)
        .arg("--data")
        .arg(data)
        .args(["--input", "u", "--output", "y", "--json"])
        .arg(report)
        .args(extra)
        .assert()
        .success();
    read_json(report)["fit"]["fit_percent"].as_f64().unwrap()
}

/// `hysid compensate` of the column y of `data` into `commands`: its stderr (it succeeded).
fn compensate(model: &Path, data: &Path, commands: &Path) -> String {
    let out = hysid()
        .args(["compensate", "--model"])
        .arg(model)
        .arg("--data")
        .arg(data)
        .args(["--reference", "y", "--csv"])
        .arg(commands)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    stderr
}

/// The column `name` of the CSV file at `path`.
fn column(path: &Path, name: &str) -> Vec<f64> {
    let text = fs::read_to_string(path).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let at = header.iter().position(|h| *h == name).unwrap();
    text.lines()
        .skip(1)
        .map(|l| l.split(',').nth(at).unwrap().parse().unwrap())
        .collect()
}

/// `hysid compensate` of the column y of `data` (into `dir/u.csv`), then `simulate` of the
/// commands against the reference: compensate's stderr and the fit % the commands reach.
fn followed(dir: &Path, model: &Path, data: &Path) -> (String, f64) {
    let commands = dir.join("u.csv");
    let stderr = compensate(model, data, &commands);
    let back = write(
        dir,
        "commands.csv",
        &column(&commands, "u"),
        &column(&commands, "reference"),
    );
    (stderr, simulate(model, &back, &dir.join("c.json"), &[]))
}

#[test]
fn a_declared_history_is_saved_reported_and_reapplied_by_simulate() {
    let dir = TempDir::new().unwrap();
    let plant = BoucWen::new(0.3, -1.0, 2.5, 1.5, 1.0).unwrap();
    let train_u = through(&[-1.0, 1.0, -0.2, 0.6, -0.7, 0.9, 0.1, -1.0, 0.5]);
    let valid_u = through(&[-0.8, 0.7, -0.4, 1.0, 0.0, -0.6, 0.8]);
    let train = write(
        dir.path(),
        "train.csv",
        &train_u,
        &saturated(&plant, &train_u),
    );
    let valid = write(
        dir.path(),
        "valid.csv",
        &valid_u,
        &saturated(&plant, &valid_u),
    );
    let (model, report) = (dir.path().join("m.json"), dir.path().join("r.json"));
    hysid()
        .args([
            "identify",
            "operator",
            "--family",
            "bouc-wen",
            "--initial-state",
        ])
        .arg("descending")
        .arg("--data")
        .arg(&train)
        .args(["--input", "u", "--output", "y", "--json"])
        .arg(&report)
        .arg("--model-out")
        .arg(&model)
        .assert()
        .success();
    let r = read_json(&report);
    assert_eq!(r["details"]["initial_state"], "descending", "{r}");
    let saved = read_json(&model);
    assert_eq!(saved["initial_state"], "descending", "{saved}");
    // The fit's turn is saved (above the training record's maximum, 1).
    let turn = saved["history_turn"].as_f64().unwrap();
    assert!(turn > 1.0 && turn.is_finite(), "{saved}");
    // The compensator runs the history too (no warning): each trial of its first command
    // integrates the descent, so the commands are the validation record's input from its
    // first sample on, while the reference falls (this Bouc–Wen's ascending branch is not
    // monotone, kₓ = 0.3 against k_w·dw/du from −2 up to 0, and past the branch's minimum
    // the inverse may take the other root).
    let commands = dir.path().join("u.csv");
    let stderr = compensate(&model, &valid, &commands);
    assert!(!stderr.contains("declared"), "{stderr}");
    let (sent, reference) = (column(&commands, "u"), column(&commands, "reference"));
    let falling = reference.windows(2).position(|w| w[1] >= w[0]).unwrap();
    assert!(falling > 20, "{falling}");
    for k in 0..falling {
        assert!(
            (sent[k] - valid_u[k]).abs() < 1e-6,
            "{k}: {} against {}",
            sent[k],
            valid_u[k]
        );
    }
    // A file without the turn (an earlier version) starts its inverse from w₀ instead, and
    // says so.
    let mut old = read_json(&model);
    old.as_object_mut().unwrap().remove("history_turn");
    let old_model = dir.path().join("old.json");
    fs::write(&old_model, old.to_string()).unwrap();
    let stderr = compensate(&old_model, &valid, &commands);
    assert!(stderr.contains("declared descending history"), "{stderr}");
    // The validation record starts at another input (−0.8), after its own descent: the
    // history is re-applied there (exact data: the fit is exact).
    let fit = simulate(&model, &valid, &dir.path().join("s.json"), &[]);
    assert!(fit > 99.9, "{fit}");

    // --history: the training record first, then the validation record continues from the
    // state it leaves (here the plant's own continuation).
    let both_u: Vec<f64> = train_u.iter().chain(&valid_u[1..]).copied().collect();
    let both_y = saturated(&plant, &both_u);
    let n = train_u.len();
    let rest = write(dir.path(), "rest.csv", &both_u[n..], &both_y[n..]);
    let fit = simulate(
        &model,
        &rest,
        &dir.path().join("h.json"),
        &["--history", train.to_str().unwrap()],
    );
    assert!(fit > 99.9, "{fit}");
    // --warm-up: the same from one file, the first n rows not scored.
    let all = write(dir.path(), "all.csv", &both_u, &both_y);
    let report = dir.path().join("w.json");
    let fit = simulate(&model, &all, &report, &["--warm-up", &n.to_string()]);
    assert!(fit > 99.9, "{fit}");
    // A warm-up that leaves nothing is refused in one line.
    let e = one_line_error(
        hysid()
            .args(["simulate", "--model"])
            .arg(&model)
            .arg("--data")
            .arg(&valid)
            .args(["--input", "u", "--output", "y", "--warm-up", "100000"]),
    );
    assert!(e.contains("--warm-up"), "{e}");
}

#[test]
fn a_declared_history_on_a_linear_family_is_fitted_saved_and_reapplied() {
    let dir = TempDir::new().unwrap();
    let u = through(&[0.4, -1.0, 1.0, -0.5, 0.5]);
    let plant = PrandtlIshlinskii::example().unwrap();
    let y = initial_state::simulate(&plant, Some(InitialStateUsed::Descending), &u).unwrap();
    let data = write(dir.path(), "d.csv", &u, &y);
    let model = dir.path().join("m.json");
    let report = dir.path().join("r.json");
    hysid()
        .args([
            "identify",
            "operator",
            "--family",
            "pi",
            "--initial-state",
            "descending",
        ])
        .arg("--data")
        .arg(&data)
        .args(["--input", "u", "--output", "y", "-q", "--json"])
        .arg(&report)
        .arg("--model-out")
        .arg(&model)
        .assert()
        .success();
    let saved = read_json(&model);
    assert_eq!(saved["initial_state"], "descending", "{saved}");
    // The PI compensator runs the history (no warning) and its commands reproduce the
    // record's input where the model is exact.
    let (stderr, followed) = followed(dir.path(), &model, &data);
    assert!(!stderr.contains("declared"), "{stderr}");
    assert!(followed > 99.999, "{followed}");
    let commands = dir.path().join("u.csv");
    let wanted = column(&commands, "reference");
    // A file without the turn (an earlier version) compensates from the operator's own
    // state, says so, and its commands miss the record's first loop.
    let mut old = read_json(&model);
    old.as_object_mut().unwrap().remove("history_turn");
    let old_model = dir.path().join("old.json");
    fs::write(&old_model, old.to_string()).unwrap();
    let stderr = compensate(&old_model, &data, &commands);
    assert!(stderr.contains("declared descending history"), "{stderr}");
    let back = write(dir.path(), "commands.csv", &column(&commands, "u"), &wanted);
    let missed = simulate(&model, &back, &dir.path().join("c.json"), &[]);
    assert!(missed < followed - 0.1, "{missed} against {followed}");
    let reported = read_json(&report);
    let fitted = reported["fit"]["fit_percent"].as_f64().unwrap();
    // simulate re-applies the descent at the record's first input: the fit's own numbers
    let again = simulate(&model, &data, &dir.path().join("s.json"), &[]);
    assert!((again - fitted).abs() < 1e-9, "{again} against {fitted}");
    assert!(again > 99.0, "{again}");
}
