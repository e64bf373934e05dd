//! Tests of `hysid::numerics::least_squares`.

use hysid::numerics::least_squares::*;
use nalgebra::DMatrix;

#[test]
fn covariance_matches_textbook_formula() {
    // y = 2 + 0.5 t + small deterministic "noise"
    let n = 50;
    let phi = DMatrix::from_fn(n, 2, |i, j| if j == 0 { 1.0 } else { i as f64 });
    let y: Vec<f64> = (0..n)
        .map(|i| 2.0 + 0.5 * i as f64 + 0.01 * ((i * 7 % 5) as f64 - 2.0))
        .collect();
    let sol = least_squares(&phi, &y, &["c", "k"]).unwrap();
    let ptp_inv = (phi.transpose() * &phi).try_inverse().unwrap();
    let expected = ptp_inv * sol.sigma2();
    assert!((sol.covariance.clone() - expected).norm() < 1e-12);
}

#[test]
fn dependent_columns_are_named() {
    let phi = DMatrix::from_fn(10, 3, |i, j| match j {
        0 => 1.0,
        1 => i as f64,
        _ => 2.0 * i as f64,
    });
    let err = least_squares(&phi, &[0.0; 10], &["c", "x", "2x"]).unwrap_err();
    let msg = err.to_string();
    assert!(msg.contains("'x'") && msg.contains("'2x'"), "{msg}");
}
