//! The simulation settings of a grey-box model in a model file (`simulation`): the integrator
//! saved faithfully.

use crate::model::greybox::{InputInterpolation, Integrator, Simulation};
use crate::{Error, Result};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

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
