//! Tests of `hysid::identify::operators::preisach`.

use hysid::identify::operators::preisach::*;
use hysid::model::operators::HysteresisOperator;
use hysid::model::operators::{Orientation, Preisach};

fn input(n: usize) -> Vec<f64> {
    // a decaying oscillation with nested reversals: reversal points all over the range
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            (1.0 - 0.9 * t) * (61.0 * t).sin() * 1.95 + 0.3 * (1.0 - t) * (233.0 * t).sin()
        })
        .collect()
}

fn truth(o: Orientation, range: (f64, f64), n: usize) -> Preisach {
    let cells = n * (n + 1) / 2;
    let w: Vec<f64> = (0..cells)
        .map(|k| 0.02 + 0.05 * ((k * 5 % 7) as f64) / 7.0)
        .collect();
    Preisach::new(range.0, range.1, n, w, 0.3, 0.1, o).unwrap()
}

#[test]
fn recovers_weights_both_orientations() {
    let u = input(6000);
    for o in [Orientation::COUNTER_CLOCKWISE, Orientation::CLOCKWISE] {
        // the grid spans the range of the core operator's input (y for a clockwise loop)
        let range = if o.inverse { (-4.0, 4.0) } else { (-2.2, 2.2) };
        let t = truth(o, range, 6);
        let y = t.simulate(&u).unwrap();
        let opts = PreisachOptions {
            levels: 6,
            lambda: 0.0,
            range: Some(range),
            orientation: Some(o),
            ..PreisachOptions::default()
        };
        let f = fit(&u, &y, &opts).unwrap();
        for (a, b) in f.model.weights().iter().zip(t.weights()) {
            assert!((a - b).abs() < 1e-6 * b, "{o:?} {a} vs {b}");
        }
        assert!((f.model.a0() - 0.3).abs() < 1e-6 * 0.3);
    }
}

#[test]
fn bad_options_are_refused() {
    let u = input(2000);
    let y = u.clone();
    let bad = PreisachOptions {
        lambda: f64::NAN,
        ..PreisachOptions::default()
    };
    assert!(fit(&u, &y, &bad).is_err());
    let bad = PreisachOptions {
        range: Some((1.0, -1.0)),
        ..PreisachOptions::default()
    };
    assert!(fit(&u, &y, &bad).is_err());
    // 210 cells need more samples than 100
    assert!(fit(&u[..100], &y[..100], &PreisachOptions::default()).is_err());
}
