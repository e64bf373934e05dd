//! Tests of `hysid::model::operators::backlash`.

use hysid::model::operators::HysteresisOperator;
use hysid::model::operators::Orientation;
use hysid::model::operators::*;

#[test]
fn right_inverse_jumps_across_the_dead_band() {
    let b = Backlash::new(2.0, 0.5, 1.0, Orientation::default()).unwrap();
    let reference = [1.0, 2.0, 3.0, 3.0, 2.0, 1.5, 2.5];
    let inv = b.invert(&reference).unwrap();
    assert_eq!(inv.u, vec![0.0, 1.0, 1.5, 1.5, 0.0, -0.25, 1.25]);
    for (p, r) in inv.predicted.iter().zip(&reference) {
        assert!((p - r).abs() < 1e-12);
    }
    assert!(inv.clipped.is_empty());
}

#[test]
fn clockwise_backlash_lists_unreachable_references() {
    let b = Backlash::new(1.0, 0.5, 0.0, Orientation::CLOCKWISE).unwrap();
    // Γ = G⁻¹ jumps at reversals: a reference moving smoothly back cannot be produced.
    let u = [0.0, 1.0, 2.0, 1.0, 0.0];
    let y = b.simulate(&u).unwrap();
    assert_eq!(y, vec![0.0, 1.5, 2.5, 0.5, -0.5]);
    let inv = b.invert(&y).unwrap();
    assert!(inv.clipped.is_empty());
    let inv = b.invert(&[0.0, 1.5, 2.5, 2.0]).unwrap();
    assert_eq!(inv.clipped, vec![3]);
}

#[test]
fn bad_parameters_are_refused() {
    assert!(Backlash::new(0.0, 0.5, 0.0, Orientation::default()).is_err());
    assert!(Backlash::new(1.0, -0.5, 0.0, Orientation::default()).is_err());
    assert!(Backlash::new(1.0, f64::INFINITY, 0.0, Orientation::default()).is_err());
}
