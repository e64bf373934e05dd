//! Tests of `hysid::identify::operators::maxwell_slip`.

use hysid::identify::operators::linear_support::threshold_grid;
use hysid::identify::operators::maxwell_slip::*;
use hysid::model::operators::HysteresisOperator;
use hysid::model::operators::{MaxwellSlip, Orientation};

fn input(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            1e-3 * ((1.0 - 0.8 * t) * (33.0 * t).sin() + 0.2 * (140.0 * t).sin())
        })
        .collect()
}

#[test]
fn recovers_stiffnesses_and_slip_forces_both_orientations() {
    let x = input(4000);
    // a fine grid: also inside the range of G's input y in the inverse form
    let widths: Vec<f64> = threshold_grid(&x, 5)
        .unwrap()
        .iter()
        .map(|w| 0.15 * w)
        .collect();
    let k = [2.0, 0.0, 1.5, 1.0, 2.0];
    for o in [
        Orientation::default(),
        Orientation {
            inverse: true,
            decreasing: false,
        },
    ] {
        let t = MaxwellSlip::new(1.0, k.to_vec(), widths.clone(), 1e-4, o).unwrap();
        let f_meas = t.simulate(&x).unwrap();
        let opts = MaxwellSlipOptions {
            widths: Some(widths.clone()),
            ..MaxwellSlipOptions::default()
        };
        let f = fit(&x, &f_meas, &opts).unwrap();
        assert_eq!(f.model.orientation(), o);
        assert!((f.model.k0() - 1.0).abs() < 1e-6, "{o:?} {}", f.model.k0());
        for (a, b) in f.model.stiffness().iter().zip(k) {
            assert!((a - b).abs() < 1e-6 * 2.0, "{o:?} {a} vs {b}");
        }
        for (a, b) in f.model.slip_forces().iter().zip(t.slip_forces()) {
            assert!((a - b).abs() < 1e-6 * b.max(1e-4), "{o:?} {a} vs {b}");
        }
    }
}
