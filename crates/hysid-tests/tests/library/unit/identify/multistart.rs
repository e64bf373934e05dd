//! Tests of `hysid::identify::multistart`.

use hysid::identify::multistart::*;
use hysid::model::Parameter;
use hysid::model::ParameterSet;

#[test]
fn starts_lie_inside_the_bounds_and_are_seeded() {
    let params = ParameterSet::new(vec![
        Parameter::new("wide", 5.0).bounds(1.0, 100.0),
        Parameter::new("narrow", 0.5).bounds(0.0, 1.0),
        Parameter::new("free", -3.0),
        Parameter::new("fixed", 7.0).fixed(true),
    ])
    .unwrap();
    let a = draw_starts(&params, 50, 9);
    let b = draw_starts(&params, 50, 9);
    assert_eq!(a[0], params);
    for (p, q) in a.iter().zip(&b) {
        assert_eq!(p, q);
        let v = p.values();
        assert!((1.0..=100.0).contains(&v[0]) && (0.0..=1.0).contains(&v[1]));
        assert!((-6.0..=-1.5).contains(&v[2]) && v[3] == 7.0);
    }
    // Log-uniform over the decade-wide bounds: about half the draws below √(1·100) = 10.
    let below = a.iter().skip(1).filter(|p| p.values()[0] < 10.0).count();
    assert!((15..=35).contains(&below), "{below}");
}
