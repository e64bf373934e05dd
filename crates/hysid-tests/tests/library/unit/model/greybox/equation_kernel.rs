//! Tests of `hysid::model::greybox::equation_kernel`.

use hysid::model::greybox::equation_model::EquationStateSpace;
use hysid::model::greybox::native::Evaluator;
use hysid::model::greybox::simulate::{
    simulate, simulate_sensitivities, InputInterpolation, InputTrack, Integrator, Simulation,
};
use hysid::model::greybox::StateSpaceModel;
use hysid::numerics::signal::multisine;

fn load(name: &str) -> EquationStateSpace {
    let path = format!(
        "{}/../../examples/equations/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    EquationStateSpace::load(std::path::Path::new(&path)).unwrap()
}

struct Case<'a> {
    theta: &'a [f64],
    x0: &'a [f64],
    amplitude: f64,
    interpolation: InputInterpolation,
    params: &'a [usize],
    initial: &'a [usize],
}

/// x and S at every sample (or x alone when `sensitivities` is false), RK4 × 4 over a
/// seeded multisine of 512 samples.
fn run(model: &dyn StateSpaceModel, case: &Case<'_>, sensitivities: bool) -> Vec<f64> {
    let u: Vec<f64> = multisine(512, 1, 750.0, 5.0, 150.0, 1.0, 3)
        .unwrap()
        .iter()
        .map(|v| case.amplitude * v)
        .collect();
    let sim = Simulation {
        integrator: Integrator::Rk4 { substeps: 4 },
        interpolation: case.interpolation,
    };
    let track = InputTrack::new(&[&u], &sim).unwrap();
    let ts = 1.0 / 750.0;
    let mut out = Vec::new();
    if sensitivities {
        let ran = simulate_sensitivities(
            model,
            case.theta,
            case.x0,
            &track,
            ts,
            4,
            case.params,
            case.initial,
            |_, x, s| {
                out.extend_from_slice(x);
                out.extend_from_slice(s);
                std::ops::ControlFlow::Continue(())
            },
        )
        .unwrap();
        assert!(ran);
    } else {
        simulate(
            model,
            case.theta,
            case.x0,
            &track,
            ts,
            sim.integrator,
            |_, x| out.extend_from_slice(x),
        )
        .unwrap();
    }
    out
}

/// The fixed-size path (bound tape or its native code, fixed arrays) gives the generic
/// path's x and S to the bit (zeros compared by value): Bouc–Wen at ν = 1 and 1.3 with parameter and
/// initial-state columns, Duffing and the cascaded tanks (two states, estimated initial
/// levels), every input interpolation, with and without sensitivities.
#[test]
fn equation_path_equals_the_generic_path() {
    let bouc_wen = load("bouc_wen.toml");
    let nominal = bouc_wen.parameters().values();
    let mut curved = nominal.clone();
    curved[6] = 1.3;
    let duffing = load("duffing.toml");
    let mut stiff = duffing.parameters().values();
    stiff[3] = 0.5;
    let tanks = load("cascaded_tanks.toml");
    let tanks_theta = tanks.parameters().values();
    let free: Vec<usize> = (0..6).collect();
    let interpolations = [
        InputInterpolation::ZeroOrderHold,
        InputInterpolation::Linear,
        InputInterpolation::BandLimited,
    ];
    let mut cases: Vec<(&EquationStateSpace, Case<'_>)> = Vec::new();
    for interpolation in interpolations {
        for theta in [&nominal, &curved] {
            for (params, initial) in [(&free[..], &[][..]), (&[1, 3, 4, 5, 6], &[0, 2])] {
                let case = Case {
                    theta,
                    x0: &[1e-4, -2e-3, 5e-5],
                    amplitude: 50.0,
                    interpolation,
                    params,
                    initial,
                };
                cases.push((&bouc_wen, case));
            }
        }
        let case = Case {
            theta: &stiff,
            x0: &[0.1, 0.0],
            amplitude: 1.0,
            interpolation,
            params: &[0, 1, 2, 3],
            initial: &[0, 1],
        };
        cases.push((&duffing, case));
        let case = Case {
            theta: &tanks_theta,
            x0: &[5.0, 4.0],
            amplitude: 1.0,
            interpolation,
            params: &[0, 1, 2],
            initial: &[0, 1],
        };
        cases.push((&tanks, case));
    }
    for (model, case) in &cases {
        let generic = crate::unit::generic_path::GenericPath(*model);
        for evaluator in [Evaluator::Tape, Evaluator::Cc] {
            // Each route to native code this machine has, held to the generic path.
            if evaluator.backends().iter().any(|b| !b.available()) {
                continue;
            }
            let model = (*model).clone().with_evaluator(evaluator);
            for sensitivities in [true, false] {
                let fixed = run(&model, case, sensitivities);
                let reference = run(&generic, case, sensitivities);
                assert_eq!(fixed.len(), reference.len());
                for (i, (a, b)) in fixed.iter().zip(&reference).enumerate() {
                    assert!(
                        a.to_bits() == b.to_bits() || (*a == 0.0 && *b == 0.0),
                        "{} {evaluator:?} {:?} {:?}/{:?} sensitivities {sensitivities}, \
                         element {i}: {a} vs {b}",
                        model.name(),
                        case.interpolation,
                        case.params,
                        case.initial
                    );
                }
            }
        }
    }
}
