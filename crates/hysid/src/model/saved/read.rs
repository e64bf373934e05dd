//! Reading `hysid.model/1` strictly: every key the kind's (the registry reads the kind's keys,
//! [`crate::model::kinds`]), none given twice, a `null` for a key of the format read as the
//! key left out; and the checks of the record processing a file asks for.

use super::{Columns, FittedModel, ModelFile, SavedModel, MODEL_KINDS, MODEL_SCHEMA};
use crate::model::kinds::unknown_kind;
use crate::model::record_filters::{InverseDynamics, Prefilter};
use crate::{Error, Result};
use serde::Deserialize;
use std::collections::BTreeSet;
use std::path::Path;
use std::sync::OnceLock;

impl ModelFile {
    /// The model file of a JSON object, checked key by key (see [`ModelFile`]); the error is
    /// one line naming the kind and the key.
    pub fn from_object(mut object: serde_json::Map<String, serde_json::Value>) -> Result<Self> {
        let bad = |message: String| Error::InvalidModel(message);
        object.retain(|key, value| !(value.is_null() && format_keys().contains(key.as_str())));
        let schema = match object.remove("schema") {
            Some(serde_json::Value::String(s)) => s,
            Some(other) => return Err(bad(format!("\"schema\" is {other}, not a string"))),
            None => return Err(bad("missing field `schema`".into())),
        };
        let kind = match object.remove("kind") {
            Some(serde_json::Value::String(kind)) => kind,
            Some(other) => return Err(bad(format!("\"kind\" is {other}, not a string"))),
            None => return Err(bad("missing field `kind`".into())),
        };
        if !MODEL_KINDS.contains(&kind.as_str()) {
            return Err(unknown_kind(&kind, ""));
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
        let model = SavedModel::from_keys(&kind, object).map_err(|e| match e {
            Error::InvalidModel(message) => bad(format!("the {kind} model: {message}")),
            other => other,
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

/// The keys `hysid.model/1` defines besides `schema` and `kind` (every kind's and the
/// envelope's, read from its JSON Schema): a `null` for any of them reads as the key left out,
/// as files written by hand spell out the keys that do not apply.
fn format_keys() -> &'static BTreeSet<String> {
    static KEYS: OnceLock<BTreeSet<String>> = OnceLock::new();
    KEYS.get_or_init(|| {
        let schema = serde_json::to_value(schemars::schema_for!(ModelFile)).unwrap_or_default();
        let kinds = schema["anyOf"].as_array().cloned().unwrap_or_default();
        std::iter::once(&schema)
            .chain(&kinds)
            .filter_map(|s| s["properties"].as_object())
            .flat_map(|properties| properties.keys().cloned())
            .filter(|key| key != "schema" && key != "kind")
            .collect()
    })
}

/// [`SavedModel`] is read as [`ModelFile`] reads it, by its kind ([`SavedModel::from_keys`]).
impl<'de> Deserialize<'de> for SavedModel {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        use serde::de::Error as _;
        let mut object = deserializer.deserialize_map(ObjectVisitor)?;
        let kind = match object.remove("kind") {
            Some(serde_json::Value::String(kind)) => kind,
            _ => return Err(D::Error::custom("missing field `kind`")),
        };
        SavedModel::from_keys(&kind, object).map_err(D::Error::custom)
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
    pub(super) fn read(path: &Path) -> Result<Self> {
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

/// The largest Butterworth order a model file may ask for (beyond it the filter is
/// numerically meaningless and the file more likely corrupt).
pub const MAX_FILTER_ORDER: usize = 20;

/// Refuses a pre-filter no fit uses: an order outside 1..=[`MAX_FILTER_ORDER`], a cut-off
/// that is not positive and finite.
pub(crate) fn check_prefilter(p: &Prefilter) -> Result<()> {
    check_filter(p.cutoff_hz.unwrap_or(1.0), p.order, "prefilter")
}

/// Refuses inverse-dynamics settings no fit uses (see [`check_prefilter`]; a decimation
/// factor of at least 1).
pub(crate) fn check_inverse_dynamics(p: &InverseDynamics) -> Result<()> {
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
