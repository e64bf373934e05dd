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

/// The estimate-only solver (the streamed factor of [Φ y]) agrees with the full solver to
/// rounding on a badly scaled, moderately conditioned problem, recovers an exact fit, and
/// refuses what the full solver refuses, naming the same columns (the condition number of an
/// exactly dependent pair is rounding, and differs between the two factorisations).
#[test]
fn estimate_only_agrees_with_the_full_solver() {
    let n = 400;
    let phi = DMatrix::from_fn(n, 4, |i, j| {
        let t = i as f64 * 0.01;
        match j {
            0 => 1e3,
            1 => (3.0 * t).sin(),
            2 => 1e-4 * (t * t),
            _ => (7.0 * t).cos() + 0.5 * (3.0 * t).sin(),
        }
    });
    let truth = [0.002, -1.5, 3e4, 0.25];
    let noise = |i: usize| 1e-3 * (((i * 37) % 11) as f64 - 5.0);
    let y: Vec<f64> = (0..n)
        .map(|i| (0..4).map(|j| phi[(i, j)] * truth[j]).sum::<f64>() + noise(i))
        .collect();
    let full = least_squares(&phi, &y, &[]).unwrap();
    let (theta, rss) = least_squares_estimate(&phi, &y, &[]).unwrap();
    for j in 0..4 {
        let scale = full.theta[j].abs();
        assert!(
            (theta[j] - full.theta[j]).abs() <= 1e-11 * scale,
            "θ{j}: {} vs {}",
            theta[j],
            full.theta[j]
        );
    }
    assert!((rss - full.residual_ss).abs() <= 1e-11 * full.residual_ss);
    // Without noise the fit is exact.
    let exact: Vec<f64> = (0..n)
        .map(|i| (0..4).map(|j| phi[(i, j)] * truth[j]).sum::<f64>())
        .collect();
    let (theta, _) = least_squares_estimate(&phi, &exact, &[]).unwrap();
    for j in 0..4 {
        assert!(
            (theta[j] - truth[j]).abs() <= 1e-9 * truth[j].abs(),
            "θ{j} = {}",
            theta[j]
        );
    }
    let dependent = DMatrix::from_fn(10, 3, |i, j| match j {
        0 => 1.0,
        1 => i as f64,
        _ => 2.0 * i as f64,
    });
    let names = ["c", "x", "2x"];
    let a = least_squares(&dependent, &[0.0; 10], &names).unwrap_err();
    let b = least_squares_estimate(&dependent, &[0.0; 10], &names).unwrap_err();
    let named = |e: &hysid::Error| {
        e.to_string()
            .split(" are (nearly)")
            .next()
            .map(String::from)
    };
    match &b {
        hysid::Error::DependentRegressors {
            columns,
            condition_number,
            ..
        } => {
            assert_eq!(columns, "'x', '2x'");
            assert!(*condition_number >= 1e12, "{condition_number}");
        }
        other => panic!("not DependentRegressors: {other}"),
    }
    assert_eq!(named(&a), named(&b));
    assert!(
        b.to_string()
            .contains("'x', '2x' are (nearly) linearly dependent"),
        "{b}"
    );
    // A column that is zero everywhere is named as the full solver names it.
    let zero = DMatrix::from_fn(10, 2, |i, j| if j == 0 { 1.0 + i as f64 } else { 0.0 });
    let a = least_squares(&zero, &[1.0; 10], &["c", "z"]).unwrap_err();
    let b = least_squares_estimate(&zero, &[1.0; 10], &["c", "z"]).unwrap_err();
    assert_eq!(a.to_string(), b.to_string());
}

/// The streamed factor over many blocks of rows (and a last partial one) gives the
/// least-squares estimate and residual sum of squares of a known problem: y = Φθ + e with e
/// orthogonal to Φ's columns, so θ̂ = θ and ‖y − Φθ̂‖² = ‖e‖² exactly in exact arithmetic.
#[test]
fn streamed_estimate_recovers_a_constructed_solution() {
    let n = 1_000 + 77;
    let p = 5;
    let phi = DMatrix::from_fn(n, p, |i, j| {
        let t = i as f64 / n as f64;
        ((j + 1) as f64 * 2.3 * t + j as f64).sin() + if j == 0 { 1.0 } else { 0.0 }
    });
    let theta = [1.5, -0.25, 3.0, 0.125, -2.0];
    // e = (I − Φ(ΦᵀΦ)⁻¹Φᵀ)·g for a deterministic g: orthogonal to every column of Φ.
    let g = nalgebra::DVector::from_fn(n, |i, _| 0.01 * (((i * 7919) % 101) as f64 - 50.0));
    let ptp = phi.transpose() * &phi;
    let e = &g - &phi * ptp.cholesky().unwrap().solve(&(phi.transpose() * &g));
    let y: Vec<f64> = (0..n)
        .map(|i| (0..p).map(|j| phi[(i, j)] * theta[j]).sum::<f64>() + e[i])
        .collect();
    let (estimate, rss) = least_squares_estimate(&phi, &y, &[]).unwrap();
    for j in 0..p {
        assert!(
            (estimate[j] - theta[j]).abs() < 1e-12,
            "θ{j} = {}",
            estimate[j]
        );
    }
    let expected = e.norm_squared();
    assert!(
        (rss - expected).abs() < 1e-10 * expected,
        "{rss} vs {expected}"
    );
}
