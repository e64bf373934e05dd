//! Tests of `hysid::identify::rls`.

use hysid::experiments::voros::CascadeExample;
use hysid::identify::rls::*;
use hysid::model::{ChForm, ColemanHodgdon};

/// a1 steps from −0.6 to −0.5 halfway through a noise-free record; RLS with λ = 0.995,
/// started from the first regime's parameters (a batch estimate), follows it.
#[test]
fn cascade_tracks_a_step_of_a1() {
    let ex = CascadeExample::example1().extended(16_000);
    let data = ex.generate(5, false).unwrap();
    let v = ex.truth.hysteresis.simulate(&data.x, 0.0).unwrap();
    let mut y = vec![0.0; v.len()];
    for t in 2..v.len() {
        let a1 = if t < 8000 { -0.6 } else { -0.5 };
        y[t] = -a1 * y[t - 1] - 0.2 * y[t - 2] + v[t - 1] + 0.5 * v[t - 2];
    }
    let track = RecursiveCascade::default()
        .run(&data.x, &y, &ex.truth)
        .unwrap();
    let a1_at = |t: usize| track.at(t).unwrap()[5];
    assert!((a1_at(7990) + 0.6).abs() < 1e-9, "before: {}", a1_at(7990));
    assert!(
        (a1_at(10_000) + 0.5).abs() < 0.01,
        "2000 samples after: {}",
        a1_at(10_000)
    );
    let mut truth = ex.truth.params();
    truth[5] = -0.5;
    for (got, want) in track.params.last().unwrap().iter().zip(&truth) {
        assert!((got - want).abs() < 1e-6 * want.abs(), "{got} vs {want}");
    }
}

/// α steps from 0.4 to 0.3 halfway through a measured hysteresis record; the separated
/// regression's RLS follows it from a start 20 % off.
#[test]
fn hysteresis_tracks_a_step_of_alpha() {
    let ex = CascadeExample::example2().extended(20_000);
    let x = ex.generate(2, false).unwrap().x;
    let before = ColemanHodgdon::general(0.4, 1.2, 0.15, 0.6, 0.1, 2.0).unwrap();
    let after = ColemanHodgdon::general(0.3, 1.2, 0.15, 0.6, 0.1, 2.0).unwrap();
    let mut y = vec![0.0; x.len()];
    for t in 1..x.len() {
        let h = if t < 10_000 { &before } else { &after };
        y[t] = h.step(y[t - 1], x[t - 1], x[t]);
    }
    let start: Vec<f64> = before.params().iter().map(|p| p * 1.2).collect();
    let initial = ColemanHodgdon::from_params(ChForm::General6, &start).unwrap();
    let track = RecursiveHysteresis::default()
        .run(&x, &y, &initial)
        .unwrap();
    let alpha_at = |t: usize| track.at(t).unwrap()[0];
    assert!(
        (alpha_at(9_990) - 0.4).abs() < 1e-4,
        "before: {}",
        alpha_at(9_990)
    );
    assert!(
        (alpha_at(13_000) - 0.3).abs() < 5e-3,
        "3000 samples after: {}",
        alpha_at(13_000)
    );
    for (got, want) in track.params.last().unwrap().iter().zip(after.params()) {
        assert!((got - want).abs() < 1e-5 * want.abs(), "{got} vs {want}");
    }
}
