//! The library's one error type.
//!
//! Every message is a single line that says what is wrong, where (file, line, channel, sample,
//! parameter) and, where there is one, what to do about it. Numerical non-convergence of an
//! iterative estimator is *not* an error: it is reported in the estimator's report
//! (see [`crate::numerics::Termination`]).

use std::path::PathBuf;

/// Errors raised by hysid.
#[non_exhaustive]
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be opened, read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The operating-system error.
        source: std::io::Error,
    },

    /// A CSV file is malformed (ragged rows, no header, bad quoting).
    #[error("{}: line {line}: {message}", path.display())]
    Csv {
        /// The file concerned.
        path: PathBuf,
        /// One-based line number in the file.
        line: u64,
        /// What is wrong.
        message: String,
    },

    /// A column asked for by name does not exist.
    #[error("{}: no column named '{column}' (the header has: {available}); pick one of those", path.display())]
    MissingColumn {
        /// The file concerned.
        path: PathBuf,
        /// The column that was asked for.
        column: String,
        /// The header's column names, comma-separated.
        available: String,
    },

    /// A cell of a CSV file is not a number.
    #[error("{}: line {line}, column '{column}': '{text}' is not a number; fix or remove that row", path.display())]
    NotNumeric {
        /// The file concerned.
        path: PathBuf,
        /// One-based line number in the file.
        line: u64,
        /// Column name.
        column: String,
        /// The offending cell.
        text: String,
    },

    /// A sample is NaN or infinite.
    #[error("channel '{channel}', sample {index}: value {value} is not finite; remove or interpolate it")]
    NonFinite {
        /// Channel name.
        channel: String,
        /// Zero-based sample index.
        index: usize,
        /// The value found.
        value: f64,
    },

    /// Data that cannot be used as given (unequal lengths, bad sample time, empty file...).
    #[error("invalid data: {0}")]
    InvalidData(String),

    /// Fewer samples than the estimator needs for the number of parameters.
    #[error(
        "too few samples: {samples} usable samples for {parameters} parameters; \
         give at least {needed} samples"
    )]
    TooFewSamples {
        /// Usable samples.
        samples: usize,
        /// Parameters to estimate.
        parameters: usize,
        /// Minimum number of samples needed.
        needed: usize,
    },

    /// The input does not excite the system enough to identify the model.
    #[error("input '{channel}' does not excite the system: {reason}")]
    NotExciting {
        /// Input channel name.
        channel: String,
        /// Why it is not exciting and what to do.
        reason: String,
    },

    /// The turning sense of the measured loop cannot be told from the data (too few
    /// reversals, or a loop indistinguishable from noise;
    /// [`crate::model::operators::orientation`]): the user must give it.
    #[error(
        "the loop's orientation cannot be told from the data: {reason}; give it with \
         --orientation ccw|cw (Python: orientation=\"ccw\" or \"cw\")"
    )]
    UndeterminedOrientation {
        /// Why it cannot be told.
        reason: String,
    },

    /// The measured loop lies outside what the family can represent, whatever its
    /// parameters: its turning sense and its trend together (a Dahl loop turns clockwise
    /// where it rises, [`crate::model::operators::dahl`]).
    #[error("a {family} operator cannot represent this loop: {reason}")]
    OutsideFamily {
        /// The family.
        family: String,
        /// What the loop does, what the family's loops do, and what to fit instead.
        reason: String,
    },

    /// The discrete Coleman–Hodgdon recursion left its valid range: α·|Δx(t)| > 1.
    #[error(
        "input moves too fast at sample {index}: alpha*|dx| = {product:.4} > 1 \
         (alpha = {alpha}, dx = {dx}); sample faster or scale the input down"
    )]
    RateLimit {
        /// Zero-based sample index.
        index: usize,
        /// The hysteresis parameter α.
        alpha: f64,
        /// The input increment Δx(t).
        dx: f64,
        /// α·|Δx(t)|.
        product: f64,
    },

    /// A model parameter value is not acceptable.
    #[error("parameter {name} = {}: {reason}", number(.value))]
    InvalidParameter {
        /// Parameter name (literature symbol).
        name: String,
        /// The value given.
        value: f64,
        /// Why it is not acceptable.
        reason: String,
    },

    /// A setting of an estimator, a filter or a generator is out of range or unknown.
    /// `option` is the library's name of the setting (a field name such as `cutoff_hz`); the
    /// CLI maps it to its flag. The message is `reason`, which names the value.
    #[error("{reason}")]
    InvalidOption {
        /// The setting's name in the library (`cutoff_hz`, `substeps`, `starts`, …).
        option: String,
        /// The value given, as text.
        value: String,
        /// Why it is not acceptable, and the acceptable range.
        reason: String,
    },

    /// A model (a saved file, or one put together by a caller) is inconsistent: a missing
    /// structure key, a parameter set that does not fit its kind.
    #[error("invalid model: {0}")]
    InvalidModel(String),

    /// A model and what it is applied to do not match: the data's channel counts, the
    /// number of initial states or parameter values given.
    #[error("{0}")]
    ModelMismatch(String),

    /// A model and what it is applied to differ in a count: input or output channels,
    /// initial-state values.
    #[error("{model} has {expected} {what}; {given} given")]
    CountMismatch {
        /// The model ("the bouc_wen model", "an operator cascade").
        model: String,
        /// What is counted, plural ("input channels", "output channels", "initial-state
        /// values per experiment").
        what: &'static str,
        /// How many the model has.
        expected: usize,
        /// How many were given.
        given: usize,
    },

    /// Regressors of a least-squares problem are (nearly) linearly dependent, or one is zero
    /// over the whole record.
    #[error(
        "regressors {columns} are {problem}; the data do not excite the model enough or it \
         has too many parameters"
    )]
    DependentRegressors {
        /// The regressors involved, by name (`'b1', 'a2'`).
        columns: String,
        /// What is wrong with them ("(nearly) linearly dependent (condition number
        /// 1.2e13)", "zero or not finite over the whole record").
        problem: String,
        /// The condition number of the column-scaled problem (∞ for a zero column).
        condition_number: f64,
    },

    /// A parameter name that the model does not have.
    #[error("{0}")]
    UnknownParameter(String),

    /// An operation the model or method does not support (e.g. Newmark integration of a
    /// model that is not second-order mechanical).
    #[error("{0}")]
    Unsupported(String),

    /// A result or a model could not be turned into JSON (an internal failure, never of the
    /// data).
    #[error("serialisation: {0}")]
    Serialization(String),

    /// A model's output on the data is NaN or ±∞ (a numerical failure: the model is
    /// unstable or the data lie outside its range).
    #[error("{0}")]
    NonFiniteOutput(String),

    /// The caller asked a computation to stop (a replicate skipped, a search cancelled).
    #[error("cancelled: {0}")]
    Cancelled(String),

    /// An output file cannot be written as asked (it is an input, it appears twice, its
    /// directory is missing).
    #[error("{0}")]
    InvalidOutput(String),

    /// An output of a run is one of its inputs or another of its outputs — the same file
    /// after symbolic links, `..` and hard links — or a directory output holds one. Refused
    /// when the output is registered, before any work.
    #[error("{0}")]
    OutputClash(Clash),

    /// An operation is not defined for a model of this kind.
    #[error("model kind '{kind}' does not support {operation}")]
    UnsupportedKind {
        /// The model kind.
        kind: String,
        /// What was asked of it.
        operation: String,
    },

    /// A plot could not be laid out (an internal failure of the plot layout, never of the
    /// data).
    #[error("plot: {0}")]
    Plot(String),

    /// A least-squares problem is singular or numerically rank deficient.
    #[error("singular regression: {0}")]
    Singular(String),

    /// A simulation produced non-finite values (the model diverged).
    #[error("simulation diverged at sample {index}: {reason}")]
    Diverged {
        /// Zero-based sample index where a non-finite value first appeared.
        index: usize,
        /// What diverged.
        reason: String,
    },

    /// An equation-file model is invalid (see [`EquationFileError`]).
    #[error(transparent)]
    Equations(#[from] EquationFileError),

    /// A saved model or report could not be (de)serialised.
    #[error("model file {}: {message}", path.display())]
    ModelFile {
        /// The file concerned.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },

    /// A result to be written holds NaN or ±∞ (a numerical failure, not bad data).
    #[error(
        "the result holds {value} at '{key}', which cannot be written; the estimate diverged \
         (check the data's scaling, the start values and the bounds)"
    )]
    NonFiniteResult {
        /// Key path of the first non-finite number (`model.parameters.alpha.value`).
        key: String,
        /// The number found.
        value: f64,
    },

    /// A model of this kind cannot be inverted (no compensator can be computed from it).
    #[error("not invertible: model kind '{kind}': {reason}")]
    NotInvertible {
        /// The model kind (`ch_cascade`, `bouc_wen`, …).
        kind: String,
        /// Why, and what to use instead.
        reason: String,
    },
}

/// An equation-file model (`hysid-equations`) is invalid: parse, name or bound error at
/// a line and column of the file.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{origin}: line {line}, column {column}: {message}")]
pub struct EquationFileError {
    /// Where the text came from: the file's path, or the saved model that embeds it.
    pub origin: String,
    /// 1-based line in the text.
    pub line: usize,
    /// 1-based column (in characters).
    pub column: usize,
    /// What is wrong and what to do (one line).
    pub message: String,
}

/// A number for a message: as Rust writes it, but in exponent form when that would be a
/// long row of digits (1e308, 1e-300).
pub(crate) fn number(value: &f64) -> String {
    let v = value.abs();
    if v != 0.0 && v.is_finite() && !(1e-6..1e16).contains(&v) {
        format!("{value:e}")
    } else {
        value.to_string()
    }
}

/// What an output path clashes with (see [`Error::OutputClash`]).
#[non_exhaustive]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClashKind {
    /// The output is a file the run reads.
    Input,
    /// The output is a directory that holds a file (or directory) the run reads.
    HoldsInput,
    /// The output is another output of the run, or one is inside the other.
    Output,
}

/// An output path that would replace an input or another output of the same run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Clash {
    /// The output, as given.
    pub output: PathBuf,
    /// The input or output it clashes with, as given: for a file read from inside a
    /// directory, the directory.
    pub other: PathBuf,
    /// The file concerned, as found: the input file read, or the other output.
    pub file: PathBuf,
    /// What the clash is.
    pub kind: ClashKind,
}

impl Clash {
    /// The one-line message, naming the output and the other path by their command-line
    /// flags where a front end gives them (`--json report.json`), else as "output …".
    pub fn describe(&self, output_flag: Option<&str>, other_flag: Option<&str>) -> String {
        let named = |flag: Option<&str>, path: &std::path::Path, what: &str| match flag {
            Some(f) => format!("{f} {}", path.display()),
            None => format!("{what}{}", path.display()),
        };
        let out = named(output_flag, &self.output, "output ");
        let file = self.file.display();
        match self.kind {
            ClashKind::Input => {
                let other = named(other_flag, &self.other, "");
                let same = if self.file == self.other {
                    format!("the same file as {other}")
                } else {
                    format!("the same file as {file}, read from {other}")
                };
                format!(
                    "{out} is also an input of this run ({same}); writing it would destroy the \
                     input: choose another output path"
                )
            }
            ClashKind::HoldsInput => {
                let other = named(other_flag, &self.other, "");
                let held = if self.file == self.other {
                    other
                } else {
                    format!("{file}, read from {other}")
                };
                format!(
                    "{out} holds the input {held}, which replacing the directory would delete; \
                     choose another directory"
                )
            }
            ClashKind::Output => {
                let other = named(other_flag, &self.other, "");
                format!(
                    "{out} clashes with the output {other} of the same run (the same file, or one \
                     inside the other); give each output its own path"
                )
            }
        }
    }
}

impl std::fmt::Display for Clash {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.describe(None, None))
    }
}

/// What kind of failure an [`Error`] is: the one classification from which the command
/// line's exit codes and the Python exception classes are derived.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Category {
    /// Input data that cannot be used: unreadable CSV content, a missing column, non-finite
    /// or too few samples, an input that does not excite the model.
    Data,
    /// A setting or a model that is out of range, unknown or inconsistent with what it is
    /// applied to (an option, a parameter, a model's structure, an operation the model does
    /// not support).
    Config,
    /// A saved model or an output file that cannot be read or written as asked.
    ModelFile,
    /// The file system: a file could not be opened, read or written.
    Io,
    /// A numerical failure: a singular regression, a diverged simulation, a non-finite
    /// result.
    Numerical,
    /// The request contradicts itself: an output that would replace an input or another
    /// output of the same run.
    Usage,
    /// The caller stopped the computation.
    Cancelled,
    /// A failure of hysid itself (serialisation or plot layout), never of the data: a bug.
    Internal,
}

impl Error {
    /// The error's [`Category`] (exhaustive: a new variant must be classified here).
    pub fn category(&self) -> Category {
        match self {
            Error::Csv { .. }
            | Error::MissingColumn { .. }
            | Error::NotNumeric { .. }
            | Error::NonFinite { .. }
            | Error::InvalidData(_)
            | Error::TooFewSamples { .. }
            | Error::NotExciting { .. }
            | Error::UndeterminedOrientation { .. }
            | Error::OutsideFamily { .. }
            | Error::RateLimit { .. } => Category::Data,
            Error::InvalidParameter { .. }
            | Error::InvalidOption { .. }
            | Error::InvalidModel(_)
            | Error::ModelMismatch(_)
            | Error::CountMismatch { .. }
            | Error::UnknownParameter(_)
            | Error::Unsupported(_)
            | Error::UnsupportedKind { .. }
            | Error::Equations(_)
            | Error::NotInvertible { .. } => Category::Config,
            Error::ModelFile { .. } | Error::InvalidOutput(_) => Category::ModelFile,
            Error::OutputClash(_) => Category::Usage,
            Error::Io { .. } => Category::Io,
            Error::Singular(_)
            | Error::DependentRegressors { .. }
            | Error::Diverged { .. }
            | Error::NonFiniteOutput(_)
            | Error::NonFiniteResult { .. } => Category::Numerical,
            Error::Cancelled(_) => Category::Cancelled,
            Error::Serialization(_) | Error::Plot(_) => Category::Internal,
        }
    }

    /// [`Error::InvalidOption`] of the setting `option` with value `value`.
    pub fn invalid_option(option: &str, value: impl std::fmt::Display, reason: String) -> Self {
        Error::InvalidOption {
            option: option.into(),
            value: value.to_string(),
            reason,
        }
    }
}

/// Shorthand for results in this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
