//! Each operator family's streaming code: one file per family implementing [`Emit`], and the
//! dispatch from an [`OperatorModel`] to it, generated from the family registry
//! (`operator_families!`), so that a family missing here does not compile.
//!
//! The rate-independent families with a core operator G and an [`Orientation`] implement
//! [`oriented::EmitCore`] (G and G⁻¹) and get their [`Emit`] from [`oriented`]; the
//! differential families implement [`differential::EmitOde`] (their slope and output) and
//! get theirs from the one Dormand–Prince driver of [`differential`].
//!
//! [`Orientation`]: crate::model::operators::Orientation

pub mod backlash;
pub mod bouc_wen;
pub mod dahl;
pub mod differential;
pub mod duhem;
pub mod gpi;
pub mod jiles_atherton;
pub mod kp;
pub mod maxwell_slip;
pub mod oriented;
pub mod pi;
pub mod preisach;

use super::program::{Ns, Program};
use crate::model::operators::OperatorModel;
use crate::Result;

/// What a family supplies to the exporter: its forward step and its inverse step, as helpers
/// of a [`Program`] in the namespace `ns`.
pub trait Emit {
    /// Emits `ns.step(x) -> f64`: Γ\[u\]ₖ for the input uₖ = x (the sample the library's
    /// `simulate` gives at k), advancing the operator's state; with the fields and the
    /// initialisation it needs. Returns the helper's name.
    fn emit_forward(&self, ns: &Ns, prog: &mut Program) -> Result<String>;
    /// Emits `ns.inverse(r) -> f64`: the input uₖ the library's `invert` gives for the
    /// reference rₖ, advancing the state. Returns the helper's name.
    fn emit_inverse(&self, ns: &Ns, prog: &mut Program) -> Result<String>;
}

/// The dispatch from an operator of any family to its [`Emit`].
macro_rules! dispatch {
    ($($variant:ident: $ty:ty),* $(,)?) => {
        /// The family's forward step ([`Emit::emit_forward`]).
        pub fn forward(op: &OperatorModel, ns: &Ns, prog: &mut Program) -> Result<String> {
            match op {
                $(OperatorModel::$variant(m) => Emit::emit_forward(m, ns, prog),)*
            }
        }
        /// The family's inverse step ([`Emit::emit_inverse`]).
        pub fn inverse(op: &OperatorModel, ns: &Ns, prog: &mut Program) -> Result<String> {
            match op {
                $(OperatorModel::$variant(m) => Emit::emit_inverse(m, ns, prog),)*
            }
        }
    };
}
crate::model::operators::operator_families!(dispatch);
