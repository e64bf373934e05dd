//! Tests of `hysid::numerics::nnls`.

use hysid::numerics::nnls::*;
use nalgebra::{DMatrix, DVector};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

fn objective(g: &DMatrix<f64>, b: &DVector<f64>, x: &[f64]) -> f64 {
    let xv = DVector::from_column_slice(x);
    0.5 * xv.dot(&(g * &xv)) - b.dot(&xv)
}

/// The optimum by enumerating every passive set: the NNLS solution is the equality
/// solution on its support, feasible, with the least objective among feasible ones.
fn brute_force(g: &DMatrix<f64>, b: &DVector<f64>, unconstrained: &[bool]) -> Vec<f64> {
    let n = b.len();
    let mut best = (f64::INFINITY, vec![0.0; n]);
    for mask in 0..(1u32 << n) {
        let p: Vec<bool> = (0..n)
            .map(|i| unconstrained[i] || mask & (1 << i) != 0)
            .collect();
        let z = solve_passive(g, b, &p);
        if (0..n).any(|i| !unconstrained[i] && z[i] < 0.0) {
            continue;
        }
        let f = objective(g, b, &z);
        if f < best.0 {
            best = (f, z);
        }
    }
    best.1
}

#[test]
fn agrees_with_brute_force_active_set_enumeration() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    for case in 0..200 {
        let n = 2 + case % 5;
        let m = n + 3;
        let phi = DMatrix::from_fn(m, n, |_, _| rng.random::<f64>() - 0.5);
        let y = DVector::from_fn(m, |_, _| rng.random::<f64>() - 0.5);
        let g = phi.transpose() * &phi;
        let b = phi.transpose() * &y;
        let unconstrained: Vec<bool> = (0..n).map(|i| case % 3 == 0 && i == 0).collect();
        let got = nnls_gram(&g, &b, &unconstrained).unwrap();
        assert!(got.converged);
        let want = brute_force(&g, &b, &unconstrained);
        for i in 0..n {
            assert!(
                (got.x[i] - want[i]).abs() < 1e-9,
                "case {case}: {:?} vs {want:?}",
                got.x
            );
            assert!(unconstrained[i] || got.x[i] >= 0.0);
        }
    }
}

#[test]
fn sizes_and_non_finite_values_are_refused() {
    let g = DMatrix::identity(2, 2);
    assert!(nnls_gram(&g, &DVector::zeros(3), &[false; 3]).is_err());
    let b = DVector::from_vec(vec![f64::NAN, 1.0]);
    assert!(nnls_gram(&g, &b, &[false; 2]).is_err());
}
