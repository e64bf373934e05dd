//! Tests of `hysid::model::operators::pi`.

use hysid::model::operators::HysteresisOperator;
use hysid::model::operators::Orientation;
use hysid::model::operators::*;

/// A decaying sine with nested reversals (minor loops).
fn input(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            3.0 * (1.0 - 0.8 * t) * (40.0 * t).sin() + 0.7 * (170.0 * t).sin()
        })
        .collect()
}

fn example(o: Orientation) -> PrandtlIshlinskii {
    PrandtlIshlinskii::new(
        0.8,
        vec![0.5, 0.3, 0.0, 0.2],
        vec![0.3, 0.7, 1.2, 2.0],
        0.4,
        o,
    )
    .unwrap()
}

#[test]
fn analytic_inverse_round_trip_both_orientations() {
    let u = input(3000);
    for o in [Orientation::COUNTER_CLOCKWISE, Orientation::CLOCKWISE] {
        let pi = example(o);
        let reference = pi.simulate(&u).unwrap();
        let inv = pi.invert(&reference).unwrap();
        assert!(inv.clipped.is_empty());
        let err = inv
            .predicted
            .iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-9, "{o:?}: {err}");
        // the inverse reconstructs the input itself
        let eu = inv
            .u
            .iter()
            .zip(&u)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(eu < 1e-9, "{o:?}: {eu}");
    }
}

#[test]
fn numerical_inverse_when_a0_is_zero_and_clipping_when_saturated() {
    let u = input(2000);
    let pi = PrandtlIshlinskii::new(
        0.0,
        vec![1.0, 0.5],
        vec![0.2, 0.6],
        0.0,
        Orientation::default(),
    )
    .unwrap();
    let reference: Vec<f64> = pi.simulate(&u).unwrap();
    let inv = pi.invert(&reference).unwrap();
    let err = inv
        .predicted
        .iter()
        .zip(&reference)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(err < 1e-9 && inv.clipped.is_empty(), "{err}");
    // a stop-type (saturating) PI: a0 = 1, a1 = −1 → output bounded by ±r1
    let sat =
        PrandtlIshlinskii::new(1.0, vec![-1.0], vec![0.5], 0.0, Orientation::default()).unwrap();
    let inv = sat.invert(&[0.2, 0.4, 0.9, 0.1, -0.7]).unwrap();
    assert_eq!(inv.clipped, vec![2, 4]);
    assert!((inv.predicted[2] - 0.5).abs() < 1e-12 && (inv.predicted[3] - 0.1).abs() < 1e-12);
}

#[test]
fn bad_parameters_are_refused() {
    let o = Orientation::default();
    assert!(PrandtlIshlinskii::new(1.0, vec![1.0, 1.0], vec![0.5, 0.2], 0.0, o).is_err());
    assert!(PrandtlIshlinskii::new(1.0, vec![-2.0], vec![0.5], 0.0, o).is_err());
    assert!(PrandtlIshlinskii::new(f64::NAN, vec![1.0], vec![0.5], 0.0, o).is_err());
    assert!(PrandtlIshlinskii::new(1.0, vec![1.0], vec![0.5, 0.6], 0.0, o).is_err());
    let pi = example(o);
    assert!(pi.simulate(&[0.0, f64::NAN]).is_err());
    assert!(pi.simulate(&[]).is_err());
}
