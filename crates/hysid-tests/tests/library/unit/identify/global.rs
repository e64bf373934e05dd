//! Tests of `hysid::identify::global`.

use hysid::identify::global::*;
use hysid::model::{ChForm, ColemanHodgdon, HysteresisCascade, LinearBlock};

#[test]
fn basis_signals_reproduce_the_hysteresis() {
    let ch = ColemanHodgdon::general(0.4, 1.2, 0.15, 0.6, 0.1, 2.0).unwrap();
    let x: Vec<f64> = (0..300).map(|t| 3.5 * (t as f64 * 0.07).sin()).collect();
    let v = ch.simulate(&x, 0.0).unwrap();
    let psi = basis_signals(ChForm::General6, &x, 0.4, 2.0);
    for t in 0..x.len() {
        let combo = 1.2 * psi[0][t] + 0.15 * psi[1][t] + 0.6 * psi[2][t] + 0.1 * psi[3][t];
        assert!((combo - v[t]).abs() < 1e-12);
    }
}

#[test]
fn exact_at_the_true_grid_point() {
    let ch = ColemanHodgdon::saturated(0.3, 1.0, 0.5, 3.0).unwrap();
    let lin = LinearBlock::new(vec![-0.6, 0.2], vec![1.0, 0.5], 1).unwrap();
    let truth = HysteresisCascade::new(ch, lin).unwrap();
    let x: Vec<f64> = (0..2000)
        .map(|t| 5.0 * (t as f64 * 0.05).sin() * (1.0 + 0.3 * (t as f64 * 0.003).cos()))
        .collect();
    let y = truth.simulate(&x).unwrap().y;
    let search = GlobalSearch::new(ChForm::Saturated4, 2, 2, 1);
    let c = search.evaluate(&x, &y, 0.3, 3.0).unwrap();
    for (a, b) in c.cascade.params().iter().zip(truth.params()) {
        assert!((a - b).abs() < 1e-8 * b.abs().max(1.0), "{a} vs {b}");
    }
    assert!(c.output_cost < 1e-16);
}
