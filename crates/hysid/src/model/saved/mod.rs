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
//! variants of [`SavedModel`], a serde enum tagged by `kind` generated from the registry of
//! kinds ([`crate::model::kinds`], one module per kind holding its file's keys), so a key the
//! kind needs is required by the type and any other key is refused, naming its path
//! ([`ModelFile::from_object`]). Kinds and their structure keys:
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

mod fitted;
mod read;
mod simulation;

pub use crate::model::kinds::ch_cascade::FittedCascade;
pub use crate::model::kinds::coleman_hodgdon::FittedHysteresis;
pub use crate::model::kinds::equations::FittedEquations;
pub use crate::model::kinds::grey_box::FittedGreyBox;
pub use crate::model::kinds::grey_box::GreyBoxFile;
pub use crate::model::kinds::operator::FittedHysteresisOperator;
pub use crate::model::kinds::operator::OPERATOR_KIND;
pub use crate::model::kinds::operator_cascade::FittedOperatorCascade;
pub use crate::model::kinds::operator_cascade::OPERATOR_CASCADE_KIND;
pub use crate::model::kinds::{FittedKind, SavedModel, MODEL_KINDS};
pub use fitted::{FittedModel, Prediction};
pub use read::MAX_FILTER_ORDER;
pub(crate) use read::{check_inverse_dynamics, check_prefilter};
pub use simulation::{SimulationSpec, MAX_SUBSTEPS};

use crate::model::record_filters::{InverseDynamics, Prefilter};
use crate::model::Parameter;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

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
}
