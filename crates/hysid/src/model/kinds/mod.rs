//! The registry of model kinds: **the one list** (`model_kinds!`) from which everything that
//! exists once per kind of `hysid.model/1` is generated.
//!
//! A kind is one module of this directory: the keys of its model file (`File`, a serde struct
//! whose required keys are required by the type and which refuses any other key), how a file
//! becomes a fitted model, checking every value ([`ModelKind::fitted`]), and how a fitted model
//! is saved again (the module's `saved`, which [`FittedModel::to_file`] calls). The list
//! generates:
//!
//! * [`SavedModel`], the enum of every kind's file tagged by `kind` (its serde form and its
//!   JSON Schema, `docs/schema/hysid.model.v1.json`), with the user's own grey-box model
//!   ([`SavedModel::UserGreyBox`], written, never read) appended;
//! * [`MODEL_KINDS`], the names this version reads (the error of an unknown kind lists them);
//! * the reading of a file by its kind: the kind's `File` read with `serde_path_to_error`, so
//!   that the error names the path of the bad key (`"parameters"[2]."value"`), and the
//!   dispatch from a file to its fitted model ([`SavedModel::fitted`]).
//!
//! The run-time half has its own list, `fitted_kinds!`: a fitted model of each kind is a
//! struct of its module (`FittedHysteresisOperator`, `FittedHysteresis`, …) implementing
//! [`FittedKind`] — how it simulates, steps one sample at a time, compensates and is saved —
//! and the list generates the [`FittedModel`] enum (one variant per struct, besides the two
//! record-processing wrappers), its dispatch ([`FittedModel::as_kind`]) and, in the export
//! layer, the dispatch to each kind's program (`export::kinds`).
//!
//! A new kind is its module here, one line of `model_kinds!`, one of `fitted_kinds!` and its
//! export program (see `docs/architecture.md`, "A new model kind").

pub mod ch_cascade;
pub mod coleman_hodgdon;
pub mod equations;
pub mod grey_box;
pub mod operator;
pub mod operator_cascade;

use crate::model::compensate::Compensation;
use crate::model::greybox::native::Evaluator;
use crate::model::saved::{FittedModel, ParameterRecord, SimulationSpec};
use crate::model::stream::{Compensator, Stepper};
use crate::{Error, Result};
use schemars::JsonSchema;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::fmt::Debug;

/// What a kind of `hysid.model/1` knows: its file's keys and how they become a fitted model.
pub trait ModelKind {
    /// The keys of the kind's model file besides `kind` (its serde form).
    type File: Clone + Debug + PartialEq + Serialize + DeserializeOwned + JsonSchema;

    /// The file's parameters, in the model's order.
    fn parameters(file: &Self::File) -> &[ParameterRecord];

    /// The fitted model of a file of the kind, checking every value (the envelope, the
    /// schema tag and the record processing, are checked by [`FittedModel::from_file`]).
    fn fitted(file: &Self::File) -> Result<FittedModel>;
}

/// What a fitted model of one kind does at run time. Each kind's module implements it for
/// its `Fitted…` struct, which `fitted_kinds!` makes a variant of [`FittedModel`]; the
/// methods of [`FittedModel`] dispatch to it (after the record processing of a wrapper).
pub trait FittedKind {
    /// The model of its model file (the kind's [`SavedModel`] variant).
    fn saved(&self) -> SavedModel;

    /// The outputs for the input channels `inputs` sampled every `ts`; `y0` is the measured
    /// initial output (see [`FittedModel::simulate`], which also refuses a non-finite one).
    fn simulate(&self, inputs: &[&[f64]], ts: f64, y0: Option<f64>) -> Result<Vec<Vec<f64>>>;

    /// The model one sample at a time, `ts` and `y0` as for [`FittedKind::simulate`]
    /// ([`FittedModel::stepper`]).
    fn stepper(&self, ts: f64, y0: Option<f64>) -> Result<Box<dyn Stepper>>;

    /// Its compensator one sample at a time ([`FittedModel::compensator`]); by default none
    /// ([`Error::NotInvertible`]).
    fn compensator(&self) -> Result<Box<dyn Compensator>> {
        Err(not_invertible(self.saved().kind()))
    }

    /// The input that makes it follow `reference`, unlimited
    /// ([`crate::model::compensate::compensate`], which checks the reference first); by
    /// default none ([`Error::NotInvertible`]).
    fn compensate(&self, reference: &[f64]) -> Result<Compensation> {
        let _ = reference;
        Err(not_invertible(self.saved().kind()))
    }

    /// Why its one-sample step differs from its batch simulation, if it does
    /// ([`FittedModel::streaming_differs`]); by default they agree.
    fn streaming_differs(&self) -> Option<String> {
        None
    }

    /// Runs its equation tapes by `evaluator` ([`FittedModel::with_evaluator`]); by default
    /// it has none.
    fn set_evaluator(&mut self, evaluator: Evaluator) {
        let _ = evaluator;
    }

    /// Whether its output depends only on the sequence of its inputs
    /// ([`FittedModel::rate_independent`]); by default not.
    fn rate_independent(&self) -> bool {
        false
    }

    /// The same model sampled every `to` seconds instead of the `from` it was fitted at
    /// ([`FittedModel::resampled`]): a continuous-time model re-steps its integration
    /// ([`Simulation::resampled`](crate::model::greybox::Simulation::resampled)); None, the
    /// default, for a model whose step is its sample time (a discrete-time model, an
    /// operator, a linear block).
    fn resampled(&self, from: f64, to: f64) -> Option<FittedModel> {
        let _ = (from, to);
        None
    }
}

/// The refusal to compensate a model of kind `kind`.
pub(crate) fn not_invertible(kind: &str) -> Error {
    Error::NotInvertible {
        kind: kind.to_string(),
        reason: "compensation inverts hysteresis operators, the Coleman–Hodgdon \
                 hysteresis alone and operator cascades with a minimum-phase linear \
                 block; identify one of those"
            .into(),
    }
}

/// The first input channel of `inputs` (the only one of a single-input kind).
pub(crate) fn first<'a>(inputs: &[&'a [f64]]) -> Result<&'a [f64]> {
    inputs
        .first()
        .copied()
        .ok_or_else(|| Error::ModelMismatch("no input channel given".into()))
}

/// The one list of fitted model kinds: calls `$callback! { Variant => Type, … }` with each
/// [`FittedModel`] variant (its doc comment first) and the struct it holds, which implements
/// [`FittedKind`]. The two record-processing wrappers (`Prefiltered`, `InverseDynamics`) are
/// not kinds and are not listed. Adding a kind is adding its line here (and in
/// `model_kinds!` for its file).
macro_rules! fitted_kinds {
    ($callback:ident) => {
        $callback! {
            /// The Coleman–Hodgdon hysteresis alone.
            Hysteresis => $crate::model::kinds::coleman_hodgdon::FittedHysteresis,
            /// The Coleman–Hodgdon cascade.
            Cascade => $crate::model::kinds::ch_cascade::FittedCascade,
            /// A built-in grey-box model.
            GreyBox => $crate::model::kinds::grey_box::FittedGreyBox,
            /// Any hysteresis operator followed by a linear block.
            OperatorCascade => $crate::model::kinds::operator_cascade::FittedOperatorCascade,
            /// A grey-box model written as equations (`hysid-equations`).
            Equations => $crate::model::kinds::equations::FittedEquations,
            /// A hysteresis operator of one of the families of [`crate::model::operators`].
            Operator => $crate::model::kinds::operator::FittedHysteresisOperator,
        }
    };
}
pub(crate) use fitted_kinds;

/// The one list of model kinds: calls `$callback! { Variant = "kind" => KindType, … }` with
/// each kind's [`SavedModel`] variant (its doc comment first), the `kind` key naming it and
/// the type implementing [`ModelKind`], in the order of the module docs of
/// [`crate::model::saved`]. Adding a kind is adding its line here.
macro_rules! model_kinds {
    ($callback:ident) => {
        $callback! {
            /// The Coleman–Hodgdon hysteresis alone.
            ColemanHodgdon = "coleman_hodgdon" => coleman_hodgdon::ColemanHodgdonKind,
            /// The Coleman–Hodgdon hysteresis followed by a linear block (Vörös 2015).
            ChCascade = "ch_cascade" => ch_cascade::ChCascadeKind,
            /// A hysteresis operator followed by a linear block.
            OperatorCascade = "operator_cascade" => operator_cascade::OperatorCascadeKind,
            /// The built-in Bouc–Wen oscillator (`GreyBoxKind::BoucWen`).
            BoucWen = "bouc_wen" => grey_box::BoucWenKind,
            /// The built-in rigid body (`GreyBoxKind::RigidBody`).
            RigidBody = "rigid_body" => grey_box::RigidBodyKind,
            /// The built-in actuator, saddle fixed (`GreyBoxKind::ActuatorFixed`).
            ActuatorFixed = "actuator_fixed" => grey_box::ActuatorFixedKind,
            /// The built-in actuator, saddle free (`GreyBoxKind::ActuatorFree`).
            ActuatorFree = "actuator_free" => grey_box::ActuatorFreeKind,
            /// A grey-box model written as equations (`hysid-equations`).
            Equations = "equations" => equations::EquationsKind,
            /// A hysteresis operator of one family.
            Operator = "operator" => operator::OperatorKind,
        }
    };
}

/// Generates [`SavedModel`], [`MODEL_KINDS`] and the dispatch by kind from the list.
macro_rules! define_kinds {
    ($($(#[$doc:meta])* $variant:ident = $name:literal => $kind:ty),* $(,)?) => {
        /// A saved model by its kind (the `kind` key of `hysid.model/1`): each variant holds
        /// the kind's file, the parameters in the model's order and the structure keys the
        /// kind needs (see the module docs of [`crate::model::saved`]). Each kind's required
        /// keys are required here; the optional ones have the documented defaults.
        #[derive(Clone, Debug, PartialEq, Serialize, JsonSchema)]
        #[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
        pub enum SavedModel {
            $($(#[$doc])* #[serde(rename = $name)] $variant(<$kind as ModelKind>::File),)*
            /// A grey-box model of the library's user (its own [`StateSpaceModel`], e.g.
            /// Python callbacks), under the kind the model gives itself: written into
            /// reports, never read back (no file can rebuild it).
            ///
            /// [`StateSpaceModel`]: crate::model::greybox::StateSpaceModel
            #[serde(untagged)]
            #[schemars(skip)]
            UserGreyBox {
                /// The model's own kind.
                kind: String,
                /// Its parameters.
                parameters: Vec<ParameterRecord>,
                /// How it is simulated.
                simulation: SimulationSpec,
                /// Its initial state.
                initial_state: Vec<f64>,
            },
        }

        /// The kinds this version reads, in the order of [`SavedModel`].
        pub const MODEL_KINDS: [&str; [$($name),*].len()] = [$($name),*];

        impl SavedModel {
            /// The kind (the `kind` key).
            pub fn kind(&self) -> &str {
                match self {
                    $(SavedModel::$variant(_) => $name,)*
                    SavedModel::UserGreyBox { kind, .. } => kind,
                }
            }

            /// The parameters in the model's order.
            pub fn parameters(&self) -> &[ParameterRecord] {
                match self {
                    $(SavedModel::$variant(file) => <$kind as ModelKind>::parameters(file),)*
                    SavedModel::UserGreyBox { parameters, .. } => parameters,
                }
            }

            /// The saved model of kind `kind` from the file's other keys `object` (without
            /// `kind`); the error names the path of the bad key, not the kind.
            pub fn from_keys(
                kind: &str,
                object: serde_json::Map<String, serde_json::Value>,
            ) -> Result<Self> {
                match kind {
                    $($name => read::<$kind>(object).map(SavedModel::$variant),)*
                    _ => Err(unknown_kind(kind, "")),
                }
            }

            /// The fitted model of this file, checking every value ([`ModelKind::fitted`]).
            pub fn fitted(&self) -> Result<FittedModel> {
                match self {
                    $(SavedModel::$variant(file) => <$kind as ModelKind>::fitted(file),)*
                    SavedModel::UserGreyBox { kind, .. } => Err(unknown_kind(
                        kind,
                        " (a grey-box model of your own is rebuilt from its code, not from a file)",
                    )),
                }
            }
        }
    };
}

model_kinds!(define_kinds);

/// The error of a kind this version does not read, listing those it does, then `note`.
pub(crate) fn unknown_kind(kind: &str, note: &str) -> Error {
    Error::InvalidModel(format!(
        "unknown model kind '{kind}'; this version knows {}{note}",
        MODEL_KINDS.join(", ")
    ))
}

/// The file of kind `K` from its keys, the error naming the path of the bad key:
/// `"delay": invalid type: …`, `"parameters"[0]: missing field `value``; a missing or unknown
/// key at the top is named by serde itself.
fn read<K: ModelKind>(object: serde_json::Map<String, serde_json::Value>) -> Result<K::File> {
    serde_path_to_error::deserialize(serde_json::Value::Object(object)).map_err(|e| {
        let mut path = String::new();
        for segment in e.path().iter() {
            match segment {
                serde_path_to_error::Segment::Seq { index } => path += &format!("[{index}]"),
                serde_path_to_error::Segment::Map { key } if path.is_empty() => {
                    path += &format!("\"{key}\"")
                }
                serde_path_to_error::Segment::Map { key } => path += &format!(".\"{key}\""),
                _ => path += ".?",
            }
        }
        match path.is_empty() {
            true => Error::InvalidModel(e.inner().to_string()),
            false => Error::InvalidModel(format!("{path}: {}", e.inner())),
        }
    })
}

/// The parameter records of a model file of kind `kind`, looked up by name.
pub(crate) struct Records<'a> {
    /// The kind, for the errors.
    pub kind: &'a str,
    /// The records in the file's order.
    pub list: &'a [ParameterRecord],
}

impl<'a> Records<'a> {
    /// The record called `name`.
    pub fn get(&self, name: &str) -> Result<&'a ParameterRecord> {
        self.list.iter().find(|p| p.name == name).ok_or_else(|| {
            Error::InvalidModel(format!(
                "parameter '{name}' is missing from the {} model",
                self.kind
            ))
        })
    }

    /// The coefficients `<letter>1`, `<letter>2`, … in order (none missing in between).
    pub fn coefficients(&self, letter: char) -> Result<Vec<ParameterRecord>> {
        let mut found: Vec<(usize, &ParameterRecord)> = self
            .list
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
                    self.kind
                )));
            }
        }
        Ok(found.into_iter().map(|(_, p)| p.clone()).collect())
    }
}

/// The records of `parameters` with standard deviations `std`.
pub(crate) fn records(
    parameters: &crate::model::ParameterSet,
    std: &[f64],
) -> Vec<ParameterRecord> {
    parameters
        .iter()
        .zip(std)
        .map(|(p, s)| ParameterRecord::of(p, *s))
        .collect()
}
