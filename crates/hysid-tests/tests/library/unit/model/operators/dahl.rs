//! Tests of `hysid::model::operators::dahl`.

use hysid::model::operators::dahl::*;
use hysid::model::operators::differential::LoopOrientation;
use hysid::model::operators::HysteresisOperator;

/// i = 1 from F = 0: F(x) = F_c·(1 − e^{−σx/F_c}) on an ascending branch.
#[test]
fn ascending_branch_has_the_closed_form() {
    let d = Dahl::new(20.0, 2.0, 1.0).unwrap();
    let f = d.simulate(&[0.0, 0.3]).unwrap();
    assert!((f[1] - 2.0 * (1.0 - (-3.0f64).exp())).abs() < 1e-10);
    let mut mirrored = d.clone();
    mirrored.orientation = LoopOrientation::CounterClockwise;
    let f = mirrored.simulate(&[0.0, -0.3]).unwrap();
    assert!((f[1] - 2.0 * (1.0 - (-3.0f64).exp())).abs() < 1e-10);
}

#[test]
fn bad_parameters_are_refused() {
    assert!(Dahl::new(1.0, 0.0, 1.0).is_err());
    assert!(Dahl::new(1.0, 1.0, 0.5).is_err());
}
