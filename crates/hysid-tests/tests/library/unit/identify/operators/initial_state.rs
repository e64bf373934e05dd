//! Tests of the initial state of the linear-in-weights fits
//! (`hysid::identify::operators`, `FamilyOptions::initial_state`; MODELS.md §4.8): a record
//! that starts at the end of a descent is fitted from that history, and `estimate` finds it.

use hysid::identify::operators::{fit_operator, Family, FamilyOptions};
use hysid::model::operators::{initial_state, InitialState, InitialStateUsed, OperatorModel};
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
    let families = [
        Family::Pi,
        Family::Gpi,
        Family::MaxwellSlip,
        Family::Backlash,
        Family::Preisach,
        Family::Kp,
    ];
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
