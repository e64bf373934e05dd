//! The static Bouc–Wen operator (`model::operators::bouc_wen`):
//! dw/du = A − (β·s + γ)|w|ⁿ with s = +1 when δ·w ≥ 0 and −1 otherwise, y = kₓu + k_w w,
//! integrated by the differential driver ([`super::differential`]).

use super::differential::{self, EmitOde};
use crate::export::code::{local, select, Ty};
use crate::export::program::{Ns, Program};
use crate::model::operators::BoucWen;
use crate::Result;

impl EmitOde for BoucWen {
    fn emit_slope(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        let (a, beta, gamma, n) = (self.a, self.beta, self.gamma, self.n);
        prog.function(
            &ns.name("slope"),
            &[("u", Ty::F64), ("w", Ty::F64), ("d", Ty::F64)],
            Some(Ty::F64),
            |b| {
                let w = local("w");
                let s = b.let_("s", select((local("d") * w.clone()).ge(0.0), 1.0, -1.0));
                let aw = w.abs();
                let power = if n == 1.0 { aw } else { aw.powf(n) };
                b.ret(a - (beta * s + gamma) * power);
            },
        )
    }
    fn emit_output(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        let (kx, kw) = (self.kx, self.kw);
        prog.function(
            &ns.name("output"),
            &[("u", Ty::F64), ("w", Ty::F64)],
            Some(Ty::F64),
            |b| {
                b.ret(kx * local("u") + kw * local("w"));
            },
        )
    }
}

differential::differential_emit!(BoucWen);
