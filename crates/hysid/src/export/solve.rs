//! The monotone per-sample solve of the rate-independent inverses, emitted once per operator
//! that needs it: a transliteration of `model::operators::solve_monotone` (bracketing by
//! doubling steps, then the Illinois variant of regula falsi, at most 300 iterations), with
//! the same constants and the same order of operations, so the generated inverse picks the
//! library's root to the bit. In single precision the tolerances tied to the resolution of
//! the type are those of `float` ([`typed`], [`epsilon`]): the same stopping rules, reached
//! after as many iterations as in double.

use super::code::{epsilon, idx, lit, local, typed, Expr, Ty};
use super::program::{Ns, Program};
use super::stmt::Block;
use crate::Result;
use std::ops::Not;

/// Declares the flag field `ns.clipped` of an inverse's solve: set when the last target lay
/// beyond a saturation level. Returns its name.
pub fn clipped_field(prog: &mut Program, ns: &Ns) -> Result<String> {
    prog.field(
        &ns.name("clipped"),
        Ty::Flag,
        None,
        "the last solve clipped its target to a saturation level",
    )
}

/// Emits the narrowing of a bracket of the root of f(x) = v at a trial x strictly inside it,
/// the bracket in the mutable locals `a`, `fa`, `b`, `fb` (f(a) ≤ v ≤ f(b)), as the bounded
/// Preisach and KP solves do (`Preisach::solve`, `Kp::solve`): `fx = f(x)`; return x when
/// fx = v; else x becomes a (fx < v, then `below` adds its statements: the root lies above x)
/// or b. Returns the local `fx`.
pub fn narrow(b: &mut Block, fx: Expr, x: Expr, v: Expr, below: impl FnOnce(&mut Block)) -> Expr {
    let fx = b.let_("fx", fx);
    b.if_(fx.clone().eq(v.clone()), |b| b.ret(x.clone()));
    b.if_else(
        fx.clone().lt(v),
        |b| {
            b.set("a", x.clone());
            b.set("fa", fx.clone());
            below(b);
        },
        |b| {
            b.set("b", x.clone());
            b.set("fb", fx.clone());
        },
    );
    fx
}

/// Emits `ns.solve(target, center, span, unbounded_below, unbounded_above) -> f64`, the root
/// of `branch(x) = target` for the helper `branch` (a non-decreasing function of x that only
/// reads the state). It sets the flag field `ns.clipped` when the target lay beyond a
/// saturation level. Returns the solver's name.
pub fn emit(prog: &mut Program, ns: &Ns, branch: &str) -> Result<String> {
    prog.bound(
        "The monotone solve (bracketing by doubling steps, then Illinois regula falsi) \
         evaluates its branch at most 2 + D + 300 + 2 times a step, D the doublings of the \
         bracket: none where the branch is bounded, else at most floor(log2(1e30 / s)) + 1 \
         from its half-width s (the doubling stops beyond 1e30).",
    );
    let clipped = clipped_field(prog, ns)?;
    let f = |x: Expr| Expr::Call(branch.into(), vec![x]);
    let illinois = prog.function(
        &ns.name("illinois"),
        &[
            ("target", Ty::F64),
            ("a", Ty::F64),
            ("fa", Ty::F64),
            ("b", Ty::F64),
            ("fb", Ty::F64),
        ],
        Some(Ty::F64),
        |b| {
            let target = local("target");
            let lo = b.var("lo", local("a"));
            let flo = b.var("flo", local("fa") - target.clone());
            let hi = b.var("hi", local("b"));
            let fhi = b.var("fhi", local("fb") - target.clone());
            b.if_(flo.clone().eq(0.0), |b| b.ret(lo.clone()));
            b.if_(fhi.clone().eq(0.0), |b| b.ret(hi.clone()));
            let side = b.var("side", 0.0);
            b.for_("_iteration", idx(0), idx(300), |b, _| {
                // ε of the code's type: in float the double ε is never reached, and every
                // solve would run to the cap (the smallest width: 1e-300 rounds to 0 in
                // float, the smallest normal float instead).
                let width = lit(2.0)
                    * epsilon()
                    * lo.clone()
                        .abs()
                        .max(hi.clone().abs())
                        .max(typed(1e-300, f32::MIN_POSITIVE as f64));
                b.if_((hi.clone() - lo.clone()).le(width), |b| b.break_());
                let m = b.var(
                    "m",
                    (lo.clone() * fhi.clone() - hi.clone() * flo.clone())
                        / (fhi.clone() - flo.clone()),
                );
                b.if_(
                    m.clone().gt(lo.clone()).and(m.clone().lt(hi.clone())).not(),
                    |b| b.set("m", 0.5 * (lo.clone() + hi.clone())),
                );
                let fm = b.let_("fm", f(m.clone()) - target.clone());
                b.if_(fm.clone().eq(0.0), |b| b.ret(m.clone()));
                b.if_else(
                    fm.clone().lt(0.0),
                    |b| {
                        b.set("lo", m.clone());
                        b.set("flo", fm.clone());
                        b.if_(side.clone().eq(-1.0), |b| b.set("fhi", fhi.clone() * 0.5));
                        b.set("side", -1.0);
                    },
                    |b| {
                        b.set("hi", m.clone());
                        b.set("fhi", fm.clone());
                        b.if_(side.clone().eq(1.0), |b| b.set("flo", flo.clone() * 0.5));
                        b.set("side", 1.0);
                    },
                );
            });
            b.if_(
                (f(lo.clone()) - target.clone())
                    .abs()
                    .le((f(hi.clone()) - target.clone()).abs()),
                |b| b.ret(lo.clone()),
            );
            b.ret(hi);
        },
    )?;
    prog.function(
        &ns.name("solve"),
        &[
            ("target", Ty::F64),
            ("center", Ty::F64),
            ("half_width", Ty::F64),
            ("unbounded_below", Ty::Flag),
            ("unbounded_above", Ty::Flag),
        ],
        Some(Ty::F64),
        |b| {
            let target = local("target");
            let w = local("half_width");
            let span = b.let_(
                "span",
                crate::export::code::select(w.clone().gt(0.0).and(w.clone().is_finite()), w, 1.0),
            );
            let lo = b.var("lo", local("center") - span.clone());
            let hi = b.var("hi", local("center") + span.clone());
            let flo = b.var("flo", f(lo.clone()));
            let fhi = b.var("fhi", f(hi.clone()));
            // A target counts as clipped beyond 1e-12 of its size in double, 16 float ε
            // (about 1.9e-6) in single, where the saturation level itself is only known
            // to the float resolution.
            let tol = b.let_(
                "tol",
                typed(1e-12, 16.0 * f32::EPSILON as f64) * (1.0 + target.clone().abs()),
            );
            let step = b.var("step", span.clone());
            b.while_(fhi.clone().lt(target.clone()), |b| {
                b.if_(
                    local("unbounded_above").not().or(step.clone().gt(1e30)),
                    |b| {
                        b.set_state(&clipped, (target.clone() - fhi.clone()).gt(tol.clone()));
                        b.ret(hi.clone());
                    },
                );
                b.set("lo", hi.clone());
                b.set("flo", fhi.clone());
                b.set("step", step.clone() * 2.0);
                b.set("hi", hi.clone() + step.clone());
                b.set("fhi", f(hi.clone()));
            });
            b.set("step", span);
            b.while_(flo.clone().gt(target.clone()), |b| {
                b.if_(
                    local("unbounded_below").not().or(step.clone().gt(1e30)),
                    |b| {
                        b.set_state(&clipped, (flo.clone() - target.clone()).gt(tol.clone()));
                        b.ret(lo.clone());
                    },
                );
                b.set("hi", lo.clone());
                b.set("fhi", flo.clone());
                b.set("step", step.clone() * 2.0);
                b.set("lo", lo.clone() - step.clone());
                b.set("flo", f(lo.clone()));
            });
            b.set_state(&clipped, Expr::Flag(false));
            b.ret(Expr::Call(illinois.clone(), vec![target, lo, flo, hi, fhi]));
        },
    )
}
