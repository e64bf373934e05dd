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

/// A PI with a saturating static envelope on the record's own range, fitted on its own
/// thresholds with an envelope: the weights, the offset and the envelope's slope values come
/// back (a round trip with known parameters), in both orientations. The fit holds a₀u in the
/// envelope (a₀ = 0, every slope value raised by the plant's a₀: the same operator).
#[test]
fn recovers_an_envelope_both_orientations() {
    use hysid::model::operators::Envelope;
    let u = input(4000);
    for o in [Orientation::COUNTER_CLOCKWISE, Orientation::CLOCKWISE] {
        let plays = truth(&u, o);
        // the core's input is u counter-clockwise and G's output clockwise: the envelope
        // lives on the range the fit sees (G's input)
        let core_input = match o.inverse {
            false => u.clone(),
            true => truth(&u, Orientation::COUNTER_CLOCKWISE)
                .simulate(&u)
                .unwrap(),
        };
        let lo = core_input.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = core_input.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let slopes = vec![0.2, 1.4, 0.05];
        let t = PrandtlIshlinskii::with_static_envelope(
            plays.a0(),
            plays.weights().to_vec(),
            plays.thresholds().to_vec(),
            plays.offset(),
            o,
            Some(Envelope::new(lo, hi, slopes.clone()).unwrap()),
        )
        .unwrap();
        let x = match o.inverse {
            // Γ = G⁻¹: feed G's outputs of the counter-clockwise form so that the core's
            // input covers [lo, hi]
            false => u.clone(),
            true => {
                let ccw = PrandtlIshlinskii::with_static_envelope(
                    plays.a0(),
                    plays.weights().to_vec(),
                    plays.thresholds().to_vec(),
                    plays.offset(),
                    Orientation::COUNTER_CLOCKWISE,
                    Some(Envelope::new(lo, hi, slopes.clone()).unwrap()),
                )
                .unwrap();
                ccw.simulate(&core_input).unwrap()
            }
        };
        let y = t.simulate(&x).unwrap();
        let opts = PiOptions {
            grid: Some(t.thresholds().to_vec()),
            orientation: Some(o),
            envelope: true,
            ..PiOptions::default()
        };
        let f = fit(&x, &y, &opts).unwrap();
        let e = f.model.envelope().expect("an envelope was asked for");
        assert_eq!(
            (e.lo(), e.hi()),
            (lo, hi),
            "{o:?}: the range is the core input's"
        );
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1.0);
        for (a, b) in e.slopes().iter().zip(&slopes) {
            let b = b + t.a0();
            assert!(rel(*a, b) < 1e-6, "{o:?}: slope value {a} vs {b}");
        }
        assert_eq!(f.model.a0(), 0.0);
        for (a, b) in f.model.weights().iter().zip(t.weights()) {
            assert!(rel(*a, *b) < 1e-6, "{o:?}: {a} vs {b}");
        }
        // a₀u = a₀(u − lo) + a₀lo: the offset takes a₀lo
        let offset = t.offset() + t.a0() * lo;
        assert!(rel(f.model.offset(), offset) < 1e-6, "{o:?}: offset");
        assert!(f.fit_percent > 99.9999, "{o:?}: {}", f.fit_percent);
        // parameters a0, a1…a6, r1…r6, c, e0…e2, e_lo, e_hi; the range has no σ
        let names = f.parameters.names();
        assert_eq!(&names[14..], ["e0", "e1", "e2", "e_lo", "e_hi"]);
        assert!(f.std[14].is_some() && f.std[17].is_none() && f.std[18].is_none());
        assert!(f.std[0].is_none(), "a0 is not estimated beside an envelope");
    }
}

/// By default the envelope is a candidate of the size choice: on a saturating record it is
/// chosen and fits what the plays alone cannot; `none` keeps the plays alone, `cubic` with
/// fixed thresholds adds it to today's fixed grid.
#[test]
fn the_default_fit_chooses_an_envelope_where_the_plays_cannot_follow() {
    use hysid::identify::operators::{fit_operator, EnvelopeChoice, Family, FamilyOptions};
    let u = input(3000);
    let grid = threshold_grid(&u, 6).unwrap();
    let x = PrandtlIshlinskii::new(
        1.0,
        vec![0.4, 0.3, 0.2, 0.0, 0.0, 0.0],
        grid,
        0.0,
        Orientation::default(),
    )
    .unwrap()
    .simulate(&u)
    .unwrap();
    // the plays beside a saturating static curve of the input (a magnet's yoke)
    let y: Vec<f64> = x
        .iter()
        .zip(&u)
        .map(|(p, v)| 0.3 * p + 10.0 * ((v - 2.0) / 2.5).tanh())
        .collect();
    let fitted = |envelope, choose| {
        let options = FamilyOptions {
            envelope,
            choose_thresholds: choose,
            ..FamilyOptions::default()
        };
        fit_operator(Family::Pi, &u, &y, &options).unwrap()
    };
    let auto = fitted(EnvelopeChoice::Auto, true);
    let none = fitted(EnvelopeChoice::None, true);
    let size = auto.fit.model_size.clone().unwrap();
    println!(
        "auto: {} {:.3} %, none: {:.3} %",
        size.chosen, auto.fit.fit_percent, none.fit.fit_percent
    );
    assert!(size.chosen.ends_with("+ envelope"), "{size:?}");
    assert!(size.candidates.iter().any(|c| !c.size.contains("envelope")));
    // a cubic follows this tanh (to 0.89 of its saturation) to about 1 %
    assert!(auto.fit.fit_percent > 98.5, "{}", auto.fit.fit_percent);
    assert!(auto.fit.fit_percent > none.fit.fit_percent + 3.0);
    let none_size = none.fit.model_size.clone().unwrap();
    assert!(none_size
        .candidates
        .iter()
        .all(|c| !c.size.contains("envelope")));
    let names = |f: &hysid::identify::operators::FittedOperator| f.fit.parameters.names();
    assert!(!names(&none).iter().any(|n| n == "e0"));
    // fixed thresholds: auto keeps today's recipe, cubic adds the envelope to it
    assert!(!names(&fitted(EnvelopeChoice::Auto, false))
        .iter()
        .any(|n| n == "e0"));
    assert!(names(&fitted(EnvelopeChoice::Cubic, false))
        .iter()
        .any(|n| n == "e0"));
}
