//! Tests of `hysid::model::coleman_hodgdon`.

use hysid::model::coleman_hodgdon::*;
use hysid::Error;

/// The recursion test vector of docs/models/coleman-hodgdon-cascade.md §14
/// (6-parameter set, y(0) = 0).
#[test]
fn recursion_test_vector() {
    let ch = ColemanHodgdon::general(0.5, 1.0, 0.2, 0.5, 0.2, 3.0).unwrap();
    let x = [
        0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 3.5, 3.0, 2.0, 1.0, 0.0, -1.0,
    ];
    let expected = [
        0.0,
        0.375,
        0.78125,
        1.2109375,
        1.658203125,
        2.1186523438,
        2.5889892578,
        2.8167419434,
        3.0125564575,
        2.9344173431,
        2.7008130074,
        1.8504065037,
        0.9252032518,
        -0.0373983741,
        -1.0186991870,
    ];
    let y = ch.simulate(&x, 0.0).unwrap();
    for (t, (&got, &want)) in y.iter().zip(&expected).enumerate() {
        // The table is printed to 10 decimals: 0.5e-10 is its rounding.
        assert!((got - want).abs() < 1e-9, "t = {t}: {got} vs {want}");
    }
}

#[test]
fn separated_form_reproduces_recursion() {
    for ch in [
        ColemanHodgdon::general(0.4, 1.2, 0.15, 0.6, 0.1, 2.0).unwrap(),
        ColemanHodgdon::saturated(0.3, 1.0, 0.5, 3.0).unwrap(),
    ] {
        let x: Vec<f64> = (0..200).map(|t| 4.0 * (t as f64 * 0.11).sin()).collect();
        let y = ch.simulate(&x, 0.0).unwrap();
        let theta = ch.separated_params();
        let mut phi = vec![0.0; theta.len()];
        for t in 1..x.len() {
            ColemanHodgdon::separated_regressor(
                ch.form(),
                ch.d(),
                x[t - 1],
                x[t],
                y[t - 1],
                &mut phi,
            );
            let dy: f64 = phi.iter().zip(&theta).map(|(a, b)| a * b).sum();
            assert!((y[t] - y[t - 1] - dy).abs() < 1e-12);
        }
        let back = ColemanHodgdon::from_separated(ch.form(), &theta).unwrap();
        for (a, b) in back.params().iter().zip(ch.params()) {
            assert!((a - b).abs() < 1e-12);
        }
    }
}

#[test]
fn step_partials_match_finite_differences() {
    let ch = ColemanHodgdon::general(0.4, 1.2, 0.15, 0.6, 0.1, 2.0).unwrap();
    for &(yp, xp, x) in &[
        (0.3, 1.0, 1.4),
        (1.1, 2.5, 2.2),
        (-0.7, -1.9, -2.6),
        (0.0, 0.0, 0.3),
    ] {
        let mut partials = [0.0; 6];
        let dy_prev = ch.step_partials(yp, xp, x, &mut partials);
        let p = ch.params();
        for (j, &analytic) in partials.iter().enumerate() {
            let h = 1e-7;
            let mut hi = p.clone();
            hi[j] += h;
            let mut lo = p.clone();
            lo[j] -= h;
            let fd = (ColemanHodgdon::from_params(ChForm::General6, &hi)
                .unwrap()
                .step(yp, xp, x)
                - ColemanHodgdon::from_params(ChForm::General6, &lo)
                    .unwrap()
                    .step(yp, xp, x))
                / (2.0 * h);
            assert!(
                (fd - analytic).abs() < 1e-7,
                "param {j}: {fd} vs {analytic}"
            );
        }
        let fd = (ch.step(yp + 1e-7, xp, x) - ch.step(yp - 1e-7, xp, x)) / 2e-7;
        assert!((fd - dy_prev).abs() < 1e-7);
    }
}

#[test]
fn rate_limit_is_reported() {
    let ch = ColemanHodgdon::saturated(0.3, 1.0, 0.5, 3.0).unwrap();
    let err = ch.simulate(&[0.0, 1.0, 5.0], 0.0).unwrap_err();
    assert!(matches!(err, Error::RateLimit { index: 2, .. }), "{err}");
}

#[test]
fn admissibility_of_project_examples() {
    assert!(
        ColemanHodgdon::saturated(0.3, 1.0, 0.5, 3.0)
            .unwrap()
            .admissibility()
            .holds
    );
    assert!(
        ColemanHodgdon::general(0.4, 1.2, 0.15, 0.6, 0.1, 2.0)
            .unwrap()
            .admissibility()
            .holds
    );
    let bad = ColemanHodgdon::general(0.4, 1.0, 0.1, 1.2, 0.3, 2.0)
        .unwrap()
        .admissibility();
    assert!(!bad.holds);
    assert_eq!(bad.violations.len(), 2);
}

#[test]
fn invalid_parameters_are_refused() {
    assert!(ColemanHodgdon::saturated(0.0, 1.0, 0.5, 3.0).is_err());
    assert!(ColemanHodgdon::saturated(0.3, 1.0, 0.5, -1.0).is_err());
    assert!(ColemanHodgdon::general(0.3, f64::NAN, 0.1, 0.5, 0.1, 1.0).is_err());
}
