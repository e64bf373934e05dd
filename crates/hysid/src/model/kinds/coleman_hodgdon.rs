//! Kind `coleman_hodgdon`: the Coleman–Hodgdon hysteresis alone
//! ([`FittedModel::Hysteresis`]).

use super::{ModelKind, Records};
use crate::model::coleman_hodgdon::InitialOutput;
use crate::model::saved::{FittedModel, ParameterRecord, SavedModel};
use crate::model::{ChForm, ColemanHodgdon, Parameter};
use crate::Result;
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
        Ok(FittedModel::Hysteresis {
            model,
            initial: file.initial_output.unwrap_or(InitialOutput::Measured),
            std,
        })
    }
}

/// The saved form of [`FittedModel::Hysteresis`].
pub(crate) fn saved(model: &ColemanHodgdon, initial: InitialOutput, std: &[f64]) -> SavedModel {
    SavedModel::ColemanHodgdon(ColemanHodgdonFile {
        parameters: hysteresis_records(model, std),
        hysteresis: model.form(),
        initial_output: Some(initial),
    })
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
