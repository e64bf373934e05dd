//! Tests of `hysid::model::linear`.

use hysid::model::*;

#[test]
fn example_two_block_is_stable() {
    let lin = LinearBlock::new(vec![-1.5, 0.7, -0.1], vec![1.0, 0.4, -0.2], 2).unwrap();
    assert!(lin.is_stable());
    assert!((lin.static_gain() - 1.2 / 0.1).abs() < 1e-12);
    let unstable = LinearBlock::new(vec![-2.1, 1.1], vec![1.0], 1).unwrap();
    assert!(!unstable.is_stable());
}

#[test]
fn delay_shifts_the_response() {
    let lin = LinearBlock::new(vec![], vec![1.0, 0.4, -0.2], 2).unwrap();
    let y = lin.simulate(&[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    assert_eq!(y, vec![0.0, 0.0, 1.0, 0.4, -0.2, 0.0]);
}
