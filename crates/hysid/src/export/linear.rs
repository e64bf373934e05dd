//! The linear block B(q)/A(q)·q⁻ᵏ of the cascades (`model::linear`) as streaming code, and
//! the operator cascade's inverse of it (`OperatorCascade::compensate`).
//!
//! The forward block keeps the last nₐ outputs and the last k + n_b inputs (zero before the
//! first sample, which gives the library's sums: a missing past term adds ±0) and sums
//! y(t) = −Σ aᵢ y(t−i) + Σ bⱼ v(t−k−j+1) in the library's order.
//!
//! **The inverse needs the reference k samples ahead.** The batch compensate computes
//! v(s) = r(s + k) + Σ aᵢ r(s + k − i) − Σ_{j≥2} bⱼ v(s − j + 1) (r = 0 before sample k): the
//! command at s depends on the reference at s + k. The exported compensator of a cascade
//! with delay k therefore takes r(s + k) as its input at step s (a preview of k samples; with
//! k = 0 the reference itself); fed so, it gives the batch command sample for sample.

use super::code::{idx, local, Block, Expr, Ty};
use super::program::{Ns, Program};
use crate::model::LinearBlock;
use crate::Result;

/// Shifts the history `field` of length `n` by one (element i moves to i + 1) and stores
/// `newest` at 0.
fn push(b: &mut Block, field: &str, n: usize, newest: Expr) {
    if n == 0 {
        return;
    }
    if n >= 2 {
        b.for_("i", idx(0), idx(n - 1), |b, i| {
            let to = idx(n - 1) - i.clone();
            let from = idx(n - 2) - i;
            b.set_at(field, to, Expr::StateAt(field.into(), Box::new(from)));
        });
    }
    b.set_at(field, idx(0), newest);
}

/// Emits `ns.filter(v) -> f64`: the block's output at this sample for its input v.
pub fn forward(block: &LinearBlock, ns: &Ns, prog: &mut Program) -> Result<String> {
    let (na, nb, k) = (block.na(), block.nb(), block.delay());
    let nv = k + nb;
    let ys = prog.field(&ns.name("y_past"), Ty::F64, Some(na), "y(t−1), …, y(t−na)")?;
    let vs = prog.field(&ns.name("v_past"), Ty::F64, Some(nv), "v(t), v(t−1), …")?;
    let a = prog.table(&ns.table("a"), block.a().to_vec())?;
    let bt = prog.table(&ns.table("b"), block.b().to_vec())?;
    prog.function(&ns.name("filter"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
        push(b, &vs, nv, local("v"));
        let acc = b.var("acc", 0.0);
        b.for_("i", idx(0), idx(na), |b, i| {
            let term = Expr::Table(a.clone(), Box::new(i.clone()))
                * Expr::StateAt(ys.clone(), Box::new(i));
            b.set("acc", acc.clone() - term);
        });
        b.for_("j", idx(0), idx(nb), |b, j| {
            let past = Expr::StateAt(vs.clone(), Box::new(idx(k) + j.clone()));
            b.set(
                "acc",
                acc.clone() + Expr::Table(bt.clone(), Box::new(j)) * past,
            );
        });
        push(b, &ys, na, acc.clone());
        b.ret(acc);
    })
}

/// Emits `ns.unfilter(q) -> f64`: the operator output v(s) the batch compensate asks for,
/// from q = r(s + k) (see the module docs).
pub fn inverse(block: &LinearBlock, ns: &Ns, prog: &mut Program) -> Result<String> {
    let (na, nb) = (block.na(), block.nb());
    let qs = prog.field(
        &ns.name("r_past"),
        Ty::F64,
        Some(na),
        "r(s+k−1), …, r(s+k−na)",
    )?;
    let vs = prog.field(
        &ns.name("v_past"),
        Ty::F64,
        Some(nb.saturating_sub(1)),
        "v(s−1), v(s−2), …",
    )?;
    let a = prog.table(&ns.table("a"), block.a().to_vec())?;
    let bt = prog.table(&ns.table("b"), block.b().to_vec())?;
    prog.function(
        &ns.name("unfilter"),
        &[("q", Ty::F64)],
        Some(Ty::F64),
        |b| {
            let acc = b.var("acc", local("q"));
            b.for_("i", idx(0), idx(na), |b, i| {
                let term = Expr::Table(a.clone(), Box::new(i.clone()))
                    * Expr::StateAt(qs.clone(), Box::new(i));
                b.set("acc", acc.clone() + term);
            });
            b.for_("j", idx(1), idx(nb), |b, j| {
                let past = Expr::StateAt(vs.clone(), Box::new(j.clone() - idx(1)));
                b.set(
                    "acc",
                    acc.clone() - Expr::Table(bt.clone(), Box::new(j)) * past,
                );
            });
            push(b, &qs, na, local("q"));
            push(b, &vs, nb.saturating_sub(1), acc.clone());
            b.ret(acc);
        },
    )
}
