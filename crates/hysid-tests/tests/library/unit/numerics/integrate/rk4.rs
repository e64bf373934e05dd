//! Tests of `hysid::numerics::integrate::rk4`.

use hysid::numerics::integrate::rk4::*;

/// ẋ = λx: one step multiplies by the degree-4 Taylor polynomial of e^(λh).
#[test]
fn one_step_is_the_fourth_order_taylor_polynomial() {
    let (lambda, h) = (-0.7, 0.3);
    let mut rk = Rk4::new(1);
    let mut x = [2.0];
    rk.step(&mut |_, x, dx| dx[0] = lambda * x[0], &mut x, 0.0, h, true);
    let z: f64 = lambda * h;
    let taylor = 1.0 + z + z * z / 2.0 + z.powi(3) / 6.0 + z.powi(4) / 24.0;
    assert!((x[0] - 2.0 * taylor).abs() < 1e-15, "{}", x[0]);
}

/// ẋ = t³ is integrated exactly (RK4 is exact for polynomials of degree ≤ 3 in t), and
/// the stages see the nodes and offsets of the step.
#[test]
fn integrates_a_cubic_exactly_and_reports_its_nodes() {
    let mut rk = Rk4::new(1);
    let mut seen = Vec::new();
    let mut x = [0.0];
    let (t0, h) = (0.5, 0.25);
    rk.step(
        &mut |s: Stage, _, dx| {
            seen.push(s);
            dx[0] = s.dt.powi(3);
        },
        &mut x,
        t0,
        h,
        false,
    );
    let exact = ((t0 + h).powi(4) - t0.powi(4)) / 4.0;
    assert!((x[0] - exact).abs() < 1e-15);
    assert_eq!(seen.len(), 4);
    assert!(seen.iter().all(|s| s.node.is_none()));
    assert_eq!(seen[1].dt, t0 + 0.5 * h);
    rk.step(
        &mut |s: Stage, _, dx| {
            seen.push(s);
            dx[0] = 0.0;
        },
        &mut x,
        0.0,
        h,
        true,
    );
    let nodes: Vec<_> = seen[4..].iter().map(|s| s.node).collect();
    assert_eq!(nodes, [Some(0), Some(1), Some(1), Some(2)]);
}
