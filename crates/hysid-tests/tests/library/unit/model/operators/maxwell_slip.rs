//! Tests of `hysid::model::operators::maxwell_slip`.

use hysid::model::operators::stop;
use hysid::model::operators::HysteresisOperator;
use hysid::model::operators::Orientation;
use hysid::model::operators::*;

#[test]
fn elements_are_stop_operators_and_the_inverse_round_trips() {
    let x: Vec<f64> = (0..2000)
        .map(|k| {
            let t = k as f64 / 2000.0;
            (1.0 - 0.6 * t) * (25.0 * t).sin() + 0.2 * (90.0 * t).sin()
        })
        .collect();
    let m = MaxwellSlip::new(
        0.5,
        vec![2.0, 1.0],
        vec![0.1, 0.4],
        0.0,
        Orientation::default(),
    )
    .unwrap();
    let f = m.simulate(&x).unwrap();
    let (e1, e2) = (stop(&x, 0.1), stop(&x, 0.4));
    for k in 0..x.len() {
        assert!((f[k] - (0.5 * x[k] + 2.0 * e1[k] + e2[k])).abs() < 1e-12);
    }
    assert_eq!(m.slip_forces(), vec![0.2, 0.4]);
    for o in [Orientation::COUNTER_CLOCKWISE, Orientation::CLOCKWISE] {
        let m = MaxwellSlip::new(0.5, vec![2.0, 1.0], vec![0.1, 0.4], 0.0, o).unwrap();
        let reference = m.simulate(&x).unwrap();
        let inv = m.invert(&reference).unwrap();
        let err = inv
            .predicted
            .iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-9 && inv.clipped.is_empty(), "{o:?} {err}");
    }
}

#[test]
fn pure_friction_saturates_and_clips() {
    let m = MaxwellSlip::new(
        0.0,
        vec![2.0, 1.0],
        vec![0.1, 0.4],
        0.0,
        Orientation::default(),
    )
    .unwrap();
    // |F| ≤ W1 + W2 = 0.6
    let inv = m.invert(&[0.1, 0.5, 0.7, 0.0, -0.65]).unwrap();
    assert_eq!(inv.clipped, vec![2, 4]);
    assert!((inv.predicted[1] - 0.5).abs() < 1e-12 && (inv.predicted[2] - 0.6).abs() < 1e-12);
    assert!(MaxwellSlip::new(-1.0, vec![1.0], vec![0.1], 0.0, Orientation::default()).is_err());
}
