//! The generalised Duhem (Coleman–Hodgdon) operator (`model::operators::duhem`):
//! dy/du = α·δ·(a·u + b − y) + c, y the state, integrated by the differential driver
//! ([`super::differential`]).

use super::differential::{self, EmitOde};
use crate::export::code::{local, Ty};
use crate::export::program::{Ns, Program};
use crate::model::operators::Duhem;
use crate::Result;

impl EmitOde for Duhem {
    fn emit_slope(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        let (alpha, a, b0, c) = (self.alpha, self.a, self.b, self.c);
        prog.function(
            &ns.name("slope"),
            &[("u", Ty::F64), ("y", Ty::F64), ("d", Ty::F64)],
            Some(Ty::F64),
            |b| b.ret(alpha * local("d") * (a * local("u") + b0 - local("y")) + c),
        )
    }
    fn emit_output(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        prog.function(
            &ns.name("output"),
            &[("u", Ty::F64), ("y", Ty::F64)],
            Some(Ty::F64),
            |b| b.ret(local("y")),
        )
    }
}

differential::differential_emit!(Duhem);
