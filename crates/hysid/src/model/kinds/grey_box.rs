//! Kinds `bouc_wen`, `rigid_body`, `actuator_fixed`, `actuator_free`: the built-in grey-box
//! models ([`GreyBoxKind`], [`FittedModel::GreyBox`]), one file form for the four, and the
//! user's own grey-box model, written under its own kind ([`SavedModel::UserGreyBox`]).

use super::{records, FittedKind, ModelKind, Records};
use crate::model::greybox::models::{self, GreyBoxKind};
use crate::model::greybox::simulate::{simulate, InputTrack};
use crate::model::greybox::InputInterpolation;
use crate::model::greybox::{Simulation, StateSpaceModel};
use crate::model::saved::{FittedModel, ParameterRecord, SavedModel, SimulationSpec};
use crate::model::stream::{self, Stepper};
use crate::model::ParameterSet;
use crate::{Error, Result};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The structure of a built-in grey-box model in a model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GreyBoxFile {
    /// The built-in model's parameters (matched by name).
    pub parameters: Vec<ParameterRecord>,
    /// How the model is simulated (the default RK4 when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub simulation: Option<SimulationSpec>,
    /// Its initial state (zeros when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_state: Option<Vec<f64>>,
}

/// Declares the registry's kind of a built-in grey-box model.
macro_rules! grey_box_kind {
    ($(#[$doc:meta])* $name:ident => $kind:ident) => {
        $(#[$doc])*
        pub struct $name;

        impl ModelKind for $name {
            type File = GreyBoxFile;

            fn parameters(file: &GreyBoxFile) -> &[ParameterRecord] {
                &file.parameters
            }

            fn fitted(file: &GreyBoxFile) -> Result<FittedModel> {
                fitted(GreyBoxKind::$kind, file)
            }
        }
    };
}

grey_box_kind!(
    /// The kind `bouc_wen` in the registry ([`super::ModelKind`]).
    BoucWenKind => BoucWen
);
grey_box_kind!(
    /// The kind `rigid_body` in the registry ([`super::ModelKind`]).
    RigidBodyKind => RigidBody
);
grey_box_kind!(
    /// The kind `actuator_fixed` in the registry ([`super::ModelKind`]).
    ActuatorFixedKind => ActuatorFixed
);
grey_box_kind!(
    /// The kind `actuator_free` in the registry ([`super::ModelKind`]).
    ActuatorFreeKind => ActuatorFree
);

impl SavedModel {
    /// The saved built-in grey-box model `kind`.
    pub fn grey_box(kind: GreyBoxKind, file: GreyBoxFile) -> Self {
        match kind {
            GreyBoxKind::BoucWen => SavedModel::BoucWen(file),
            GreyBoxKind::RigidBody => SavedModel::RigidBody(file),
            GreyBoxKind::ActuatorFixed => SavedModel::ActuatorFixed(file),
            GreyBoxKind::ActuatorFree => SavedModel::ActuatorFree(file),
        }
    }

    /// The built-in grey-box model and its structure, for the grey-box kinds.
    pub fn as_grey_box(&self) -> Option<(GreyBoxKind, &GreyBoxFile)> {
        match self {
            SavedModel::BoucWen(g) => Some((GreyBoxKind::BoucWen, g)),
            SavedModel::RigidBody(g) => Some((GreyBoxKind::RigidBody, g)),
            SavedModel::ActuatorFixed(g) => Some((GreyBoxKind::ActuatorFixed, g)),
            SavedModel::ActuatorFree(g) => Some((GreyBoxKind::ActuatorFree, g)),
            _ => None,
        }
    }
}

/// The fitted built-in model `kind` of its file: every parameter by name, inside the model's
/// own bounds.
fn fitted(kind: GreyBoxKind, file: &GreyBoxFile) -> Result<FittedModel> {
    let model = kind.model();
    let name = kind.name();
    let records = Records {
        kind: name,
        list: &file.parameters,
    };
    let mut parameters = model.parameters();
    let mut std = Vec::new();
    for i in 0..parameters.len() {
        let e = records.get(&parameters.get(i).name.clone())?;
        // The model's own bounds are its physics (a positive mass, non-negative friction): a
        // file's wider bounds do not admit a value outside them.
        let own = parameters.get(i);
        if !(own.min..=own.max).contains(&e.value) {
            return Err(Error::InvalidParameter {
                name: own.name.clone(),
                value: e.value,
                reason: format!(
                    "the {name} model needs {} in [{}, {}]",
                    own.name, own.min, own.max
                ),
            });
        }
        *parameters.get_mut(i) = e.parameter();
        std.push(e.std_or_nan());
    }
    parameters.validate()?;
    let n = model.states().len();
    let initial_state = file.initial_state.clone().unwrap_or_else(|| vec![0.0; n]);
    if initial_state.len() != n || initial_state.iter().any(|v| !v.is_finite()) {
        return Err(Error::InvalidModel(format!(
            "\"initial_state\" needs {n} finite values for the {name} model"
        )));
    }
    let simulation = file
        .simulation
        .as_ref()
        .map_or(Ok(Simulation::default()), SimulationSpec::simulation)?;
    Ok(FittedModel::GreyBox(FittedGreyBox {
        kind: name.to_string(),
        parameters,
        std,
        simulation,
        initial_state,
    }))
}

/// A fitted built-in grey-box model ([`FittedModel::GreyBox`]).
#[derive(Clone, Debug, PartialEq)]
pub struct FittedGreyBox {
    /// Its kind (`bouc_wen`, `rigid_body`, …; or the kind a user's own model gives itself).
    pub kind: String,
    /// Its parameters (values, units, bounds, fixed flags).
    pub parameters: ParameterSet,
    /// Their standard deviations.
    pub std: Vec<f64>,
    /// How it is simulated.
    pub simulation: Simulation,
    /// Its initial state.
    pub initial_state: Vec<f64>,
}

/// The built-in model integrated ([`crate::model::greybox`]), in batch and one interval at
/// a time; not invertible. Saved as a built-in kind's file, or as the user's model under
/// its own kind.
impl FittedKind for FittedGreyBox {
    fn saved(&self) -> SavedModel {
        let parameters = records(&self.parameters, &self.std);
        let simulation = SimulationSpec::of(&self.simulation);
        let initial_state = self.initial_state.clone();
        match GreyBoxKind::parse(&self.kind).filter(|k| k.name() == self.kind) {
            Some(kind) => SavedModel::grey_box(
                kind,
                GreyBoxFile {
                    parameters,
                    simulation: Some(simulation),
                    initial_state: Some(initial_state),
                },
            ),
            None => SavedModel::UserGreyBox {
                kind: self.kind.clone(),
                parameters,
                simulation,
                initial_state,
            },
        }
    }

    fn simulate(&self, inputs: &[&[f64]], ts: f64, _y0: Option<f64>) -> Result<Vec<Vec<f64>>> {
        let model = models::by_kind(&self.kind)?;
        let theta = self.parameters.values();
        simulate_outputs(
            model.as_ref(),
            &theta,
            &self.initial_state,
            inputs,
            ts,
            &self.simulation,
        )
    }

    fn resampled(&self, from: f64, to: f64) -> Option<FittedModel> {
        let model = models::by_kind(&self.kind).ok()?;
        (!model.discrete_time()).then(|| {
            FittedModel::GreyBox(Self {
                simulation: self.simulation.resampled(from, to),
                ..self.clone()
            })
        })
    }

    fn stepper(&self, ts: f64, _y0: Option<f64>) -> Result<Box<dyn Stepper>> {
        let model = models::by_kind(&self.kind)?;
        stream::grey_box(
            model,
            self.parameters.values(),
            &self.initial_state,
            &self.simulation,
            ts,
        )
    }

    fn streaming_differs(&self) -> Option<String> {
        streamed_differently(&self.simulation)
    }
}

/// Why a grey-box or equation model simulated by `simulation` streams differently from its
/// batch simulation: band-limited input interpolation, which reads the whole record's
/// spectrum, is streamed with linear interpolation; None for the other interpolations.
pub(crate) fn streamed_differently(simulation: &Simulation) -> Option<String> {
    (simulation.interpolation == InputInterpolation::BandLimited).then(|| {
        "the model was saved with band-limited input interpolation, which reads the \
         whole record's spectrum; one sample at a time it is streamed with linear \
         interpolation between the samples, so its outputs differ from `simulate`'s"
            .into()
    })
}

/// The outputs of `model` simulated from `x0` with parameters `theta` for the input
/// channels `inputs` sampled every `ts` (the built-in models and the equation models alike).
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
