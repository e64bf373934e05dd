//! The program of each model kind: which components (an operator of the registry, a linear
//! block, the Coleman–Hodgdon recursion) a model is made of and how its step chains them.

use super::code::Expr;
use super::families;
use super::program::{Ns, Program};
use crate::model::saved::FittedModel;
use crate::{Error, Result};

/// The streaming program of `model`, or of its compensator when `inverse`.
pub fn program(model: &FittedModel, inverse: bool) -> Result<Program> {
    let mut prog = Program::new(1, 1);
    let step = match model {
        FittedModel::Operator { model, .. } => {
            let ns = Ns::new("op_");
            if inverse {
                families::inverse(model, &ns, &mut prog)?
            } else {
                families::forward(model, &ns, &mut prog)?
            }
        }
        other => {
            return Err(Error::UnsupportedKind {
                kind: other.to_file().kind().to_string(),
                operation: "export as code (this version exports operators, operator \
                            cascades and Coleman–Hodgdon models)"
                    .into(),
            })
        }
    };
    prog.fallible_step(|b| {
        b.let_("y0", Expr::Call(step, vec![Expr::Input(0)]));
    })?;
    Ok(prog)
}
