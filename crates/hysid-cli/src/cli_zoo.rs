//! Command-line syntax of the hysteresis model zoo: `identify operator`, `compare`,
//! `compensate` (clap derive; the help text comes from these doc comments).

use clap::Args;
use hysid::model::operators::Family;
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

/// The record: one input and one output column.
#[derive(Debug, Args)]
pub struct ZooDataArgs {
    /// CSV file with a header row, or a MATLAB .mat file (-v7 or older).
    #[arg(long)]
    pub data: PathBuf,
    /// Input column (the hysteresis input u, e.g. voltage or field H).
    #[arg(long)]
    pub input: String,
    /// Output column (the hysteresis output y, e.g. displacement or flux density B).
    #[arg(long)]
    pub output: String,
    /// Sample time; otherwise from the time column, else 1 (rate-independent families ignore it).
    #[arg(long)]
    pub ts: Option<f64>,
    /// Time column (default: a column named t, time, t_s or time_s, if any).
    #[arg(long)]
    pub time: Option<String>,
}

/// The families' settings.
#[derive(Debug, Args)]
pub struct FamilyArgs {
    /// PI / generalised-PI thresholds and Maxwell-slip elements: a count N in 1..=200
    /// (a uniform grid over the input range), or the thresholds themselves as a
    /// comma-separated list r1,r2,… (strictly increasing, > 0).
    #[arg(long, default_value = "10")]
    pub thresholds: String,
    /// Intervals N of the Preisach grid over the input range, 1..=100 (N(N+1)/2 cells).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub grid: u32,
    /// Smoothness penalty λ ≥ 0 of the Preisach weights (relative to the Gram matrix).
    #[arg(long, default_value_t = 1e-6)]
    pub lambda: f64,
    /// Dead zones on each side of the generalised PI, 0..=20.
    #[arg(long = "dead-zones", default_value_t = 4, value_parser = clap::value_parser!(u32).range(0..=20))]
    pub dead_zones: u32,
}

/// Options of `hysid identify operator`.
#[derive(Debug, Args)]
pub struct OperatorArgs {
    /// The family (the list is the registry's).
    #[arg(long, help = family_help("The family"))]
    pub family: String,
    #[command(flatten)]
    pub data: ZooDataArgs,
    #[command(flatten)]
    pub options: FamilyArgs,
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the fitted model here (`hysid.model/1`, loadable by `hysid simulate --model`
    /// and `hysid compensate --model`).
    #[arg(long = "model-out")]
    pub model_out: Option<PathBuf>,
    /// Directory for plots (SVG): the measured and simulated loops.
    #[arg(long)]
    pub plots: Option<PathBuf>,
}

/// Options of `hysid compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    #[command(flatten)]
    pub data: ZooDataArgs,
    /// Validation record with the same columns; without it the first 60 % of --data trains
    /// and the rest validates.
    #[arg(long)]
    pub validate: Option<PathBuf>,
    /// Families to compare, comma-separated, or all.
    #[arg(long, default_value = "all")]
    pub families: String,
    #[command(flatten)]
    pub options: FamilyArgs,
    /// Write the JSON report here (the rows in details.families, the best model in model).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the best family's model here (`hysid.model/1`).
    #[arg(long = "model-out")]
    pub model_out: Option<PathBuf>,
    /// Directory for plots (SVG): every family's validation loop over the measured one.
    #[arg(long)]
    pub plots: Option<PathBuf>,
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
    /// Sample time; otherwise from the time column, else 1.
    #[arg(long)]
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
}
