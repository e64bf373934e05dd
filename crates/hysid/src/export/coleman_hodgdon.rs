//! The Coleman–Hodgdon recursion (`model::coleman_hodgdon`) as streaming code, and its
//! per-sample inverse (`model::compensate`):
//! y(t) = y(t−1) + α|Δx|(f(x) − y(t−1)) + g(x)Δx with the odd piecewise-linear f and the
//! even piecewise-constant g, in the library's order of operations.
//!
//! The forward step errors (the error flag) where α·|Δx| > 1 + 1e-12, as the library's rate
//! check refuses the record (1 + 4ε in single precision, and the clipping tolerances those of
//! `float`: [`typed`]). A model that starts from the measured output
//! (`initial_output: measured`) has no forward stream (a stream has no measured output);
//! its compensator starts from the first reference, as `hysid compensate` does.

use super::code::{call, local, select, typed, Expr, Ty};
use super::program::{mark_clip, Ns, Program, DIVERGED_FIELD};
use super::solve;
use crate::model::coleman_hodgdon::InitialOutput;
use crate::model::ColemanHodgdon;
use crate::Result;

/// The recursion's fields: the last output and input, and whether a sample was taken.
struct Recursion {
    y: String,
    x: String,
    started: String,
    step: String,
}

/// Emits the fields and `ns.ch_step(y_prev, x_prev, x) -> f64` (`ColemanHodgdon::step`).
fn recursion(ch: &ColemanHodgdon, ns: &Ns, prog: &mut Program) -> Result<Recursion> {
    let y = prog.field(&ns.name("y"), Ty::F64, None, "the last output")?;
    let x = prog.field(&ns.name("x"), Ty::F64, None, "the last input")?;
    let started = prog.field(
        &ns.name("started"),
        Ty::Flag,
        None,
        "a first sample was taken",
    )?;
    let (alpha, m1, m2, c1, c2, d) = (ch.alpha(), ch.m1(), ch.m2(), ch.c1(), ch.c2(), ch.d());
    let step = prog.function(
        &ns.name("ch_step"),
        &[("y_prev", Ty::F64), ("x_prev", Ty::F64), ("x", Ty::F64)],
        Some(Ty::F64),
        |b| {
            let x = local("x");
            let dx = b.let_("dx", x.clone() - local("x_prev"));
            let outside = b.local("outside", Ty::Flag, false, x.clone().abs().gt(d));
            let signum0 = select(x.clone().gt(0.0), 1.0, select(x.clone().lt(0.0), -1.0, 0.0));
            let f = b.let_(
                "f",
                select(
                    outside.clone(),
                    m2 * x.clone() + (m1 - m2) * d * signum0,
                    m1 * x,
                ),
            );
            let g = b.let_("g", select(outside, c2, c1));
            let y_prev = local("y_prev");
            b.ret(y_prev.clone() + alpha * dx.clone().abs() * (f - y_prev) + g * dx);
        },
    )?;
    Ok(Recursion {
        y,
        x,
        started,
        step,
    })
}

/// Emits `ns.ch(x) -> f64`: the hysteresis from the output `v0` at the first sample.
pub fn forward(ch: &ColemanHodgdon, v0: f64, ns: &Ns, prog: &mut Program) -> Result<String> {
    let rec = recursion(ch, ns, prog)?;
    let alpha = ch.alpha();
    prog.function(&ns.name("ch"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
        let (y, x, v) = (
            Expr::State(rec.y.clone()),
            Expr::State(rec.x.clone()),
            local("v"),
        );
        b.if_else(
            Expr::State(rec.started.clone()),
            |b| {
                let rate = alpha * (v.clone() - x.clone()).abs();
                // 1 + 4 float ε in single precision (1 + 1e-12 rounds to 1 in float).
                let limit = typed(1.0 + 1e-12, 1.0 + 4.0 * f32::EPSILON as f64);
                b.if_(rate.gt(limit), |b| {
                    b.set_state(DIVERGED_FIELD, Expr::Flag(true))
                });
                b.set_state(
                    &rec.y,
                    call(&rec.step, vec![y.clone(), x.clone(), v.clone()]),
                );
            },
            |b| {
                b.set_state(&rec.y, v0);
                b.set_state(&rec.started, Expr::Flag(true));
            },
        );
        b.set_state(&rec.x, v.clone());
        b.ret(y);
    })
}

/// Emits `ns.ch_inverse(r) -> f64` (`compensate`'s `coleman_hodgdon_inverse`).
pub fn inverse(
    ch: &ColemanHodgdon,
    initial: InitialOutput,
    ns: &Ns,
    prog: &mut Program,
) -> Result<String> {
    let rec = recursion(ch, ns, prog)?;
    let alpha = ch.alpha();
    let reach = if alpha > 0.0 {
        1.0 / alpha
    } else {
        f64::MAX.sqrt()
    };
    let (m1, m2, d) = (ch.m1(), ch.m2(), ch.d());
    let f = prog.function(&ns.name("f"), &[("x", Ty::F64)], Some(Ty::F64), |b| {
        let x = local("x");
        let outer = m2 * x.clone() + (m1 - m2) * d * x.clone().signum();
        b.ret(select(x.clone().abs().le(d), m1 * x, outer));
    })?;
    let solve_f = solve::emit(prog, &ns.sub("f"), &f)?;
    let step_c = rec.step.clone();
    let (y_s, x_s) = (Expr::State(rec.y.clone()), Expr::State(rec.x.clone()));
    let (y_c, x_c) = (y_s.clone(), x_s.clone());
    let trial = prog.function(
        &ns.name("trial"),
        &[("v", Ty::F64)],
        Some(Ty::F64),
        move |b| {
            let clamped = b.let_(
                "xv",
                local("v").clamp(x_c.clone() - reach, x_c.clone() + reach),
            );
            b.ret(call(&step_c, vec![y_c, x_c, clamped]));
        },
    )?;
    let solve_step = solve::emit(prog, &ns.sub("r"), &trial)?;
    let span_f = d.abs().max(1.0).min(reach);
    prog.function(
        &ns.name("ch_inverse"),
        &[("r", Ty::F64)],
        Some(Ty::F64),
        |b| {
            let r = local("r");
            b.if_else(
                Expr::State(rec.started.clone()),
                |b| {
                    let args = vec![
                        r.clone(),
                        x_s.clone(),
                        reach.into(),
                        Expr::Flag(false),
                        Expr::Flag(false),
                    ];
                    let solved = b.let_("solved", call(&solve_step, args));
                    let xt = b.let_("xt", solved.clamp(x_s.clone() - reach, x_s.clone() + reach));
                    b.set_state(
                        &rec.y,
                        call(&rec.step, vec![y_s.clone(), x_s.clone(), xt.clone()]),
                    );
                    b.set_state(&rec.x, xt);
                    // Clipped where the solve clipped, or where the new output missed r (the
                    // recursion need not be monotone on every branch).
                    let missed = (y_s.clone() - r.clone())
                        .abs()
                        .gt(typed(1e-9, 1e-5) * (1.0 + r.clone().abs()));
                    mark_clip(b, Expr::State(ns.sub("r").name("clipped")).or(missed));
                },
                |b| {
                    let y0 = match initial {
                        InitialOutput::Measured => r.clone(),
                        InitialOutput::Zero => 0.0.into(),
                    };
                    let x0 = if m1 <= 0.0 {
                        Expr::from(0.0)
                    } else {
                        let args = vec![
                            y0.clone(),
                            0.0.into(),
                            span_f.into(),
                            Expr::Flag(true),
                            Expr::Flag(true),
                        ];
                        let x = b.let_("x0", call(&solve_f, args));
                        select(x.clone().is_finite(), x, 0.0)
                    };
                    b.set_state(&rec.x, x0);
                    // The first reference counts as clipped when the start misses it.
                    let missed = (y0.clone() - r.clone())
                        .abs()
                        .gt(typed(1e-12, 16.0 * f32::EPSILON as f64) * (1.0 + r.clone().abs()));
                    mark_clip(b, missed);
                    b.set_state(&rec.y, y0);
                    b.set_state(&rec.started, Expr::Flag(true));
                },
            );
            b.ret(x_s.clone());
        },
    )
}
