//! Tests of `hysid::model::record_filters`.

use hysid::model::record_filters::*;
use hysid::numerics::sign0;

/// A noise-free rigid body, u = (M q̈ + Fv q̇ + Fc sgn q̇ + offset)/g with analytic
/// derivatives of a slow sine: the prediction matches the reduced u to the accuracy of
/// the numerical differentiation.
#[test]
fn inverse_dynamics_predicts_a_known_rigid_body() {
    let (ts, n) = (1e-3, 20_000);
    let p = RigidBodyValues {
        inertia: 2.0,
        fv: 3.0,
        fc: 0.5,
        offset: -0.2,
        gain: 4.0,
    };
    let q: Vec<f64> = (0..n).map(|k| 0.1 * (2.0 * k as f64 * ts).sin()).collect();
    let u: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 * ts;
            let (qd, qdd) = (0.2 * (2.0 * t).cos(), -0.4 * (2.0 * t).sin());
            (p.inertia * qdd + p.fv * qd + p.fc * sign0(qd) + p.offset) / p.gain
        })
        .collect();
    let id = InverseDynamics {
        cutoff_hz: 100.0,
        order: 4,
        decimation: 10,
        border: 50,
    };
    let (qr, u_hat) = id.predict(&p, &q, ts).unwrap();
    let u_ref = id.reduce(&u).unwrap();
    assert_eq!((qr.len(), u_hat.len()), (u_ref.len(), u_ref.len()));
    assert_eq!(u_hat.len(), 2000 - 10);
    let fit = hysid::numerics::metrics::fit_percent(&u_ref, &u_hat);
    assert!(fit > 99.0, "fit {fit} %");
}

/// Mean removal alone subtracts the mean; a cut-off at or above Nyquist is refused.
#[test]
fn prefilter_removes_the_mean_and_checks_the_cut_off() {
    let f = Prefilter {
        remove_mean: true,
        cutoff_hz: None,
        order: 4,
    };
    assert_eq!(
        f.apply(&[1.0, 2.0, 3.0], 0.1).unwrap(),
        vec![-1.0, 0.0, 1.0]
    );
    let f = Prefilter {
        cutoff_hz: Some(5.0),
        ..f
    };
    assert!(f.apply(&[1.0; 100], 0.1).is_err());
}
