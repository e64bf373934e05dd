//! Tests of `hysid::identify::operators::family`.

use crate::unit::test_signals::piezo_record;
use hysid::identify::operators::family::*;
use hysid::model::operators::{HysteresisOperator, PrandtlIshlinskii};
use hysid::model::operators::{LoopOrientation, OperatorModel, Orientation};
use hysid::model::saved::FittedHysteresisOperator;
use hysid::model::saved::FittedModel;

#[test]
fn names_round_trip() {
    for f in Family::ALL {
        assert_eq!(Family::parse(f.name()).unwrap(), *f);
    }
    assert_eq!(Family::parse("Maxwell_Slip").unwrap(), Family::MaxwellSlip);
    let e = Family::parse("pii").unwrap_err().to_string();
    assert!(e.contains("unknown hysteresis family 'pii'") && !e.contains('\n'));
    assert_eq!(Family::parse_list("all").unwrap(), Family::ALL);
    assert_eq!(
        Family::parse_list("pi,preisach,pi").unwrap(),
        vec![Family::Pi, Family::Preisach]
    );
}

#[test]
fn options_ranges_are_checked() {
    let bad_grid = FamilyOptions {
        threshold_grid: Some(vec![0.2, 0.1]),
        ..FamilyOptions::default()
    };
    assert!(bad_grid.validate().is_err());
    let zero = FamilyOptions {
        thresholds: 0,
        ..FamilyOptions::default()
    };
    assert!(zero.validate().unwrap_err().to_string().contains("1..=200"));
}

/// PI data with known weights: fit_operator recovers them through the registry, and the
/// saved model simulates to the fit's own output.
#[test]
fn pi_through_the_registry() {
    let r = vec![0.1, 0.2, 0.3, 0.4];
    let truth = PrandtlIshlinskii::new(
        0.5,
        vec![0.4, 0.3, 0.2, 0.1],
        r.clone(),
        0.2,
        Orientation::default(),
    )
    .unwrap();
    let u: Vec<f64> = (0..2000)
        .map(|k| {
            let t = k as f64 / 2000.0;
            (1.0 - 0.6 * t) * (2.0 * std::f64::consts::PI * 5.0 * t).sin()
        })
        .collect();
    let y = truth.simulate(&u).unwrap();
    let options = FamilyOptions {
        threshold_grid: Some(r),
        orientation: Some(Orientation::default()),
        ..FamilyOptions::default()
    };
    let fitted = fit_operator(Family::Pi, &u, &y, &options).unwrap();
    let FittedModel::Operator(FittedHysteresisOperator {
        model: OperatorModel::Pi(pi),
        ..
    }) = &fitted.fit.model
    else {
        panic!("not a PI model")
    };
    for (a, b) in pi.weights().iter().zip(truth.weights()) {
        assert!((a - b).abs() < 1e-6 * b, "{a} vs {b}");
    }
    let back = FittedModel::from_file(&fitted.fit.model.to_file()).unwrap();
    let yhat = back.simulate(&[&u], 1.0, None).unwrap();
    assert_eq!(yhat[0], fitted.fit.simulated);
}

/// Every family ignores the settings it does not declare ([`Identify::SETTINGS`], which the
/// command line uses to refuse a flag for a family): its fit with all of them changed is
/// bit for bit the fit with the defaults. Data: each family's registry example on a short
/// record with minor loops.
#[test]
#[ignore = "long (Jiles–Atherton's fit twice, several seconds): run by `-- --ignored` and CI"]
fn families_read_only_the_settings_they_declare() {
    use crate::unit::test_signals::training_input;
    let u = training_input(2_000, 1.5);
    let changed = |declared: &[FamilySetting]| {
        let mut options = FamilyOptions::default();
        for setting in [
            FamilySetting::Thresholds,
            FamilySetting::ThresholdGrid,
            FamilySetting::Grid,
            FamilySetting::Lambda,
            FamilySetting::DeadZones,
            FamilySetting::Orientation,
            FamilySetting::Envelope,
        ] {
            if declared.contains(&setting) {
                continue;
            }
            match setting {
                FamilySetting::Thresholds => options.thresholds = 7,
                FamilySetting::ThresholdGrid => {
                    options.threshold_grid = Some(vec![0.1, 0.2, 0.4]);
                    options.thresholds = 3;
                }
                FamilySetting::Grid => options.grid = 6,
                FamilySetting::Lambda => options.lambda = 1e-2,
                FamilySetting::DeadZones => options.dead_zones = 2,
                FamilySetting::Orientation => options.orientation = Some(Orientation::CLOCKWISE),
                FamilySetting::Envelope => {
                    options.envelope = hysid::identify::operators::EnvelopeChoice::Cubic
                }
            }
        }
        options
    };
    for example in OperatorModel::examples().unwrap() {
        let family = example.family();
        let y = example.as_operator().simulate(&u).unwrap();
        let settings = family.settings();
        let base = fit_operator(family, &u, &y, &FamilyOptions::default()).unwrap();
        let other = fit_operator(family, &u, &y, &changed(settings)).unwrap();
        let bits = |f: &FittedOperator| -> Vec<u64> {
            f.fit
                .parameters
                .values()
                .iter()
                .map(|v| v.to_bits())
                .collect()
        };
        assert_eq!(
            bits(&base),
            bits(&other),
            "{family} reads a setting it does not declare ({settings:?})"
        );
        for setting in settings {
            assert!(Family::reading(*setting).contains(&family));
        }
    }
}

/// ch4 is ch6 with m2 = c2 = 0, so the zoo's ch6 (started from the better of the separated
/// regression and the nested ch4 fit, `HysteresisIdentification::better_start`) fits a real
/// piezo record at least as well as ch4 — on the whole record and on `compare`'s 60 %
/// training part; the published recipe's start alone is reported beside it.
#[test]
fn ch6_fits_a_real_piezo_record_at_least_as_well_as_its_nested_ch4() {
    use hysid::data::IdData;
    use hysid::identify::hysteresis::HysteresisIdentification;
    use hysid::model::ChForm;
    use hysid::numerics::levenberg_marquardt::Control;
    let (u, y) = piezo_record();
    for n in [u.len() * 6 / 10, u.len()] {
        let (u, y) = (&u[..n], &y[..n]);
        let options = FamilyOptions::default();
        let ch4 = fit_operator(Family::Ch4, u, y, &options).unwrap();
        let ch6 = fit_operator(Family::Ch6, u, y, &options).unwrap();
        let data = IdData::siso(1.0, "u", u.to_vec(), "y", y.to_vec()).unwrap();
        let published = HysteresisIdentification::new(ChForm::General6)
            .estimate(&data, &mut |_| Control::Continue)
            .map(|f| f.output_error.fit_percent[0][0]);
        println!(
            "{n} samples: ch6 {:.3} % ({:?}), ch4 {:.3} %, ch6 from the separated start alone {:?}",
            ch6.fit.fit_percent, ch6.fit.termination, ch4.fit.fit_percent, published
        );
        assert!(
            ch6.fit.rmse <= ch4.fit.rmse * (1.0 + 1e-9),
            "{n}: ch6 rmse {} above ch4's {}",
            ch6.fit.rmse,
            ch4.fit.rmse
        );
    }
}

/// A record whose input passes the threshold at a single sample: the free separated
/// regression's outer columns are then dependent (one row), where the d profile's tied
/// columns are not. Both forms used to refuse it ("regressors … dependent"); they now start
/// from the profile's solution, and ch6 fits it at least as well as its nested ch4.
#[test]
fn a_threshold_passed_by_one_sample_is_fitted_not_refused() {
    use hysid::model::{ChForm, ColemanHodgdon};
    let truth = ColemanHodgdon::general(0.3, 1.2, 0.15, 0.6, 0.1, 2.0).unwrap();
    let mut u = vec![0.0];
    for a in [1.0, 0.6, 0.8, 0.4, 1.0, 0.7] {
        let ramp = |from: f64, to: f64, n: usize| -> Vec<f64> {
            (1..=n)
                .map(|i| from + (to - from) * i as f64 / n as f64)
                .collect()
        };
        u.extend(ramp(0.0, a, 40));
        u.extend(ramp(a, -a, 80));
        u.extend(ramp(-a, 0.0, 40));
    }
    u[100] = 2.3;
    let y = truth.simulate(&u, 0.0).unwrap();
    assert_eq!(truth.form(), ChForm::General6);
    let options = FamilyOptions::default();
    let ch4 = fit_operator(Family::Ch4, &u, &y, &options).unwrap();
    let ch6 = fit_operator(Family::Ch6, &u, &y, &options).unwrap();
    println!(
        "ch6 {:.3} %, ch4 {:.3} %",
        ch6.fit.fit_percent, ch4.fit.fit_percent
    );
    assert!(ch6.fit.rmse <= ch4.fit.rmse * (1.0 + 1e-9));
    assert!(ch4.fit.fit_percent > 90.0, "{}", ch4.fit.fit_percent);
}

/// Units far from 1 (#38 item 4): the real piezo record in (V, µm), in (mV, km) and in
/// (kV, nm·10⁻²) fits to the same fit % in every linear-in-weights family (their normal
/// equations are equilibrated), in ch4/ch6 and in Bouc–Wen, Duhem and Dahl (fitted in units
/// of unit size; Dahl turned clockwise, the only way its structure takes this loop).
/// Jiles–Atherton is left out: its B = μ₀(H + M) ties it to T and A/m, and a record in other
/// units is refused naming them.
#[test]
fn units_far_from_one_fit_to_the_same_figures() {
    let (u, y) = piezo_record();
    let families = crate::unit::test_signals::LINEAR_IN_WEIGHTS
        .into_iter()
        .chain([
            Family::Ch4,
            Family::Ch6,
            Family::BoucWen,
            Family::Duhem,
            Family::Dahl,
        ]);
    for family in families {
        let options = FamilyOptions {
            loop_orientation: (family == Family::Dahl).then_some(LoopOrientation::Clockwise),
            ..FamilyOptions::default()
        };
        let base = fit_operator(family, &u, &y, &options)
            .unwrap()
            .fit
            .fit_percent;
        for (su, sy) in [(1e3, 1e-6), (1e-4, 1e5)] {
            let us: Vec<f64> = u.iter().map(|v| v * su).collect();
            let ys: Vec<f64> = y.iter().map(|v| v * sy).collect();
            let scaled = fit_operator(family, &us, &ys, &options)
                .unwrap_or_else(|e| panic!("{family} at ({su}, {sy}): {e}"))
                .fit
                .fit_percent;
            assert!(
                (scaled - base).abs() < 1e-6,
                "{family}: fit {scaled} % in units ({su}, {sy}), {base} % in V and µm"
            );
        }
    }
}
