//! Fitted models and the saved-model file `hysid.model/1`.
//!
//! A fitted model is what an estimator returns and what `hysid simulate` loads: the model with
//! its parameter values, standard deviations, units, bounds and fixed flags. The same JSON
//! object is the `model` key of every report (`hysid.report/1`), so a report is also a model
//! file:
//!
//! ```json
//! {"schema": "hysid.model/1", "kind": "ch_cascade",
//!  "parameters": [
//!    {"name": "alpha", "value": 0.3, "std": 0.001, "unit": "", "fixed": false,
//!     "lower": 0.0, "upper": null},
//!    {"name": "b1", "value": 1.0, "std": null, "unit": "", "fixed": true,
//!     "lower": null, "upper": null}, …],
//!  "hysteresis": "ch4", "delay": 1}
//! ```
//!
//! `parameters` is a flat list in the model's order: `std` is null where the parameter was not
//! estimated (fixed, or unknown), `lower`/`upper` null where unbounded. The kinds are the
//! variants of [`SavedModel`], a serde enum tagged by `kind` whose variants hold each kind's
//! parameters and structure keys, so a key the kind needs is required by the type and any
//! other key is refused, naming it ([`ModelFile::from_object`]). Kinds and their structure
//! keys:
//!
//! | kind | structure | parameters |
//! |---|---|---|
//! | `coleman_hodgdon` | `hysteresis` (`ch4`/`ch6`), `initial_output` (`measured`/`zero`) | α, m₁, c₁, d (ch6: and m₂, c₂) |
//! | `ch_cascade` | `hysteresis`, `delay` | hysteresis, then b₁ (fixed at 1) … b_m, a₁ … a_n |
//! | `operator_cascade` | `operator` (the family and its structure: thresholds, grid, orientation, …), `delay` | the operator's (prefixed `op_` where they collide with a₁…, b₁…), then a₁ … a_n, b₁ (fixed at 1) … b_m |
//! | `bouc_wen`, `rigid_body`, `actuator_fixed`, `actuator_free` | `simulation`, `initial_state` | the grey-box model's |
//! | `equations` | `equations` (the equation file's text), `simulation`, `initial_state` | the file's `[parameters]` |
//! | `operator` | `family` (an operator family of the registry, `model::operators::Family`), `operator` (the operator's full structure: thresholds, weights, grid, orientation, initial state) | the family's, named as in the literature |
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
use crate::model::greybox::models::GreyBoxKind;
use crate::model::greybox::native::Evaluator;
use crate::model::greybox::{models, InputInterpolation, Integrator, Simulation};
use crate::model::operators::initial_state;
use crate::model::operators::{InitialStateUsed, OperatorModel};
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

/// The saved-model file `hysid.model/1` (see the module docs): the schema tag, the model
/// (its kind, parameters and structure, [`SavedModel`]) and the processing its fit applied
/// to the records.
///
/// Written as one flat JSON object, `schema`, `kind`, `parameters`, the kind's structure
/// keys, then `prefilter` and `inverse_dynamics` when set. Read strictly: a key that is not
/// the kind's is refused, naming it (a `null` stands for an absent key, as files written by
/// hand spell out keys that do not apply), and so is a key given twice.
// Serialize and the JSON Schema are derived (`deny_unknown_fields` gives the schema its
// `unevaluatedProperties: false`); Deserialize is written out (`ModelFile::from_object`), as
// serde's `flatten` would let any key through.
#[derive(Clone, Debug, PartialEq, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// Always `hysid.model/1`.
    pub schema: String,
    /// The model: its kind, parameters and structure.
    #[serde(flatten)]
    pub model: SavedModel,
    /// The pre-filter the model was fitted with (the actuator's step 3): `hysid simulate`
    /// filters input and measured output alike before simulating.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prefilter: Option<Prefilter>,
    /// The preprocessing of an inverse-dynamics fit (kind `rigid_body` from `rigid-body ls`):
    /// the model predicts the drive signal from the measured position, as the fit did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inverse_dynamics: Option<InverseDynamics>,
    /// The sample time in seconds of the data the model was fitted on (absent in files of
    /// earlier versions, and for models fitted without one). `hysid export` takes the
    /// exported step's period from it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_time: Option<f64>,
    /// The names of the data columns the model was fitted on (absent in files of earlier
    /// versions): an export names its inputs and outputs after them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub columns: Option<Columns>,
    /// \[min, max\] of each input of the data the model was fitted on, in the model's order
    /// of inputs (absent in files of earlier versions): a compensator's default command
    /// limits ([`crate::model::limits`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub input_range: Option<Vec<[f64; 2]>>,
}

/// The data columns a model was fitted on, in the model's order of inputs and outputs.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Columns {
    /// The input columns (`--input`), one per model input.
    pub inputs: Vec<String>,
    /// The measured output columns (`--output`), one per model output.
    pub outputs: Vec<String>,
}

/// A saved model by its kind (the `kind` key of `hysid.model/1`): the parameters in the
/// model's order and the structure keys the kind needs (see the module docs). Each kind's
/// required keys are required here; the optional ones have the documented defaults.
// `parameters` sits in every variant, right after the tag, so that a file's keys come in the
// order every version has written them: `schema`, `kind`, `parameters`, the structure.
#[derive(Clone, Debug, PartialEq, Serialize, JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum SavedModel {
    /// The Coleman–Hodgdon hysteresis alone.
    ColemanHodgdon {
        /// alpha, m1, c1, d (ch6: alpha, m1, m2, c1, c2, d).
        parameters: Vec<ParameterRecord>,
        /// `ch4` or `ch6`.
        hysteresis: ChForm,
        /// Where the output of the hysteresis starts (`measured` when absent).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        initial_output: Option<InitialOutput>,
    },
    /// The Coleman–Hodgdon hysteresis followed by a linear block (Vörös 2015).
    ChCascade {
        /// The hysteresis parameters, then b1 (fixed at 1) … bm, a1 … an.
        parameters: Vec<ParameterRecord>,
        /// `ch4` or `ch6`.
        hysteresis: ChForm,
        /// Delay k of the linear block.
        delay: usize,
    },
    /// A hysteresis operator followed by a linear block.
    OperatorCascade {
        /// The operator's parameters (prefixed `op_` where they collide with a1…, b1…),
        /// then a1 … an, b1 (fixed at 1) … bm.
        parameters: Vec<ParameterRecord>,
        /// Delay k of the linear block.
        delay: usize,
        /// `{"family": …, "operator": {…}}`: the operator family and its structure, whose
        /// values are read from `parameters`. Checked on reading.
        operator: serde_json::Value,
    },
    /// The built-in Bouc–Wen oscillator (`GreyBoxKind::BoucWen`).
    BoucWen(GreyBoxFile),
    /// The built-in rigid body (`GreyBoxKind::RigidBody`).
    RigidBody(GreyBoxFile),
    /// The built-in actuator, saddle fixed (`GreyBoxKind::ActuatorFixed`).
    ActuatorFixed(GreyBoxFile),
    /// The built-in actuator, saddle free (`GreyBoxKind::ActuatorFree`).
    ActuatorFree(GreyBoxFile),
    /// A grey-box model written as equations (`hysid-equations`).
    Equations {
        /// The equation file's `[parameters]`, in its order.
        parameters: Vec<ParameterRecord>,
        /// How the model is simulated (the default RK4 when absent).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        simulation: Option<SimulationSpec>,
        /// Its initial state (the text's `[initial]` when absent).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        initial_state: Option<Vec<f64>>,
        /// The equation file's text, so that the saved model is self-contained.
        equations: String,
    },
    /// A hysteresis operator of one family.
    Operator {
        /// The family's parameters, named as in the literature.
        parameters: Vec<ParameterRecord>,
        /// The family's name, one of the registry's operator families (`pi`, `preisach`,
        /// `kp`, …: `hysid::model::operators::Family`).
        family: String,
        /// The operator's full structure: thresholds, weights, grids, orientation and
        /// initial state, as the family defines them. Checked on reading.
        operator: serde_json::Value,
        /// The initial state the operator starts from (`demagnetised`, `descending`,
        /// `ascending`, `estimated`: `hysid::model::operators::InitialStateUsed`); a declared
        /// history is re-applied at every record's first input. Absent: the structure's own
        /// state, as before the field existed.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        initial_state: Option<InitialStateUsed>,
    },
    /// A grey-box model of the library's user (its own [`StateSpaceModel`], e.g. Python
    /// callbacks), under the kind the model gives itself: written into reports, never read
    /// back (no file can rebuild it).
    ///
    /// [`StateSpaceModel`]: crate::model::greybox::StateSpaceModel
    #[serde(untagged, skip_deserializing)]
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

/// How [`SavedModel`] is read: the same enum without [`SavedModel::UserGreyBox`], which is
/// never read back and, as an untagged variant in the derived reader, would turn every error
/// of the tagged ones (a missing key, an unknown one) into "did not match any variant". The
/// compiler checks that each variant builds its [`SavedModel`] twin field by field.
#[derive(Deserialize)]
#[serde(
    remote = "SavedModel",
    tag = "kind",
    rename_all = "snake_case",
    deny_unknown_fields
)]
enum SavedModelReader {
    ColemanHodgdon {
        parameters: Vec<ParameterRecord>,
        hysteresis: ChForm,
        #[serde(default)]
        initial_output: Option<InitialOutput>,
    },
    ChCascade {
        parameters: Vec<ParameterRecord>,
        hysteresis: ChForm,
        delay: usize,
    },
    OperatorCascade {
        parameters: Vec<ParameterRecord>,
        delay: usize,
        operator: serde_json::Value,
    },
    BoucWen(GreyBoxFile),
    RigidBody(GreyBoxFile),
    ActuatorFixed(GreyBoxFile),
    ActuatorFree(GreyBoxFile),
    Equations {
        parameters: Vec<ParameterRecord>,
        #[serde(default)]
        simulation: Option<SimulationSpec>,
        #[serde(default)]
        initial_state: Option<Vec<f64>>,
        equations: String,
    },
    Operator {
        parameters: Vec<ParameterRecord>,
        family: String,
        operator: serde_json::Value,
        #[serde(default)]
        initial_state: Option<InitialStateUsed>,
    },
}

impl<'de> Deserialize<'de> for SavedModel {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        SavedModelReader::deserialize(deserializer)
    }
}

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

/// The kinds this version reads, in the order of [`SavedModel`].
pub const MODEL_KINDS: [&str; 9] = [
    "coleman_hodgdon",
    "ch_cascade",
    OPERATOR_CASCADE_KIND,
    "bouc_wen",
    "rigid_body",
    "actuator_fixed",
    "actuator_free",
    EQUATIONS_KIND,
    OPERATOR_KIND,
];

/// The keys of `hysid.model/1` besides `schema` and `kind`: a `null` for any of them reads as
/// the key left out.
const MODEL_KEYS: [&str; 11] = [
    "parameters",
    "hysteresis",
    "delay",
    "initial_output",
    "simulation",
    "initial_state",
    "equations",
    "family",
    "operator",
    "prefilter",
    "inverse_dynamics",
];

impl SavedModel {
    /// The kind (the `kind` key).
    pub fn kind(&self) -> &str {
        match self {
            SavedModel::ColemanHodgdon { .. } => "coleman_hodgdon",
            SavedModel::ChCascade { .. } => "ch_cascade",
            SavedModel::OperatorCascade { .. } => OPERATOR_CASCADE_KIND,
            SavedModel::BoucWen(_) => GreyBoxKind::BoucWen.name(),
            SavedModel::RigidBody(_) => GreyBoxKind::RigidBody.name(),
            SavedModel::ActuatorFixed(_) => GreyBoxKind::ActuatorFixed.name(),
            SavedModel::ActuatorFree(_) => GreyBoxKind::ActuatorFree.name(),
            SavedModel::Equations { .. } => EQUATIONS_KIND,
            SavedModel::Operator { .. } => OPERATOR_KIND,
            SavedModel::UserGreyBox { kind, .. } => kind,
        }
    }

    /// The parameters in the model's order.
    pub fn parameters(&self) -> &[ParameterRecord] {
        match self {
            SavedModel::ColemanHodgdon { parameters, .. }
            | SavedModel::ChCascade { parameters, .. }
            | SavedModel::OperatorCascade { parameters, .. }
            | SavedModel::Equations { parameters, .. }
            | SavedModel::Operator { parameters, .. }
            | SavedModel::UserGreyBox { parameters, .. } => parameters,
            SavedModel::BoucWen(g)
            | SavedModel::RigidBody(g)
            | SavedModel::ActuatorFixed(g)
            | SavedModel::ActuatorFree(g) => &g.parameters,
        }
    }

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

impl ModelFile {
    /// The model file of `model` (schema `hysid.model/1`, no record processing).
    pub fn new(model: SavedModel) -> Self {
        Self {
            schema: MODEL_SCHEMA.into(),
            model,
            prefilter: None,
            inverse_dynamics: None,
            sample_time: None,
            columns: None,
            input_range: None,
        }
    }

    /// The file with the sample time `ts` (seconds) and the column names of the data the
    /// model was fitted on.
    pub fn with_data(mut self, ts: f64, columns: Columns) -> Self {
        self.sample_time = Some(ts);
        self.columns = Some(columns);
        self
    }

    /// The file with the input range of `data`, the data the model was fitted on
    /// (`input_range`, [`crate::model::limits::input_range_of`]).
    pub fn with_input_range(mut self, data: &crate::data::IdData) -> Self {
        self.input_range = Some(crate::model::limits::input_range_of(data));
        self
    }

    /// The default command limits of the model's compensator: its file's `input_range` of
    /// input 0, None when the file has none.
    pub fn limits(&self) -> Option<crate::model::limits::Limits> {
        crate::model::limits::Limits::of_range(self.input_range.as_deref(), 0)
    }

    /// The model kind (the `kind` key).
    pub fn kind(&self) -> &str {
        self.model.kind()
    }

    /// The parameters in the model's order.
    pub fn parameters(&self) -> &[ParameterRecord] {
        self.model.parameters()
    }

    /// The model file of a JSON object, checked key by key (see [`ModelFile`]); the error is
    /// one line naming the kind and the key.
    pub fn from_object(mut object: serde_json::Map<String, serde_json::Value>) -> Result<Self> {
        let bad = |message: String| Error::InvalidModel(message);
        object.retain(|key, value| !(value.is_null() && MODEL_KEYS.contains(&key.as_str())));
        let schema = match object.remove("schema") {
            Some(serde_json::Value::String(s)) => s,
            Some(other) => return Err(bad(format!("\"schema\" is {other}, not a string"))),
            None => return Err(bad("missing field `schema`".into())),
        };
        let kind = match object.get("kind") {
            Some(serde_json::Value::String(kind)) => kind.clone(),
            Some(other) => return Err(bad(format!("\"kind\" is {other}, not a string"))),
            None => return Err(bad("missing field `kind`".into())),
        };
        if !MODEL_KINDS.contains(&kind.as_str()) {
            return Err(bad(format!(
                "unknown model kind '{kind}'; this version knows {}",
                MODEL_KINDS.join(", ")
            )));
        }
        let prefilter = object
            .remove("prefilter")
            .map(serde_json::from_value)
            .transpose()
            .map_err(|e| bad(format!("\"prefilter\": {e}")))?;
        let inverse_dynamics = object
            .remove("inverse_dynamics")
            .map(serde_json::from_value)
            .transpose()
            .map_err(|e| bad(format!("\"inverse_dynamics\": {e}")))?;
        let sample_time = match object.remove("sample_time") {
            None | Some(serde_json::Value::Null) => None,
            Some(value) => match value.as_f64() {
                Some(ts) if ts.is_finite() && ts > 0.0 => Some(ts),
                _ => {
                    return Err(bad(format!(
                        "\"sample_time\" is {value}; give the sample time in seconds, a \
                         positive finite number"
                    )))
                }
            },
        };
        let columns = object
            .remove("columns")
            .filter(|value| !value.is_null())
            .map(serde_json::from_value::<Columns>)
            .transpose()
            .map_err(|e| bad(format!("\"columns\": {e}")))?;
        let input_range = object
            .remove("input_range")
            .filter(|value| !value.is_null())
            .map(serde_json::from_value::<Vec<[f64; 2]>>)
            .transpose()
            .map_err(|e| bad(format!("\"input_range\": {e}")))?;
        if let Some([lo, hi]) = input_range
            .iter()
            .flatten()
            .find(|[lo, hi]| !(lo.is_finite() && hi.is_finite() && lo <= hi))
        {
            return Err(bad(format!(
                "\"input_range\" holds [{lo}, {hi}]; give each input's [min, max], finite \
                 numbers with min <= max"
            )));
        }
        let read = |object: serde_json::Map<String, serde_json::Value>| {
            serde_json::from_value::<SavedModel>(serde_json::Value::Object(object))
        };
        let model = read(object.clone()).map_err(|e| {
            // serde names a missing or unknown key, not one whose value is wrong: that key
            // is the one without which the model reads, or is only missing.
            let message = e.to_string();
            let names_a_key = object
                .keys()
                .map(String::as_str)
                .chain(MODEL_KEYS)
                .any(|key| message.contains(&format!("field `{key}`")));
            let culprit = (!names_a_key).then(|| {
                object.keys().filter(|k| *k != "kind").find(|key| {
                    let mut without = object.clone();
                    without.remove(*key);
                    match read(without) {
                        Ok(_) => true,
                        Err(e) => e.to_string() == format!("missing field `{key}`"),
                    }
                })
            });
            match culprit.flatten() {
                Some(key) => bad(format!("the {kind} model: \"{key}\": {message}")),
                None => bad(format!("the {kind} model: {message}")),
            }
        })?;
        Ok(Self {
            schema,
            model,
            prefilter,
            inverse_dynamics,
            sample_time,
            columns,
            input_range,
        })
    }
}

impl<'de> Deserialize<'de> for ModelFile {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        use serde::de::Error as _;
        let object = deserializer.deserialize_map(ObjectVisitor)?;
        ModelFile::from_object(object).map_err(|e| match e {
            Error::InvalidModel(message) => D::Error::custom(message),
            other => D::Error::custom(other),
        })
    }
}

/// A JSON object whose keys are all different.
struct ObjectVisitor;

impl<'de> serde::de::Visitor<'de> for ObjectVisitor {
    type Value = serde_json::Map<String, serde_json::Value>;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a hysid.model/1 object")
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(
        self,
        mut access: A,
    ) -> std::result::Result<Self::Value, A::Error> {
        use serde::de::Error as _;
        let mut object = serde_json::Map::new();
        while let Some((key, value)) = access.next_entry::<String, serde_json::Value>()? {
            if object.contains_key(&key) {
                return Err(A::Error::custom(format!("duplicate field `{key}`")));
            }
            object.insert(key, value);
        }
        Ok(object)
    }
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
        /// Which code runs its tapes when it is simulated (not saved: a setting of the run,
        /// [`FittedModel::with_evaluator`]; [`Evaluator::Auto`] when read from a file).
        evaluator: Evaluator,
    },
    /// A hysteresis operator of one of the families of [`crate::model::operators`].
    Operator {
        /// The family's name (`pi`, `preisach`, …; equal to `model.family()`).
        family: &'static str,
        /// The operator.
        model: OperatorModel,
        /// Standard deviations in `model.as_operator().parameters()` order (NaN: none).
        std: Vec<f64>,
        /// The initial state it starts from (None: as its structure holds it).
        initial_state: Option<InitialStateUsed>,
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
            FittedModel::Operator {
                model,
                initial_state,
                ..
            } => Ok(vec![initial_state::simulate(
                model.as_operator(),
                *initial_state,
                first()?,
            )?]),
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
                evaluator,
                ..
            } => {
                let model =
                    EquationStateSpace::parse(equations, "saved model")?.with_evaluator(*evaluator);
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
                evaluator: Evaluator::Auto,
            },
            other => other,
        }
    }

    /// The same model with its equation tapes run by `evaluator` (an equation model, also
    /// inside a pre-filtered one); other models unchanged.
    pub fn with_evaluator(self, evaluator: Evaluator) -> Self {
        match self {
            FittedModel::Equations {
                equations,
                parameters,
                std,
                simulation,
                initial_state,
                ..
            } => FittedModel::Equations {
                equations,
                parameters,
                std,
                simulation,
                initial_state,
                evaluator,
            },
            FittedModel::Prefiltered { model, prefilter } => FittedModel::Prefiltered {
                model: Box::new(model.with_evaluator(evaluator)),
                prefilter,
            },
            other => other,
        }
    }

    /// The model file of this model.
    pub fn to_file(&self) -> ModelFile {
        let records = |parameters: &ParameterSet, std: &[f64]| -> Vec<ParameterRecord> {
            parameters
                .iter()
                .zip(std)
                .map(|(p, s)| ParameterRecord::of(p, *s))
                .collect()
        };
        let model = match self {
            FittedModel::Hysteresis {
                model,
                initial,
                std,
            } => SavedModel::ColemanHodgdon {
                parameters: hysteresis_records(model, std),
                hysteresis: model.form(),
                initial_output: Some(*initial),
            },
            FittedModel::Cascade { model, std } => SavedModel::ChCascade {
                parameters: cascade_records(model, std),
                hysteresis: model.hysteresis.form(),
                delay: model.linear.delay(),
            },
            FittedModel::OperatorCascade { model, std } => SavedModel::OperatorCascade {
                parameters: records(&model.parameters(), std),
                delay: model.linear.delay(),
                // The structure of a constructed operator is always representable; a failure
                // would only leave it null, and reading the file back then says so.
                operator: serde_json::to_value(&model.operator).unwrap_or_default(),
            },
            FittedModel::GreyBox {
                kind,
                parameters,
                std,
                simulation,
                initial_state,
            } => {
                let parameters = records(parameters, std);
                let simulation = SimulationSpec::of(simulation);
                match GreyBoxKind::parse(kind).filter(|k| k.name() == kind) {
                    Some(kind) => SavedModel::grey_box(
                        kind,
                        GreyBoxFile {
                            parameters,
                            simulation: Some(simulation),
                            initial_state: Some(initial_state.clone()),
                        },
                    ),
                    None => SavedModel::UserGreyBox {
                        kind: kind.clone(),
                        parameters,
                        simulation,
                        initial_state: initial_state.clone(),
                    },
                }
            }
            FittedModel::Equations {
                equations,
                parameters,
                std,
                simulation,
                initial_state,
                ..
            } => SavedModel::Equations {
                parameters: records(parameters, std),
                simulation: Some(SimulationSpec::of(simulation)),
                initial_state: Some(initial_state.clone()),
                equations: equations.clone(),
            },
            FittedModel::Prefiltered { model, prefilter } => {
                return ModelFile {
                    prefilter: Some(*prefilter),
                    ..model.to_file()
                }
            }
            FittedModel::InverseDynamics {
                model,
                preprocessing,
            } => {
                return ModelFile {
                    inverse_dynamics: Some(*preprocessing),
                    ..model.to_file()
                }
            }
            FittedModel::Operator {
                family,
                model,
                std,
                initial_state,
            } => SavedModel::Operator {
                parameters: records(&model.as_operator().parameters(), std),
                family: family.to_string(),
                // As for the operator cascade: a failure would only leave the structure null.
                operator: model.structure().unwrap_or_default(),
                initial_state: *initial_state,
            },
        };
        ModelFile::new(model)
    }

    /// The fitted model of an operator with standard deviations `std` (NaN: none).
    pub fn operator(model: OperatorModel, std: Vec<f64>) -> Self {
        FittedModel::Operator {
            family: model.family().name(),
            model,
            std,
            initial_state: None,
        }
    }

    /// The same model starting from `state` (an operator; other kinds are returned as they
    /// are).
    pub fn with_initial_state(self, state: Option<InitialStateUsed>) -> Self {
        match self {
            FittedModel::Operator {
                family, model, std, ..
            } => FittedModel::Operator {
                family,
                model,
                std,
                initial_state: state,
            },
            other => other,
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
        let records = Records {
            kind: file.kind(),
            list: file.parameters(),
        };
        match &file.model {
            SavedModel::ColemanHodgdon {
                hysteresis,
                initial_output,
                ..
            } => {
                let (model, std) = hysteresis_from_records(*hysteresis, &records)?;
                Ok(FittedModel::Hysteresis {
                    model,
                    initial: initial_output.unwrap_or(InitialOutput::Measured),
                    std,
                })
            }
            SavedModel::ChCascade {
                hysteresis, delay, ..
            } => ch_cascade_from_records(*hysteresis, *delay, &records),
            SavedModel::OperatorCascade {
                delay, operator, ..
            } => operator_cascade_from_file(*delay, operator, &records),
            SavedModel::Operator {
                family,
                operator,
                initial_state,
                ..
            } => {
                let model = OperatorModel::from_structure(family, operator)?;
                let names = model.as_operator().parameters();
                let mut std = Vec::with_capacity(names.len());
                for p in names.iter() {
                    std.push(records.get(&p.name)?.std_or_nan());
                }
                Ok(Self::operator(model, std).with_initial_state(*initial_state))
            }
            SavedModel::Equations {
                parameters,
                simulation,
                initial_state,
                equations,
            } => equations_from_file(
                equations,
                parameters,
                simulation.as_ref(),
                initial_state.as_deref(),
            ),
            SavedModel::BoucWen(g) => Self::grey_box_from_file(GreyBoxKind::BoucWen, g),
            SavedModel::RigidBody(g) => Self::grey_box_from_file(GreyBoxKind::RigidBody, g),
            SavedModel::ActuatorFixed(g) => {
                Self::grey_box_from_file(GreyBoxKind::ActuatorFixed, g)
            }
            SavedModel::ActuatorFree(g) => Self::grey_box_from_file(GreyBoxKind::ActuatorFree, g),
            SavedModel::UserGreyBox { kind, .. } => Err(Error::InvalidModel(format!(
                "unknown model kind '{kind}'; this version knows {} (a grey-box model of your own is rebuilt from its code, not from a file)",
                MODEL_KINDS.join(", ")
            ))),
        }
    }

    fn grey_box_from_file(kind: GreyBoxKind, file: &GreyBoxFile) -> Result<Self> {
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
            // The model's own bounds are its physics (a positive mass, non-negative
            // friction): a file's wider bounds do not admit a value outside them.
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
        Ok(FittedModel::GreyBox {
            kind: name.to_string(),
            parameters,
            std,
            simulation,
            initial_state,
        })
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

impl ModelFile {
    /// Reads a model file, or the `model` object of a report, and checks that it describes
    /// a model ([`FittedModel::from_file`]); the errors name `path`. Unlike
    /// [`FittedModel::load`] it keeps everything the file holds (`sample_time`, `columns`).
    pub fn load(path: &Path) -> Result<Self> {
        let file = Self::read(path)?;
        FittedModel::from_file(&file).map_err(|e| Error::ModelFile {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        Ok(file)
    }

    /// The model file at `path` (or the `model` of the report there), parsed, not checked.
    fn read(path: &Path) -> Result<Self> {
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
        let no_model = || bad("this report holds no model (its \"model\" is null)".into());
        let not_a_model =
            |e: serde_json::Error| bad(format!("not a {MODEL_SCHEMA} model file: {e}"));
        // Read from the text, not from `value`, so that a key given twice is refused.
        let file: ModelFile = match value.get("schema").and_then(|s| s.as_str()) {
            Some(s) if s.starts_with("hysid.report/") => {
                /// The model of a report (its other keys are the report's business).
                #[derive(Deserialize)]
                struct ReportModel {
                    model: Option<ModelFile>,
                }
                if value.get("model").is_none_or(serde_json::Value::is_null) {
                    return Err(no_model());
                }
                let report: ReportModel = serde_json::from_str(&text).map_err(not_a_model)?;
                report.model.ok_or_else(no_model)?
            }
            _ if value.is_null() => return Err(no_model()),
            _ => serde_json::from_str(&text).map_err(not_a_model)?,
        };
        Ok(file)
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
fn operator_cascade_from_file(
    delay: usize,
    structure: &serde_json::Value,
    records: &Records,
) -> Result<FittedModel> {
    let operator: OperatorModel = serde_json::from_value(structure.clone()).map_err(|e| {
        Error::InvalidModel(format!("the operator of the operator_cascade model: {e}"))
    })?;
    let b = records.coefficients('b')?;
    let a = records.coefficients('a')?;
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
        let e = records.get(&name)?;
        values.push(e.value);
        std.push(e.std_or_nan());
    }
    Ok(FittedModel::OperatorCascade {
        model: template.with_values(&values)?,
        std,
    })
}

/// The Coleman–Hodgdon hysteresis of form `form` from its records, and their standard
/// deviations in [`ChForm::parameter_names`] order.
fn hysteresis_from_records(form: ChForm, records: &Records) -> Result<(ColemanHodgdon, Vec<f64>)> {
    let mut values = Vec::new();
    let mut std = Vec::new();
    for name in form.parameter_names() {
        let e = records.get(name)?;
        values.push(e.value);
        std.push(e.std_or_nan());
    }
    Ok((ColemanHodgdon::from_params(form, &values)?, std))
}

/// A Coleman–Hodgdon cascade from its records: the hysteresis, then b1 = 1, b2 … and a1 ….
fn ch_cascade_from_records(form: ChForm, delay: usize, records: &Records) -> Result<FittedModel> {
    let (hysteresis, mut std) = hysteresis_from_records(form, records)?;
    let b = records.coefficients('b')?;
    let a = records.coefficients('a')?;
    if b.is_empty() || b[0].value != 1.0 {
        return Err(Error::InvalidModel(
            "a ch_cascade model needs b1 = 1 (the gain sits in the hysteresis)".into(),
        ));
    }
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

/// The parameter records of a model file of kind `kind`, looked up by name.
struct Records<'a> {
    kind: &'a str,
    list: &'a [ParameterRecord],
}

impl<'a> Records<'a> {
    /// The record called `name`.
    fn get(&self, name: &str) -> Result<&'a ParameterRecord> {
        self.list.iter().find(|p| p.name == name).ok_or_else(|| {
            Error::InvalidModel(format!(
                "parameter '{name}' is missing from the {} model",
                self.kind
            ))
        })
    }

    /// The coefficients `<letter>1`, `<letter>2`, … in order (none missing in between).
    fn coefficients(&self, letter: char) -> Result<Vec<ParameterRecord>> {
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
