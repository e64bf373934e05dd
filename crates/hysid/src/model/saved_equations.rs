//! Saved equation-file models (kind `equations` of `hysid.model/1`): the file's text travels
//! in the `equations` key, so a saved fit is self-contained.

use crate::model::greybox::equation_model::EquationStateSpace;
use crate::model::greybox::simulate::{simulate, InputTrack};
use crate::model::greybox::{Simulation, StateSpaceModel};
use crate::model::saved::{FittedModel, ParameterRecord, SimulationSpec};
use crate::{Error, Result};

/// The fitted equation model of a model file: the embedded text `text` compiled, its
/// parameters taken from the file's records by name (every one must be there), the initial
/// state from `initial_state` or else the text's `[initial]`.
pub(crate) fn equations_from_file(
    text: &str,
    records: &[ParameterRecord],
    simulation: Option<&SimulationSpec>,
    initial_state: Option<&[f64]>,
) -> Result<FittedModel> {
    let model = EquationStateSpace::parse(text, "the model's \"equations\"")?;
    let mut parameters = model.parameters();
    let mut std = Vec::with_capacity(parameters.len());
    for i in 0..parameters.len() {
        let name = parameters.get(i).name.clone();
        let record = records.iter().find(|p| p.name == name).ok_or_else(|| {
            Error::InvalidModel(format!(
                "parameter '{name}' of the equations is missing from \"parameters\""
            ))
        })?;
        *parameters.get_mut(i) = record.parameter();
        std.push(record.std_or_nan());
    }
    parameters.validate()?;
    let n = model.states().len();
    let initial_state = initial_state.map_or_else(|| model.initial_values(), <[f64]>::to_vec);
    if initial_state.len() != n || initial_state.iter().any(|v| !v.is_finite()) {
        return Err(Error::InvalidModel(format!(
            "\"initial_state\" needs {n} finite values for the equations model '{}'",
            model.name()
        )));
    }
    let simulation = simulation.map_or(Ok(Simulation::default()), SimulationSpec::simulation)?;
    Ok(FittedModel::Equations {
        equations: text.to_string(),
        parameters,
        std,
        simulation,
        initial_state,
        evaluator: crate::model::greybox::native::Evaluator::Auto,
    })
}

/// The outputs of `model` simulated from `x0` with parameters `theta` for the input
/// channels `inputs` sampled every `ts`.
pub(crate) fn simulate_outputs(
    model: &dyn StateSpaceModel,
    theta: &[f64],
    x0: &[f64],
    inputs: &[&[f64]],
    ts: f64,
    simulation: &Simulation,
) -> Result<Vec<Vec<f64>>> {
    if inputs.len() != model.inputs().len() {
        return Err(Error::CountMismatch {
            model: format!("the {} model", model.kind()),
            what: "input channels",
            expected: model.inputs().len(),
            given: inputs.len(),
        });
    }
    let track = InputTrack::new(inputs, simulation)?;
    let n_outputs = model.outputs().len();
    let mut outputs = vec![Vec::with_capacity(track.len()); n_outputs];
    let (mut u, mut y) = (vec![0.0; inputs.len()], vec![0.0; n_outputs]);
    simulate(
        model,
        theta,
        x0,
        &track,
        ts,
        simulation.integrator,
        |k, x| {
            track.at(k, 0.0, &mut u);
            model.output(x, &u, theta, &mut y);
            for (o, v) in outputs.iter_mut().zip(&y) {
                o.push(*v);
            }
        },
    )?;
    Ok(outputs)
}
