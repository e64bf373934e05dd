//! The adaptive integration of one sample interval, as the library's (`greybox::simulate`'s
//! `Stepper::dopri_interval` and `dopri_stages`): Dormand–Prince 5(4) in the fraction τ of
//! the interval, from dτ = 0.1, the step accepted when the RMS of the error over
//! atol + rtol·max(|x|, |x₅|) is at most 1 (or dτ < 1e-12), then scaled by
//! clamp(0.9·norm^(−1/5), 0.2, 5) (5 at a zero error); the stages read the input at their
//! own time. More than 1 000 000 trial steps in one interval, or a state that is not finite,
//! set the error flag (the library's `Diverged`).

use super::{Driver, EmitStateSpace};
use crate::export::code::{idx, local, Block, Expr, Ty};
use crate::export::program::{Program, DIVERGED_FIELD};
use crate::model::greybox::simulate::dormand_prince::{A, B4, B5, C};
use crate::Result;
use std::ops::Not;

/// The library's trial-step budget of one interval.
const GUARD: usize = 1_000_000;

/// Emits `advance()` with tolerances (rtol, atol). Returns its name.
pub fn emit(
    code: &dyn EmitStateSpace,
    d: &Driver,
    (rtol, atol): (f64, f64),
    prog: &mut Program,
) -> Result<String> {
    prog.bound(format!(
        "The adaptive Dormand-Prince integration tries at most {GUARD} steps (7 right-hand \
         sides each) a sample interval; beyond, the step sets the error flag."
    ));
    let model = code.model();
    let (n, n_in) = (model.states().len(), model.inputs().len());
    let ns = &d.ns;
    let array = |prog: &mut Program, name: &str, doc: &str| {
        prog.field(&ns.name(name), Ty::F64, Some(n), doc)
    };
    let ks: Vec<String> = (0..7)
        .map(|s| array(prog, &format!("dp_k{s}"), &format!("the rate of stage {s}")))
        .collect::<Result<_>>()?;
    let y5 = array(
        prog,
        "dp_y5",
        "the fifth-order solution of the last trial step",
    )?;
    let err = array(prog, "dp_err", "its difference to the fourth-order one")?;
    let at = |name: &str, i: &Expr| Expr::StateAt(name.into(), Box::new(i.clone()));
    // stages(tau, dtau): the seven stages from x, then y5 and err.
    let stages = prog.function(
        &ns.name("dp_stages"),
        &[("tau", Ty::F64), ("dtau", Ty::F64)],
        None,
        |b| {
            let (tau, dtau) = (local("tau"), local("dtau"));
            let h = b.let_("h", dtau.clone() * d.ts);
            for s in 0..7 {
                b.for_("i", idx(0), idx(n), |b, i| {
                    b.set_at(&d.xs, i.clone(), at(&d.x, &i));
                    for (j, a) in A[s].iter().enumerate().take(s) {
                        let term = h.clone() * *a * at(&ks[j], &i);
                        b.set_at(&d.xs, i.clone(), at(&d.xs, &i) + term);
                    }
                });
                let tau_s = b.let_(&format!("tau{s}"), tau.clone() + C[s] * dtau.clone());
                d.input_at(b, n_in, &tau_s);
                let t = (d.interval_start() + tau_s) * d.ts;
                b.call(&d.rhs, vec![t, Expr::F64(0.0)]);
                super::copy(b, &ks[s], &d.rate, n);
            }
            b.for_("i", idx(0), idx(n), |b, i| {
                let (s5, s4) = (b.var("s5", 0.0), b.var("s4", 0.0));
                for s in 0..7 {
                    b.set("s5", s5.clone() + B5[s] * at(&ks[s], &i));
                    b.set("s4", s4.clone() + B4[s] * at(&ks[s], &i));
                }
                b.set_at(&y5, i.clone(), at(&d.x, &i) + h.clone() * s5.clone());
                b.set_at(&err, i, h.clone() * (s5 - s4));
            });
        },
    )?;
    prog.function(&ns.name("advance"), &[], None, |b| {
        let tau = b.var("tau", 0.0);
        let dtau = b.var("dtau", 0.1);
        let guard = b.local("guard", Ty::Index, true, idx(0));
        b.while_(tau.clone().lt(1.0 - 1e-15), |b| {
            b.set("guard", guard.clone() + idx(1));
            b.if_(guard.clone().gt(idx(GUARD)), fail);
            b.set("dtau", dtau.clone().min(1.0 - tau.clone()));
            b.call(&stages, vec![tau.clone(), dtau.clone()]);
            let sum = b.var("sum", 0.0);
            b.for_("i", idx(0), idx(n), |b, i| {
                let scale = atol + rtol * at(&d.x, &i).abs().max(at(&y5, &i).abs());
                let ratio = b.let_("ratio", at(&err, &i) / scale);
                b.set("sum", sum.clone() + ratio.clone() * ratio);
            });
            let norm = b.let_("norm", (sum / (n as f64)).sqrt());
            b.if_(norm.clone().le(1.0).or(dtau.clone().lt(1e-12)), |b| {
                b.set("tau", tau.clone() + dtau.clone());
                super::copy(b, &d.x, &y5, n);
                b.for_("i", idx(0), idx(n), |b, i| {
                    b.if_(at(&d.x, &i).is_finite().not(), fail);
                });
            });
            let power = b.let_("power", (0.9 * norm.clone().powf(-0.2)).clamp(0.2, 5.0));
            let factor = b.let_(
                "factor",
                crate::export::code::select(norm.eq(0.0), 5.0, power),
            );
            b.set("dtau", dtau.clone() * factor);
        });
    })
}

/// Sets the error flag and leaves `advance`.
fn fail(b: &mut Block) {
    b.set_state(DIVERGED_FIELD, Expr::Flag(true));
    b.ret_void();
}
