//! Tests of `hysid::report::rigid_body`.

use hysid::identify::rigid_body::{RigidBodyEstimate, RigidBodyLs};
use hysid::report::rigid_body::*;
use serde_json::json;

fn estimate() -> RigidBodyEstimate {
    RigidBodyEstimate {
        names: vec!["M".into(), "Fv".into(), "Fc".into()],
        values: vec![1.5, 20.0, 3.0],
        std: vec![0.01, 0.2, 0.03],
        covariance: Vec::new(),
        relative_std_percent: vec![0.67, 1.0, 1.0],
        relative_error_percent: 2.5,
        condition_number: 4.0,
        condition_number_unscaled: 40.0,
        equations: 1000,
    }
}

/// The estimates go into the built-in model by name; the gain is fixed at the given
/// value and the offset, not estimated, fixed; the preprocessing is saved.
#[test]
fn model_holds_the_estimates_and_fixes_the_rest() {
    let ls = RigidBodyLs {
        gain: 35.15,
        ..RigidBodyLs::emps()
    };
    let file = rigid_body_model(&estimate(), &ls).to_file();
    let p = |name: &str| file.parameters().iter().find(|p| p.name == name).unwrap();
    assert_eq!(file.kind(), "rigid_body");
    assert_eq!(
        (p("M").value, p("M").std, p("M").fixed),
        (1.5, Some(0.01), false)
    );
    assert_eq!((p("Fc").value, p("Fc").std), (3.0, Some(0.03)));
    assert_eq!(
        (p("gain").value, p("gain").fixed, p("gain").std),
        (35.15, true, None)
    );
    assert!(p("offset").fixed);
    let id = file.inverse_dynamics.unwrap();
    assert_eq!(
        (id.cutoff_hz, id.order, id.decimation, id.border),
        (100.0, 4, 10, 50)
    );
}

/// On a noise-free record of the estimated rigid body (a slow sine, u from the analytic
/// derivatives) the predicted drive signal fits to the accuracy of the numerical
/// differentiation, on the decimated samples without the borders.
#[test]
fn report_states_the_fit_of_the_predicted_drive_signal() {
    let (ts, n) = (1e-3, 20_000);
    let q: Vec<f64> = (0..n).map(|k| 0.1 * (2.0 * k as f64 * ts).sin()).collect();
    let u: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 * ts;
            let (qd, qdd) = (0.2 * (2.0 * t).cos(), -0.4 * (2.0 * t).sin());
            1.5 * qdd + 20.0 * qd + 3.0 * hysid::numerics::sign0(qd)
        })
        .collect();
    let ls = RigidBodyLs {
        decimation: 10,
        border: 50,
        ..RigidBodyLs::default()
    };
    let record = RigidBodyRecord {
        source: "a.csv",
        q: &q,
        u: &u,
        ts,
    };
    let r = rigid_body_report(
        &estimate(),
        &ls,
        record,
        &[record],
        0.1,
        json!({"position": "q"}),
    )
    .unwrap();
    assert_eq!(r.command, "rigid-body ls");
    let fit = r.fit.as_ref().unwrap();
    assert!(fit.fit_percent > 99.0, "{}", fit.fit_percent);
    assert_eq!(fit.per_experiment[0].samples, 2000 - 10);
    assert_eq!(r.validation[0].fit_percent, fit.fit_percent);
    assert_eq!(r.details["relative_std_percent"]["Fv"], 1.0);
    assert_eq!(r.details["settings"]["cutoff_hz"], 100.0);
    assert_eq!(r.details["settings"]["position"], "q");
    assert_eq!(r.details["condition_number"], 40.0);
    assert_eq!(r.data.as_ref().map(|d| d.samples), Some(n));
    assert!(r.to_json().is_ok());
}
