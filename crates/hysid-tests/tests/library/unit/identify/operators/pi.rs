//! Tests of `hysid::identify::operators::pi`.

use hysid::identify::operators::linear_support::threshold_grid;
use hysid::identify::operators::pi::*;
use hysid::model::operators::HysteresisOperator;
use hysid::model::operators::{Orientation, PrandtlIshlinskii};
use hysid::numerics::metrics;
use rand::rngs::Xoshiro256PlusPlus;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

/// A decaying oscillation with nested minor loops.
pub(crate) fn input(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            2.0 + 3.0 * (1.0 - 0.8 * t) * (37.0 * t).sin() + 0.6 * (151.0 * t).sin()
        })
        .collect()
}

fn truth(u: &[f64], o: Orientation) -> PrandtlIshlinskii {
    let grid = threshold_grid(u, 6).unwrap();
    PrandtlIshlinskii::new(0.9, vec![0.5, 0.0, 0.3, 0.25, 0.0, 0.1], grid, 0.4, o).unwrap()
}

#[test]
fn recovers_weights_both_orientations() {
    let u = input(4000);
    for o in [Orientation::COUNTER_CLOCKWISE, Orientation::CLOCKWISE] {
        let t = truth(&u, o);
        let y = t.simulate(&u).unwrap();
        let opts = PiOptions {
            grid: Some(t.thresholds().to_vec()),
            ..PiOptions::default()
        };
        let f = fit(&u, &y, &opts).unwrap();
        assert_eq!(f.model.orientation(), o);
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1.0);
        assert!(
            rel(f.model.a0(), t.a0()) < 1e-6,
            "{o:?} a0 {}",
            f.model.a0()
        );
        for (a, b) in f.model.weights().iter().zip(t.weights()) {
            assert!(rel(*a, *b) < 1e-6, "{o:?} {a} vs {b}");
        }
        assert!(rel(f.model.offset(), t.offset()) < 1e-6);
        assert!(f.fit_percent > 99.9999, "{}", f.fit_percent);
        // thresholds are fixed: no σ
        assert!(f.std[7..13].iter().all(Option::is_none) && f.std[0].is_some());
    }
}

#[test]
fn default_grid_recovers_its_own_model() {
    let u = input(3000);
    let grid = threshold_grid(&u, 10).unwrap();
    let t = PrandtlIshlinskii::new(
        0.5,
        (0..10).map(|i| 0.1 + 0.05 * i as f64).collect(),
        grid,
        -1.0,
        Orientation::default(),
    )
    .unwrap();
    let y = t.simulate(&u).unwrap();
    let f = fit(&u, &y, &PiOptions::default()).unwrap();
    for (a, b) in f.model.weights().iter().zip(t.weights()) {
        assert!((a - b).abs() < 1e-6 * b, "{a} vs {b}");
    }
    assert_eq!(f.termination, hysid::numerics::Termination::ZeroResidual);
    let sel = fit(
        &u,
        &y,
        &PiOptions {
            select: Some(vec![3, 10, 20]),
            ..PiOptions::default()
        },
    )
    .unwrap();
    assert_eq!(sel.model.weights().len(), 10);
}

#[test]
fn noisy_weights_within_three_sigma() {
    let u = input(4000);
    let t = truth(&u, Orientation::COUNTER_CLOCKWISE);
    let clean = t.simulate(&u).unwrap();
    let noise_std = metrics::std_dev(&clean) / 100.0; // SNR 40 dB
    let (mut inside, mut total) = (0, 0);
    for seed in 0..8u64 {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let normal = Normal::new(0.0, noise_std).unwrap();
        let y: Vec<f64> = clean.iter().map(|v| v + normal.sample(&mut rng)).collect();
        let opts = PiOptions {
            grid: Some(t.thresholds().to_vec()),
            orientation: Some(Orientation::COUNTER_CLOCKWISE),
            ..PiOptions::default()
        };
        let f = fit(&u, &y, &opts).unwrap();
        let truth_values = [t.a0()].into_iter().chain(t.weights().iter().copied());
        for (i, tv) in truth_values.enumerate() {
            let est = f.parameters.get(i).value;
            // a weight at the bound (no σ) counts as inside when it is within noise of 0
            let ok = match f.std[i] {
                Some(s) => (est - tv).abs() <= 3.0 * s,
                None => tv.abs() <= 3.0 * noise_std,
            };
            inside += ok as usize;
            total += 1;
        }
    }
    assert!(inside * 10 >= total * 9, "{inside}/{total}");
}

#[test]
fn bad_data_are_refused() {
    let u = input(500);
    let y = u.clone();
    let o = PiOptions::default();
    assert!(fit(&u[..5], &y[..5], &o).is_err());
    let mut bad = y.clone();
    bad[7] = f64::NAN;
    assert!(fit(&u, &bad, &o)
        .unwrap_err()
        .to_string()
        .contains("sample 7"));
    let ramp: Vec<f64> = (0..500).map(|k| k as f64).collect();
    assert!(fit(&ramp, &ramp, &o)
        .unwrap_err()
        .to_string()
        .contains("reversal"));
    let grid = PiOptions {
        grid: Some(vec![0.5, 0.2]),
        ..o.clone()
    };
    assert!(fit(&u, &y, &grid)
        .unwrap_err()
        .to_string()
        .contains("increasing"));
    assert!(fit(&u, &y[..400], &o).is_err());
}

/// A Preisach plant a PI operator can only approximate: its density depends on the centre
/// (α + β)/2 of a relay as well as on its half-width (α − β)/2 (a density of the half-width
/// alone would be a PI operator, Brokate & Sprekels 1996), so its loops are asymmetric and
/// its minor loops not congruent. 20 levels over [−1.6, 1.6], driven by the 20 000-sample
/// records of the differential tests (amplitude 1.5), 40 dB output noise.
fn preisach_records() -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    use crate::unit::test_signals::{training_input, validation_input, with_noise};
    use hysid::model::operators::Preisach;
    let (lower, upper, n) = (-1.6, 1.6, 20);
    let h = (upper - lower) / n as f64;
    let mut w = Vec::new();
    // Cells (i, j), j ≤ i: switching-up threshold α at level i, switching-down β at level j.
    for i in 0..n {
        for j in 0..=i {
            let (alpha, beta) = (lower + (i as f64 + 0.5) * h, lower + (j as f64 + 0.5) * h);
            let (centre, half) = ((alpha + beta) / 2.0, (alpha - beta) / 2.0);
            w.push(0.08 * (-((centre - 0.2) / 0.8).powi(2) - (half / 0.6).powi(2)).exp());
        }
    }
    let plant =
        Preisach::new(lower, upper, n, w, 0.2, 0.0, Orientation::COUNTER_CLOCKWISE).unwrap();
    let u = training_input(20_000, 1.5);
    let v = validation_input(20_000, 1.5);
    let y = with_noise(&plant.simulate(&u).unwrap(), 40.0, 7);
    let yv = with_noise(&plant.simulate(&v).unwrap(), 40.0, 107);
    (u, y, v, yv)
}

/// The best validation fit % of a PI operator on [`preisach_records`]: that of the lowest
/// training criterion, the NNLS fit on a dense grid of 400 thresholds (the family's
/// continuum limit: any threshold placement is within a 400th of the range of one of the
/// grid's), found by `dense_pi_on_a_preisach_loop` below (run once with
/// `-- --ignored --nocapture`; it printed 85.7555 % at the training fit 83.3212 %; 10, 20,
/// 40 and 100 thresholds gave 85.7020, 85.8345, 85.8695 and 85.7660 %).
const PREISACH_LOOP_BEST_PI: f64 = 85.7555;

#[test]
fn pi_reaches_its_best_on_a_preisach_loop() {
    let (u, y, v, yv) = preisach_records();
    let fit = fit(&u, &y, &PiOptions::default()).unwrap();
    let got = metrics::fit_percent(&yv, &fit.model.simulate(&v).unwrap());
    assert!(
        got >= PREISACH_LOOP_BEST_PI - 0.1,
        "validation fit {got:.4} % vs the family's best {PREISACH_LOOP_BEST_PI:.4} %"
    );
}

#[test]
#[ignore = "the one-off dense search behind PREISACH_LOOP_BEST_PI"]
fn dense_pi_on_a_preisach_loop() {
    let (u, y, v, yv) = preisach_records();
    for thresholds in [10, 20, 40, 100, 400] {
        let options = PiOptions {
            thresholds,
            ..PiOptions::default()
        };
        let fit = fit(&u, &y, &options).unwrap();
        let got = metrics::fit_percent(&yv, &fit.model.simulate(&v).unwrap());
        eprintln!(
            "PI with {thresholds} thresholds: validation fit {got:.4} % (training {:.4} %)",
            fit.fit_percent
        );
    }
}
