//! Tests of `hysid::identify::operators::kp`.

use crate::unit::test_signals::piezo_record;
use hysid::identify::operators::kp::*;
use hysid::identify::operators::preisach::{self, PreisachOptions};
use hysid::model::operators::{HysteresisOperator, Kp, Orientation};
use hysid::numerics::metrics;
use hysid::numerics::Termination;
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Normal};

/// A decaying oscillation with nested reversals: reversal points all over the range.
fn input(n: usize, f1: f64, f2: f64) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            (1.0 - 0.9 * t) * (f1 * t).sin() * 1.95 + 0.3 * (1.0 - t) * (f2 * t).sin()
        })
        .collect()
}

/// n thresholds over `range`, ridge width `relative`·range, seeded weights in [0.02, 0.1].
fn truth(o: Orientation, range: (f64, f64), n: usize, relative: f64, seed: u64) -> Kp {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let w: Vec<f64> = (0..n * (n + 1) / 2)
        .map(|_| rng.random_range(0.02..0.1))
        .collect();
    let t = Kp::uniform_thresholds(range.0, range.1, n).unwrap();
    Kp::new(t, relative * (range.1 - range.0), w, 0.3, 0.1, o).unwrap()
}

fn options(o: Orientation, range: (f64, f64), n: usize, relative: f64) -> KpOptions {
    KpOptions {
        levels: n,
        widths: vec![relative],
        lambda: 0.0,
        range: Some(range),
        orientation: Some(o),
        ..KpOptions::default()
    }
}

#[test]
fn recovers_weights_both_orientations() {
    let u = input(6000, 61.0, 233.0);
    for o in [Orientation::COUNTER_CLOCKWISE, Orientation::CLOCKWISE] {
        // the grid spans the range of the core operator's input (y for a clockwise loop)
        let range = if o.inverse { (-4.0, 4.0) } else { (-2.2, 2.2) };
        let t = truth(o, range, 6, 0.25, 7);
        let y = t.simulate(&u).unwrap();
        let f = fit(&u, &y, &options(o, range, 6, 0.25)).unwrap();
        assert_eq!(f.model.thresholds(), t.thresholds());
        assert_eq!(f.model.width(), t.width());
        let mut worst = 0.0f64;
        for (k, (a, b)) in f.model.weights().iter().zip(t.weights()).enumerate() {
            assert!((a - b).abs() < 1e-6 * b, "{o:?} weight {k}: {a} vs {b}");
            worst = worst.max((a - b).abs() / b);
        }
        println!("{o:?}: largest relative weight error {worst:.1e}");
        assert!((f.model.a0() - 0.3).abs() < 1e-6 * 0.3, "{o:?}");
        assert!((f.model.offset() - 0.1).abs() < 1e-6, "{o:?}");
        assert_eq!(f.termination, Termination::ZeroResidual, "{o:?}");
        assert!(f.fit_percent > 99.9999, "{o:?}");
        assert_eq!(f.parameters.names(), t.parameters().names());
    }
}

#[test]
fn the_width_profile_finds_the_true_ridge_width() {
    let u = input(4000, 61.0, 233.0);
    let o = Orientation::COUNTER_CLOCKWISE;
    let t = truth(o, (-2.2, 2.2), 5, 0.25, 11);
    let y = t.simulate(&u).unwrap();
    let opts = KpOptions {
        widths: vec![0.1, 0.25, 0.5],
        ..options(o, (-2.2, 2.2), 5, 0.25)
    };
    let f = fit(&u, &y, &opts).unwrap();
    assert_eq!(f.model.width(), t.width());
    assert_eq!(f.evaluations, 3);
    assert!(f.fit_percent > 99.9999);
}

#[test]
fn noisy_fit_predicts_a_second_record_as_well_as_the_truth() {
    let o = Orientation::COUNTER_CLOCKWISE;
    let range = (-2.2, 2.2);
    let t = truth(o, range, 6, 0.25, 3);
    let add_noise = |clean: &[f64], seed: u64| -> Vec<f64> {
        let std = metrics::std_dev(clean) / 100.0; // SNR 40 dB
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let normal = Normal::new(0.0, std).unwrap();
        clean.iter().map(|v| v + normal.sample(&mut rng)).collect()
    };
    let u = input(5000, 61.0, 233.0);
    let y = add_noise(&t.simulate(&u).unwrap(), 1);
    let f = fit(&u, &y, &options(o, range, 6, 0.25)).unwrap();
    assert!(f.std.iter().any(|s| s.is_some()));
    // the validation record: other frequencies, other noise
    let uv = input(3000, 47.0, 181.0);
    let yv = add_noise(&t.simulate(&uv).unwrap(), 2);
    let fit_true = metrics::fit_percent(&yv, &t.simulate(&uv).unwrap());
    let fit_est = metrics::fit_percent(&yv, &f.model.simulate(&uv).unwrap());
    println!("40 dB: validation fit {fit_est:.4} % (true operator {fit_true:.4} %)");
    assert!(
        (fit_true - fit_est).abs() < 0.1,
        "validation fit {fit_est:.4} % vs the true operator's {fit_true:.4} %"
    );
}

#[test]
fn bad_options_are_refused() {
    let u = input(2000, 61.0, 233.0);
    let y = u.clone();
    let cases = [
        (
            "lambda",
            KpOptions {
                lambda: f64::NAN,
                ..KpOptions::default()
            },
        ),
        (
            "lambda",
            KpOptions {
                lambda: -1.0,
                ..KpOptions::default()
            },
        ),
        (
            "range",
            KpOptions {
                range: Some((1.0, -1.0)),
                ..KpOptions::default()
            },
        ),
        (
            "widths",
            KpOptions {
                widths: vec![],
                ..KpOptions::default()
            },
        ),
        (
            "widths",
            KpOptions {
                widths: vec![0.1, 0.0],
                ..KpOptions::default()
            },
        ),
        (
            "levels",
            KpOptions {
                levels: 0,
                ..KpOptions::default()
            },
        ),
        (
            "levels",
            KpOptions {
                levels: 101,
                ..KpOptions::default()
            },
        ),
    ];
    for (option, opts) in cases {
        match fit(&u, &y, &opts) {
            Err(hysid::Error::InvalidOption { option: o, .. }) => assert_eq!(o, option),
            other => panic!("{option}: {other:?}"),
        }
    }
    // 212 parameters need more samples than 100
    assert!(fit(&u[..100], &y[..100], &KpOptions::default()).is_err());
}

fn rms(a: &[f64], b: &[f64]) -> f64 {
    metrics::mse(a, b).sqrt()
}

/// On the real piezo record, with the split of `hysid compare` (first 60 % train, the model
/// simulated over the whole record, the rest scored), the default KP fit predicts at least as
/// well as the default Preisach fit, and compensates at least as well. Compensation is judged
/// against the real plant: the reference is the measured displacement, so the ideal
/// compensating input is the voltage that was measured; the figure is the RMS of
/// Γ⁻¹\[y\] − u over the validation samples. As a second view each model's compensating
/// input is fed to the other family's model as the plant.
#[test]
fn piezo_record_default_kp_is_at_least_as_good_as_preisach() {
    let (u, y) = piezo_record();
    let split = u.len() * 6 / 10;
    let kp = fit(&u[..split], &y[..split], &KpOptions::default()).unwrap();
    let pr = preisach::fit(&u[..split], &y[..split], &PreisachOptions::default()).unwrap();
    let val = |m: &dyn HysteresisOperator| {
        let sim = m.simulate(&u).unwrap();
        metrics::fit_percent(&y[split..], &sim[split..])
    };
    let (kp_val, pr_val) = (val(&kp.model), val(&pr.model));
    println!(
        "piezo validation fit %: kp {kp_val:.3} (train {:.3}, a = {:.2} V, {:.3} s), \
         preisach {pr_val:.3} (train {:.3}, {:.3} s)",
        kp.fit_percent,
        kp.model.width(),
        kp.elapsed_s,
        pr.fit_percent,
        pr.elapsed_s
    );
    assert!(kp_val >= pr_val, "kp {kp_val} vs preisach {pr_val}");
    assert!(kp_val > 99.3, "kp {kp_val}");

    let kp_inv = kp.model.invert(&y).unwrap();
    let pr_inv = pr.model.invert(&y).unwrap();
    assert!(kp_inv.clipped.is_empty());
    assert!(rms(&kp_inv.predicted, &y) < 1e-9);
    let kp_u = rms(&kp_inv.u[split..], &u[split..]);
    let pr_u = rms(&pr_inv.u[split..], &u[split..]);
    let kp_through_pr = rms(&pr.model.simulate(&kp_inv.u).unwrap()[split..], &y[split..]);
    let pr_through_kp = rms(&kp.model.simulate(&pr_inv.u).unwrap()[split..], &y[split..]);
    println!(
        "piezo compensation: RMS(inverse(y) − u) kp {kp_u:.3} V, preisach {pr_u:.3} V \
         ({} clipped); kp-compensated through the preisach model {kp_through_pr:.4} µm, \
         preisach-compensated through the kp model {pr_through_kp:.4} µm",
        pr_inv.clipped.len()
    );
    assert!(kp_u <= pr_u, "kp {kp_u} V vs preisach {pr_u} V");
    assert!(kp_through_pr <= pr_through_kp);
}
