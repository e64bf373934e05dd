//! Non-negative least squares on the normal equations (Lawson & Hanson 1974, ch. 23).
//!
//! minimise ½xᵀGx − bᵀx subject to xᵢ ≥ 0 for the constrained i (G = ΦᵀΦ, b = Φᵀy: the
//! same minimiser as ‖Φx − y‖² ≥ 0-constrained), some variables optionally unconstrained
//! (an offset). The active-set method keeps a passive set P, solves the equality problem
//! G_PP z = b_P, steps back along x → z to the first variable that would turn negative and
//! drops it, and adds the variable with the largest dual wⱼ = (b − Gx)ⱼ > 0 until every dual
//! of the active set is ≤ 0 (the Karush–Kuhn–Tucker conditions). Working on the (n × n)
//! Gram matrix instead of the tall Φ makes every iteration independent of the sample count.
//! The passive set starts as the positive part of the unconstrained solution (a warm start,
//! Bro & de Jong 1997), which on clean data is often already the answer.
//!
//! References: C. L. Lawson, R. J. Hanson, *Solving Least Squares Problems*, Prentice-Hall
//! 1974; R. Bro, S. de Jong, "A fast non-negativity-constrained least squares algorithm",
//! J. Chemometrics 11 (1997) 393–401.

use crate::{Error, Result};
use nalgebra::{DMatrix, DVector};

/// The solution of a non-negative least-squares problem.
#[derive(Clone, Debug, PartialEq)]
pub struct Nnls {
    /// The minimiser.
    pub x: Vec<f64>,
    /// The passive (free) set at the solution: unconstrained variables and the positive ones.
    pub passive: Vec<bool>,
    /// Outer iterations (variables added).
    pub iterations: usize,
    /// False when the iteration limit stopped the search before the KKT conditions held.
    pub converged: bool,
}

/// Solves min ½xᵀGx − bᵀx, xᵢ ≥ 0 where `!unconstrained[i]`, for a symmetric positive
/// semi-definite G.
pub fn nnls_gram(g: &DMatrix<f64>, b: &DVector<f64>, unconstrained: &[bool]) -> Result<Nnls> {
    let n = b.len();
    if g.nrows() != n || g.ncols() != n || unconstrained.len() != n {
        return Err(Error::ModelMismatch(format!(
            "NNLS: Gram matrix {}x{}, right-hand side {n}, {} flags; sizes must agree",
            g.nrows(),
            g.ncols(),
            unconstrained.len()
        )));
    }
    if g.iter().chain(b.iter()).any(|v| !v.is_finite()) {
        return Err(Error::Singular(
            "NNLS: the normal equations contain non-finite values; check the data".into(),
        ));
    }
    let scale = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let all: Vec<bool> = vec![true; n];
    let z0 = solve_passive(g, b, &all);
    let mut passive: Vec<bool> = (0..n).map(|i| unconstrained[i] || z0[i] > 0.0).collect();
    let mut blocked = vec![false; n];
    let mut x = vec![0.0; n];
    let max_iter = 3 * n + 20;
    let mut iterations = 0;
    loop {
        inner_loop(g, b, unconstrained, &mut passive, &mut x);
        let w = dual(g, b, &x);
        let xmax = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let bmax = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let tol = 1e3 * f64::EPSILON * (bmax + scale * xmax);
        let candidate = (0..n)
            .filter(|&j| !passive[j] && !blocked[j] && w[j] > tol)
            .max_by(|&i, &j| w[i].total_cmp(&w[j]));
        let Some(j) = candidate else {
            return Ok(Nnls {
                x,
                passive,
                iterations,
                converged: true,
            });
        };
        iterations += 1;
        if iterations > max_iter {
            return Ok(Nnls {
                x,
                passive,
                iterations,
                converged: false,
            });
        }
        passive[j] = true;
        // a variable whose equality solution is not positive cannot enter (round-off): keep
        // it out so the search cannot cycle
        let z = solve_passive(g, b, &passive);
        if z[j] <= 0.0 {
            passive[j] = false;
            blocked[j] = true;
        } else {
            blocked.iter_mut().for_each(|v| *v = false);
        }
    }
}

/// The inner loop: from a feasible x, moves to the equality solution on the passive set,
/// stepping back and dropping variables that would turn negative.
fn inner_loop(
    g: &DMatrix<f64>,
    b: &DVector<f64>,
    unconstrained: &[bool],
    passive: &mut [bool],
    x: &mut [f64],
) {
    let n = x.len();
    for _ in 0..=n {
        let z = solve_passive(g, b, passive);
        let bad: Vec<usize> = (0..n)
            .filter(|&i| passive[i] && !unconstrained[i] && z[i] <= 0.0)
            .collect();
        if bad.is_empty() {
            x.copy_from_slice(&z);
            return;
        }
        // the first variable to reach 0 along x → z blocks the step and leaves P
        let (blocking, alpha) =
            bad.iter()
                .map(|&i| (i, x[i] / (x[i] - z[i])))
                .fold(
                    (bad[0], f64::INFINITY),
                    |m, c| if c.1 < m.1 { c } else { m },
                );
        let alpha = alpha.clamp(0.0, 1.0);
        for i in 0..n {
            x[i] += alpha * (z[i] - x[i]);
        }
        let xs = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..n {
            if bad.contains(&i) && (i == blocking || x[i] <= 1e-14 * xs) {
                passive[i] = false;
                x[i] = 0.0;
            }
        }
    }
}

/// The dual w = b − Gx.
fn dual(g: &DMatrix<f64>, b: &DVector<f64>, x: &[f64]) -> Vec<f64> {
    let xv = DVector::from_column_slice(x);
    (b - g * xv).iter().copied().collect()
}

/// The solution of G_PP z_P = b_P with z = 0 outside P (Cholesky; a minimum-norm SVD solve
/// when G_PP is singular).
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn solve_passive(g: &DMatrix<f64>, b: &DVector<f64>, passive: &[bool]) -> Vec<f64> {
    let idx: Vec<usize> = (0..b.len()).filter(|&i| passive[i]).collect();
    let mut z = vec![0.0; b.len()];
    if idx.is_empty() {
        return z;
    }
    let gp = DMatrix::from_fn(idx.len(), idx.len(), |r, c| g[(idx[r], idx[c])]);
    let bp = DVector::from_fn(idx.len(), |r, _| b[idx[r]]);
    let sol = solve_spd(gp, &bp);
    for (k, &i) in idx.iter().enumerate() {
        z[i] = sol[k];
    }
    z
}

/// Solves an SPD system by Cholesky, or by the SVD with a relative rank tolerance when it is
/// (numerically) singular.
pub(crate) fn solve_spd(a: DMatrix<f64>, rhs: &DVector<f64>) -> DVector<f64> {
    let max_diag = a.diagonal().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if let Some(ch) = a.clone().cholesky() {
        let min_diag = ch
            .l_dirty()
            .diagonal()
            .iter()
            .fold(f64::INFINITY, |m, v| m.min(v.abs()));
        if min_diag * min_diag > 1e-13 * max_diag {
            return ch.solve(rhs);
        }
    }
    let n = rhs.len();
    let svd = a.svd(true, true);
    let eps = 1e-13 * svd.singular_values.max();
    svd.solve(rhs, eps).unwrap_or_else(|_| DVector::zeros(n))
}

/// The inverse of G restricted to the passive set (for the covariance), None when singular.
pub(crate) fn passive_inverse(
    g: &DMatrix<f64>,
    passive: &[bool],
) -> Option<(Vec<usize>, DMatrix<f64>)> {
    let idx: Vec<usize> = (0..passive.len()).filter(|&i| passive[i]).collect();
    let gp = DMatrix::from_fn(idx.len(), idx.len(), |r, c| g[(idx[r], idx[c])]);
    let inv = gp.cholesky()?.inverse();
    Some((idx, inv))
}
