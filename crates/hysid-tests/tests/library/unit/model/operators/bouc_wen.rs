//! Tests of `hysid::model::operators::bouc_wen`.

use hysid::model::operators::bouc_wen::*;
use hysid::model::operators::HysteresisOperator;

/// n = 1, β = γ: on an ascending branch from w = 0, dw/du = 1 − 2β·w, so
/// w(u) = (1 − e^{−2βu})/(2β).
#[test]
fn ascending_branch_has_the_closed_form() {
    let bw = BoucWen::new(0.5, 2.0, 1.5, 1.5, 1.0).unwrap();
    let y = bw.simulate(&[0.0, 0.4]).unwrap();
    let w = (1.0 - (-3.0f64 * 0.4).exp()) / 3.0;
    assert!((y[1] - (0.5 * 0.4 + 2.0 * w)).abs() < 1e-10);
}

#[test]
fn unbounded_classes_are_refused() {
    assert!(BoucWen::new(1.0, 1.0, 1.0, 2.0, 1.0).is_err());
    assert!(BoucWen::new(1.0, 1.0, 1.0, -1.0, 1.0).is_err());
    assert!(BoucWen::new(1.0, 1.0, 1.0, 0.0, 0.5).is_err());
}
