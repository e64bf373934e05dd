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
//! Kinds: `coleman_hodgdon` (the hysteresis alone; `initial_output` is `measured` or `zero`)
//! and `ch_cascade` (hysteresis followed by a linear block; b₁ = 1 is fixed).

use crate::estimate::hysteresis::{simulate_switched, InitialOutput};
use crate::model::{ChForm, ColemanHodgdon, HysteresisCascade, LinearBlock};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// A parameter value with its standard deviation (0 when fixed, NaN written as null when
/// unknown).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// The value.
    pub value: f64,
    /// One standard deviation.
    #[serde(default, with = "nullable")]
    pub std: f64,
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
    /// `coleman_hodgdon` or `ch_cascade`.
    pub kind: String,
    /// `ch4` or `ch6`.
    pub hysteresis: ChForm,
    /// Parameters by name (MODELS.md symbols).
    pub parameters: BTreeMap<String, ParameterEntry>,
    /// Delay k of the linear block (cascade only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delay: Option<usize>,
    /// Initial output of the hysteresis alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_output: Option<InitialOutput>,
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
}

impl FittedModel {
    /// Simulates the model's output for the input `x`; `y0` is the measured initial output
    /// (used by a hysteresis with [`InitialOutput::Measured`]). Errors when α·|Δx| > 1.
    pub fn simulate(&self, x: &[f64], y0: Option<f64>) -> Result<Vec<f64>> {
        match self {
            FittedModel::Hysteresis { model, initial, .. } => {
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
                Ok(simulate_switched(model, x, v0, None))
            }
            FittedModel::Cascade { model, .. } => Ok(model.simulate(x)?.y),
        }
    }

    /// The model file of this model.
    pub fn to_file(&self) -> ModelFile {
        match self {
            FittedModel::Hysteresis {
                model,
                initial,
                std,
            } => ModelFile {
                kind: "coleman_hodgdon".into(),
                hysteresis: model.form(),
                parameters: hysteresis_entries(model, std),
                delay: None,
                initial_output: Some(*initial),
            },
            FittedModel::Cascade { model, std } => {
                let nh = model.hysteresis.form().n_params();
                let mut parameters = hysteresis_entries(&model.hysteresis, &std[..nh]);
                let nb = model.linear.nb();
                let mut b = vec![Estimate {
                    value: 1.0,
                    std: 0.0,
                }];
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
                    kind: "ch_cascade".into(),
                    hysteresis: model.hysteresis.form(),
                    parameters,
                    delay: Some(model.linear.delay()),
                    initial_output: None,
                }
            }
        }
    }

    /// Rebuilds a fitted model from a model file.
    pub fn from_file(file: &ModelFile) -> Result<Self> {
        let form = file.hysteresis;
        let names = form.parameter_names();
        let mut values = Vec::new();
        let mut std = Vec::new();
        for name in names {
            let e = scalar(file, name)?;
            values.push(e.value);
            std.push(e.std);
        }
        let hysteresis = ColemanHodgdon::from_params(form, &values)?;
        match file.kind.as_str() {
            "coleman_hodgdon" => Ok(FittedModel::Hysteresis {
                model: hysteresis,
                initial: file.initial_output.unwrap_or(InitialOutput::Measured),
                std,
            }),
            "ch_cascade" => {
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
            other => Err(Error::Config(format!(
                "unknown model kind '{other}'; this version knows coleman_hodgdon and ch_cascade"
            ))),
        }
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

fn scalar(file: &ModelFile, name: &str) -> Result<Estimate> {
    match file.parameters.get(name) {
        Some(ParameterEntry::Scalar(e)) => Ok(*e),
        Some(ParameterEntry::List(_)) => Err(Error::Config(format!(
            "parameter '{name}' must be a single value"
        ))),
        None => Err(Error::Config(format!(
            "parameter '{name}' is missing (a {} model needs {})",
            file.hysteresis.short_name(),
            file.hysteresis.parameter_names().join(", ")
        ))),
    }
}

fn list(file: &ModelFile, name: &str) -> Result<Vec<Estimate>> {
    match file.parameters.get(name) {
        Some(ParameterEntry::List(v)) => Ok(v.clone()),
        Some(ParameterEntry::Scalar(e)) => Ok(vec![*e]),
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
