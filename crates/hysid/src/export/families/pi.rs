//! The Prandtl–Ishlinskii operator (`model::operators::pi`): G\[u\] = c + a₀u + Σ aᵢ F_{rᵢ}\[u\]
//! with the play states zᵢ (from 0) in the state; G⁻¹ is Krejčí & Kuhnen's analytic inverse
//! b₀(v − c) + Σ bᵢ F_{sᵢ}\[v − c\] (its constants computed by the library itself, so they are
//! the same bits), or, when some âᵢ ≤ 0, the library's exact per-sample solve of the
//! piecewise-linear branch. A static envelope E(u) (`model::operators::envelope`) is its own
//! helper `ns.envelope(x)`, added after c + a₀x as the library adds it, with the library's
//! Horner coefficients. The Maxwell-slip and generalised PI families reuse these pieces.

use super::oriented::EmitCore;
use crate::export::code::{idx, lit, local, select, Block, Expr, Ty};
use crate::export::program::{Ns, Program};
use crate::export::solve;
use crate::model::operators::{Envelope, Orientation, PrandtlIshlinskii};
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

/// E(x) of a static envelope: `ns.envelope(x)`, its end tangents beyond [lo, hi] and
/// Horner's rule in t = (x − lo)·(1/w) on it, p = m_n then p = p·t + mₖ (`Envelope::value`).
fn emit_envelope(e: &Envelope, ns: &Ns, prog: &mut Program) -> Result<String> {
    let (c_lo, c_hi) = e.end_slopes();
    let (lo, hi, top, inverse_width) = (e.lo(), e.hi(), e.top(), e.inverse_width());
    let monomial = e.monomial().to_vec();
    prog.function(
        &ns.name("envelope"),
        &[("x", Ty::F64)],
        Some(Ty::F64),
        |b| {
            let x = local("x");
            let t = b.let_("t", (x.clone() - lo) * inverse_width);
            let (last, rest) = monomial.split_last().expect("an envelope's coefficients");
            let horner = rest
                .iter()
                .rev()
                .fold(lit(*last), |p, &m| p * t.clone() + m);
            let above = top + c_hi * (x.clone() - hi);
            let below = c_lo * (x.clone() - lo);
            b.ret(select(
                x.clone().lt(lo),
                below,
                select(x.gt(hi), above, horner),
            ));
        },
    )
}

/// c + a₀x + E(x), the static part of G, in the library's order (`static_part`).
fn static_part(pi: &PrandtlIshlinskii, envelope: &Option<String>, x: Expr) -> Expr {
    let (c, a0) = (pi.offset(), pi.a0());
    let y = c + a0 * x.clone();
    match envelope {
        Some(e) => y + Expr::Call(e.clone(), vec![x]),
        None => y,
    }
}

/// The envelope helper of `pi`, if it has one.
fn envelope_of(pi: &PrandtlIshlinskii, ns: &Ns, prog: &mut Program) -> Result<Option<String>> {
    pi.envelope()
        .map(|e| emit_envelope(e, ns, prog))
        .transpose()
}

/// G of a PI operator: `ns.g(x)`.
pub fn emit_forward(pi: &PrandtlIshlinskii, ns: &Ns, prog: &mut Program) -> Result<String> {
    prog.bound(format!(
        "The PI operator updates its {} plays once a step.",
        pi.weights().len()
    ));
    let plays = plays(prog, ns, pi.weights(), pi.thresholds())?;
    let envelope = envelope_of(pi, ns, prog)?;
    prog.function(&ns.name("g"), &[("x", Ty::F64)], Some(Ty::F64), |b| {
        b.var("acc", static_part(pi, &envelope, local("x")));
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
    let envelope = envelope_of(pi, ns, prog)?;
    let at = |name: &str, i: Expr| Expr::Table(name.into(), Box::new(i));
    let zi = |i: Expr| Expr::StateAt(z.clone(), Box::new(i));
    // G's output for the input x from the play states (not updated).
    let branch = prog.function(&ns.name("branch"), &[("x", Ty::F64)], Some(Ty::F64), |b| {
        let sum = b.var("sum", 0.0);
        b.for_("i", idx(0), idx(n), |b, i| {
            let step = play_step(zi(i.clone()), local("x"), at(&r, i.clone()));
            b.set("sum", sum.clone() + at(&a, i) * step);
        });
        b.ret(static_part(pi, &envelope, local("x")) + sum);
    })?;
    let solve = solve::emit(prog, ns, &branch)?;
    let plays = 2.0 * pi.thresholds().last().copied().unwrap_or(0.0);
    let range = pi.envelope().map(|e| (e.lo(), e.hi()));
    let (below, above) = pi.unbounded();
    let (below, above) = (Expr::Flag(below), Expr::Flag(above));
    let name = prog.function(&ns.name("g_inv"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
        let up = Expr::State(u_prev.clone());
        // `solve_reach`: 2rₙ, with an envelope max(2rₙ, hi − u_prev, u_prev − lo)
        let reach = match range {
            Some((lo, hi)) => lit(plays).max(lit(hi) - up.clone()).max(up.clone() - lo),
            None => lit(plays),
        };
        let span = reach + 1e-9 * (1.0 + up.clone().abs()) + f64::MIN_POSITIVE;
        let args = vec![local("v"), up, span, below.clone(), above.clone()];
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
