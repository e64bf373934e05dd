//! Command-line syntax (clap derive); the help text comes from these doc comments.

use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;

/// Identify dynamic systems with hysteresis from measured input/output data.
#[derive(Debug, Parser)]
#[command(name = "hysid", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a built-in example end to end: generate data, identify, report, plot.
    #[command(subcommand)]
    Demo(Demo),
    /// Identify a model from a CSV file.
    #[command(subcommand)]
    Identify(Identify),
    /// Simulate a saved model on the input of a CSV file (fit % and RMSE when the measured
    /// output is given).
    Simulate(SimulateArgs),
    /// Write a built-in example's data as CSV (for benchmarks and for trying `identify`).
    #[command(subcommand)]
    Generate(Generate),
}

/// Data generators.
#[derive(Debug, Subcommand)]
pub enum Generate {
    /// The cascade examples of MODELS.md §1.6 (columns t, x, y).
    Voros(GenerateVorosArgs),
}

/// Options of `hysid generate voros`.
#[derive(Debug, Args)]
pub struct GenerateVorosArgs {
    /// Which example: 1 or 2.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub example: u8,
    /// Number of samples (the amplitude schedule repeats); default the example's own length.
    #[arg(long)]
    pub samples: Option<usize>,
    /// Leave the output noise out.
    #[arg(long)]
    pub noise_free: bool,
    /// Seed of the input disturbance and the output noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The CSV file to write.
    #[arg(long)]
    pub out: PathBuf,
}

/// Built-in examples.
#[derive(Debug, Subcommand)]
pub enum Demo {
    /// Vörös (2015): Coleman–Hodgdon hysteresis followed by a linear block, the project's
    /// Example 1 or 2 (MODELS.md §1.6).
    Voros(VorosArgs),
}

/// Options of `hysid demo voros`.
#[derive(Debug, Args)]
pub struct VorosArgs {
    /// Which example: 1 (ch4 hysteresis, second-order block) or 2 (ch6, third order).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub example: u8,
    /// Leave the output noise out (SNR 50 otherwise).
    #[arg(long)]
    pub noise_free: bool,
    /// Seed of the input disturbance and the output noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Directory for the plots (SVG).
    #[arg(long, default_value = "hysid-out")]
    pub out: PathBuf,
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// How the standard deviations are obtained.
    #[arg(long, value_enum, default_value_t = UncertaintyArg::Bootstrap)]
    pub uncertainty: UncertaintyArg,
    /// Bootstrap replicates (with --uncertainty bootstrap).
    #[arg(long, default_value_t = 30)]
    pub replicates: usize,
}

/// How standard deviations are computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum UncertaintyArg {
    /// From the curvature of the criterion at the estimate (fast).
    Asymptotic,
    /// Parametric bootstrap with a full re-identification per replicate (slower; right when
    /// the criterion has nearly equal minima or parameters are weakly identifiable).
    Bootstrap,
}

/// Identification commands.
#[derive(Debug, Subcommand)]
pub enum Identify {
    /// Coleman–Hodgdon hysteresis followed by a linear block (Vörös 2015).
    Cascade(CascadeArgs),
    /// Coleman–Hodgdon hysteresis alone, its input and output both measured.
    Hysteresis(HysteresisArgs),
}

/// Where the data come from.
#[derive(Debug, Args)]
pub struct DataArgs {
    /// CSV file with a header row.
    #[arg(long)]
    pub data: PathBuf,
    /// Input column (the hysteresis input x). Repeat --input/--output pairs to fit several
    /// experiments (e.g. loops measured separately) together.
    #[arg(long, required = true)]
    pub input: Vec<String>,
    /// Output column (one per --input).
    #[arg(long, required = true)]
    pub output: Vec<String>,
    /// Sample time; otherwise from the time column, else 1.
    #[arg(long)]
    pub ts: Option<f64>,
    /// Time column (default: a column named t, time, t_s or time_s, if any).
    #[arg(long)]
    pub time: Option<String>,
}

/// Where the results go.
#[derive(Debug, Args)]
pub struct OutputArgs {
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the fitted model here (loadable by `hysid simulate`).
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Directory for plots (SVG).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Options of `hysid identify cascade`.
#[derive(Debug, Args)]
pub struct CascadeArgs {
    #[command(flatten)]
    pub data: DataArgs,
    /// Hysteresis form: ch4 (saturated, 4 parameters) or ch6.
    #[arg(long)]
    pub hysteresis: String,
    /// Order n of A(q⁻¹).
    #[arg(long)]
    pub na: usize,
    /// Number m of B coefficients (b1 = 1 included).
    #[arg(long)]
    pub nb: usize,
    /// Input delay k ≥ 1 of the linear block.
    #[arg(long)]
    pub delay: usize,
    /// How the standard deviations are obtained.
    #[arg(long, value_enum, default_value_t = UncertaintyArg::Asymptotic)]
    pub uncertainty: UncertaintyArg,
    /// Bootstrap replicates (with --uncertainty bootstrap).
    #[arg(long, default_value_t = 30)]
    pub replicates: usize,
    /// Seed of the bootstrap.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    #[command(flatten)]
    pub output: OutputArgs,
}

/// Options of `hysid identify hysteresis`.
#[derive(Debug, Args)]
pub struct HysteresisArgs {
    #[command(flatten)]
    pub data: DataArgs,
    /// Hysteresis form: ch4 (saturated, 4 parameters) or ch6.
    #[arg(long)]
    pub hysteresis: String,
    /// Where the simulated output starts: the measured first sample, or zero.
    #[arg(long, value_enum, default_value_t = InitialArg::Measured)]
    pub initial_output: InitialArg,
    #[command(flatten)]
    pub output: OutputArgs,
}

/// Initial output of a simulated hysteresis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum InitialArg {
    /// The measured output's first sample.
    Measured,
    /// Zero.
    Zero,
}

/// Options of `hysid simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Model file written by `hysid identify … --model`.
    #[arg(long)]
    pub model: PathBuf,
    /// CSV file with a header row.
    #[arg(long)]
    pub data: PathBuf,
    /// Input column.
    #[arg(long)]
    pub input: String,
    /// Measured output column, for fit % and RMSE.
    #[arg(long)]
    pub output: Option<String>,
    /// Write the input and the simulated output (and the measured one) as CSV here.
    #[arg(long = "out")]
    pub out_csv: Option<PathBuf>,
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
}
