//! Tests of `hysid::model::operators::differential`.

use hysid::model::operators::differential::*;

/// dx/du = 1 − δ·x, y = x: the exact branch solution is known in closed form.
struct Relax;
impl InputOde for Relax {
    fn slope(&self, _u: f64, x: f64, d: f64) -> f64 {
        1.0 - d * x
    }
    fn output(&self, _u: f64, x: f64) -> f64 {
        x
    }
    fn initial_state(&self) -> f64 {
        0.0
    }
    fn state_scale(&self) -> f64 {
        1.0
    }
    fn max_substep(&self) -> f64 {
        0.5
    }
    fn inversion_span(&self) -> f64 {
        40.0
    }
}

#[test]
fn branch_matches_the_closed_form_whatever_the_sampling() {
    // Ascending from x = 0: x(u) = 1 − e^{−u}.
    let coarse = simulate(&Relax, &[0.0, 3.0]).unwrap();
    let fine: Vec<f64> = (0..=3000).map(|k| k as f64 * 1e-3).collect();
    let fine = simulate(&Relax, &fine).unwrap();
    let exact = 1.0 - (-3.0f64).exp();
    assert!((coarse[1] - exact).abs() < 1e-9, "{}", coarse[1]);
    assert!((fine[3000] - exact).abs() < 1e-9, "{}", fine[3000]);
}

#[test]
fn inverse_reproduces_a_reachable_reference_and_clips_the_rest() {
    let u: Vec<f64> = (0..400)
        .map(|k| 3.0 * (k as f64 * 0.05).sin() * (1.0 - k as f64 / 800.0))
        .collect();
    let r = simulate(&Relax, &u).unwrap();
    let inv = invert(&Relax, &r).unwrap();
    assert!(inv.clipped.is_empty(), "{:?}", inv.clipped);
    let y = simulate(&Relax, &inv.u).unwrap();
    let worst = y
        .iter()
        .zip(&r)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "{worst}");
    // |x| < 1 always for this operator: 1.5 is out of reach.
    let inv = invert(&Relax, &[0.0, 0.5, 1.5, 0.2]).unwrap();
    assert_eq!(inv.clipped, vec![2]);
    assert!((inv.predicted[3] - 0.2).abs() < 1e-12);
}

#[test]
fn orientation_from_the_loop_area() {
    let t: Vec<f64> = (0..100).map(|k| k as f64 * 0.0628).collect();
    let u: Vec<f64> = t.iter().map(|t| t.sin()).collect();
    let lag: Vec<f64> = t.iter().map(|t| (t - 0.3).sin()).collect();
    let lead: Vec<f64> = t.iter().map(|t| (t + 0.3).sin()).collect();
    assert_eq!(
        LoopOrientation::of_loop(&u, &lag),
        LoopOrientation::CounterClockwise
    );
    assert_eq!(
        LoopOrientation::of_loop(&u, &lead),
        LoopOrientation::Clockwise
    );
}

#[test]
fn nan_input_is_an_error() {
    assert!(simulate(&Relax, &[0.0, f64::NAN]).is_err());
    assert!(invert(&Relax, &[]).is_err());
}

/// The sensitivities carried through the Runge–Kutta steps against central differences of
/// the simulation, for every family and parameter. To 0.1 % of each column's size: a step
/// across a kink of the slope (|w| at w = 0 when n = 1, a reversal's switch) differentiates
/// the stages it took, which the differences of two adaptive integrations only approximate.
#[test]
fn integrated_sensitivities_match_central_differences() {
    use hysid::model::operators::{
        BoucWen, Dahl, Duhem, HysteresisOperator, JaOutput, JilesAtherton, LoopOrientation,
    };
    fn check<M: InputOdeSensitivity + HysteresisOperator>(
        make: &dyn Fn(&[f64]) -> M,
        theta: &[f64],
        u: &[f64],
    ) {
        let m = make(theta);
        let p = m.n_parameters();
        assert_eq!(p, theta.len());
        let mut sens = vec![vec![0.0; u.len()]; p];
        let mut yhat = vec![0.0; u.len()];
        simulate_with_sensitivities(&m, u, TOLERANCE, |k, y, d| {
            yhat[k] = y;
            for j in 0..p {
                sens[j][k] = d[j];
            }
        })
        .unwrap();
        assert_eq!(yhat, m.simulate(u).unwrap(), "the same path as simulate");
        for j in 0..p {
            // Steps large enough that the integration error (1e-10) does not swamp them.
            let h = 1e-3 * theta[j].abs().max(1e-3);
            let mut t = theta.to_vec();
            t[j] += h;
            let up = make(&t).simulate(u).unwrap();
            t[j] -= 2.0 * h;
            // On a bound (n = 1): a forward difference.
            let (down, h) = match make(&t).simulate(u) {
                Ok(down) => (down, h),
                Err(_) => (yhat.clone(), 0.5 * h),
            };
            let scale = sens[j].iter().fold(1e-12f64, |a, v| a.max(v.abs()));
            for k in 0..u.len() {
                let fd = (up[k] - down[k]) / (2.0 * h);
                assert!(
                    (fd - sens[j][k]).abs() <= 1e-3 * scale,
                    "{} parameter {j} sample {k}: {} vs {fd}",
                    m.family(),
                    sens[j][k]
                );
            }
        }
    }
    let tau = std::f64::consts::TAU;
    let u: Vec<f64> = (0..600)
        .map(|k| {
            let t = k as f64 / 600.0;
            (1.0 - 0.6 * t) * (tau * 2.0 * t).sin() + 0.2 * (tau * 11.0 * t).sin()
        })
        .collect();
    let bw = |t: &[f64]| BoucWen {
        kx: t[0],
        kw: t[1],
        a: t[2],
        beta: t[3],
        gamma: t[4],
        n: t[5],
        w0: t[6],
    };
    check(&bw, &[0.8, -1.2, 1.0, 2.0, 0.5, 1.6, 0.05], &u);
    check(&bw, &[0.8, 1.2, 1.0, 2.0, -0.5, 1.0, 0.05], &u);
    let duhem = |t: &[f64]| Duhem {
        alpha: t[0],
        a: t[1],
        b: t[2],
        c: t[3],
        y0: t[4],
    };
    check(&duhem, &[3.0, 1.5, 0.2, 0.4, -0.1], &u);
    for orientation in [
        LoopOrientation::Clockwise,
        LoopOrientation::CounterClockwise,
    ] {
        let dahl = move |t: &[f64]| Dahl {
            sigma: t[0],
            fc: t[1],
            i: t[2],
            f0: t[3],
            orientation,
        };
        check(&dahl, &[12.0, 2.0, 1.8, 0.3], &u);
        let ja = move |t: &[f64]| {
            let mut m = JilesAtherton::new(t[0], t[1], t[2], t[3], t[4]).unwrap();
            m.m0 = t[5];
            m.orientation = orientation;
            m.output = JaOutput::Magnetisation;
            m
        };
        let h: Vec<f64> = u.iter().map(|v| 40.0 * v).collect();
        check(&ja, &[2.5e5, 8.0, 5.0, 0.3, 5e-6, 1e4], &h);
    }
}
