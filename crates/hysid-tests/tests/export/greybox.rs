//! The grey-box and equation-file cases: each built-in model and three equation files (one
//! reading t, one discrete-time, the Bouc–Wen example with ν = 1.5 through `pow`), with
//! zero-order hold and linear interpolation, RK4 with 4 sub-steps; the adaptive integrator
//! on two of them; and Newmark on the models that accept it ([`newmark_cases`]). Rigid body
//! and actuators stick and slip on these inputs.

use crate::cases::{signal, Case};
use hysid::export::ExportOptions;
use hysid::model::greybox::equation_model::EquationStateSpace;
use hysid::model::greybox::models::GreyBoxKind;
use hysid::model::greybox::{InputInterpolation, Integrator, Simulation, StateSpaceModel};
use hysid::model::saved::FittedModel;
use hysid::model::saved::{FittedEquations, FittedGreyBox};
use hysid::model::ParameterSet;

/// An equation file that reads the time t (and a `sin`, an `abs`).
pub const TIMED: &str = include_str!("../fixtures/equations/forced.toml");

/// A discrete-time equation file (with an integer power and a `max`).
pub const DISCRETE: &str = include_str!("../fixtures/equations/recursion.toml");

const RK4: Integrator = Integrator::Rk4 { substeps: 4 };
const ADAPTIVE: Integrator = Integrator::Adaptive {
    rtol: 1e-6,
    atol: 1e-9,
};

/// The case `label` of `model` on `input` sampled every `ts`.
fn case(label: &str, model: &FittedModel, input: Vec<f64>, ts: f64) -> Case {
    let expected = model
        .simulate(&[&input], ts, None)
        .unwrap_or_else(|e| panic!("{label}: the library's simulate failed: {e}"))[0]
        .clone();
    Case {
        name: label.into(),
        file: model.to_file(),
        options: ExportOptions {
            sample_time: Some(ts),
            ..ExportOptions::default()
        },
        input,
        expected,
        clipped: None,
    }
}

fn no_std(n: usize) -> Vec<f64> {
    vec![f64::NAN; n]
}

/// A built-in model with its defaults overridden by `values` (name, value).
fn built_in(kind: GreyBoxKind, values: &[(&str, f64)], simulation: Simulation) -> FittedModel {
    let model = kind.model();
    let mut parameters: ParameterSet = model.parameters();
    let mut theta = parameters.values();
    for (name, v) in values {
        let i = parameters
            .names()
            .iter()
            .position(|n| n == name)
            .expect("a parameter of the model");
        theta[i] = *v;
    }
    parameters.set_values(&theta);
    FittedModel::GreyBox(FittedGreyBox {
        kind: kind.name().into(),
        std: no_std(parameters.len()),
        parameters,
        simulation,
        initial_state: vec![0.0; model.states().len()],
    })
}

/// An equation file with its own parameter values and initial state.
pub fn equations(text: &str, simulation: Simulation) -> FittedModel {
    let model = EquationStateSpace::parse(text, "test").expect("a valid equation file");
    FittedModel::Equations(FittedEquations {
        equations: text.into(),
        parameters: model.parameters(),
        std: no_std(model.parameters().len()),
        simulation,
        initial_state: model.initial_values(),
        evaluator: hysid::model::greybox::native::Evaluator::Auto,
    })
}

fn scaled(u: &[f64], scale: f64) -> Vec<f64> {
    u.iter().map(|v| scale * v).collect()
}

/// Every grey-box and equation-file case.
pub fn cases() -> Vec<Case> {
    let u = signal(3000, 41);
    let bouc_wen = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/equations/bouc_wen.toml"
    ))
    .expect("the example")
    .replace("nu         = { value = 1.0", "nu         = { value = 1.5");
    let mut out = Vec::new();
    for (tag, interpolation) in [
        ("zoh", InputInterpolation::ZeroOrderHold),
        ("linear", InputInterpolation::Linear),
    ] {
        let rk4 = Simulation {
            integrator: RK4,
            interpolation,
        };
        let bw = built_in(GreyBoxKind::BoucWen, &[], rk4);
        out.push(case(
            &format!("gb_bouc_wen_{tag}"),
            &bw,
            scaled(&u, 120.0),
            1.0 / 750.0,
        ));
        let rigid = [("Fv", 0.5), ("Fc", 0.3), ("offset", 0.05)];
        let rb = built_in(GreyBoxKind::RigidBody, &rigid, rk4);
        out.push(case(
            &format!("gb_rigid_body_{tag}"),
            &rb,
            scaled(&u, 0.6),
            1e-3,
        ));
        let fixed = built_in(GreyBoxKind::ActuatorFixed, &[], rk4);
        out.push(case(
            &format!("gb_actuator_fixed_{tag}"),
            &fixed,
            scaled(&u, 0.5),
            1e-3,
        ));
        let free = built_in(GreyBoxKind::ActuatorFree, &[], rk4);
        out.push(case(
            &format!("gb_actuator_free_{tag}"),
            &free,
            scaled(&u, 0.5),
            1e-3,
        ));
        let timed = equations(TIMED, rk4);
        out.push(case(&format!("eq_timed_{tag}"), &timed, u.clone(), 1e-2));
        let discrete = equations(DISCRETE, rk4);
        out.push(case(
            &format!("eq_discrete_{tag}"),
            &discrete,
            scaled(&u, 0.5),
            1e-2,
        ));
        let example = equations(&bouc_wen, rk4);
        out.push(case(
            &format!("eq_bouc_wen_{tag}"),
            &example,
            scaled(&u, 120.0),
            1.0 / 750.0,
        ));
    }
    let adaptive = Simulation {
        integrator: ADAPTIVE,
        interpolation: InputInterpolation::Linear,
    };
    let bw = built_in(GreyBoxKind::BoucWen, &[], adaptive);
    out.push(case(
        "gb_bouc_wen_adaptive",
        &bw,
        scaled(&u, 120.0),
        1.0 / 750.0,
    ));
    let timed = equations(TIMED, adaptive);
    out.push(case("eq_timed_adaptive", &timed, u.clone(), 1e-2));
    out.extend(newmark_cases(&u));
    out.extend(resampled_cases(&u));
    out
}

/// A model fitted every `fitted` seconds exported at `ts` (`--ts` other than the file's):
/// the export's model is the library's [`FittedModel::resampled`], and the code must equal
/// its simulation at `ts`.
fn resampled_case(label: &str, model: &FittedModel, input: Vec<f64>, fitted: f64, ts: f64) -> Case {
    let stepped = model
        .resampled(fitted, ts)
        .unwrap_or_else(|| panic!("{label}: a continuous-time model is re-stepped"));
    let mut case = case(label, &stepped, input, ts);
    case.file = model.to_file();
    case.file.sample_time = Some(fitted);
    case
}

/// The re-stepped cases (#39 item 7): RK4 at a third and at 2.5 times the fitted sample
/// time (2 and 10 sub-steps for the fitted 4), Newmark at twice it, and the equation file
/// that reads t.
fn resampled_cases(u: &[f64]) -> Vec<Case> {
    let rk4 = Simulation {
        integrator: RK4,
        interpolation: InputInterpolation::Linear,
    };
    let bw = built_in(GreyBoxKind::BoucWen, &[], rk4);
    let fitted = 1.0 / 750.0;
    let mut out = vec![
        resampled_case(
            "gb_bouc_wen_at_third",
            &bw,
            scaled(u, 120.0),
            fitted,
            fitted / 3.0,
        ),
        resampled_case(
            "gb_bouc_wen_at_2_5",
            &bw,
            scaled(u, 120.0),
            fitted,
            2.5 * fitted,
        ),
        resampled_case(
            "eq_timed_at_half",
            &equations(TIMED, rk4),
            u.to_vec(),
            1e-2,
            5e-3,
        ),
    ];
    let newmark = Simulation {
        integrator: Integrator::Newmark { substeps: 1 },
        interpolation: InputInterpolation::Linear,
    };
    let bw = built_in(GreyBoxKind::BoucWen, &[], newmark);
    out.push(resampled_case(
        "gb_bouc_wen_newmark_at_twice",
        &bw,
        scaled(u, 120.0),
        fitted,
        2.0 * fitted,
    ));
    out
}

/// The sub-steps of a re-stepped model are no longer than the fitted model's and as few as
/// that allows, so its integration error is no larger: on a smooth input u(t) sampled at
/// the fitted rate and at a third and 2.5 times its period, the error of each model against
/// the same model integrated with 64 sub-steps per sample (its reference) — the fitted
/// model's at its rate, the re-stepped one's at the new rate. The error grows with the
/// sub-step h (as h⁴ for RK4) and with the length of the record, which is the same here:
/// at a third of the period h′ = 2h/3, at 2.5 times it h′ = h. And the refusal for a
/// discrete-time model.
#[test]
fn a_continuous_time_model_is_re_stepped_for_another_sample_time() {
    let rk4 = |substeps| Simulation {
        integrator: Integrator::Rk4 { substeps },
        interpolation: InputInterpolation::Linear,
    };
    for (n, from, to, expected) in [
        (4, 3.0, 1.0, 2),
        (4, 1.0, 2.5, 10),
        (4, 1.0, 2.0, 8),
        (10, 1.0, 0.01, 1),
        (3, 0.3, 0.1, 1),
    ] {
        let got = rk4(n).resampled(from, to).integrator;
        assert_eq!(
            got,
            Integrator::Rk4 { substeps: expected },
            "{n} {from} {to}"
        );
    }
    let fitted = 1.0 / 750.0;
    let duration = 4.0;
    let smooth = |t: f64| {
        let w = 2.0 * std::f64::consts::PI;
        80.0 * (w * 7.0 * t).sin() + 40.0 * (w * 23.0 * t).sin()
    };
    // The largest error of `model` at `ts` against itself with 64 sub-steps.
    let error = |model: &FittedModel, ts: f64| {
        let n = (duration / ts).round() as usize;
        let u: Vec<f64> = (0..n).map(|k| smooth(k as f64 * ts)).collect();
        let y = model.simulate(&[&u], ts, None).unwrap().remove(0);
        let reference = built_in(GreyBoxKind::BoucWen, &[], rk4(64));
        let r = reference.simulate(&[&u], ts, None).unwrap().remove(0);
        let range = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = y
            .iter()
            .zip(&r)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        worst / range
    };
    let bw = built_in(GreyBoxKind::BoucWen, &[], rk4(4));
    let at_fitted = error(&bw, fitted);
    for (factor, allowed) in [(1.0 / 3.0, 1.0), (2.5, 1.5)] {
        let stepped = bw
            .resampled(fitted, factor * fitted)
            .expect("continuous time");
        let at_new = error(&stepped, factor * fitted);
        println!("ts × {factor}: error {at_new:.3e} (fitted: {at_fitted:.3e})");
        assert!(
            at_fitted > 0.0 && at_new <= allowed * at_fitted,
            "{at_new:e} {at_fitted:e}"
        );
    }
    let discrete = equations(DISCRETE, rk4(4));
    assert!(discrete.resampled(1e-2, 5e-3).is_none());
}

/// The Newmark cases: the built-in models the library integrates with Newmark (a
/// second-order mechanical layout without Coulomb friction: Bouc–Wen only; equation files
/// have no mechanical layout), with zero-order hold and linear interpolation, one and three
/// sub-steps, and ν = 1.5 (|z|^ν by `pow`) at a longer sample time (larger Newton steps).
fn newmark_cases(u: &[f64]) -> Vec<Case> {
    let accepts = |kind: GreyBoxKind| {
        let model = kind.model();
        model.mechanical_dofs().is_some() && model.stick_slip_velocity().is_none()
    };
    assert_eq!(
        GreyBoxKind::ALL
            .into_iter()
            .filter(|k| accepts(*k))
            .collect::<Vec<_>>(),
        [GreyBoxKind::BoucWen],
        "a new built-in model accepts Newmark: add its cases"
    );
    let mut out = Vec::new();
    for (tag, interpolation, substeps) in [
        ("zoh1", InputInterpolation::ZeroOrderHold, 1),
        ("linear3", InputInterpolation::Linear, 3),
    ] {
        let newmark = Simulation {
            integrator: Integrator::Newmark { substeps },
            interpolation,
        };
        let bw = built_in(GreyBoxKind::BoucWen, &[], newmark);
        out.push(case(
            &format!("gb_bouc_wen_newmark_{tag}"),
            &bw,
            scaled(u, 120.0),
            1.0 / 750.0,
        ));
    }
    let stiff = Simulation {
        integrator: Integrator::Newmark { substeps: 2 },
        interpolation: InputInterpolation::Linear,
    };
    let bw = built_in(GreyBoxKind::BoucWen, &[("nu", 1.5)], stiff);
    out.push(case(
        "gb_bouc_wen_newmark_nu",
        &bw,
        scaled(u, 150.0),
        1.0 / 300.0,
    ));
    out
}
