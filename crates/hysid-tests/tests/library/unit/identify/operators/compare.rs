//! Tests of `hysid::identify::operators::compare`.

use hysid::identify::operators::compare::*;
use hysid::identify::operators::family::Family;
use hysid::model::operators::{Backlash, HysteresisOperator, Orientation};

/// Data made by a backlash: backlash ranks above PI-less families that cannot follow it,
/// the split covers 60 %, a failing family keeps its error in its row.
#[test]
fn ranks_and_keeps_failures() {
    let truth = Backlash::new(1.5, 0.2, 0.1, Orientation::default()).unwrap();
    let u: Vec<f64> = (0..1500)
        .map(|k| {
            let t = k as f64 / 1500.0;
            (0.3 + 0.7 * t) * (2.0 * std::f64::consts::PI * 4.0 * t).sin()
        })
        .collect();
    let y = truth.simulate(&u).unwrap();
    let options = CompareOptions {
        families: vec![Family::Duhem, Family::Backlash, Family::Pi],
        ..CompareOptions::default()
    };
    let c = compare(&u, &y, None, &options).unwrap();
    assert_eq!(
        c.split,
        Split::Fraction {
            fraction: 0.6,
            train: 900,
            samples: 1500
        }
    );
    assert_eq!(c.rows.len(), 3);
    let best = c.best().unwrap();
    assert!(best.family == "backlash" || best.family == "pi");
    assert!(best.validation_fit_percent.unwrap() > 99.9);
    // A record with no reversal fails every family, row by row.
    let ramp: Vec<f64> = (0..200).map(|k| k as f64).collect();
    let c = compare(&ramp, &ramp, None, &options).unwrap();
    assert!(c.rows.iter().all(|r| r.error.is_some()) && c.best().is_none());
}
