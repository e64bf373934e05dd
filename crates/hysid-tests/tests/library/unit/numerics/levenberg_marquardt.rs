//! Tests of `hysid::numerics::levenberg_marquardt`.

use hysid::numerics::levenberg_marquardt::*;
use hysid::numerics::Termination;
use hysid::{Error, Result};

/// Exponential decay y = a·exp(−b t) sampled at 30 points.
struct Decay {
    t: Vec<f64>,
    y: Vec<f64>,
}

impl LeastSquaresProblem for Decay {
    fn n_params(&self) -> usize {
        2
    }
    fn n_residuals(&self) -> usize {
        self.t.len()
    }
    fn residuals(&self, p: &[f64], r: &mut [f64]) -> Result<()> {
        if p[1] < -5.0 {
            return Err(Error::Diverged {
                index: 0,
                reason: "test".into(),
            });
        }
        for ((ri, t), y) in r.iter_mut().zip(&self.t).zip(&self.y) {
            *ri = y - p[0] * (-p[1] * t).exp();
        }
        Ok(())
    }
}

fn decay() -> Decay {
    let t: Vec<f64> = (0..30).map(|k| k as f64 * 0.1).collect();
    let y = t.iter().map(|t| 2.5 * (-1.3 * t).exp()).collect();
    Decay { t, y }
}

/// Fits the decay from `start` with free parameters `free` inside [lo, hi].
fn fit(start: [f64; 2], free: &[usize], lo: [f64; 2], hi: [f64; 2], control: Control) -> LmReport {
    minimize(
        &decay(),
        &start,
        free,
        &lo,
        &hi,
        &LmConfig::default(),
        &mut |_| control,
    )
    .unwrap()
}

const INF: f64 = f64::INFINITY;

#[test]
fn recovers_exact_parameters_from_far_start() {
    let report = fit([0.5, 4.0], &[0, 1], [-INF; 2], [INF; 2], Control::Continue);
    assert!((report.theta[0] - 2.5).abs() < 1e-9, "{:?}", report);
    assert!((report.theta[1] - 1.3).abs() < 1e-9);
}

#[test]
fn respects_bounds_and_fixed_parameters() {
    let report = fit(
        [1.0, 1.0],
        &[0, 1],
        [0.0, 0.0],
        [2.0, 10.0],
        Control::Continue,
    );
    assert_eq!(report.theta[0], 2.0);
    let fixed = fit(
        [2.5, 1.0],
        &[1],
        [0.0, 0.0],
        [10.0, 10.0],
        Control::Continue,
    );
    assert_eq!(fixed.theta[0], 2.5);
    assert!((fixed.theta[1] - 1.3).abs() < 1e-9);
    assert_eq!(fixed.covariance().std[0], 0.0);
}

#[test]
fn callback_can_stop() {
    let report = fit([0.5, 4.0], &[0, 1], [-INF; 2], [INF; 2], Control::Stop);
    assert_eq!(report.termination, Termination::Stopped);
    assert_eq!(report.iterations, 1);
}

/// A trial point where the model cannot be simulated is rejected, not fatal: the decay
/// refuses b < −5, and a start near that wall still converges.
#[test]
fn diverging_trials_are_rejected() {
    let report = fit([8.0, -4.9], &[0, 1], [-INF; 2], [INF; 2], Control::Continue);
    assert!(
        report.rejected_trials > 0,
        "no trial was rejected: {report:?}"
    );
    assert!((report.theta[1] - 1.3).abs() < 1e-9, "{report:?}");
}

#[test]
fn a_model_that_cannot_start_is_an_error() {
    let err = minimize(
        &decay(),
        &[1.0, -6.0],
        &[0, 1],
        &[-INF; 2],
        &[INF; 2],
        &LmConfig::default(),
        &mut |_| Control::Continue,
    );
    assert!(err.is_err());
}
