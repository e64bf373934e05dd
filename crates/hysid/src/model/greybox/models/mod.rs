//! Built-in grey-box models.
//!
//! * [`BoucWen`]: the single-degree-of-freedom Bouc–Wen oscillator of the hysteretic
//!   benchmark (Noël & Schoukens 2016), in identifiable parameters.
//! * [`RigidBody`]: a rigid body with viscous and Coulomb friction and a force offset.
//! * [`ActuatorFixed`], [`ActuatorFree`]: the linear actuator with a Dhaouadi hysteresis of
//!   Gunnar et al. (2006), saddle fixed and free.

mod actuator;
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub mod bouc_wen;
mod bouc_wen_kernel;
mod rigid_body;

pub use actuator::{ActuatorFixed, ActuatorFree};
pub use bouc_wen::BoucWen;
pub use rigid_body::RigidBody;

use super::StateSpaceModel;
use crate::{Error, Result};

/// The built-in grey-box models, by the kind a model file names them with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GreyBoxKind {
    /// [`BoucWen`], `bouc_wen`.
    BoucWen,
    /// [`RigidBody`], `rigid_body`.
    RigidBody,
    /// [`ActuatorFixed`], `actuator_fixed`.
    ActuatorFixed,
    /// [`ActuatorFree`], `actuator_free`.
    ActuatorFree,
}

impl GreyBoxKind {
    /// Every built-in model.
    pub const ALL: [GreyBoxKind; 4] = [
        GreyBoxKind::BoucWen,
        GreyBoxKind::RigidBody,
        GreyBoxKind::ActuatorFixed,
        GreyBoxKind::ActuatorFree,
    ];

    /// The kind's name in a model file (`bouc_wen`, `rigid_body`, `actuator_fixed`,
    /// `actuator_free`), equal to the model's [`StateSpaceModel::kind`].
    pub fn name(self) -> &'static str {
        match self {
            GreyBoxKind::BoucWen => "bouc_wen",
            GreyBoxKind::RigidBody => "rigid_body",
            GreyBoxKind::ActuatorFixed => "actuator_fixed",
            GreyBoxKind::ActuatorFree => "actuator_free",
        }
    }

    /// The built-in model called `name` (any case, dashes allowed for underscores:
    /// `bouc-wen` as on the command line), or None.
    pub fn parse(name: &str) -> Option<Self> {
        let name = name.trim().to_ascii_lowercase().replace('-', "_");
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// The model.
    pub fn model(self) -> Box<dyn StateSpaceModel> {
        match self {
            GreyBoxKind::BoucWen => Box::new(BoucWen),
            GreyBoxKind::RigidBody => Box::new(RigidBody),
            GreyBoxKind::ActuatorFixed => Box::new(ActuatorFixed),
            GreyBoxKind::ActuatorFree => Box::new(ActuatorFree),
        }
    }
}

/// The built-in model called `kind` (`bouc_wen`, `rigid_body`, `actuator_fixed`,
/// `actuator_free`; dashes allowed for underscores; see [`GreyBoxKind::parse`]).
pub fn by_kind(kind: &str) -> Result<Box<dyn StateSpaceModel>> {
    match GreyBoxKind::parse(kind) {
        Some(kind) => Ok(kind.model()),
        None => {
            let other = kind.trim().to_ascii_lowercase().replace('-', "_");
            Err(Error::invalid_option("model", &other, format!(
                "unknown grey-box model '{other}'; the built-in ones are bouc-wen, rigid-body, actuator-fixed and actuator-free"
            )))
        }
    }
}

/// sgn with sgn(0) = 0 (friction and hysteresis laws use it).
#[inline]
pub fn sign0(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// The direction s of Coulomb friction Fc·s at velocity `v` under the `applied` force (all
/// other forces on the body): sgn(v) while sliding; at rest, sgn(applied) when the applied
/// force breaks the body away (|applied| > Fc), and None while friction holds it
/// (|applied| ≤ Fc: the friction force is then −applied and the acceleration zero). Models
/// that use it name their velocity in
/// [`StateSpaceModel::stick_slip_velocity`] so that RK4 stops at v = 0.
#[inline]
pub fn coulomb_direction(v: f64, applied: f64, fc: f64) -> Option<f64> {
    if v != 0.0 {
        Some(sign0(v))
    } else if applied.abs() > fc {
        Some(sign0(applied))
    } else {
        None
    }
}
