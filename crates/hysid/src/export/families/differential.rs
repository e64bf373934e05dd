//! The driver of the differential families (`model::operators::differential`), emitted once
//! per operator: the state x integrated in the input between two samples by the embedded
//! Dormand–Prince 5(4) pair with the library's coefficients, tolerance (1e-10) and step
//! control, and the inverse's bracketing and Illinois solve of the sample's output. A family
//! supplies only its slope dx/du = F(u, x, δ) and output y = h(u, x) ([`EmitOde`]) and the
//! constants of its [`InputOde`] (initial state, scales, spans), computed by the library.
//!
//! **Sub-step budget and the error flag.** The library gives one simulation a budget of
//! 100 000 + 100·(samples) sub-steps; the generated step gives each sample interval
//! 100 000. An interval that exceeds its budget, whose step size underflows or whose slope
//! is not finite (the library's `Diverged` error), and a non-finite input, set the error
//! flag: the outputs then hold their last values until the next init.

use crate::export::code::{
    call, epsilon, idx, lit, local, min_positive, select, typed, Block, Expr, Ty,
};
use crate::export::program::{mark_clip, Ns, Program, DIVERGED_FIELD};
use crate::model::operators::differential::{HistoryRun, InputOde, BRACKET_DOUBLINGS, TOLERANCE};
use crate::Result;
use std::ops::Not;

/// The sub-steps one sample interval may take.
pub const SUBSTEP_BUDGET: usize = 100_000;

/// The integration's relative tolerance in single precision (the library's [`TOLERANCE`],
/// 1e-10, in double): 10⁻⁶, about 8 `float` ulps. The error estimate of a Dormand–Prince
/// step is a difference of slopes that each carry a rounding error of about ε·|k|, so a
/// tolerance below float resolution is never met and every step shrinks to its floor; at
/// 10⁻⁶ the float code takes about as many sub-steps as the double one, and its error,
/// a few 10⁻⁶ of the state's scale, stays well inside the single-precision bar of 10⁻⁴.
pub const SINGLE_TOLERANCE: f64 = 1e-6;

/// The integration's absolute tolerance in single precision, relative to the state's scale
/// (the library's, in double, is [`TOLERANCE`] times the scale): 10⁻¹⁴. The test is
/// err ≤ atol + rtol·max(|x|, |x_new|), and max(|x|, |x_new|) ≥ |x_new − x|/2, so the relative
/// term alone stays about 50 times above the rounding noise of the error estimate (a
/// difference of slopes, some ε·|x_new − x|/10) even where the state crosses 0: the absolute
/// term only keeps the test defined at x = x_new = 0. A larger one (10⁻⁶ of the scale)
/// accepted one-step errors at the kink of a Jiles–Atherton branch (where the irreversible
/// term sets in after a reversal) of 10⁻³ of a minor loop's range, when the loops are small
/// beside Mₛ: on the export's test sequence over ±1 A/m with the classic parameters the float
/// code differed by 5.7·10⁻⁴ of the range, now by 4·10⁻⁵.
pub const SINGLE_ABSOLUTE: f64 = 1e-14;

/// The inverse's output tolerance in single precision (1e-13 of |r| + |y| in double): 10⁻⁶,
/// the integration's tolerance, below which the float branch is noise.
pub const SINGLE_YTOL: f64 = 1e-6;

/// Implements [`super::Emit`] for a differential family (an [`EmitOde`]) through
/// [`forward`] and [`inverse`]: one line per family.
macro_rules! differential_emit {
    ($ty:ty) => {
        impl $crate::export::families::Emit for $ty {
            fn emit_forward(
                &self,
                ns: &$crate::export::program::Ns,
                prog: &mut $crate::export::program::Program,
            ) -> $crate::Result<String> {
                $crate::export::families::differential::forward(self, ns, prog)
            }
            fn emit_inverse(
                &self,
                history: Option<$crate::model::operators::differential::HistoryRun>,
                ns: &$crate::export::program::Ns,
                prog: &mut $crate::export::program::Program,
            ) -> $crate::Result<String> {
                $crate::export::families::differential::inverse(self, history, ns, prog)
            }
        }
    };
}
pub(crate) use differential_emit;

/// What a differential family supplies: its equations as helpers.
pub trait EmitOde: InputOde {
    /// Emits `ns.slope(u, x, d) -> f64`, the library's `InputOde::slope`.
    fn emit_slope(&self, ns: &Ns, prog: &mut Program) -> Result<String>;
    /// Emits `ns.output(u, x) -> f64`, the library's `InputOde::output`.
    fn emit_output(&self, ns: &Ns, prog: &mut Program) -> Result<String>;
}

/// The names the driver's pieces share.
struct Driver {
    x: String,
    u_prev: String,
    started: String,
    fail: String,
    advance: String,
    output: String,
}

/// Emits the state, the Dormand–Prince step and `ns.advance(x, u0, u1)`.
fn driver<O: EmitOde + ?Sized>(ode: &O, ns: &Ns, prog: &mut Program) -> Result<Driver> {
    let x = prog.field(&ns.name("x"), Ty::F64, None, "the state at the last input")?;
    let u_prev = prog.field(&ns.name("u_prev"), Ty::F64, None, "the last input")?;
    let started = prog.field(
        &ns.name("started"),
        Ty::Flag,
        None,
        "a first sample was taken",
    )?;
    let fail = prog.field(
        &ns.name("fail"),
        Ty::Flag,
        None,
        "the last integration failed",
    )?;
    let dp_err = prog.field(&ns.name("dp_err"), Ty::F64, None, "the last error estimate")?;
    let slope = ode.emit_slope(ns, prog)?;
    let output = ode.emit_output(ns, prog)?;
    let dp = prog.function(
        &ns.name("dormand_prince"),
        &[
            ("u", Ty::F64),
            ("x", Ty::F64),
            ("h", Ty::F64),
            ("d", Ty::F64),
        ],
        Some(Ty::F64),
        |b| {
            let (u, x, h) = (local("u"), local("x"), local("h"));
            let f = |du: Expr, xx: Expr| call(&slope, vec![u.clone() + du, xx, local("d")]);
            let k1 = b.let_("k1", f(lit(0.0), x.clone()));
            let k2 = b.let_(
                "k2",
                f(h.clone() / 5.0, x.clone() + h.clone() * k1.clone() / 5.0),
            );
            let c = |v: f64| lit(v);
            let k3 = b.let_(
                "k3",
                f(
                    0.3 * h.clone(),
                    x.clone()
                        + h.clone() * (c(3.0 / 40.0) * k1.clone() + c(9.0 / 40.0) * k2.clone()),
                ),
            );
            let k4 = b.let_(
                "k4",
                f(
                    0.8 * h.clone(),
                    x.clone()
                        + h.clone()
                            * (c(44.0 / 45.0) * k1.clone() - c(56.0 / 15.0) * k2.clone()
                                + c(32.0 / 9.0) * k3.clone()),
                ),
            );
            let k5 = b.let_(
                "k5",
                f(
                    c(8.0 / 9.0) * h.clone(),
                    x.clone()
                        + h.clone()
                            * (c(19372.0 / 6561.0) * k1.clone() - c(25360.0 / 2187.0) * k2.clone()
                                + c(64448.0 / 6561.0) * k3.clone()
                                - c(212.0 / 729.0) * k4.clone()),
                ),
            );
            let k6 = b.let_(
                "k6",
                f(
                    h.clone(),
                    x.clone()
                        + h.clone()
                            * (c(9017.0 / 3168.0) * k1.clone() - c(355.0 / 33.0) * k2.clone()
                                + c(46732.0 / 5247.0) * k3.clone()
                                + c(49.0 / 176.0) * k4.clone()
                                - c(5103.0 / 18656.0) * k5.clone()),
                ),
            );
            let x5 = b.let_(
                "x5",
                x.clone()
                    + h.clone()
                        * (c(35.0 / 384.0) * k1.clone()
                            + c(500.0 / 1113.0) * k3.clone()
                            + c(125.0 / 192.0) * k4.clone()
                            - c(2187.0 / 6784.0) * k5.clone()
                            + c(11.0 / 84.0) * k6.clone()),
            );
            let k7 = b.let_("k7", f(h.clone(), x5.clone()));
            let err = h
                * (c(71.0 / 57600.0) * k1 - c(71.0 / 16695.0) * k3 + c(71.0 / 1920.0) * k4
                    - c(17253.0 / 339200.0) * k5
                    + c(22.0 / 525.0) * k6
                    - c(1.0 / 40.0) * k7);
            b.set_state(&dp_err, err.abs());
            b.ret(x5);
        },
    )?;
    let h_max = ode.max_substep().abs().max(f64::MIN_POSITIVE);
    let scale = ode.state_scale().abs().max(f64::MIN_POSITIVE);
    let atol = typed(TOLERANCE * scale, SINGLE_ABSOLUTE * scale);
    let rtol = typed(TOLERANCE, SINGLE_TOLERANCE);
    let fail_c = fail.clone();
    let advance = prog.function(
        &ns.name("advance"),
        &[("x0", Ty::F64), ("u0", Ty::F64), ("u1", Ty::F64)],
        Some(Ty::F64),
        move |b| {
            let (u0, u1) = (local("u0"), local("u1"));
            b.set_state(&fail_c, Expr::Flag(false));
            let span = b.let_("span", u1.clone() - u0.clone());
            b.if_(span.clone().eq(0.0), |b| b.ret(local("x0")));
            let direction = b.let_("direction", span.clone().signum());
            let u = b.var("u", u0);
            let x = b.var("x", local("x0"));
            let h = b.var("h", span.abs().min(h_max));
            let budget = b.local("budget", Ty::Index, true, idx(SUBSTEP_BUDGET));
            let failed = |b: &mut Block| {
                b.set_state(&fail_c, Expr::Flag(true));
                b.ret(local("x"));
            };
            b.while_(budget.clone().gt(idx(0)), |b| {
                b.set("budget", budget.clone() - idx(1));
                let remaining = b.let_("remaining", (u1.clone() - u.clone()).abs());
                b.if_(remaining.clone().le(0.0), |b| b.ret(x.clone()));
                let last = b.local("last", Ty::Flag, false, h.clone().ge(remaining.clone()));
                let step = b.let_("step", select(last.clone(), remaining, h.clone()));
                let args = vec![
                    u.clone(),
                    x.clone(),
                    step.clone() * direction.clone(),
                    direction.clone(),
                ];
                let x_new = b.let_("x_new", call(&dp, args));
                let err = b.let_("err", Expr::State(dp_err.clone()));
                b.if_else(
                    x_new
                        .clone()
                        .is_finite()
                        .not()
                        .or(err.clone().is_finite().not()),
                    |b| {
                        let floor = typed(1e-14, 10.0 * f32::EPSILON as f64);
                        b.if_(step.clone().le(floor * (u.clone().abs() + h_max)), failed);
                        b.set("h", step.clone() * 0.25);
                    },
                    |b| {
                        let tol = b.let_(
                            "tol",
                            atol.clone() + rtol.clone() * x.clone().abs().max(x_new.clone().abs()),
                        );
                        b.if_(err.clone().le(tol.clone()), |b| {
                            let moved = u.clone() + step.clone() * direction.clone();
                            b.set("u", select(last.clone(), u1.clone(), moved));
                            b.set("x", x_new.clone());
                        });
                        let power = b.let_("power", 0.9 * (tol.clone() / err.clone()).powf(0.2));
                        let factor = b.let_(
                            "factor",
                            select((err.clone() * 6000.0).le(tol), 5.0, power.clamp(0.2, 5.0)),
                        );
                        b.set("h", (step.clone() * factor).min(h_max));
                        // Below ε·|u| a step would not move u at all.
                        let floor = typed(1e-15, f32::EPSILON as f64);
                        b.if_(h.clone().le(floor * (u.clone().abs() + h_max)), failed);
                    },
                );
            });
            failed(b);
        },
    )?;
    Ok(Driver {
        x,
        u_prev,
        started,
        fail,
        advance,
        output,
    })
}

/// Emits the forward step `ns.step(x)`: the state x₀ at the first sample, then advanced from
/// the last input to this one; the output h(u, x).
pub fn forward<O: EmitOde + ?Sized>(ode: &O, ns: &Ns, prog: &mut Program) -> Result<String> {
    prog.bound(format!(
        "The Dormand-Prince integration takes at most {SUBSTEP_BUDGET} sub-steps (7 slopes \
         each) a step; beyond, the step sets the error flag."
    ));
    let d = driver(ode, ns, prog)?;
    let x0 = ode.initial_state();
    prog.function(&ns.name("step"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
        let v = local("v");
        b.if_(v.clone().is_finite().not(), |b| {
            b.set_state(DIVERGED_FIELD, Expr::Flag(true))
        });
        b.if_else(
            Expr::State(d.started.clone()),
            |b| {
                let args = vec![
                    Expr::State(d.x.clone()),
                    Expr::State(d.u_prev.clone()),
                    v.clone(),
                ];
                b.set_state(&d.x, call(&d.advance, args));
                b.if_(Expr::State(d.fail.clone()), |b| {
                    b.set_state(DIVERGED_FIELD, Expr::Flag(true))
                });
            },
            |b| {
                b.set_state(&d.x, x0);
                b.set_state(&d.started, Expr::Flag(true));
            },
        );
        b.set_state(&d.u_prev, v.clone());
        b.ret(call(&d.output, vec![v, Expr::State(d.x.clone())]));
    })
}

/// Emits the inverse step `ns.inverse(r)` (`differential::invert`): the sample's output as
/// a function of the new input solved for r by `solve_sample` and its Illinois iteration;
/// with a declared `history`, the first command's trials v each run it from x₀ at v to the
/// turn and back (`differential::HistoryRun::state_at`, the turn by `families::turn_at`).
pub fn inverse<O: EmitOde + ?Sized>(
    ode: &O,
    history: Option<HistoryRun>,
    ns: &Ns,
    prog: &mut Program,
) -> Result<String> {
    prog.bound(format!(
        "The inverse integrates the branch at most {} times a step (the start and a probe, \
         {BRACKET_DOUBLINGS} doublings of the bracket each way, 200 Illinois iterations and \
         the root), each of at most {SUBSTEP_BUDGET} Dormand-Prince sub-steps.",
        3 + 2 * BRACKET_DOUBLINGS + 200
    ));
    if let Some(run) = history {
        prog.bound(format!(
            "The first command runs the declared {} history on each trial: its branch \
             integrates two intervals, to the turn and back, of at most {SUBSTEP_BUDGET} \
             sub-steps each (a first step of up to twice the work of the others' bound).",
            run.history.state.name()
        ));
    }
    let d = driver(ode, ns, prog)?;
    let x0 = ode.initial_state();
    let br_x = prog.field(
        &ns.name("br_x"),
        Ty::F64,
        None,
        "the state of the last trial input",
    )?;
    let sol_x = prog.field(
        &ns.name("sol_x"),
        Ty::F64,
        None,
        "the state of the solution",
    )?;
    // y(v) on the sample's branch; its state into br_x, a failed integration into fail.
    let branch = prog.function(&ns.name("branch"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
        b.if_else(
            Expr::State(d.started.clone()),
            |b| {
                let args = vec![
                    Expr::State(d.x.clone()),
                    Expr::State(d.u_prev.clone()),
                    local("v"),
                ];
                b.set_state(&br_x, call(&d.advance, args));
            },
            |b| match history {
                None => {
                    b.set_state(&d.fail, Expr::Flag(false));
                    b.set_state(&br_x, x0);
                }
                Some(run) => {
                    let v = local("v");
                    // a trial beyond the saved turn fails, as HistoryRun::admits refuses it
                    if let Some(t) = run.history.turn {
                        let beyond = ((lit(t) - v.clone()) * lit(run.history.direction()))
                            .gt(lit(0.0))
                            .not();
                        b.if_(beyond, |b| {
                            b.set_state(&d.fail, Expr::Flag(true));
                            b.set_state(&br_x, lit(x0));
                            b.ret(call(&d.output, vec![v.clone(), lit(x0)]));
                        });
                    }
                    let turn = b.let_("turn", super::turn_at(run.history, run.reach, v.clone()));
                    let x_turn = b.let_(
                        "x_turn",
                        call(&d.advance, vec![lit(x0), v.clone(), turn.clone()]),
                    );
                    b.if_(Expr::State(d.fail.clone()), |b| {
                        b.set_state(&br_x, x_turn.clone());
                        b.ret(call(&d.output, vec![v.clone(), x_turn.clone()]));
                    });
                    b.set_state(&br_x, call(&d.advance, vec![x_turn, turn, v]));
                }
            },
        );
        b.ret(call(&d.output, vec![local("v"), Expr::State(br_x.clone())]));
    })?;
    let failed = Expr::State(d.fail.clone());
    let give_up = |b: &mut Block, v: Expr| {
        b.set_state(DIVERGED_FIELD, Expr::Flag(true));
        b.ret(v);
    };
    let illinois = prog.function(
        &ns.name("illinois"),
        &[
            ("a0", Ty::F64),
            ("ga0", Ty::F64),
            ("b0", Ty::F64),
            ("gb0", Ty::F64),
            ("r", Ty::F64),
            ("ytol", Ty::F64),
        ],
        Some(Ty::F64),
        |b| {
            let (a, ga, bb, gb, r) = (
                b.var("a", local("a0")),
                b.var("ga", local("ga0")),
                b.var("b", local("b0")),
                b.var("gb", local("gb0")),
                local("r"),
            );
            let side = b.var("side", 0.0);
            b.call(&branch, vec![bb.clone()]);
            b.if_(failed.clone(), |b| give_up(b, bb.clone()));
            b.set_state(&sol_x, Expr::State(br_x.clone()));
            let v = b.var("v", bb.clone());
            b.for_("_iteration", idx(0), idx(200), |b, _| {
                b.set(
                    "v",
                    (a.clone() * gb.clone() - bb.clone() * ga.clone()) / (gb.clone() - ga.clone()),
                );
                let outside = v
                    .clone()
                    .is_finite()
                    .not()
                    .or(v.clone().le(a.clone().min(bb.clone())))
                    .or(v.clone().ge(a.clone().max(bb.clone())));
                b.if_(outside, |b| b.set("v", 0.5 * (a.clone() + bb.clone())));
                let yv = b.let_("yv", call(&branch, vec![v.clone()]));
                b.if_(failed.clone(), |b| give_up(b, v.clone()));
                b.set_state(&sol_x, Expr::State(br_x.clone()));
                let gv = b.let_("gv", yv - r.clone());
                let width = lit(4.0) * epsilon() * v.clone().abs().max(min_positive());
                b.if_(
                    gv.clone()
                        .abs()
                        .le(local("ytol"))
                        .or((bb.clone() - a.clone()).abs().le(width)),
                    |b| b.break_(),
                );
                b.if_else(
                    gv.clone().signum().eq(gb.clone().signum()),
                    |b| {
                        b.set("b", v.clone());
                        b.set("gb", gv.clone());
                        b.if_(side.clone().eq(1.0), |b| b.set("ga", ga.clone() * 0.5));
                        b.set("side", 1.0);
                    },
                    |b| {
                        b.set("a", v.clone());
                        b.set("ga", gv.clone());
                        b.if_(side.clone().eq(-1.0), |b| b.set("gb", gb.clone() * 0.5));
                        b.set("side", -1.0);
                    },
                );
            });
            b.ret(v);
        },
    )?;
    let span = ode.inversion_span().abs();
    // The probe of the branch's direction and the first bracketing step are the same in
    // both precisions, so that the float code tries the same inputs (rounded) and finds the
    // same bracket; a trial below float resolution only repeats the start.
    let probe = 1e-6 * ode.max_substep().abs();
    let solve = prog.function(
        &ns.name("solve_sample"),
        &[("start", Ty::F64), ("r", Ty::F64)],
        Some(Ty::F64),
        |b| {
            let (start, r) = (local("start"), local("r"));
            let y0 = b.let_("y0", call(&branch, vec![start.clone()]));
            b.if_(failed.clone(), |b| give_up(b, start.clone()));
            b.set_state(&sol_x, Expr::State(br_x.clone()));
            let g0 = b.let_("g0", y0.clone() - r.clone());
            let ytol = b.let_(
                "ytol",
                typed(1e-13, SINGLE_YTOL)
                    * (r.clone().abs() + y0.clone().abs()).max(min_positive()),
            );
            b.if_(g0.clone().abs().le(ytol.clone()), |b| b.ret(start.clone()));
            let (best_v, best_x, best_y) = (
                b.var("best_v", start.clone()),
                b.var("best_x", Expr::State(br_x.clone())),
                b.var("best_y", y0.clone()),
            );
            let yp = b.let_("yp", call(&branch, vec![start.clone() + probe]));
            let rising = b.let_(
                "rising",
                select(failed.clone().not().and(yp.lt(y0)), -1.0, 1.0),
            );
            let first = b.let_("first", -g0.clone().signum() * rising);
            b.for_("pass", idx(0), idx(2), |b, pass| {
                let direction = b.let_(
                    "direction",
                    select(pass.eq(idx(0)), first.clone(), -first.clone()),
                );
                let dd = b.var("dd", 1e-9 * span);
                let a = b.var("a", start.clone());
                let ga = b.var("ga", g0.clone());
                b.for_("doubling", idx(0), idx(BRACKET_DOUBLINGS), |b, _| {
                    b.if_(dd.clone().gt(span), |b| b.break_());
                    let v = b.let_("v", start.clone() + direction.clone() * dd.clone());
                    let yv = b.let_("yv", call(&branch, vec![v.clone()]));
                    b.if_(failed.clone(), |b| b.break_());
                    let xv = b.let_("xv", Expr::State(br_x.clone()));
                    b.if_(
                        (yv.clone() - r.clone())
                            .abs()
                            .lt((best_y.clone() - r.clone()).abs()),
                        |b| {
                            b.set("best_v", v.clone());
                            b.set("best_x", xv.clone());
                            b.set("best_y", yv.clone());
                        },
                    );
                    let gv = b.let_("gv", yv - r.clone());
                    b.if_(gv.clone().abs().le(ytol.clone()), |b| {
                        b.set_state(&sol_x, xv.clone());
                        b.ret(v.clone());
                    });
                    b.if_(gv.clone().signum().ne(g0.clone().signum()), |b| {
                        b.ret(call(
                            &illinois,
                            vec![
                                a.clone(),
                                ga.clone(),
                                v.clone(),
                                gv.clone(),
                                r.clone(),
                                ytol.clone(),
                            ],
                        ));
                    });
                    b.set("a", v.clone());
                    b.set("ga", gv);
                    b.set("dd", dd.clone() * 2.0);
                });
            });
            // No bracket on either side: the closest output found, and the reference counts
            // as clipped.
            mark_clip(b, Expr::Flag(true));
            b.set_state(&sol_x, best_x);
            b.ret(best_v);
        },
    )?;
    let anchor = history.map_or(ode.anchor_input(), |run| run.start(ode));
    prog.function(&ns.name("inverse"), &[("r", Ty::F64)], Some(Ty::F64), |b| {
        b.if_(local("r").is_finite().not(), |b| {
            b.set_state(DIVERGED_FIELD, Expr::Flag(true))
        });
        let start = select(
            Expr::State(d.started.clone()),
            Expr::State(d.u_prev.clone()),
            anchor,
        );
        let v = b.let_("v", call(&solve, vec![start, local("r")]));
        b.set_state(&d.x, Expr::State(sol_x.clone()));
        b.set_state(&d.started, Expr::Flag(true));
        b.set_state(&d.u_prev, v.clone());
        b.ret(v);
    })
}
