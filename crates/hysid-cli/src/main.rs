//! `hysid`: identify dynamic systems with hysteresis from the command line.
//!
//! Every command prints a short human report on stdout, writes progress to stderr, and, with
//! `--json FILE`, a machine-readable report. Every error is one line on stderr, and the exit
//! code says its class: 0 success, 1 bad input or data, 2 usage, 3 numerical failure, 4 I/O
//! (the table is in [`exit`]).

/// `println!` that keeps going when stdout is closed (a pipe into `head`): the human report
/// is lost, the run, its files and its exit code are not. Any other failed write (a full
/// disk under `> report.txt`) ends the run with exit 4 ([`exit::on_stdout`]).
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        $crate::exit::on_stdout(writeln!(std::io::stdout(), $($arg)*));
    }};
}

/// `eprintln!` that keeps going when stderr is closed: progress, warnings and errors
/// written to a closed stream are lost, the run is not.
macro_rules! tell {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

mod budget;
mod cli;
mod cli_zoo;
mod commands;
mod exit;
mod options;
mod output;
mod progress;
mod report;

use clap::error::ErrorKind;
use clap::{CommandFactory, Parser};
use exit::ExitClass;
use std::process::ExitCode;

fn main() -> ExitCode {
    exit::one_line_panics();
    remove_partial_outputs_on_interrupt();
    let args: Vec<std::ffi::OsString> = std::env::args_os().collect();
    exit::remember_args(&args);
    let cli = match cli::Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => return parser_exit(&e),
    };
    progress::init(cli.run.quiet, cli.run.time_limit);
    budget::init(cli.run.allow_long);
    match commands::run(cli) {
        Ok(()) => {
            if let Some(warning) = progress::time_limit_warning() {
                tell!("{warning}");
            }
            if let Some(failure) = exit::stdout_failure() {
                tell!("error: writing the report to stdout: {failure}; free space where stdout goes, or send it elsewhere (the result files are written)");
                return ExitClass::Io.exit_code();
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            tell!("error: {}", exit::one_line(&e));
            exit::classify(&e).exit_code()
        }
    }
}

/// On SIGINT, SIGTERM or SIGHUP: the temporaries of the run's outputs are removed (the
/// previous outputs stay as they were) and the process exits with status 130. The program
/// installs this handler, not the library (signals belong to the program).
fn remove_partial_outputs_on_interrupt() {
    // Without a handler (one could not be installed) the default action still ends the
    // run; its temporaries are hidden files that a later run of the same output ignores.
    let _ = ctrlc::set_handler(|| {
        hysid::io::atomic::remove_live_temporaries();
        std::process::exit(130);
    });
}

/// `--help` and `--version` print as usual (exit 0); every other parser error is one line
/// on stderr with exit 2.
fn parser_exit(e: &clap::Error) -> ExitCode {
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            // Printing help to a closed pipe is not worth an error.
            let _ = e.print();
            ExitCode::SUCCESS
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let command = exit::usage_command(&e.render().to_string());
            tell!("error: '{command}' needs a subcommand; run '{command} --help' for the list");
            ExitClass::Usage.exit_code()
        }
        _ => {
            let args: Vec<String> = std::env::args_os()
                .skip(1)
                .map(|a| a.to_string_lossy().into_owned())
                .collect();
            let command = exit::command_path(&cli::Cli::command(), &args);
            tell!(
                "error: {}",
                exit::usage_line(&e.render().to_string(), &command)
            );
            ExitClass::Usage.exit_code()
        }
    }
}
