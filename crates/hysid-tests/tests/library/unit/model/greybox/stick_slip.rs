//! Tests of `hysid::model::greybox::stick_slip`.

use hysid::model::greybox::models::sign0;
use hysid::model::greybox::stick_slip::*;
use hysid::numerics::integrate::Stage;

/// A unit mass with Coulomb friction 1 under a constant force f.
fn block(f: f64) -> impl FnMut(Stage, &[f64], Option<f64>, &mut [f64]) {
    move |_: Stage, x: &[f64], held: Option<f64>, dx: &mut [f64]| {
        let friction = match held {
            Some(d) => d,
            None if x[1] != 0.0 => sign0(x[1]),
            None => f.clamp(-1.0, 1.0),
        };
        dx[0] = x[1];
        dx[1] = f - friction;
    }
}

fn run(f: f64, h: f64, steps: usize, velocity: Option<usize>) -> [f64; 2] {
    let mut rk = StickSlip::new(2);
    let mut rate = block(f);
    let mut x = [0.0, 1.0];
    for _ in 0..steps {
        rk.step(&mut rate, &mut x, h, velocity, None);
    }
    x
}

#[test]
fn a_sliding_block_stops_and_sticks() {
    // Deceleration 0.5 from speed 1: stops after 2 s, having moved 1.
    let x = run(0.5, 0.3, 20, Some(1));
    assert_eq!(x[1], 0.0);
    assert!((x[0] - 1.0).abs() < 1e-12, "{}", x[0]);
}

#[test]
fn without_events_rk4_chatters() {
    let x = run(0.5, 0.3, 20, None);
    assert!(x[1] != 0.0);
}

#[test]
fn a_force_beyond_friction_reverses_the_block() {
    // Deceleration 3 until rest at t = 1/3 (x = 1/6), then acceleration −1.
    let x = run(-2.0, 0.05, 40, Some(1));
    let t: f64 = 2.0 - 1.0 / 3.0;
    assert!((x[1] + t).abs() < 1e-12, "{}", x[1]);
    assert!((x[0] - (1.0 / 6.0 - 0.5 * t * t)).abs() < 1e-12, "{}", x[0]);
}
