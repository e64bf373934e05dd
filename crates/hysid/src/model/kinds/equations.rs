//! Kind `equations`: a grey-box model written as an equation file (`hysid-equations`,
//! [`FittedModel::Equations`]). The file's text travels in the `equations` key, so a saved fit
//! is self-contained.

use super::{records, ModelKind};
use crate::model::greybox::equation_model::EquationStateSpace;
use crate::model::greybox::native::Evaluator;
use crate::model::greybox::{Simulation, StateSpaceModel};
use crate::model::saved::{FittedModel, ParameterRecord, SavedModel, SimulationSpec};
use crate::model::ParameterSet;
use crate::{Error, Result};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The kind `equations` in the registry ([`super::ModelKind`]).
pub struct EquationsKind;

/// The keys of an `equations` model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EquationsFile {
    /// The equation file's `[parameters]`, in its order.
    pub parameters: Vec<ParameterRecord>,
    /// How the model is simulated (the default RK4 when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub simulation: Option<SimulationSpec>,
    /// Its initial state (the text's `[initial]` when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_state: Option<Vec<f64>>,
    /// The equation file's text, so that the saved model is self-contained.
    pub equations: String,
}

impl ModelKind for EquationsKind {
    type File = EquationsFile;

    fn parameters(file: &EquationsFile) -> &[ParameterRecord] {
        &file.parameters
    }

    /// The embedded text compiled, its parameters taken from the file's records by name
    /// (every one must be there), the initial state from `initial_state` or else the text's
    /// `[initial]`.
    fn fitted(file: &EquationsFile) -> Result<FittedModel> {
        let text = &file.equations;
        let model = EquationStateSpace::parse(text, "the model's \"equations\"")?;
        let mut parameters = model.parameters();
        let mut std = Vec::with_capacity(parameters.len());
        for i in 0..parameters.len() {
            let name = parameters.get(i).name.clone();
            let record = file
                .parameters
                .iter()
                .find(|p| p.name == name)
                .ok_or_else(|| {
                    Error::InvalidModel(format!(
                        "parameter '{name}' of the equations is missing from \"parameters\""
                    ))
                })?;
            *parameters.get_mut(i) = record.parameter();
            std.push(record.std_or_nan());
        }
        parameters.validate()?;
        let n = model.states().len();
        let initial_state = file
            .initial_state
            .clone()
            .unwrap_or_else(|| model.initial_values());
        if initial_state.len() != n || initial_state.iter().any(|v| !v.is_finite()) {
            return Err(Error::InvalidModel(format!(
                "\"initial_state\" needs {n} finite values for the equations model '{}'",
                model.name()
            )));
        }
        let simulation = file
            .simulation
            .as_ref()
            .map_or(Ok(Simulation::default()), SimulationSpec::simulation)?;
        Ok(FittedModel::Equations {
            equations: text.to_string(),
            parameters,
            std,
            simulation,
            initial_state,
            evaluator: Evaluator::Auto,
        })
    }
}

/// The saved form of [`FittedModel::Equations`].
pub(crate) fn saved(
    equations: &str,
    parameters: &ParameterSet,
    std: &[f64],
    simulation: &Simulation,
    initial_state: &[f64],
) -> SavedModel {
    SavedModel::Equations(EquationsFile {
        parameters: records(parameters, std),
        simulation: Some(SimulationSpec::of(simulation)),
        initial_state: Some(initial_state.to_vec()),
        equations: equations.to_string(),
    })
}
