//! Exit codes and one-line error messages.
//!
//! | code | meaning |
//! | --- | --- |
//! | 0 | success (also `--help` and `--version`) |
//! | 1 | bad input or data: a malformed or inconsistent file, a parameter out of its range, data that cannot identify the model — degenerate data among them: a channel whose squares overflow or underflow (beyond 1e150, all below 1e-150), an output without variation at double precision, a rig truth that makes the simulation or its tables non-finite |
//! | 2 | usage: the command line itself is wrong (unknown option, missing or unparsable value, an output path that is an input or another output of the run) |
//! | 3 | numerical failure: a singular regression, a diverged simulation, a non-finite result |
//! | 4 | I/O: a file could not be opened, read or written; stdout failed other than by a closed pipe (a closed pipe loses the report text, not the run) |
//! | 130 | interrupted (SIGINT, SIGTERM, SIGHUP): the run's partial outputs removed (`main`'s handler) |
//! | 101 | an internal fault (a panic) — a bug to report |
//!
//! Every error is one line on stderr: what is wrong, where, and what to do. Usage errors
//! from the argument parser are folded to one line and end with the `--help` to run.

use hysid::error::Category;
use hysid::Error;
use std::process::ExitCode;

/// The class of a failed run, which fixes its exit code (see the [module table](self)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExitClass {
    /// Bad input or data (exit 1).
    BadInput,
    /// The command line is wrong (exit 2).
    Usage,
    /// A numerical failure (exit 3).
    Numerical,
    /// A file could not be read or written (exit 4).
    Io,
}

impl ExitClass {
    /// The process exit code of this class.
    pub fn code(self) -> u8 {
        match self {
            ExitClass::BadInput => 1,
            ExitClass::Usage => 2,
            ExitClass::Numerical => 3,
            ExitClass::Io => 4,
        }
    }

    /// The class as a process exit code.
    pub fn exit_code(self) -> ExitCode {
        ExitCode::from(self.code())
    }
}

/// The class of a library error, from its [`Category`]: an unreadable or unwritable file is
/// I/O, a numerical failure is numerical, everything about the content of files, data and
/// settings is bad input (so are a cancelled run and an internal serialisation failure,
/// which a command reports like any other refusal).
pub fn library_class(error: &Error) -> ExitClass {
    match error.category() {
        Category::Io => ExitClass::Io,
        Category::Numerical => ExitClass::Numerical,
        // Flags that name the same file twice: the command line itself is wrong.
        Category::Usage => ExitClass::Usage,
        Category::Data
        | Category::Config
        | Category::ModelFile
        | Category::Cancelled
        | Category::Internal => ExitClass::BadInput,
    }
}

/// A command line that parses but asks for something impossible (flags that exclude each
/// other in a way the parser cannot express): exit 2, like a parser error.
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

/// The class of a command's error: that of the first library or I/O error in its chain,
/// else bad input (the command's own checks are about what the user gave).
pub fn classify(error: &anyhow::Error) -> ExitClass {
    for cause in error.chain() {
        if cause.downcast_ref::<UsageError>().is_some() {
            return ExitClass::Usage;
        }
        if let Some(e) = cause.downcast_ref::<Error>() {
            return library_class(e);
        }
        if cause.downcast_ref::<std::io::Error>().is_some() {
            return ExitClass::Io;
        }
    }
    ExitClass::BadInput
}

/// The command-line flag of a library setting ([`Error::InvalidOption`]'s `option`), where
/// the CLI has one.
const FLAGS: [(&str, &str); 16] = [
    ("cutoff_hz", "--cutoff"),
    ("starts", "--starts"),
    ("start_factor", "--start-factor"),
    ("replicates", "--replicates"),
    ("example", "--example"),
    ("levels", "--grid"),
    ("lambda", "--lambda"),
    ("family", "--family"),
    ("families", "--families"),
    ("hysteresis", "--hysteresis"),
    ("model", "--model"),
    ("substeps", "--substeps"),
    ("noise", "--noise"),
    ("ts", "--ts"),
    ("y0", "--y0"),
    ("name", "--name"),
];

/// The flag a library error is about, when it is a setting the CLI has a flag for: the
/// library speaks of its settings, the CLI of its flags.
fn flag_of(e: &anyhow::Error) -> Option<&'static str> {
    e.chain()
        .find_map(|cause| match cause.downcast_ref::<Error>() {
            Some(Error::InvalidOption { option, .. }) => FLAGS
                .iter()
                .find(|(name, _)| name == option)
                .map(|(_, flag)| *flag),
            _ => None,
        })
}

/// The command line as parsed (after [`crate::deprecated::rewrite`]), for naming the flag
/// of a path in an error.
static ARGS: std::sync::OnceLock<Vec<std::ffi::OsString>> = std::sync::OnceLock::new();

/// Keeps the command line for [`one_line`]: an output clash names its paths by their flags.
pub fn remember_args(args: &[std::ffi::OsString]) {
    let _ = ARGS.set(args.to_vec());
}

/// The output options of every command, by role (the rest of a command's path options are
/// inputs).
const OUTPUT_FLAGS: [&str; 6] = [
    "--json",
    "--model-out",
    "--csv",
    "--plots",
    "--data-out",
    "--out",
];

/// The flags whose value is `path` on the command line (`--flag PATH` or `--flag=PATH`),
/// among the output flags or among the others; else the output flags whose value is a
/// directory `path` lies in (`demo`'s `--plots DIR` holds `DIR/actuator`).
fn flags_for(path: &std::path::Path, output: bool) -> Vec<String> {
    let Some(args) = ARGS.get() else {
        return Vec::new();
    };
    let mut pairs: Vec<(String, std::path::PathBuf)> = Vec::new();
    for (k, arg) in args.iter().enumerate() {
        let Some(text) = arg.to_str() else { continue };
        if !text.starts_with("--") {
            continue;
        }
        match text.split_once('=') {
            Some((flag, value)) => pairs.push((flag.to_string(), value.into())),
            None => {
                if let Some(value) = args.get(k + 1) {
                    pairs.push((text.to_string(), value.into()));
                }
            }
        }
    }
    let wanted = |flag: &str| OUTPUT_FLAGS.contains(&flag) == output;
    let exact: Vec<String> = pairs
        .iter()
        .filter(|(flag, value)| wanted(flag) && value == path)
        .map(|(flag, _)| flag.clone())
        .collect();
    if !exact.is_empty() || !output {
        return exact;
    }
    pairs
        .iter()
        .filter(|(flag, value)| {
            wanted(flag) && !value.as_os_str().is_empty() && path.starts_with(value)
        })
        .map(|(flag, _)| flag.clone())
        .collect()
}

/// The message of a library error, an output clash naming its paths by their flags.
fn library_text(cause: &(dyn std::error::Error + 'static)) -> String {
    match cause.downcast_ref::<Error>() {
        Some(Error::OutputClash(clash)) => {
            let other_is_output = clash.kind == hysid::error::ClashKind::Output;
            let output = flags_for(&clash.output, true);
            let other = flags_for(&clash.other, other_is_output);
            // Two outputs given the same path: name two different flags.
            let other_flag = other
                .iter()
                .find(|f| output.first() != Some(*f))
                .or(other.first());
            clash.describe(
                output.first().map(String::as_str),
                other_flag.map(String::as_str),
            )
        }
        _ => cause.to_string(),
    }
}

/// The error chain on one line, "context: cause", leaving out causes the message already
/// quotes (the library's errors include their source in their own text); a setting out of
/// range is prefixed by its flag, an output clash names the flags of both paths.
pub fn one_line(e: &anyhow::Error) -> String {
    let mut message = String::new();
    for cause in e.chain() {
        let text = library_text(cause);
        if !message.contains(&text) {
            if !message.is_empty() {
                message.push_str(": ");
            }
            message.push_str(&text);
        }
    }
    if let Some(flag) = flag_of(e) {
        message = format!("{flag}: {message}");
    }
    collapse(&message)
}

/// Folds a parser error (several lines: the error, a usage block, tips) to one line:
/// "what; tips; run 'hysid CMD --help' for the options".
/// `command` names the subcommand when the message has no usage line to name it.
pub fn usage_line(rendered: &str, command: &str) -> String {
    let mut what = Vec::new();
    let mut tips = Vec::new();
    let mut command = command.to_string();
    let mut in_error = true;
    for line in rendered.lines() {
        let trimmed = line.trim();
        if trimmed.is_empty() {
            in_error = false;
            continue;
        }
        if let Some(usage) = trimmed.strip_prefix("Usage:") {
            command = command_of(usage);
            in_error = false;
        } else if let Some(tip) = trimmed.strip_prefix("tip:") {
            tips.push(tip.trim().to_string());
        } else if trimmed.starts_with("For more information") {
            in_error = false;
        } else if in_error {
            what.push(trimmed.strip_prefix("error:").unwrap_or(trimmed).trim());
        }
    }
    let mut message = what.join(" ");
    if message.is_empty() {
        message = "the command line is not valid".into();
    }
    for tip in tips {
        message.push_str("; ");
        message.push_str(&tip);
    }
    collapse(&format!(
        "{message}; run '{command} --help' for the options"
    ))
}

/// The command a parser error is about ("hysid identify cascade"), from its usage line.
pub fn usage_command(rendered: &str) -> String {
    rendered
        .lines()
        .find_map(|line| line.trim().strip_prefix("Usage:"))
        .map(command_of)
        .unwrap_or_else(|| "hysid".into())
}

/// "hysid identify cascade" from a usage line "hysid identify cascade [OPTIONS] --data <F> …".
fn command_of(usage: &str) -> String {
    let words: Vec<&str> = usage
        .split_whitespace()
        .take_while(|w| {
            !w.starts_with('-')
                && !w.starts_with('[')
                && !w.starts_with('<')
                && w.chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        })
        .collect();
    if words.is_empty() {
        "hysid".into()
    } else {
        words.join(" ")
    }
}

/// The subcommand path named on the command line ("hysid identify cascade"): the leading
/// words of `args` (after the program) that are subcommands of `root`.
pub fn command_path(root: &clap::Command, args: &[String]) -> String {
    let mut path = vec![root.get_name().to_string()];
    let mut command = root;
    for arg in args {
        match command.find_subcommand(arg) {
            Some(sub) => {
                path.push(sub.get_name().to_string());
                command = sub;
            }
            None => break,
        }
    }
    path.join(" ")
}

/// Whitespace (newlines included) collapsed to single spaces.
fn collapse(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The first failed write of the human report to stdout other than a closed pipe.
static STDOUT_FAILURE: std::sync::OnceLock<String> = std::sync::OnceLock::new();

/// Takes the result of a write of the human report to stdout (`say!`): a closed pipe (the
/// reader has gone, as `head` does) is not a failure; any other error is kept, the first
/// one, for [`stdout_failure`].
pub fn on_stdout(result: std::io::Result<()>) {
    if let Err(e) = result {
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            let _ = STDOUT_FAILURE.set(e.to_string());
        }
    }
}

/// The failed write of [`on_stdout`], if any: the run then exits with 4 (I/O).
pub fn stdout_failure() -> Option<&'static str> {
    STDOUT_FAILURE.get().map(String::as_str)
}

/// Installs a panic hook that reports an internal fault on one line (where, what, and to
/// report it) instead of the runtime's multi-line message; the exit code stays 101.
pub fn one_line_panics() {
    std::panic::set_hook(Box::new(|info| {
        let what = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown fault".into());
        let place = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        // a closed stderr must not turn the report into a second panic (an abort)
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "error: internal fault{place}: {}; please report it with the command line that caused it",
            collapse(&what)
        );
    }));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exit_codes_follow_the_table() {
        let codes: Vec<u8> = [
            ExitClass::BadInput,
            ExitClass::Usage,
            ExitClass::Numerical,
            ExitClass::Io,
        ]
        .iter()
        .map(|c| c.code())
        .collect();
        assert_eq!(codes, [1, 2, 3, 4]);
    }

    #[test]
    fn library_errors_are_classified_by_meaning() {
        let io = Error::Io {
            path: "x.csv".into(),
            source: std::io::Error::other("disk full"),
        };
        assert_eq!(library_class(&io), ExitClass::Io);
        assert_eq!(
            library_class(&Error::Singular("rank 2 of 3".into())),
            ExitClass::Numerical
        );
        let diverged = Error::Diverged {
            index: 3,
            reason: "x1 is inf".into(),
        };
        assert_eq!(library_class(&diverged), ExitClass::Numerical);
        assert_eq!(
            library_class(&Error::InvalidData("empty".into())),
            ExitClass::BadInput
        );
        let wrapped = anyhow::Error::from(io).context("reading the data");
        assert_eq!(classify(&wrapped), ExitClass::Io);
        assert_eq!(classify(&anyhow::anyhow!("bad --fix")), ExitClass::BadInput);
        let nan = anyhow::Error::from(Error::NonFiniteResult {
            key: "fit".into(),
            value: f64::NAN,
        });
        assert_eq!(classify(&nan), ExitClass::Numerical);
    }

    #[test]
    fn parser_errors_fold_to_one_line() {
        let rendered = "error: invalid value 'abc' for '--delay <K>': invalid digit found in string\n\nUsage: hysid identify cascade [OPTIONS] --data <F>\n\nFor more information, try '--help'.\n";
        assert_eq!(
            usage_line(rendered, "hysid"),
            "invalid value 'abc' for '--delay <K>': invalid digit found in string; run 'hysid identify cascade --help' for the options"
        );
        let missing = "error: the following required arguments were not provided:\n  --data <F>\n  --input <COL>\n\nUsage: hysid simulate --model <FILE> --data <F>\n\nFor more information, try '--help'.\n";
        assert_eq!(
            usage_line(missing, "hysid"),
            "the following required arguments were not provided: --data <F> --input <COL>; run 'hysid simulate --help' for the options"
        );
        let no_usage = "error: invalid value 'x' for '--na <NA>': invalid digit found in string\n";
        assert_eq!(
            usage_line(no_usage, "hysid identify cascade"),
            "invalid value 'x' for '--na <NA>': invalid digit found in string; run 'hysid identify cascade --help' for the options"
        );
        let tip = "error: unexpected argument '--foo' found\n\n  tip: to pass '--foo' as a value, use '-- --foo'\n\nUsage: hysid generate voros [OPTIONS]\n";
        assert_eq!(
            usage_line(tip, "hysid"),
            "unexpected argument '--foo' found; to pass '--foo' as a value, use '-- --foo'; run 'hysid generate voros --help' for the options"
        );
    }
}
