//! The Newmark integration of one sample interval with m sub-steps, as the library's
//! (`greybox::simulate`'s `Stepper::newmark_step`), in its order of operations.
//!
//! A model with d mechanical degrees of freedom has n states: d positions q, their d
//! velocities v, and n − 2d first-order states w. Sub-step j of m runs from τ = j/m to
//! τ + 1/m of the interval, h = (1/m)·ts. From the rates f₀ = f(t, x) at its start, the
//! average-acceleration scheme (γ = ½, β = ¼; c = ½ for w) gives the end state as a
//! function of the p = n − d unknowns: the end accelerations a₁ and first-order rates r₁,
//!
//! ```text
//! q₁ = q₀ + h·v₀ + h²·(¼·a₀ + ¼·a₁)     v₁ = v₀ + h·(½·a₀ + ½·a₁)
//! w₁ = w₀ + h·(½·ẇ₀ + ½·r₁)
//! ```
//!
//! and the corrector solves g(z) = z − f_{v,w}(t₁, x₁(z)) = 0 for z = (a₁, r₁) by Newton's
//! method from z = 0: at most 50 iterations, stopped as soon as every |gᵢ| ≤ 1e-13·s with
//! s = max(1, maxᵢ |zᵢ|); the Newton matrix J = I − ∂f/∂z by forward differences with the
//! step 1e-7·max(|z_c|, 1e-6·s) in column c; z ← z − J⁻¹·g.
//!
//! J⁻¹·g is solved as nalgebra's `LU::solve` does (Golub & Van Loan, *Matrix
//! Computations*, 4th ed., 2013, Algorithm 3.4.1, Gaussian elimination with partial
//! pivoting), operation by operation so that the result is the library's to the bit: in
//! column i the pivot is the first row r ≥ i of largest |J_ri|; the rows i and pivot are
//! swapped (with g); the multipliers below the pivot are multiplied by the reciprocal of the
//! pivot; the trailing block is updated J_rk ← J_rk − J_ik·J_ri; then forward substitution
//! with the unit lower factor, g_r ← g_r − g_i·L_ri, and back substitution from the last
//! row, z_i = g_i / U_ii, g_r ← g_r − z_i·U_ri. A zero pivot (a singular Newton matrix, the
//! library's `Diverged`) sets the error flag.
//!
//! The matrix is held row by row in a state array of p² values; every array is sized from
//! the model's state count.

use super::{copy, Driver, EmitStateSpace};
use crate::export::code::{call, idx, local, typed, Block, Expr, Ty};
use crate::export::program::{Program, DIVERGED_FIELD};
use crate::{Error, Result};
use std::ops::Not;

/// The corrector's iteration budget (the library's).
const ITERATIONS: usize = 50;
/// The residual tolerance relative to the unknowns' scale.
const TOLERANCE: f64 = 1e-13;
/// The relative step of the Newton matrix's differences.
const RELATIVE_STEP: f64 = 1e-7;
/// The floor of a difference step relative to the scale.
const STEP_FLOOR: f64 = 1e-6;
/// The residual tolerance in single precision: 4·10⁻⁶, about 32 `float` ulps (1e-13 is
/// below float resolution: the corrector would never converge and run its 50 iterations).
const SINGLE_TOLERANCE: f64 = 4e-6;
/// The relative difference step in single precision: √ε of `float` ≈ 3.5·10⁻⁴, the
/// standard forward-difference step (Dennis & Schnabel, *Numerical Methods for
/// Unconstrained Optimization and Nonlinear Equations*, 1983, §5.4); 1e-7 is about one float
/// ulp, and the differences would be rounding noise.
const SINGLE_RELATIVE_STEP: f64 = 3.4526698e-4;
/// The floor of a difference step relative to the scale in single precision: 1 (the step is
/// √ε of max(|z|, scale), so that the difference of the rates stays above their rounding).
const SINGLE_STEP_FLOOR: f64 = 1.0;
/// β of the position update (average acceleration).
const BETA: f64 = 0.25;
/// γ of the velocity update.
const GAMMA: f64 = 0.5;
/// The trapezoidal weight of the first-order states.
const TRAPEZOID: f64 = 0.5;

/// Emits `advance()`: x from t_{k−1} to t_k in `substeps` Newmark steps. Returns its name.
pub fn emit(
    code: &dyn EmitStateSpace,
    d: &Driver,
    substeps: usize,
    prog: &mut Program,
) -> Result<String> {
    prog.bound(format!(
        "Newmark takes {} sub-steps a step, each at most {ITERATIONS} Newton iterations of \
         one residual, its difference Jacobian and an LU solve.",
        substeps.max(1)
    ));
    let model = code.model();
    let (n, n_in) = (model.states().len(), model.inputs().len());
    let dofs = model
        .mechanical_dofs()
        .filter(|dofs| 2 * dofs <= n)
        .ok_or_else(|| {
            Error::Unsupported(format!(
                "Newmark integration needs a second-order mechanical model; {} is not one \
                 (use RK4)",
                model.kind()
            ))
        })?;
    let p = n - dofs;
    let m = substeps.max(1);
    let dtau = 1.0 / m as f64;
    let h = dtau * d.ts;
    let ns = &d.ns;
    let array = |prog: &mut Program, name: &str, len: usize, doc: &str| {
        prog.field(&ns.name(name), Ty::F64, Some(len), doc)
    };
    let start = array(prog, "nm_start", n, "the state at the Newmark step's start")?;
    let rate0 = array(prog, "nm_rate0", n, "the rates at the step's start")?;
    let rate1 = array(prog, "nm_rate1", n, "the rates at the corrector's iterate")?;
    let z = array(
        prog,
        "nm_z",
        p,
        "the unknowns: end accelerations and first-order rates",
    )?;
    let trial = array(
        prog,
        "nm_trial",
        p,
        "the unknowns the end state is built from",
    )?;
    let g = array(
        prog,
        "nm_g",
        p,
        "the corrector's residual, then its Newton step",
    )?;
    let jac = array(
        prog,
        "nm_jac",
        p * p,
        "the Newton matrix row by row, then its LU factors",
    )?;
    let at = |name: &str, i: Expr| Expr::StateAt(name.into(), Box::new(i));
    let h = Expr::F64(h);

    // eval(tau): f at fraction τ of the interval, the state in xs, into rate.
    let eval = prog.function(&ns.name("nm_eval"), &[("tau", Ty::F64)], None, |b| {
        let tau = local("tau");
        d.input_at(b, n_in, &tau);
        let t = (d.interval_start() + tau) * d.ts;
        b.call(&d.rhs, vec![t, Expr::F64(0.0)]);
    })?;

    // state_of(): the end state of the step for the unknowns in trial, into xs.
    let state_of = prog.function(&ns.name("nm_state_of"), &[], None, |b| {
        b.for_("i", idx(0), idx(dofs), |b, i| {
            let q = b.let_("q", at(&start, i.clone()));
            let v = b.let_("v", at(&start, idx(dofs) + i.clone()));
            let a0 = b.let_("a0", at(&rate0, idx(dofs) + i.clone()));
            let a1 = b.let_("a1", at(&trial, i.clone()));
            let position = q
                + h.clone() * v.clone()
                + h.clone() * h.clone() * ((0.5 - BETA) * a0.clone() + BETA * a1.clone());
            b.set_at(&d.xs, i.clone(), position);
            let velocity = v + h.clone() * ((1.0 - GAMMA) * a0 + GAMMA * a1);
            b.set_at(&d.xs, idx(dofs) + i, velocity);
        });
        b.for_("j", idx(2 * dofs), idx(n), |b, j| {
            let r = at(&trial, j.clone() - idx(dofs));
            let value = at(&start, j.clone())
                + h.clone() * ((1.0 - TRAPEZOID) * at(&rate0, j.clone()) + TRAPEZOID * r);
            b.set_at(&d.xs, j, value);
        });
    })?;

    let solve = lu_solve(ns, &jac, &g, p, prog)?;

    // step(tau, tau1): one Newmark step from τ to τ₁, x in place.
    let step = prog.function(
        &ns.name("nm_step"),
        &[("tau", Ty::F64), ("tau1", Ty::F64)],
        None,
        |b| {
            let tau1 = local("tau1");
            copy(b, &d.xs, &d.x, n);
            b.call(&eval, vec![local("tau")]);
            copy(b, &start, &d.x, n);
            copy(b, &rate0, &d.rate, n);
            b.for_("i", idx(0), idx(p), |b, i| b.set_at(&z, i, 0.0));
            b.for_("_iteration", idx(0), idx(ITERATIONS), |b, _| {
                copy(b, &trial, &z, p);
                b.call(&state_of, vec![]);
                b.call(&eval, vec![tau1.clone()]);
                copy(b, &rate1, &d.rate, n);
                b.for_("i", idx(0), idx(p), |b, i| {
                    let value = at(&z, i.clone()) - at(&rate1, idx(dofs) + i.clone());
                    b.set_at(&g, i, value);
                });
                let scale = b.var("scale", 1.0);
                b.for_("i", idx(0), idx(p), |b, i| {
                    b.set("scale", scale.clone().max(at(&z, i).abs()));
                });
                let converged = b.local("converged", Ty::Flag, true, Expr::Flag(true));
                b.for_("i", idx(0), idx(p), |b, i| {
                    let tol = typed(TOLERANCE, SINGLE_TOLERANCE);
                    let within = at(&g, i).abs().le(tol * scale.clone());
                    b.if_(within.not(), |b| b.set("converged", Expr::Flag(false)));
                });
                b.if_(converged, |b| b.break_());
                b.for_("r", idx(0), idx(p), |b, r| {
                    b.for_("c", idx(0), idx(p), |b, c| {
                        let one = crate::export::code::select(r.clone().eq(c.clone()), 1.0, 0.0);
                        b.set_at(&jac, idx(p) * r.clone() + c, one);
                    });
                });
                b.for_("c", idx(0), idx(p), |b, c| {
                    let zc = at(&z, c.clone()).abs();
                    let step = typed(RELATIVE_STEP, SINGLE_RELATIVE_STEP);
                    let floor = typed(STEP_FLOOR, SINGLE_STEP_FLOOR);
                    let dz = b.let_("dz", step * zc.max(floor * scale.clone()));
                    copy(b, &trial, &z, p);
                    b.set_at(&trial, c.clone(), at(&trial, c.clone()) + dz.clone());
                    b.call(&state_of, vec![]);
                    b.call(&eval, vec![tau1.clone()]);
                    b.for_("r", idx(0), idx(p), |b, r| {
                        let cell = idx(p) * r.clone() + c.clone();
                        let slope = (at(&d.rate, idx(dofs) + r.clone())
                            - at(&rate1, idx(dofs) + r))
                            / dz.clone();
                        b.set_at(&jac, cell.clone(), at(&jac, cell) - slope);
                    });
                });
                b.if_(call(&solve, vec![]).not(), |b| {
                    b.set_state(DIVERGED_FIELD, Expr::Flag(true));
                    b.ret_void();
                });
                b.for_("i", idx(0), idx(p), |b, i| {
                    b.set_at(&z, i.clone(), at(&z, i.clone()) - at(&g, i));
                });
            });
            copy(b, &trial, &z, p);
            b.call(&state_of, vec![]);
            copy(b, &d.x, &d.xs, n);
        },
    )?;

    prog.function(&ns.name("advance"), &[], None, |b| {
        b.for_("j", idx(0), idx(m), |b, j| {
            let tau = b.let_("tau", j.to_f64() / (m as f64));
            b.call(&step, vec![tau.clone(), tau + dtau]);
            b.if_(Expr::State(DIVERGED_FIELD.into()), |b| b.ret_void());
        });
    })
}

/// Emits `nm_solve()` in the namespace `ns`: the LU factorisation with partial pivoting of
/// the p × p matrix in the state array `jac` (row by row, p² values) in place and the
/// solution of jac·δ = g into the state array `g` (p values), as nalgebra's `LU::new` and
/// `LU::solve` (see the module docs); the helper returns false, with `jac` and `g` partly
/// overwritten, at a zero pivot (where `solve` gives None). Returns the helper's name.
pub fn lu_solve(
    ns: &crate::export::program::Ns,
    jac: &str,
    g: &str,
    p: usize,
    prog: &mut Program,
) -> Result<String> {
    let a = |r: Expr, c: Expr| Expr::StateAt(jac.into(), Box::new(idx(p) * r + c));
    let gi = |i: Expr| Expr::StateAt(g.into(), Box::new(i));
    let set_a = |b: &mut Block, r: Expr, c: Expr, v: Expr| b.set_at(jac, idx(p) * r + c, v);
    prog.function(&ns.name("nm_solve"), &[], Some(Ty::Flag), |b| {
        b.for_("i", idx(0), idx(p), |b, i| {
            // The pivot: the first row of largest magnitude in column i, from row i down.
            let piv = b.local("piv", Ty::Index, true, i.clone());
            let big = b.var("big", a(i.clone(), i.clone()).abs());
            b.for_("r", i.clone() + idx(1), idx(p), |b, r| {
                let v = b.let_("v", a(r.clone(), i.clone()).abs());
                b.if_(v.clone().gt(big.clone()), |b| {
                    b.set("big", v);
                    b.set("piv", r);
                });
            });
            let diag = b.let_("diag", a(piv.clone(), i.clone()));
            b.if_(diag.clone().eq(0.0), |b| b.ret(Expr::Flag(false)));
            b.if_(piv.clone().ne(i.clone()), |b| {
                b.for_("c", idx(0), idx(p), |b, c| {
                    let held = b.let_("held", a(i.clone(), c.clone()));
                    set_a(b, i.clone(), c.clone(), a(piv.clone(), c.clone()));
                    set_a(b, piv.clone(), c, held);
                });
                let held = b.let_("held_g", gi(i.clone()));
                b.set_at(g, i.clone(), gi(piv.clone()));
                b.set_at(g, piv.clone(), held);
            });
            let inv = b.let_("inv", 1.0 / diag);
            b.for_("r", i.clone() + idx(1), idx(p), |b, r| {
                set_a(
                    b,
                    r.clone(),
                    i.clone(),
                    a(r.clone(), i.clone()) * inv.clone(),
                );
            });
            b.for_("k", i.clone() + idx(1), idx(p), |b, k| {
                b.for_("r", i.clone() + idx(1), idx(p), |b, r| {
                    let update =
                        a(r.clone(), k.clone()) - a(i.clone(), k.clone()) * a(r.clone(), i.clone());
                    set_a(b, r, k.clone(), update);
                });
            });
        });
        // Forward substitution with the unit lower factor.
        b.for_("i", idx(0), idx(p), |b, i| {
            b.for_("r", i.clone() + idx(1), idx(p), |b, r| {
                let value = gi(r.clone()) - gi(i.clone()) * a(r.clone(), i.clone());
                b.set_at(g, r, value);
            });
        });
        // Back substitution from the last row.
        b.for_("back", idx(0), idx(p), |b, back| {
            let i = b.local("i", Ty::Index, false, idx(p - 1) - back);
            let coeff = b.let_("coeff", gi(i.clone()) / a(i.clone(), i.clone()));
            b.set_at(g, i.clone(), coeff.clone());
            b.for_("r", idx(0), i.clone(), |b, r| {
                let value = gi(r.clone()) - coeff.clone() * a(r.clone(), i.clone());
                b.set_at(g, r, value);
            });
        });
        b.ret(Expr::Flag(true));
    })
}
