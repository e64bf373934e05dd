//! Tests of `hysid::model::saved`.

use hysid::experiments::voros::CascadeExample;
use hysid::model::coleman_hodgdon::InitialOutput;
use hysid::model::saved::*;
use hysid::model::saved::{FittedCascade, FittedHysteresis, FittedOperatorCascade};
use hysid::model::{ColemanHodgdon, LinearBlock};
use hysid::model::{OperatorCascade, OperatorModel};

#[test]
fn cascade_round_trips_through_json() {
    let truth = CascadeExample::example2().truth;
    let std: Vec<f64> = (0..truth.params().len())
        .map(|i| 0.01 * (i + 1) as f64)
        .collect();
    let fitted = FittedModel::Cascade(FittedCascade { model: truth, std });
    let json = serde_json::to_string(&fitted.to_file()).unwrap();
    assert!(
        json.contains("\"kind\":\"ch_cascade\"")
            && json.contains("\"hysteresis\":\"ch6\"")
            && json.contains("\"schema\":\"hysid.model/1\"")
    );
    let back = FittedModel::from_file(&serde_json::from_str(&json).unwrap()).unwrap();
    assert_eq!(back, fitted);
}

#[test]
fn operator_cascade_round_trips_through_json() {
    use hysid::model::operators::{Orientation, Preisach};
    let w: Vec<f64> = (0..10).map(|k| 0.05 + 0.01 * k as f64).collect();
    let op = Preisach::new(-2.0, 2.0, 4, w, 0.3, 0.1, Orientation::default()).unwrap();
    let linear = LinearBlock::new(vec![-0.5], vec![1.0, 0.3], 1).unwrap();
    let model = OperatorCascade::new(OperatorModel::Preisach(op), linear).unwrap();
    let std: Vec<f64> = (0..model.parameters().len())
        .map(|i| 0.01 * i as f64)
        .collect();
    let fitted = FittedModel::OperatorCascade(FittedOperatorCascade { model, std });
    let json = serde_json::to_string(&fitted.to_file()).unwrap();
    assert!(
        json.contains("\"kind\":\"operator_cascade\"") && json.contains("\"family\":\"preisach\"")
    );
    let back = FittedModel::from_file(&serde_json::from_str(&json).unwrap()).unwrap();
    let u: Vec<f64> = (0..300).map(|k| 2.0 * (k as f64 * 0.05).sin()).collect();
    let (a, b) = (
        fitted.simulate(&[&u], 1.0, None).unwrap(),
        back.simulate(&[&u], 1.0, None).unwrap(),
    );
    let d = a[0]
        .iter()
        .zip(&b[0])
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(d < 1e-12, "{d} {:?}", &json);
    let bad = json.replace(
        "\"name\":\"b1\",\"value\":1.0",
        "\"name\":\"b1\",\"value\":2.0",
    );
    assert!(FittedModel::from_file(&serde_json::from_str(&bad).unwrap()).is_err());
}

#[test]
fn unknown_std_is_null() {
    let model = ColemanHodgdon::saturated(0.3, 1.0, 0.5, 3.0).unwrap();
    let fitted = FittedModel::Hysteresis(FittedHysteresis {
        model,
        initial: InitialOutput::Zero,
        std: vec![f64::NAN, 0.1, 0.1, 0.1],
    });
    let json = serde_json::to_string(&fitted.to_file()).unwrap();
    assert!(json.contains("\"std\":null"), "{json}");
    let back = FittedModel::from_file(&serde_json::from_str(&json).unwrap()).unwrap();
    let FittedModel::Hysteresis(FittedHysteresis { std, .. }) = back else {
        panic!()
    };
    assert!(std[0].is_nan());
}
