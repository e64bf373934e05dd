//! Tests of `hysid::model::compensate`.

use hysid::model::coleman_hodgdon::InitialOutput;
use hysid::model::compensate::*;
use hysid::model::operators::{OperatorModel, Orientation, PrandtlIshlinskii};
use hysid::model::saved::FittedModel;
use hysid::model::saved::{FittedCascade, FittedHysteresis};
use hysid::model::ColemanHodgdon;
use hysid::Error;

fn reference(n: usize, amplitude: f64) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            amplitude * (1.0 - 0.5 * t) * (2.0 * std::f64::consts::PI * 3.0 * t).sin()
        })
        .collect()
}

#[test]
fn pi_compensation_tracks_to_1e9() {
    let pi = PrandtlIshlinskii::new(
        0.6,
        vec![0.3, 0.2, 0.1],
        vec![0.1, 0.2, 0.3],
        0.0,
        Orientation::default(),
    )
    .unwrap();
    let model = FittedModel::operator(OperatorModel::Pi(pi), vec![f64::NAN; 7]);
    let c = compensate(&model, &reference(500, 1.0)).unwrap();
    let (rms, max) = c.tracking_error();
    assert!(c.clipped.is_empty() && max < 1e-9, "rms {rms} max {max}");
    let y = model.simulate(&[&c.u], 1.0, None).unwrap();
    assert_eq!(y[0], c.predicted);
}

#[test]
fn coleman_hodgdon_compensation_and_clipping() {
    let ch = ColemanHodgdon::saturated(0.5, 1.0, 0.3, 3.0).unwrap();
    let model = FittedModel::Hysteresis(FittedHysteresis {
        model: ch,
        initial: InitialOutput::Measured,
        std: vec![f64::NAN; 4],
    });
    let r = reference(800, 1.5);
    let c = compensate(&model, &r).unwrap();
    let (_, max) = c.tracking_error();
    assert!(c.clipped.is_empty() && max < 1e-6, "max {max}");
    let y = model.simulate(&[&c.u], 1.0, Some(r[0])).unwrap();
    assert_eq!(y[0], c.predicted);
    // Beyond the saturated material function's range (|f| ≤ m1·d = 3) the reference is
    // clipped, counted and listed as ranges.
    let far: Vec<f64> = r.iter().map(|v| 5.0 * v).collect();
    let c = compensate(&model, &far).unwrap();
    assert!(!c.clipped.is_empty());
    assert!(!c.clipped_ranges().is_empty());
}

#[test]
fn a_cascade_is_not_invertible() {
    let truth = hysid::experiments::voros::CascadeExample::example2().truth;
    let std = vec![f64::NAN; truth.params().len()];
    let model = FittedModel::Cascade(FittedCascade { model: truth, std });
    let e = compensate(&model, &[0.0, 1.0]).unwrap_err();
    assert!(matches!(e, Error::NotInvertible { .. }));
    assert!(e
        .to_string()
        .starts_with("not invertible: model kind 'ch_cascade'"));
}
