//! The Prandtl–Ishlinskii operator (`model::operators::pi`): G\[u\] = c + a₀u + Σ aᵢ F_{rᵢ}\[u\]
//! with the play states zᵢ (from 0) in the state; G⁻¹ is Krejčí & Kuhnen's analytic inverse
//! b₀(v − c) + Σ bᵢ F_{sᵢ}\[v − c\] (its constants computed by the library itself, so they are
//! the same bits), or, when some âᵢ ≤ 0, the library's exact per-sample solve of the
//! piecewise-linear branch. The Maxwell-slip and generalised PI families reuse these pieces.

use super::oriented::EmitCore;
use crate::export::code::{idx, local, Block, Expr, Ty};
use crate::export::program::{Ns, Program};
use crate::export::solve;
use crate::model::operators::{Orientation, PrandtlIshlinskii};
use crate::Result;

/// F_r\[u\] one step: max(u − r, min(u + r, z)).
pub fn play_step(z: Expr, u: Expr, r: Expr) -> Expr {
    (u.clone() - r.clone()).max((u + r).min(z))
}

/// Emits the plays of weights `weights` on thresholds `thresholds` (state `ns.z`, tables
/// `ns.A`, `ns.R`) into `b`: advances every play with the input `x` and adds aᵢ·zᵢ to the
/// mutable local `acc`, play by play.
pub fn plays(
    prog: &mut Program,
    ns: &Ns,
    weights: &[f64],
    thresholds: &[f64],
) -> Result<impl FnOnce(&mut Block, Expr)> {
    let n = weights.len();
    let z = prog.field(&ns.name("z"), Ty::F64, Some(n), "the play states")?;
    let a = prog.table(&ns.table("a"), weights.to_vec())?;
    let r = prog.table(&ns.table("r"), thresholds.to_vec())?;
    Ok(move |b: &mut Block, x: Expr| {
        b.for_("i", idx(0), idx(n), |b, i| {
            let zi = Expr::StateAt(z.clone(), Box::new(i.clone()));
            let ri = Expr::Table(r.clone(), Box::new(i.clone()));
            b.set_at(&z, i.clone(), play_step(zi.clone(), x.clone(), ri));
            let ai = Expr::Table(a.clone(), Box::new(i));
            b.set("acc", local("acc") + ai * zi);
        });
    })
}

/// G of a PI operator: `ns.g(x)`.
pub fn emit_forward(pi: &PrandtlIshlinskii, ns: &Ns, prog: &mut Program) -> Result<String> {
    prog.bound(format!(
        "The PI operator updates its {} plays once a step.",
        pi.weights().len()
    ));
    let plays = plays(prog, ns, pi.weights(), pi.thresholds())?;
    let (c, a0) = (pi.offset(), pi.a0());
    prog.function(&ns.name("g"), &[("x", Ty::F64)], Some(Ty::F64), |b| {
        b.var("acc", c + a0 * local("x"));
        plays(b, local("x"));
        b.ret(local("acc"));
    })
}

/// G⁻¹ of a PI operator: `ns.g_inv(v)`, analytic or by the per-sample solve.
pub fn emit_inverse(
    pi: &PrandtlIshlinskii,
    ns: &Ns,
    prog: &mut Program,
) -> Result<(String, Option<String>)> {
    prog.bound(format!(
        "The PI inverse updates its {} plays once a step (and evaluates them once per \
         evaluation of a monotone solve, where it has one).",
        pi.weights().len()
    ));
    let c = pi.offset();
    match pi.inverse_parameters() {
        Some((b0, b, s)) => {
            let plays = plays(prog, &ns.sub("inv"), &b, &s)?;
            let name =
                prog.function(&ns.name("g_inv"), &[("v", Ty::F64)], Some(Ty::F64), |bl| {
                    let w = bl.let_("w", local("v") - c);
                    bl.var("acc", b0 * w.clone());
                    plays(bl, w);
                    bl.ret(local("acc"));
                })?;
            Ok((name, None))
        }
        None => emit_numerical_inverse(pi, ns, prog),
    }
}

/// G⁻¹ by the exact per-sample solve of the monotone branch (`backward_numerical`).
fn emit_numerical_inverse(
    pi: &PrandtlIshlinskii,
    ns: &Ns,
    prog: &mut Program,
) -> Result<(String, Option<String>)> {
    let n = pi.weights().len();
    let z = prog.field(&ns.name("z"), Ty::F64, Some(n), "the play states")?;
    let u_prev = prog.field(&ns.name("u_prev"), Ty::F64, None, "the last input")?;
    let a = prog.table(&ns.table("a"), pi.weights().to_vec())?;
    let r = prog.table(&ns.table("r"), pi.thresholds().to_vec())?;
    let (c, a0) = (pi.offset(), pi.a0());
    let at = |name: &str, i: Expr| Expr::Table(name.into(), Box::new(i));
    let zi = |i: Expr| Expr::StateAt(z.clone(), Box::new(i));
    // G's output for the input x from the play states (not updated).
    let branch = prog.function(&ns.name("branch"), &[("x", Ty::F64)], Some(Ty::F64), |b| {
        let sum = b.var("sum", 0.0);
        b.for_("i", idx(0), idx(n), |b, i| {
            let step = play_step(zi(i.clone()), local("x"), at(&r, i.clone()));
            b.set("sum", sum.clone() + at(&a, i) * step);
        });
        b.ret(c + a0 * local("x") + sum);
    })?;
    let solve = solve::emit(prog, ns, &branch)?;
    let r_max = pi.thresholds().last().copied().unwrap_or(0.0);
    let unbounded = Expr::Flag(pi.final_slope() > 0.0);
    let name = prog.function(&ns.name("g_inv"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
        let up = Expr::State(u_prev.clone());
        let span = 2.0 * r_max + 1e-9 * (1.0 + up.clone().abs()) + f64::MIN_POSITIVE;
        let args = vec![local("v"), up, span, unbounded.clone(), unbounded.clone()];
        let uk = b.let_("uk", Expr::Call(solve.clone(), args));
        b.for_("i", idx(0), idx(n), |b, i| {
            b.set_at(
                &z,
                i.clone(),
                play_step(zi(i.clone()), uk.clone(), at(&r, i)),
            );
        });
        b.set_state(&u_prev, uk.clone());
        b.ret(uk);
    })?;
    Ok((name, Some(ns.name("clipped"))))
}

impl EmitCore for PrandtlIshlinskii {
    fn orientation(&self) -> Orientation {
        PrandtlIshlinskii::orientation(self)
    }
    fn emit_core(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        emit_forward(self, ns, prog)
    }
    fn emit_core_inverse(&self, ns: &Ns, prog: &mut Program) -> Result<(String, Option<String>)> {
        emit_inverse(self, ns, prog)
    }
}
