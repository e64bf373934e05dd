//! Tests of `hysid::model::greybox::models`.

mod bouc_wen_kernel;

use hysid::model::greybox::models::*;
use hysid::model::greybox::StateSpaceModel;

/// ∂f/∂x and ∂f/∂θ of a model against central differences of f at a few points; for a
/// model with Coulomb friction also with the friction held in either direction.
fn check_jacobians(model: &dyn StateSpaceModel, points: &[(Vec<f64>, Vec<f64>)], theta: &[f64]) {
    let mut modes = vec![None];
    if model.stick_slip_velocity().is_some() {
        modes.extend([Some(1.0), Some(-1.0)]);
    }
    for held in modes {
        check_jacobians_held(model, points, theta, held);
    }
}

fn check_jacobians_held(
    model: &dyn StateSpaceModel,
    points: &[(Vec<f64>, Vec<f64>)],
    theta: &[f64],
    held: Option<f64>,
) {
    let n = model.states().len();
    let p = theta.len();
    for (x, u) in points {
        let (mut fx, mut ft) = (vec![0.0; n * n], vec![0.0; n * p]);
        let provided = match held {
            None => model.rhs_jacobians(0.0, x, u, theta, &mut fx, &mut ft),
            Some(d) => model.rhs_jacobians_sliding(0.0, x, u, theta, d, &mut fx, &mut ft),
        };
        assert!(provided);
        let f = |x: &[f64], th: &[f64]| {
            let mut dx = vec![0.0; n];
            match held {
                None => model.rhs(0.0, x, u, th, &mut dx),
                Some(d) => model.rhs_sliding(0.0, x, u, th, d, &mut dx),
            }
            dx
        };
        for j in 0..n {
            let h = 1e-6 * x[j].abs().max(1e-3);
            let (mut hi, mut lo) = (x.clone(), x.clone());
            hi[j] += h;
            lo[j] -= h;
            let (a, b) = (f(&hi, theta), f(&lo, theta));
            for i in 0..n {
                let fd = (a[i] - b[i]) / (2.0 * h);
                let an = fx[i * n + j];
                assert!(
                    (fd - an).abs() <= 1e-6 * an.abs().max(1.0),
                    "{} ({held:?}) ∂f{i}/∂x{j} at {x:?}: {fd} vs {an}",
                    model.kind()
                );
            }
        }
        for j in 0..p {
            let h = 1e-6 * theta[j].abs().max(1e-3);
            let (mut hi, mut lo) = (theta.to_vec(), theta.to_vec());
            hi[j] += h;
            lo[j] -= h;
            let (a, b) = (f(x, &hi), f(x, &lo));
            for i in 0..n {
                let fd = (a[i] - b[i]) / (2.0 * h);
                let an = ft[i * p + j];
                assert!(
                    (fd - an).abs() <= 1e-6 * an.abs().max(1.0),
                    "{} ({held:?}) ∂f{i}/∂θ{j} at {x:?}: {fd} vs {an}",
                    model.kind()
                );
            }
        }
    }
}

#[test]
fn bouc_wen_jacobians_agree_with_differences() {
    let points = vec![
        (vec![1e-3, 0.05, 20.0], vec![30.0]),
        (vec![-2e-3, -0.08, -35.0], vec![-12.0]),
        (vec![4e-4, -0.02, 5.0], vec![0.0]),
    ];
    check_jacobians(&BoucWen, &points, &BoucWen.parameters().values());
    // With a free exponent ν ≠ 1 too.
    let mut theta = BoucWen.parameters().values();
    theta[6] = 1.3;
    check_jacobians(&BoucWen, &points, &theta);
}

#[test]
fn actuator_jacobians_agree_with_differences() {
    let fixed_points = vec![
        (vec![0.03, 0.4, 0.2], vec![0.8]),
        (vec![-0.05, -1.2, -0.3], vec![-0.2]),
    ];
    check_jacobians(
        &ActuatorFixed,
        &fixed_points,
        &ActuatorFixed.parameters().values(),
    );
    let free_points = vec![
        (vec![0.03, 0.4, 2e-4, 0.2], vec![0.8]),
        (vec![-0.05, -1.2, -1e-3, -0.3], vec![-0.2]),
    ];
    check_jacobians(
        &ActuatorFree,
        &free_points,
        &ActuatorFree.parameters().values(),
    );
}

#[test]
fn rigid_body_jacobians_agree_with_differences() {
    let points = vec![(vec![0.1, 0.3], vec![2.0]), (vec![-0.2, -0.5], vec![-1.0])];
    check_jacobians(&RigidBody, &points, &[95.0, 200.0, 20.0, -3.0, 35.0]);
}
