//! Steady-state hysteresis loops of the Dhaouadi model (step 2 of Gunnar et al. 2006).
//!
//! # Formula (docs/models/actuator.md §2, DERIVED; corrects the seed copy's sign)
//!
//! Under x1 = Q sin(ωt), the hysteresis torque x4 of ẋ4 = −α|ẋ1|x4 + A ẋ1 follows, on the
//! ascending (ẋ1 > 0) and the descending branch,
//!
//! ```text
//! Cu(x1) =  (A/α)·(1 − 2e^{−α(Q + x1)} / (1 + e^{−2αQ}))
//! Cd(x1) = −(A/α)·(1 − 2e^{−α(Q − x1)} / (1 + e^{−2αQ}))
//! ```
//!
//! and the loop torque is τn = φ(x1) + Cu/d(x1), φ(x1) = k1 x1 + k2 x1³. The seed copy prints
//! e^{+α(Q+x1)}: a transcription error. Useful facts: the half-width (Cu − Cd)/2 =
//! (A/α)(1 − cosh(αx1)/cosh(αQ)) does not depend on k1, k2, and Cu(±Q) = ±(A/α)tanh(αQ).
//!
//! # Branches of a measured loop
//!
//! [`turning_points`] finds the reversals of a measured torsion by a zig-zag with a dead band
//! (a reversal counts once the signal has come back by more than the band, so measurement
//! noise near the extremes does not make false reversals), and [`branch_samples`] labels
//! every sample with its branch and leaves out the samples near the reversals, where the
//! motor sticks and the friction torque is anywhere in ±Fc.
//!
//! Reference: R. Dhaouadi, F. H. Ghorbel, P. S. Gandhi, "A new dynamic model of hysteresis in
//! harmonic drives", IEEE Trans. Industrial Electronics 50(6), 2003; Gunnar et al. (2006)
//! eq. (10).

/// The ascending-branch hysteresis torque Cu(x1) for amplitude Q.
pub fn ascending(a: f64, alpha: f64, q: f64, x1: f64) -> f64 {
    (a / alpha) * (1.0 - 2.0 * (-alpha * (q + x1)).exp() / (1.0 + (-2.0 * alpha * q).exp()))
}

/// The descending-branch hysteresis torque Cd(x1) for amplitude Q.
pub fn descending(a: f64, alpha: f64, q: f64, x1: f64) -> f64 {
    -(a / alpha) * (1.0 - 2.0 * (-alpha * (q - x1)).exp() / (1.0 + (-2.0 * alpha * q).exp()))
}

/// The reversals of `x`: (index, +1 for a maximum or −1 for a minimum) of every extreme
/// after which `x` comes back by more than `band`.
pub fn turning_points(x: &[f64], band: f64) -> Vec<(usize, f64)> {
    let mut points = Vec::new();
    let Some(&start) = x.first() else {
        return points;
    };
    // The direction of the current run (0: not yet known) and the index of its extreme.
    let (mut direction, mut extreme) = (0.0, 0);
    for (k, &v) in x.iter().enumerate().skip(1) {
        if direction == 0.0 {
            if (v - start).abs() > band {
                direction = (v - start).signum();
                extreme = k;
            }
        } else if (v - x[extreme]) * direction >= 0.0 {
            extreme = k;
        } else if (x[extreme] - v) * direction > band {
            points.push((extreme, direction));
            direction = -direction;
            extreme = k;
        }
    }
    points
}

/// The samples of a loop record that step 2 uses, as (index, direction ±1 of the motion):
/// every branch of `x` between the reversals `points` of [`turning_points`], with the
/// partial branches before the first and after the last, leaving out the samples within
/// `margin` of a reversal's value.
pub fn branch_samples(x: &[f64], points: &[(usize, f64)], margin: f64) -> Vec<(usize, f64)> {
    let mut out = Vec::new();
    let Some(&(last, last_kind)) = points.last() else {
        return out;
    };
    let near = |k: usize, p: usize| (x[k] - x[p]).abs() < margin;
    let mut start: Option<usize> = None;
    // Each segment runs towards a maximum (ascending) or a minimum (descending).
    for &(p, kind) in points {
        let from = start.map_or(0, |s| s + 1);
        for k in from..p {
            if !near(k, p) && !start.is_some_and(|s| near(k, s)) {
                out.push((k, kind));
            }
        }
        start = Some(p);
    }
    for k in last + 1..x.len() {
        if !near(k, last) {
            out.push((k, -last_kind));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
