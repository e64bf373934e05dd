//! The Krasnosel'skii–Pokrovskii operator (`model::operators::kp`): the kernel states ξ_{ij}
//! (order (0,0), (1,0), (1,1), …) advanced by ξ ← max(ρ(x − tᵢ), min(ρ(x − tⱼ), ξ)) through
//! comparisons, as the library does; the output c + a₀x + Σ μₖξₖ with the sum in the
//! library's four interleaved partial sums. G⁻¹ is the library's monotone per-sample solve of
//! the trial output (one running sum), then the states advance with the solution.

use super::oriented::EmitCore;
use crate::export::code::{call, idx, local, select, Block, Expr, Ty};
use crate::export::program::{Ns, Program};
use crate::export::solve;
use crate::model::operators::{Kp, Orientation};
use crate::Result;

/// The names of the kernels' fields and tables.
struct Kernels {
    xi: String,
    ramps: String,
    mu: String,
    levels: usize,
}

impl Kernels {
    /// Declares the kernel states (initialised as `KernelStates::new`), the ramps' scratch
    /// space, the weights and the helper `ns.fill_ramps(x)`.
    fn declare(kp: &Kp, ns: &Ns, prog: &mut Program) -> Result<(Self, String)> {
        let t = kp.thresholds();
        let n = t.len();
        let two_over_a = 2.0 / kp.width();
        let ridge = |x: f64| (x * two_over_a).clamp(-1.0, 1.0);
        let mut initial = Vec::with_capacity(n * (n + 1) / 2);
        for (i, &ti) in t.iter().enumerate() {
            for &tj in &t[..=i] {
                initial.push(ridge(-0.5 * (ti + tj)));
            }
        }
        let k = initial.len();
        let xi = prog.field(&ns.name("xi"), Ty::F64, Some(k), "the kernel states")?;
        let ramps = prog.field(&ns.name("ramps"), Ty::F64, Some(n), "ρ(x − tᵢ) (scratch)")?;
        let xi0 = prog.table(&ns.table("xi0"), initial)?;
        let tt = prog.table(&ns.table("t"), t.to_vec())?;
        let mu = prog.table(&ns.table("mu"), kp.weights().to_vec())?;
        let xi_init = xi.clone();
        prog.init(|b| {
            b.for_("k", idx(0), idx(k), |b, kk| {
                b.set_at(&xi_init, kk.clone(), Expr::Table(xi0, Box::new(kk)));
            });
        });
        let ramps_c = ramps.clone();
        let fill = prog.function(&ns.name("fill_ramps"), &[("x", Ty::F64)], None, |b| {
            b.for_("i", idx(0), idx(n), |b, i| {
                let r = b.let_(
                    "r",
                    (local("x") - Expr::Table(tt, Box::new(i.clone()))) * two_over_a,
                );
                b.set_at(&ramps_c, i, r.clamp(-1.0, 1.0));
            });
        })?;
        Ok((
            Self {
                xi,
                ramps,
                mu,
                levels: n,
            },
            fill,
        ))
    }

    /// Loops over the kernels: `body(b, k, updated ξ_k)` with k = i(i + 1)/2 + j.
    fn each(&self, b: &mut Block, body: impl Fn(&mut Block, Expr, Expr)) {
        let ramp = |i: Expr| Expr::StateAt(self.ramps.clone(), Box::new(i));
        b.for_("i", idx(0), idx(self.levels), |b, i| {
            let up = b.let_("up", ramp(i.clone()));
            b.for_("j", idx(0), i.clone() + idx(1), |b, j| {
                let k = b.local(
                    "k",
                    Ty::Index,
                    false,
                    i.clone() * (i.clone() + idx(1)) / idx(2) + j.clone(),
                );
                let old = b.let_("old", Expr::StateAt(self.xi.clone(), Box::new(k.clone())));
                let down = ramp(j);
                let held = b.let_("held", select(down.clone().lt(old.clone()), down, old));
                let new = b.let_("new", select(up.clone().gt(held.clone()), up.clone(), held));
                body(b, k, new);
            });
        });
    }

    fn mu(&self, k: Expr) -> Expr {
        Expr::Table(self.mu.clone(), Box::new(k))
    }
    fn xi(&self, k: Expr) -> Expr {
        Expr::StateAt(self.xi.clone(), Box::new(k))
    }
}

impl EmitCore for Kp {
    fn orientation(&self) -> Orientation {
        Kp::orientation(self)
    }

    fn emit_core(&self, ns: &Ns, prog: &mut Program) -> Result<String> {
        prog.bound(format!(
            "The KP operator evaluates its {} ramps and {} kernels once a step.",
            self.thresholds().len(),
            self.weights().len()
        ));
        let (kernels, ramps) = Kernels::declare(self, ns, prog)?;
        let k = kernels.levels * (kernels.levels + 1) / 2;
        let (c, a0) = (self.offset(), self.a0());
        prog.function(&ns.name("g"), &[("x", Ty::F64)], Some(Ty::F64), |b| {
            b.call(&ramps, vec![local("x")]);
            kernels.each(b, |b, k, new| b.set_at(&kernels.xi, k, new));
            // Σ μₖξₖ in four interleaved partial sums, then the tail (`advance_weighted`).
            for l in 0..4 {
                b.var(&format!("acc{l}"), 0.0);
            }
            b.for_("chunk", idx(0), idx(k / 4), |b, chunk| {
                for l in 0..4 {
                    let at = chunk.clone() * idx(4) + idx(l);
                    let acc = format!("acc{l}");
                    b.set(&acc, local(&acc) + kernels.mu(at.clone()) * kernels.xi(at));
                }
            });
            let rest = b.var("rest", 0.0);
            b.for_("m", idx(k - k % 4), idx(k), |b, m| {
                b.set("rest", rest.clone() + kernels.mu(m.clone()) * kernels.xi(m));
            });
            let s = b.let_(
                "sum",
                (local("acc0") + local("acc1")) + (local("acc2") + local("acc3")) + rest,
            );
            b.ret(c + a0 * local("x") + s);
        })
    }

    fn emit_core_inverse(&self, ns: &Ns, prog: &mut Program) -> Result<(String, Option<String>)> {
        prog.bound(format!(
            "The KP inverse's trial evaluates the {} ramps and {} kernels; the solve's \
             bracket starts from the half-width s = {:e}.",
            self.thresholds().len(),
            self.weights().len(),
            {
                let t = self.thresholds();
                0.5 * (t[t.len() - 1] - t[0] + self.width()) * (1.0 + 1e-12)
            }
        ));
        let (kernels, ramps) = Kernels::declare(self, ns, prog)?;
        let (c, a0) = (self.offset(), self.a0());
        let trial = prog.function(&ns.name("trial"), &[("x", Ty::F64)], Some(Ty::F64), |b| {
            b.call(&ramps, vec![local("x")]);
            let acc = b.var("acc", 0.0);
            kernels.each(b, |b, k, new| {
                b.set("acc", acc.clone() + kernels.mu(k) * new)
            });
            b.ret(c + a0 * local("x") + acc);
        })?;
        let solve = solve::emit(prog, ns, &trial)?;
        let t = self.thresholds();
        let (lo, hi) = (
            t[0] - 0.5 * self.width(),
            t[t.len() - 1] + 0.5 * self.width(),
        );
        let center = 0.5 * (lo + hi);
        let span = 0.5 * (hi - lo) * (1.0 + 1e-12);
        let unbounded = Expr::Flag(a0 > 0.0);
        let name = prog.function(&ns.name("g_inv"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
            let args = vec![
                local("v"),
                center.into(),
                span.into(),
                unbounded.clone(),
                unbounded,
            ];
            let x = b.let_("u", call(&solve, args));
            b.call(&ramps, vec![x.clone()]);
            kernels.each(b, |b, k, new| b.set_at(&kernels.xi, k, new));
            b.ret(x);
        })?;
        Ok((name, Some(ns.name("clipped"))))
    }
}
