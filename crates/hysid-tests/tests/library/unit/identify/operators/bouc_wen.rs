//! Tests of `hysid::identify::operators::bouc_wen`.

use crate::unit::test_signals::{nested_loops, with_noise, within_three_sigma};
use hysid::identify::operators::bouc_wen::*;
use hysid::model::operators::{BoucWen, HysteresisOperator};

fn truth(kw: f64) -> BoucWen {
    let mut m = BoucWen::new(0.8, kw, 2.0, 0.5, 1.0).unwrap();
    m.w0 = 0.05;
    m
}

fn check_recovery(m: &BoucWen, options: &BoucWenOptions) {
    let u = nested_loops(1500, 1.5);
    let y = m.simulate(&u).unwrap();
    let fit = fit(&u, &y, options).unwrap();
    assert!(fit.termination.converged(), "{:?}", fit.termination);
    for (p, q) in m.parameters().iter().zip(fit.parameters.iter()) {
        assert!(
            (p.value - q.value).abs() <= 1e-4 * p.value.abs().max(1.0),
            "{}: {} vs {}",
            p.name,
            q.value,
            p.value
        );
    }
    assert!(fit.fit_percent > 99.99);
}

#[test]
fn recovers_both_orientations_without_noise() {
    check_recovery(&truth(1.2), &BoucWenOptions::default());
    check_recovery(&truth(-1.2), &BoucWenOptions::default());
}

#[test]
fn recovers_an_estimated_exponent() {
    let mut m = truth(1.2);
    m.n = 1.6;
    let options = BoucWenOptions {
        estimate_n: true,
        ..BoucWenOptions::default()
    };
    check_recovery(&m, &options);
}

#[test]
fn noisy_estimates_lie_within_three_sigma() {
    let m = truth(1.2);
    let u = nested_loops(1500, 1.5);
    let y = m.simulate(&u).unwrap();
    let (mut inside, mut total) = (0, 0);
    for seed in 0..5 {
        let fit = fit(&u, &with_noise(&y, 40.0, seed), &BoucWenOptions::default()).unwrap();
        let (i, n) = within_three_sigma(&m.parameters(), &fit.parameters, &fit.std);
        inside += i;
        total += n;
    }
    assert_eq!(total, 25);
    assert!(inside * 10 >= total * 9, "{inside}/{total}");
}

#[test]
fn inverse_follows_a_reachable_reference() {
    let m = truth(1.2);
    let r = m.simulate(&nested_loops(800, 1.5)).unwrap();
    let inv = m.invert(&r).unwrap();
    assert!(inv.clipped.is_empty());
    let y = m.simulate(&inv.u).unwrap();
    let worst = y
        .iter()
        .zip(&r)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-6, "{worst}");
}

#[test]
fn bad_records_are_errors() {
    let u = nested_loops(200, 1.0);
    let y = truth(1.0).simulate(&u).unwrap();
    let o = BoucWenOptions::default();
    assert!(fit(&u[..10], &y[..10], &o).is_err());
    let ramp: Vec<f64> = (0..100).map(f64::from).collect();
    assert!(fit(&ramp, &ramp, &o).is_err());
    let mut bad = y.clone();
    bad[3] = f64::NAN;
    assert!(fit(&u, &bad, &o).is_err());
    assert!(fit(&u, &y[1..], &o).is_err());
}
