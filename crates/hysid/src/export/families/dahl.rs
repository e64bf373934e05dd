//! Dahl friction (`model::operators::dahl`): dF/du = s·σ·sgn(β)|β|ⁱ with
//! β = 1 − F/F_c·s·δ and s = −(the orientation's sign), F the state and the output,
//! integrated by the differential driver ([`super::differential`]).

use super::differential::{self, EmitOde};
use crate::export::code::{lit, local, Ty};
use crate::export::program::{Ns, Program};
use crate::model::operators::Dahl;
use crate::Result;

impl EmitOde for Dahl {
    fn emit_slope(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        let s = -self.orientation.sign();
        let (sigma, fc, i) = (self.sigma, self.fc, self.i);
        prog.function(
            &ns.name("slope"),
            &[("u", Ty::F64), ("f", Ty::F64), ("d", Ty::F64)],
            Some(Ty::F64),
            |b| {
                let base = b.let_("base", 1.0 - local("f") / fc * s * local("d"));
                b.ret(lit(s) * sigma * base.clone().signum() * base.abs().powf(i));
            },
        )
    }
    fn emit_output(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        prog.function(
            &ns.name("output"),
            &[("u", Ty::F64), ("f", Ty::F64)],
            Some(Ty::F64),
            |b| b.ret(local("f")),
        )
    }
}

differential::differential_emit!(Dahl);
