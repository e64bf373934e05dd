//! Tests of `hysid::identify::operators::gpi`.

use hysid::identify::operators::gpi::*;
use hysid::identify::operators::linear_support::threshold_grid;
use hysid::model::operators::HysteresisOperator;
use hysid::model::operators::{DeadZones, GeneralizedPi, Orientation, PrandtlIshlinskii};

fn input(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            2.5 * (1.0 - 0.75 * t) * (31.0 * t).sin() + 0.5 * (127.0 * t).sin()
        })
        .collect()
}

#[test]
fn recovers_weights_both_orientations() {
    let u = input(4000);
    let grid = threshold_grid(&u, 5).unwrap();
    let upper = vec![0.6, 1.4];
    let lower = vec![-0.9];
    for o in [Orientation::COUNTER_CLOCKWISE, Orientation::CLOCKWISE] {
        let h = PrandtlIshlinskii::new(
            0.7,
            vec![0.4, 0.0, 0.3, 0.2, 0.1],
            grid.clone(),
            0.2,
            Orientation::default(),
        )
        .unwrap();
        let s_inv = DeadZones::new(1.0, vec![(0.6, 0.25), (1.4, -0.3)], vec![(-0.9, 0.4)]).unwrap();
        let t = GeneralizedPi::new(h, s_inv.inverse(), o);
        let y = t.simulate(&u).unwrap();
        let opts = GpiOptions {
            grid: Some(grid.clone()),
            dead_zone_grid: Some((upper.clone(), lower.clone())),
            ..GpiOptions::default()
        };
        let f = fit(&u, &y, &opts).unwrap();
        assert_eq!(f.model.orientation(), o);
        let hp = f.model.pi();
        assert!((hp.a0() - 0.7).abs() < 1e-6, "{o:?} {}", hp.a0());
        for (a, b) in hp.weights().iter().zip([0.4, 0.0, 0.3, 0.2, 0.1]) {
            assert!((a - b).abs() < 1e-6 * b.max(1.0), "{o:?} {a} vs {b}");
        }
        let d = f.model.dead_zones().inverse();
        for ((_, a), (_, b)) in d
            .upper()
            .iter()
            .zip(s_inv.upper())
            .chain(d.lower().iter().zip(s_inv.lower()))
        {
            assert!((a - b).abs() < 1e-6, "{o:?} {a} vs {b}");
        }
        assert!(f.fit_percent > 99.9999);
    }
}
