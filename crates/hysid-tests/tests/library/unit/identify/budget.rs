//! Tests of `hysid::identify::budget`.

use hysid::identify::budget::*;
use hysid::identify::cascade::CascadeIdentification;
use hysid::identify::greybox::GreyBoxEstimation;
use hysid::identify::Uncertainty;
use hysid::model::coleman_hodgdon::ChForm;
use hysid::model::greybox::Simulation;
use hysid::model::greybox::{InputInterpolation, Integrator};

#[test]
fn a_simulation_counts_its_steps_and_states() {
    // 1000 samples, 4 sub-steps, 1 input, 2 states, 3 parameters, zero-order hold:
    // 8 · 1000 · (1 + 2·4 + 3 + 4) bytes, 4000 steps.
    let w = simulation(1000, 4, 1, 2, 3, false);
    assert_eq!(w.bytes, 8 * 1000 * 16);
    assert_eq!(w.evaluations, 4000);
    // Band-limited: 3 · s · c more words per sample.
    let b = simulation(1000, 4, 1, 2, 3, true);
    assert_eq!(b.bytes, 8 * 1000 * (12 + 8 + 3 + 4));
}

#[test]
fn absurd_requests_saturate_instead_of_overflowing() {
    let w = simulation(usize::MAX, usize::MAX, 1, 7, 7, true);
    assert_eq!(w.bytes, u64::MAX);
    assert_eq!(w.evaluations, u64::MAX);
}

#[test]
fn the_bouc_wen_benchmark_at_10000_substeps_needs_gigabytes() {
    // The case: 40 960 samples, band-limited input, 10 000 sub-steps.
    let est = GreyBoxEstimation {
        simulation: Simulation {
            integrator: Integrator::Rk4 { substeps: 10_000 },
            interpolation: InputInterpolation::BandLimited,
        },
        ..GreyBoxEstimation::default()
    };
    let w = est.work_estimate(40_960, 1, 3, 5);
    assert!(w.bytes > 9_000_000_000, "{}", w.bytes);
    let small = GreyBoxEstimation::default().work_estimate(40_960, 1, 3, 5);
    assert!(small.bytes < 100_000_000, "{}", small.bytes);
}

#[test]
fn bootstrap_replicates_multiply_the_cascade_work() {
    let mut id = CascadeIdentification::new(ChForm::Saturated4, 2, 2, 1);
    let once = id.work_estimate(2000);
    id.uncertainty = Uncertainty::Bootstrap(9);
    let ten = id.work_estimate(2000);
    assert_eq!(ten.evaluations, once.evaluations * 10);
    assert_eq!(ten.bytes, once.bytes);
}
