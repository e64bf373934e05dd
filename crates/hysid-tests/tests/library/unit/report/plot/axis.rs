//! Tests of `hysid::report::plot::axis`.

use hysid::report::plot::axis::*;

#[test]
fn constant_and_degenerate_ranges_are_padded() {
    assert_eq!(pad_range((0.0, 0.0), 0.05), (-1.0, 1.0));
    let (lo, hi) = pad_range((5.0, 5.0), 0.05);
    assert!(lo < 5.0 && hi > 5.0);
    let (lo, hi) = pad_range((-f64::MAX, f64::MAX), 0.05);
    assert!((hi - lo).is_finite());
}

#[test]
fn tick_labels_share_decimals() {
    let f = AxisFormat::new((0.0, 1.0), 6);
    assert_eq!(f.format(0.5), "0.5");
    assert_eq!(f.format(0.0), "0.0");
    let f = AxisFormat::new((0.0, 2e-6), 6);
    assert_eq!(f.exp(), -6);
    assert!(f.describe("k [N/m]").contains("1e-6"));
    assert_eq!(AxisFormat::new((-1.0, 1.0), 5).format(-1e-12), "0.0");
}
