//! Kind `coleman_hodgdon`: the Coleman–Hodgdon hysteresis alone
//! ([`FittedModel::Hysteresis`]).

use super::{first, FittedKind, ModelKind, Records};
use crate::model::coleman_hodgdon::{simulate_switched, InitialOutput};
use crate::model::compensate::Compensation;
use crate::model::saved::{FittedModel, ParameterRecord, SavedModel};
use crate::model::stream::{self, compensate_stream, Compensator, Stepper};
use crate::model::{ChForm, ColemanHodgdon, Parameter};
use crate::{Error, Result};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The kind `coleman_hodgdon` in the registry ([`super::ModelKind`]).
pub struct ColemanHodgdonKind;

/// The keys of a `coleman_hodgdon` model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ColemanHodgdonFile {
    /// alpha, m1, c1, d (ch6: alpha, m1, m2, c1, c2, d).
    pub parameters: Vec<ParameterRecord>,
    /// `ch4` or `ch6`.
    pub hysteresis: ChForm,
    /// Where the output of the hysteresis starts (`measured` when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_output: Option<InitialOutput>,
}

impl ModelKind for ColemanHodgdonKind {
    type File = ColemanHodgdonFile;

    fn parameters(file: &ColemanHodgdonFile) -> &[ParameterRecord] {
        &file.parameters
    }

    fn fitted(file: &ColemanHodgdonFile) -> Result<FittedModel> {
        let records = Records {
            kind: "coleman_hodgdon",
            list: &file.parameters,
        };
        let (model, std) = hysteresis_from_records(file.hysteresis, &records)?;
        Ok(FittedModel::Hysteresis(FittedHysteresis {
            model,
            initial: file.initial_output.unwrap_or(InitialOutput::Measured),
            std,
        }))
    }
}

/// A fitted Coleman–Hodgdon hysteresis ([`FittedModel::Hysteresis`]).
#[derive(Clone, Debug, PartialEq)]
pub struct FittedHysteresis {
    /// The model.
    pub model: ColemanHodgdon,
    /// Where its output starts.
    pub initial: InitialOutput,
    /// Standard deviations in [`crate::model::ChForm::parameter_names`] order.
    pub std: Vec<f64>,
}

impl FittedHysteresis {
    /// The output the recursion starts from: 0, or the measured `y0`.
    fn start(&self, y0: Option<f64>) -> Result<f64> {
        match self.initial {
            InitialOutput::Measured => y0.ok_or_else(|| {
                Error::ModelMismatch(
                    "this hysteresis starts from the measured output; give the measured output"
                        .into(),
                )
            }),
            InitialOutput::Zero => Ok(0.0),
        }
    }
}

/// The recursion of [`crate::model::coleman_hodgdon`] from its start; the compensator is the
/// per-sample solve, and the batch compensation runs it one step at a time.
impl FittedKind for FittedHysteresis {
    /// A hysteresis in the input alone: the sequence of inputs sets the output.
    fn rate_independent(&self) -> bool {
        true
    }

    fn saved(&self) -> SavedModel {
        SavedModel::ColemanHodgdon(ColemanHodgdonFile {
            parameters: hysteresis_records(&self.model, &self.std),
            hysteresis: self.model.form(),
            initial_output: Some(self.initial),
        })
    }

    fn simulate(&self, inputs: &[&[f64]], _ts: f64, y0: Option<f64>) -> Result<Vec<Vec<f64>>> {
        let x = first(inputs)?;
        self.model.check_rate(x)?;
        Ok(vec![simulate_switched(
            &self.model,
            x,
            self.start(y0)?,
            None,
        )])
    }

    fn stepper(&self, _ts: f64, y0: Option<f64>) -> Result<Box<dyn Stepper>> {
        Ok(stream::hysteresis_stepper(&self.model, self.start(y0)?))
    }

    fn compensator(&self) -> Result<Box<dyn Compensator>> {
        Ok(stream::hysteresis_compensator(&self.model, self.initial))
    }

    fn compensate(&self, reference: &[f64]) -> Result<Compensation> {
        // The per-sample solve of `model::compensate`, one step of the stream at a time.
        let stream = compensate_stream(self.compensator()?.as_mut(), reference)?;
        Ok(Compensation {
            settled_from: 0,
            ..stream
        })
    }
}

/// The Coleman–Hodgdon hysteresis of form `form` from its records, and their standard
/// deviations in [`ChForm::parameter_names`] order.
pub(crate) fn hysteresis_from_records(
    form: ChForm,
    records: &Records,
) -> Result<(ColemanHodgdon, Vec<f64>)> {
    let mut values = Vec::new();
    let mut std = Vec::new();
    for name in form.parameter_names() {
        let e = records.get(name)?;
        values.push(e.value);
        std.push(e.std_or_nan());
    }
    Ok((ColemanHodgdon::from_params(form, &values)?, std))
}

/// The records of the hysteresis `model` with standard deviations `std`.
pub(crate) fn hysteresis_records(model: &ColemanHodgdon, std: &[f64]) -> Vec<ParameterRecord> {
    model
        .form()
        .parameter_names()
        .iter()
        .zip(model.params().iter().zip(std))
        .map(|(name, (v, s))| ParameterRecord::of(&Parameter::new(*name, *v), *s))
        .collect()
}
