//! Tests of `hysid::model::operators::kp`.

use hysid::model::operators::kp::KernelStates;
use hysid::model::operators::OperatorFamily;
use hysid::model::operators::{play, HysteresisOperator, Kp, Orientation};
use hysid::Error;

/// A KP operator on 5 thresholds over [−2, 2] with weights 0.05 … 0.15 (no zero weight).
pub(crate) fn example(a0: f64, o: Orientation) -> Kp {
    let t = Kp::uniform_thresholds(-2.0, 2.0, 5).unwrap();
    let w: Vec<f64> = (0..15)
        .map(|k| 0.05 + 0.1 * ((k * 7 % 11) as f64) / 11.0)
        .collect();
    Kp::new(t, 0.6, w, a0, 0.3, o).unwrap()
}

/// A decaying oscillation with minor loops.
pub(crate) fn input(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            1.9 * (1.0 - 0.8 * t) * (41.0 * t).sin() + 0.25 * (157.0 * t).sin()
        })
        .collect()
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn uniform_grid_is_the_interval_midpoints() {
    let t = Kp::uniform_thresholds(-2.0, 2.0, 4).unwrap();
    assert_eq!(t, vec![-1.5, -0.5, 0.5, 1.5]);
    assert!(Kp::uniform_thresholds(1.0, 1.0, 4).is_err());
    assert!(Kp::uniform_thresholds(0.0, 1.0, 0).is_err());
}

#[test]
fn a_kernel_is_a_play_from_zero_followed_by_a_ridge() {
    // thresholds (s1, s2) = (−0.5, 0.7): play half-width 0.6 around 0.1, ridge width 0.3
    let (s1, s2, a) = (-0.5, 0.7, 0.3);
    let kp = Kp::new(
        vec![s1, s2],
        a,
        vec![0.0, 1.0, 0.0],
        0.0,
        0.0,
        Orientation::default(),
    )
    .unwrap();
    let u = input(3000);
    let y = kp.simulate(&u).unwrap();
    let z = play(&u, 0.5 * (s2 - s1));
    let m = 0.5 * (s1 + s2);
    let expected: Vec<f64> = z
        .iter()
        .map(|zk| (2.0 * (zk - m) / a).clamp(-1.0, 1.0))
        .collect();
    assert!(max_abs_diff(&y, &expected) < 1e-15);
    // the kernel visits both saturations and the ramp
    assert!(y.contains(&1.0) && y.contains(&-1.0));
    assert!(y.iter().any(|&v| v.abs() < 0.9));
}

#[test]
fn initial_state_is_every_play_at_zero() {
    // kernel centres (s1 + s2)/2 over the grid [−1.5, −0.5, 0.5, 1.5], ridge width 0.4:
    // ξ₋₁ = ρ(−centre) = −1 for centres ≥ 0.2, +1 for ≤ −0.2, 0 for the centre 0
    let t = vec![-1.5, -0.5, 0.5, 1.5];
    let states = KernelStates::new(&t, 0.4);
    // order (0,0), (1,0), (1,1), (2,0), (2,1), (2,2), (3,0), (3,1), (3,2), (3,3)
    let expected = [1.0, 1.0, 1.0, 1.0, 0.0, -1.0, 0.0, -1.0, -1.0, -1.0];
    assert_eq!(states.values(), &expected);
    // the first sample at 0 keeps that state: the output is c + Σ μ ξ₋₁
    let w: Vec<f64> = (1..=10).map(f64::from).collect();
    let kp = Kp::new(t, 0.4, w.clone(), 0.0, 0.5, Orientation::default()).unwrap();
    let y0 = kp.simulate(&[0.0]).unwrap()[0];
    let direct: f64 = 0.5 + w.iter().zip(expected).map(|(a, b)| a * b).sum::<f64>();
    assert!((y0 - direct).abs() < 1e-12, "{y0} vs {direct}");
}

#[test]
fn simulation_equals_the_weighted_sum_of_the_kernel_states() {
    // the kernel states are the recipe's regressors: c + a0·u + Σ μ ξ must be the output
    let kp = example(0.2, Orientation::default());
    let u = input(1500);
    let y = kp.simulate(&u).unwrap();
    let mut states = KernelStates::new(kp.thresholds(), kp.width());
    for (k, &x) in u.iter().enumerate() {
        states.advance(x);
        let direct = kp.offset()
            + kp.a0() * x
            + states
                .values()
                .iter()
                .zip(kp.weights())
                .map(|(xi, w)| xi * w)
                .sum::<f64>();
        assert!(
            (direct - y[k]).abs() < 1e-12,
            "sample {k}: {direct} vs {}",
            y[k]
        );
        assert!(states.values().iter().all(|v| (-1.0..=1.0).contains(v)));
    }
}

#[test]
fn rate_independent_and_periodic_after_one_cycle() {
    let kp = example(0.2, Orientation::default());
    // rate independence: inserting intermediate points between the samples (the same input
    // path, sampled more finely) changes nothing at the original samples
    let u = input(700);
    let mut fine = Vec::with_capacity(3 * u.len());
    for k in 0..u.len() {
        if k > 0 {
            fine.push(u[k - 1] + (u[k] - u[k - 1]) / 3.0);
            fine.push(u[k - 1] + 2.0 * (u[k] - u[k - 1]) / 3.0);
        }
        fine.push(u[k]);
    }
    let (y, yf) = (kp.simulate(&u).unwrap(), kp.simulate(&fine).unwrap());
    for k in 0..u.len() {
        assert!((y[k] - yf[3 * k]).abs() < 1e-12, "sample {k}");
    }
    // a periodic input between fixed extremes: the loop closes after the first period
    let period = 400;
    let u: Vec<f64> = (0..3 * period)
        .map(|k| 1.5 * (2.0 * std::f64::consts::PI * k as f64 / period as f64).sin() + 0.2)
        .collect();
    let y = kp.simulate(&u).unwrap();
    assert!(max_abs_diff(&y[period..2 * period], &y[2 * period..]) < 1e-12);
}

#[test]
fn saturates_at_plus_minus_the_weight_sum() {
    let kp = example(0.2, Orientation::default());
    let total: f64 = kp.weights().iter().sum();
    let y = kp.simulate(&[5.0, -5.0, 0.0]).unwrap();
    assert!((y[0] - (0.3 + 1.0 + total)).abs() < 1e-12);
    assert!((y[1] - (0.3 - 1.0 - total)).abs() < 1e-12);
    // decreasing orientation: the output's sign flips
    let neg = example(
        0.2,
        Orientation {
            inverse: false,
            decreasing: true,
        },
    );
    let yn = neg.simulate(&[5.0, -5.0, 0.0]).unwrap();
    for (a, b) in y.iter().zip(&yn) {
        assert!((a + b).abs() < 1e-12);
    }
}

#[test]
fn branches_are_continuous_without_relay_jumps() {
    // Lipschitz constant a0 + 2Σμ/a: a fine ramp input moves the output by at most that per step
    let kp = example(0.1, Orientation::default());
    let total: f64 = kp.weights().iter().sum();
    let lipschitz = 0.1 + 2.0 * total / kp.width();
    let u: Vec<f64> = (0..4001)
        .map(|k| 2.5 * (k as f64 * std::f64::consts::PI / 1000.0).cos())
        .collect();
    let y = kp.simulate(&u).unwrap();
    for k in 1..u.len() {
        assert!((y[k] - y[k - 1]).abs() <= lipschitz * (u[k] - u[k - 1]).abs() + 1e-12);
    }
}

#[test]
fn inverse_round_trip_both_orientations() {
    let u = input(1500);
    for o in [
        Orientation::COUNTER_CLOCKWISE,
        Orientation::CLOCKWISE,
        Orientation {
            inverse: false,
            decreasing: true,
        },
    ] {
        for a0 in [0.0, 0.3] {
            let kp = example(a0, o);
            // a saturating clockwise operator (Γ = G⁻¹, a0 = 0) takes inputs within c ± Σμ only
            let u: Vec<f64> = if o.inverse && a0 == 0.0 {
                u.iter().map(|v| 0.5 * v).collect()
            } else {
                u.clone()
            };
            let reference = kp.simulate(&u).unwrap();
            let inv = kp.invert(&reference).unwrap();
            assert!(inv.clipped.is_empty(), "{o:?} a0 {a0}: {:?}", inv.clipped);
            let again = kp.simulate(&inv.u).unwrap();
            let err = max_abs_diff(&again, &reference);
            assert!(
                err < 1e-6,
                "{o:?} a0 {a0}: simulate(invert(r)) off by {err}"
            );
            assert!(max_abs_diff(&inv.predicted, &reference) < 1e-6);
            if a0 > 0.0 && !o.inverse {
                // strictly increasing branches: the input itself comes back
                assert!(max_abs_diff(&inv.u, &u) < 1e-6, "{o:?}");
            }
        }
    }
}

#[test]
fn unreachable_reference_is_clipped_and_listed() {
    let kp = example(0.0, Orientation::default());
    let total: f64 = kp.weights().iter().sum();
    let reference = [0.0, 0.3 + total + 1.0, 0.5, 0.3 - total - 0.5, 0.1];
    let inv = kp.invert(&reference).unwrap();
    assert_eq!(inv.clipped, vec![1, 3]);
    assert!((inv.predicted[1] - (0.3 + total)).abs() < 1e-9);
    assert!((inv.predicted[3] - (0.3 - total)).abs() < 1e-9);
    for k in [0, 2, 4] {
        assert!((inv.predicted[k] - reference[k]).abs() < 1e-9, "sample {k}");
    }
    let again = kp.simulate(&inv.u).unwrap();
    assert!(max_abs_diff(&again, &inv.predicted) < 1e-12);
}

#[test]
fn parameters_are_a0_the_weights_by_pair_and_c() {
    let kp = example(0.2, Orientation::default());
    let p = kp.parameters();
    let names = p.names();
    assert_eq!(kp.family(), "kp");
    assert_eq!(names.len(), 17);
    assert_eq!(
        &names[..5],
        &["a0", "mu1_1", "mu2_1", "mu2_2", "mu3_1"].map(String::from)
    );
    assert_eq!(names[15], "mu5_5");
    assert_eq!(names[16], "c");
    assert_eq!(p.get(1).min, 0.0);
    assert_eq!(p.get(16).min, f64::NEG_INFINITY);
    // with_values of its own values is the same operator; new values are checked
    let v = p.values();
    assert_eq!(kp.with_values(&v).unwrap(), kp);
    let mut bad = v.clone();
    bad[3] = -0.1;
    assert!(kp.with_values(&bad).is_err());
    assert!(kp.with_values(&v[..16]).is_err());
}

#[test]
fn output_scale_scales_the_output() {
    let kp = example(0.2, Orientation::default());
    let idx = kp.output_scale().unwrap();
    assert_eq!(idx, (0..17).collect::<Vec<_>>());
    let mut v = kp.parameters().values();
    for &i in &idx {
        v[i] *= 2.5;
    }
    let scaled = kp.with_values(&v).unwrap();
    let u = input(800);
    let (y, ys) = (kp.simulate(&u).unwrap(), scaled.simulate(&u).unwrap());
    for (a, b) in y.iter().zip(&ys) {
        assert!((2.5 * a - b).abs() < 1e-12);
    }
    assert_eq!(example(0.2, Orientation::CLOCKWISE).output_scale(), None);
}

#[test]
fn serde_round_trip_and_checked_rebuild() {
    let kp = example(0.2, Orientation::CLOCKWISE);
    let text = serde_json::to_string(&kp).unwrap();
    let back: Kp = serde_json::from_str(&text).unwrap();
    assert_eq!(back, kp);
    let back = back.checked().unwrap();
    assert_eq!(back, kp);
    let u = input(500);
    assert_eq!(back.simulate(&u).unwrap(), kp.simulate(&u).unwrap());
}

/// The serde form of `example` with one field replaced, read and checked.
fn checked_with(field: &str, value: serde_json::Value) -> hysid::Result<Kp> {
    let mut json = serde_json::to_value(example(0.2, Orientation::default())).unwrap();
    json[field] = value;
    let kp: Kp = serde_json::from_value(json).unwrap();
    kp.checked()
}

fn reason(e: Error) -> String {
    e.to_string()
}

#[test]
fn checked_refuses_bad_structures_naming_the_rule() {
    // a negative weight
    let mut w: Vec<f64> = example(0.2, Orientation::default()).weights().to_vec();
    w[1] = -0.01;
    let e = reason(checked_with("weights", serde_json::json!(w)).unwrap_err());
    assert!(
        e.contains("mu2_1") && e.contains("weights must be finite and >= 0"),
        "{e}"
    );
    // a non-increasing grid
    let e = reason(
        checked_with("thresholds", serde_json::json!([-1.0, 0.0, 0.0, 1.0, 2.0])).unwrap_err(),
    );
    assert!(e.contains("t3") && e.contains("strictly increasing"), "{e}");
    let e = reason(
        checked_with("thresholds", serde_json::json!([-1.0, 0.5, 0.0, 1.0, 2.0])).unwrap_err(),
    );
    assert!(e.contains("strictly increasing"), "{e}");
    // a ridge width ≤ 0
    for a in [0.0, -0.5] {
        let e = reason(checked_with("width", serde_json::json!(a)).unwrap_err());
        assert!(e.contains("ridge width a must be finite and > 0"), "{e}");
    }
    // a negative reversible slope, a weight count that does not match the grid
    let e = reason(checked_with("a0", serde_json::json!(-1.0)).unwrap_err());
    assert!(e.contains("a0") && e.contains(">= 0"), "{e}");
    let e = reason(checked_with("weights", serde_json::json!([0.1, 0.2])).unwrap_err());
    assert!(e.contains("15 kernels"), "{e}");
    let e = reason(checked_with("thresholds", serde_json::json!([])).unwrap_err());
    assert!(e.contains("empty"), "{e}");
    // a constant operator (zero weights are fine while a0 > 0, and a0 = 0 with weights)
    assert!(checked_with("weights", serde_json::json!(vec![0.0; 15])).is_ok());
    assert!(checked_with("a0", serde_json::json!(0.0)).is_ok());
    let mut zero = serde_json::to_value(example(0.2, Orientation::default())).unwrap();
    zero["weights"] = serde_json::json!(vec![0.0; 15]);
    zero["a0"] = serde_json::json!(0.0);
    let e = reason(
        serde_json::from_value::<Kp>(zero)
            .unwrap()
            .checked()
            .unwrap_err(),
    );
    assert!(e.contains("constant"), "{e}");
}

#[test]
fn bad_signals_are_refused() {
    let kp = example(0.2, Orientation::default());
    assert!(kp.simulate(&[]).is_err());
    assert!(kp.simulate(&[0.0, f64::NAN]).is_err());
    assert!(kp.invert(&[f64::INFINITY]).is_err());
}

/// The bounded inverse (bisection over the ramp edges, then over the rows' and columns'
/// switch points, then the last piece's line) solves G(x) = r to rounding on references that
/// are no model's output — a seeded random walk with reversals of every size, up to 10 %
/// beyond the saturation levels, so that most samples take the bisections — on grids of 1 to 20 thresholds, with ridges narrower than the
/// grid's spacing, tiling it, and spanning several thresholds, with and without a₀; and no
/// sample takes more trials than `Kp::inverse_trials` states.
#[test]
fn the_bounded_inverse_solves_arbitrary_references_within_its_stated_trials() {
    let mut uniform = crate::unit::test_signals::xorshift_uniform(0x9e37_79b9_7f4a_7c15u64);
    for n in [1, 2, 5, 20] {
        let t = Kp::uniform_thresholds(-2.0, 2.0, n).unwrap();
        let spacing = 4.0 / n as f64;
        for width in [0.6 * spacing, spacing, 4.0 * spacing, 7.0] {
            for a0 in [0.3, 0.0] {
                let k = n * (n + 1) / 2;
                let w: Vec<f64> = (0..k).map(|_| 0.01 + uniform()).collect();
                let kp = Kp::new(t.clone(), width, w, a0, 0.3, Orientation::default()).unwrap();
                let total: f64 = kp.weights().iter().sum();
                let (lo, hi) = (0.3 - total, 0.3 + total);
                // reflected at 10 % beyond the saturation levels, so that most references
                // are reached inside the grid and take the bisections
                let (floor, ceiling) = (lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo));
                let mut r = Vec::new();
                let mut x = 0.3;
                for _ in 0..2000 {
                    x += (uniform() - 0.5) * (hi - lo) * uniform().powi(3) * 1.5;
                    if x > ceiling {
                        x = (2.0 * ceiling - x).max(floor);
                    } else if x < floor {
                        x = (2.0 * floor - x).min(ceiling);
                    }
                    r.push(x);
                }
                let bound = kp.inverse_trials();
                let (u, trials) = kp.core_inverse_counting_trials(&r);
                let worst = trials.iter().copied().max().unwrap_or(0);
                assert!(
                    worst <= bound,
                    "n {n} width {width} a0 {a0}: {worst} trials, bound {bound}"
                );
                if n > 1 {
                    let inside = trials.iter().filter(|&&t| t > 2).count();
                    assert!(
                        inside > trials.len() / 2,
                        "n {n} width {width} a0 {a0}: only {inside} samples bisected"
                    );
                }
                let y = kp.simulate(&u).unwrap();
                for (s, (&rs, &ys)) in r.iter().zip(&y).enumerate() {
                    let tol = 1e-9 * (1.0 + rs.abs());
                    if a0 > 0.0 || (rs > lo + tol && rs < hi - tol) {
                        assert!(
                            (ys - rs).abs() <= tol,
                            "n {n} width {width} a0 {a0} sample {s}: G(G⁻¹(r)) = {ys} for r = {rs}"
                        );
                    } else {
                        let level = rs.clamp(lo, hi);
                        assert!(
                            (ys - level).abs() <= tol,
                            "sample {s}: {ys} vs level {level}"
                        );
                    }
                }
            }
        }
    }
}
