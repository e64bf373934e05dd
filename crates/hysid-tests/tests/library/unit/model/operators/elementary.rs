//! Tests of `hysid::model::operators::elementary`.

use hysid::model::operators::*;

#[test]
fn play_follows_its_definition() {
    // r = 1: rises with u − 1, holds inside the band, falls with u + 1.
    let u = [0.5, 2.0, 3.0, 2.5, 1.0, 0.0];
    assert_eq!(play(&u, 1.0), vec![0.0, 1.0, 2.0, 2.0, 2.0, 1.0]);
    assert_eq!(stop(&u, 1.0), vec![0.5, 1.0, 1.0, 0.5, -1.0, -1.0]);
}

#[test]
fn thresholds_are_checked() {
    assert!(validate_thresholds("r", &[0.1, 0.2]).is_ok());
    let e = validate_thresholds("r", &[0.2, 0.1])
        .unwrap_err()
        .to_string();
    assert!(e.contains("not strictly increasing"), "{e}");
    assert!(validate_thresholds("r", &[0.0, 0.1]).is_err());
    assert!(validate_thresholds("r", &[f64::NAN]).is_err());
}

#[test]
fn monotone_solve_finds_roots_and_clips() {
    let f = |u: f64| (u - 1.0).max(0.0) - (-1.0 - u).max(0.0);
    let b = Branch {
        center: 0.0,
        span: 2.0,
        unbounded_below: true,
        unbounded_above: true,
    };
    let (u, c) = solve_monotone(f, 37.5, b);
    assert!((f(u) - 37.5).abs() < 1e-12 && !c);
    let sat = |u: f64| u.clamp(-1.0, 1.0);
    let b = Branch {
        unbounded_above: false,
        ..b
    };
    let (u, c) = solve_monotone(sat, 3.0, b);
    assert!(c && sat(u) == 1.0);
    let (u, c) = solve_monotone(sat, 0.25, b);
    assert!(!c && (u - 0.25).abs() < 1e-15);
}

#[test]
fn orientation_is_detected() {
    let u: Vec<f64> = (0..400).map(|k| (k as f64 * 0.05).sin()).collect();
    let y = play(&u, 0.3);
    assert_eq!(
        Orientation::detect(&u, &y).unwrap(),
        Orientation::COUNTER_CLOCKWISE
    );
    assert_eq!(Orientation::detect(&y, &u).unwrap(), Orientation::CLOCKWISE);
    let neg: Vec<f64> = y.iter().map(|v| -v).collect();
    let o = Orientation::detect(&u, &neg).unwrap();
    assert!(o.decreasing && !o.inverse);
}
