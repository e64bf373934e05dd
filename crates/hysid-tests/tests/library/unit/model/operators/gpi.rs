//! Tests of `hysid::model::operators::gpi`.

use hysid::model::operators::Orientation;
use hysid::model::operators::*;
use hysid::model::operators::{HysteresisOperator, PrandtlIshlinskii};

fn example(o: Orientation) -> GeneralizedPi {
    let h = PrandtlIshlinskii::new(0.6, vec![0.4, 0.3], vec![0.4, 1.0], 0.1, o).unwrap();
    let s = DeadZones::new(1.0, vec![(0.5, 0.3), (1.5, 0.4)], vec![(-0.8, -0.2)]).unwrap();
    GeneralizedPi::new(h, s, o)
}

#[test]
fn dead_zone_inverse_is_exact() {
    let s = example(Orientation::default()).dead_zones().clone();
    let inv = s.inverse();
    for k in -40..=40 {
        let v = k as f64 * 0.11;
        assert!((inv.eval(s.eval(v)) - v).abs() < 1e-13, "{v}");
    }
    assert!(DeadZones::new(1.0, vec![(0.5, -1.5)], vec![]).is_err());
    assert!(DeadZones::new(1.0, vec![(0.5, 0.1), (0.4, 0.1)], vec![]).is_err());
    assert!(DeadZones::new(1.0, vec![], vec![(0.4, 0.1)]).is_err());
}

#[test]
fn inverse_round_trip_both_orientations() {
    let u: Vec<f64> = (0..3000)
        .map(|k| {
            let t = k as f64 / 3000.0;
            2.5 * (1.0 - 0.7 * t) * (30.0 * t).sin() + 0.5 * (130.0 * t).cos()
        })
        .collect();
    for o in [Orientation::COUNTER_CLOCKWISE, Orientation::CLOCKWISE] {
        let g = example(o);
        let reference = g.simulate(&u).unwrap();
        let inv = g.invert(&reference).unwrap();
        let err = inv
            .predicted
            .iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-9 && inv.clipped.is_empty(), "{o:?}: {err}");
    }
}
