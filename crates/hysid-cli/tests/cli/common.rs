//! Running the built `hysid` binary: `std::process` and a few checks on the outcome, written
//! here rather than taken from a test-harness crate, whose matchers would bring a regular-
//! expression engine into the test build for the handful of checks these tests make.

use std::ffi::OsStr;
use std::path::Path;
use std::process::{Command, Output};

/// `identify cascade` of Example 1's structure (4-parameter hysteresis, n = m = 2, delay 1)
/// on columns x → y, without `--data`.
pub const IDENTIFY_CASCADE: [&str; 14] = [
    "identify",
    "cascade",
    "--input",
    "x",
    "--output",
    "y",
    "--hysteresis",
    "ch4",
    "--na",
    "2",
    "--nb",
    "2",
    "--delay",
    "1",
];

/// The JSON document (a report or a model file) the run wrote at `path`.
pub fn read_json(path: impl AsRef<Path>) -> serde_json::Value {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A command running the `hysid` binary that Cargo built for these tests.
pub fn hysid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hysid"))
}

/// Runs `cmd`, expects a failure exit and exactly one line on stderr, "error: …", without a
/// panic; returns that line.
pub fn one_line_error(cmd: &mut Command) -> String {
    let out = cmd.assert().failure().get_output().stderr.clone();
    let err = String::from_utf8(out).unwrap();
    assert!(
        !err.contains("panicked") && err.lines().count() == 1 && err.starts_with("error: "),
        "{err}"
    );
    err
}

/// Runs `cmd`, expects exit `code` and exactly one line on stderr, "error: …"; returns that
/// line.
pub fn fails_with(cmd: &mut Command, code: i32) -> String {
    let out = cmd.output().unwrap();
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(code), "stderr: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "not one line: {stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    stderr
}

/// Runs a command and keeps its outcome for the checks of [`Outcome`].
pub trait Assert {
    /// Runs the command to the end, capturing stdout and stderr; panics only if it cannot
    /// be started.
    fn assert(&mut self) -> Outcome;
}

impl Assert for Command {
    fn assert(&mut self) -> Outcome {
        let output = self
            .output()
            .unwrap_or_else(|e| panic!("cannot run {:?}: {e}", self.get_program()));
        let line = std::iter::once(self.get_program())
            .chain(self.get_args())
            .map(OsStr::to_string_lossy)
            .collect::<Vec<_>>()
            .join(" ");
        Outcome { output, line }
    }
}

/// The finished run of a command: its exit status and captured streams. Every check panics
/// with the command line and both streams when it fails.
pub struct Outcome {
    output: Output,
    line: String,
}

impl Outcome {
    fn fail(&self, what: &str) -> ! {
        panic!(
            "{what}\ncommand: {}\nstatus: {}\nstdout: {}\nstderr: {}",
            self.line,
            self.output.status,
            String::from_utf8_lossy(&self.output.stdout),
            String::from_utf8_lossy(&self.output.stderr)
        )
    }

    /// The command exited with status 0.
    pub fn success(self) -> Self {
        if !self.output.status.success() {
            self.fail("expected success");
        }
        self
    }

    /// The command exited with a non-zero status (a signal is not a failure exit).
    pub fn failure(self) -> Self {
        if self.output.status.success() || self.output.status.code().is_none() {
            self.fail("expected a failure exit");
        }
        self
    }

    /// The command exited with status `code`.
    pub fn code(self, code: i32) -> Self {
        if self.output.status.code() != Some(code) {
            self.fail(&format!("expected exit code {code}"));
        }
        self
    }

    /// stderr contains `text`.
    pub fn stderr_contains(self, text: &str) -> Self {
        if !String::from_utf8_lossy(&self.output.stderr).contains(text) {
            self.fail(&format!("expected {text:?} on stderr"));
        }
        self
    }

    /// stdout does not contain `text`.
    pub fn stdout_lacks(self, text: &str) -> Self {
        if String::from_utf8_lossy(&self.output.stdout).contains(text) {
            self.fail(&format!("expected no {text:?} on stdout"));
        }
        self
    }

    /// The captured status and streams.
    pub fn get_output(&self) -> &Output {
        &self.output
    }
}
