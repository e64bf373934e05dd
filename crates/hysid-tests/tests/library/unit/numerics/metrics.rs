//! Tests of `hysid::numerics::metrics`.

use hysid::numerics::metrics::*;

#[test]
fn fit_and_rmse_on_known_values() {
    let y = [0.0, 2.0, 4.0];
    let yhat = [0.0, 2.0, 5.0];
    // ‖e‖ = 1, ‖y − ȳ‖ = sqrt(8)
    assert!((fit_percent(&y, &yhat) - 100.0 * (1.0 - 1.0 / 8f64.sqrt())).abs() < 1e-12);
    assert!((rmse(&y, &yhat) - (1.0f64 / 3.0).sqrt()).abs() < 1e-12);
    assert!((fpe(2.0, 100, 10) - 2.0 * 1.1 / 0.9).abs() < 1e-12);
}
