//! Streaming models (`hysid::model::stream`): every kind's `Stepper` against the batch
//! `FittedModel::simulate`, every compensator against the batch `compensate`, to the bit
//! (`to_bits` on every sample), on a seeded signal with nested minor loops; reset; the
//! one-line errors.

use hysid::model::coleman_hodgdon::InitialOutput;
use hysid::model::compensate::{compensate, compensate_within};
use hysid::model::greybox::equation_model::EquationStateSpace;
use hysid::model::greybox::models::GreyBoxKind;
use hysid::model::greybox::{InputInterpolation, Integrator, Simulation, StateSpaceModel};
use hysid::model::limits::Limits;
use hysid::model::operators::OperatorModel;
use hysid::model::saved::FittedModel;
use hysid::model::saved::{
    FittedCascade, FittedEquations, FittedGreyBox, FittedHysteresis, FittedOperatorCascade,
};
use hysid::model::stream::{compensate_stream, run, Stepper};
use hysid::model::{ColemanHodgdon, HysteresisCascade, LinearBlock, OperatorCascade};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

/// A seeded signal of amplitude about `scale`: a decaying sweep (nested minor loops), a
/// second tone and a little noise.
fn signal(n: usize, scale: f64, seed: u64) -> Vec<f64> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            let envelope = 1.0 - 0.8 * t;
            let s = envelope * (2.0 * std::f64::consts::PI * 7.0 * t).sin()
                + 0.15 * (2.0 * std::f64::consts::PI * 31.0 * t).sin();
            scale * (s + 0.01 * rng.random_range(-1.0..1.0))
        })
        .collect()
}

/// Asserts `a` and `b` hold the same bits, naming the first sample where they differ.
fn assert_same(a: &[f64], b: &[f64], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    if let Some(k) = (0..a.len()).find(|&k| a[k].to_bits() != b[k].to_bits()) {
        panic!("{what}: sample {k}: {} against {}", a[k], b[k]);
    }
}

/// The stepper of `model` run over `inputs` equals `simulate` to the bit (or both fail with
/// the same message); run twice with a reset in between gives the same bits again.
fn assert_streams(model: &FittedModel, inputs: &[&[f64]], ts: f64, y0: Option<f64>, what: &str) {
    let batch = model.simulate(inputs, ts, y0);
    let mut stepper = model
        .stepper(ts, y0)
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    let first = run(stepper.as_mut(), inputs);
    match (&batch, &first) {
        (Ok(b), Ok(s)) => {
            assert_eq!(b.len(), s.len(), "{what}: output count");
            for (bc, sc) in b.iter().zip(s) {
                assert_same(bc, sc, &format!("{what}: stepper against simulate"));
            }
        }
        (Err(b), Err(s)) => assert_eq!(b.to_string(), s.to_string(), "{what}"),
        (b, s) => panic!("{what}: batch {b:?} but stream {s:?}"),
    }
    stepper.reset();
    let second = run(stepper.as_mut(), inputs);
    match (first, second) {
        (Ok(a), Ok(b)) => {
            for (ac, bc) in a.iter().zip(&b) {
                assert_same(ac, bc, &format!("{what}: a reset stepper"));
            }
        }
        (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string(), "{what}"),
        (a, b) => panic!("{what}: first run {a:?}, second {b:?}"),
    }
}

/// The compensator of `model` equals `compensate` to the bit: commands, predicted outputs,
/// clipped samples and their count; again after a reset.
fn assert_compensates(model: &FittedModel, reference: &[f64], what: &str) {
    let batch = compensate(model, reference).unwrap_or_else(|e| panic!("{what}: {e}"));
    let mut compensator = model
        .compensator(1.0)
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    for round in 0..2 {
        let stream = compensate_stream(compensator.as_mut(), reference)
            .unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_same(&batch.u, &stream.u, &format!("{what}: u (round {round})"));
        let predicted = format!("{what}: predicted (round {round})");
        assert_same(&batch.predicted, &stream.predicted, &predicted);
        assert_eq!(
            batch.clipped, stream.clipped,
            "{what}: clipped (round {round})"
        );
        assert_eq!(
            compensator.clipped(),
            batch.clipped.len(),
            "{what}: clipped count"
        );
        assert_eq!(
            batch.settled_from, stream.settled_from,
            "{what}: settled_from"
        );
    }
}

fn no_std(n: usize) -> Vec<f64> {
    vec![f64::NAN; n]
}

/// Every operator of the registry with its variants (a PI with a static envelope), and of
/// every linear-in-weights family its clockwise (inverse-operator) form too: (name,
/// operator, an input inside its domain).
fn operators() -> Vec<(String, OperatorModel, Vec<f64>)> {
    let u = signal(600, 1.0, 7);
    let mut out = Vec::new();
    let variants = OperatorModel::variants().unwrap().into_iter();
    let examples = OperatorModel::examples()
        .unwrap()
        .into_iter()
        .map(|m| ("", m));
    for (variant, model) in examples.chain(variants) {
        let family = model.family().name().to_string();
        let name = match variant {
            "" => family.clone(),
            v => format!("{family} ({v})"),
        };
        let mut structure = model.structure().unwrap();
        if let Some(o) = structure.get_mut("orientation").filter(|o| o.is_object()) {
            o["inverse"] = serde_json::Value::Bool(true);
            let clockwise = OperatorModel::from_structure(&family, &structure).unwrap();
            // Γ = G⁻¹ takes G's outputs: the counter-clockwise operator's on the signal.
            let inside = model.as_operator().simulate(&u).unwrap();
            out.push((format!("{name} (clockwise)"), clockwise, inside));
        }
        out.push((name, model, u.clone()));
    }
    out
}

/// A declared history (descending, ascending) runs at the stream's first good sample as the
/// batch simulation of the saved model runs it before the record: the same bits for every
/// family and both orientations, with the fit's saved turn, on records starting mid-loop, at
/// the input's extremes and beyond the saved turn; a non-finite first sample is skipped and
/// the history runs at the next; a model file keeps the turn.
#[test]
fn a_declared_history_streams_as_the_saved_model_simulates_it() {
    use hysid::model::operators::initial_state::History;
    use hysid::model::operators::InitialStateUsed;
    use hysid::model::saved::ModelFile;
    let mut primed = 0;
    for (name, model, u) in operators() {
        let n = model.as_operator().parameters().len();
        // The two histories start differently (so the test sees which one runs).
        let starts: Vec<f64> = [InitialStateUsed::Descending, InitialStateUsed::Ascending]
            .iter()
            .map(|&state| {
                let turn = state.turning_input(model.as_operator(), &u);
                FittedModel::operator(model.clone(), no_std(n))
                    .with_initial_state(Some(state), turn)
                    .simulate(&[&u], 1.0, None)
                    .unwrap()[0][0]
            })
            .collect();
        assert_ne!(starts[0], starts[1], "{name}");
        let (lo, hi) = u
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        for state in [InitialStateUsed::Descending, InitialStateUsed::Ascending] {
            // The turn a fit on `u` saves.
            let turn = state.turning_input(model.as_operator(), &u);
            let fitted = FittedModel::operator(model.clone(), no_std(n))
                .with_initial_state(Some(state), turn);
            let what = format!("{name}, {}", state.name());
            // The record itself, cut open mid-loop, and one starting at each extreme.
            let at_min = u.iter().position(|&v| v == lo).unwrap();
            let at_max = u.iter().position(|&v| v == hi).unwrap();
            for (cut, label) in [
                (0, "whole"),
                (217, "cut open"),
                (at_min, "at min"),
                (at_max, "at max"),
            ] {
                assert_streams(
                    &fitted,
                    &[&u[cut..]],
                    1.0,
                    None,
                    &format!("{what}, {label}"),
                );
            }
            // A saved turn the record starts beyond (a record far outside the fit's range).
            let beyond = FittedModel::operator(model.clone(), no_std(n))
                .with_initial_state(Some(state), Some(0.5 * (lo + hi)));
            let tail: Vec<f64> = u
                .iter()
                .copied()
                .filter(|v| v.abs() <= 0.9 * hi.abs().max(lo.abs()))
                .collect();
            assert_streams(
                &beyond,
                &[&tail],
                1.0,
                None,
                &format!("{what}, beyond the turn"),
            );
            // The history's path: the record's first input, the turn, then the record.
            let history = History::of(Some(state), turn).unwrap();
            let path = history.path(model.as_operator(), &u);
            assert_eq!(&path[..2], &[u[0], turn.unwrap()], "{what}");
            // A non-finite first sample: skipped, the history runs at the next one.
            let mut stepper = fitted.stepper(1.0, None).unwrap();
            let mut y = [0.0];
            stepper.step(&[f64::NAN], &mut y).unwrap();
            assert_eq!(stepper.faults(), 1, "{what}");
            let rest = run(stepper.as_mut(), &[&u[1..]]).unwrap();
            let expected = fitted.simulate(&[&u[1..]], 1.0, None).unwrap();
            assert_same(
                &rest[0],
                &expected[0],
                &format!("{what}, after a bad first sample"),
            );
            // The compensator after the history: the stream equals the batch, and the
            // commands make the model, simulated after its history, follow the reference (to
            // rounding; a differential family to its inverse's tolerance).
            let history = History::of(Some(state), turn);
            assert!(model.history_reaches_the_inverse(history), "{what}");
            let reference = fitted.simulate(&[&u[217..]], 1.0, None).unwrap().remove(0);
            assert_compensates(&fitted, &reference, &format!("{what}, compensated"));
            primed += 1;
            let commands = compensate(&fitted, &reference).unwrap();
            let followed = fitted
                .simulate(&[&commands.u], 1.0, None)
                .unwrap()
                .remove(0);
            let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            // A differential family's branch y(v) is its integration's, smooth to its
            // tolerance (1e-10 of the state's scale) as v moves the sub-steps; the
            // inverse's root is as close as the branch's steps allow.
            let differential =
                ["bouc-wen", "duhem", "dahl", "jiles-atherton"].contains(&model.family().name());
            let tolerance = if differential { 1e-9 } else { 1e-12 };
            assert!(
                commands.clipped.is_empty(),
                "{what}: {:?}",
                commands.clipped
            );
            for (k, (a, b)) in followed.iter().zip(&reference).enumerate() {
                assert!(
                    (a - b).abs() <= tolerance * scale,
                    "{what}: sample {k}: {a} against {b}"
                );
            }
            // Where the history is not the structure's own start (the Preisach plane's
            // negative saturation is the ascending one), a linear-in-weights family's own
            // inverse misses the first samples.
            let own = FittedModel::operator(model.clone(), no_std(n));
            let own_start = own.simulate(&[&u[217..]], 1.0, None).unwrap().remove(0);
            if !differential && own_start[0] != reference[0] {
                let missed = compensate(&own, &reference).unwrap().u;
                let off = fitted.simulate(&[&missed], 1.0, None).unwrap().remove(0);
                assert!((off[0] - reference[0]).abs() > 1e-6 * scale, "{what}");
            }
            // Saved and read back: the state and the turn.
            let text = serde_json::to_string(&fitted.to_file()).unwrap();
            assert!(text.contains("\"history_turn\""), "{what}: {text}");
            let back =
                FittedModel::from_file(&serde_json::from_str::<ModelFile>(&text).unwrap()).unwrap();
            assert_same(
                &back.simulate(&[&u[217..]], 1.0, None).unwrap()[0],
                &fitted.simulate(&[&u[217..]], 1.0, None).unwrap()[0],
                &what,
            );
        }
    }
    // Every family in both orientations, both histories.
    assert!(primed >= 2 * 14, "{primed}");
}

#[test]
fn every_operator_streams_as_it_simulates_and_inverts() {
    let families = operators();
    assert!(families.len() >= hysid::model::operators::Family::operators().count());
    for (name, model, u) in families {
        let n = model.as_operator().parameters().len();
        let fitted = FittedModel::operator(model.clone(), no_std(n));
        assert_streams(&fitted, &[&u], 1.0, None, &name);
        // A reachable reference (the operator's own output) and one beyond a saturation
        // level (clipped where the family saturates).
        let y = model.as_operator().simulate(&u).unwrap();
        assert_compensates(&fitted, &y, &name);
        let far: Vec<f64> = y.iter().map(|v| 3.0 * v).collect();
        assert_compensates(&fitted, &far, &format!("{name}, far reference"));
    }
}

fn linear(b2: f64) -> LinearBlock {
    LinearBlock::new(vec![-0.6, 0.08], vec![1.0, b2], 1).unwrap()
}

#[test]
fn operator_cascades_stream_and_compensate_as_the_batch() {
    for (name, model, u) in operators() {
        let cascade = OperatorCascade::new(model, linear(0.4)).unwrap();
        let n = cascade.parameters().len();
        let fitted = FittedModel::OperatorCascade(FittedOperatorCascade {
            model: cascade.clone(),
            std: no_std(n),
        });
        assert_streams(&fitted, &[&u], 1.0, None, &format!("{name} cascade"));
        let r = cascade.simulate(&u).unwrap().y;
        assert_compensates(&fitted, &r, &format!("{name} cascade"));
    }
}

#[test]
fn a_non_minimum_phase_cascade_has_no_compensator_and_says_so_as_the_batch_does() {
    let model = OperatorModel::examples().unwrap().remove(0);
    let cascade = OperatorCascade::new(model, linear(1.5)).unwrap();
    let n = cascade.parameters().len();
    let fitted = FittedModel::OperatorCascade(FittedOperatorCascade {
        model: cascade,
        std: no_std(n),
    });
    let stream = fitted.compensator(1.0).unwrap_err().to_string();
    let batch = compensate(&fitted, &[0.0, 0.1]).unwrap_err().to_string();
    assert_eq!(stream, batch);
    assert!(
        stream.contains("not minimum phase") && !stream.contains('\n'),
        "{stream}"
    );
}

fn coleman_hodgdon() -> [ColemanHodgdon; 2] {
    [
        ColemanHodgdon::saturated(0.3, 1.0, 0.5, 3.0).unwrap(),
        ColemanHodgdon::general(0.4, 1.2, 0.15, 0.6, 0.1, 2.0).unwrap(),
    ]
}

#[test]
fn coleman_hodgdon_hysteresis_and_cascades_stream_as_the_batch() {
    let x = signal(800, 2.0, 11);
    for ch in coleman_hodgdon() {
        for initial in [InitialOutput::Measured, InitialOutput::Zero] {
            let fitted = FittedModel::Hysteresis(FittedHysteresis {
                model: ch.clone(),
                initial,
                std: no_std(ch.params().len()),
            });
            let what = format!("{:?} {initial:?}", ch.form());
            assert_streams(&fitted, &[&x], 1.0, Some(0.25), &what);
            let y = fitted.simulate(&[&x], 1.0, Some(0.25)).unwrap().remove(0);
            assert_compensates(&fitted, &y, &what);
            let far: Vec<f64> = y.iter().map(|v| 4.0 * v).collect();
            assert_compensates(&fitted, &far, &format!("{what}, far reference"));
        }
        let cascade = HysteresisCascade::new(ch.clone(), linear(0.4)).unwrap();
        let fitted = FittedModel::Cascade(FittedCascade {
            std: no_std(cascade.params().len()),
            model: cascade,
        });
        assert_streams(&fitted, &[&x], 1.0, None, "ch cascade");
        // A step faster than the rate limit 1/α: the same error, at the same sample.
        let fast: Vec<f64> = x.iter().map(|v| 10.0 * v).collect();
        assert_streams(&fitted, &[&fast], 1.0, None, "ch cascade, too fast");
        let err = fitted.compensator(1.0).unwrap_err().to_string();
        assert_eq!(err, compensate(&fitted, &x).unwrap_err().to_string());
        assert!(
            err.contains("not invertible") && !err.contains('\n'),
            "{err}"
        );
    }
}

/// The simulation settings the grey-box streams are checked with.
fn simulations() -> Vec<Simulation> {
    let mut out = Vec::new();
    for interpolation in [
        InputInterpolation::ZeroOrderHold,
        InputInterpolation::Linear,
    ] {
        for integrator in [
            Integrator::Rk4 { substeps: 4 },
            Integrator::Newmark { substeps: 2 },
            Integrator::Adaptive {
                rtol: 1e-6,
                atol: 1e-9,
            },
        ] {
            out.push(Simulation {
                integrator,
                interpolation,
            });
        }
    }
    out
}

/// The input channels of a model: seeded signals of amplitude `scale`.
fn channels(n_inputs: usize, scale: f64) -> Vec<Vec<f64>> {
    (0..n_inputs)
        .map(|c| signal(300, scale, 100 + c as u64))
        .collect()
}

#[test]
fn built_in_grey_box_models_stream_as_they_simulate() {
    for kind in GreyBoxKind::ALL {
        let model = kind.model();
        let parameters = model.parameters();
        let inputs = channels(model.inputs().len(), 1.0);
        let slices: Vec<&[f64]> = inputs.iter().map(Vec::as_slice).collect();
        for simulation in simulations() {
            let fitted = FittedModel::GreyBox(FittedGreyBox {
                kind: kind.name().to_string(),
                std: no_std(parameters.len()),
                parameters: parameters.clone(),
                simulation,
                initial_state: vec![0.0; model.states().len()],
            });
            let what = format!("{} {simulation:?}", kind.name());
            match fitted.stepper(1e-3, None) {
                Ok(_) => assert_streams(&fitted, &slices, 1e-3, None, &what),
                // Refused settings (Newmark for a model that is not mechanical, …) are
                // refused by the batch alike.
                Err(e) => assert_eq!(
                    e.to_string(),
                    fitted
                        .simulate(&slices, 1e-3, None)
                        .unwrap_err()
                        .to_string()
                ),
            }
            assert!(fitted.streaming_differs().is_none(), "{what}");
        }
    }
}

/// An equation file that reads the time t, and a discrete-time one (shared with the export
/// tests).
const TIMED: &str = include_str!("../fixtures/equations/forced.toml");
const DISCRETE: &str = include_str!("../fixtures/equations/recursion.toml");

#[test]
fn equation_models_stream_as_they_simulate() {
    let texts = [
        std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../examples/equations/bouc_wen.toml"
        ))
        .unwrap(),
        TIMED.to_string(),
        DISCRETE.to_string(),
    ];
    for text in texts {
        let model = EquationStateSpace::parse(&text, "test").unwrap();
        let inputs = channels(model.inputs().len(), 1.0);
        let slices: Vec<&[f64]> = inputs.iter().map(Vec::as_slice).collect();
        for simulation in simulations() {
            let fitted = FittedModel::Equations(FittedEquations {
                equations: text.clone(),
                parameters: model.parameters(),
                std: no_std(model.parameters().len()),
                simulation,
                initial_state: model.initial_values(),
                evaluator: hysid::model::greybox::native::Evaluator::Auto,
            });
            let what = format!("{} {simulation:?}", model.name());
            match fitted.stepper(1e-2, None) {
                Ok(_) => assert_streams(&fitted, &slices, 1e-2, None, &what),
                Err(e) => assert_eq!(
                    e.to_string(),
                    fitted
                        .simulate(&slices, 1e-2, None)
                        .unwrap_err()
                        .to_string()
                ),
            }
        }
    }
}

#[test]
fn band_limited_interpolation_is_reported_as_differing() {
    let kind = GreyBoxKind::BoucWen;
    let model = kind.model();
    let fitted = FittedModel::GreyBox(FittedGreyBox {
        kind: kind.name().into(),
        std: no_std(model.parameters().len()),
        parameters: model.parameters(),
        simulation: Simulation {
            integrator: Integrator::Rk4 { substeps: 4 },
            interpolation: InputInterpolation::BandLimited,
        },
        initial_state: vec![0.0; model.states().len()],
    });
    let why = fitted.streaming_differs().unwrap();
    assert!(why.contains("band-limited") && !why.contains('\n'), "{why}");
    // It still streams (with linear interpolation).
    assert!(fitted.stepper(1e-3, None).is_ok());
}

#[test]
fn kinds_that_cannot_stream_or_invert_say_so_in_one_line() {
    let kind = GreyBoxKind::RigidBody;
    let model = kind.model();
    let rigid = FittedModel::GreyBox(FittedGreyBox {
        kind: kind.name().into(),
        std: no_std(model.parameters().len()),
        parameters: model.parameters(),
        simulation: Simulation::default(),
        initial_state: vec![0.0; model.states().len()],
    });
    let err = rigid.compensator(1.0).unwrap_err().to_string();
    assert!(
        err.contains("not invertible") && !err.contains('\n'),
        "{err}"
    );
    let prefiltered = FittedModel::prefiltered(
        rigid,
        Some(hysid::model::record_filters::Prefilter {
            remove_mean: true,
            cutoff_hz: Some(10.0),
            order: 2,
        }),
    );
    for err in [
        prefiltered.stepper(1e-3, None).unwrap_err().to_string(),
        prefiltered.compensator(1e-3).unwrap_err().to_string(),
    ] {
        assert!(err.contains("zero phase") && !err.contains('\n'), "{err}");
    }
}

#[test]
fn bad_samples_are_skipped_and_counted_and_wrong_shapes_are_one_line_errors() {
    let model = OperatorModel::examples().unwrap().remove(0);
    let mut stepper = model.stepper().unwrap();
    let mut y = [1.0];
    // Before any good sample a forward model gives 0; the flag and the count.
    stepper.step(&[f64::NAN], &mut y).unwrap();
    assert_eq!((y[0], stepper.error(), stepper.faults()), (0.0, true, 1));
    stepper.step(&[0.4], &mut y).unwrap();
    let good = y[0];
    assert!(!stepper.error());
    stepper.step(&[f64::NEG_INFINITY], &mut y).unwrap();
    assert_eq!((y[0], stepper.error(), stepper.faults()), (good, true, 2));
    // The next good sample is the one the sequence without the bad ones gives.
    stepper.step(&[-0.3], &mut y).unwrap();
    let clean = model.as_operator().simulate(&[0.4, -0.3]).unwrap();
    assert_eq!(y[0].to_bits(), clean[1].to_bits());
    let err = stepper.step(&[0.0, 1.0], &mut y).unwrap_err().to_string();
    assert!(err.contains("1 input(s)") && !err.contains('\n'), "{err}");
    stepper.reset();
    assert_eq!((stepper.error(), stepper.faults()), (false, 0));

    // A limited compensator: the midpoint before any good reference, the limits after.
    let mut compensator = model.compensator().unwrap();
    let limits = Limits::parse("-0.5:0.25").unwrap();
    compensator.set_limits(Some(limits));
    let step = compensator.step(f64::INFINITY).unwrap();
    assert_eq!((step.u, step.clipped), (-0.125, false));
    assert_eq!((compensator.error(), compensator.faults()), (true, 1));
    let step = compensator.step(1e3).unwrap();
    assert_eq!((step.u, step.clipped), (0.25, true));
    let step = compensator.step(-1e3).unwrap();
    assert_eq!(
        (step.u, step.clipped, compensator.clipped()),
        (-0.5, true, 2)
    );
    assert!(!compensator.error());
    // The batch with the same limits agrees.
    let batch = compensate_within(
        &FittedModel::operator(
            model.clone(),
            vec![f64::NAN; model.as_operator().parameters().len()],
        ),
        &[1e3, -1e3],
        Some(limits),
    )
    .unwrap();
    assert_eq!((batch.u, batch.clipped), (vec![0.25, -0.5], vec![0, 1]));
}

#[test]
fn limits_parse_apply_and_refuse_in_one_line() {
    let l = Limits::parse("-10:150").unwrap();
    assert_eq!((l.lo(), l.hi(), l.midpoint()), (-10.0, 150.0, 70.0));
    assert_eq!(l.apply(-11.0), (-10.0, true));
    assert_eq!(l.apply(151.0), (150.0, true));
    assert_eq!(l.apply(3.0), (3.0, false));
    for bad in ["150:-10", "1", "a:b", "nan:1", "0:inf"] {
        let err = Limits::parse(bad).unwrap_err().to_string();
        assert!(err.contains("LO:HI") && !err.contains('\n'), "{bad}: {err}");
    }
}

#[test]
fn a_preisach_stream_refuses_an_input_that_nests_deeper_than_its_memory() {
    let model = OperatorModel::examples()
        .unwrap()
        .into_iter()
        .find(|m| m.family().name() == "preisach")
        .unwrap();
    // Shrinking oscillations: every reversal a new corner of the staircase.
    let u: Vec<f64> = (0..200)
        .map(|k| 0.9 * (-1f64).powi(k) * (1.0 - k as f64 / 250.0))
        .collect();
    let batch = model.as_operator().simulate(&u).unwrap();
    let mut stepper: Box<dyn Stepper> = model.stepper().unwrap();
    let err = run(stepper.as_mut(), &[&u]).unwrap_err().to_string();
    assert!(err.contains("minor loops") && !err.contains('\n'), "{err}");
    // Up to the capacity it is the batch's.
    stepper.reset();
    let depth = hysid::model::operators::preisach::STREAM_MEMORY - 2;
    let head = run(stepper.as_mut(), &[&u[..depth]]).unwrap();
    assert_same(&head[0], &batch[..depth], "preisach within its memory");
}
