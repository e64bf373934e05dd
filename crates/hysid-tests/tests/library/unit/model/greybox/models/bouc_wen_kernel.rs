//! Tests of `hysid::model::greybox::models::bouc_wen_kernel`.

use hysid::model::greybox::models::BoucWen;
use hysid::model::greybox::simulate::{
    simulate, simulate_sensitivities, InputInterpolation, InputTrack, Integrator, Simulation,
};
use hysid::model::greybox::StateSpaceModel;
use hysid::numerics::signal::multisine;

fn run(
    model: &dyn StateSpaceModel,
    theta: &[f64],
    interpolation: InputInterpolation,
    params: &[usize],
    initial: &[usize],
) -> Vec<f64> {
    let u = multisine(1024, 1, 750.0, 5.0, 150.0, 50.0, 7).unwrap();
    let sim = Simulation {
        integrator: Integrator::Rk4 { substeps: 4 },
        interpolation,
    };
    let track = InputTrack::new(&[&u], &sim).unwrap();
    let mut out = Vec::new();
    let x0 = [1e-4, -2e-3, 5e-5];
    let ran = simulate_sensitivities(
        model,
        theta,
        &x0,
        &track,
        1.0 / 750.0,
        4,
        params,
        initial,
        |_, x, s| {
            out.extend_from_slice(x);
            out.extend_from_slice(s);
            std::ops::ControlFlow::Continue(())
        },
    )
    .unwrap();
    assert!(ran);
    out
}

#[test]
fn fixed_path_equals_the_generic_path() {
    let nominal = BoucWen.parameters().values();
    let mut other_nu = nominal.clone();
    other_nu[hysid::model::greybox::models::bouc_wen::NU] = 1.3;
    let columns: [(&[usize], &[usize]); 3] = [
        (&[0, 1, 2, 3, 4, 5], &[]),
        (&[1, 3, 4, 5, 6], &[0, 2]),
        (&[2], &[1]),
    ];
    for theta in [&nominal, &other_nu] {
        for interpolation in [
            InputInterpolation::ZeroOrderHold,
            InputInterpolation::Linear,
            InputInterpolation::BandLimited,
        ] {
            for (params, initial) in columns {
                let fixed = run(&BoucWen, theta, interpolation, params, initial);
                let generic = run(
                    &crate::unit::generic_path::GenericPath(&BoucWen),
                    theta,
                    interpolation,
                    params,
                    initial,
                );
                assert_eq!(fixed.len(), generic.len());
                for (i, (a, b)) in fixed.iter().zip(&generic).enumerate() {
                    assert!(
                        a.to_bits() == b.to_bits(),
                        "{interpolation:?} {params:?}/{initial:?} element {i}: {a} vs {b}"
                    );
                }
            }
        }
    }
}

/// A plain simulation (no sensitivity column) on the fixed-size path gives the generic
/// path's states to the bit: ν = 1 and 1.3, every input interpolation.
#[test]
fn fixed_plain_simulation_equals_the_generic_path() {
    let nominal = BoucWen.parameters().values();
    let mut other_nu = nominal.clone();
    other_nu[hysid::model::greybox::models::bouc_wen::NU] = 1.3;
    let u = multisine(1024, 1, 750.0, 5.0, 150.0, 50.0, 7).unwrap();
    for theta in [&nominal, &other_nu] {
        for interpolation in [
            InputInterpolation::ZeroOrderHold,
            InputInterpolation::Linear,
            InputInterpolation::BandLimited,
        ] {
            let sim = Simulation {
                integrator: Integrator::Rk4 { substeps: 4 },
                interpolation,
            };
            let track = InputTrack::new(&[&u], &sim).unwrap();
            let states = |model: &dyn StateSpaceModel| {
                let mut out = Vec::new();
                let x0 = [1e-4, -2e-3, 5e-5];
                simulate(
                    model,
                    theta,
                    &x0,
                    &track,
                    1.0 / 750.0,
                    sim.integrator,
                    |_, x| out.extend_from_slice(x),
                )
                .unwrap();
                out
            };
            let fixed = states(&BoucWen);
            let generic = states(&crate::unit::generic_path::GenericPath(&BoucWen));
            assert_eq!(fixed.len(), generic.len());
            for (i, (a, b)) in fixed.iter().zip(&generic).enumerate() {
                assert_eq!(
                    a.to_bits(),
                    b.to_bits(),
                    "{interpolation:?} element {i}: {a} vs {b}"
                );
            }
        }
    }
}

/// The fixed-size loop compiled for AVX (where the processor has it) gives the portable
/// loop's bits: Bouc–Wen with parameter and initial-state columns, and a plain simulation,
/// every interpolation.
#[test]
fn avx_loop_equals_the_portable_loop() {
    use hysid::model::greybox::fixed_rk4::with_portable_loop;
    let theta = BoucWen.parameters().values();
    for interpolation in [
        InputInterpolation::ZeroOrderHold,
        InputInterpolation::Linear,
        InputInterpolation::BandLimited,
    ] {
        for (params, initial) in [
            (&[0, 1, 2, 3, 4, 5][..], &[][..]),
            (&[1, 3][..], &[0, 2][..]),
        ] {
            let avx = run(&BoucWen, &theta, interpolation, params, initial);
            let portable =
                with_portable_loop(|| run(&BoucWen, &theta, interpolation, params, initial));
            assert_eq!(avx.len(), portable.len());
            for (i, (a, b)) in avx.iter().zip(&portable).enumerate() {
                assert_eq!(
                    a.to_bits(),
                    b.to_bits(),
                    "{interpolation:?} {params:?} element {i}"
                );
            }
        }
    }
}
