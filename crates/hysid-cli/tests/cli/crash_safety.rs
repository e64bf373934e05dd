//! Crash-safe outputs: a run killed by SIGKILL at any moment leaves every output path with
//! its previous complete content or the new one — never nothing, never a part.
//!
//! Each scenario runs once to completion (its outputs are then the "previous" ones and its
//! duration T is measured), then 20 more times, each killed at a moment drawn from a seeded
//! generator in [0, 1.2·T) — before, during and after the writes. After every kill each
//! output must be complete: the report and the model file parse as JSON and carry their
//! schema tag, the plot directory holds every figure, each a whole SVG document; the data
//! directory holds every record, each with all its rows.
//!
//! Interrupted runs (SIGINT at the same kind of seeded moments) must in addition leave no
//! temporary behind and exit with status 130: the command line's own handler removes them
//! (the library installs none; signals belong to the program).

use crate::common::{hysid, Assert};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use std::fs;
use std::path::Path;
use std::process::Command;
use std::time::Instant;
use tempfile::TempDir;

/// How many kills each scenario makes.
const KILLS: usize = 20;

/// How a run is stopped.
#[derive(Clone, Copy, PartialEq)]
enum Stop {
    /// SIGKILL: no handler runs; hidden temporaries may stay.
    Kill,
    /// SIGINT: the handler removes every temporary and exits with 130.
    Interrupt,
}

/// Runs `command` to completion once, then `KILLS` times killed at seeded moments, calling
/// `check` on the working directory after each run.
fn killed_at_random_moments(
    seed: u64,
    dir: &Path,
    command: impl Fn() -> Command,
    check: impl Fn(&Path),
) {
    stopped_at_random_moments(Stop::Kill, seed, dir, command, check);
}

/// [`killed_at_random_moments`] with the run stopped by `stop`. An interrupted run must have
/// exited with 130 (or 0 when it had finished) and left no `hysid-tmp` temporary.
fn stopped_at_random_moments(
    stop: Stop,
    seed: u64,
    dir: &Path,
    command: impl Fn() -> Command,
    check: impl Fn(&Path),
) {
    let started = Instant::now();
    let status = command().status().unwrap();
    assert!(status.success(), "the complete run failed");
    let duration = started.elapsed();
    check(dir);
    let mut rng = StdRng::seed_from_u64(seed);
    for _ in 0..KILLS {
        let moment = duration.mul_f64(rng.random_range(0.0..1.2));
        let mut child = command().spawn().unwrap();
        std::thread::sleep(moment);
        // The run may already have finished: then the kill is a no-op and the check sees
        // the new outputs.
        match stop {
            Stop::Kill => {
                let _ = child.kill();
                child.wait().unwrap();
            }
            Stop::Interrupt => {
                let _ = Command::new("kill")
                    .args(["-INT", &child.id().to_string()])
                    .status();
                let status = child.wait().unwrap();
                assert!(
                    matches!(status.code(), Some(0 | 130)),
                    "an interrupted run exited with {status}"
                );
                let left: Vec<String> = walk(dir)
                    .into_iter()
                    .filter(|name| name.contains("hysid-tmp"))
                    .collect();
                assert!(left.is_empty(), "temporaries left after SIGINT: {left:?}");
            }
        }
        check(dir);
    }
}

/// The names of every file and directory under `dir`.
fn walk(dir: &Path) -> Vec<String> {
    let mut names = Vec::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for entry in fs::read_dir(&d).unwrap().flatten() {
            names.push(entry.file_name().to_string_lossy().into_owned());
            if entry.path().is_dir() {
                pending.push(entry.path());
            }
        }
    }
    names
}

/// The JSON document at `path`, which must exist and parse, with its `schema` tag.
fn complete_json(path: &Path) -> String {
    let text = fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{} is missing after a kill: {e}", path.display()));
    let value: serde_json::Value = serde_json::from_str(&text)
        .unwrap_or_else(|e| panic!("{} is not complete JSON after a kill: {e}", path.display()));
    value["schema"]
        .as_str()
        .unwrap_or_else(|| panic!("{} has no schema tag", path.display()))
        .to_string()
}

/// Checks that `dir` holds exactly the files `names`, each passing `complete`.
fn complete_dir(dir: &Path, names: &[String], complete: impl Fn(&str) -> bool) {
    let mut found: Vec<String> = fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{} is missing after a kill: {e}", dir.display()))
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    found.sort();
    let mut expected = names.to_vec();
    expected.sort();
    assert_eq!(found, expected, "{} after a kill", dir.display());
    for name in names {
        let text = fs::read_to_string(dir.join(name)).unwrap();
        assert!(
            complete(&text),
            "{}/{name} is incomplete after a kill",
            dir.display()
        );
    }
}

#[test]
#[ignore = "long (21 runs, about ten seconds): run by `cargo test --release -- --ignored` and CI"]
fn a_killed_cascade_fit_leaves_its_report_model_and_plots_complete() {
    let tmp = TempDir::new().unwrap();
    let dir = tmp.path().to_path_buf();
    hysid()
        .current_dir(&dir)
        .args(["generate", "voros", "--example", "1", "--samples", "200000"])
        .args(["--seed", "3", "--csv", "big.csv"])
        .assert()
        .success();
    let figures: Vec<String> = ["input.svg", "loops.svg", "output.svg"]
        .map(String::from)
        .to_vec();
    killed_at_random_moments(
        27,
        &dir,
        || {
            let mut cmd = Command::new(env!("CARGO_BIN_EXE_hysid"));
            cmd.current_dir(&dir)
                .args(crate::common::IDENTIFY_CASCADE)
                .args(["--data", "big.csv", "--json", "report.json"])
                .args(["--model-out", "model.json", "--plots", "plots"])
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::null());
            cmd
        },
        |dir| {
            assert_eq!(complete_json(&dir.join("report.json")), "hysid.report/1");
            assert_eq!(complete_json(&dir.join("model.json")), "hysid.model/1");
            let plots = dir.join("plots");
            let svgs: Vec<String> = fs::read_dir(&plots)
                .unwrap_or_else(|e| panic!("plots is missing after a kill: {e}"))
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            for name in &figures {
                assert!(svgs.contains(name), "{name} missing after a kill: {svgs:?}");
            }
            complete_dir(&plots, &svgs, |text| text.trim_end().ends_with("</svg>"));
        },
    );
}

#[test]
#[ignore = "long (21 runs, about ten seconds): run by `cargo test --release -- --ignored` and CI"]
fn a_killed_rig_leaves_its_data_directory_complete() {
    rig_stopped_at_random_moments(Stop::Kill, 29);
}

#[test]
#[ignore = "long (21 runs, about ten seconds): run by `cargo test --release -- --ignored` and CI"]
fn an_interrupted_rig_removes_its_partial_outputs() {
    rig_stopped_at_random_moments(Stop::Interrupt, 31);
}

/// The rig's data directory after runs stopped by `stop` at moments drawn with `seed`.
fn rig_stopped_at_random_moments(stop: Stop, seed: u64) {
    let tmp = TempDir::new().unwrap();
    let dir = tmp.path().to_path_buf();
    let mut names: Vec<String> = (1..=8).map(|k| format!("dataset{k}.csv")).collect();
    names.push("rig.json".into());
    // A whole CSV record: every row has the header's number of fields, and the last row
    // ends with its newline.
    let whole_csv = |text: &str| {
        let fields = |line: &str| line.split(',').count();
        let mut lines = text.lines();
        let header = lines.next().map(fields).unwrap_or(0);
        text.ends_with('\n') && header > 1 && lines.all(|line| fields(line) == header)
    };
    stopped_at_random_moments(
        stop,
        seed,
        &dir,
        || {
            let mut cmd = Command::new(env!("CARGO_BIN_EXE_hysid"));
            cmd.current_dir(&dir)
                .args(["actuator", "rig", "--data-out", "rig"])
                .stdout(std::process::Stdio::null())
                .stderr(std::process::Stdio::null());
            cmd
        },
        |dir| {
            let rig = dir.join("rig");
            complete_dir(&rig, &names, |text| {
                if text.trim_start().starts_with('{') {
                    serde_json::from_str::<serde_json::Value>(text).is_ok()
                } else {
                    whole_csv(text)
                }
            });
            // Nothing but the data directory and, after kills, hidden temporaries.
            for entry in fs::read_dir(dir).unwrap() {
                let name = entry.unwrap().file_name().to_string_lossy().into_owned();
                assert!(name == "rig" || name.starts_with('.'), "unexpected {name}");
            }
        },
    );
}
