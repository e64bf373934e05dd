//! Fitted models and their JSON model files.
//!
//! A fitted model is what an estimator returns and what `hysid simulate` loads: the model with
//! its parameter values and standard deviations. The JSON layout is the `model` object of the
//! command-line reports:
//!
//! ```json
//! {"kind": "ch_cascade", "hysteresis": "ch4",
//!  "parameters": {"alpha": {"value": 0.3, "std": 0.001}, "m1": {…}, "c1": {…}, "d": {…},
//!                 "a": [{"value": -0.6, "std": 0.01}, …], "b": [{"value": 1.0, "std": 0.0}, …]},
//!  "delay": 1}
//! ```
//!
//! Kinds: `coleman_hodgdon` (the hysteresis alone; `initial_output` is `measured` or `zero`),
//! `ch_cascade` (hysteresis followed by a linear block; b₁ = 1 is fixed), and the grey-box
//! models `bouc_wen` and `rigid_body`, which add `simulation` (integrator, sub-steps, input
//! interpolation) and `initial_state`:
//!
//! ```json
//! {"kind": "bouc_wen",
//!  "parameters": {"mL": {"value": 2.0005, "std": 0.00015, "unit": "kg"}, …},
//!  "simulation": {"integrator": "rk4", "substeps": 4, "interpolation": "band_limited"},
//!  "initial_state": [0.0, 0.0, 0.0]}
//! ```

use crate::estimate::hysteresis::{simulate_switched, InitialOutput};
use crate::estimate::ParameterSet;
use crate::greybox::simulate::{simulate as simulate_state_space, InputTrack};
use crate::greybox::{models, InputInterpolation, Integrator, Simulation};
use crate::model::{ChForm, ColemanHodgdon, HysteresisCascade, LinearBlock};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// A parameter value with its standard deviation (0 when fixed, NaN written as null when
/// unknown).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// One standard deviation.
    #[serde(default, with = "nullable")]
    pub std: f64,
    /// The unit (grey-box models).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub unit: String,
}

/// A parameter entry: a scalar or a coefficient list.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ParameterEntry {
    /// A scalar parameter.
    Scalar(Estimate),
    /// A polynomial's coefficients.
    List(Vec<Estimate>),
}

/// The JSON model file (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelFile {
    /// `coleman_hodgdon`, `ch_cascade`, `bouc_wen` or `rigid_body`.
    pub kind: String,
    /// `ch4` or `ch6` (Coleman–Hodgdon kinds).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hysteresis: Option<ChForm>,
    /// Parameters by name (MODELS.md symbols).
    pub parameters: BTreeMap<String, ParameterEntry>,
    /// Delay k of the linear block (cascade only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delay: Option<usize>,
    /// Initial output of the hysteresis alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_output: Option<InitialOutput>,
    /// How a grey-box model is simulated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub simulation: Option<SimulationSpec>,
    /// Initial state of a grey-box model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_state: Option<Vec<f64>>,
}

/// The most integrator sub-steps per sample a model file may ask for: beyond it a
/// simulation is work without end in sight, not accuracy.
pub const MAX_SUBSTEPS: usize = 1000;

/// The simulation settings in a model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SimulationSpec {
    /// `rk4` or `newmark`.
    pub integrator: String,
    /// Sub-steps per sample.
    pub substeps: usize,
    /// Input interpolation.
    pub interpolation: InputInterpolation,
}

impl SimulationSpec {
    /// The spec of a simulation (adaptive integrators are saved as RK4 with 20 sub-steps).
    pub fn of(sim: &Simulation) -> Self {
        let (integrator, substeps) = match sim.integrator {
            Integrator::Rk4 { substeps } => ("rk4", substeps),
            Integrator::Newmark { substeps } => ("newmark", substeps),
            Integrator::Adaptive { .. } => ("rk4", 20),
        };
        Self {
            integrator: integrator.into(),
            substeps,
            interpolation: sim.interpolation,
        }
    }

    /// The simulation settings.
    pub fn simulation(&self) -> Result<Simulation> {
        if !(1..=MAX_SUBSTEPS).contains(&self.substeps) {
            return Err(Error::Config(format!(
                "\"substeps\": {} is out of range 1..={MAX_SUBSTEPS}; give a number of RK4 sub-steps per sample in that range",
                self.substeps
            )));
        }
        let substeps = self.substeps;
        let integrator = match self.integrator.as_str() {
            "rk4" => Integrator::Rk4 { substeps },
            "newmark" => Integrator::Newmark { substeps },
            other => {
                return Err(Error::Config(format!(
                    "unknown integrator '{other}'; use rk4 or newmark"
                )))
            }
        };
        Ok(Simulation {
            integrator,
            interpolation: self.interpolation,
        })
    }
}

/// A fitted model that can simulate.
#[derive(Clone, Debug, PartialEq)]
pub enum FittedModel {
    /// The hysteresis alone.
    Hysteresis {
        /// The model.
        model: ColemanHodgdon,
        /// Where its output starts.
        initial: InitialOutput,
        /// Standard deviations in [`ChForm::parameter_names`] order.
        std: Vec<f64>,
    },
    /// The cascade.
    Cascade {
        /// The model.
        model: HysteresisCascade,
        /// Standard deviations in [`HysteresisCascade::params`] order.
        std: Vec<f64>,
    },
    /// A built-in grey-box model.
    GreyBox {
        /// Its kind (`bouc_wen`, `rigid_body`).
        kind: String,
        /// Its parameters (values, units, bounds, fixed flags).
        parameters: ParameterSet,
        /// Their standard deviations.
        std: Vec<f64>,
        /// How it is simulated.
        simulation: Simulation,
        /// Its initial state.
        initial_state: Vec<f64>,
    },
}

impl FittedModel {
    /// Simulates the model's outputs for the input channels `inputs` sampled every `ts`;
    /// `y0` is the measured initial output (used by a hysteresis with
    /// [`InitialOutput::Measured`]). Errors when α·|Δx| > 1 or the simulation diverges
    /// (an output that is NaN or ±∞, e.g. an unstable linear block, is
    /// [`Error::Diverged`], never returned).
    pub fn simulate(&self, inputs: &[&[f64]], ts: f64, y0: Option<f64>) -> Result<Vec<Vec<f64>>> {
        let outputs = self.simulate_unchecked(inputs, ts, y0)?;
        for (channel, y) in outputs.iter().enumerate() {
            if let Some(index) = y.iter().position(|v| !v.is_finite()) {
                return Err(Error::Diverged {
                    index,
                    reason: format!(
                        "output {} is {}; the model is unstable or its parameters are out of range for this input",
                        channel + 1,
                        y[index]
                    ),
                });
            }
        }
        Ok(outputs)
    }

    fn simulate_unchecked(
        &self,
        inputs: &[&[f64]],
        ts: f64,
        y0: Option<f64>,
    ) -> Result<Vec<Vec<f64>>> {
        let first = || {
            inputs
                .first()
                .copied()
                .ok_or_else(|| Error::Config("no input channel given".into()))
        };
        match self {
            FittedModel::Hysteresis { model, initial, .. } => {
                let x = first()?;
                model.check_rate(x)?;
                let v0 = match initial {
                    InitialOutput::Measured => y0.ok_or_else(|| {
                        Error::Config(
                            "this hysteresis starts from the measured output; give the output column (--output)"
                                .into(),
                        )
                    })?,
                    InitialOutput::Zero => 0.0,
                };
                Ok(vec![simulate_switched(model, x, v0, None)])
            }
            FittedModel::Cascade { model, .. } => Ok(vec![model.simulate(first()?)?.y]),
            FittedModel::GreyBox {
                kind,
                parameters,
                simulation,
                initial_state,
                ..
            } => {
                let model = models::by_kind(kind)?;
                if inputs.len() != model.inputs().len() {
                    return Err(Error::Config(format!(
                        "the {kind} model has {} input(s), {} given",
                        model.inputs().len(),
                        inputs.len()
                    )));
                }
                let track = InputTrack::new(inputs, simulation)?;
                let theta = parameters.values();
                let mut outputs = vec![Vec::with_capacity(track.len()); model.outputs().len()];
                let (mut u, mut y) = (vec![0.0; inputs.len()], vec![0.0; outputs.len()]);
                simulate_state_space(
                    model.as_ref(),
                    &theta,
                    initial_state,
                    &track,
                    ts,
                    simulation.integrator,
                    |k, x| {
                        track.at(k, 0.0, &mut u);
                        model.output(x, &u, &theta, &mut y);
                        for (o, v) in outputs.iter_mut().zip(&y) {
                            o.push(*v);
                        }
                    },
                )?;
                Ok(outputs)
            }
        }
    }

    /// The model file of this model.
    pub fn to_file(&self) -> ModelFile {
        let empty = |kind: &str| ModelFile {
            kind: kind.into(),
            hysteresis: None,
            parameters: BTreeMap::new(),
            delay: None,
            initial_output: None,
            simulation: None,
            initial_state: None,
        };
        match self {
            FittedModel::Hysteresis {
                model,
                initial,
                std,
            } => ModelFile {
                hysteresis: Some(model.form()),
                parameters: hysteresis_entries(model, std),
                initial_output: Some(*initial),
                ..empty("coleman_hodgdon")
            },
            FittedModel::Cascade { model, std } => {
                let nh = model.hysteresis.form().n_params();
                let mut parameters = hysteresis_entries(&model.hysteresis, &std[..nh]);
                let nb = model.linear.nb();
                let mut b = vec![estimate((&1.0, &0.0))];
                b.extend(
                    model.linear.b()[1..]
                        .iter()
                        .zip(&std[nh..nh + nb - 1])
                        .map(estimate),
                );
                let a = model
                    .linear
                    .a()
                    .iter()
                    .zip(&std[nh + nb - 1..])
                    .map(estimate)
                    .collect();
                parameters.insert("b".into(), ParameterEntry::List(b));
                parameters.insert("a".into(), ParameterEntry::List(a));
                ModelFile {
                    hysteresis: Some(model.hysteresis.form()),
                    parameters,
                    delay: Some(model.linear.delay()),
                    ..empty("ch_cascade")
                }
            }
            FittedModel::GreyBox {
                kind,
                parameters,
                std,
                simulation,
                initial_state,
            } => ModelFile {
                parameters: parameters
                    .iter()
                    .zip(std)
                    .map(|(p, s)| {
                        let mut e = estimate((&p.value, s));
                        e.unit = p.unit.clone();
                        (p.name.clone(), ParameterEntry::Scalar(e))
                    })
                    .collect(),
                simulation: Some(SimulationSpec::of(simulation)),
                initial_state: Some(initial_state.clone()),
                ..empty(kind)
            },
        }
    }

    /// Rebuilds a fitted model from a model file.
    pub fn from_file(file: &ModelFile) -> Result<Self> {
        match file.kind.as_str() {
            "coleman_hodgdon" | "ch_cascade" => Self::coleman_hodgdon_from_file(file),
            kind => Self::grey_box_from_file(kind, file),
        }
    }

    fn coleman_hodgdon_from_file(file: &ModelFile) -> Result<Self> {
        let form = file.hysteresis.ok_or_else(|| {
            Error::Config(format!(
                "a {} model needs \"hysteresis\": \"ch4\" or \"ch6\"",
                file.kind
            ))
        })?;
        let mut values = Vec::new();
        let mut std = Vec::new();
        for name in form.parameter_names() {
            let e = scalar(file, name, &form.parameter_names().join(", "))?;
            values.push(e.value);
            std.push(e.std);
        }
        let hysteresis = ColemanHodgdon::from_params(form, &values)?;
        if file.kind == "coleman_hodgdon" {
            return Ok(FittedModel::Hysteresis {
                model: hysteresis,
                initial: file.initial_output.unwrap_or(InitialOutput::Measured),
                std,
            });
        }
        let a = list(file, "a")?;
        let b = list(file, "b")?;
        let delay = file
            .delay
            .ok_or_else(|| Error::Config("a ch_cascade model needs \"delay\"".into()))?;
        let linear = LinearBlock::new(
            a.iter().map(|e| e.value).collect(),
            b.iter().map(|e| e.value).collect(),
            delay,
        )?;
        std.extend(b.iter().skip(1).map(|e| e.std));
        std.extend(a.iter().map(|e| e.std));
        Ok(FittedModel::Cascade {
            model: HysteresisCascade::new(hysteresis, linear)?,
            std,
        })
    }

    fn grey_box_from_file(kind: &str, file: &ModelFile) -> Result<Self> {
        let model = models::by_kind(kind).map_err(|_| {
            Error::Config(format!(
                "unknown model kind '{kind}'; this version knows coleman_hodgdon, ch_cascade, bouc_wen and rigid_body"
            ))
        })?;
        let mut parameters = model.parameters();
        let names = parameters.names().join(", ");
        let mut std = Vec::new();
        for i in 0..parameters.len() {
            let e = scalar(file, &parameters.get(i).name.clone(), &names)?;
            parameters.get_mut(i).value = e.value;
            std.push(e.std);
        }
        let n = model.states().len();
        let initial_state = file.initial_state.clone().unwrap_or_else(|| vec![0.0; n]);
        if initial_state.len() != n {
            return Err(Error::Config(format!(
                "\"initial_state\" needs {n} values for the {kind} model"
            )));
        }
        let simulation = file
            .simulation
            .as_ref()
            .map_or(Ok(Simulation::default()), SimulationSpec::simulation)?;
        Ok(FittedModel::GreyBox {
            kind: kind.to_string(),
            parameters,
            std,
            simulation,
            initial_state,
        })
    }

    /// Reads a model file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let file: ModelFile = serde_json::from_str(&text).map_err(|e| Error::ModelFile {
            path: path.to_path_buf(),
            message: format!("not a hysid model file: {e}"),
        })?;
        Self::from_file(&file).map_err(|e| Error::ModelFile {
            path: path.to_path_buf(),
            message: e.to_string(),
        })
    }
}

fn estimate((value, std): (&f64, &f64)) -> Estimate {
    Estimate {
        value: *value,
        std: *std,
        unit: String::new(),
    }
}

fn hysteresis_entries(model: &ColemanHodgdon, std: &[f64]) -> BTreeMap<String, ParameterEntry> {
    model
        .form()
        .parameter_names()
        .iter()
        .zip(model.params().iter().zip(std))
        .map(|(name, pair)| (name.to_string(), ParameterEntry::Scalar(estimate(pair))))
        .collect()
}

fn scalar(file: &ModelFile, name: &str, all: &str) -> Result<Estimate> {
    match file.parameters.get(name) {
        Some(ParameterEntry::Scalar(e)) => Ok(e.clone()),
        Some(ParameterEntry::List(_)) => Err(Error::Config(format!(
            "parameter '{name}' must be a single value"
        ))),
        None => Err(Error::Config(format!(
            "parameter '{name}' is missing (a {} model needs {all})",
            file.kind
        ))),
    }
}

fn list(file: &ModelFile, name: &str) -> Result<Vec<Estimate>> {
    match file.parameters.get(name) {
        Some(ParameterEntry::List(v)) => Ok(v.clone()),
        Some(ParameterEntry::Scalar(e)) => Ok(vec![e.clone()]),
        None => Err(Error::Config(format!(
            "coefficient list '{name}' is missing"
        ))),
    }
}

/// Writes NaN as null and reads null as NaN, so unknown standard deviations survive JSON.
mod nullable {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        if v.is_finite() {
            s.serialize_f64(*v)
        } else {
            s.serialize_none()
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::examples::CascadeExample;

    #[test]
    fn cascade_round_trips_through_json() {
        let truth = CascadeExample::example2().truth;
        let std: Vec<f64> = (0..truth.params().len())
            .map(|i| 0.01 * (i + 1) as f64)
            .collect();
        let fitted = FittedModel::Cascade { model: truth, std };
        let json = serde_json::to_string(&fitted.to_file()).unwrap();
        assert!(
            json.contains("\"kind\":\"ch_cascade\"") && json.contains("\"hysteresis\":\"ch6\"")
        );
        let back = FittedModel::from_file(&serde_json::from_str(&json).unwrap()).unwrap();
        assert_eq!(back, fitted);
    }

    #[test]
    fn unknown_std_is_null() {
        let model = ColemanHodgdon::saturated(0.3, 1.0, 0.5, 3.0).unwrap();
        let fitted = FittedModel::Hysteresis {
            model,
            initial: InitialOutput::Zero,
            std: vec![f64::NAN, 0.1, 0.1, 0.1],
        };
        let json = serde_json::to_string(&fitted.to_file()).unwrap();
        assert!(json.contains("\"std\":null"), "{json}");
        let back = FittedModel::from_file(&serde_json::from_str(&json).unwrap()).unwrap();
        let FittedModel::Hysteresis { std, .. } = back else {
            panic!()
        };
        assert!(std[0].is_nan());
    }
}
