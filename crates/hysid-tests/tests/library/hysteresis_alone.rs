//! The Coleman–Hodgdon hysteresis identified from its measured input and output.

use hysid::data::{Channel, Experiment, IdData};
use hysid::experiments::voros::CascadeExample;
use hysid::identify::hysteresis::HysteresisIdentification;
use hysid::model::{ChForm, ColemanHodgdon};
use hysid::numerics::signal::add_noise_snr;
use hysid::numerics::Control;

fn truth(form: ChForm) -> ColemanHodgdon {
    match form {
        ChForm::General6 => ColemanHodgdon::general(0.4, 1.2, 0.15, 0.6, 0.1, 2.0).unwrap(),
        ChForm::Saturated4 => ColemanHodgdon::saturated(0.3, 1.0, 0.5, 3.0).unwrap(),
    }
}

/// The examples' inputs (triangles with an amplitude schedule and a uniform disturbance).
fn input(form: ChForm, seed: u64) -> Vec<f64> {
    let ex = match form {
        ChForm::General6 => CascadeExample::example2(),
        ChForm::Saturated4 => CascadeExample::example1(),
    };
    ex.generate(seed, false).unwrap().x
}

#[test]
fn noise_free_round_trip_is_exact() {
    for form in [ChForm::Saturated4, ChForm::General6] {
        let h = truth(form);
        let x = input(form, 4);
        let y = h.simulate(&x, 0.0).unwrap();
        let data = IdData::siso(1.0, "x", x, "y", y).unwrap();
        let fit = HysteresisIdentification::new(form)
            .estimate(&data, &mut |_| Control::Continue)
            .unwrap();
        for (e, t) in fit.model.params().iter().zip(h.params()) {
            assert!(
                ((e - t) / t).abs() < 1e-6,
                "{form:?}: {:?} vs {:?}",
                fit.model.params(),
                h.params()
            );
        }
    }
}

#[test]
fn several_experiments_are_fitted_together() {
    let h = truth(ChForm::General6);
    let experiments: Vec<Experiment> = (1..=3)
        .map(|seed| {
            let x: Vec<f64> = input(ChForm::General6, seed)
                .into_iter()
                .take(1500)
                .collect();
            let y = h.simulate(&x, 0.0).unwrap();
            Experiment::new(format!("run {seed}"), vec![x], vec![y]).unwrap()
        })
        .collect();
    let data = IdData::new(
        1.0,
        vec![Channel::new("x")],
        vec![Channel::new("y")],
        experiments,
    )
    .unwrap();
    let fit = HysteresisIdentification::new(ChForm::General6)
        .estimate(&data, &mut |_| Control::Continue)
        .unwrap();
    assert_eq!(fit.output_error.fit_percent.len(), 3);
    for (e, t) in fit.model.params().iter().zip(h.params()) {
        assert!(((e - t) / t).abs() < 1e-6, "{:?}", fit.model.params());
    }
}

/// With output noise (SNR 50) the output-error estimate lies within 3 reported standard
/// deviations of the truth for (nearly) every parameter and seed.
#[test]
fn noisy_estimates_lie_within_their_standard_deviations() {
    let h = truth(ChForm::General6);
    let (mut inside, mut total) = (0, 0);
    for seed in 1..=10 {
        let x = input(ChForm::General6, seed);
        let (y, _) = add_noise_snr(&h.simulate(&x, 0.0).unwrap(), 50.0, 1000 + seed).unwrap();
        let data = IdData::siso(1.0, "x", x, "y", y).unwrap();
        let fit = HysteresisIdentification::new(ChForm::General6)
            .estimate(&data, &mut |_| Control::Continue)
            .unwrap();
        let std = fit.std();
        for ((e, t), s) in fit.model.params().iter().zip(h.params()).zip(&std) {
            total += 1;
            if (e - t).abs() <= 3.0 * s {
                inside += 1;
            }
        }
    }
    assert!(
        inside as f64 >= 0.9 * total as f64,
        "{inside}/{total} within 3 std"
    );
}

/// Real records vendored in `data/` (no published parameters exist for them): the
/// identification runs and fits them at least as well as recorded in the README.
#[test]
fn real_piezo_and_ferrite_records_are_fitted() {
    use hysid::data::CsvSpec;
    use std::path::Path;
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data");
    let spec = |input: &str, output: &str| CsvSpec {
        inputs: vec![input.into()],
        outputs: vec![output.into()],
        time: None,
        ts: None,
    };
    let piezo = IdData::from_csv(
        &root.join("piezo/piezo_150V_1Hz.csv"),
        &spec("voltage_V", "displacement_um"),
    )
    .unwrap();
    let fit = HysteresisIdentification::new(ChForm::General6)
        .estimate(&piezo, &mut |_| Control::Continue)
        .unwrap();
    assert!(
        fit.output_error.fit_percent[0][0] > 99.4,
        "piezo fit {:?}",
        fit.output_error.fit_percent
    );

    let file = root.join("ferrite/mnzn_ferrite_bh_loops.csv");
    let mut loops: Option<IdData> = None;
    for k in 1..=4 {
        let one =
            IdData::from_csv(&file, &spec(&format!("H{k}_A_per_m"), &format!("B{k}_T"))).unwrap();
        let exp = one.experiment(0);
        let renamed = IdData::new(
            one.ts(),
            vec![Channel::new("H")],
            vec![Channel::new("B")],
            vec![Experiment::new(
                format!("loop {k}"),
                vec![exp.input(0).to_vec()],
                vec![exp.output(0).to_vec()],
            )
            .unwrap()],
        )
        .unwrap();
        loops = Some(match loops {
            None => renamed,
            Some(l) => l.merge(renamed).unwrap(),
        });
    }
    let loops = loops.unwrap();
    let fit = HysteresisIdentification::new(ChForm::General6)
        .estimate(&loops, &mut |_| Control::Continue)
        .unwrap();
    for f in &fit.output_error.fit_percent {
        assert!(
            f[0] > 92.0,
            "ferrite fits {:?}",
            fit.output_error.fit_percent
        );
    }
}
