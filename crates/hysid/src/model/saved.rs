//! Fitted models and the saved-model file `hysid.model/1`.
//!
//! A fitted model is what an estimator returns and what `hysid simulate` loads: the model with
//! its parameter values, standard deviations, units, bounds and fixed flags. The same JSON
//! object is the `model` key of every report (`hysid.report/1`), so a report is also a model
//! file:
//!
//! ```json
//! {"schema": "hysid.model/1", "kind": "ch_cascade", "hysteresis": "ch4", "delay": 1,
//!  "parameters": [
//!    {"name": "alpha", "value": 0.3, "std": 0.001, "unit": "", "fixed": false,
//!     "lower": 0.0, "upper": null},
//!    {"name": "b1", "value": 1.0, "std": null, "unit": "", "fixed": true,
//!     "lower": null, "upper": null}, …]}
//! ```
//!
//! `parameters` is a flat list in the model's order: `std` is null where the parameter was not
//! estimated (fixed, or unknown), `lower`/`upper` null where unbounded. Kinds and their
//! structure keys:
//!
//! | kind | structure | parameters |
//! |---|---|---|
//! | `coleman_hodgdon` | `hysteresis` (`ch4`/`ch6`), `initial_output` (`measured`/`zero`) | α, m₁, c₁, d (ch6: and m₂, c₂) |
//! | `ch_cascade` | `hysteresis`, `delay` | hysteresis, then b₁ (fixed at 1) … b_m, a₁ … a_n |
//! | `operator_cascade` | `operator` (the family and its structure: thresholds, grid, orientation, …), `delay` | the operator's (prefixed `op_` where they collide with a₁…, b₁…), then a₁ … a_n, b₁ (fixed at 1) … b_m |
//! | `bouc_wen`, `rigid_body`, `actuator_fixed`, `actuator_free` | `simulation`, `initial_state` | the grey-box model's |
//! | `equations` | `equations` (the equation file's text), `simulation`, `initial_state` | the file's `[parameters]` |
//! | `operator` | `family` (`pi`, `gpi`, `preisach`, `jiles-atherton`, `bouc-wen`, `duhem`, `dahl`, `maxwell-slip`, `backlash`), `operator` (the operator's full structure: thresholds, weights, grid, orientation, initial state) | the family's, named as in the literature |
//!
//! Any kind may carry the processing its fit applied to the records ([`record_filters`]):
//! `prefilter` (`{remove_mean, cutoff_hz, order}`, the actuator's step 3: records filtered
//! before simulating, [`FittedModel::Prefiltered`]) or, for `rigid_body`, `inverse_dynamics`
//! (`{cutoff_hz, order, decimation, border}`: the drive signal predicted from the position,
//! [`FittedModel::InverseDynamics`]). [`FittedModel::predict`] applies it, so the fit % of a
//! report is reproduced from its model file.
//!
//! [`record_filters`]: crate::model::record_filters
//!
//! `simulation` saves the integrator faithfully: `{"integrator": "rk4", "substeps": 10,
//! "interpolation": "zero_order_hold"}`, `newmark` with `substeps`, or `dopri5` with `rtol`
//! and `atol`.

use crate::model::coleman_hodgdon::{simulate_switched, InitialOutput};
use crate::model::greybox::equation_model::{EquationStateSpace, EQUATIONS_KIND};
use crate::model::greybox::{models, InputInterpolation, Integrator, Simulation};
use crate::model::operators::OperatorModel;
use crate::model::record_filters::{InverseDynamics, Prefilter, RigidBodyValues};
use crate::model::saved_equations::{equations_from_file, simulate_outputs};
use crate::model::OperatorCascade;
use crate::model::{ChForm, ColemanHodgdon, HysteresisCascade, LinearBlock};
use crate::model::{Parameter, ParameterSet};
use crate::{Error, Result};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The kind of a saved hysteresis operator (see the module docs).
pub const OPERATOR_KIND: &str = "operator";

/// The schema tag of a saved model.
pub const MODEL_SCHEMA: &str = "hysid.model/1";

/// One parameter of a saved model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ParameterRecord {
    /// The literature's symbol (`alpha`, `m1`, `a1`, `b2`, `mL`, …).
    pub name: String,
    /// The value.
    pub value: f64,
    /// One standard deviation; null where the parameter was not estimated.
    pub std: Option<f64>,
    /// The unit ("" when dimensionless or unknown).
    pub unit: String,
    /// True when the value was held, not estimated.
    pub fixed: bool,
    /// Lower bound; null when unbounded.
    pub lower: Option<f64>,
    /// Upper bound; null when unbounded.
    pub upper: Option<f64>,
}

impl ParameterRecord {
    /// The record of `p` with standard deviation `std` (NaN, or a fixed parameter, gives null).
    pub fn of(p: &Parameter, std: f64) -> Self {
        Self {
            name: p.name.clone(),
            value: p.value,
            std: (!p.fixed && std.is_finite()).then_some(std),
            unit: p.unit.clone(),
            fixed: p.fixed,
            lower: p.min.is_finite().then_some(p.min),
            upper: p.max.is_finite().then_some(p.max),
        }
    }

    /// The parameter this record describes.
    pub fn parameter(&self) -> Parameter {
        Parameter::new(self.name.clone(), self.value)
            .unit(self.unit.clone())
            .bounds(
                self.lower.unwrap_or(f64::NEG_INFINITY),
                self.upper.unwrap_or(f64::INFINITY),
            )
            .fixed(self.fixed)
    }

    /// The standard deviation as a number (NaN when null).
    pub fn std_or_nan(&self) -> f64 {
        self.std.unwrap_or(f64::NAN)
    }
}

/// The saved-model file `hysid.model/1` (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// Always `hysid.model/1`.
    pub schema: String,
    /// The model kind (see the module docs).
    pub kind: String,
    /// The parameters in the model's order.
    pub parameters: Vec<ParameterRecord>,
    /// `ch4` or `ch6` (Coleman–Hodgdon kinds).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hysteresis: Option<ChForm>,
    /// Delay k of the linear block (cascade).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delay: Option<usize>,
    /// Where the output of the hysteresis alone starts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_output: Option<InitialOutput>,
    /// How a grey-box model is simulated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub simulation: Option<SimulationSpec>,
    /// Initial state of a grey-box model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_state: Option<Vec<f64>>,
    /// The equation file's text (kind `equations`), so that the saved model is
    /// self-contained.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub equations: Option<String>,
    /// The operator family (kind `operator`): `pi`, `gpi`, `preisach`, `jiles-atherton`,
    /// `bouc-wen`, `duhem`, `dahl`, `maxwell-slip` or `backlash`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub family: Option<String>,
    /// The operator's full structure: for kind `operator` its thresholds, weights, grids,
    /// orientation and initial state, as the family defines them; for kind
    /// `operator_cascade` `{"family": …, "operator": {…}}` with the structure, whose values
    /// are read from `parameters`. Checked on reading.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub operator: Option<serde_json::Value>,
    /// The pre-filter the model was fitted with (the actuator's step 3): `hysid simulate`
    /// filters input and measured output alike before simulating.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prefilter: Option<Prefilter>,
    /// The preprocessing of an inverse-dynamics fit (kind `rigid_body` from `rigid-body ls`):
    /// the model predicts the drive signal from the measured position, as the fit did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inverse_dynamics: Option<InverseDynamics>,
}

/// The simulation settings in a model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SimulationSpec {
    /// `rk4`, `newmark` or `dopri5`.
    pub integrator: String,
    /// Sub-steps per sample (`rk4`, `newmark`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub substeps: Option<usize>,
    /// Relative tolerance (`dopri5`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rtol: Option<f64>,
    /// Absolute tolerance (`dopri5`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub atol: Option<f64>,
    /// Input interpolation between samples.
    pub interpolation: InputInterpolation,
}

/// The largest number of sub-steps a model file may ask for: beyond it a simulation of an
/// ordinary record takes hours, and the file is more likely corrupt than meant.
pub const MAX_SUBSTEPS: usize = 1000;

impl SimulationSpec {
    /// The spec of a simulation, saved faithfully.
    pub fn of(sim: &Simulation) -> Self {
        let (integrator, substeps, rtol, atol) = match sim.integrator {
            Integrator::Rk4 { substeps } => ("rk4", Some(substeps), None, None),
            Integrator::Newmark { substeps } => ("newmark", Some(substeps), None, None),
            Integrator::Adaptive { rtol, atol } => ("dopri5", None, Some(rtol), Some(atol)),
        };
        Self {
            integrator: integrator.into(),
            substeps,
            rtol,
            atol,
            interpolation: sim.interpolation,
        }
    }

    /// The simulation settings, checked.
    pub fn simulation(&self) -> Result<Simulation> {
        let substeps = || match self.substeps {
            Some(n) if (1..=MAX_SUBSTEPS).contains(&n) => Ok(n),
            Some(n) => Err(Error::InvalidModel(format!(
                "substeps {n} is outside 1..={MAX_SUBSTEPS}"
            ))),
            None => Err(Error::InvalidModel(format!(
                "the {} integrator needs \"substeps\"",
                self.integrator
            ))),
        };
        let tolerance = |name: &str, v: Option<f64>| match v {
            Some(t) if t.is_finite() && t > 0.0 => Ok(t),
            _ => Err(Error::InvalidModel(format!(
                "the dopri5 integrator needs a positive finite \"{name}\""
            ))),
        };
        let integrator = match self.integrator.as_str() {
            "rk4" => Integrator::Rk4 {
                substeps: substeps()?,
            },
            "newmark" => Integrator::Newmark {
                substeps: substeps()?,
            },
            "dopri5" => Integrator::Adaptive {
                rtol: tolerance("rtol", self.rtol)?,
                atol: tolerance("atol", self.atol)?,
            },
            other => {
                return Err(Error::InvalidModel(format!(
                    "unknown integrator '{other}'; use rk4, newmark or dopri5"
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
    /// Any hysteresis operator followed by a linear block.
    OperatorCascade {
        /// The model.
        model: OperatorCascade,
        /// Standard deviations in [`OperatorCascade::parameters`] order (NaN where not
        /// estimated).
        std: Vec<f64>,
    },
    /// A grey-box model written as equations (`hysid-equations`).
    Equations {
        /// The equation file's text.
        equations: String,
        /// Its parameters (values, units, bounds, fixed flags) in the file's order.
        parameters: ParameterSet,
        /// Their standard deviations.
        std: Vec<f64>,
        /// How it is simulated.
        simulation: Simulation,
        /// Its initial state.
        initial_state: Vec<f64>,
    },
    /// A hysteresis operator of one of the families of [`crate::model::operators`].
    Operator {
        /// The family's name (`pi`, `preisach`, …; equal to `model.family()`).
        family: &'static str,
        /// The operator.
        model: OperatorModel,
        /// Standard deviations in `model.as_operator().parameters()` order (NaN: none).
        std: Vec<f64>,
    },
    /// A model fitted to pre-filtered records: it filters every record (inputs and measured
    /// output alike) before it simulates.
    Prefiltered {
        /// The model as fitted to the filtered records.
        model: Box<FittedModel>,
        /// The filter.
        prefilter: Prefilter,
    },
    /// A rigid body (a [`FittedModel::GreyBox`] of kind `rigid_body`) fitted by inverse
    /// dynamics: it predicts the drive signal from the measured position (see
    /// [`InverseDynamics`]).
    InverseDynamics {
        /// The rigid body.
        model: Box<FittedModel>,
        /// The preprocessing of the fit.
        preprocessing: InverseDynamics,
    },
}

/// One record as a model's fit sees it: the inputs the model is driven by (filtered,
/// decimated where the fit did so), its outputs, and the measured output processed alike.
#[derive(Clone, Debug, PartialEq)]
pub struct Prediction {
    /// The inputs as the model sees them.
    pub inputs: Vec<Vec<f64>>,
    /// The model's outputs (simulated, or predicted by inverse dynamics).
    pub outputs: Vec<Vec<f64>>,
    /// The measured counterpart of output 0, processed as the fit processed it.
    pub measured: Option<Vec<f64>>,
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
                .ok_or_else(|| Error::ModelMismatch("no input channel given".into()))
        };
        match self {
            FittedModel::Hysteresis { model, initial, .. } => {
                let x = first()?;
                model.check_rate(x)?;
                let v0 = match initial {
                    InitialOutput::Measured => y0.ok_or_else(|| {
                        Error::ModelMismatch(
                            "this hysteresis starts from the measured output; give the measured output"
                                .into(),
                        )
                    })?,
                    InitialOutput::Zero => 0.0,
                };
                Ok(vec![simulate_switched(model, x, v0, None)])
            }
            FittedModel::Cascade { model, .. } => Ok(vec![model.simulate(first()?)?.y]),
            FittedModel::Prefiltered { model, prefilter } => {
                let filtered = inputs
                    .iter()
                    .map(|x| prefilter.apply(x, ts))
                    .collect::<Result<Vec<_>>>()?;
                model.simulate_unchecked(&slices(&filtered), ts, y0)
            }
            FittedModel::InverseDynamics { preprocessing, .. } => Ok(vec![
                preprocessing.predict(&self.rigid_body()?, first()?, ts)?.1,
            ]),
            FittedModel::OperatorCascade { model, .. } => Ok(vec![model.simulate(first()?)?.y]),
            FittedModel::Operator { model, .. } => {
                Ok(vec![model.as_operator().simulate(first()?)?])
            }
            FittedModel::GreyBox {
                kind,
                parameters,
                simulation,
                initial_state,
                ..
            } => {
                let model = models::by_kind(kind)?;
                let theta = parameters.values();
                simulate_outputs(
                    model.as_ref(),
                    &theta,
                    initial_state,
                    inputs,
                    ts,
                    simulation,
                )
            }
            FittedModel::Equations {
                equations,
                parameters,
                simulation,
                initial_state,
                ..
            } => {
                let model = EquationStateSpace::parse(equations, "saved model")?;
                simulate_outputs(
                    &model,
                    &parameters.values(),
                    initial_state,
                    inputs,
                    ts,
                    simulation,
                )
            }
        }
    }

    /// The model's outputs for the inputs `inputs` sampled every `ts`, and the measured output
    /// `measured` processed as the fit processed it: filtered for a
    /// [`FittedModel::Prefiltered`], decimated and trimmed for a
    /// [`FittedModel::InverseDynamics`] (whose input is the position and whose output the
    /// predicted drive signal); as they are for every other model. fit % of
    /// `outputs[0]` against `measured` is the fit the model's report states.
    pub fn predict(
        &self,
        inputs: &[&[f64]],
        measured: Option<&[f64]>,
        ts: f64,
    ) -> Result<Prediction> {
        match self {
            FittedModel::Prefiltered { model, prefilter } => {
                let filtered = inputs
                    .iter()
                    .map(|x| prefilter.apply(x, ts))
                    .collect::<Result<Vec<_>>>()?;
                let measured = measured.map(|y| prefilter.apply(y, ts)).transpose()?;
                model.predict(&slices(&filtered), measured.as_deref(), ts)
            }
            FittedModel::InverseDynamics { preprocessing, .. } => {
                let q = inputs.first().copied().unwrap_or_default();
                if let Some(u) = measured.filter(|u| u.len() != q.len()) {
                    return Err(Error::InvalidData(format!(
                        "the position has {} samples, the drive signal {}",
                        q.len(),
                        u.len()
                    )));
                }
                let (position, predicted) = preprocessing.predict(&self.rigid_body()?, q, ts)?;
                if let Some(index) = predicted.iter().position(|v| !v.is_finite()) {
                    return Err(Error::Diverged {
                        index,
                        reason:
                            "the predicted drive signal is not finite; scale the position data down"
                                .into(),
                    });
                }
                Ok(Prediction {
                    inputs: vec![position],
                    outputs: vec![predicted],
                    measured: measured.map(|u| preprocessing.reduce(u)).transpose()?,
                })
            }
            _ => Ok(Prediction {
                outputs: self.simulate(inputs, ts, measured.and_then(|y| y.first().copied()))?,
                inputs: inputs.iter().map(|x| x.to_vec()).collect(),
                measured: measured.map(<[f64]>::to_vec),
            }),
        }
    }

    /// `model` fitted to records filtered by `prefilter` (unchanged when there is none).
    pub fn prefiltered(model: FittedModel, prefilter: Option<Prefilter>) -> Self {
        match prefilter {
            Some(prefilter) => FittedModel::Prefiltered {
                model: Box::new(model),
                prefilter,
            },
            None => model,
        }
    }

    /// The rigid body's values of an inverse-dynamics model (M, Fv, Fc, offset, gain).
    fn rigid_body(&self) -> Result<RigidBodyValues> {
        let inner = match self {
            FittedModel::InverseDynamics { model, .. } => model.as_ref(),
            other => other,
        };
        let parameters = match inner {
            FittedModel::GreyBox {
                kind, parameters, ..
            } if kind == "rigid_body" => parameters,
            other => {
                return Err(Error::UnsupportedKind {
                    kind: other.to_file().kind,
                    operation: "inverse dynamics (a rigid_body model)".into(),
                })
            }
        };
        let value = |name: &str| parameters.iter().find(|p| p.name == name).map(|p| p.value);
        match (
            value("M"),
            value("Fv"),
            value("Fc"),
            value("offset"),
            value("gain"),
        ) {
            (Some(inertia), Some(fv), Some(fc), Some(offset), Some(gain)) => Ok(RigidBodyValues {
                inertia,
                fv,
                fc,
                offset,
                gain,
            }),
            _ => Err(Error::InvalidModel(
                "a rigid body needs the parameters M, Fv, Fc, offset and gain".into(),
            )),
        }
    }

    /// A built-in-style grey-box fit ([`FittedModel::GreyBox`]) of the equation model with
    /// file text `equations`, as [`FittedModel::Equations`]; other variants unchanged.
    pub fn with_equations(self, equations: &str) -> Self {
        match self {
            FittedModel::GreyBox {
                parameters,
                std,
                simulation,
                initial_state,
                ..
            } => FittedModel::Equations {
                equations: equations.to_string(),
                parameters,
                std,
                simulation,
                initial_state,
            },
            other => other,
        }
    }

    /// The model file of this model.
    pub fn to_file(&self) -> ModelFile {
        let empty = |kind: &str, parameters: Vec<ParameterRecord>| ModelFile {
            schema: MODEL_SCHEMA.into(),
            kind: kind.into(),
            parameters,
            hysteresis: None,
            delay: None,
            initial_output: None,
            simulation: None,
            initial_state: None,
            equations: None,
            family: None,
            operator: None,
            prefilter: None,
            inverse_dynamics: None,
        };
        match self {
            FittedModel::Hysteresis {
                model,
                initial,
                std,
            } => ModelFile {
                hysteresis: Some(model.form()),
                initial_output: Some(*initial),
                ..empty("coleman_hodgdon", hysteresis_records(model, std))
            },
            FittedModel::Cascade { model, std } => ModelFile {
                hysteresis: Some(model.hysteresis.form()),
                delay: Some(model.linear.delay()),
                ..empty("ch_cascade", cascade_records(model, std))
            },
            FittedModel::OperatorCascade { model, std } => ModelFile {
                delay: Some(model.linear.delay()),
                operator: serde_json::to_value(&model.operator).ok(),
                ..empty(
                    OPERATOR_CASCADE_KIND,
                    model
                        .parameters()
                        .iter()
                        .zip(std)
                        .map(|(p, s)| ParameterRecord::of(p, *s))
                        .collect(),
                )
            },
            FittedModel::GreyBox {
                kind,
                parameters,
                std,
                simulation,
                initial_state,
            } => ModelFile {
                simulation: Some(SimulationSpec::of(simulation)),
                initial_state: Some(initial_state.clone()),
                ..empty(
                    kind,
                    parameters
                        .iter()
                        .zip(std)
                        .map(|(p, s)| ParameterRecord::of(p, *s))
                        .collect(),
                )
            },
            FittedModel::Equations {
                equations,
                parameters,
                std,
                simulation,
                initial_state,
            } => ModelFile {
                simulation: Some(SimulationSpec::of(simulation)),
                initial_state: Some(initial_state.clone()),
                equations: Some(equations.clone()),
                ..empty(
                    EQUATIONS_KIND,
                    parameters
                        .iter()
                        .zip(std)
                        .map(|(p, s)| ParameterRecord::of(p, *s))
                        .collect(),
                )
            },
            FittedModel::Prefiltered { model, prefilter } => ModelFile {
                prefilter: Some(*prefilter),
                ..model.to_file()
            },
            FittedModel::InverseDynamics {
                model,
                preprocessing,
            } => ModelFile {
                inverse_dynamics: Some(*preprocessing),
                ..model.to_file()
            },
            FittedModel::Operator { family, model, std } => ModelFile {
                family: Some(family.to_string()),
                // The structure of a constructed operator is always representable; a failure
                // would only drop it, and reading the file back then says so.
                operator: model.structure().ok(),
                ..empty(
                    OPERATOR_KIND,
                    model
                        .as_operator()
                        .parameters()
                        .iter()
                        .zip(std)
                        .map(|(p, s)| ParameterRecord::of(p, *s))
                        .collect(),
                )
            },
        }
    }

    /// The fitted model of an operator with standard deviations `std` (NaN: none).
    pub fn operator(model: OperatorModel, std: Vec<f64>) -> Self {
        FittedModel::Operator {
            family: model.family().name(),
            model,
            std,
        }
    }

    /// Rebuilds a fitted model from a model file, checking every value.
    pub fn from_file(file: &ModelFile) -> Result<Self> {
        if file.schema != MODEL_SCHEMA {
            return Err(Error::InvalidModel(format!(
                "schema '{}' is not {MODEL_SCHEMA}; save the model again with this version",
                file.schema
            )));
        }
        if let Some(p) = file.parameters.iter().find(|p| !p.value.is_finite()) {
            return Err(Error::InvalidModel(format!(
                "parameter '{}' has no finite value",
                p.name
            )));
        }
        if let Some(prefilter) = file.prefilter {
            check_prefilter(&prefilter)?;
            let inner = ModelFile {
                prefilter: None,
                ..file.clone()
            };
            return Ok(Self::prefiltered(Self::from_file(&inner)?, Some(prefilter)));
        }
        if let Some(preprocessing) = file.inverse_dynamics {
            check_inverse_dynamics(&preprocessing)?;
            let inner = ModelFile {
                inverse_dynamics: None,
                ..file.clone()
            };
            let model = FittedModel::InverseDynamics {
                model: Box::new(Self::from_file(&inner)?),
                preprocessing,
            };
            model.rigid_body()?;
            return Ok(model);
        }
        match file.kind.as_str() {
            "coleman_hodgdon" | "ch_cascade" => Self::coleman_hodgdon_from_file(file),
            EQUATIONS_KIND => equations_from_file(file),
            OPERATOR_CASCADE_KIND => operator_cascade_from_file(file),
            OPERATOR_KIND => Self::operator_from_file(file),
            kind => Self::grey_box_from_file(kind, file),
        }
    }

    fn coleman_hodgdon_from_file(file: &ModelFile) -> Result<Self> {
        let form = file.hysteresis.ok_or_else(|| {
            Error::InvalidModel(format!(
                "a {} model needs \"hysteresis\": \"ch4\" or \"ch6\"",
                file.kind
            ))
        })?;
        let mut values = Vec::new();
        let mut std = Vec::new();
        for name in form.parameter_names() {
            let e = record(file, name)?;
            values.push(e.value);
            std.push(e.std_or_nan());
        }
        let hysteresis = ColemanHodgdon::from_params(form, &values)?;
        if file.kind == "coleman_hodgdon" {
            return Ok(FittedModel::Hysteresis {
                model: hysteresis,
                initial: file.initial_output.unwrap_or(InitialOutput::Measured),
                std,
            });
        }
        let b = coefficients(file, 'b')?;
        let a = coefficients(file, 'a')?;
        if b.is_empty() || b[0].value != 1.0 {
            return Err(Error::InvalidModel(
                "a ch_cascade model needs b1 = 1 (the gain sits in the hysteresis)".into(),
            ));
        }
        let delay = file
            .delay
            .ok_or_else(|| Error::InvalidModel("a ch_cascade model needs \"delay\"".into()))?;
        let linear = LinearBlock::new(
            a.iter().map(|e| e.value).collect(),
            b.iter().map(|e| e.value).collect(),
            delay,
        )?;
        std.extend(b.iter().skip(1).map(ParameterRecord::std_or_nan));
        std.extend(a.iter().map(ParameterRecord::std_or_nan));
        Ok(FittedModel::Cascade {
            model: HysteresisCascade::new(hysteresis, linear)?,
            std,
        })
    }

    fn operator_from_file(file: &ModelFile) -> Result<Self> {
        let (Some(family), Some(structure)) = (&file.family, &file.operator) else {
            return Err(Error::InvalidModel(
                "an operator model needs \"family\" and \"operator\"; save the model again".into(),
            ));
        };
        let model = OperatorModel::from_structure(family, structure)?;
        let names = model.as_operator().parameters();
        let mut std = Vec::with_capacity(names.len());
        for p in names.iter() {
            std.push(record(file, &p.name)?.std_or_nan());
        }
        Ok(Self::operator(model, std))
    }

    fn grey_box_from_file(kind: &str, file: &ModelFile) -> Result<Self> {
        let model = models::by_kind(kind).map_err(|_| {
            Error::InvalidModel(format!(
                "unknown model kind '{kind}'; this version knows coleman_hodgdon, ch_cascade, bouc_wen, rigid_body, actuator_fixed, actuator_free, equations, operator and operator_cascade"
            ))
        })?;
        let mut parameters = model.parameters();
        let mut std = Vec::new();
        for i in 0..parameters.len() {
            let e = record(file, &parameters.get(i).name.clone())?;
            // The model's own bounds are its physics (a positive mass, non-negative
            // friction): a file's wider bounds do not admit a value outside them.
            let own = parameters.get(i);
            if !(own.min..=own.max).contains(&e.value) {
                return Err(Error::InvalidParameter {
                    name: own.name.clone(),
                    value: e.value,
                    reason: format!(
                        "the {kind} model needs {} in [{}, {}]",
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
                "\"initial_state\" needs {n} finite values for the {kind} model"
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

    /// Reads a model file, or the `model` object of a report.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let bad = |message: String| Error::ModelFile {
            path: path.to_path_buf(),
            message,
        };
        let value: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| bad(format!("not JSON: {e}")))?;
        let object = match value.get("schema").and_then(|s| s.as_str()) {
            Some(s) if s.starts_with("hysid.report/") => value
                .get("model")
                .cloned()
                .ok_or_else(|| bad("this report holds no model (its \"model\" is null)".into()))?,
            _ => value,
        };
        if object.is_null() {
            return Err(bad(
                "this report holds no model (its \"model\" is null)".into()
            ));
        }
        let file: ModelFile = serde_json::from_value(object)
            .map_err(|e| bad(format!("not a {MODEL_SCHEMA} model file: {e}")))?;
        Self::from_file(&file).map_err(|e| bad(e.to_string()))
    }
}

/// The slices of `signals`.
fn slices(signals: &[Vec<f64>]) -> Vec<&[f64]> {
    signals.iter().map(Vec::as_slice).collect()
}

/// The largest Butterworth order a model file may ask for (beyond it the filter is
/// numerically meaningless and the file more likely corrupt).
pub const MAX_FILTER_ORDER: usize = 20;

/// Refuses a pre-filter no fit uses: an order outside 1..=[`MAX_FILTER_ORDER`], a cut-off
/// that is not positive and finite.
fn check_prefilter(p: &Prefilter) -> Result<()> {
    check_filter(p.cutoff_hz.unwrap_or(1.0), p.order, "prefilter")
}

/// Refuses inverse-dynamics settings no fit uses (see [`check_prefilter`]; a decimation
/// factor of at least 1).
fn check_inverse_dynamics(p: &InverseDynamics) -> Result<()> {
    if p.decimation == 0 {
        return Err(Error::InvalidModel(
            "\"inverse_dynamics\" needs a decimation factor of at least 1".into(),
        ));
    }
    check_filter(p.cutoff_hz, p.order, "inverse_dynamics")
}

fn check_filter(cutoff_hz: f64, order: usize, key: &str) -> Result<()> {
    if !(cutoff_hz.is_finite() && cutoff_hz > 0.0 && (1..=MAX_FILTER_ORDER).contains(&order)) {
        return Err(Error::InvalidModel(format!(
            "\"{key}\" needs a positive finite cut-off and an order in 1..={MAX_FILTER_ORDER} (got {cutoff_hz} Hz, order {order})"
        )));
    }
    Ok(())
}

/// The kind of [`FittedModel::OperatorCascade`].
pub const OPERATOR_CASCADE_KIND: &str = "operator_cascade";

/// An operator cascade from its file: the structure from `operator`, every value from
/// `parameters` (validated by the family's constructor).
fn operator_cascade_from_file(file: &ModelFile) -> Result<FittedModel> {
    let structure = file.operator.clone().ok_or_else(|| {
        Error::InvalidModel(
            "an operator_cascade model needs \"operator\" (family and structure)".into(),
        )
    })?;
    let operator: OperatorModel = serde_json::from_value(structure).map_err(|e| {
        Error::InvalidModel(format!("the operator of the operator_cascade model: {e}"))
    })?;
    let delay = file
        .delay
        .ok_or_else(|| Error::InvalidModel("an operator_cascade model needs \"delay\"".into()))?;
    let b = coefficients(file, 'b')?;
    let a = coefficients(file, 'a')?;
    if b.is_empty() || b[0].value != 1.0 {
        return Err(Error::InvalidModel(
            "an operator_cascade model needs b1 = 1 (the gain sits in the operator)".into(),
        ));
    }
    let linear = LinearBlock::new(
        a.iter().map(|e| e.value).collect(),
        b.iter().map(|e| e.value).collect(),
        delay,
    )?;
    let template = OperatorCascade::new(operator, linear)?;
    let mut values = Vec::new();
    let mut std = Vec::new();
    for name in template.parameters().names() {
        let e = record(file, &name)?;
        values.push(e.value);
        std.push(e.std_or_nan());
    }
    Ok(FittedModel::OperatorCascade {
        model: template.with_values(&values)?,
        std,
    })
}

fn hysteresis_records(model: &ColemanHodgdon, std: &[f64]) -> Vec<ParameterRecord> {
    model
        .form()
        .parameter_names()
        .iter()
        .zip(model.params().iter().zip(std))
        .map(|(name, (v, s))| ParameterRecord::of(&Parameter::new(*name, *v), *s))
        .collect()
}

fn cascade_records(model: &HysteresisCascade, std: &[f64]) -> Vec<ParameterRecord> {
    let nh = model.hysteresis.form().n_params();
    let nb = model.linear.nb();
    let mut records = hysteresis_records(&model.hysteresis, &std[..nh]);
    records.push(ParameterRecord::of(
        &Parameter::new("b1", 1.0).fixed(true),
        f64::NAN,
    ));
    let b = model.linear.b()[1..].iter().zip(&std[nh..nh + nb - 1]);
    records
        .extend(b.enumerate().map(|(j, (v, s))| {
            ParameterRecord::of(&Parameter::new(format!("b{}", j + 2), *v), *s)
        }));
    let a = model.linear.a().iter().zip(&std[nh + nb - 1..]);
    records
        .extend(a.enumerate().map(|(i, (v, s))| {
            ParameterRecord::of(&Parameter::new(format!("a{}", i + 1), *v), *s)
        }));
    records
}

fn record<'a>(file: &'a ModelFile, name: &str) -> Result<&'a ParameterRecord> {
    file.parameters
        .iter()
        .find(|p| p.name == name)
        .ok_or_else(|| {
            Error::InvalidModel(format!(
                "parameter '{name}' is missing from the {} model",
                file.kind
            ))
        })
}

/// The coefficients `<letter>1`, `<letter>2`, … in order (none missing in between).
fn coefficients(file: &ModelFile, letter: char) -> Result<Vec<ParameterRecord>> {
    let mut found: Vec<(usize, &ParameterRecord)> = file
        .parameters
        .iter()
        .filter_map(|p| {
            let rest = p.name.strip_prefix(letter)?;
            rest.parse::<usize>().ok().map(|k| (k, p))
        })
        .collect();
    found.sort_by_key(|(k, _)| *k);
    for (i, (k, _)) in found.iter().enumerate() {
        if *k != i + 1 {
            return Err(Error::InvalidModel(format!(
                "coefficient {letter}{} is missing from the {} model",
                i + 1,
                file.kind
            )));
        }
    }
    Ok(found.into_iter().map(|(_, p)| p.clone()).collect())
}
