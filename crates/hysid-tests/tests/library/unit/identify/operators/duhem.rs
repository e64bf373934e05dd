//! Tests of `hysid::identify::operators::duhem`.

use crate::unit::test_signals::{nested_loops, with_noise, within_three_sigma};
use hysid::identify::operators::duhem::*;
use hysid::model::operators::{Duhem, HysteresisOperator};

fn truth(c: f64) -> Duhem {
    let mut m = Duhem::new(3.0, 1.5, 0.2, c).unwrap();
    m.y0 = -0.1;
    m
}

fn check_recovery(m: &Duhem) {
    let u = nested_loops(1500, 1.5);
    let y = m.simulate(&u).unwrap();
    let fit = fit(&u, &y, &DuhemOptions::default()).unwrap();
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
}

#[test]
fn recovers_both_orientations_without_noise() {
    check_recovery(&truth(0.4)); // c < a: counter-clockwise
    check_recovery(&truth(2.6)); // c > a: clockwise
}

#[test]
fn noisy_estimates_lie_within_three_sigma() {
    let m = truth(0.4);
    let u = nested_loops(1500, 1.5);
    let y = m.simulate(&u).unwrap();
    let (mut inside, mut total) = (0, 0);
    for seed in 10..15 {
        let fit = fit(&u, &with_noise(&y, 40.0, seed), &DuhemOptions::default()).unwrap();
        let (i, n) = within_three_sigma(&m.parameters(), &fit.parameters, &fit.std);
        inside += i;
        total += n;
    }
    assert_eq!(total, 25);
    assert!(inside * 10 >= total * 9, "{inside}/{total}");
}

#[test]
#[ignore = "long (several seconds): run by `cargo test --release -- --ignored` and CI"]
fn inverse_follows_a_reachable_reference() {
    for m in [truth(0.4), truth(2.6)] {
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
}

#[test]
fn too_few_reversals_is_an_error() {
    // A monotone input: one branch only, no loop.
    let u: Vec<f64> = (0..30).map(|k| (k as f64 * 0.05).sin()).collect();
    let y = truth(0.4).simulate(&u).unwrap();
    assert!(fit(&u, &y, &DuhemOptions::default()).is_err());
}
