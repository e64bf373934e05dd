//! The Krasnosel'skii–Pokrovskii operator (`model::operators::kp`): the kernel states ξ_{ij}
//! (order (0,0), (1,0), (1,1), …) advanced by ξ ← max(ρ(x − tᵢ), min(ρ(x − tⱼ), ξ)) through
//! comparisons, as the library does; the output c + a₀x + Σ μₖξₖ with the sum in the
//! library's four interleaved partial sums. G⁻¹ is the library's bounded per-sample solve of
//! the trial output (one running sum): bisections over the ramp edges and over the sorted
//! switch points of the rows and columns whose ramps cover the bracket, then the last piece's
//! line (`Kp::solve`); then the states advance with the solution.

use super::oriented::EmitCore;
use crate::export::code::{call, idx, local, select, typed, Block, Expr, Ty};
use crate::export::program::{Ns, Program};
use crate::export::solve;
use crate::model::operators::kp::ramp_edges;
use crate::model::operators::{Kp, Orientation};
use crate::Result;
use std::ops::Not;

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
            "The KP inverse takes at most {} trials a step (2 at the outer ramp edges, then \
             bisections over the ramp edges and the switch points of the rows and columns \
             whose ramps cover the bracket), each an evaluation of the {} ramps and {} \
             kernels, then one advance.",
            self.inverse_trials(),
            self.thresholds().len(),
            self.weights().len()
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
        let solve = bounded_solve(self, ns, prog, &kernels, &trial)?;
        let name = prog.function(&ns.name("g_inv"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
            let x = b.let_("u", call(&solve, vec![local("v")]));
            b.call(&ramps, vec![x.clone()]);
            kernels.each(b, |b, k, new| b.set_at(&kernels.xi, k, new));
            b.ret(x);
        })?;
        Ok((name, Some(ns.name("clipped"))))
    }
}

/// Emits `ns.solve(v)`, the library's `Kp::solve` (module docs of `model::operators::kp`,
/// "Inverse") with the same comparisons and order of operations; `trial(x)` is the output
/// after x from the kernel states. Sets the flag `ns.clipped`. Returns the function's name.
fn bounded_solve(
    kp: &Kp,
    ns: &Ns,
    prog: &mut Program,
    kernels: &Kernels,
    trial: &str,
) -> Result<String> {
    let clipped = solve::clipped_field(prog, ns)?;
    let edges = ramp_edges(kp.thresholds(), kp.width());
    let (m, n) = (edges.len(), kp.thresholds().len());
    let (e_first, e_last) = (edges[0], edges[m - 1]);
    let edge = prog.table(&ns.table("edge"), edges)?;
    let thresholds = ns.table("t");
    let (a0, h) = (kp.a0(), 0.5 * kp.width());
    // The ramps' ends tᵢ ∓ h as `ramp_edges` computes them, for the test whether a ramp
    // covers the bracket: in single precision the same floats as the edges' (fl(tᵢ) + fl(h)
    // may differ from them by an ulp, and a ramp would then seem to cover a window it only
    // touches, costing trials the stated bound does not count). The library's tᵢ + h are
    // these values in double.
    let t = kp.thresholds();
    let t_lo = prog.table(&ns.table("t_lo"), t.iter().map(|&ti| ti - h).collect())?;
    let t_hi = prog.table(&ns.table("t_hi"), t.iter().map(|&ti| ti + h).collect())?;
    let f = |x: Expr| call(trial, vec![x]);
    prog.function(&ns.name("solve"), &[("v", Ty::F64)], Some(Ty::F64), |b| {
        let v = local("v");
        let tol = typed(1e-12, 16.0 * f32::EPSILON as f64) * (1.0 + v.clone().abs());
        b.set_state(&clipped, Expr::Flag(false));
        let (a, bb) = (local("a"), local("b"));
        b.var("a", e_last);
        b.var("b", e_first);
        let fa = b.var("fa", f(a.clone()));
        let fb = b.var("fb", f(bb.clone()));
        // Beyond the outer edges only a0 x moves: from (x0, f0) the root is linear.
        let linear = |b: &mut Block, x0: Expr, f0: Expr| {
            b.if_(f0.clone().eq(v.clone()), |b| b.ret(x0.clone()));
            if a0 > 0.0 {
                let x = b.let_("x_lin", x0.clone() + (v.clone() - f0.clone()) / a0);
                b.if_(x.clone().is_finite(), |b| b.ret(x));
            }
            b.set_state(&clipped, (v.clone() - f0).abs().gt(tol.clone()));
            b.ret(x0);
        };
        b.if_(v.clone().le(fa.clone()), |b| {
            linear(b, a.clone(), fa.clone())
        });
        b.if_(v.clone().ge(fb.clone()), |b| {
            linear(b, bb.clone(), fb.clone())
        });
        // Bisection over the points point(k), k in [lo, end), that do not increase with k:
        // a trial for each point inside (a, b) (`Bracket::over_sorted`).
        let over_sorted =
            |b: &mut Block, tag: &str, lo: Expr, end: Expr, point: &dyn Fn(Expr) -> Expr| {
                let (lo_name, end_name) = (format!("lo_{tag}"), format!("end_{tag}"));
                let lo = b.local(&lo_name, Ty::Index, true, lo);
                let end = b.local(&end_name, Ty::Index, true, end);
                b.while_(lo.clone().lt(end.clone()), |b| {
                    let mid = b.local(
                        "mid",
                        Ty::Index,
                        false,
                        lo.clone() + (end.clone() - lo.clone()) / idx(2),
                    );
                    let x = b.let_("x", point(mid.clone()));
                    // the larger points lie at the smaller k
                    let above = b.local("above", Ty::Flag, true, Expr::Flag(false));
                    b.if_else(
                        x.clone().le(a.clone()),
                        |b| b.set("above", Expr::Flag(true)),
                        |b| {
                            b.if_(x.clone().lt(bb.clone()), |b| {
                                solve::narrow(b, f(x.clone()), x.clone(), v.clone(), |b| {
                                    b.set("above", Expr::Flag(true))
                                });
                            });
                        },
                    );
                    b.if_else(
                        above,
                        |b| b.set(&end_name, mid.clone()),
                        |b| b.set(&lo_name, mid.clone() + idx(1)),
                    );
                });
            };
        over_sorted(b, "e", idx(1), idx(m - 1), &|k| {
            Expr::Table(edge.clone(), Box::new(k))
        });
        b.for_("i", idx(0), idx(n), |b, i| {
            let ti = b.let_("ti", Expr::Table(thresholds.clone(), Box::new(i.clone())));
            let (lo, hi) = (
                Expr::Table(t_lo.clone(), Box::new(i.clone())),
                Expr::Table(t_hi.clone(), Box::new(i.clone())),
            );
            let outside = hi.le(a.clone()).or(lo.ge(bb.clone()));
            b.if_(outside.not(), |b| {
                let row = b.local(
                    "row",
                    Ty::Index,
                    false,
                    i.clone() * (i.clone() + idx(1)) / idx(2),
                );
                // row i: t_i + h xi[i][j], j < i; column i: t_i + h xi[k][i], k > i
                over_sorted(b, "r", idx(0), i.clone(), &|j| {
                    ti.clone() + h * kernels.xi(row.clone() + j)
                });
                over_sorted(b, "c", i.clone() + idx(1), idx(n), &|k| {
                    ti.clone() + h * kernels.xi(k.clone() * (k + idx(1)) / idx(2) + i.clone())
                });
            });
        });
        let s = b.let_("s", (v.clone() - fa.clone()) / (fb.clone() - fa.clone()));
        let root = b.let_("root", a.clone() + s * (bb.clone() - a.clone()));
        b.ret(root.clamp(a, bb));
    })
}
