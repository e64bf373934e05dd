//! `hysid`: identify dynamic systems with hysteresis from the command line.
//!
//! Every command prints a short human report on stdout, writes progress to stderr, and, with
//! `--json FILE`, a machine-readable report. Errors are one line on stderr with exit code 1
//! (2 for command-line usage errors, from clap).

mod cli;
mod commands;
mod output;
mod plot;
mod progress;
mod report;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = cli::Cli::parse();
    match commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One line whatever the error chain: "context: cause: cause".
            let message = format!("{e:#}").replace('\n', " ");
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
