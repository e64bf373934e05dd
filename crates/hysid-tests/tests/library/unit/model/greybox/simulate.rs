//! Tests of `hysid::model::greybox::simulate`.

use hysid::model::greybox::simulate::*;

#[test]
fn zero_order_hold_holds_to_the_end_of_the_interval() {
    let sim = Simulation::default();
    let track = InputTrack::new(&[&[1.0, 2.0, 3.0]], &sim).unwrap();
    let mut u = [0.0];
    track.at(0, 1.0, &mut u);
    assert_eq!(u[0], 1.0);
    let lin = InputTrack::new(
        &[&[1.0, 2.0, 3.0]],
        &Simulation {
            interpolation: InputInterpolation::Linear,
            ..sim
        },
    )
    .unwrap();
    lin.at(1, 0.25, &mut u);
    assert_eq!(u[0], 2.25);
}

mod integrator_tests {
    use hysid::model::greybox::simulate::*;

    use hysid::model::greybox::models::BoucWen;
    use hysid::numerics::signal::multisine;

    /// Bouc–Wen driven by one benchmark-like multisine period at 750 Hz.
    fn run(integrator: Integrator, interpolation: InputInterpolation) -> Vec<f64> {
        let u = multisine(2048, 1, 750.0, 5.0, 150.0, 50.0, 4).unwrap();
        let sim = Simulation {
            integrator,
            interpolation,
        };
        let track = InputTrack::new(&[&u], &sim).unwrap();
        let theta = hysid::model::greybox::StateSpaceModel::parameters(&BoucWen).values();
        let mut y = Vec::new();
        simulate(
            &BoucWen,
            &theta,
            &[0.0; 3],
            &track,
            1.0 / 750.0,
            integrator,
            |_, x| y.push(x[0]),
        )
        .unwrap();
        y
    }

    fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        a.iter()
            .zip(b)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max)
            / scale
    }

    /// Stated tolerances against Dormand–Prince at rtol 1e-10: RK4 with 20 sub-steps (15 kHz)
    /// within 5e-5 of the peak output and converging (the |ẏ| and |z| kinks of the model cut
    /// RK4's order to about 2 there), Newmark (second order) with 20 sub-steps within 2e-2
    /// and with 200 within 2e-4.
    #[test]
    fn rk4_and_newmark_agree_with_the_adaptive_reference() {
        for interpolation in [
            InputInterpolation::ZeroOrderHold,
            InputInterpolation::Linear,
        ] {
            let reference = run(
                Integrator::Adaptive {
                    rtol: 1e-10,
                    atol: 1e-14,
                },
                interpolation,
            );
            let rk4 = relative_difference(
                &run(Integrator::Rk4 { substeps: 20 }, interpolation),
                &reference,
            );
            let rk4_fine = relative_difference(
                &run(Integrator::Rk4 { substeps: 80 }, interpolation),
                &reference,
            );
            assert!(rk4 < 5e-5, "{interpolation:?} RK4: {rk4:e}");
            assert!(
                rk4_fine < rk4 / 8.0,
                "{interpolation:?} RK4 converges: {rk4:e} → {rk4_fine:e}"
            );
            let newmark20 = relative_difference(
                &run(Integrator::Newmark { substeps: 20 }, interpolation),
                &reference,
            );
            let newmark200 = relative_difference(
                &run(Integrator::Newmark { substeps: 200 }, interpolation),
                &reference,
            );
            assert!(
                newmark20 < 2e-2,
                "{interpolation:?} Newmark 20: {newmark20:e}"
            );
            assert!(
                newmark200 < 2e-4,
                "{interpolation:?} Newmark 200: {newmark200:e}"
            );
            assert!(
                newmark200 < newmark20 / 50.0,
                "second order: {newmark20:e} → {newmark200:e}"
            );
        }
    }
}
