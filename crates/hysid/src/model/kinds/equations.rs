//! Kind `equations`: a grey-box model written as an equation file (`hysid-equations`,
//! [`FittedModel::Equations`]). The file's text travels in the `equations` key, so a saved fit
//! is self-contained.

use super::grey_box::{simulate_outputs, streamed_differently};
use super::{records, FittedKind, ModelKind};
use crate::model::greybox::equation_model::EquationStateSpace;
use crate::model::greybox::native::Evaluator;
use crate::model::greybox::{Simulation, StateSpaceModel};
use crate::model::saved::{FittedModel, ParameterRecord, SavedModel, SimulationSpec};
use crate::model::stream::{self, Stepper};
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
        Ok(FittedModel::Equations(FittedEquations {
            equations: text.to_string(),
            parameters,
            std,
            simulation,
            initial_state,
            evaluator: Evaluator::Auto,
        }))
    }
}

/// A fitted equation model ([`FittedModel::Equations`]).
#[derive(Clone, Debug, PartialEq)]
pub struct FittedEquations {
    /// The equation file's text.
    pub equations: String,
    /// Its parameters (values, units, bounds, fixed flags) in the file's order.
    pub parameters: ParameterSet,
    /// Their standard deviations.
    pub std: Vec<f64>,
    /// How it is simulated.
    pub simulation: Simulation,
    /// Its initial state.
    pub initial_state: Vec<f64>,
    /// Which code runs its tapes when it is simulated (not saved: a setting of the run,
    /// [`FittedModel::with_evaluator`]; [`Evaluator::Auto`] when read from a file).
    pub evaluator: Evaluator,
}

impl FittedEquations {
    /// The text compiled, its tapes run by the chosen evaluator.
    fn model(&self) -> Result<EquationStateSpace> {
        Ok(EquationStateSpace::parse(&self.equations, "saved model")?
            .with_evaluator(self.evaluator))
    }
}

/// The equations integrated as a grey-box model ([`crate::model::greybox`]), in batch and
/// one interval at a time; not invertible.
impl FittedKind for FittedEquations {
    fn saved(&self) -> SavedModel {
        SavedModel::Equations(EquationsFile {
            parameters: records(&self.parameters, &self.std),
            simulation: Some(SimulationSpec::of(&self.simulation)),
            initial_state: Some(self.initial_state.clone()),
            equations: self.equations.clone(),
        })
    }

    fn simulate(&self, inputs: &[&[f64]], ts: f64, _y0: Option<f64>) -> Result<Vec<Vec<f64>>> {
        let theta = self.parameters.values();
        simulate_outputs(
            &self.model()?,
            &theta,
            &self.initial_state,
            inputs,
            ts,
            &self.simulation,
        )
    }

    fn stepper(&self, ts: f64, _y0: Option<f64>) -> Result<Box<dyn Stepper>> {
        let theta = self.parameters.values();
        stream::grey_box(
            Box::new(self.model()?),
            theta,
            &self.initial_state,
            &self.simulation,
            ts,
        )
    }

    fn streaming_differs(&self) -> Option<String> {
        streamed_differently(&self.simulation)
    }

    fn set_evaluator(&mut self, evaluator: Evaluator) {
        self.evaluator = evaluator;
    }

    fn resampled(&self, from: f64, to: f64) -> Option<FittedModel> {
        (!self.model().ok()?.discrete_time()).then(|| {
            FittedModel::Equations(Self {
                simulation: self.simulation.resampled(from, to),
                ..self.clone()
            })
        })
    }
}
