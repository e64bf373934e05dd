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
