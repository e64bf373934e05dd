//! Tests of `hysid::experiments::actuator_rig`.

use hysid::experiments::actuator_rig::*;
use hysid::model::greybox::models::ActuatorFixed;
use hysid::model::greybox::simulate::rk4_step;

#[test]
fn loop_amplitudes_span_the_papers_torques() {
    let q = Rig::default().loop_amplitudes();
    assert!(q.windows(2).all(|w| w[0] < w[1]));
    assert!(
        (0.04..0.05).contains(&q[0]) && (0.09..0.1).contains(&q[3]),
        "{q:?}"
    );
}

/// Without backlash and noise the saddle-fixed records are exactly the identification
/// model's simulation.
#[test]
fn torque_sets_match_the_identification_model() {
    let rig = Rig {
        angle_noise: 0.0,
        torque_noise: 0.0,
        ..Rig::default()
    };
    let record = rig.record(6).unwrap();
    let mut x = [0.0; 3];
    let theta = rig.truth.clone();
    for (k, (&tau, &angle)) in record.torque.iter().zip(&record.angle).enumerate() {
        assert!((x[0] - angle).abs() < 1e-15, "sample {k}");
        for _ in 0..rig.substeps {
            rk4_step(&ActuatorFixed, &theta, 0.0, &mut x, &[tau], 1e-4);
        }
    }
}

#[test]
fn controlled_sets_follow_their_references() {
    let rig = Rig {
        angle_noise: 0.0,
        torque_noise: 0.0,
        ..Rig::default()
    };
    let loops = rig.record(3).unwrap();
    let q = rig.loop_amplitudes()[1];
    let peak = loops.angle.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!((peak / q - 1.0).abs() < 0.02, "{peak} vs {q}");
    let speed_run = rig.record(1).unwrap();
    let speed = hysid::numerics::signal::gradient(&speed_run.angle, speed_run.ts);
    let max_speed = speed.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!((max_speed / 210.0 - 1.0).abs() < 0.05, "{max_speed}");
}
