//! Tests of `hysid::identify::operators::dahl`.

use hysid::identify::operators::dahl::*;
use hysid::model::operators::{Dahl, HysteresisOperator, LoopOrientation};

fn truth(orientation: LoopOrientation) -> Dahl {
    let mut m = Dahl::new(12.0, 2.0, 1.8).unwrap();
    m.f0 = 0.3;
    m.orientation = orientation;
    m
}

fn check_recovery(m: &Dahl) {
    let u = nested_loops(1500, 1.0);
    let y = m.simulate(&u).unwrap();
    let fit = fit(&u, &y, &DahlOptions::default()).unwrap();
    assert!(fit.termination.converged(), "{:?}", fit.termination);
    assert_eq!(fit.model.orientation, m.orientation);
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

use crate::unit::test_signals::{nested_loops, with_noise, within_three_sigma};

#[test]
fn recovers_both_orientations_without_noise() {
    check_recovery(&truth(LoopOrientation::CounterClockwise));
    check_recovery(&truth(LoopOrientation::Clockwise));
}

#[test]
fn noisy_estimates_lie_within_three_sigma() {
    let m = truth(LoopOrientation::CounterClockwise);
    let u = nested_loops(1500, 1.0);
    let y = m.simulate(&u).unwrap();
    let (mut inside, mut total) = (0, 0);
    for seed in 20..25 {
        let fit = fit(&u, &with_noise(&y, 40.0, seed), &DahlOptions::default()).unwrap();
        let (i, n) = within_three_sigma(&m.parameters(), &fit.parameters, &fit.std);
        inside += i;
        total += n;
    }
    assert_eq!(total, 20);
    assert!(inside * 10 >= total * 9, "{inside}/{total}");
}

#[test]
fn inverse_follows_a_reachable_reference_and_clips_beyond_fc() {
    for o in [
        LoopOrientation::CounterClockwise,
        LoopOrientation::Clockwise,
    ] {
        let m = truth(o);
        let r = m.simulate(&nested_loops(800, 1.0)).unwrap();
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
    // |F| < F_c = 2: the samples asking for 2.5 are clipped and listed.
    let inv = truth(LoopOrientation::CounterClockwise)
        .invert(&[0.3, 1.0, 2.5, 2.5, 0.0])
        .unwrap();
    assert_eq!(inv.clipped, vec![2, 3]);
    assert!((inv.predicted[4] - 0.0).abs() < 1e-9);
}
