//! Backlash (`model::operators::backlash`): G\[u\] = c + g·F_r\[u\] with the play state z
//! (from 0); G⁻¹ is the play's right inverse of Tao & Kokotović: with w = (v − c)/g,
//! uₖ = w + r when w rises, w − r when it falls, uₖ₋₁ when it holds.

use super::oriented::EmitCore;
use super::pi::play_step;
use crate::export::code::{local, select, Expr, Ty};
use crate::export::program::{Ns, Program};
use crate::model::operators::{Backlash, Orientation};
use crate::Result;

impl EmitCore for Backlash {
    fn orientation(&self) -> Orientation {
        Backlash::orientation(self)
    }

    fn emit_core(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        let z = prog.field(&ns.name("z"), Ty::F64, None, "the play state")?;
        let (r, c, g) = (self.half_width(), self.offset(), self.gain());
        prog.function(&ns.name("g"), &[("x", Ty::F64)], Some(Ty::F64), |b| {
            b.set_state(&z, play_step(Expr::State(z.clone()), local("x"), r.into()));
            b.ret(c + g * Expr::State(z.clone()));
        })
    }

    fn emit_core_inverse(&self, ns: &Ns, prog: &mut Program) -> Result<(String, Option<String>)> {
        let z = prog.field(&ns.name("w"), Ty::F64, None, "the last play output")?;
        let u_prev = prog.field(&ns.name("u_prev"), Ty::F64, None, "the last input")?;
        let (r, c, g) = (self.half_width(), self.offset(), self.gain());
        let name = prog.function(&ns.name("g_inv"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
            let w = b.let_("w", (local("v") - c) / g);
            let zs = Expr::State(z.clone());
            let uk = b.let_(
                "uk",
                select(
                    w.clone().gt(zs.clone()),
                    w.clone() + r,
                    select(w.clone().lt(zs), w.clone() - r, Expr::State(u_prev.clone())),
                ),
            );
            b.set_state(&z, w);
            b.set_state(&u_prev, uk.clone());
            b.ret(uk);
        })?;
        Ok((name, None))
    }
}
