//! Tests of `hysid::model::operators::duhem`.

use hysid::model::operators::duhem::*;
use hysid::model::operators::HysteresisOperator;

/// A long ascending ramp settles on f(u) + (c − a)/α, a descending one on f(u) − (c − a)/α.
#[test]
fn branches_settle_on_the_offset_lines() {
    let d = Duhem::new(4.0, 1.0, 0.2, 0.5).unwrap();
    let y = d.simulate(&[0.0, 10.0, -10.0]).unwrap();
    assert!(
        (y[1] - (10.0 + 0.2 + (0.5 - 1.0) / 4.0)).abs() < 1e-8,
        "{}",
        y[1]
    );
    assert!(
        (y[2] - (-10.0 + 0.2 - (0.5 - 1.0) / 4.0)).abs() < 1e-8,
        "{}",
        y[2]
    );
}

#[test]
fn bad_alpha_is_refused() {
    assert!(Duhem::new(0.0, 1.0, 0.0, 0.0).is_err());
    assert!(Duhem::new(1.0, f64::INFINITY, 0.0, 0.0).is_err());
}
