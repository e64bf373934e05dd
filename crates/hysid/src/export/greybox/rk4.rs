//! The RK4 integration of one sample interval with m sub-steps, as the library's
//! (`greybox::simulate`'s `Stepper::rk4_step`, `numerics::integrate::Rk4::step` and
//! `greybox::stick_slip::StickSlip::step`), in its order of operations:
//!
//! * sub-step j of m has length h = (1/m)·ts; its stages read the input on the half-step
//!   grid (node 2j, 2j + 1, 2j + 2 of 2m per interval) and the time
//!   t = (k − 1 + j/m + dt/ts)·ts;
//! * with Coulomb friction (the model's friction velocity v = x\[iv\]), a sub-step that starts
//!   sliding holds the friction direction in all four stages; when it would end with v on
//!   the other side of zero it is cut where v = 0 (Illinois regula falsi on the fraction φ
//!   of the step, at most 60 iterations), v is set to 0 and the rest of the sub-step is taken
//!   from rest, its stages reading the input at their own time. A sub-step that starts at
//!   rest lets the right-hand side decide between sticking and breaking away.
//!
//! The helpers work on the state's arrays: `w` is the state a sequence of stages advances
//! in place, `k1` … `k4` the stage rates.

use super::{copy, sign0, Driver, EmitStateSpace};
use crate::export::code::{idx, local, select, Block, Expr, Ty};
use crate::export::program::Program;
use crate::model::greybox::InputInterpolation;
use crate::Result;
use std::ops::Not;

/// The iterations of the search for a velocity zero crossing (`stick_slip`'s).
const ROOT_ITERATIONS: usize = 60;

/// Emits `advance()`: x from t_{k−1} to t_k in `substeps` RK4 steps. Returns its name.
pub fn emit(
    code: &dyn EmitStateSpace,
    d: &Driver,
    substeps: usize,
    prog: &mut Program,
) -> Result<String> {
    let m = substeps.max(1);
    prog.bound(format!(
        "RK4 takes {m} sub-steps a step, 4 right-hand sides each (at most 63 stage sets a \
         sub-step where a stick-slip crossing is located)."
    ));
    let model = code.model();
    let (n, n_in) = (model.states().len(), model.inputs().len());
    let ns = &d.ns;
    let j = prog.field(
        &ns.name("j"),
        Ty::Index,
        None,
        "the RK4 sub-step being taken",
    )?;
    let array = |prog: &mut Program, name: &str, doc: &str| {
        prog.field(&ns.name(name), Ty::F64, Some(n), doc)
    };
    let w = array(prog, "w", "the state the RK4 stages advance")?;
    let ks: Vec<String> = (1..=4)
        .map(|s| {
            array(
                prog,
                &format!("k{s}"),
                &format!("the rate of RK4 stage {s}"),
            )
        })
        .collect::<Result<_>>()?;
    // eval(dt, node, d): f at dt seconds into sub-step j, the input on the grid's node
    // (0, 1, 2) or, off the grid (node 3), at the stage's own time.
    let eval = prog.function(
        &ns.name("eval"),
        &[("dt", Ty::F64), ("node", Ty::Index), ("d", Ty::F64)],
        None,
        |b| {
            let jj = Expr::State(j.clone());
            let tau = b.let_("tau", jj.clone().to_f64() / (m as f64) + local("dt") / d.ts);
            if d.interpolation == InputInterpolation::Linear {
                b.if_else(
                    local("node").lt(idx(3)),
                    |b| {
                        let index = idx(2) * jj.clone() + local("node");
                        let grid = index.to_f64() / ((2 * m) as f64);
                        d.input_at(b, n_in, &grid);
                    },
                    |b| d.input_at(b, n_in, &tau),
                );
            } else {
                d.input_at(b, n_in, &tau);
            }
            let t = (d.interval_start() + tau) * d.ts;
            b.call(&d.rhs, vec![t, local("d")]);
        },
    )?;
    let stages = prog.function(
        &ns.name("stages"),
        &[
            ("t0", Ty::F64),
            ("h", Ty::F64),
            ("d", Ty::F64),
            ("grid", Ty::Flag),
        ],
        None,
        |b| {
            let (t0, h) = (local("t0"), local("h"));
            let half = b.let_("half", 0.5 * h.clone());
            let node = |i: usize| select(local("grid"), idx(i), idx(3));
            let at = |name: &str, i: &Expr| Expr::StateAt(name.into(), Box::new(i.clone()));
            // The stage state w + c·k (w itself for the first stage), then its rate into k.
            let stage =
                |b: &mut Block, from: Option<(&Expr, &str)>, dt: Expr, node: Expr, k: &str| {
                    b.for_("i", idx(0), idx(n), |b, i| {
                        let value = match from {
                            Some((c, prev)) => at(&w, &i) + c.clone() * at(prev, &i),
                            None => at(&w, &i),
                        };
                        b.set_at(&d.xs, i, value);
                    });
                    b.call(&eval, vec![dt, node, local("d")]);
                    copy(b, k, &d.rate, n);
                };
            stage(b, None, t0.clone(), node(0), &ks[0]);
            stage(
                b,
                Some((&half, &ks[0])),
                t0.clone() + half.clone(),
                node(1),
                &ks[1],
            );
            stage(
                b,
                Some((&half, &ks[1])),
                t0.clone() + half.clone(),
                node(1),
                &ks[2],
            );
            stage(b, Some((&h, &ks[2])), t0 + h.clone(), node(2), &ks[3]);
            let sixth = b.let_("sixth", h / 6.0);
            b.for_("i", idx(0), idx(n), |b, i| {
                let k = |s: usize| at(&ks[s], &i);
                let sum = k(0) + 2.0 * k(1) + 2.0 * k(2) + k(3);
                b.set_at(&w, i.clone(), at(&w, &i) + sixth.clone() * sum);
            });
        },
    )?;
    let substep = match model.stick_slip_velocity() {
        None => prog.function(&ns.name("substep"), &[("h", Ty::F64)], None, |b| {
            copy(b, &w, &d.x, n);
            b.call(
                &stages,
                vec![Expr::F64(0.0), local("h"), Expr::F64(0.0), Expr::Flag(true)],
            );
            copy(b, &d.x, &w, n);
        })?,
        Some(iv) => stick_slip(d, n, iv, &w, &stages, prog)?,
    };
    let h = (1.0 / m as f64) * d.ts;
    prog.function(&ns.name("advance"), &[], None, |b| {
        b.for_("j", idx(0), idx(m), |b, jj| {
            b.set_state(&j, jj);
            b.call(&substep, vec![Expr::F64(h)]);
        });
    })
}

/// Emits `sliding(phi, h, side)`, `crossing(h, side, v1)` and `substep(h)`: the stick–slip
/// RK4 step of a model whose friction velocity is state `iv`. Returns `substep`'s name.
fn stick_slip(
    d: &Driver,
    n: usize,
    iv: usize,
    w: &str,
    stages: &str,
    prog: &mut Program,
) -> Result<String> {
    let ns = &d.ns;
    let x_at = |i: usize| Expr::StateAt(d.x.clone(), Box::new(idx(i)));
    let w_v = Expr::StateAt(w.into(), Box::new(idx(iv)));
    // The sliding step of fraction φ from x into w; its final velocity.
    let sliding = prog.function(
        &ns.name("sliding"),
        &[("phi", Ty::F64), ("h", Ty::F64), ("side", Ty::F64)],
        Some(Ty::F64),
        |b| {
            let phi = local("phi");
            copy(b, w, &d.x, n);
            let args = vec![
                Expr::F64(0.0),
                phi.clone() * local("h"),
                local("side"),
                phi.eq(1.0),
            ];
            b.call(stages, args);
            b.ret(w_v.clone());
        },
    )?;
    // The fraction φ ∈ (0, 1] where the sliding step's final velocity is zero.
    let crossing = prog.function(
        &ns.name("crossing"),
        &[("h", Ty::F64), ("side", Ty::F64), ("v1", Ty::F64)],
        Some(Ty::F64),
        |b| {
            let side = local("side");
            let a = b.var("a", 0.0);
            let fa = b.var("fa", x_at(iv));
            let bb = b.var("b", 1.0);
            let fb = b.var("fb", local("v1"));
            let last = b.var("last", 0.0);
            b.for_("_iteration", idx(0), idx(ROOT_ITERATIONS), |b, _| {
                let c = b.let_(
                    "c",
                    (a.clone() * fb.clone() - bb.clone() * fa.clone()) / (fb.clone() - fa.clone()),
                );
                let inside = c.clone().gt(a.clone()).and(c.clone().lt(bb.clone()));
                b.if_(inside.not().or((bb.clone() - a.clone()).lt(1e-15)), |b| {
                    b.break_()
                });
                let fc = b.let_(
                    "fc",
                    crate::export::code::call(&sliding, vec![c.clone(), local("h"), side.clone()]),
                );
                b.if_(fc.clone().eq(0.0), |b| b.ret(c.clone()));
                b.if_else(
                    (fc.clone() * side.clone()).gt(0.0),
                    |b| {
                        b.set("a", c.clone());
                        b.set("fa", fc.clone());
                        b.if_(last.clone().eq(-1.0), |b| b.set("fb", fb.clone() * 0.5));
                        b.set("last", -1.0);
                    },
                    |b| {
                        b.set("b", c.clone());
                        b.set("fb", fc.clone());
                        b.if_(last.clone().eq(1.0), |b| b.set("fa", fa.clone() * 0.5));
                        b.set("last", 1.0);
                    },
                );
            });
            b.ret(select(fa.abs().lt(fb.abs()), a, bb));
        },
    )?;
    prog.function(&ns.name("substep"), &[("h", Ty::F64)], None, |b| {
        let h = local("h");
        let whole = |b: &mut Block| {
            copy(b, w, &d.x, n);
            let args = vec![Expr::F64(0.0), h.clone(), Expr::F64(0.0), Expr::Flag(true)];
            b.call(stages, args);
            copy(b, &d.x, w, n);
        };
        let side = b.let_("side", sign0(x_at(iv)));
        b.if_(side.clone().eq(0.0), |b| {
            whole(b);
            b.ret_void();
        });
        let end = b.let_(
            "end",
            crate::export::code::call(&sliding, vec![Expr::F64(1.0), h.clone(), side.clone()]),
        );
        b.if_((end.clone() * side.clone()).gt(0.0), |b| {
            copy(b, &d.x, w, n);
            b.ret_void();
        });
        let phi = b.let_(
            "phi",
            crate::export::code::call(&crossing, vec![h.clone(), side.clone(), end]),
        );
        b.call(&sliding, vec![phi.clone(), h.clone(), side]);
        copy(b, &d.x, w, n);
        b.set_at(&d.x, idx(iv), 0.0);
        copy(b, w, &d.x, n);
        let rest = vec![
            phi.clone() * h.clone(),
            (1.0 - phi) * h,
            Expr::F64(0.0),
            Expr::Flag(false),
        ];
        b.call(stages, rest);
        copy(b, &d.x, w, n);
    })
}
