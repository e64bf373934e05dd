//! Kind `operator_cascade`: a hysteresis operator of the registry followed by a linear block
//! ([`FittedModel::OperatorCascade`]).

use super::{first, records, FittedKind, ModelKind, Records};
use crate::model::compensate::Compensation;
use crate::model::saved::{FittedModel, ParameterRecord, SavedModel};
use crate::model::stream::{self, Compensator, Stepper};
use crate::model::{LinearBlock, OperatorCascade, OperatorModel};
use crate::{Error, Result};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The kind of [`FittedModel::OperatorCascade`].
pub const OPERATOR_CASCADE_KIND: &str = "operator_cascade";

/// The kind `operator_cascade` in the registry ([`super::ModelKind`]).
pub struct OperatorCascadeKind;

/// The keys of an `operator_cascade` model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OperatorCascadeFile {
    /// The operator's parameters (prefixed `op_` where they collide with a1…, b1…),
    /// then a1 … an, b1 (fixed at 1) … bm.
    pub parameters: Vec<ParameterRecord>,
    /// Delay k of the linear block.
    pub delay: usize,
    /// `{"family": …, "operator": {…}}`: the operator family and its structure, whose
    /// values are read from `parameters`. Checked on reading.
    pub operator: serde_json::Value,
}

impl ModelKind for OperatorCascadeKind {
    type File = OperatorCascadeFile;

    fn parameters(file: &OperatorCascadeFile) -> &[ParameterRecord] {
        &file.parameters
    }

    /// The structure from `operator`, every value from `parameters` (validated by the
    /// family's constructor).
    fn fitted(file: &OperatorCascadeFile) -> Result<FittedModel> {
        let records = Records {
            kind: OPERATOR_CASCADE_KIND,
            list: &file.parameters,
        };
        let operator: OperatorModel =
            serde_json::from_value(file.operator.clone()).map_err(|e| {
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
            file.delay,
        )?;
        let template = OperatorCascade::new(operator, linear)?;
        let mut values = Vec::new();
        let mut std = Vec::new();
        for name in template.parameters().names() {
            let e = records.get(&name)?;
            values.push(e.value);
            std.push(e.std_or_nan());
        }
        Ok(FittedModel::OperatorCascade(FittedOperatorCascade {
            model: template.with_values(&values)?,
            std,
        }))
    }
}

/// A fitted operator cascade ([`FittedModel::OperatorCascade`]).
#[derive(Clone, Debug, PartialEq)]
pub struct FittedOperatorCascade {
    /// The model.
    pub model: OperatorCascade,
    /// Standard deviations in [`OperatorCascade::parameters`] order (NaN where not
    /// estimated).
    pub std: Vec<f64>,
}

/// The operator, then the linear block; compensated by the block's inverse (minimum-phase B
/// only, the reference k samples ahead), then the operator's inverse.
impl FittedKind for FittedOperatorCascade {
    fn saved(&self) -> SavedModel {
        SavedModel::OperatorCascade(OperatorCascadeFile {
            parameters: records(&self.model.parameters(), &self.std),
            delay: self.model.linear.delay(),
            // The structure of a constructed operator is always representable; a failure
            // would only leave it null, and reading the file back then says so.
            operator: serde_json::to_value(&self.model.operator).unwrap_or_default(),
        })
    }

    fn simulate(&self, inputs: &[&[f64]], _ts: f64, _y0: Option<f64>) -> Result<Vec<Vec<f64>>> {
        Ok(vec![self.model.simulate(first(inputs)?)?.y])
    }

    fn stepper(&self, _ts: f64, _y0: Option<f64>) -> Result<Box<dyn Stepper>> {
        stream::operator_cascade_stepper(&self.model)
    }

    fn compensator(&self) -> Result<Box<dyn Compensator>> {
        stream::operator_cascade_compensator(&self.model)
    }

    fn compensate(&self, reference: &[f64]) -> Result<Compensation> {
        let inv = self.model.compensate(reference)?;
        Ok(Compensation {
            reference: reference.to_vec(),
            u: inv.u,
            predicted: inv.predicted,
            clipped: inv.clipped,
            settled_from: inv.delay,
        })
    }
}
