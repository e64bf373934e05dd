//! The Jiles–Atherton model (`model::operators::jiles_atherton`): dM/dH from the
//! anhysteretic (Langevin, with its series below |x| = 0.1, or tanh) and the irreversible
//! magnetisation, in the orientation's sign, with M or B = μ₀(H + M) as the output;
//! integrated by the differential driver ([`super::differential`]).

use super::differential::{self, EmitOde};
use crate::export::code::{lit, local, select, Block, Expr, Ty};
use crate::export::program::{Ns, Program};
use crate::model::operators::jiles_atherton::MU0;
use crate::model::operators::{Anhysteretic, JaOutput, JilesAtherton};
use crate::Result;

/// The anhysteretic shape L(x) and L'(x) into the locals `l` and `dl`.
fn shape(b: &mut Block, kind: Anhysteretic, x: Expr) {
    match kind {
        Anhysteretic::Langevin => {
            let x2 = b.let_("x2", x.clone() * x.clone());
            let third = lit(1.0 / 3.0);
            let series_l = x.clone()
                * (third.clone()
                    - x2.clone()
                        * (lit(1.0 / 45.0)
                            - x2.clone() * (lit(2.0 / 945.0) - x2.clone() / 4725.0)));
            let series_dl = third
                - x2.clone() * (lit(1.0 / 15.0) - x2.clone() * (lit(2.0 / 189.0) - x2 / 675.0));
            let small = b.local("small", Ty::Flag, false, x.clone().abs().lt(0.1));
            let sh = b.let_("sh", x.clone().sinh());
            let inv_x2 = 1.0 / (x.clone() * x.clone());
            let large_dl = select(
                sh.clone().is_finite(),
                inv_x2.clone() - 1.0 / (sh.clone() * sh),
                inv_x2,
            );
            b.let_(
                "l",
                select(small.clone(), series_l, 1.0 / x.clone().tanh() - 1.0 / x),
            );
            b.let_("dl", select(small, series_dl, large_dl));
        }
        Anhysteretic::Tanh => {
            let t = b.let_("l", x.tanh());
            b.let_("dl", 1.0 - t.clone() * t);
        }
    }
}

impl EmitOde for JilesAtherton {
    fn emit_slope(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        let s = self.orientation.sign();
        let ja = self.clone();
        prog.function(
            &ns.name("slope"),
            &[("u", Ty::F64), ("m", Ty::F64), ("d", Ty::F64)],
            Some(Ty::F64),
            move |b| {
                // dm_dh(h = s·u, m, δ = s·d)
                let h = b.let_("hh", s * local("u"));
                let delta = b.let_("delta", s * local("d"));
                let m = local("m");
                let x = b.let_("xa", (h + ja.alpha * m.clone()) / ja.a);
                shape(b, ja.anhysteretic, x);
                let man = b.let_("man", ja.ms * local("l"));
                let dman = b.let_("dman", ja.ms / ja.a * local("dl"));
                let mirr = b.let_("mirr", (m - ja.c * man.clone()) / (1.0 - ja.c));
                let gap = b.let_("gap", man - mirr);
                let dmirr = b.var("dmirr", 0.0);
                b.if_((gap.clone() * delta.clone()).gt(0.0), |b| {
                    let den = b.let_("den1", delta.clone() * ja.k - ja.alpha * gap.clone());
                    b.if_((den.clone() * delta.clone()).le(0.0), |b| {
                        b.ret(s * Expr::Nan)
                    });
                    b.set("dmirr", gap.clone() / den);
                });
                let den = b.let_("den", 1.0 - ja.alpha * ja.c * dman.clone());
                b.if_(den.clone().le(0.0), |b| b.ret(s * Expr::Nan));
                b.ret(s * (((1.0 - ja.c) * dmirr + ja.c * dman) / den));
            },
        )
    }
    fn emit_output(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        let (output, sign) = (self.output, self.orientation.sign());
        prog.function(
            &ns.name("output"),
            &[("u", Ty::F64), ("m", Ty::F64)],
            Some(Ty::F64),
            |b| match output {
                JaOutput::Magnetisation => b.ret(local("m")),
                JaOutput::FluxDensity => b.ret(MU0 * (sign * local("u") + local("m"))),
            },
        )
    }
}

differential::differential_emit!(JilesAtherton);
