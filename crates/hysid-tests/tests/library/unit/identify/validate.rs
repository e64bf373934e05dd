//! Tests of `hysid::identify::validate`.

use hysid::data::IdData;
use hysid::identify::validate::*;
use hysid::numerics::signal::gaussian_noise;

#[test]
fn white_residuals_stay_inside_the_band() {
    let n = 5000;
    let u = gaussian_noise(n, 1.0, 1).unwrap();
    let noise = gaussian_noise(n, 0.1, 2).unwrap();
    let data = IdData::siso(1.0, "u", u, "y", noise.clone()).unwrap();
    let a = residual_analysis(&data, 0, 0, &vec![0.0; n], 25);
    assert_eq!(a.autocorrelation[0], 1.0);
    assert!(a.auto_outside <= 2 && a.cross_outside[0] <= 2, "{a:?}");
    // A residual that is the input delayed by 3 shows up at τ = 3 of the cross-correlation.
    let u = data.experiment(0).input(0).to_vec();
    let delayed: Vec<f64> = (0..n)
        .map(|t| if t >= 3 { u[t - 3] } else { 0.0 })
        .collect();
    let data = IdData::siso(1.0, "u", u, "y", delayed).unwrap();
    let a = residual_analysis(&data, 0, 0, &vec![0.0; n], 10);
    let peak = a.cross_correlation[0]
        .iter()
        .enumerate()
        .max_by(|x, y| x.1.total_cmp(y.1))
        .unwrap()
        .0;
    assert_eq!(peak as i64 - 10, 3);
}
