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

/// A piecewise-linear input through `turns`, `per_unit` samples per unit of input.
fn through(turns: &[f64], per_unit: f64) -> Vec<f64> {
    let mut u = vec![turns[0]];
    for w in turns.windows(2) {
        let n = ((w[1] - w[0]).abs() * per_unit).ceil().max(1.0) as usize;
        for k in 1..=n {
            u.push(w[0] + (w[1] - w[0]) * k as f64 / n as f64);
        }
    }
    u
}

/// The bar of issue #38 item 2: a static Bouc–Wen plant whose training and validation
/// records both start in saturation at the input's minimum (after a descent from 50 times
/// the range above it). The default fit (`estimate`), saved and simulated on the validation
/// record, reaches ≥ 99.3 % and comes within 0.1 point of the fit with the true (declared
/// descending) state; the demagnetised start (the behaviour before) falls short.
#[test]
fn a_record_starting_in_saturation_is_fitted_from_its_estimated_state() {
    use hysid::identify::operators::{fit_operator, Family, FamilyOptions};
    use hysid::model::operators::InitialState;
    use hysid::model::saved::{FittedModel, ModelFile};
    use hysid::numerics::metrics::fit_percent;
    let mut plant = BoucWen::new(0.3, -1.0, 2.5, 1.5, 1.0).unwrap();
    let in_saturation = |plant: &BoucWen, u0: f64| {
        let w =
            hysid::model::operators::differential::states(plant, &[u0, u0 + 100.0, u0]).unwrap();
        w[2]
    };
    let train_u = through(
        &[-1.0, 1.0, -0.2, 0.6, -0.7, 0.9, 0.1, 0.4, -1.0, 0.5],
        200.0,
    );
    let valid_u = through(&[-1.0, 0.7, -0.4, 1.0, 0.0, 0.5, -0.8, 0.8], 200.0);
    plant.w0 = in_saturation(&plant, train_u[0]);
    let train_y = with_noise(&plant.simulate(&train_u).unwrap(), 46.0, 11);
    plant.w0 = in_saturation(&plant, valid_u[0]);
    let valid_y = with_noise(&plant.simulate(&valid_u).unwrap(), 46.0, 12);
    let validation = |state: InitialState| {
        let options = FamilyOptions {
            initial_state: state,
            ..FamilyOptions::default()
        };
        let fitted = fit_operator(Family::BoucWen, &train_u, &train_y, &options).unwrap();
        // Through the model file, as `hysid simulate --model` reads it.
        let text = serde_json::to_string(&fitted.fit.model.to_file()).unwrap();
        let model =
            FittedModel::from_file(&serde_json::from_str::<ModelFile>(&text).unwrap()).unwrap();
        let y = model.simulate(&[&valid_u], 1.0, None).unwrap().remove(0);
        fit_percent(&valid_y, &y)
    };
    let estimated = validation(InitialState::Estimate);
    let best = validation(InitialState::Descending);
    let before = validation(InitialState::Demagnetised);
    eprintln!(
        "validation fit %: estimate {estimated:.3}, true state {best:.3}, demagnetised {before:.3}"
    );
    assert!(estimated >= 99.3, "{estimated}");
    assert!(estimated >= best - 0.1, "{estimated} vs {best}");
    assert!(before < estimated - 1.0, "{before} vs {estimated}");
}
