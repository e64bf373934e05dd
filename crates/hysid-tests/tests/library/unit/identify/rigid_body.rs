//! Tests of `hysid::identify::rigid_body`.

use hysid::identify::rigid_body::*;

/// Noise-free rigid-body data with friction: the regression recovers the parameters to
/// the accuracy of the numerical differentiation.
#[test]
fn recovers_a_simulated_rigid_body() {
    let ts = 1e-3;
    let n = 20_000;
    let (m, fv, fc, off) = (2.0, 3.0, 0.5, -0.2);
    let q: Vec<f64> = (0..n).map(|k| 0.1 * (k as f64 * ts * 2.0).sin()).collect();
    let u: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 * ts;
            let (qd, qdd) = (0.2 * (2.0 * t).cos(), -0.4 * (2.0 * t).sin());
            m * qdd + fv * qd + fc * hysid::numerics::sign0(qd) + off
        })
        .collect();
    let est = RigidBodyLs {
        offset: true,
        decimation: 10,
        border: 50,
        ..RigidBodyLs::default()
    }
    .estimate(&q, &u, ts)
    .unwrap();
    for (got, want) in est.values.iter().zip([m, fv, fc, off]) {
        assert!(
            (got - want).abs() < 2e-3 * want.abs().max(1.0),
            "{:?}",
            est.values
        );
    }
}

#[test]
fn one_way_motion_is_refused() {
    let q: Vec<f64> = (0..5000).map(|k| k as f64 * 1e-3).collect();
    let err = RigidBodyLs::default()
        .estimate(&q, &vec![1.0; 5000], 1e-3)
        .unwrap_err();
    assert!(err.to_string().contains("never changes sign"), "{err}");
}
