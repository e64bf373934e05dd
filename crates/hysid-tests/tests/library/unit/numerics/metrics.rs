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

/// The one-pass fit % and MSE are the separate functions' values bit for bit, and the sums
/// follow the documented order (lanes i mod 8, added pairwise), for every length of tail.
#[test]
fn one_pass_figures_equal_the_separate_ones() {
    for n in [1usize, 2, 7, 8, 9, 15, 16, 17, 1001] {
        let y: Vec<f64> = (0..n)
            .map(|i| ((i * 7919) % 113) as f64 * 0.37 - 9.0)
            .collect();
        let yhat: Vec<f64> = y
            .iter()
            .enumerate()
            .map(|(i, v)| v + ((i % 5) as f64 - 2.0) * 0.1)
            .collect();
        let (fit, mse_value) = fit_percent_and_mse(&y, &yhat);
        assert_eq!(fit.to_bits(), fit_percent(&y, &yhat).to_bits(), "n {n}");
        assert_eq!(mse_value.to_bits(), mse(&y, &yhat).to_bits(), "n {n}");
        let mut lanes = [0.0; 8];
        for i in 0..n {
            lanes[i % 8] += (y[i] - yhat[i]).powi(2);
        }
        let sum = ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3]))
            + ((lanes[4] + lanes[5]) + (lanes[6] + lanes[7]));
        assert_eq!(
            mse(&y, &yhat).to_bits(),
            (sum / n as f64).to_bits(),
            "n {n}"
        );
    }
}
