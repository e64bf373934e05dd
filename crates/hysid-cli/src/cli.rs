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
    #[command(flatten)]
    pub run: RunArgs,
}

/// Options of every command: progress, time and work limits.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Print no progress on stderr (errors and warnings still go there).
    #[arg(long, short, global = true)]
    pub quiet: bool,
    /// Stop the long searches (multi-start, bootstrap, the global grid, grey-box fits) after
    /// this many seconds with the best result so far; the report's search.termination is then
    /// `time_limit` and a warning line is printed (exit 0). Range (0, 1e7].
    #[arg(long = "time-limit", global = true, value_parser = crate::options::seconds)]
    pub time_limit: Option<f64>,
    /// Run a request whose estimated work exceeds the budget of 1e10 model evaluations
    /// (sample-steps); without it such a request is refused before it starts.
    #[arg(long = "allow-long", global = true)]
    pub allow_long: bool,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a built-in example end to end: generate data, identify, report, plot.
    #[command(subcommand)]
    Demo(Demo),
    /// Identify a model from a CSV or MAT file.
    #[command(subcommand)]
    Identify(Identify),
    /// Simulate a saved model on the input of a CSV or MAT file (fit % and RMSE when the measured
    /// output is given).
    Simulate(SimulateArgs),
    /// Write a built-in example's data as CSV (for benchmarks and for trying `identify`).
    #[command(subcommand)]
    Generate(Generate),
    /// Nonlinear grey-box models (MATLAB's idnlgrey/nlgreyest/present).
    #[command(subcommand)]
    Greybox(Greybox),
    /// Public benchmarks.
    #[command(subcommand)]
    Benchmark(Benchmark),
    /// The linear actuator with hysteresis of Gunnar et al. (2006): virtual test rig and the
    /// three-step identification.
    #[command(subcommand)]
    Actuator(Actuator),
    /// Rigid bodies with friction: inverse-dynamics least squares.
    #[command(subcommand, name = "rigid-body")]
    RigidBody(RigidBody),
    /// Fit several hysteresis families to one record and rank them by validation fit %.
    Compare(crate::cli_zoo::CompareArgs),
    /// The input that makes a fitted hysteresis model follow a reference (feed-forward
    /// compensation by the model's inverse).
    Compensate(crate::cli_zoo::CompensateArgs),
    /// Write a saved model (or its compensator) as C99 code, a no_std Rust crate or an FMI 2.0
    /// Co-Simulation FMU. Exit codes: 0 written; 1 a model or request that cannot be
    /// exported (a kind without an exporter, --inverse on a model without an inverse, a
    /// non-minimum-phase cascade, a missing or contradicting sample time, a non-empty --out,
    /// no C compiler for the FMU's binary); 2 usage (an unknown target, --out that is or
    /// holds the model file); 4 I/O.
    Export(ExportArgs),
}

/// Actuator commands.
#[derive(Debug, Subcommand)]
pub enum Actuator {
    /// Simulate the paper's eight experiments on the virtual rig and write them as
    /// DIR/dataset1.csv … dataset8.csv (columns t_s, tau_Nm, theta_rad) and DIR/rig.json.
    Rig(RigArgs),
    /// The three steps on data sets 1–8 of a directory: tables I–III, figures 2 and 4.
    Identify(ActuatorIdentifyArgs),
}

/// Settings of the virtual rig.
#[derive(Debug, Args)]
pub struct RigSettings {
    /// Play width of an unmodelled backlash in the flexibility [rad] (0: none; the real
    /// actuator has one, e.g. 0.003). Range [0, 1e6].
    #[arg(long, default_value_t = 0.0, value_parser = crate::options::nonnegative)]
    pub backlash: f64,
    /// Measurement noise as a multiple of the documented levels (one 16-bit count:
    /// 2.77e-5 rad on the angle, 4.40e-5 N·m on the torque); 0 for none. Range [0, 1e6].
    #[arg(long, default_value_t = 1.0, value_parser = crate::options::nonnegative)]
    pub noise: f64,
    /// Seed of the noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// A true parameter, NAME=VALUE (repeatable; J, Fv, Fc, k1, k2, alpha, A; default
    /// Table I's m67).
    #[arg(long)]
    pub truth: Vec<String>,
}

/// The actuator's known constants.
#[derive(Debug, Args)]
pub struct ActuatorConstants {
    /// Gear ratio r of the screw [m/rad] (known; the paper's actuator: 1.867e-3). Range
    /// (0, 1e12].
    #[arg(long, default_value_t = 1.867e-3, value_parser = crate::options::positive)]
    pub gear_ratio: f64,
    /// Saddle mass m [kg] (known; the paper's actuator: 1.2). Range [0, 1e6].
    #[arg(long, default_value_t = 1.2, value_parser = crate::options::nonnegative)]
    pub saddle_mass: f64,
}

/// Options of `hysid actuator rig`.
#[derive(Debug, Args)]
pub struct RigArgs {
    /// Directory for the data sets (built beside it and swapped in when complete).
    #[arg(long = "data-out")]
    pub data_out: PathBuf,
    #[command(flatten)]
    pub constants: ActuatorConstants,
    #[command(flatten)]
    pub rig: RigSettings,
}

/// Settings of the three steps.
#[derive(Debug, Args)]
pub struct ThreeStepArgs {
    /// Remove the sample mean of every signal before filtering.
    #[arg(long)]
    pub remove_mean: bool,
    /// Cut-off of the zero-phase 4th-order Butterworth pre-filter [Hz] (the paper: 100).
    /// Range (0, 1e12], below the Nyquist frequency of the data.
    #[arg(long, default_value_t = 100.0, value_parser = crate::options::positive)]
    pub cutoff: f64,
    /// Step 2 leaves out samples within this fraction of a loop's peak-to-peak torsion from
    /// a reversal, where the motor sticks and the friction torque is unknown. Range [0, 0.5).
    #[arg(long, default_value_t = 0.05, value_parser = crate::options::margin)]
    pub reversal_margin: f64,
    /// Fit step 3 (and score Table II) on the unfiltered records; the paper pre-filters
    /// them, which biases a nonlinear model slightly (see the README).
    #[arg(long)]
    pub unfiltered_step3: bool,
    /// Maximum iterations of each step-3 fit (the paper: 30). Range 1..=10000.
    #[arg(long, default_value_t = 30, value_parser = crate::options::count::<1, 10_000>)]
    pub max_iterations: usize,
    /// Stop a step-3 fit when the expected relative improvement falls below this (the
    /// paper: 0.01 %). Range [1e-15, 1).
    #[arg(long, default_value_t = 1e-4, value_parser = crate::options::tolerance)]
    pub tolerance: f64,
}

/// Options of `hysid actuator identify`.
#[derive(Debug, Args)]
pub struct ActuatorIdentifyArgs {
    /// Directory holding dataset1.csv … dataset8.csv (columns t_s, tau_Nm, theta_rad); a
    /// rig.json beside them adds the true parameters to the tables.
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub constants: ActuatorConstants,
    #[command(flatten)]
    pub steps: ThreeStepArgs,
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the m67 model here (`hysid.model/1`, loadable by `hysid simulate --model`).
    #[arg(long = "model-out")]
    pub model_out: Option<PathBuf>,
    /// Directory for the tables (Markdown) and the plots (SVG).
    #[arg(long)]
    pub plots: Option<PathBuf>,
}

/// Rigid-body commands.
#[derive(Debug, Subcommand)]
pub enum RigidBody {
    /// Inverse-dynamics least squares of M q̈ + Fv q̇ + Fc sgn(q̇) [+ offset] = g·u (step 1 of
    /// Gunnar et al. 2006; the EMPS reference method).
    Ls(RigidBodyLsArgs),
}

/// Options of `hysid rigid-body ls`.
#[derive(Debug, Args)]
pub struct RigidBodyLsArgs {
    /// Estimation record: CSV with a time column t_s, t, time or time_s, or a MATLAB .mat
    /// file with such a time variable (columns are then variable names or name(:,k)).
    #[arg(long)]
    pub data: PathBuf,
    /// Column of the measured position.
    #[arg(long)]
    pub position: String,
    /// Column of the drive signal u (force = gain·u).
    #[arg(long)]
    pub input: String,
    /// Drive gain g [force per unit of u] (EMPS: 35.15065188 N/V). Range ±[1e-9, 1e9].
    #[arg(long, default_value_t = 1.0, value_parser = crate::options::gain, allow_negative_numbers = true)]
    pub gain: f64,
    /// Estimate a constant force offset.
    #[arg(long)]
    pub offset: bool,
    /// Validation record(s) with the same columns (repeatable): relative error of the
    /// estimate on each.
    #[arg(long)]
    pub validate: Vec<PathBuf>,
    /// Cut-off of the zero-phase Butterworth position filter [Hz]. Range (0, 1e12], below
    /// the Nyquist frequency of the data.
    #[arg(long, default_value_t = 100.0, value_parser = crate::options::positive)]
    pub cutoff: f64,
    /// Order of the Butterworth filter. Range 1..=12.
    #[arg(long, default_value_t = 4, value_parser = crate::options::count::<1, 12>)]
    pub order: usize,
    /// Decimation factor of the regression ("parallel decimation"; 1 for none). Range
    /// 1..=10000.
    #[arg(long, default_value_t = 10, value_parser = crate::options::count::<1, 10_000>)]
    pub decimate: usize,
    /// Samples dropped at each end (filter transients), at the original rate. Range
    /// 0..=100000000, fewer than half the record.
    #[arg(long, default_value_t = 50, value_parser = crate::options::count::<0, 100_000_000>)]
    pub border: usize,
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the estimate as a `rigid_body` model here (`hysid.model/1`).
    #[arg(long = "model-out")]
    pub model_out: Option<PathBuf>,
}

/// Grey-box commands.
#[derive(Debug, Subcommand)]
pub enum Greybox {
    /// Fit a built-in grey-box model by output error.
    Fit(GreyboxFitArgs),
}

/// Options of `hysid greybox fit`.
#[derive(Debug, Args)]
pub struct GreyboxFitArgs {
    /// The model: bouc-wen, rigid-body, actuator-fixed or actuator-free.
    #[arg(
        long,
        required_unless_present = "model_file",
        conflicts_with = "model_file"
    )]
    pub model: Option<String>,
    /// Or a model written as equations: a TOML equation file (see examples/equations/).
    #[arg(long = "model-file")]
    pub model_file: Option<PathBuf>,
    #[command(flatten)]
    pub evaluator: EvaluatorArgs,
    #[command(flatten)]
    pub data: DataArgs,
    /// Keep this parameter at its value (repeatable).
    #[arg(long)]
    pub fix: Vec<String>,
    /// Estimate this parameter although the model fixes it by default (e.g. nu, gain).
    #[arg(long)]
    pub free: Vec<String>,
    /// Initial value, NAME=VALUE (repeatable).
    #[arg(long)]
    pub init: Vec<String>,
    /// Bounds, NAME=LO:HI (repeatable; inf allowed).
    #[arg(long)]
    pub bounds: Vec<String>,
    /// Estimate the initial value of this state in every experiment (repeatable).
    #[arg(long = "estimate-x0")]
    pub estimate_x0: Vec<String>,
    #[command(flatten)]
    pub simulation: SimulationArgs,
    #[command(flatten)]
    pub search: SearchArgs,
    /// Print and report the ±20 % one-at-a-time sensitivity table (Gunnar et al. 2006).
    #[arg(long)]
    pub sensitivity: bool,
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the fitted model here (loadable by `hysid simulate`).
    #[arg(long = "model-out")]
    pub model_out: Option<PathBuf>,
    /// Directory for plots (SVG).
    #[arg(long)]
    pub plots: Option<PathBuf>,
}

/// How a grey-box model is simulated.
#[derive(Debug, Args)]
pub struct SimulationArgs {
    /// Integrator.
    #[arg(long, value_enum, default_value_t = IntegratorArg::Rk4)]
    pub integrator: IntegratorArg,
    /// Integration steps per sample. Range 1..=1000 (memory and work checked against the
    /// record's length).
    #[arg(long, default_value_t = 10, value_parser = crate::options::count::<1, 1000>)]
    pub substeps: usize,
    /// Input between samples.
    #[arg(long, value_enum, default_value_t = InterpolationArg::Zoh)]
    pub interpolation: InterpolationArg,
}

/// The evaluator of an equation model's tapes.
#[derive(Debug, Args)]
pub struct EvaluatorArgs {
    /// How an equation model's equations are evaluated: auto (native code from the C
    /// compiler, cached, else the tape interpreter), cc (native code only: exit 1 when no C
    /// compiler works) or tape (the interpreter). Default: $HYSID_EVALUATOR (auto, native,
    /// cc or tape), else auto. The report's details.evaluation says which ran.
    #[arg(long, value_enum)]
    pub evaluator: Option<EvaluatorArg>,
}

/// Evaluators of equation models.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum EvaluatorArg {
    /// Native code from the C compiler (or the cache), else the tape interpreter.
    Auto,
    /// Native code from the C compiler (or the cache) only.
    Cc,
    /// The tape interpreter.
    Tape,
}

/// Integrators.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum IntegratorArg {
    /// Fixed-step fourth-order Runge–Kutta (analytic sensitivities).
    Rk4,
    /// Newmark average acceleration (second-order mechanical models).
    Newmark,
}

/// Input interpolations.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum InterpolationArg {
    /// Zero-order hold.
    Zoh,
    /// Linear.
    Linear,
    /// Band-limited (periodic records).
    BandLimited,
}

/// Search settings.
#[derive(Debug, Args)]
pub struct SearchArgs {
    /// Number of starting points (drawn inside the bounds; the first is the given start).
    /// Range 1..=100000 (work checked against the record's length).
    #[arg(long, default_value_t = 1, value_parser = crate::options::count::<1, 100_000>)]
    pub starts: usize,
    /// Seed of the random starts.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Maximum iterations of the final fit, a hard cap (Gunnar et al. 2006 use 30). Range
    /// 1..=100000. Not given: 100, and a fit still improving at 100 goes on to at most 1000
    /// (docs/numerics.md §1).
    #[arg(long, value_parser = crate::options::count::<1, 100_000>)]
    pub max_iterations: Option<usize>,
    /// Stop when the expected relative improvement falls below this (Gunnar et al. 2006:
    /// 1e-4, i.e. 0.01 %) and the Gauss–Newton step is below 1e-7·√(X/1e-10) of every
    /// parameter (so a stop means a minimum; docs/numerics.md §1). Range [1e-15, 1).
    #[arg(long, default_value_t = 1e-10, value_parser = crate::options::tolerance)]
    pub tolerance: f64,
}

/// Benchmarks.
#[derive(Debug, Subcommand)]
pub enum Benchmark {
    /// The Bouc–Wen hysteretic benchmark (Noël & Schoukens 2016).
    BoucWen(BoucWenArgs),
}

/// Options of `hysid benchmark bouc-wen`.
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct BoucWenArgs {
    /// Make test signals by the official recipe instead.
    #[command(subcommand)]
    pub generate: Option<BoucWenGenerate>,
    /// Training record (columns t_s, u_N, y_m; CSV or MATLAB .mat).
    #[arg(long)]
    pub train: Option<PathBuf>,
    /// Test record(s), same columns, scored by e_RMS in simulation mode.
    #[arg(long)]
    pub test: Vec<PathBuf>,
    /// Score test records after repeating their input twice and keeping the second pass
    /// (steady state of a periodic test signal) instead of simulating from rest.
    #[arg(long)]
    pub steady_state: bool,
    /// Start from the benchmark's nominal parameters times this factor. Range [1e-6, 1e6].
    #[arg(long, default_value_t = 1.0, value_parser = crate::options::factor)]
    pub start_factor: f64,
    /// Initial value, NAME=VALUE (repeatable; overrides the nominal start).
    #[arg(long)]
    pub init: Vec<String>,
    #[command(flatten)]
    pub search: BenchmarkSearchArgs,
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the fitted model here (`hysid.model/1`, loadable by `hysid simulate --model`).
    #[arg(long = "model-out")]
    pub model_out: Option<PathBuf>,
    /// Directory for plots (SVG).
    #[arg(long)]
    pub plots: Option<PathBuf>,
}

/// Search settings of the benchmark fit.
#[derive(Debug, Args)]
pub struct BenchmarkSearchArgs {
    /// Number of starting points. Range 1..=100000 (work checked against the record's
    /// length).
    #[arg(long, default_value_t = 8, value_parser = crate::options::count::<1, 100_000>)]
    pub starts: usize,
    /// Seed of the random starts.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// RK4 steps per sample (750 Hz × 4 = 3 kHz; the training record's residual is its noise
    /// from 2 on). Range 1..=1000 (memory and work checked against the record's length).
    #[arg(long, default_value_t = 4, value_parser = crate::options::count::<1, 1000>)]
    pub substeps: usize,
}

/// Test-signal generation.
#[derive(Debug, Subcommand)]
pub enum BoucWenGenerate {
    /// Simulate a test signal by the official recipe and write t_s, u_N, y_m.
    Generate(BoucWenGenerateArgs),
}

/// Options of `hysid benchmark bouc-wen generate`.
#[derive(Debug, Args)]
pub struct BoucWenGenerateArgs {
    /// multisine (8192 samples per period, 5–150 Hz, RMS 50 N) or sweep (40 sin(2π(18t + t²/12))).
    #[arg(long, value_enum, default_value_t = SignalArg::Multisine)]
    pub signal: SignalArg,
    /// Multisine periods to simulate and write (from rest). Range 1..=10000 (memory
    /// checked).
    #[arg(long, default_value_t = 2, value_parser = crate::options::count::<1, 10_000>)]
    pub periods: usize,
    /// Sweep samples. Range 2..=100000000 (memory checked).
    #[arg(long, default_value_t = 153_000, value_parser = crate::options::count::<2, 100_000_000>)]
    pub samples: usize,
    /// Seed of the multisine phases.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// RMS of white Gaussian output noise to add (the training records use 8e-6 m). Range
    /// [0, 1e6].
    #[arg(long, default_value_t = 0.0, value_parser = crate::options::nonnegative)]
    pub noise: f64,
    /// The CSV file to write.
    #[arg(long)]
    pub csv: PathBuf,
}

/// Benchmark test signals.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SignalArg {
    /// Random-phase multisine.
    Multisine,
    /// Linear sine sweep.
    Sweep,
}

/// Data generators.
#[derive(Debug, Subcommand)]
pub enum Generate {
    /// The cascade examples of docs/models/coleman-hodgdon-cascade.md §13 (columns t, x, y).
    Voros(GenerateVorosArgs),
}

/// Options of `hysid generate voros`.
#[derive(Debug, Args)]
pub struct GenerateVorosArgs {
    /// Which example: 1 or 2.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub example: u8,
    /// Number of samples (the amplitude schedule repeats); default the example's own length.
    /// Range 2..=100000000 (memory checked).
    #[arg(long, value_parser = crate::options::count::<2, 100_000_000>)]
    pub samples: Option<usize>,
    /// Leave the output noise out.
    #[arg(long)]
    pub noise_free: bool,
    /// Seed of the input disturbance and the output noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// The CSV file to write.
    #[arg(long)]
    pub csv: PathBuf,
}

/// Built-in examples.
#[derive(Debug, Subcommand)]
pub enum Demo {
    /// Vörös (2015): Coleman–Hodgdon hysteresis followed by a linear block, the project's
    /// Example 1 or 2 (docs/models/coleman-hodgdon-cascade.md §13).
    Voros(VorosArgs),
    /// Gunnar et al. (2006): the virtual actuator rig and the three steps, with the paper's
    /// tables and figures.
    Actuator(DemoActuatorArgs),
}

/// Options of `hysid demo actuator`.
#[derive(Debug, Args)]
pub struct DemoActuatorArgs {
    #[command(flatten)]
    pub constants: ActuatorConstants,
    #[command(flatten)]
    pub rig: RigSettings,
    #[command(flatten)]
    pub steps: ThreeStepArgs,
    /// Directory for the data sets, tables and plots.
    #[arg(long, default_value = "hysid-out")]
    pub plots: PathBuf,
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
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
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Directory for the plots (SVG).
    #[arg(long, default_value = "hysid-out")]
    pub plots: PathBuf,
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// How the standard deviations are obtained.
    #[arg(long, value_enum, default_value_t = UncertaintyArg::Bootstrap)]
    pub uncertainty: UncertaintyArg,
    /// Bootstrap replicates (with --uncertainty bootstrap). Range 1..=100000 (work checked
    /// against the record's length).
    #[arg(long, default_value_t = 30, value_parser = crate::options::count::<1, 100_000>)]
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
    /// A hysteresis (Coleman–Hodgdon ch4/ch6 or any operator family) followed by a linear
    /// block (Vörös 2015).
    Cascade(CascadeArgs),
    /// Coleman–Hodgdon hysteresis alone, its input and output both measured.
    Hysteresis(HysteresisArgs),
    /// A hysteresis operator of one family (PI, Preisach, Jiles–Atherton, Bouc–Wen, …) from
    /// its measured input and output.
    Operator(crate::cli_zoo::OperatorArgs),
}

/// Where the data come from.
#[derive(Debug, Args)]
pub struct DataArgs {
    /// CSV file with a header row, or a MATLAB .mat file (-v7 or older; columns are then
    /// variable names, or name(:,k) for column k of a matrix).
    #[arg(long)]
    pub data: PathBuf,
    /// Input column (the hysteresis input x). Repeat --input/--output pairs to fit several
    /// experiments (e.g. loops measured separately) together. `greybox fit` takes the
    /// model's inputs and outputs per experiment: with k inputs and one output,
    /// `--input X1 … --input Xk --output Y` is one experiment (repeat the group for more).
    #[arg(long, required = true)]
    pub input: Vec<String>,
    /// Output column (one per --input; `greybox fit`: as many per experiment as the model
    /// has outputs).
    #[arg(long, required = true)]
    pub output: Vec<String>,
    /// Sample time [s]; otherwise from the time column, else 1. Range (0, 1e12].
    #[arg(long, value_parser = crate::options::positive)]
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
    /// Write the fitted model here (`hysid.model/1`, loadable by `hysid simulate --model`).
    #[arg(long = "model-out")]
    pub model_out: Option<PathBuf>,
    /// Directory for plots (SVG).
    #[arg(long)]
    pub plots: Option<PathBuf>,
}

/// Options of `hysid identify cascade`.
#[derive(Debug, Args)]
pub struct CascadeArgs {
    #[command(flatten)]
    pub data: DataArgs,
    /// Hysteresis: ch4 (saturated Coleman–Hodgdon, 4 parameters), ch6, or an operator family
    /// (the list is the registry's).
    #[arg(long, help = crate::cli_zoo::family_help("Hysteresis: ch4 (saturated Coleman–Hodgdon, 4 parameters), ch6, or an operator family"))]
    pub hysteresis: String,
    /// Operator families with a threshold grid: number of thresholds (play or slip elements)
    /// (10). Range 1..=200; refused for a family that has none, naming those that have.
    #[arg(long, value_parser = crate::options::count::<1, 200>)]
    pub thresholds: Option<usize>,
    /// Operator families on the Preisach plane: intervals of the grid (10). Range 1..=100;
    /// refused for a family that has none, naming those that have.
    #[arg(long, alias = "levels", value_parser = crate::options::count::<1, 100>)]
    pub grid: Option<usize>,
    /// Operator families: the turning sense of the operator's loop in the (u, y) plane, ccw
    /// (the output lags the input) or cw. Default: the family's start decides (detected for
    /// the differential families, counter-clockwise — clockwise for maxwell-slip — up to the
    /// trend for the starts linear in the weights). A value a start cannot take is refused.
    #[arg(long, value_enum)]
    pub orientation: Option<crate::cli_zoo::OrientationArg>,
    /// Order n of A(q⁻¹). Range 0..=50.
    #[arg(long, value_parser = crate::options::count::<0, 50>)]
    pub na: usize,
    /// Number m of B coefficients (b1 = 1 included). Range 1..=50.
    #[arg(long, value_parser = crate::options::count::<1, 50>)]
    pub nb: usize,
    /// Input delay k of the linear block. Range 1..=100000, shorter than the record.
    #[arg(long, value_parser = crate::options::count::<1, 100_000>)]
    pub delay: usize,
    /// How the standard deviations are obtained.
    #[arg(long, value_enum, default_value_t = UncertaintyArg::Asymptotic)]
    pub uncertainty: UncertaintyArg,
    /// Bootstrap replicates (with --uncertainty bootstrap). Range 1..=100000 (work checked
    /// against the record's length).
    #[arg(long, default_value_t = 30, value_parser = crate::options::count::<1, 100_000>)]
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

/// Options of `hysid export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    /// Model file written by `--model-out` (`hysid.model/1`), or a report (`--json`) whose
    /// model is exported.
    #[arg(long)]
    pub model: PathBuf,
    /// What to write: c (DIR/NAME.h and DIR/NAME.c, C99), rust (the no_std crate DIR/NAME/),
    /// fmu (DIR/NAME.fmu, FMI 2.0 Co-Simulation with its sources and a binary built by $CC,
    /// else cc).
    #[arg(long, value_enum)]
    pub target: TargetArg,
    /// Name of the exported model (the C prefix, the crate and the FMU): a C identifier of at
    /// most 64 characters, not a C or Rust keyword.
    #[arg(long)]
    pub name: String,
    /// Output directory: created if missing, refused if it holds any file; written beside
    /// and renamed into place when complete.
    #[arg(long)]
    pub out: PathBuf,
    /// Export the compensator (input: the reference; output: the command) instead of the
    /// model.
    #[arg(long)]
    pub inverse: bool,
    /// Sample time [s] of the exported step, required when the model file has none (files
    /// of earlier versions). Another than the file's re-steps a continuous-time grey-box or
    /// equation model (sub-steps no longer than the fitted model's; the header states the
    /// integration error's estimate); for any other model it must equal the file's.
    /// Range (0, 1e12].
    #[arg(long, value_parser = crate::options::positive)]
    pub ts: Option<f64>,
    /// With --target fmu: leave the binary out (a source-only FMU; no C compiler needed).
    #[arg(long = "no-binary")]
    pub no_binary: bool,
    /// The measured initial output y(0) a Coleman–Hodgdon hysteresis saved with
    /// "initial_output": "measured" starts from (required to export its forward step;
    /// `hysid simulate` takes it from the record). Any finite number.
    #[arg(long, allow_hyphen_values = true, value_parser = crate::options::finite)]
    pub y0: Option<f64>,
    /// With --inverse: limit the command to [LO, HI], written LO:HI (e.g. -10:150), stated in
    /// the generated header; a command beyond them is set to the nearer limit and counted as
    /// clipped. Default: the model file's input_range (the fitted data's input range); a file
    /// without one exports an unlimited compensator (with a warning).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::options::limits)]
    pub limits: Option<hysid::model::limits::Limits>,
    /// The code's floating-point type: double (the library's numbers to the bit) or single
    /// (float / f32, for single-precision FPUs such as the Cortex-M4F; within the bound its
    /// header states, measured at export and at most 1e-4 of the output's range, else
    /// refused). --target c or rust only.
    #[arg(long, value_enum, default_value_t = PrecisionArg::Double)]
    pub precision: PrecisionArg,
    /// With --precision single: measure the bound on this CSV record instead of the test
    /// sequence over the model file's input range (its --input columns for a model, its
    /// --output column as the references for a compensator).
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// With --data: an input column of the record (repeat for several inputs); for a
    /// model's export.
    #[arg(long)]
    pub input: Vec<String>,
    /// With --data and --inverse: the record's output column, fed to the compensator as
    /// its references.
    #[arg(long)]
    pub output: Option<String>,
    /// Add reference vectors and a program that checks the code against them (c: DIR/NAME_test.c
    /// with main and NAME_test_run; rust: DIR/NAME/tests/vectors.rs); not with --target fmu.
    #[arg(long = "test-vectors")]
    pub test_vectors: bool,
    /// With --test-vectors or --precision single: the input range LO:HI the test sequence
    /// covers (for the vectors and the single-precision bound; default: the model file's
    /// input_range; required when the file has none and no --data is given).
    #[arg(long = "test-range", allow_hyphen_values = true, value_parser = crate::options::limits)]
    pub test_range: Option<hysid::model::limits::Limits>,
}

/// The floating-point type of exported code.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PrecisionArg {
    /// double / f64.
    Double,
    /// float / f32.
    Single,
}

/// Export targets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TargetArg {
    /// C99: NAME.h and NAME.c.
    C,
    /// A no_std Rust library crate NAME/.
    Rust,
    /// An FMI 2.0 Co-Simulation FMU NAME.fmu.
    Fmu,
}

/// Options of `hysid simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Model file written by `hysid identify … --model` or `hysid greybox fit --model-out`.
    #[arg(long)]
    pub model: PathBuf,
    /// CSV file with a header row, or a MATLAB .mat file (-v7 or older; columns are then
    /// variable names, or name(:,k) for column k of a matrix). Repeat for several records:
    /// the fit is then over all of them, as a multi-record fit's report states it.
    #[arg(long, required = true)]
    pub data: Vec<PathBuf>,
    /// Input column (repeat for models with several inputs; the position for a rigid body
    /// fitted by `rigid-body ls`).
    #[arg(long, required = true)]
    pub input: Vec<String>,
    /// Measured output column, for fit % and RMSE (the drive signal for a rigid body fitted
    /// by `rigid-body ls`, which predicts it from the position).
    #[arg(long)]
    pub output: Option<String>,
    /// Sample time [s]; otherwise from the time column, else 1. Range (0, 1e12].
    #[arg(long, value_parser = crate::options::positive)]
    pub ts: Option<f64>,
    /// Time column (default: a column named t, time, t_s or time_s, if any).
    #[arg(long)]
    pub time: Option<String>,
    /// Write the input and the simulated output (and the measured one) as CSV here, as the
    /// model sees them (filtered or decimated where its fit was). Only with one --data.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    #[command(flatten)]
    pub evaluator: EvaluatorArgs,
    /// Run the first N rows of each record to set the model's state without scoring them
    /// (nor writing them to --csv). Range 0..=1e9, fewer than the record's rows.
    #[arg(long = "warm-up", default_value_t = 0, value_parser = crate::options::count::<0, 1_000_000_000>)]
    pub warm_up: usize,
    /// A record (same --input columns) run through the model first: each --data record is
    /// simulated from the state it leaves (a saved declared initial state is applied at the
    /// history's first input instead).
    #[arg(long)]
    pub history: Option<PathBuf>,
    /// Write the JSON report here.
    #[arg(long)]
    pub json: Option<PathBuf>,
}
