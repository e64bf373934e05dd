//! Tests of `hysid::model::operators::differential`.

use hysid::model::operators::differential::*;

/// dx/du = 1 − δ·x, y = x: the exact branch solution is known in closed form.
struct Relax;
impl InputOde for Relax {
    fn slope(&self, _u: f64, x: f64, d: f64) -> f64 {
        1.0 - d * x
    }
    fn output(&self, _u: f64, x: f64) -> f64 {
        x
    }
    fn initial_state(&self) -> f64 {
        0.0
    }
    fn state_scale(&self) -> f64 {
        1.0
    }
    fn max_substep(&self) -> f64 {
        0.5
    }
    fn inversion_span(&self) -> f64 {
        40.0
    }
}

#[test]
fn branch_matches_the_closed_form_whatever_the_sampling() {
    // Ascending from x = 0: x(u) = 1 − e^{−u}.
    let coarse = simulate(&Relax, &[0.0, 3.0]).unwrap();
    let fine: Vec<f64> = (0..=3000).map(|k| k as f64 * 1e-3).collect();
    let fine = simulate(&Relax, &fine).unwrap();
    let exact = 1.0 - (-3.0f64).exp();
    assert!((coarse[1] - exact).abs() < 1e-9, "{}", coarse[1]);
    assert!((fine[3000] - exact).abs() < 1e-9, "{}", fine[3000]);
}

#[test]
fn inverse_reproduces_a_reachable_reference_and_clips_the_rest() {
    let u: Vec<f64> = (0..400)
        .map(|k| 3.0 * (k as f64 * 0.05).sin() * (1.0 - k as f64 / 800.0))
        .collect();
    let r = simulate(&Relax, &u).unwrap();
    let inv = invert(&Relax, &r).unwrap();
    assert!(inv.clipped.is_empty(), "{:?}", inv.clipped);
    let y = simulate(&Relax, &inv.u).unwrap();
    let worst = y
        .iter()
        .zip(&r)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "{worst}");
    // |x| < 1 always for this operator: 1.5 is out of reach.
    let inv = invert(&Relax, &[0.0, 0.5, 1.5, 0.2]).unwrap();
    assert_eq!(inv.clipped, vec![2]);
    assert!((inv.predicted[3] - 0.2).abs() < 1e-12);
}

#[test]
fn orientation_from_the_loop_area() {
    let t: Vec<f64> = (0..100).map(|k| k as f64 * 0.0628).collect();
    let u: Vec<f64> = t.iter().map(|t| t.sin()).collect();
    let lag: Vec<f64> = t.iter().map(|t| (t - 0.3).sin()).collect();
    let lead: Vec<f64> = t.iter().map(|t| (t + 0.3).sin()).collect();
    assert_eq!(
        LoopOrientation::of_loop(&u, &lag),
        LoopOrientation::CounterClockwise
    );
    assert_eq!(
        LoopOrientation::of_loop(&u, &lead),
        LoopOrientation::Clockwise
    );
}

#[test]
fn nan_input_is_an_error() {
    assert!(simulate(&Relax, &[0.0, f64::NAN]).is_err());
    assert!(invert(&Relax, &[]).is_err());
}
