//! The orientation wrapper of the rate-independent families (as the library's
//! `oriented_simulate` and `oriented_invert`): with the core G of a family and the sign s = ±1
//! of its [`Orientation`],
//!
//! | orientation | forward Γ\[u\] | inverse |
//! |---|---|---|
//! | Γ = ±G | s·G\[u\] | G⁻¹\[s·r\] |
//! | Γ = ±G⁻¹ | s·G⁻¹\[u\] | G\[s·r\] |
//!
//! An input outside the domain of G⁻¹ in the forward step (the library's simulate refuses the
//! record) sets the error flag.

use super::Emit;
use crate::export::code::{lit, local, typed, Expr, Ty};
use crate::export::program::{mark_clip, Ns, Program, DIVERGED_FIELD};
use crate::model::operators::differential::HistoryRun;
use crate::model::operators::Orientation;
use crate::Result;

/// A core operator G, emitted as streaming code.
pub trait EmitCore {
    /// The orientation mapping G onto Γ.
    fn orientation(&self) -> Orientation;
    /// Emits `ns.g(x) -> f64`: G's output for the input x, advancing G's state. Returns the
    /// helper's name.
    fn emit_core(&self, ns: &Ns, prog: &mut Program) -> Result<String>;
    /// Emits `ns.g_inv(v) -> f64`: G⁻¹'s output for v, advancing its state; returns the
    /// helper's name and, for an inverse that can clip, the name of the flag field it sets
    /// when it clipped.
    fn emit_core_inverse(&self, ns: &Ns, prog: &mut Program) -> Result<(String, Option<String>)>;
}

impl<T: EmitCore> Emit for T {
    fn emit_forward(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        let o = self.orientation();
        let s = o.sign();
        if o.inverse {
            let (g_inv, clipped) = self.emit_core_inverse(ns, prog)?;
            prog.function(&ns.name("step"), &[("x", Ty::F64)], Some(Ty::F64), |b| {
                let v = b.let_("v", Expr::Call(g_inv, vec![local("x")]));
                if let Some(clipped) = clipped {
                    b.if_(Expr::State(clipped), |b| {
                        b.set_state(DIVERGED_FIELD, Expr::Flag(true))
                    });
                }
                b.ret(lit(s) * v);
            })
        } else {
            let g = self.emit_core(ns, prog)?;
            prog.function(&ns.name("step"), &[("x", Ty::F64)], Some(Ty::F64), |b| {
                b.ret(lit(s) * Expr::Call(g, vec![local("x")]));
            })
        }
    }

    /// The history is never run here: these families' inverses are primed instead
    /// ([`super::inverse_after`]).
    fn emit_inverse(
        &self,
        _history: Option<HistoryRun>,
        ns: &Ns,
        prog: &mut Program,
    ) -> Result<String> {
        let o = self.orientation();
        let s = o.sign();
        if !o.inverse {
            // Γ = ±G: u = G⁻¹[s·r], clipped where G⁻¹'s solve clips.
            let (g_inv, clipped) = self.emit_core_inverse(ns, prog)?;
            return prog.function(&ns.name("inverse"), &[("r", Ty::F64)], Some(Ty::F64), |b| {
                let u = b.let_("u", Expr::Call(g_inv, vec![lit(s) * local("r")]));
                if let Some(clipped) = clipped {
                    mark_clip(b, Expr::State(clipped));
                }
                b.ret(u);
            });
        }
        // Γ = ±G⁻¹: u = G[ρ], ρ = s·r; clipped when G⁻¹[u] (a second, checking state of G⁻¹)
        // misses ρ by more than 1e-9 of the largest |ρ| so far (at least 1).
        let g = self.emit_core(ns, prog)?;
        let check = ns.sub("check");
        let (g_inv, _) = self.emit_core_inverse(&check, prog)?;
        let scale = prog.field(
            &check.name("scale"),
            Ty::F64,
            None,
            "the largest |reference| so far (at least 1)",
        )?;
        prog.init(|b| b.set_state(&scale, 1.0));
        prog.function(&ns.name("inverse"), &[("r", Ty::F64)], Some(Ty::F64), |b| {
            let rho = b.let_("rho", lit(s) * local("r"));
            let u = b.let_("u", Expr::Call(g, vec![rho.clone()]));
            let y = b.let_("y", Expr::Call(g_inv, vec![u.clone()]));
            b.set_state(&scale, Expr::State(scale.clone()).max(rho.clone().abs()));
            // (1e-5 in single precision, about 80 float ulps, as the float solves meet ρ
            // only to their resolution.)
            let tol = typed(1e-9, 1e-5);
            mark_clip(b, (y - rho).abs().gt(tol * Expr::State(scale.clone())));
            b.ret(u);
        })
    }
}
