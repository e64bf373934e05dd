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

/// A single loop measured from its tip (the vendored Mn-Zn ferrite's largest loop): the
/// training part, the descent and a third of the return, cannot tell the orientation, so the
/// comparison detects it on the whole record (counter-clockwise, a B(H) loop) and gives it
/// to the families that could not tell — every linear-in-weights family is fitted and
/// scored, its row says `record`; Jiles–Atherton detects its own, Dahl refuses for its
/// stated reason. Before, eight families failed ("cannot be told").
#[test]
fn a_single_loop_takes_the_records_orientation_when_its_training_part_cannot_tell() {
    use crate::unit::test_signals::ferrite_loop;
    use hysid::identify::operators::family::OrientationSource;
    use hysid::model::operators::LoopOrientation;
    let (h, b) = ferrite_loop(4);
    assert!(LoopOrientation::detect(&h[..77], &b[..77]).is_err());
    let options = CompareOptions {
        families: Family::ALL.to_vec(),
        ..CompareOptions::default()
    };
    let c = compare(&h, &b, None, &options).unwrap();
    assert_eq!(
        c.orientation,
        Some((LoopOrientation::CounterClockwise, OrientationSource::Record))
    );
    for family in crate::unit::test_signals::LINEAR_IN_WEIGHTS {
        let row = c.row(family).unwrap();
        assert_eq!(row.error, None, "{family}");
        assert_eq!(row.orientation_source, Some("record"), "{family}");
        assert_eq!(row.orientation, Some("ccw"), "{family}");
    }
    assert_eq!(
        c.row(Family::JilesAtherton).unwrap().orientation_source,
        Some("detected")
    );
    let dahl = c.row(Family::Dahl).unwrap().error.clone().unwrap();
    assert!(dahl.contains("counter-clockwise"), "{dahl}");
    assert_eq!(c.best().unwrap().family, "jiles-atherton");
}
