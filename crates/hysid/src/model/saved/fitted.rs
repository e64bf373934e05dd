//! The fitted model ([`FittedModel`]): what an estimator returns and `hysid simulate` loads,
//! able to simulate and predict, saved by [`FittedModel::to_file`] and read back by
//! [`FittedModel::from_file`] through the registry of kinds ([`crate::model::kinds`]).

use super::{check_inverse_dynamics, check_prefilter, ModelFile, MODEL_SCHEMA};
use crate::model::greybox::native::Evaluator;
use crate::model::kinds::equations::FittedEquations;
use crate::model::kinds::grey_box::FittedGreyBox;
use crate::model::kinds::operator::FittedHysteresisOperator;
use crate::model::kinds::{self, fitted_kinds, FittedKind};
use crate::model::operators::{InitialStateUsed, OperatorModel};
use crate::model::record_filters::{InverseDynamics, Prefilter, RigidBodyValues};
use crate::{Error, Result};
use std::path::Path;

/// Generates [`FittedModel`] and its dispatch to each kind ([`FittedModel::as_kind`]) from
/// the list of fitted kinds ([`crate::model::kinds`]).
macro_rules! define_fitted_model {
    ($($(#[$doc:meta])* $variant:ident => $fitted:ty),* $(,)?) => {
        /// A fitted model that can simulate: a model of one kind (a struct of its module of
        /// [`crate::model::kinds`], implementing [`FittedKind`]), or one of them behind the
        /// processing its records had in the fit.
        #[derive(Clone, Debug, PartialEq)]
        pub enum FittedModel {
            $($(#[$doc])* $variant($fitted),)*
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

        impl FittedModel {
            /// What this is: a model of one kind, or one behind its record processing.
            fn view(&self) -> View<'_> {
                match self {
                    $(FittedModel::$variant(m) => View::Kind(m),)*
                    FittedModel::Prefiltered { model, prefilter } => {
                        View::Prefiltered(model, prefilter)
                    }
                    FittedModel::InverseDynamics {
                        model,
                        preprocessing,
                    } => View::InverseDynamics(model, preprocessing),
                }
            }

            /// The model of one kind this is, None for the record-processing wrappers
            /// ([`FittedModel::Prefiltered`], [`FittedModel::InverseDynamics`]).
            fn as_kind_mut(&mut self) -> Option<&mut dyn FittedKind> {
                match self {
                    $(FittedModel::$variant(m) => Some(m),)*
                    FittedModel::Prefiltered { .. } | FittedModel::InverseDynamics { .. } => None,
                }
            }
        }
    };
}

/// A [`FittedModel`] seen as a model of one kind or as one of the wrappers with its inner
/// model: the one match every method dispatches on.
pub(crate) enum View<'a> {
    /// A model of one kind.
    Kind(&'a dyn FittedKind),
    /// [`FittedModel::Prefiltered`]: the inner model and the filter.
    Prefiltered(&'a FittedModel, &'a Prefilter),
    /// [`FittedModel::InverseDynamics`]: the rigid body and the preprocessing.
    InverseDynamics(&'a FittedModel, &'a InverseDynamics),
}

fitted_kinds!(define_fitted_model);

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
    /// [`InitialOutput::Measured`](crate::model::coleman_hodgdon::InitialOutput::Measured)). Errors when α·|Δx| > 1 or the simulation diverges
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
        match self.view() {
            View::Kind(kind) => kind.simulate(inputs, ts, y0),
            View::Prefiltered(model, prefilter) => {
                let filtered = inputs
                    .iter()
                    .map(|x| prefilter.apply(x, ts))
                    .collect::<Result<Vec<_>>>()?;
                model.simulate_unchecked(&slices(&filtered), ts, y0)
            }
            View::InverseDynamics(_, preprocessing) => Ok(vec![
                preprocessing
                    .predict(&self.rigid_body()?, kinds::first(inputs)?, ts)?
                    .1,
            ]),
        }
    }

    /// The model of one kind this is, None for the record-processing wrappers
    /// ([`FittedModel::Prefiltered`], [`FittedModel::InverseDynamics`]).
    pub fn as_kind(&self) -> Option<&dyn FittedKind> {
        match self.view() {
            View::Kind(kind) => Some(kind),
            View::Prefiltered(..) | View::InverseDynamics(..) => None,
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
            FittedModel::GreyBox(FittedGreyBox {
                kind, parameters, ..
            }) if kind == "rigid_body" => parameters,
            other => {
                return Err(Error::UnsupportedKind {
                    kind: other.to_file().kind().to_string(),
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
            FittedModel::GreyBox(FittedGreyBox {
                parameters,
                std,
                simulation,
                initial_state,
                ..
            }) => FittedModel::Equations(FittedEquations {
                equations: equations.to_string(),
                parameters,
                std,
                simulation,
                initial_state,
                evaluator: Evaluator::Auto,
            }),
            other => other,
        }
    }

    /// The same model with its equation tapes run by `evaluator` (an equation model, also
    /// inside a pre-filtered one); other models unchanged.
    pub fn with_evaluator(mut self, evaluator: Evaluator) -> Self {
        self.set_evaluator(evaluator);
        self
    }

    /// The same model sampled every `to` seconds instead of the `from` it was fitted at: a
    /// continuous-time grey-box or equation model with its integration re-stepped
    /// ([`Simulation::resampled`](crate::model::greybox::Simulation::resampled)); None for
    /// a model whose step is tied to its sample time (a discrete-time model, an operator, a
    /// cascade, a pre-filtered record or an inverse-dynamics regression).
    pub fn resampled(&self, from: f64, to: f64) -> Option<FittedModel> {
        self.as_kind()?.resampled(from, to)
    }

    /// Whether its output depends only on the sequence of its inputs, not on when they came
    /// (a hysteresis operator, the Coleman–Hodgdon hysteresis): its records' time columns
    /// need only increase ([`TimeSteps::Ordered`](crate::data::TimeSteps::Ordered)). False
    /// for the wrappers, whose record processing runs in time.
    pub fn rate_independent(&self) -> bool {
        self.as_kind().is_some_and(|k| k.rate_independent())
    }

    /// [`Self::with_evaluator`] in place.
    fn set_evaluator(&mut self, evaluator: Evaluator) {
        match self {
            FittedModel::Prefiltered { model, .. } => model.set_evaluator(evaluator),
            FittedModel::InverseDynamics { .. } => {}
            kind => {
                if let Some(kind) = kind.as_kind_mut() {
                    kind.set_evaluator(evaluator)
                }
            }
        }
    }

    /// The model file of this model (each kind saved by its module of
    /// [`crate::model::kinds`]).
    pub fn to_file(&self) -> ModelFile {
        match self.view() {
            View::Kind(kind) => ModelFile::new(kind.saved()),
            View::Prefiltered(model, prefilter) => ModelFile {
                prefilter: Some(*prefilter),
                ..model.to_file()
            },
            View::InverseDynamics(model, preprocessing) => ModelFile {
                inverse_dynamics: Some(*preprocessing),
                ..model.to_file()
            },
        }
    }

    /// The fitted model of an operator with standard deviations `std` (NaN: none).
    pub fn operator(model: OperatorModel, std: Vec<f64>) -> Self {
        FittedModel::Operator(FittedHysteresisOperator {
            family: model.family().name(),
            model,
            std,
            initial_state: None,
            history_turn: None,
        })
    }

    /// The same model starting from `state`, a declared history turning at `turn` (an
    /// operator; other kinds are returned as they are).
    pub fn with_initial_state(self, state: Option<InitialStateUsed>, turn: Option<f64>) -> Self {
        match self {
            FittedModel::Operator(op) => FittedModel::Operator(FittedHysteresisOperator {
                initial_state: state,
                history_turn: turn,
                ..op
            }),
            other => other,
        }
    }

    /// The declared history (`descending`, `ascending`) this model starts after that its
    /// compensator does not run: one saved without its turn (files of earlier versions);
    /// None otherwise
    /// ([`crate::model::OperatorModel::history_reaches_the_inverse`]).
    pub fn history_beyond_the_inverse(&self) -> Option<InitialStateUsed> {
        let FittedModel::Operator(op) = self else {
            return None;
        };
        let history = op.history()?;
        (!op.model.history_reaches_the_inverse(Some(history))).then_some(history.state)
    }

    /// Rebuilds a fitted model from a model file, checking every value.
    pub fn from_file(file: &ModelFile) -> Result<Self> {
        if file.schema != MODEL_SCHEMA {
            return Err(Error::InvalidModel(format!(
                "schema '{}' is not {MODEL_SCHEMA}; save the model again with this version",
                file.schema
            )));
        }
        if let Some(p) = file.parameters().iter().find(|p| !p.value.is_finite()) {
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
        file.model.fitted()
    }

    /// Reads a model file, or the `model` object of a report.
    pub fn load(path: &Path) -> Result<Self> {
        let file = ModelFile::read(path)?;
        Self::from_file(&file).map_err(|e| Error::ModelFile {
            path: path.to_path_buf(),
            message: e.to_string(),
        })
    }
}

/// The slices of `signals`.
fn slices(signals: &[Vec<f64>]) -> Vec<&[f64]> {
    signals.iter().map(Vec::as_slice).collect()
}
