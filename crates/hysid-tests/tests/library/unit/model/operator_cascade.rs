//! Tests of `hysid::model::operator_cascade`.

use hysid::model::operator_cascade::*;
use hysid::model::operators::Orientation;
use hysid::model::operators::{Backlash, BoucWen, PrandtlIshlinskii};
use hysid::model::{LinearBlock, OperatorModel};

/// Nested reversals: a decaying oscillation with a faster one on top (minor loops).
fn input(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            2.0 * (1.0 - 0.6 * t) * (23.0 * t).sin() + 0.5 * (131.0 * t).sin()
        })
        .collect()
}

fn pi() -> OperatorModel {
    OperatorModel::Pi(
        PrandtlIshlinskii::new(
            0.8,
            vec![0.5, 0.3, 0.2],
            vec![0.2, 0.5, 1.0],
            0.1,
            Orientation::default(),
        )
        .unwrap(),
    )
}

fn second_order(b: Vec<f64>) -> LinearBlock {
    LinearBlock::new(vec![-1.2, 0.5], b, 2).unwrap()
}

#[test]
fn parameters_round_trip_and_prefix_collisions() {
    let c = OperatorCascade::new(pi(), second_order(vec![1.0, 0.4])).unwrap();
    let p = c.parameters();
    assert_eq!(
        p.names(),
        [
            "op_a0", "op_a1", "op_a2", "op_a3", "op_r1", "op_r2", "op_r3", "op_c", "a1", "a2",
            "b1", "b2"
        ]
    );
    assert!(p.get(10).fixed && p.get(4).fixed && !p.get(0).fixed);
    let back = c.with_values(&p.values()).unwrap();
    assert_eq!(back, c);
    let mut bad = p.values();
    bad[10] = 2.0;
    assert!(c.with_values(&bad).is_err());
    let bl = Backlash::new(1.0, 0.3, 0.0, Orientation::default()).unwrap();
    let c = OperatorCascade::new(OperatorModel::Backlash(bl), second_order(vec![1.0])).unwrap();
    assert_eq!(c.parameters().names(), ["g", "r", "c", "a1", "a2", "b1"]);
}

#[test]
fn compensation_tracks_the_reference_pi_and_backlash() {
    let r: Vec<f64> = input(2000).iter().map(|x| 1.5 * x).collect();
    let bl = Backlash::new(1.7, 0.4, 0.2, Orientation::default()).unwrap();
    for (op, tol) in [(pi(), 1e-9), (OperatorModel::Backlash(bl), 1e-9)] {
        let c = OperatorCascade::new(op, second_order(vec![1.0, 0.4])).unwrap();
        let comp = c.compensate(&r).unwrap();
        assert!(comp.clipped.is_empty());
        let scale = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (t, (p, rt)) in comp.predicted.iter().zip(&r).enumerate().skip(2) {
            assert!(
                (p - rt).abs() <= tol * scale,
                "{} t = {t}: {p} vs {rt}",
                c.operator.family()
            );
        }
        assert_eq!(comp.predicted[..2], [0.0, 0.0]);
    }
}

#[test]
fn compensation_through_a_numerical_inverse() {
    let r: Vec<f64> = input(1500).iter().map(|x| 0.8 * x).collect();
    let bw = BoucWen::new(0.6, 0.8, 1.5, 0.5, 1.0).unwrap();
    let c = OperatorCascade::new(OperatorModel::BoucWen(bw), second_order(vec![1.0])).unwrap();
    let comp = c.compensate(&r).unwrap();
    assert!(comp.clipped.is_empty(), "{:?}", comp.clipped.len());
    for (t, (p, rt)) in comp.predicted.iter().zip(&r).enumerate().skip(2) {
        assert!((p - rt).abs() <= 1e-6, "t = {t}");
    }
}

#[test]
fn non_minimum_phase_block_is_refused() {
    let c = OperatorCascade::new(pi(), second_order(vec![1.0, 1.5])).unwrap();
    assert!((c.zero_radius() - 1.5).abs() < 1e-12);
    let e = c.compensate(&[0.0, 1.0, 2.0]).unwrap_err().to_string();
    assert!(
        e.contains("not minimum phase") && e.contains("alone"),
        "{e}"
    );
    let c = OperatorCascade::new(pi(), second_order(vec![1.0, 0.4])).unwrap();
    assert!(c.compensate(&[0.0, f64::NAN]).is_err());
    assert!(c.compensate(&[]).is_err());
}

#[test]
fn structure_survives_json_and_values_are_rechecked() {
    let c = OperatorCascade::new(pi(), second_order(vec![1.0, 0.4])).unwrap();
    let json = serde_json::to_string(&c.operator).unwrap();
    assert!(json.contains("\"family\":\"pi\""), "{json}");
    let back: OperatorModel = serde_json::from_str(&json).unwrap();
    assert_eq!(
        back.with_values(&c.operator.as_operator().parameters().values())
            .unwrap(),
        c.operator
    );
    // a negative partial weight sum is refused by the family's constructor
    let mut v = c.operator.as_operator().parameters().values();
    v[0] = -1.0;
    assert!(c.operator.with_values(&v).is_err());
}
