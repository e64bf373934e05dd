//! The compensator tutorial (`docs/tutorials/compensator.md`) as written: its `sh` blocks run
//! in order with `sh -e` from the repository root, its `c` block is the program they compile,
//! and the C program's commands must equal `hysid compensate`'s to 1e-12 of their range.
//!
//! Only two things are substituted: the scratch directory `/tmp/hysid-tutorial` becomes a
//! temporary one, and `hysid` is found first on `PATH` in the directory of the binary Cargo
//! built for these tests (the tutorial's `cargo install` line is skipped).

use crate::common::read_json;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use tempfile::TempDir;

const SCRATCH: &str = "/tmp/hysid-tutorial";
const INSTALL: &str = "cargo install --path crates/hysid-cli";

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The fenced blocks of a markdown text, in order: (info string, body).
fn fenced_blocks(markdown: &str) -> Vec<(String, String)> {
    let mut blocks = Vec::new();
    let mut open: Option<(String, String)> = None;
    for line in markdown.lines() {
        match (&mut open, line.strip_prefix("```")) {
            (None, Some(info)) => open = Some((info.trim().to_string(), String::new())),
            (Some(_), Some(rest)) if rest.trim().is_empty() => blocks.extend(open.take()),
            (Some((_, body)), _) => {
                body.push_str(line);
                body.push('\n');
            }
            (None, None) => {}
        }
    }
    assert!(open.is_none(), "an unclosed fenced block");
    blocks
}

/// Runs a shell block from the repository root; returns its stdout.
fn run_sh(script: &str, path: &str) -> String {
    let out = Command::new("sh")
        .args(["-e", "-c", script])
        .current_dir(repo_root())
        .env("PATH", path)
        .output()
        .expect("cannot run sh");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "the tutorial's block failed ({}):\n{script}\nstdout:\n{stdout}\nstderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// The value of `--flag VALUE` in a command line.
fn flag_value<'a>(command: &'a str, flag: &str) -> Option<&'a str> {
    let mut words = command.split_whitespace();
    words.find(|w| *w == flag)?;
    words.next()
}

#[test]
fn fenced_blocks_are_split_by_their_info_strings() {
    let blocks = fenced_blocks("text\n```sh\necho a\n```\n\n```c\nint x;\n```\n```\nplain\n```\n");
    assert_eq!(
        blocks,
        vec![
            ("sh".to_string(), "echo a\n".to_string()),
            ("c".to_string(), "int x;\n".to_string()),
            (String::new(), "plain\n".to_string()),
        ]
    );
}

#[test]
#[ignore = "long (compare fits every family, some 20 s): run by `-- --ignored` and CI"]
fn compensator_tutorial_runs_as_written_and_its_c_equals_hysid_compensate() {
    let markdown = fs::read_to_string(repo_root().join("docs/tutorials/compensator.md")).unwrap();
    let tmp = TempDir::new().unwrap();
    let scratch = tmp.path().join("hysid-tutorial");
    let scratch_str = scratch.to_str().unwrap();
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_hysid")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin_dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );

    let blocks = fenced_blocks(&markdown);
    let sh: Vec<&String> = blocks
        .iter()
        .filter(|(i, _)| i == "sh")
        .map(|(_, b)| b)
        .collect();
    let c: Vec<&String> = blocks
        .iter()
        .filter(|(i, _)| i == "c")
        .map(|(_, b)| b)
        .collect();
    assert!(
        sh.len() >= 6,
        "expected the tutorial's steps, found {} sh blocks",
        sh.len()
    );
    assert_eq!(c.len(), 1, "exactly one C program");
    assert!(
        markdown.contains(&format!("Save it as `{SCRATCH}/main.c`")),
        "the tutorial names where the C program goes"
    );
    for needle in [
        "hysid compare ",
        "hysid identify operator ",
        "hysid compensate ",
        "hysid export ",
        "--target c --inverse",
        "%.17g",
    ] {
        assert!(markdown.contains(needle), "the tutorial lost `{needle}`");
    }

    let mut last_stdout = String::new();
    let mut c_written = false;
    for (info, body) in &blocks {
        match info.as_str() {
            "sh" => {
                let script: String = body
                    .lines()
                    .filter(|line| line.trim() != INSTALL)
                    .collect::<Vec<_>>()
                    .join("\n")
                    .replace(SCRATCH, scratch_str);
                // The program is saved before anything compiles it.
                assert!(
                    c_written || !script.contains("main.c"),
                    "main.c compiled before the tutorial shows it"
                );
                last_stdout = run_sh(&script, &path);
            }
            "c" => {
                fs::write(scratch.join("main.c"), body).unwrap();
                c_written = true;
            }
            _ => {}
        }
    }

    // The family fitted is the one compare ranked first.
    let compare = read_json(scratch.join("compare.json"));
    let best = compare["details"]["best"].as_str().unwrap().to_string();
    let identify = sh
        .iter()
        .find(|b| b.contains("hysid identify operator"))
        .unwrap();
    assert_eq!(flag_value(identify, "--family"), Some(best.as_str()));

    // The figure the tutorial prints, and the same comparison made here.
    let figure: f64 = last_stdout
        .trim()
        .rsplit('=')
        .next()
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or_else(|| panic!("no figure in the last block's output: {last_stdout}"));
    assert!(figure <= 1e-12, "printed max difference {figure}");
    let compensated = fs::read_to_string(scratch.join("compensate.csv")).unwrap();
    let mut lines = compensated.lines();
    let u_col = lines
        .next()
        .unwrap()
        .split(',')
        .position(|h| h == "u")
        .expect("a u column");
    let u: Vec<f64> = lines
        .map(|l| l.split(',').nth(u_col).unwrap().parse().unwrap())
        .collect();
    let c_out: Vec<f64> = fs::read_to_string(scratch.join("u_c.txt"))
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect();
    assert_eq!(u.len(), 2000);
    assert_eq!(c_out.len(), u.len());
    let (lo, hi) = u
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
    let max_diff = u
        .iter()
        .zip(&c_out)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(hi > lo);
    assert!(
        max_diff <= 1e-12 * (hi - lo),
        "C differs from hysid compensate by {max_diff} (range {})",
        hi - lo
    );
    assert_eq!(figure, max_diff / (hi - lo));
}
