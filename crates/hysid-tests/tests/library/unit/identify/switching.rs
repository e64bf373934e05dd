//! Tests of `hysid::identify::switching`.

use hysid::identify::switching::*;

#[test]
fn truncated_normal_limits() {
    // Wide normal over a narrow interval: uniform, mean the midpoint, std width/√12.
    let (m, s) = truncated_normal(1.0, 100.0, 1.0, 1.2);
    assert!(
        (m - 1.1).abs() < 1e-4 && (s - 0.2 / 12f64.sqrt()).abs() < 1e-4,
        "{m} {s}"
    );
    // Narrow normal inside a wide interval: untouched.
    let (m, s) = truncated_normal(1.0, 1e-3, 0.0, 2.0);
    assert!((m - 1.0).abs() < 1e-12 && (s - 1e-3).abs() < 1e-9);
    // Half-infinite interval: the half-normal mean s·√(2/π).
    let (m, _) = truncated_normal(0.0, 1.0, 0.0, f64::INFINITY);
    assert!((m - (2.0 / std::f64::consts::PI).sqrt()).abs() < 1e-6);
    assert!((normal_cdf(1.0) - 0.841_344_746).abs() < 1e-7);
}

/// A long noisy record of Example 1 (pipelined passes), the output-error structure with the
/// switching frozen by `h`, and a start near the truth whose d classifies differently.
fn long_fit() -> (
    hysid::data::IdData,
    impl Fn(Option<Switching>) -> hysid::identify::cascade::CascadeStructure + Sync,
    hysid::model::ParameterSet,
) {
    use hysid::identify::cascade_pass::PIPELINE_SAMPLES;
    let ex =
        hysid::experiments::voros::CascadeExample::example1().extended(PIPELINE_SAMPLES + 4_321);
    let data = ex.generate(3, true).unwrap().id_data().unwrap();
    let structure = super::true_structure(&ex);
    let mut theta = ex.truth.params();
    for (i, v) in theta.iter_mut().enumerate() {
        *v *= 1.0 + 0.004 * (i as f64 + 1.0);
    }
    let params = structure.parameter_set(&theta, &data);
    let make = move |switching| hysid::identify::cascade::CascadeStructure {
        switching,
        ..structure.clone()
    };
    (data, make, params)
}

/// The output-error estimator the cascade's final fits use.
fn near_start_estimator() -> hysid::identify::output_error::OutputError {
    use hysid::numerics::levenberg_marquardt::LmConfig;
    hysid::identify::output_error::OutputError {
        config: LmConfig {
            initial_damping: 1e-8,
            ..LmConfig::default()
        },
        ..Default::default()
    }
}

/// A companion run beside a long record's last trial pass sees that point, on one thread,
/// and changes nothing: the fit is the one without it, bit for bit, with the same passes.
/// The start computed on one thread is the one computed on two.
#[test]
fn a_companion_sees_the_last_trial_point_and_changes_nothing() {
    use hysid::numerics::levenberg_marquardt::Control;
    let (data, make, params) = long_fit();
    let estimator = near_start_estimator();
    let h = classify(&data, params.get(params.index_of("d").unwrap()).value);
    let model = make(Some(h));
    let plain = estimator
        .estimate_from(&model, &data, &params, None, &mut |_| Control::Continue)
        .unwrap();
    let seen = std::sync::Mutex::new(Vec::new());
    let companion = |theta: &[f64], threads: usize| {
        seen.lock().unwrap().push((theta.to_vec(), threads));
    };
    let beside = estimator
        .estimate_beside(&model, &data, &params, None, Some(&companion), &mut |_| {
            Control::Continue
        })
        .unwrap();
    assert_eq!(beside.parameters.values(), plain.parameters.values());
    assert_eq!(beside.report.cost.to_bits(), plain.report.cost.to_bits());
    assert_eq!(beside.std(), plain.std());
    assert_eq!(
        beside.report.sensitivity_evaluations,
        plain.report.sensitivity_evaluations
    );
    let seen = seen.into_inner().unwrap();
    if rayon::current_num_threads() >= 2 {
        let (last, threads) = seen
            .last()
            .expect("the last trial point is near the minimum");
        assert_eq!(*last, beside.parameters.values());
        assert_eq!(*threads, 1);
    }
    let final_d = beside.parameters.get(params.index_of("d").unwrap()).value;
    let next = make(Some(classify(&data, final_d)));
    let on = |threads| {
        estimator
            .start_on(&next, &data, &beside.parameters, threads)
            .unwrap()
            .map(|s| s.cost().to_bits())
    };
    assert_eq!(on(1), on(2));
}

/// The switching fixed point on a long record, which computes each next start beside the
/// fit's last trial pass, ends where the same fixed point does inside a one-thread pool (no
/// pipelined passes, nothing beside them): the same fits, bit for bit.
#[test]
fn the_fixed_point_with_starts_computed_ahead_equals_the_plain_one() {
    use hysid::numerics::levenberg_marquardt::Control;
    let (data, make, params) = long_fit();
    let estimator = near_start_estimator();
    let run = || {
        fit_with_switching_updates(&make, &data, &params, &estimator, 0, &mut |_| {
            Control::Continue
        })
        .unwrap()
    };
    let ahead = run();
    let plain = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(run);
    assert!(
        ahead.fits >= 2,
        "the start must re-classify: {} fit(s)",
        ahead.fits
    );
    assert_eq!(ahead.fits, plain.fits);
    assert_eq!(ahead.consistent, plain.consistent);
    assert_eq!(ahead.fit.parameters.values(), plain.fit.parameters.values());
    assert_eq!(
        ahead.fit.report.cost.to_bits(),
        plain.fit.report.cost.to_bits()
    );
}
