//! Tests of `hysid::identify::bootstrap`.

use hysid::data::IdData;
use hysid::identify::bootstrap::*;
use hysid::Result;

/// With a linear model the bootstrap spread matches the known standard deviation of the
/// mean, σ/√N.
#[test]
fn spread_of_a_mean_estimate() {
    let n = 400;
    let data = IdData::siso(1.0, "u", vec![0.0; n], "y", vec![1.0; n]).unwrap();
    let simulated = vec![vec![vec![1.0; n]]];
    let refit = |d: &IdData| -> Result<Vec<f64>> {
        let y = d.experiment(0).output(0);
        Ok(vec![y.iter().sum::<f64>() / y.len() as f64])
    };
    let b = parametric_bootstrap(&data, &simulated, &[2.0], 400, 7, &refit).unwrap();
    let expected = 2.0 / (n as f64).sqrt();
    assert!(
        (b.std[0] / expected - 1.0).abs() < 0.12,
        "{} vs {expected}",
        b.std[0]
    );
    assert_eq!(b.failed, 0);
}
