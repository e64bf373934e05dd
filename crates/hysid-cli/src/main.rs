//! `hysid`: identify dynamic systems with hysteresis from the command line.
//!
//! Every command prints a short human report on stdout, writes progress to stderr, and, with
//! `--json FILE`, a machine-readable report. Errors are one line on stderr with exit code 1
//! (2 for command-line usage errors, from clap).

mod cli;
mod commands;
mod deprecated;
mod output;
mod plot;
mod progress;
mod report;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = deprecated::rewrite(std::env::args_os().collect());
    let cli = cli::Cli::parse_from(args);
    match commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", one_line(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error chain on one line, "context: cause", leaving out causes the message already
/// quotes (the library's errors include their source in their own text).
fn one_line(e: &anyhow::Error) -> String {
    let mut message = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if !message.contains(&text) {
            if !message.is_empty() {
                message.push_str(": ");
            }
            message.push_str(&text);
        }
    }
    message.replace('\n', " ")
}
