//! Tests of `hysid::identify::switching`.

use hysid::identify::switching::*;

#[test]
fn truncated_normal_limits() {
    // Wide normal over a narrow interval: uniform, mean the midpoint, std width/√12.
    let (m, s) = truncated_normal(1.0, 100.0, 1.0, 1.2);
    assert!(
        (m - 1.1).abs() < 1e-4 && (s - 0.2 / 12f64.sqrt()).abs() < 1e-4,
        "{m} {s}"
    );
    // Narrow normal inside a wide interval: untouched.
    let (m, s) = truncated_normal(1.0, 1e-3, 0.0, 2.0);
    assert!((m - 1.0).abs() < 1e-12 && (s - 1e-3).abs() < 1e-9);
    // Half-infinite interval: the half-normal mean s·√(2/π).
    let (m, _) = truncated_normal(0.0, 1.0, 0.0, f64::INFINITY);
    assert!((m - (2.0 / std::f64::consts::PI).sqrt()).abs() < 1e-6);
    assert!((normal_cdf(1.0) - 0.841_344_746).abs() < 1e-7);
}
