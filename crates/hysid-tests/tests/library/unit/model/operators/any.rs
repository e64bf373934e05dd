//! Tests of `hysid::model::operators::any`.

use hysid::model::operators::any::*;
use hysid::model::operators::Orientation;
use hysid::model::operators::{PrandtlIshlinskii, Preisach};

#[test]
fn structure_round_trips_and_is_checked() {
    let pi = PrandtlIshlinskii::new(
        0.5,
        vec![0.3, 0.2],
        vec![0.1, 0.4],
        1.0,
        Orientation::CLOCKWISE,
    )
    .unwrap();
    let m = OperatorModel::Pi(pi);
    let s = m.structure().unwrap();
    assert_eq!(OperatorModel::from_structure("pi", &s).unwrap(), m);
    // A non-monotone threshold grid in a file is refused by the constructor.
    let mut bad = s.clone();
    bad["thresholds"] = serde_json::json!([0.4, 0.1]);
    assert!(OperatorModel::from_structure("pi", &bad).is_err());
    assert!(OperatorModel::from_structure("nope", &s).is_err());
}

#[test]
fn preisach_cache_is_rebuilt() {
    let w = vec![1.0, 0.5, 2.0];
    let p = Preisach::new(-1.0, 1.0, 2, w, 0.1, 0.0, Orientation::default()).unwrap();
    let m = OperatorModel::Preisach(p);
    let back = OperatorModel::from_structure("preisach", &m.structure().unwrap()).unwrap();
    let u = [0.0, 0.8, -0.3, 0.5, -1.0, 1.0];
    assert_eq!(
        back.as_operator().simulate(&u).unwrap(),
        m.as_operator().simulate(&u).unwrap()
    );
}
