//! Identification data: named channels, experiments and the [`IdData`] container.
//!
//! [`IdData`] plays the role of MATLAB's `iddata` (and of `merge(iddata, ...)`): a sample
//! time, a description of every input and output channel, and one or more experiments that
//! share those channels. Every constructor validates its arguments, so code that receives an
//! [`IdData`] can rely on a positive finite sample time, equal-length finite channels and
//! unique channel names.
//!
//! Reading and writing CSV files lives in [`csv_io`]; its functions are re-exported here.

use std::borrow::Cow;
use std::fmt;
use std::ops::Range;

use crate::error::{Error, Result};

pub mod actuator_records;
pub mod csv_io;
pub mod mat5;
pub mod mat_io;

pub use csv_io::{read_columns, write_csv, CsvSpec, TimeSteps};
pub use mat_io::is_mat;

/// Sample times of two data sets that differ by less than this relative amount are taken
/// as equal by [`IdData::merge`]: sample times derived from time columns may differ in
/// the last bits.
const TS_MERGE_RTOL: f64 = 1e-9;

/// Name given to the single experiment built by the convenience constructors.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub const DEFAULT_EXPERIMENT_NAME: &str = "exp1";

/// A named signal channel with a unit (`""` when unknown).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Channel {
    /// Channel name, unique within a data set.
    pub name: String,
    /// Physical unit, `""` when unknown.
    pub unit: String,
}

impl Channel {
    /// A channel with the given name and no unit.
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            unit: String::new(),
        }
    }

    /// The same channel with its unit set.
    pub fn with_unit(mut self, unit: impl Into<String>) -> Self {
        self.unit = unit.into();
        self
    }
}

impl fmt::Display for Channel {
    /// `name [unit]`, or just `name` when the unit is unknown.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.unit.is_empty() {
            f.write_str(&self.name)
        } else {
            write!(f, "{} [{}]", self.name, self.unit)
        }
    }
}

/// One experiment: equal-length sample vectors, one `Vec` per channel (column-major).
#[derive(Clone, Debug, PartialEq)]
pub struct Experiment {
    /// Experiment name (free text, e.g. the file it came from).
    pub name: String,
    inputs: Vec<Vec<f64>>,
    outputs: Vec<Vec<f64>>,
}

impl Experiment {
    /// An experiment from one sample vector per input and per output channel.
    ///
    /// Fails with [`Error::InvalidData`] if there is no channel at all, no sample, or the
    /// channels differ in length. Finiteness is checked by [`IdData::new`], which knows the
    /// channel names to report.
    pub fn new(
        name: impl Into<String>,
        inputs: Vec<Vec<f64>>,
        outputs: Vec<Vec<f64>>,
    ) -> Result<Self> {
        let name = name.into();
        check_lengths(&name, &inputs, &outputs)?;
        Ok(Self {
            name,
            inputs,
            outputs,
        })
    }

    /// The experiment's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of samples (the same in every channel).
    pub fn len(&self) -> usize {
        labelled(&self.inputs, &self.outputs)
            .next()
            .map_or(0, |(_, _, samples)| samples.len())
    }

    /// Always `false` for a validated experiment; provided for symmetry with [`len`](Self::len).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Samples of input channel `ch`.
    ///
    /// # Panics
    /// If `ch` is not a valid input index.
    pub fn input(&self, ch: usize) -> &[f64] {
        &self.inputs[ch]
    }

    /// Samples of output channel `ch`.
    ///
    /// # Panics
    /// If `ch` is not a valid output index.
    pub fn output(&self, ch: usize) -> &[f64] {
        &self.outputs[ch]
    }

    /// The samples in `range` of every channel; the caller has checked the range.
    fn slice(&self, range: Range<usize>) -> Self {
        let cut = |channels: &[Vec<f64>]| -> Vec<Vec<f64>> {
            channels.iter().map(|c| c[range.clone()].to_vec()).collect()
        };
        Self {
            name: self.name.clone(),
            inputs: cut(&self.inputs),
            outputs: cut(&self.outputs),
        }
    }
}

/// Identification data: sample time, channel descriptions and one or more experiments.
///
/// All experiments share the channels and the sample time; their lengths may differ.
#[derive(Clone, Debug, PartialEq)]
pub struct IdData {
    ts: f64,
    inputs: Vec<Channel>,
    outputs: Vec<Channel>,
    experiments: Vec<Experiment>,
}

impl IdData {
    /// Identification data from its parts, validated.
    ///
    /// Fails with [`Error::InvalidData`] unless `ts` is finite and positive, channel names
    /// are non-empty, free of control characters and unique (inputs and outputs together),
    /// there is at least one experiment, and every experiment has as many input and output
    /// channels as described. Fails with [`Error::NonFinite`] on the first NaN or infinite
    /// sample; its `channel` is the channel name, followed by ` (experiment i)` (zero-based)
    /// when there are several experiments, and its `index` is the zero-based sample index
    /// within that experiment. Fails with [`Error::InvalidData`] on a channel whose values
    /// cannot be squared and summed at double precision (see [`MAX_MAGNITUDE`] and
    /// [`MIN_MAGNITUDE`]): every estimator's loss, fit % and criteria are sums of squares.
    pub fn new(
        ts: f64,
        inputs: Vec<Channel>,
        outputs: Vec<Channel>,
        experiments: Vec<Experiment>,
    ) -> Result<Self> {
        check_ts(ts)?;
        check_channel_names(&inputs, &outputs)?;
        if experiments.is_empty() {
            return Err(invalid("a data set needs at least one experiment".into()));
        }
        for (i, experiment) in experiments.iter().enumerate() {
            check_channel_counts(experiment, &inputs, &outputs)?;
            let label = |name: &str| match experiments.len() {
                1 => name.to_owned(),
                _ => format!("{name} (experiment {i})"),
            };
            check_finite(&experiment.inputs, &inputs, label)?;
            check_finite(&experiment.outputs, &outputs, label)?;
            check_scale(&experiment.inputs, &inputs, label)?;
            check_scale(&experiment.outputs, &outputs, label)?;
        }
        Ok(Self {
            ts,
            inputs,
            outputs,
            experiments,
        })
    }

    /// Single-input single-output data of one experiment.
    ///
    /// ```
    /// use hysid::data::IdData;
    ///
    /// let data = IdData::siso(0.01, "u", vec![0.0, 1.0, 2.0], "y", vec![0.0, 0.5, 1.5])?;
    /// assert_eq!(data.ts(), 0.01);
    /// assert_eq!(data.n_samples(), 3);
    /// assert_eq!(data.output_by_name(0, "y")?, &[0.0, 0.5, 1.5]);
    ///
    /// // Validation: the channels must have the same length.
    /// assert!(IdData::siso(0.01, "u", vec![0.0, 1.0], "y", vec![0.0]).is_err());
    /// # Ok::<(), hysid::Error>(())
    /// ```
    pub fn siso(
        ts: f64,
        input_name: &str,
        input: Vec<f64>,
        output_name: &str,
        output: Vec<f64>,
    ) -> Result<Self> {
        let experiment = Experiment::new(DEFAULT_EXPERIMENT_NAME, vec![input], vec![output])?;
        Self::new(
            ts,
            vec![Channel::new(input_name)],
            vec![Channel::new(output_name)],
            vec![experiment],
        )
    }

    /// One input channel and no outputs, e.g. the excitation for a simulation.
    pub fn input_only(ts: f64, input_name: &str, input: Vec<f64>) -> Result<Self> {
        let experiment = Experiment::new(DEFAULT_EXPERIMENT_NAME, vec![input], Vec::new())?;
        Self::new(
            ts,
            vec![Channel::new(input_name)],
            Vec::new(),
            vec![experiment],
        )
    }

    /// Sample time.
    pub fn ts(&self) -> f64 {
        self.ts
    }

    /// Number of experiments (at least one).
    pub fn n_experiments(&self) -> usize {
        self.experiments.len()
    }

    /// All experiments.
    pub fn experiments(&self) -> &[Experiment] {
        &self.experiments
    }

    /// Experiment `i`.
    ///
    /// # Panics
    /// If `i` is not a valid experiment index.
    pub fn experiment(&self, i: usize) -> &Experiment {
        &self.experiments[i]
    }

    /// Descriptions of the input channels.
    pub fn input_channels(&self) -> &[Channel] {
        &self.inputs
    }

    /// Descriptions of the output channels.
    pub fn output_channels(&self) -> &[Channel] {
        &self.outputs
    }

    /// Total number of samples over all experiments.
    pub fn n_samples(&self) -> usize {
        self.experiments.iter().map(Experiment::len).sum()
    }

    /// Samples of input channel `ch` in experiment `exp`.
    ///
    /// # Panics
    /// If `exp` or `ch` is out of range.
    pub fn input(&self, exp: usize, ch: usize) -> &[f64] {
        self.experiments[exp].input(ch)
    }

    /// Samples of output channel `ch` in experiment `exp`.
    ///
    /// # Panics
    /// If `exp` or `ch` is out of range.
    pub fn output(&self, exp: usize, ch: usize) -> &[f64] {
        self.experiments[exp].output(ch)
    }

    /// Samples of the input channel called `name` in experiment `exp`.
    ///
    /// Fails with [`Error::InvalidData`] if there is no such input.
    ///
    /// # Panics
    /// If `exp` is out of range.
    pub fn input_by_name(&self, exp: usize, name: &str) -> Result<&[f64]> {
        let ch = find_channel(&self.inputs, "input", name)?;
        Ok(self.input(exp, ch))
    }

    /// Samples of the output channel called `name` in experiment `exp`.
    ///
    /// Fails with [`Error::InvalidData`] if there is no such output.
    ///
    /// # Panics
    /// If `exp` is out of range.
    pub fn output_by_name(&self, exp: usize, name: &str) -> Result<&[f64]> {
        let ch = find_channel(&self.outputs, "output", name)?;
        Ok(self.output(exp, ch))
    }

    /// The samples in `range` of every experiment.
    ///
    /// Fails with [`Error::InvalidData`] if the range is empty or reaches past the end of
    /// the shortest experiment.
    pub fn slice(&self, range: Range<usize>) -> Result<Self> {
        let shortest = self.shortest_experiment();
        if range.start >= range.end || range.end > shortest {
            return Err(invalid(format!(
                "sample range {}..{} must be non-empty and within 0..{shortest} \
                 (the shortest experiment has {shortest} samples)",
                range.start, range.end
            )));
        }
        Ok(self.map_experiments(|e| e.slice(range.clone())))
    }

    /// Splits every experiment at sample `at` into an estimation part (`..at`) and a
    /// validation part (`at..`).
    ///
    /// Fails with [`Error::InvalidData`] unless both parts are non-empty in every experiment.
    pub fn split(&self, at: usize) -> Result<(Self, Self)> {
        let shortest = self.shortest_experiment();
        if at == 0 || at >= shortest {
            return Err(invalid(format!(
                "split point {at} must leave samples on both sides: choose it in 1..{shortest} \
                 (the shortest experiment has {shortest} samples)"
            )));
        }
        let head = self.map_experiments(|e| e.slice(0..at));
        let tail = self.map_experiments(|e| e.slice(at..e.len()));
        Ok((head, tail))
    }

    /// The experiments at `indices`, in that order (MATLAB's `getexp`).
    ///
    /// Fails with [`Error::InvalidData`] on an empty selection or an index out of range.
    pub fn select(&self, indices: &[usize]) -> Result<Self> {
        if indices.is_empty() {
            return Err(invalid("select at least one experiment".to_string()));
        }
        let mut experiments = Vec::with_capacity(indices.len());
        for &i in indices {
            let e = self.experiments.get(i).ok_or_else(|| {
                invalid(format!(
                    "there is no experiment {i}: the data hold {}",
                    self.experiments.len()
                ))
            })?;
            experiments.push(e.clone());
        }
        Ok(Self {
            ts: self.ts,
            inputs: self.inputs.clone(),
            outputs: self.outputs.clone(),
            experiments,
        })
    }

    /// Appends the experiments of `other` to those of `self`.
    ///
    /// Fails with [`Error::InvalidData`] naming what differs if the two data sets do not
    /// have the same sample time (within a relative 1e-9) or the same input or output
    /// channels (names and units, in order). The result keeps `self`'s sample time.
    pub fn merge(mut self, other: Self) -> Result<Self> {
        if (self.ts - other.ts).abs() > TS_MERGE_RTOL * self.ts.max(other.ts) {
            return Err(invalid(format!(
                "cannot merge data sets with different sample times ({} and {})",
                self.ts, other.ts
            )));
        }
        check_same_channels("input", &self.inputs, &other.inputs)?;
        check_same_channels("output", &self.outputs, &other.outputs)?;
        self.experiments.extend(other.experiments);
        Ok(self)
    }

    fn shortest_experiment(&self) -> usize {
        self.experiments
            .iter()
            .map(Experiment::len)
            .min()
            .unwrap_or(0)
    }

    /// The same data set with every experiment transformed; `f` must keep the shape valid.
    fn map_experiments(&self, f: impl Fn(&Experiment) -> Experiment) -> Self {
        Self {
            ts: self.ts,
            inputs: self.inputs.clone(),
            outputs: self.outputs.clone(),
            experiments: self.experiments.iter().map(f).collect(),
        }
    }
}

/// Every channel of an experiment as `(kind, index within kind, samples)`, inputs first.
fn labelled<'a>(
    inputs: &'a [Vec<f64>],
    outputs: &'a [Vec<f64>],
) -> impl Iterator<Item = (&'static str, usize, &'a [f64])> {
    let tag = |kind| move |(i, c): (usize, &'a Vec<f64>)| (kind, i, c.as_slice());
    let inputs = inputs.iter().enumerate().map(tag("input"));
    let outputs = outputs.iter().enumerate().map(tag("output"));
    inputs.chain(outputs)
}

/// Checks that an experiment has at least one channel and one sample, and equal lengths.
fn check_lengths(name: &str, inputs: &[Vec<f64>], outputs: &[Vec<f64>]) -> Result<()> {
    let context = || format!("experiment '{}'", one_line(name));
    let mut channels = labelled(inputs, outputs);
    let Some((_, _, first)) = channels.next() else {
        return Err(invalid(format!("{} has no channels", context())));
    };
    if first.is_empty() {
        return Err(invalid(format!("{} has no samples", context())));
    }
    match channels.find(|(_, _, samples)| samples.len() != first.len()) {
        None => Ok(()),
        Some((kind, index, samples)) => Err(invalid(format!(
            "{}: {kind} {index} has {} samples but the first channel has {}; \
             all channels must have the same length",
            context(),
            samples.len(),
            first.len()
        ))),
    }
}

fn check_ts(ts: f64) -> Result<()> {
    if ts.is_finite() && ts > 0.0 {
        Ok(())
    } else {
        Err(invalid(format!(
            "sample time ts = {ts} must be finite and positive"
        )))
    }
}

fn check_channel_names(inputs: &[Channel], outputs: &[Channel]) -> Result<()> {
    let all: Vec<&str> = inputs
        .iter()
        .chain(outputs)
        .map(|c| c.name.as_str())
        .collect();
    for (i, name) in all.iter().enumerate() {
        if name.trim().is_empty() {
            return Err(invalid(format!(
                "channel {i} has an empty name; give every channel a name"
            )));
        }
        if name.chars().any(char::is_control) {
            return Err(invalid(format!(
                "channel name '{}' contains control characters",
                one_line(name)
            )));
        }
        if all[..i].contains(name) {
            return Err(invalid(format!(
                "channel name '{name}' is used twice; input and output names must be unique"
            )));
        }
    }
    Ok(())
}

fn check_channel_counts(
    experiment: &Experiment,
    inputs: &[Channel],
    outputs: &[Channel],
) -> Result<()> {
    let counts = [
        ("input", experiment.inputs.len(), inputs.len()),
        ("output", experiment.outputs.len(), outputs.len()),
    ];
    for (kind, found, described) in counts {
        if found != described {
            return Err(invalid(format!(
                "experiment '{}' has {found} {kind} channels but {described} are described",
                one_line(&experiment.name)
            )));
        }
    }
    Ok(())
}

/// The largest magnitude a sample may have: the sum of the squares of 10⁸ such samples is
/// still finite (1e150² · 1e8 = 1e308). A channel beyond it is refused by [`IdData::new`]
/// (rescale it, e.g. change its unit).
pub const MAX_MAGNITUDE: f64 = 1e150;

/// The smallest magnitude of a channel (its largest |sample|) that is not zero: below it the
/// squares of its values and of their differences underflow (1e-150² · ε ≈ 2e-316, near the
/// smallest double), so a loss would be zero whatever the fit. A channel whose samples are
/// all this small (and not all zero) is refused by [`IdData::new`].
pub const MIN_MAGNITUDE: f64 = 1e-150;

/// Refuses a channel that cannot be squared at double precision: a sample beyond
/// [`MAX_MAGNITUDE`], or every sample below [`MIN_MAGNITUDE`] without all being zero.
fn check_scale(
    samples: &[Vec<f64>],
    channels: &[Channel],
    label: impl Fn(&str) -> String,
) -> Result<()> {
    for (values, channel) in samples.iter().zip(channels) {
        let (index, largest) =
            values
                .iter()
                .map(|v| v.abs())
                .enumerate()
                .fold(
                    (0, 0.0_f64),
                    |best, (k, v)| if v > best.1 { (k, v) } else { best },
                );
        if largest > MAX_MAGNITUDE {
            return Err(invalid(format!(
                "channel '{}', sample {index}: |value| {largest:e} exceeds {MAX_MAGNITUDE:e}, where squares and sums of squares overflow double precision; rescale the channel (e.g. change its unit)",
                one_line(&label(&channel.name))
            )));
        }
        if largest > 0.0 && largest < MIN_MAGNITUDE {
            return Err(invalid(format!(
                "channel '{}': every value is below {MIN_MAGNITUDE:e} in magnitude (the largest is {largest:e}), where squares underflow double precision and every loss would be zero; rescale the channel (e.g. change its unit)",
                one_line(&label(&channel.name))
            )));
        }
    }
    Ok(())
}

/// Whether `values` vary at double precision: their spread (max − min) is at least
/// [`MIN_MAGNITUDE`] and more than a few rounding errors (8 ε) of their magnitude. A
/// measured output that does not vary leaves nothing to fit and fit % undefined; the
/// estimators refuse it through this one test.
pub fn varies(values: &[f64]) -> bool {
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let spread = hi - lo;
    let magnitude = lo.abs().max(hi.abs());
    spread.is_finite() && spread >= MIN_MAGNITUDE && spread > 8.0 * f64::EPSILON * magnitude
}

/// Reports the first non-finite sample; `label` turns a channel name into the reported one.
fn check_finite(
    samples: &[Vec<f64>],
    channels: &[Channel],
    label: impl Fn(&str) -> String,
) -> Result<()> {
    for (values, channel) in samples.iter().zip(channels) {
        if let Some((index, &value)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(Error::NonFinite {
                channel: label(&channel.name),
                index,
                value,
            });
        }
    }
    Ok(())
}

fn check_same_channels(kind: &str, ours: &[Channel], theirs: &[Channel]) -> Result<()> {
    if ours == theirs {
        return Ok(());
    }
    let list = |channels: &[Channel]| {
        let names: Vec<String> = channels.iter().map(Channel::to_string).collect();
        one_line(&names.join(", ")).into_owned()
    };
    Err(invalid(format!(
        "cannot merge data sets with different {kind} channels ({} and {})",
        list(ours),
        list(theirs)
    )))
}

fn find_channel(channels: &[Channel], kind: &str, name: &str) -> Result<usize> {
    channels.iter().position(|c| c.name == name).ok_or_else(|| {
        let names: Vec<&str> = channels.iter().map(|c| c.name.as_str()).collect();
        invalid(format!(
            "no {kind} channel named '{}'; the {kind}s are: {}",
            one_line(name),
            names.join(", ")
        ))
    })
}

fn invalid(message: String) -> Error {
    Error::InvalidData(message)
}

/// `text` with control characters (newlines in particular) escaped, so that error messages
/// built from names and cells found in files stay on one line.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn one_line(text: &str) -> Cow<'_, str> {
    if !text.chars().any(char::is_control) {
        return Cow::Borrowed(text);
    }
    let mut escaped = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if c.is_control() {
            escaped.extend(c.escape_default());
        } else {
            escaped.push(c);
        }
    }
    Cow::Owned(escaped)
}
