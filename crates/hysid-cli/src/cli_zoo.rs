//! Command-line syntax of the hysteresis model zoo: `identify operator`, `compare`,
//! `compensate` (clap derive; the help text comes from these doc comments). The record and
//! the outputs are the shared groups of [`crate::cli`] ([`DataArgs`], [`OutputArgs`]).

use crate::cli::{DataArgs, OutputArgs};
use clap::{Args, ValueEnum};
use hysid::identify::operators::EnvelopeChoice;
use hysid::model::operators::{Family, InitialState, LoopOrientation};
use std::path::PathBuf;

/// `lead`, then every family of the registry with its model and reference (the help text of
/// `--family` and `--hysteresis`).
pub fn family_help(lead: &str) -> String {
    let families: Vec<String> = Family::ALL
        .iter()
        .map(|f| format!("{} ({})", f.name(), f.title()))
        .collect();
    format!("{lead}: {}", families.join("; "))
}

/// The families' settings.
#[derive(Debug, Args)]
pub struct FamilyArgs {
    /// PI / generalised-PI thresholds and Maxwell-slip elements: a count N in 1..=200
    /// (a uniform grid over the input range), or the thresholds themselves as a
    /// comma-separated list r1,r2,… (strictly increasing, > 0). Default: the count (4, 6, 8,
    /// 10, 14, 20) and the placement (uniform, or geometric from the record's smallest
    /// reversal) chosen by the fit % on the last 30 % of the record (`details.model_size`).
    #[arg(long)]
    pub thresholds: Option<String>,
    /// Intervals N of the Preisach and KP grids over the input range, 1..=100 (N(N+1)/2
    /// cells). Default: chosen among 6, 8, 10, 14, 20, 30, 40 by the fit % on the last 30 %
    /// of the record, within a work bound (`details.model_size`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub grid: Option<u32>,
    /// Smoothness penalty λ of the Preisach weights (relative to the Gram matrix). Range
    /// [0, 1e6].
    #[arg(long, default_value_t = 1e-6, value_parser = crate::options::nonnegative)]
    pub lambda: f64,
    /// Dead zones on each side of the generalised PI, 0..=20. Default: chosen with the
    /// thresholds from the data (4, 8 or 12, scored on the last 30 % of the record as the
    /// thresholds are); 4 when --thresholds is given.
    #[arg(long = "dead-zones", value_parser = clap::value_parser!(u32).range(0..=20))]
    pub dead_zones: Option<u32>,
    /// The loop's turning sense in the (u, y) plane, u horizontal: ccw (counter-clockwise:
    /// the output lags the input, as a piezo stack or a magnet's B(H)) or cw. Default:
    /// detected from the area between the ascending and descending branches (an error
    /// naming this flag when the record cannot tell). The trend (y rising or falling with u)
    /// is always detected.
    #[arg(long, value_enum)]
    pub orientation: Option<OrientationArg>,
    /// The initial hysteresis state: demagnetised (the family's neutral state), descending
    /// (the record starts at the end of a descent from above its maximum, e.g. after
    /// standardisation), ascending (from below its minimum), or estimate (fitted from the
    /// data: the differential families score the three starts and refine x0, the others
    /// keep the start of least loss). ch4/ch6 start at the measured output instead. Saved
    /// in the model file and re-applied by `simulate`.
    #[arg(long = "initial-state", value_enum, default_value = "estimate")]
    pub initial_state: InitialStateArg,
    /// The PI's static envelope, a monotone cubic E(u) beside the plays for a static curve
    /// they cannot follow (a saturating magnet; docs/zoo.md): auto (each candidate size is
    /// tried without and with it on the last 30 % of the record; none when --thresholds is
    /// given), none, or cubic. Read by pi only.
    #[arg(long, value_enum, default_value = "auto")]
    pub envelope: EnvelopeArg,
}

/// The `--envelope` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum EnvelopeArg {
    /// Chosen with the thresholds on the held-out part.
    Auto,
    /// No envelope.
    None,
    /// A cubic envelope.
    Cubic,
}

impl From<EnvelopeArg> for EnvelopeChoice {
    fn from(e: EnvelopeArg) -> Self {
        match e {
            EnvelopeArg::Auto => EnvelopeChoice::Auto,
            EnvelopeArg::None => EnvelopeChoice::None,
            EnvelopeArg::Cubic => EnvelopeChoice::Cubic,
        }
    }
}

/// The `--initial-state` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum InitialStateArg {
    /// The family's neutral state.
    Demagnetised,
    /// After a descent from above the record's maximum.
    Descending,
    /// After an ascent from below the record's minimum.
    Ascending,
    /// Fitted from the data.
    Estimate,
}

impl From<InitialStateArg> for InitialState {
    fn from(s: InitialStateArg) -> Self {
        match s {
            InitialStateArg::Demagnetised => InitialState::Demagnetised,
            InitialStateArg::Descending => InitialState::Descending,
            InitialStateArg::Ascending => InitialState::Ascending,
            InitialStateArg::Estimate => InitialState::Estimate,
        }
    }
}

/// The `--orientation` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OrientationArg {
    /// Counter-clockwise: the ascending branch below the descending one.
    Ccw,
    /// Clockwise: the ascending branch above the descending one.
    Cw,
}

impl From<OrientationArg> for LoopOrientation {
    fn from(o: OrientationArg) -> Self {
        match o {
            OrientationArg::Ccw => LoopOrientation::CounterClockwise,
            OrientationArg::Cw => LoopOrientation::Clockwise,
        }
    }
}

/// Options of `hysid identify operator`.
#[derive(Debug, Args)]
pub struct OperatorArgs {
    /// The family (the list is the registry's).
    #[arg(long, help = family_help("The family"))]
    pub family: String,
    /// The record: one --input and one --output column.
    #[command(flatten)]
    pub data: DataArgs,
    #[command(flatten)]
    pub options: FamilyArgs,
    /// The report, the fitted model (loadable by `hysid simulate --model` and `hysid
    /// compensate --model`) and the plots (the measured and simulated loops).
    #[command(flatten)]
    pub output: OutputArgs,
}

/// Options of `hysid compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// The record: one --input and one --output column.
    #[command(flatten)]
    pub data: DataArgs,
    /// Validation record with the same columns; without it the first 60 % of --data trains
    /// and the rest validates.
    #[arg(long)]
    pub validate: Option<PathBuf>,
    /// Families to compare, comma-separated, or all.
    #[arg(long, default_value = "all")]
    pub families: String,
    #[command(flatten)]
    pub options: FamilyArgs,
    /// The report (the rows in details.families, the best model in model), the best
    /// family's model and the plots (every family's validation loop over the measured one).
    #[command(flatten)]
    pub output: OutputArgs,
}

/// Options of `hysid compensate`.
#[derive(Debug, Args)]
pub struct CompensateArgs {
    /// Model file of a hysteresis operator or a Coleman–Hodgdon hysteresis (`hysid identify
    /// operator --model-out`, `hysid identify hysteresis --model-out`, or a report).
    #[arg(long)]
    pub model: PathBuf,
    /// CSV file with a header row, or a MATLAB .mat file, holding the reference.
    #[arg(long)]
    pub data: PathBuf,
    /// Column of the reference r the output should follow.
    #[arg(long)]
    pub reference: String,
    /// Sample time [s]; otherwise from the time column, else 1. Range (0, 1e12].
    #[arg(long, value_parser = crate::options::positive)]
    pub ts: Option<f64>,
    /// Time column (default: a column named t, time, t_s or time_s, if any).
    #[arg(long)]
    pub time: Option<String>,
    /// Write the columns reference, u (the compensating input) and predicted (the model's
    /// output for u) here.
    #[arg(long)]
    pub csv: PathBuf,
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Directory for plots (SVG): reference, input and predicted output.
    #[arg(long)]
    pub plots: Option<PathBuf>,
    /// Limit the command to [LO, HI], written LO:HI (e.g. -10:150): a command beyond them is
    /// set to the nearer limit and counted as clipped. Default: the model file's input_range
    /// (the fitted data's input range); a file without one is not limited (with a warning).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::options::limits)]
    pub limits: Option<hysid::model::limits::Limits>,
}
