//! The three-step identification of Gunnar et al. (2006) on the virtual rig: round trips
//! with known parameters (noise-free, noisy), the backlash pattern of the paper's tables,
//! and bad input.

use hysid::experiments::actuator_rig::Rig;
use hysid::identify::actuator::{ActuatorIdentification, Record, ThreeSteps, PARAMETERS};
use hysid::Error;
use std::collections::BTreeMap;

fn records(rig: &Rig) -> BTreeMap<usize, Record> {
    rig.data_sets().unwrap()
}

fn identify(rig: &Rig) -> ActuatorIdentification {
    ThreeSteps::default().run(&records(rig)).unwrap()
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Without noise and backlash the rig is the model: step 3 (m67) recovers the truth within
/// 0.1 %; step 2 gives k1, k2 within 5 % and α, A within 15 % (the bars of the issue).
#[test]
#[ignore = "long (several seconds): run by `cargo test --release -- --ignored` and CI"]
fn noise_free_rig_without_backlash() {
    let rig = Rig {
        angle_noise: 0.0,
        torque_noise: 0.0,
        ..Rig::default()
    };
    let id = identify(&rig);
    let truth = &rig.truth;
    let m67 = id.step3["m67"].fit.parameters.values();
    for (i, name) in PARAMETERS.iter().enumerate() {
        assert!(
            relative(m67[i], truth[i]) < 1e-3,
            "m67 {name}: {} vs {}",
            m67[i],
            truth[i]
        );
    }
    for (i, tol) in [(3, 0.05), (4, 0.05), (5, 0.15), (6, 0.15)] {
        assert!(
            relative(id.m0[i], truth[i]) < tol,
            "m0 {}: {} vs {}",
            PARAMETERS[i],
            id.m0[i],
            truth[i]
        );
    }
    // Step 1 sees the rigid inertia Jt = J + r²m.
    let jt = truth[0] + rig.r * rig.r * rig.m;
    assert!(
        relative(id.step1.values[0], jt) < 0.01,
        "Jt {}",
        id.step1.values[0]
    );
    // Every step-3 model fits the estimation sets better than m0.
    for (name, fits) in &id.fit_table {
        assert!(fits.iter().all(|f| *f > 95.0), "{name}: {fits:?}");
    }
}

/// Without the paper's pre-filter in step 3 the noise-free rig data are exactly what the
/// model simulates: every step-3 model recovers the truth to round-off (1e-6), and fits
/// 100 %. (With it, m67 is 0.006 % off in J: filtering input and output is not filtering
/// the error of a nonlinear model.)
#[test]
#[ignore = "long (the three steps to round-off, several seconds): run by `-- --ignored` and CI"]
fn unfiltered_step3_recovers_the_noise_free_truth_exactly() {
    let rig = Rig {
        angle_noise: 0.0,
        torque_noise: 0.0,
        ..Rig::default()
    };
    let steps = ThreeSteps {
        prefilter_step3: false,
        ..ThreeSteps::default()
    };
    let id = steps.run(&records(&rig)).unwrap();
    for model in ["m67", "m68"] {
        let values = id.step3[model].fit.parameters.values();
        for (i, name) in PARAMETERS.iter().enumerate() {
            assert!(
                relative(values[i], rig.truth[i]) < 1e-6,
                "{model} {name}: {} vs {}",
                values[i],
                rig.truth[i]
            );
        }
        assert!(id.fit_table[model].iter().all(|f| *f > 99.9999), "{model}");
    }
}

/// With the rig's measurement noise, the m67 estimates lie within 3 of their reported
/// standard deviations of the truth.
#[test]
#[ignore = "long (several seconds): run by `cargo test --release -- --ignored` and CI"]
fn noisy_rig_estimates_lie_within_three_standard_deviations() {
    let rig = Rig::default();
    let id = identify(&rig);
    let fit = &id.step3["m67"].fit;
    let (values, std) = (fit.parameters.values(), fit.std());
    for (i, name) in PARAMETERS.iter().enumerate() {
        let error = (values[i] - rig.truth[i]).abs();
        assert!(
            std[i] > 0.0 && error < 3.0 * std[i],
            "{name}: {} vs truth {} (std {})",
            values[i],
            rig.truth[i],
            std[i]
        );
    }
}

/// With the unmodelled backlash of the real actuator, the tables show the paper's pattern:
/// fits below 100 %, and the step-3 estimates (m67, m68, all parameters free) improving on
/// m0 on every data set. The variants with J, Fv, Fc held at their step-1 values (m67f,
/// m68f) must at least lower the output error on the data they were fitted to.
#[test]
#[ignore = "long (several seconds): run by `cargo test --release -- --ignored` and CI"]
fn backlash_gives_the_papers_pattern() {
    let rig = Rig {
        backlash: 3e-3,
        ..Rig::default()
    };
    let id = identify(&rig);
    let m0 = &id.fit_table["m0"];
    for (name, fits) in &id.fit_table {
        assert!(fits.iter().all(|f| *f < 99.0), "{name}: {fits:?}");
    }
    for name in ["m67", "m68"] {
        for (set, (f, f0)) in id.fit_table[name].iter().zip(m0).enumerate() {
            assert!(f > f0, "{name} on data set {}: {f} vs m0 {f0}", set + 6);
        }
    }
    for name in ["m67f", "m68f"] {
        let report = &id.step3[name].fit.report;
        assert!(report.cost < report.initial_cost, "{name}: {report:?}");
    }
}

#[test]
fn a_missing_data_set_is_reported() {
    let mut recs = records(&Rig::default());
    recs.remove(&4);
    let err = ThreeSteps::default().run(&recs).unwrap_err();
    assert!(matches!(err, Error::InvalidData(_)), "{err}");
    assert!(err.to_string().contains("data set 4"), "{err}");
}

#[test]
fn a_loop_without_a_full_period_is_reported() {
    let mut recs = records(&Rig::default());
    let half = recs[&3].angle.len() / 3;
    let set = recs.get_mut(&3).unwrap();
    set.angle.truncate(half);
    set.torque.truncate(half);
    let err = ThreeSteps::default().run(&recs).unwrap_err();
    assert!(err.to_string().contains("data set 3"), "{err}");
    assert!(err.to_string().contains("full loop period"), "{err}");
}

#[test]
fn a_speed_that_never_changes_sign_is_reported() {
    let mut recs = records(&Rig::default());
    let set = recs.get_mut(&1).unwrap();
    set.angle = (0..set.angle.len()).map(|k| 0.01 * k as f64).collect();
    let err = ThreeSteps::default().run(&recs).unwrap_err();
    assert!(err.to_string().contains("sign"), "{err}");
}
