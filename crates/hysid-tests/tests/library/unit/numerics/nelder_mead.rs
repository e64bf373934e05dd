//! Tests of `hysid::numerics::nelder_mead`.

use hysid::numerics::nelder_mead::*;

#[test]
fn finds_the_rosenbrock_minimum() {
    let rosen = |x: &[f64]| (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2);
    let (x, fx) = nelder_mead(rosen, &[-1.2, 1.0], &[0.5, 0.5], 2000, 1e-15);
    assert!(
        (x[0] - 1.0).abs() < 1e-4 && (x[1] - 1.0).abs() < 1e-4,
        "{x:?} {fx}"
    );
}
