//! Kuhnen's generalised PI (`model::operators::gpi`): G = S∘H, a PI operator H
//! ([`super::pi`], its core) followed by the dead-zone superposition
//! S(v) = d₀v + Σ d⁺ⱼ max(v − z⁺ⱼ, 0) + Σ d⁻ⱼ min(v − z⁻ⱼ, 0); G⁻¹ = H⁻¹∘S⁻¹ with S⁻¹ the
//! dead zones of the same shape the library computes (`DeadZones::inverse`).

use super::oriented::EmitCore;
use super::pi;
use crate::export::code::{idx, local, Expr, Ty};
use crate::export::program::{Ns, Program};
use crate::model::operators::{DeadZones, GeneralizedPi, Orientation};
use crate::Result;

/// Emits `ns.s(v) -> f64`, S(v) summed as `DeadZones::eval` sums it (upper zones, then lower
/// ones, each side from 0, then d₀v + up + down).
fn dead_zones(zones: &DeadZones, ns: &Ns, prog: &mut Program) -> Result<String> {
    let mut sides = Vec::new();
    for (side, list, upper) in [("p", zones.upper(), true), ("n", zones.lower(), false)] {
        let z = prog.table(
            &ns.table(&format!("z{side}")),
            list.iter().map(|p| p.0).collect(),
        )?;
        let d = prog.table(
            &ns.table(&format!("d{side}")),
            list.iter().map(|p| p.1).collect(),
        )?;
        sides.push((z, d, list.len(), upper));
    }
    let d0 = zones.d0();
    prog.function(&ns.name("s"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
        for (k, (z, d, n, upper)) in sides.into_iter().enumerate() {
            let sum = format!("sum{k}");
            b.var(&sum, 0.0);
            b.for_("j", idx(0), idx(n), |b, j| {
                let t = |name: &str| Expr::Table(name.into(), Box::new(j.clone()));
                let gap = local("v") - t(&z);
                let clipped = if upper { gap.max(0.0) } else { gap.min(0.0) };
                b.set(&sum, local(&sum) + t(&d) * clipped);
            });
        }
        b.ret(d0 * local("v") + local("sum0") + local("sum1"));
    })
}

impl EmitCore for GeneralizedPi {
    fn orientation(&self) -> Orientation {
        GeneralizedPi::orientation(self)
    }

    fn emit_core(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        let h = pi::emit_forward(self.pi(), &ns.sub("h"), prog)?;
        let s = dead_zones(self.dead_zones(), ns, prog)?;
        prog.function(&ns.name("g"), &[("x", Ty::F64)], Some(Ty::F64), |b| {
            let v = b.let_("v", Expr::Call(h, vec![local("x")]));
            b.ret(Expr::Call(s, vec![v]));
        })
    }

    fn emit_core_inverse(&self, ns: &Ns, prog: &mut Program) -> Result<(String, Option<String>)> {
        let s_inv = dead_zones(&self.dead_zones().inverse(), &ns.sub("inv"), prog)?;
        let (h_inv, clipped) = pi::emit_inverse(self.pi(), &ns.sub("h"), prog)?;
        let name = prog.function(&ns.name("g_inv"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
            let w = b.let_("w", Expr::Call(s_inv, vec![local("v")]));
            b.ret(Expr::Call(h_inv, vec![w]));
        })?;
        Ok((name, clipped))
    }
}
