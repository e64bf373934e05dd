//! Tests of the initial state of the linear-in-weights fits
//! (`hysid::identify::operators`, `FamilyOptions::initial_state`; MODELS.md §4.8): a record
//! that starts at the end of a descent is fitted from that history, and `estimate` finds it.

use hysid::identify::operators::{fit_operator, Family, FamilyOptions};
use hysid::model::operators::{
    initial_state, InitialState, InitialStateUsed, JilesAtherton, OperatorModel,
};
use hysid::numerics::metrics;

/// The input: from u₀ = 0.35 down to −0.8, then seeded sweeps inside [−0.8, 0.9], 20 samples
/// per unit: the first branch is a sixth of the record.
fn record() -> Vec<f64> {
    let targets = [-0.8, 0.9, -0.6, 0.7, -0.8, 0.5, -0.3, 0.9, -0.1, 0.4];
    let mut u = vec![0.35];
    for &t in &targets {
        let at = *u.last().unwrap();
        let n = ((t - at) as f64).abs().mul_add(20.0, 1.0).ceil() as usize;
        u.extend((1..=n).map(|k| at + (t - at) * k as f64 / n as f64));
    }
    u
}

#[test]
fn a_record_starting_after_a_descent_is_fitted_from_that_history_and_estimate_finds_it() {
    let u = record();
    let families = crate::unit::test_signals::LINEAR_IN_WEIGHTS;
    let examples = OperatorModel::examples().unwrap();
    for family in families {
        let plant = examples.iter().find(|m| m.family() == family).unwrap();
        let y =
            initial_state::simulate(plant.as_operator(), Some(InitialStateUsed::Descending), &u)
                .unwrap();
        let fit = |request: InitialState| {
            let options = FamilyOptions {
                initial_state: request,
                ..FamilyOptions::default()
            };
            fit_operator(family, &u, &y, &options).unwrap()
        };
        let demagnetised = fit(InitialState::Demagnetised);
        let descending = fit(InitialState::Descending);
        let estimated = fit(InitialState::Estimate);
        assert_eq!(demagnetised.fit.initial_state, None, "{family}");
        assert_eq!(
            descending.fit.initial_state,
            Some(InitialStateUsed::Descending),
            "{family}"
        );
        // the declared history is what the plant had: the fit is better from it
        assert!(
            descending.fit.rmse < 0.5 * demagnetised.fit.rmse,
            "{family}: rmse {} from the descent, {} demagnetised",
            descending.fit.rmse,
            demagnetised.fit.rmse
        );
        assert_eq!(
            estimated.fit.initial_state,
            Some(InitialStateUsed::Descending),
            "{family}: estimate chose {:?}",
            estimated.fit.initial_state
        );
        // the saved model starts in its saved state: its simulation is the fit's
        let again = estimated.fit.model.simulate(&[&u], 1.0, None).unwrap();
        assert_eq!(again[0], estimated.fit.simulated, "{family}");
        let fit_percent = metrics::fit_percent(&y, &again[0]);
        println!(
            "{family}: fit % {fit_percent:.3} (demagnetised {:.3})",
            demagnetised.fit.fit_percent
        );
    }
}

/// A major loop measured from its tip, as a B(H) loop is (#38 item 4: no record with a full
/// major loop is refused as "not exciting"): 129 samples from u = 1 down to −1 and back, one
/// reversal. Every family's example plant, after a descent from above, is fitted back with
/// the defaults (KP to 89.7 %: its candidate ridge widths miss the plant's); the size
/// choice's training part, the first 70 %, holds the same single reversal.
#[test]
fn a_major_loop_measured_from_its_tip_is_fitted_not_refused() {
    let unit: Vec<f64> = (0..129)
        .map(|k| (std::f64::consts::PI * k as f64 / 64.0).cos())
        .collect();
    for plant in OperatorModel::examples().unwrap() {
        let family = plant.family();
        // Jiles–Atherton: a soft ferrite of the order of the vendored Mn-Zn loops, ±60 A/m
        // (the classic example's field of several kA/m, reached from M = 0 at the record's
        // first input, leaves the model's physical domain: δk < α(M_an − M_irr)).
        let (plant, amplitude) = if family == Family::JilesAtherton {
            let ferrite = JilesAtherton::new(2.5e5, 8.0, 5.0, 0.3, 5e-6).unwrap();
            (OperatorModel::JilesAtherton(ferrite), 60.0)
        } else {
            (plant, 1.0)
        };
        let u: Vec<f64> = unit.iter().map(|v| amplitude * v).collect();
        let y =
            initial_state::simulate(plant.as_operator(), Some(InitialStateUsed::Descending), &u)
                .unwrap();
        let fit = fit_operator(family, &u, &y, &FamilyOptions::default())
            .unwrap_or_else(|e| panic!("{family}: {e}"));
        println!(
            "{family}: fit % {:.3}, initial state {:?}",
            fit.fit.fit_percent, fit.fit.initial_state
        );
        let bar = if family == Family::Kp { 89.0 } else { 99.5 };
        assert!(
            fit.fit.fit_percent >= bar,
            "{family}: {} %",
            fit.fit.fit_percent
        );
    }
}

/// The vendored Mn-Zn ferrite loops (`data/ferrite`, 129 samples each from +Hₘₐₓ): no family
/// refuses one as "not exciting" (they used to: "1 reversal(s) … needs at least 2"); Dahl
/// refuses for its stated reason, a counter-clockwise loop where it rises. A monotone record,
/// or one whose only reversal is within 1 % of its range, is still refused as not exciting.
#[test]
fn single_measured_ferrite_loops_are_not_refused_as_not_exciting() {
    use crate::unit::test_signals::ferrite_loop;
    use hysid::identify::operators::family::FamilySetting;
    use hysid::model::operators::LoopOrientation;
    use hysid::Error;
    for k in 1..=4 {
        let (h, b) = ferrite_loop(k);
        for family in Family::ALL {
            match fit_operator(*family, &h, &b, &FamilyOptions::default()) {
                Ok(fit) => println!("loop {k} {family}: {:.3} %", fit.fit.fit_percent),
                Err(e @ Error::NotExciting { .. }) => panic!("loop {k}, {family}: {e}"),
                Err(e) => {
                    assert_eq!(*family, Family::Dahl, "loop {k}, {family}: {e}");
                    assert!(e.to_string().contains("counter-clockwise"), "{e}");
                }
            }
        }
    }
    // A ramp, and a ramp with one step back by 10⁻⁴ of its range: no branch to fit, even
    // with the orientation given (the check, not the orientation's detection, refuses).
    let ramp: Vec<f64> = (0..200).map(|k| k as f64 / 199.0).collect();
    let mut stepped = ramp.clone();
    stepped.push(1.0 - 1e-4);
    for u in [ramp, stepped] {
        let y: Vec<f64> = u.iter().map(|v| (3.0 * v).tanh()).collect();
        for family in Family::ALL {
            let reads = family.settings().contains(&FamilySetting::Orientation);
            let options = FamilyOptions {
                loop_orientation: reads.then_some(LoopOrientation::CounterClockwise),
                ..FamilyOptions::default()
            };
            match fit_operator(*family, &u, &y, &options) {
                Err(e @ Error::NotExciting { .. }) => {
                    assert!(e.to_string().contains("never reverses"), "{family}: {e}")
                }
                other => panic!("{family}: {:?}", other.map(|f| f.fit.fit_percent)),
            }
        }
    }
}
