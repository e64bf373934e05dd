//! Kind `operator`: a hysteresis operator of one family of the registry
//! ([`FittedModel::Operator`]).

use super::{first, records, FittedKind, ModelKind, Records};
use crate::model::compensate::Compensation;
use crate::model::operators::{initial_state, InitialStateUsed, OperatorModel};
use crate::model::saved::{FittedModel, ParameterRecord, SavedModel};
use crate::model::stream::{Compensator, Stepper};
use crate::Result;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The kind of a saved hysteresis operator.
pub const OPERATOR_KIND: &str = "operator";

/// The kind `operator` in the registry ([`super::ModelKind`]).
pub struct OperatorKind;

/// The keys of an `operator` model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OperatorFile {
    /// The family's parameters, named as in the literature.
    pub parameters: Vec<ParameterRecord>,
    /// The family's name, one of the registry's operator families (`pi`, `preisach`,
    /// `kp`, …: `hysid::model::operators::Family`).
    pub family: String,
    /// The operator's full structure: thresholds, weights, grids, orientation and
    /// initial state, as the family defines them. Checked on reading.
    pub operator: serde_json::Value,
    /// The initial state the operator starts from (`demagnetised`, `descending`,
    /// `ascending`, `estimated`: `hysid::model::operators::InitialStateUsed`); a declared
    /// history is re-applied at every record's first input. Absent: the structure's own
    /// state, as before the field existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_state: Option<InitialStateUsed>,
    /// The input a declared history (`descending`, `ascending`) turns at: the fit's u_top or
    /// u_bot, re-used for every record so a stream and a batch simulation start from the same
    /// state ([`crate::model::operators::initial_state`]). Absent (files of earlier
    /// versions): placed from each record's own range.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub history_turn: Option<f64>,
}

impl ModelKind for OperatorKind {
    type File = OperatorFile;

    fn parameters(file: &OperatorFile) -> &[ParameterRecord] {
        &file.parameters
    }

    fn fitted(file: &OperatorFile) -> Result<FittedModel> {
        let records = Records {
            kind: OPERATOR_KIND,
            list: &file.parameters,
        };
        let model = OperatorModel::from_structure(&file.family, &file.operator)?;
        let names = model.as_operator().parameters();
        let mut std = Vec::with_capacity(names.len());
        for p in names.iter() {
            std.push(records.get(&p.name)?.std_or_nan());
        }
        if let Some(turn) = file.history_turn.filter(|t| !t.is_finite()) {
            return Err(crate::Error::InvalidModel(format!(
                "\"history_turn\" is {turn}; give a finite input or remove the key"
            )));
        }
        Ok(FittedModel::operator(model, std)
            .with_initial_state(file.initial_state, file.history_turn))
    }
}

/// A fitted hysteresis operator ([`FittedModel::Operator`]).
#[derive(Clone, Debug, PartialEq)]
pub struct FittedHysteresisOperator {
    /// The family's name (`pi`, `preisach`, …; equal to `model.family()`).
    pub family: &'static str,
    /// The operator.
    pub model: OperatorModel,
    /// Standard deviations in `model.as_operator().parameters()` order (NaN: none).
    pub std: Vec<f64>,
    /// The initial state it starts from (None: as its structure holds it).
    pub initial_state: Option<InitialStateUsed>,
    /// The input a declared history turns at (the fit's; None: from each record's range).
    pub history_turn: Option<f64>,
}

impl FittedHysteresisOperator {
    /// The declared history it starts after, with its saved turn (None: the structure's
    /// own state).
    pub fn history(&self) -> Option<initial_state::History> {
        initial_state::History::of(self.initial_state, self.history_turn)
    }
}

/// The family's own simulation from the declared initial state, its step and its inverse
/// (the registry's operators, [`crate::model::operators`]).
impl FittedKind for FittedHysteresisOperator {
    /// A hysteresis in the input alone: the sequence of inputs sets the output.
    fn rate_independent(&self) -> bool {
        true
    }

    fn saved(&self) -> SavedModel {
        let model = &self.model;
        SavedModel::Operator(OperatorFile {
            parameters: records(&model.as_operator().parameters(), &self.std),
            family: self.family.to_string(),
            // As for the operator cascade: a failure would only leave the structure null.
            operator: model.structure().unwrap_or_default(),
            initial_state: self.initial_state,
            history_turn: self.history_turn,
        })
    }

    fn simulate(&self, inputs: &[&[f64]], _ts: f64, _y0: Option<f64>) -> Result<Vec<Vec<f64>>> {
        let operator = self.model.as_operator();
        let y = initial_state::simulate_from(operator, self.history(), first(inputs)?)?;
        Ok(vec![y])
    }

    fn stepper(&self, _ts: f64, _y0: Option<f64>) -> Result<Box<dyn Stepper>> {
        self.model.stepper_from(self.history())
    }

    fn compensator(&self) -> Result<Box<dyn Compensator>> {
        self.model.compensator_from(self.history())
    }

    /// The inverse after the declared history ([`OperatorModel::invert_from`]).
    fn compensate(&self, reference: &[f64]) -> Result<Compensation> {
        let inv = self.model.invert_from(self.history(), reference)?;
        Ok(Compensation {
            reference: reference.to_vec(),
            u: inv.u,
            predicted: inv.predicted,
            clipped: inv.clipped,
            settled_from: 0,
        })
    }
}
