//! Tests of `hysid::identify::actuator::loops`.

use hysid::identify::actuator::loops::*;

/// The test vectors of docs/models/actuator.md §2.
#[test]
fn loop_formula_test_vectors() {
    let cases = [
        (2.0, 3.0, 1.5, -0.75, 0.5261517082, -0.6651056865),
        (2.0, 3.0, 1.5, 0.0, 0.6518564990, -0.6518564990),
        (2.0, 3.0, 1.5, 1.5, 0.6665021406, 0.6665021406),
        (1.0, 0.8, 1.0, -0.5, -0.1442965056, -0.6235021955),
        (1.0, 0.8, 1.0, 0.5, 0.6235021955, 0.1442965056),
    ];
    for (a, alpha, q, x1, cu, cd) in cases {
        // The table is printed to 10 decimals.
        assert!(
            (ascending(a, alpha, q, x1) - cu).abs() < 1e-9,
            "Cu({a}, {alpha}, {q}, {x1})"
        );
        assert!(
            (descending(a, alpha, q, x1) - cd).abs() < 1e-9,
            "Cd({a}, {alpha}, {q}, {x1})"
        );
    }
}

/// The formula is the steady state of the differential equation (numerical check).
#[test]
fn formula_is_the_steady_state_of_the_differential_equation() {
    let (a, alpha, q) = (42.49, 112.5, 0.06);
    let n = 200_000;
    let dt = 2.0 * std::f64::consts::PI / n as f64;
    let mut x4 = 0.0;
    for period in 0..3 {
        for k in 0..n {
            let t = k as f64 * dt;
            let v = q * (t + 0.5 * dt).cos();
            // Exact solution of ẋ4 over one small step with constant ẋ1.
            let (decay, target) = ((-alpha * v.abs() * dt).exp(), a * v.signum() / alpha);
            x4 = target + (x4 - target) * decay;
            if period == 2 && k % 5000 == 0 {
                let x1n = q * (t + dt).sin();
                let branch = if (t + dt).cos() > 0.0 {
                    ascending(a, alpha, q, x1n)
                } else {
                    descending(a, alpha, q, x1n)
                };
                assert!(
                    (x4 - branch).abs() < 2e-3 * (a / alpha),
                    "t = {t}: {x4} vs {branch}"
                );
            }
        }
    }
}

#[test]
fn noisy_reversals_are_found_once() {
    // Two periods of a sine with a wiggle at every sample.
    let x: Vec<f64> = (0..2000)
        .map(|k| {
            let t = k as f64 / 1000.0 * std::f64::consts::TAU;
            t.sin() + if k % 2 == 0 { 0.01 } else { -0.01 }
        })
        .collect();
    let points = turning_points(&x, 0.1);
    let kinds: Vec<f64> = points.iter().map(|p| p.1).collect();
    assert_eq!(kinds, [1.0, -1.0, 1.0, -1.0]);
    for ((k, _), expected) in points.iter().zip([250, 750, 1250, 1750]) {
        assert!(k.abs_diff(expected) < 10, "{k} vs {expected}");
    }
    let used = branch_samples(&x, &points, 0.05);
    // The samples near the four extremes are left out, the rest labelled by branch.
    assert!(used.len() < 2000 && used.len() > 1500, "{}", used.len());
    for (k, direction) in used {
        let slope = (k as f64 / 1000.0 * std::f64::consts::TAU).cos();
        assert_eq!(direction, slope.signum(), "sample {k}");
    }
}
