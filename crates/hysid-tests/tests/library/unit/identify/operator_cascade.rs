//! Tests of `hysid::identify::operator_cascade`.

use hysid::data::IdData;
use hysid::identify::operator_cascade::*;
use hysid::identify::operators::linear_support::threshold_grid;
use hysid::identify::operators::{Family, FamilyOptions};
use hysid::model::operators::BoucWen;
use hysid::model::operators::{Backlash, Orientation, PrandtlIshlinskii};
use hysid::model::{LinearBlock, OperatorCascade, OperatorModel};
use hysid::numerics::metrics;
use hysid::numerics::Control;
use rand::rngs::Xoshiro256PlusPlus;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

/// A decaying oscillation with a faster one on top: nested reversals (minor loops).
fn input(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            3.0 * (1.0 - 0.7 * t) * (29.0 * t).sin() + 0.8 * (113.0 * t).sin()
        })
        .collect()
}

/// Second-order block y(t) = 1.2 y(t−1) − 0.5 y(t−2) + v(t−1) + 0.4 v(t−2).
fn block() -> LinearBlock {
    LinearBlock::new(vec![-1.2, 0.5], vec![1.0, 0.4], 1).unwrap()
}

fn data(u: &[f64], y: Vec<f64>) -> IdData {
    IdData::siso(1.0, "u", u.to_vec(), "y", y).unwrap()
}

fn fit(family: Family, thresholds: usize, d: &IdData) -> OperatorCascadeFit {
    let mut id = OperatorCascadeIdentification::new(family, 2, 2, 1);
    id.options = FamilyOptions {
        thresholds,
        ..FamilyOptions::default()
    };
    id.estimate(d, &mut |_| Control::Continue).unwrap()
}

fn backlash_truth() -> OperatorCascade {
    let op = Backlash::new(1.7, 0.437, -0.3, Orientation::default()).unwrap();
    OperatorCascade::new(OperatorModel::Backlash(op), block()).unwrap()
}

fn assert_relative(est: &[f64], truth: &[f64], tol: f64) {
    for (i, (e, t)) in est.iter().zip(truth).enumerate() {
        assert!(
            (e - t).abs() <= tol * t.abs().max(1e-3),
            "parameter {i}: {e} vs {t}"
        );
    }
}

#[test]
fn backlash_cascade_is_recovered_without_noise() {
    let u = input(3000);
    let truth = backlash_truth();
    let y = truth.simulate(&u).unwrap().y;
    let f = fit(Family::Backlash, 10, &data(&u, y));
    assert_eq!(
        f.initialisation,
        "equation-error least squares, rank-one factorisation"
    );
    assert_relative(
        &f.output_error.parameters.values(),
        &truth.parameters().values(),
        1e-6,
    );
    assert!(f.fit_percent > 99.9999, "{}", f.fit_percent);
}

#[test]
fn backlash_cascade_within_three_sigma_at_40_db() {
    let u = input(3000);
    let truth = backlash_truth();
    let clean = truth.simulate(&u).unwrap().y;
    let sd = metrics::std_dev(&clean) / 100.0; // SNR 40 dB
    let tv = truth.parameters().values();
    let (mut inside, mut total) = (0, 0);
    for seed in 0..4u64 {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(40 + seed);
        let normal = Normal::new(0.0, sd).unwrap();
        let y: Vec<f64> = clean.iter().map(|v| v + normal.sample(&mut rng)).collect();
        let f = fit(Family::Backlash, 10, &data(&u, y));
        for (i, s) in f.std.iter().enumerate() {
            if let Some(s) = s {
                let e = f.output_error.parameters.get(i).value;
                inside += ((e - tv[i]).abs() <= 3.0 * s) as usize;
                total += 1;
            }
        }
    }
    // 5 free parameters (g, r, c, a1, a2, b2 = 6) per seed; 3σ holds for ≥ 90 %
    assert!(total == 24 && inside * 10 >= total * 9, "{inside}/{total}");
}

#[test]
fn pi_cascade_is_recovered_without_noise() {
    let u = input(3000);
    let grid = threshold_grid(&u, 6).unwrap();
    let op = PrandtlIshlinskii::new(
        0.9,
        vec![0.5, 0.0, 0.3, 0.25, 0.1, 0.2],
        grid,
        0.4,
        Orientation::default(),
    )
    .unwrap();
    let truth = OperatorCascade::new(OperatorModel::Pi(op), block()).unwrap();
    let y = truth.simulate(&u).unwrap().y;
    let f = fit(Family::Pi, 6, &data(&u, y));
    let (est, tv) = (
        f.output_error.parameters.values(),
        truth.parameters().values(),
    );
    for (i, (e, t)) in est.iter().zip(&tv).enumerate() {
        assert!((e - t).abs() <= 1e-6 * t.abs().max(1.0), "{i}: {e} vs {t}");
    }
    // a decreasing trend is found as the decreasing orientation
    let y: Vec<f64> = truth.simulate(&u).unwrap().y.iter().map(|v| -v).collect();
    let f = fit(Family::Pi, 6, &data(&u, y));
    let OperatorModel::Pi(pi) = &f.model.operator else {
        panic!()
    };
    assert!(pi.orientation().decreasing);
    assert!((pi.a0() - 0.9).abs() < 1e-6 && f.fit_percent > 99.9999);
}

#[test]
fn bouc_wen_cascade_starts_from_its_family_fit() {
    let u = input(1500);
    let op = BoucWen::new(0.6, 0.8, 1.5, 0.5, 1.0).unwrap();
    let truth = OperatorCascade::new(OperatorModel::BoucWen(op), block()).unwrap();
    let y = truth.simulate(&u).unwrap().y;
    let f = fit(Family::BoucWen, 10, &data(&u, y));
    assert_eq!(f.initialisation, "family fit and ARX");
    assert!(f.fit_percent > 99.99, "{}", f.fit_percent);
}

#[test]
fn bad_settings_are_refused() {
    let u = input(200);
    let y = backlash_truth().simulate(&u).unwrap().y;
    let d = data(&u, y);
    let id = OperatorCascadeIdentification::new(Family::Pi, 2, 0, 1);
    assert!(id.estimate(&d, &mut |_| Control::Continue).is_err());
    let short = data(&u[..20], u[..20].to_vec());
    let id = OperatorCascadeIdentification::new(Family::Pi, 2, 2, 1);
    assert!(id.estimate(&short, &mut |_| Control::Continue).is_err());
    let flat = data(&vec![1.0; 200], (0..200).map(|k| k as f64).collect());
    assert!(id.estimate(&flat, &mut |_| Control::Continue).is_err());
}

#[test]
fn a_misfitting_family_still_starts_from_a_stable_block() {
    // Bouc–Wen fitted to a PI cascade: the ARX start on Γ₀[u] may be unstable; it is pulled
    // inside the unit circle so that output error can start.
    let u = input(1500);
    let grid = threshold_grid(&u, 4).unwrap();
    let op = PrandtlIshlinskii::new(
        0.9,
        vec![0.5, 0.3, 0.25, 0.2],
        grid,
        0.4,
        Orientation::default(),
    )
    .unwrap();
    let truth = OperatorCascade::new(OperatorModel::Pi(op), block()).unwrap();
    let y = truth.simulate(&u).unwrap().y;
    let f = fit(Family::BoucWen, 10, &data(&u, y));
    assert!(f.start.linear.spectral_radius() < 0.99);
    assert!(f.fit_percent > 90.0, "{}", f.fit_percent);
}
