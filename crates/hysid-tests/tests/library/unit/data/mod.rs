//! Tests of `hysid::data`.

mod csv_io;
mod mat5;
mod mat_io;

use proptest::prelude::*;

use hysid::data::*;
use hysid::error::{Error, Result};
use std::fmt;

/// Every error message must fit on one line.
fn assert_one_line(error: &Error) {
    let message = error.to_string();
    assert!(!message.contains('\n'), "multi-line message: {message:?}");
}

/// The error of `result`, checked for being one line.
fn err<T: fmt::Debug>(result: Result<T>) -> Error {
    let error = result.expect_err("expected an error");
    assert_one_line(&error);
    error
}

fn invalid_message<T: fmt::Debug>(result: Result<T>) -> String {
    match err(result) {
        Error::InvalidData(message) => message,
        other => panic!("expected InvalidData, got {other:?}"),
    }
}

fn ramp(n: usize, offset: f64) -> Vec<f64> {
    (0..n).map(|k| offset + k as f64).collect()
}

/// Two inputs, one output, one experiment of `n` samples.
fn miso(n: usize) -> IdData {
    let experiment = Experiment::new(
        "run",
        vec![ramp(n, 0.0), ramp(n, 100.0)],
        vec![ramp(n, 200.0)],
    );
    IdData::new(
        0.5,
        vec![Channel::new("u1").with_unit("V"), Channel::new("u2")],
        vec![Channel::new("y")],
        vec![experiment.unwrap()],
    )
    .unwrap()
}

// ---------------------------------------------------------------- construction

#[test]
fn siso_accessors() {
    let data = IdData::siso(0.1, "u", vec![1.0, 2.0, 3.0], "y", vec![4.0, 5.0, 6.0]).unwrap();
    assert_eq!(data.ts(), 0.1);
    assert_eq!(data.n_experiments(), 1);
    assert_eq!(data.n_samples(), 3);
    assert_eq!(data.input_channels(), &[Channel::new("u")]);
    assert_eq!(data.output_channels(), &[Channel::new("y")]);
    assert_eq!(data.input(0, 0), &[1.0, 2.0, 3.0]);
    assert_eq!(data.output(0, 0), &[4.0, 5.0, 6.0]);
    let experiment = data.experiment(0);
    assert_eq!(experiment.len(), 3);
    assert!(!experiment.is_empty());
    assert_eq!(experiment.name(), DEFAULT_EXPERIMENT_NAME);
    assert_eq!(experiment.input(0), &[1.0, 2.0, 3.0]);
    assert_eq!(experiment.output(0), &[4.0, 5.0, 6.0]);
    assert_eq!(data.experiments().len(), 1);
}

#[test]
fn input_only_has_no_outputs() {
    let data = IdData::input_only(1.0, "x", vec![0.0, 0.5]).unwrap();
    assert!(data.output_channels().is_empty());
    assert_eq!(data.n_samples(), 2);
    assert_eq!(data.input_by_name(0, "x").unwrap(), &[0.0, 0.5]);
}

#[test]
fn channels_by_name() {
    let data = miso(3);
    assert_eq!(data.input_by_name(0, "u2").unwrap(), &[100.0, 101.0, 102.0]);
    assert_eq!(data.output_by_name(0, "y").unwrap(), &[200.0, 201.0, 202.0]);
    let message = invalid_message(data.input_by_name(0, "y"));
    assert!(message.contains("no input channel named 'y'"), "{message}");
    assert!(message.contains("u1, u2"), "{message}");
    let message = invalid_message(data.output_by_name(0, "u1"));
    assert!(
        message.contains("no output channel named 'u1'"),
        "{message}"
    );
}

#[test]
fn channel_display_shows_unit() {
    assert_eq!(Channel::new("u").with_unit("V").to_string(), "u [V]");
    assert_eq!(Channel::new("u").to_string(), "u");
}

#[test]
fn rejects_bad_sample_times() {
    for ts in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        let message = invalid_message(IdData::siso(ts, "u", vec![1.0], "y", vec![1.0]));
        assert!(message.contains("sample time"), "{message}");
    }
}

#[test]
fn rejects_experiment_without_channels() {
    let message = invalid_message(Experiment::new("e", Vec::new(), Vec::new()));
    assert!(message.contains("no channels"), "{message}");
}

#[test]
fn rejects_experiment_without_samples() {
    let message = invalid_message(Experiment::new("e", vec![Vec::new()], vec![Vec::new()]));
    assert!(message.contains("no samples"), "{message}");
    let message = invalid_message(IdData::siso(1.0, "u", Vec::new(), "y", Vec::new()));
    assert!(message.contains("no samples"), "{message}");
}

#[test]
fn rejects_unequal_channel_lengths() {
    let message = invalid_message(Experiment::new("e", vec![ramp(3, 0.0)], vec![ramp(2, 0.0)]));
    assert!(message.contains("output 0 has 2 samples"), "{message}");
    let message = invalid_message(IdData::siso(1.0, "u", ramp(3, 0.0), "y", ramp(4, 0.0)));
    assert!(message.contains("same length"), "{message}");
}

#[test]
fn rejects_no_experiments() {
    let message = invalid_message(IdData::new(
        1.0,
        vec![Channel::new("u")],
        Vec::new(),
        Vec::new(),
    ));
    assert!(message.contains("at least one experiment"), "{message}");
}

#[test]
fn rejects_channel_count_mismatch() {
    let experiment = Experiment::new("e", vec![ramp(2, 0.0)], vec![ramp(2, 0.0)]).unwrap();
    let message = invalid_message(IdData::new(
        1.0,
        vec![Channel::new("u1"), Channel::new("u2")],
        vec![Channel::new("y")],
        vec![experiment.clone()],
    ));
    assert!(
        message.contains("1 input channels but 2 are described"),
        "{message}"
    );
    let message = invalid_message(IdData::new(
        1.0,
        vec![Channel::new("u")],
        Vec::new(),
        vec![experiment],
    ));
    assert!(
        message.contains("1 output channels but 0 are described"),
        "{message}"
    );
}

#[test]
fn rejects_bad_channel_names() {
    let message = invalid_message(IdData::siso(1.0, "", vec![1.0], "y", vec![1.0]));
    assert!(message.contains("empty name"), "{message}");
    let message = invalid_message(IdData::siso(1.0, "u", vec![1.0], "  ", vec![1.0]));
    assert!(message.contains("empty name"), "{message}");
    let message = invalid_message(IdData::siso(1.0, "u", vec![1.0], "u", vec![1.0]));
    assert!(message.contains("'u' is used twice"), "{message}");
    let message = invalid_message(IdData::siso(1.0, "u\nv", vec![1.0], "y", vec![1.0]));
    assert!(message.contains("control characters"), "{message}");
    assert!(message.contains(r"u\nv"), "{message}");
}

#[test]
fn rejects_non_finite_samples() {
    let error = err(IdData::siso(
        1.0,
        "u",
        vec![1.0, f64::NAN],
        "y",
        vec![1.0, 2.0],
    ));
    let Error::NonFinite {
        channel,
        index,
        value,
    } = error
    else {
        panic!("expected NonFinite, got {error:?}");
    };
    assert_eq!((channel.as_str(), index), ("u", 1));
    assert!(value.is_nan());

    let error = err(IdData::siso(
        1.0,
        "u",
        vec![1.0, 2.0, 3.0],
        "y",
        vec![1.0, 2.0, f64::NEG_INFINITY],
    ));
    assert!(
        matches!(error, Error::NonFinite { ref channel, index: 2, value } if channel == "y" && value == f64::NEG_INFINITY),
        "{error:?}"
    );
}

#[test]
fn non_finite_sample_names_experiment_when_there_are_several() {
    let good = Experiment::new("a", vec![ramp(2, 0.0)], Vec::new()).unwrap();
    let bad = Experiment::new("b", vec![vec![0.0, 1.0, f64::INFINITY]], Vec::new()).unwrap();
    let error = err(IdData::new(
        1.0,
        vec![Channel::new("u")],
        Vec::new(),
        vec![good, bad],
    ));
    assert!(
        matches!(error, Error::NonFinite { ref channel, index: 2, .. } if channel == "u (experiment 1)"),
        "{error:?}"
    );
}

// ---------------------------------------------------------------- slice, split, merge

#[test]
fn slice_takes_the_same_range_everywhere() {
    let data = miso(10).merge(miso(6)).unwrap();
    let part = data.slice(2..5).unwrap();
    assert_eq!(part.n_experiments(), 2);
    assert_eq!(part.n_samples(), 6);
    for exp in 0..2 {
        assert_eq!(part.input(exp, 0), &[2.0, 3.0, 4.0]);
        assert_eq!(part.input(exp, 1), &[102.0, 103.0, 104.0]);
        assert_eq!(part.output(exp, 0), &[202.0, 203.0, 204.0]);
    }
    assert_eq!(part.input_channels(), data.input_channels());
    assert_eq!(part.ts(), data.ts());
}

#[test]
fn slice_rejects_empty_or_out_of_range() {
    let data = miso(10).merge(miso(6)).unwrap();
    assert_eq!(data.slice(0..6).unwrap().n_samples(), 12);
    #[allow(clippy::reversed_empty_ranges)]
    for range in [3..3, 4..2, 0..7, 10..12] {
        let message = invalid_message(data.slice(range.clone()));
        assert!(message.contains("within 0..6"), "{range:?}: {message}");
    }
}

#[test]
fn split_cuts_every_experiment() {
    let data = miso(10).merge(miso(6)).unwrap();
    let (estimation, validation) = data.split(4).unwrap();
    assert_eq!(estimation.n_samples(), 8);
    assert_eq!(validation.n_samples(), 6 + 2);
    assert_eq!(estimation.output(1, 0), &[200.0, 201.0, 202.0, 203.0]);
    assert_eq!(validation.output(0, 0), &ramp(6, 204.0)[..]);
    assert_eq!(validation.output(1, 0), &[204.0, 205.0]);
}

#[test]
fn split_rejects_points_that_leave_a_part_empty() {
    let data = miso(10).merge(miso(6)).unwrap();
    for at in [0, 6, 10, 11] {
        let message = invalid_message(data.split(at));
        assert!(message.contains("1..6"), "{at}: {message}");
    }
}

#[test]
fn select_picks_experiments_in_the_given_order() {
    let data = miso(3).merge(miso(5)).unwrap().merge(miso(2)).unwrap();
    let picked = data.select(&[2, 0]).unwrap();
    assert_eq!(picked.n_experiments(), 2);
    assert_eq!(picked.n_samples(), 2 + 3);
    assert_eq!(picked.output(0, 0), data.output(2, 0));
    assert_eq!(picked.output(1, 0), data.output(0, 0));
    assert_eq!(picked.input_channels(), data.input_channels());
    assert_eq!(picked.ts(), data.ts());
    assert!(invalid_message(data.select(&[])).contains("at least one"));
    assert!(invalid_message(data.select(&[3])).contains("no experiment 3"));
}

#[test]
fn merge_appends_experiments() {
    let merged = miso(3).merge(miso(5)).unwrap().merge(miso(2)).unwrap();
    assert_eq!(merged.n_experiments(), 3);
    assert_eq!(merged.n_samples(), 10);
    assert_eq!(merged.experiment(1).len(), 5);
}

#[test]
fn merge_tolerates_rounding_in_the_sample_time() {
    let a = IdData::siso(0.1, "u", vec![1.0], "y", vec![1.0]).unwrap();
    let b = IdData::siso(0.1 + 1e-17, "u", vec![1.0], "y", vec![1.0]).unwrap();
    assert!(a.merge(b).is_ok());
}

#[test]
fn merge_rejects_different_sample_times() {
    let a = IdData::siso(0.1, "u", vec![1.0], "y", vec![1.0]).unwrap();
    let b = IdData::siso(0.2, "u", vec![1.0], "y", vec![1.0]).unwrap();
    let message = invalid_message(a.merge(b));
    assert!(
        message.contains("different sample times (0.1 and 0.2)"),
        "{message}"
    );
}

#[test]
fn merge_rejects_different_channels() {
    let a = IdData::siso(0.1, "u", vec![1.0], "y", vec![1.0]).unwrap();
    let b = IdData::siso(0.1, "v", vec![1.0], "y", vec![1.0]).unwrap();
    let message = invalid_message(a.clone().merge(b));
    assert!(
        message.contains("different input channels (u and v)"),
        "{message}"
    );

    let b = IdData::siso(0.1, "u", vec![1.0], "z", vec![1.0]).unwrap();
    let message = invalid_message(a.clone().merge(b));
    assert!(
        message.contains("different output channels (y and z)"),
        "{message}"
    );

    let b = IdData::new(
        0.1,
        vec![Channel::new("u")],
        vec![Channel::new("y").with_unit("m")],
        vec![Experiment::new("exp1", vec![vec![1.0]], vec![vec![1.0]]).unwrap()],
    )
    .unwrap();
    let message = invalid_message(a.merge(b));
    assert!(message.contains("(y and y [m])"), "{message}");
}

#[test]
fn one_line_escapes_control_characters_only() {
    assert_eq!(one_line("plain ü"), "plain ü");
    assert_eq!(one_line("a\nb\tc\r"), r"a\nb\tc\r");
}

// ---------------------------------------------------------------- properties

/// A data set of one to three experiments, each at least `min_len` samples long.
fn data_sets(min_len: usize) -> impl Strategy<Value = IdData> {
    let experiment = (min_len..40).prop_flat_map(|n| {
        (
            prop::collection::vec(-1e6..1e6f64, n),
            prop::collection::vec(-1e6..1e6f64, n),
        )
    });
    prop::collection::vec(experiment, 1..4).prop_map(|experiments| {
        let experiments = experiments
            .into_iter()
            .enumerate()
            .map(|(i, (u, y))| Experiment::new(format!("e{i}"), vec![u], vec![y]).unwrap())
            .collect();
        IdData::new(
            0.01,
            vec![Channel::new("u")],
            vec![Channel::new("y")],
            experiments,
        )
        .unwrap()
    })
}

proptest! {
    // Seeded: the same cases on every machine, no regression file written.
    #![proptest_config(ProptestConfig {
        rng_seed: proptest::test_runner::RngSeed::Fixed(20_261_122),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn split_then_concatenate_restores_samples(data in data_sets(2), at_fraction in 0.0..1.0f64) {
        let shortest = data.experiments().iter().map(Experiment::len).min().unwrap();
        let at = 1 + (at_fraction * (shortest - 1) as f64) as usize;
        let at = at.min(shortest - 1);
        let (head, tail) = data.split(at).unwrap();

        for exp in 0..data.n_experiments() {
            let joined_u = [head.input(exp, 0), tail.input(exp, 0)].concat();
            let joined_y = [head.output(exp, 0), tail.output(exp, 0)].concat();
            prop_assert_eq!(joined_u.as_slice(), data.input(exp, 0));
            prop_assert_eq!(joined_y.as_slice(), data.output(exp, 0));
        }

        // Merging the parts keeps every sample, each experiment split in two.
        let merged = head.merge(tail).unwrap();
        prop_assert_eq!(merged.n_experiments(), 2 * data.n_experiments());
        prop_assert_eq!(merged.n_samples(), data.n_samples());
    }

    #[test]
    fn slice_of_whole_range_is_identity(data in data_sets(1)) {
        let shortest = data.experiments().iter().map(Experiment::len).min().unwrap();
        let sliced = data.slice(0..shortest).unwrap();
        for exp in 0..data.n_experiments() {
            prop_assert_eq!(sliced.input(exp, 0), &data.input(exp, 0)[..shortest]);
        }
    }
}

#[test]
fn channels_whose_squares_overflow_or_underflow_are_refused() {
    let wave: Vec<f64> = (0..50).map(|k| (0.3 * k as f64).sin()).collect();
    let scaled = |s: f64| wave.iter().map(|v| v * s).collect::<Vec<f64>>();
    for (scale, words) in [(1e-300, "below 1e-150"), (1e300, "exceeds 1e150")] {
        let message = invalid_message(IdData::siso(1.0, "u", wave.clone(), "y", scaled(scale)));
        assert!(
            message.contains("'y'") && message.contains(words),
            "{message}"
        );
        let message = invalid_message(IdData::siso(1.0, "u", scaled(scale), "y", wave.clone()));
        assert!(
            message.contains("'u'") && message.contains("rescale"),
            "{message}"
        );
    }
    // Zero channels, and the limits themselves, are data.
    assert!(IdData::siso(1.0, "u", vec![0.0; 50], "y", wave.clone()).is_ok());
    assert!(IdData::siso(1.0, "u", scaled(1e-149), "y", scaled(1e149)).is_ok());
}

#[test]
fn variation_is_judged_at_double_precision() {
    assert!(varies(&[0.0, 1.0]));
    assert!(varies(&[1e-100, -1e-100]));
    assert!(!varies(&[0.5; 10]));
    assert!(!varies(&[]));
    // A spread of a rounding error, or one whose square underflows, is no variation.
    assert!(!varies(&[1.0, 1.0 + f64::EPSILON]));
    assert!(!varies(&[1e-300, 2e-300]));
    assert!(varies(&[1.0, 1.0 + 1e-12]));
}
