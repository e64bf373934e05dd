//! One type for an operator of any family: what a model file saves and `hysid simulate` runs.
//!
//! [`OperatorModel`] holds one of the nine families of this module. Its *structure* is the
//! operator's full serde form (thresholds, weights, grids, orientation, initial state), as a
//! JSON object; reading one back goes through the family's validating constructor, so a model
//! file cannot hold an operator its constructor would refuse (a non-monotone threshold grid, a
//! negative Preisach weight, β ≤ 0 in Bouc–Wen, …).

use super::{
    Backlash, BoucWen, Dahl, DeadZones, Duhem, GeneralizedPi, HysteresisOperator, JilesAtherton,
    MaxwellSlip, PrandtlIshlinskii, Preisach,
};
use crate::{Error, Result};
use serde::de::DeserializeOwned;
use serde::Serialize;

/// A hysteresis operator of any family of [`crate::model::operators`].
#[derive(Clone, Debug, PartialEq)]
#[allow(missing_docs)] // one variant per family, each named by its type
pub enum OperatorModel {
    Pi(PrandtlIshlinskii),
    Gpi(GeneralizedPi),
    Preisach(Preisach),
    JilesAtherton(JilesAtherton),
    BoucWen(BoucWen),
    Duhem(Duhem),
    Dahl(Dahl),
    MaxwellSlip(MaxwellSlip),
    Backlash(Backlash),
}

/// The family names of [`OperatorModel`], as [`HysteresisOperator::family`] gives them.
pub const OPERATOR_FAMILIES: [&str; 9] = [
    "pi",
    "gpi",
    "preisach",
    "jiles-atherton",
    "bouc-wen",
    "duhem",
    "dahl",
    "maxwell-slip",
    "backlash",
];

impl OperatorModel {
    /// The operator behind the common trait (simulate, invert, parameters).
    pub fn as_operator(&self) -> &dyn HysteresisOperator {
        match self {
            OperatorModel::Pi(m) => m,
            OperatorModel::Gpi(m) => m,
            OperatorModel::Preisach(m) => m,
            OperatorModel::JilesAtherton(m) => m,
            OperatorModel::BoucWen(m) => m,
            OperatorModel::Duhem(m) => m,
            OperatorModel::Dahl(m) => m,
            OperatorModel::MaxwellSlip(m) => m,
            OperatorModel::Backlash(m) => m,
        }
    }

    /// The family's name (`pi`, `gpi`, …).
    pub fn family(&self) -> &'static str {
        self.as_operator().family()
    }

    /// The full structure as a JSON object (the operator's serde form).
    pub fn structure(&self) -> Result<serde_json::Value> {
        let value = match self {
            OperatorModel::Pi(m) => to_value(m),
            OperatorModel::Gpi(m) => to_value(m),
            OperatorModel::Preisach(m) => to_value(m),
            OperatorModel::JilesAtherton(m) => to_value(m),
            OperatorModel::BoucWen(m) => to_value(m),
            OperatorModel::Duhem(m) => to_value(m),
            OperatorModel::Dahl(m) => to_value(m),
            OperatorModel::MaxwellSlip(m) => to_value(m),
            OperatorModel::Backlash(m) => to_value(m),
        }?;
        Ok(value)
    }

    /// Reads the structure written by [`structure`](Self::structure) for `family`, checked by
    /// the family's constructor.
    pub fn from_structure(family: &str, structure: &serde_json::Value) -> Result<Self> {
        Ok(match family {
            "pi" => OperatorModel::Pi(rebuild_pi(&from_value(family, structure)?)?),
            "gpi" => {
                let m: GeneralizedPi = from_value(family, structure)?;
                let z = m.dead_zones();
                let zones = DeadZones::new(z.d0(), z.upper().to_vec(), z.lower().to_vec())?;
                OperatorModel::Gpi(GeneralizedPi::new(
                    rebuild_pi(m.pi())?,
                    zones,
                    m.orientation(),
                ))
            }
            "preisach" => {
                let m: Preisach = from_value(family, structure)?;
                OperatorModel::Preisach(Preisach::new(
                    m.lower(),
                    m.upper(),
                    m.levels(),
                    m.weights().to_vec(),
                    m.a0(),
                    m.offset(),
                    m.orientation(),
                )?)
            }
            "jiles-atherton" => {
                let m: JilesAtherton = from_value(family, structure)?;
                m.validate()?;
                OperatorModel::JilesAtherton(m)
            }
            "bouc-wen" => {
                let m: BoucWen = from_value(family, structure)?;
                m.validate()?;
                OperatorModel::BoucWen(m)
            }
            "duhem" => {
                let m: Duhem = from_value(family, structure)?;
                m.validate()?;
                OperatorModel::Duhem(m)
            }
            "dahl" => {
                let m: Dahl = from_value(family, structure)?;
                m.validate()?;
                OperatorModel::Dahl(m)
            }
            "maxwell-slip" => {
                let m: MaxwellSlip = from_value(family, structure)?;
                OperatorModel::MaxwellSlip(MaxwellSlip::new(
                    m.k0(),
                    m.stiffness().to_vec(),
                    m.widths().to_vec(),
                    m.offset(),
                    m.orientation(),
                )?)
            }
            "backlash" => {
                let m: Backlash = from_value(family, structure)?;
                OperatorModel::Backlash(Backlash::new(
                    m.gain(),
                    m.half_width(),
                    m.offset(),
                    m.orientation(),
                )?)
            }
            other => {
                return Err(Error::invalid_option(
                    "family",
                    other,
                    format!(
                        "unknown operator family '{other}'; use one of {}",
                        OPERATOR_FAMILIES.join(", ")
                    ),
                ))
            }
        })
    }
}

fn rebuild_pi(m: &PrandtlIshlinskii) -> Result<PrandtlIshlinskii> {
    PrandtlIshlinskii::new(
        m.a0(),
        m.weights().to_vec(),
        m.thresholds().to_vec(),
        m.offset(),
        m.orientation(),
    )
}

fn to_value(m: &impl Serialize) -> Result<serde_json::Value> {
    serde_json::to_value(m).map_err(|e| Error::Serialization(format!("operator structure: {e}")))
}

fn from_value<T: DeserializeOwned>(family: &str, v: &serde_json::Value) -> Result<T> {
    serde_json::from_value(v.clone()).map_err(|e| {
        Error::InvalidModel(format!(
            "the \"operator\" object is not a {family} operator ({e}); save the model again"
        ))
    })
}
