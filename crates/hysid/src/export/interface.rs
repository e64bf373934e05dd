//! The outside of an export: its sample time, the names of its inputs, outputs and
//! parameters, its one-line description and the comment that opens every generated file.

use super::{ExportOptions, Interface};
use crate::model::saved::{ModelFile, SavedModel, OPERATOR_KIND};
use crate::{Error, Result};

/// The hysid version that generates the code.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Where the exported sample time came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SampleTime {
    /// The model file's `sample_time`.
    File(f64),
    /// `--ts` ([`ExportOptions::sample_time`]).
    Option(f64),
    /// None given, and none is meaningful: a rate-independent operator, exported with 0.
    RateIndependent,
    /// `--ts` other than the file's, for a continuous-time model: its integration re-stepped
    /// for the new rate ([`crate::model::saved::FittedModel::resampled`]).
    Resampled {
        /// The file's sample time (the data the model was fitted on).
        fitted: f64,
        /// The sample time given at export.
        given: f64,
    },
}

impl SampleTime {
    /// The step's period in seconds (0 for [`SampleTime::RateIndependent`]).
    pub fn seconds(self) -> f64 {
        match self {
            SampleTime::File(ts) | SampleTime::Option(ts) => ts,
            SampleTime::Resampled { given, .. } => given,
            SampleTime::RateIndependent => 0.0,
        }
    }

    /// The sample time of an export (the rule of `docs/export.md`): the file's, or
    /// `--ts` (another than the file's is [`SampleTime::Resampled`], which only a
    /// continuous-time model accepts, `export::model_at`), or 0 for a kind `operator`
    /// (rate-independent); any other kind without one is an error.
    pub fn of(file: &ModelFile, options: &ExportOptions) -> Result<Self> {
        if let Some(ts) = options.sample_time {
            if !(ts.is_finite() && ts > 0.0) {
                return Err(Error::invalid_option(
                    "ts",
                    ts,
                    "the sample time must be a positive finite number of seconds".into(),
                ));
            }
        }
        match (file.sample_time, options.sample_time) {
            (Some(fitted), Some(given)) if (fitted - given).abs() > 1e-9 * fitted.abs() => {
                Ok(SampleTime::Resampled { fitted, given })
            }
            (Some(stored), _) => Ok(SampleTime::File(stored)),
            (None, Some(given)) => Ok(SampleTime::Option(given)),
            (None, None) if file.kind() == OPERATOR_KIND => Ok(SampleTime::RateIndependent),
            (None, None) => Err(Error::invalid_option(
                "ts",
                "none",
                format!(
                    "the {} model file holds no sample_time (a file of an earlier version); \
                     give the sample time of the data it was fitted on",
                    file.kind()
                ),
            )),
        }
    }

    fn describe(self) -> String {
        match self {
            SampleTime::File(ts) => format!("{ts:?} s (the data the model was fitted on)"),
            SampleTime::Option(ts) => format!("{ts:?} s (given at export)"),
            SampleTime::Resampled { fitted, given } => format!(
                "{given:?} s (given at export; the model was fitted at {fitted:?} s, and its\n\
                 integration takes sub-steps no longer than the fitted model's)"
            ),
            SampleTime::RateIndependent => {
                "0 (a rate-independent operator: the step does not depend on time)".into()
            }
        }
    }
}

/// The model's kind, with the family for an operator (`operator pi`) or the operator of a
/// cascade.
pub fn model_name(file: &ModelFile) -> String {
    match &file.model {
        SavedModel::Operator(op) => format!("operator ({})", op.family),
        SavedModel::OperatorCascade(cascade) => {
            let family = cascade
                .operator
                .get("family")
                .and_then(|f| f.as_str())
                .unwrap_or("?");
            format!("operator_cascade ({family})")
        }
        SavedModel::ColemanHodgdon(ch) => {
            format!("{} ({})", file.kind(), ch.hysteresis.short_name())
        }
        SavedModel::ChCascade(ch) => format!("{} ({})", file.kind(), ch.hysteresis.short_name()),
        _ => file.kind().to_string(),
    }
}

/// Names `base` for `n` channels: `base` for one, `base1`, `base2`, … for several.
fn numbered(base: &str, n: usize) -> Vec<String> {
    if n == 1 {
        vec![base.to_string()]
    } else {
        (1..=n).map(|i| format!("{base}{i}")).collect()
    }
}

/// The interface of the export `name` of `file` with `n_inputs` and `n_outputs` (of the
/// model itself; a compensator swaps them).
pub fn interface(
    file: &ModelFile,
    name: &str,
    options: &ExportOptions,
    sample_time: SampleTime,
    (n_inputs, n_outputs): (usize, usize),
) -> Interface {
    let (inputs, outputs) = match &file.columns {
        Some(c) if c.inputs.len() == n_inputs && c.outputs.len() == n_outputs => {
            (c.inputs.clone(), c.outputs.clone())
        }
        _ => (numbered("u", n_inputs), numbered("y", n_outputs)),
    };
    let (inputs, outputs) = if options.inverse {
        let reference = match &file.columns {
            Some(_) => outputs.iter().map(|o| format!("{o}_reference")).collect(),
            None => numbered("r", n_outputs),
        };
        (reference, inputs)
    } else {
        (inputs, outputs)
    };
    let direction = if options.inverse {
        "compensator (reference in, command out)"
    } else {
        "forward model"
    };
    Interface {
        name: name.into(),
        n_inputs: inputs.len(),
        n_outputs: outputs.len(),
        sample_time: sample_time.seconds(),
        inputs,
        outputs,
        parameters: file
            .parameters()
            .iter()
            .map(|p| (p.name.clone(), p.value))
            .collect(),
        description: format!(
            "{}, {direction}, generated by hysid {VERSION}",
            model_name(file)
        ),
    }
}

/// The comment at the top of every generated file: what model, which version, the sample
/// time, the step semantics and the parameters of the fit (value ± standard deviation).
pub fn comment(
    file: &ModelFile,
    interface: &Interface,
    options: &ExportOptions,
    sample_time: SampleTime,
) -> String {
    let semantics = if options.inverse {
        "command `hysid compensate` reports at k for the reference"
    } else {
        "sample `hysid simulate` reports at k"
    };
    let (before, limits) = match (options.inverse, super::export_limits(file, options)) {
        (false, _) => (" (0 before any)".to_string(), String::new()),
        (true, Some(l)) => (
            format!(" (the limits' midpoint {:?} before any)", l.midpoint()),
            format!(
                "Command limits: [{:?}, {:?}] ({}); a command beyond them is set to the nearer\n\
                 limit and counted as clipped.\n",
                l.lo(),
                l.hi(),
                if options.limits.is_some() {
                    "given at export, --limits"
                } else {
                    "the input range of the data the model was fitted on"
                }
            ),
        ),
        (true, None) => (
            " (0 before any)".to_string(),
            "Command limits: none (the model file records no input range and none was given\n\
             at export): the command is not limited.\n"
                .to_string(),
        ),
    };
    let mut text = format!(
        "{}: {}.\n\nGenerated by hysid {VERSION} from a hysid.model/1 file; do not edit.\n\
         Model: {}.\nSample time: {}.\n\
         Inputs: {}. Outputs: {}.\n\
         Step semantics: a step with the input at sample k returns the output at sample k (the\n\
         {}), then advances the state to k + 1.\n\
         Bad samples: an input that is not finite (not a number, or infinite) leaves the\n\
         state unchanged and the step repeats the last good outputs{before}; the error flag\n\
         then says the last sample was bad and clears on the next good one, the faults count\n\
         keeps the total (docs/export.md, \"Limits and bad samples\").\n\
         {limits}\
         Diverged flag: set once a step cannot be computed (the differential families'\n\
         integration beyond its sub-step budget, a Preisach memory beyond its capacity, a\n\
         grey-box state that is not finite); the outputs then hold their last values until the\n\
         state is initialised again.\n\nParameters of the fit:\n",
        interface.name,
        interface.description,
        model_name(file),
        sample_time.describe(),
        interface.inputs.join(", "),
        interface.outputs.join(", "),
        semantics,
        before = before,
        limits = limits,
    );
    for p in file.parameters() {
        let std = p.std.map(|s| format!(" ± {s:?}")).unwrap_or_default();
        let fixed = if p.fixed { " (fixed)" } else { "" };
        text.push_str(&format!("  {} = {:?}{std}{fixed}\n", p.name, p.value));
    }
    text
}
