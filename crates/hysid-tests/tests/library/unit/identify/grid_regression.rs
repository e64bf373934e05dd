//! Tests of `hysid::identify::grid_regression`.

use hysid::identify::global::basis_signals;
use hysid::identify::grid_regression::*;
use hysid::model::ChForm;
use nalgebra::{DMatrix, DVector};

/// The cost agrees with a plain least-squares fit on the explicit regressor matrix, for
/// both forms and a grid point away from the truth (so the cost is not zero).
#[test]
fn cost_matches_explicit_least_squares() {
    let x: Vec<f64> = (0..3000)
        .map(|t| 5.0 * (t as f64 * 0.05).sin() * (1.0 + 0.3 * (t as f64 * 0.003).cos()))
        .collect();
    let y: Vec<f64> = (0..x.len())
        .map(|t| (t as f64 * 0.031).sin() + 0.2 * (t as f64 * 0.17).cos())
        .collect();
    for (form, nl) in [(ChForm::Saturated4, 2), (ChForm::General6, 4)] {
        let (na, nb, k) = (2, 2, 1);
        let reg = EquationError::new(form, na, nb, k, &x, &y);
        let mut s = reg.scratch();
        let (alpha, d) = (0.25, 2.2);
        let cost = reg.cost(alpha, d, &mut s).unwrap();
        let psi = basis_signals(form, &x, alpha, d);
        let t0 = 2;
        let cols = na + nb * nl;
        let phi = DMatrix::from_fn(x.len() - t0, cols, |r, c| {
            let t = r + t0;
            if c < na {
                -y[t - c - 1]
            } else {
                psi[(c - na) % nl][t - k - (c - na) / nl]
            }
        });
        let target = DVector::from_column_slice(&y[t0..]);
        let theta = phi.clone().svd(true, true).solve(&target, 1e-14).unwrap();
        let expected = (target - phi * theta).norm_squared();
        assert!(
            (cost - expected).abs() < 1e-9 * expected,
            "{form:?}: {cost} vs {expected}"
        );
    }
}

#[test]
fn cholesky_solves_a_known_system() {
    // A = [[4, 2], [2, 3]], b = A·[1, −2] = [0, −4].
    let mut a = [4.0, 2.0, 2.0, 3.0];
    let mut b = [0.0, -4.0];
    cholesky_solve(&mut a, &mut b, 2).unwrap();
    assert!((b[0] - 1.0).abs() < 1e-15 && (b[1] + 2.0).abs() < 1e-15);
    let mut singular = [1.0, 1.0, 1.0, 1.0];
    assert!(cholesky_solve(&mut singular, &mut b, 2).is_none());
}
