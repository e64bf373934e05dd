//! Kind `ch_cascade`: the Coleman–Hodgdon hysteresis followed by a linear block (Vörös 2015,
//! [`FittedModel::Cascade`]).

use super::coleman_hodgdon::{hysteresis_from_records, hysteresis_records};
use super::{first, FittedKind, ModelKind, Records};
use crate::model::saved::{FittedModel, ParameterRecord, SavedModel};
use crate::model::stream::{self, Stepper};
use crate::model::{ChForm, HysteresisCascade, LinearBlock, Parameter};
use crate::{Error, Result};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The kind `ch_cascade` in the registry ([`super::ModelKind`]).
pub struct ChCascadeKind;

/// The keys of a `ch_cascade` model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ChCascadeFile {
    /// The hysteresis parameters, then b1 (fixed at 1) … bm, a1 … an.
    pub parameters: Vec<ParameterRecord>,
    /// `ch4` or `ch6`.
    pub hysteresis: ChForm,
    /// Delay k of the linear block.
    pub delay: usize,
}

impl ModelKind for ChCascadeKind {
    type File = ChCascadeFile;

    fn parameters(file: &ChCascadeFile) -> &[ParameterRecord] {
        &file.parameters
    }

    /// The hysteresis, then b1 = 1, b2 … and a1 ….
    fn fitted(file: &ChCascadeFile) -> Result<FittedModel> {
        let records = Records {
            kind: "ch_cascade",
            list: &file.parameters,
        };
        let (hysteresis, mut std) = hysteresis_from_records(file.hysteresis, &records)?;
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
            file.delay,
        )?;
        std.extend(b.iter().skip(1).map(ParameterRecord::std_or_nan));
        std.extend(a.iter().map(ParameterRecord::std_or_nan));
        Ok(FittedModel::Cascade(FittedCascade {
            model: HysteresisCascade::new(hysteresis, linear)?,
            std,
        }))
    }
}

/// A fitted Coleman–Hodgdon cascade ([`FittedModel::Cascade`]).
#[derive(Clone, Debug, PartialEq)]
pub struct FittedCascade {
    /// The model.
    pub model: HysteresisCascade,
    /// Standard deviations in [`HysteresisCascade::params`] order.
    pub std: Vec<f64>,
}

/// The recursion from 0, then the linear block; no compensator (as `hysid compensate`).
impl FittedKind for FittedCascade {
    fn saved(&self) -> SavedModel {
        let (model, std) = (&self.model, &self.std);
        let nh = model.hysteresis.form().n_params();
        let nb = model.linear.nb();
        let mut records = hysteresis_records(&model.hysteresis, &std[..nh]);
        records.push(ParameterRecord::of(
            &Parameter::new("b1", 1.0).fixed(true),
            f64::NAN,
        ));
        let b = model.linear.b()[1..].iter().zip(&std[nh..nh + nb - 1]);
        records.extend(b.enumerate().map(|(j, (v, s))| {
            ParameterRecord::of(&Parameter::new(format!("b{}", j + 2), *v), *s)
        }));
        let a = model.linear.a().iter().zip(&std[nh + nb - 1..]);
        records.extend(a.enumerate().map(|(i, (v, s))| {
            ParameterRecord::of(&Parameter::new(format!("a{}", i + 1), *v), *s)
        }));
        SavedModel::ChCascade(ChCascadeFile {
            parameters: records,
            hysteresis: model.hysteresis.form(),
            delay: model.linear.delay(),
        })
    }

    fn simulate(&self, inputs: &[&[f64]], _ts: f64, _y0: Option<f64>) -> Result<Vec<Vec<f64>>> {
        Ok(vec![self.model.simulate(first(inputs)?)?.y])
    }

    fn stepper(&self, _ts: f64, _y0: Option<f64>) -> Result<Box<dyn Stepper>> {
        Ok(stream::ch_cascade_stepper(&self.model))
    }
}
