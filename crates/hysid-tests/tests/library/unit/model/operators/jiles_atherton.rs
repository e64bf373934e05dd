//! Tests of `hysid::model::operators::jiles_atherton`.

use hysid::model::operators::jiles_atherton::*;
use hysid::model::operators::HysteresisOperator;

#[test]
fn langevin_series_joins_the_closed_form() {
    for x in [0.0999999, 0.1, -0.1] {
        let (l, dl) = langevin(x);
        let closed = 1.0 / x.tanh() - 1.0 / x;
        assert!((l - closed).abs() < 1e-13, "{x}");
        let dclosed = 1.0 / (x * x) - 1.0 / x.sinh().powi(2);
        assert!((dl - dclosed).abs() < 1e-10, "{x}");
    }
    assert_eq!(langevin(0.0).0, 0.0);
    assert!((langevin(800.0).0 - (1.0 - 1.0 / 800.0)).abs() < 1e-15);
}

/// With c → the anhysteretic alone (c close to 1) the operator follows M_an; with α = 0 a
/// saturating ramp approaches Mₛ(coth(H/a) − a/H) within (1 − c)·gap.
#[test]
fn reversible_limit_follows_the_anhysteretic() {
    let mut ja = JilesAtherton::new(1e5, 10.0, 5.0, 0.999999, 0.0).unwrap();
    ja.output = JaOutput::Magnetisation;
    let h: Vec<f64> = (0..=200).map(|i| i as f64).collect();
    let m = ja.simulate(&h).unwrap();
    let (man, _) = ja.anhysteretic(200.0);
    assert!((m[200] - man).abs() < 1e-3 * man, "{} vs {man}", m[200]);
}

#[test]
fn bad_parameters_are_refused() {
    assert!(JilesAtherton::new(-1.0, 1.0, 1.0, 0.1, 0.0).is_err());
    assert!(JilesAtherton::new(1.0, 1.0, 1.0, 1.0, 0.0).is_err());
    assert!(JilesAtherton::new(1.0, f64::NAN, 1.0, 0.1, 0.0).is_err());
}
