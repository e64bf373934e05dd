//! Tests of `hysid::data::csv_io`.

#[cfg(unix)]
mod chunks;
mod float;
mod pipeline;

use std::fs;

use tempfile::TempDir;

use hysid::data::csv_io::*;
use hysid::data::{Channel, IdData, MAX_MAGNITUDE};
use hysid::error::{Error, Result};
use std::path::PathBuf;

/// A temporary directory holding one file, `data.csv`, with `content`.
struct Fixture {
    _dir: TempDir,
    path: PathBuf,
}

fn fixture(content: &str) -> Fixture {
    fixture_bytes(content.as_bytes())
}

fn fixture_bytes(content: &[u8]) -> Fixture {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("data.csv");
    fs::write(&path, content).unwrap();
    Fixture { _dir: dir, path }
}

fn spec(inputs: &[&str], outputs: &[&str]) -> CsvSpec {
    CsvSpec {
        inputs: inputs.iter().map(|s| s.to_string()).collect(),
        outputs: outputs.iter().map(|s| s.to_string()).collect(),
        ..CsvSpec::default()
    }
}

/// The error of `result`, checked for being one line and naming the file when it should.
fn err<T: std::fmt::Debug>(result: Result<T>) -> Error {
    let error = result.expect_err("expected an error");
    let message = error.to_string();
    assert!(!message.contains('\n'), "multi-line message: {message:?}");
    error
}

fn invalid_message<T: std::fmt::Debug>(result: Result<T>) -> String {
    match err(result) {
        Error::InvalidData(message) => message,
        other => panic!("expected InvalidData, got {other:?}"),
    }
}

fn read(f: &Fixture, names: &[&str]) -> Result<(Vec<String>, Vec<Vec<f64>>)> {
    read_columns(&f.path, names)
}

// ---------------------------------------------------------------- read_columns

#[test]
fn reads_requested_columns_in_order() {
    let f = fixture("a,b,c\n1,2,3\n4,5,6\n");
    let (header, columns) = read(&f, &["c", "a"]).unwrap();
    assert_eq!(header, ["a", "b", "c"]);
    assert_eq!(columns, [vec![3.0, 6.0], vec![1.0, 4.0]]);
}

#[test]
fn ignores_other_columns_even_if_not_numeric() {
    let f = fixture("label,x,comment\nfirst,1.5,hello\nsecond,-2e3,\n");
    let (_, columns) = read(&f, &["x"]).unwrap();
    assert_eq!(columns, [vec![1.5, -2000.0]]);
}

#[test]
fn accepts_spaces_bom_and_crlf() {
    let f = fixture_bytes(b"\xEF\xBB\xBF u , y \r\n 1 ,\t2 \r\n3,  4\r\n");
    let (header, columns) = read(&f, &["u", "y"]).unwrap();
    assert_eq!(header, ["u", "y"]);
    assert_eq!(columns, [vec![1.0, 3.0], vec![2.0, 4.0]]);
}

#[test]
fn matches_names_exactly_before_ignoring_case() {
    let f = fixture("U,u,Y\n1,2,3\n");
    let (_, columns) = read(&f, &["u", "U", "y"]).unwrap();
    assert_eq!(columns, [vec![2.0], vec![1.0], vec![3.0]]);
}

#[test]
fn rejects_ambiguous_names() {
    // Two exact matches.
    let f = fixture("x,y,x\n1,2,3\n");
    let message = invalid_message(read(&f, &["x"]));
    assert!(
        message.contains("'x' is ambiguous: columns 1, 3"),
        "{message}"
    );
    // No exact match and two case-insensitive ones.
    let f = fixture("Ab,aB\n1,2\n");
    let message = invalid_message(read(&f, &["ab"]));
    assert!(
        message.contains("'ab' is ambiguous: columns 1, 2"),
        "{message}"
    );
}

#[test]
fn missing_file_is_io_error() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("absent.csv");
    let error = err(read_columns(&path, &["u"]));
    assert!(matches!(error, Error::Io { .. }), "{error:?}");
    assert!(error.to_string().contains("absent.csv"), "{error}");
}

#[test]
fn empty_file_is_invalid() {
    for content in ["", "\n", "\n\n"] {
        let f = fixture(content);
        let message = invalid_message(read(&f, &["u"]));
        assert!(message.contains("data.csv: empty file"), "{message}");
    }
}

#[test]
fn header_only_is_invalid() {
    for content in ["u,y", "u,y\n", "u,y\n\n"] {
        let f = fixture(content);
        let message = invalid_message(read(&f, &["u"]));
        assert!(message.contains("data.csv: no data rows"), "{message}");
    }
}

#[test]
fn ragged_row_is_csv_error_with_line() {
    let f = fixture("u,y\n1,2\n3\n5,6\n");
    let error = err(read(&f, &["u"]));
    let Error::Csv {
        line, ref message, ..
    } = error
    else {
        panic!("expected Csv, got {error:?}");
    };
    assert_eq!(line, 3);
    assert!(
        message.contains("1 fields but the header has 2"),
        "{message}"
    );
    assert!(error.to_string().contains("data.csv: line 3:"), "{error}");

    let f = fixture("u,y\n1,2\n3,4,5\n");
    let error = err(read(&f, &["u"]));
    assert!(matches!(error, Error::Csv { line: 3, .. }), "{error:?}");
}

#[test]
fn missing_column_lists_the_header() {
    let f = fixture("time,u,y\n0,1,2\n");
    let error = err(read(&f, &["u", "z"]));
    let Error::MissingColumn {
        ref column,
        ref available,
        ..
    } = error
    else {
        panic!("expected MissingColumn, got {error:?}");
    };
    assert_eq!(column, "z");
    assert_eq!(available, "time, u, y");
    assert!(error.to_string().contains("data.csv"), "{error}");
}

#[test]
fn non_numeric_cell_names_line_and_column() {
    let f = fixture("u,y\n1,2\n3,4\n5,abc\n");
    let error = err(read(&f, &["u", "y"]));
    let Error::NotNumeric {
        line,
        ref column,
        ref text,
        ..
    } = error
    else {
        panic!("expected NotNumeric, got {error:?}");
    };
    assert_eq!((line, column.as_str(), text.as_str()), (4, "y", "abc"));
    assert!(
        error.to_string().contains("data.csv: line 4, column 'y'"),
        "{error}"
    );
}

#[test]
fn empty_cell_is_not_numeric() {
    let f = fixture("u,y\n1,2\n,4\n");
    let error = err(read(&f, &["u"]));
    assert!(
        matches!(error, Error::NotNumeric { line: 3, ref text, .. } if text.is_empty()),
        "{error:?}"
    );
    let f = fixture("u,y\n1,2\n  ,4\n");
    assert!(matches!(
        err(read(&f, &["u"])),
        Error::NotNumeric { line: 3, .. }
    ));
}

#[test]
fn multi_line_cell_keeps_the_message_on_one_line() {
    let f = fixture("u,y\n1,2\n\"3\n4\",5\n");
    let error = err(read(&f, &["u"]));
    assert!(
        matches!(error, Error::NotNumeric { line: 3, ref text, .. } if text == r"3\n4"),
        "{error:?}"
    );
}

#[test]
fn nan_and_infinity_are_non_finite_with_sample_index() {
    for (text, is_nan) in [
        ("nan", true),
        ("NaN", true),
        ("inf", false),
        ("-Infinity", false),
        ("1e999", false),
    ] {
        let f = fixture(&format!("u,y\n1,2\n3,4\n5,{text}\n"));
        let error = err(read(&f, &["u", "y"]));
        let Error::NonFinite {
            ref channel,
            index,
            value,
        } = error
        else {
            panic!("{text}: expected NonFinite, got {error:?}");
        };
        assert_eq!((channel.as_str(), index), ("y", 2), "{text}");
        assert_eq!(value.is_nan(), is_nan, "{text}");
    }
}

// ---------------------------------------------------------------- from_csv

#[test]
fn from_csv_uses_spec_ts_over_a_time_column() {
    let f = fixture("t,u,y\n0,1,2\n5,3,4\n6,5,6\n");
    let data = IdData::from_csv(
        &f.path,
        &CsvSpec {
            ts: Some(0.25),
            ..spec(&["u"], &["y"])
        },
    )
    .unwrap();
    assert_eq!(data.ts(), 0.25);
    assert_eq!(data.input(0, 0), &[1.0, 3.0, 5.0]);
    assert_eq!(data.output(0, 0), &[2.0, 4.0, 6.0]);
    assert_eq!(data.experiment(0).name(), "data");
}

#[test]
fn from_csv_reads_ts_from_named_time_column() {
    let f = fixture("stamp,u\n10.0,1\n10.5,2\n11.0,3\n11.5,4\n");
    let spec = CsvSpec {
        time: Some("STAMP".into()),
        ..spec(&["u"], &[])
    };
    let data = IdData::from_csv(&f.path, &spec).unwrap();
    assert_eq!(data.ts(), 0.5);
    assert!(data.output_channels().is_empty());
}

#[test]
fn from_csv_detects_conventional_time_columns() {
    for name in ["t", "Time", "T_S", "time_s"] {
        let f = fixture(&format!("u,{name},y\n1,0.0,2\n3,0.1,4\n5,0.2,6\n"));
        let data = IdData::from_csv(&f.path, &spec(&["u"], &["y"])).unwrap();
        assert!((data.ts() - 0.1).abs() < 1e-15, "{name}: {}", data.ts());
    }
}

#[test]
fn from_csv_does_not_take_a_channel_for_the_time_column() {
    let f = fixture("time,t\n1,0\n5,3\n");
    let data = IdData::from_csv(&f.path, &spec(&["t"], &[])).unwrap();
    assert_eq!(data.ts(), 4.0);
}

#[test]
fn from_csv_defaults_to_unit_sample_time() {
    let f = fixture("u,y\n1,2\n3,4\n");
    let data = IdData::from_csv(&f.path, &spec(&["U"], &["Y"])).unwrap();
    assert_eq!(data.ts(), 1.0);
    // Channels are named as in the file.
    assert_eq!(data.input_channels(), &[Channel::new("u")]);
}

#[test]
fn from_csv_tolerates_jitter_within_one_percent() {
    let f = fixture("t,u\n0,1\n0.1005,2\n0.2,3\n0.2995,4\n");
    let data = IdData::from_csv(&f.path, &spec(&["u"], &[])).unwrap();
    assert!((data.ts() - 0.0998333).abs() < 1e-6, "{}", data.ts());
}

#[test]
fn from_csv_rejects_non_uniform_time() {
    // Mean step 1; the fourth step (on line 5) is 1.5.
    let f = fixture("t,u\n0,1\n1,2\n2,3\n3.5,4\n4,5\n");
    let message = invalid_message(IdData::from_csv(&f.path, &spec(&["u"], &[])));
    assert!(
        message.contains("data.csv: line 5: time column 't' has a step of 1.5"),
        "{message}"
    );
    assert!(message.contains("--ts"), "{message}");
}

#[test]
fn from_csv_rejects_decreasing_time_at_the_right_line() {
    // A blank line and a multi-line quoted cell shift lines against rows.
    let f = fixture("t,u,note\n0,1,x\n\n1,2,\"two\nlines\"\n0.5,3,x\n");
    let message = invalid_message(IdData::from_csv(&f.path, &spec(&["u"], &[])));
    assert!(
        message.contains(
            "data.csv: line 6: time column 't' is not strictly increasing (0.5 follows 1)"
        ),
        "{message}"
    );
    let f = fixture("t,u\n0,1\n0,2\n");
    let message = invalid_message(IdData::from_csv(&f.path, &spec(&["u"], &[])));
    assert!(
        message.contains("line 3: time column 't' is not strictly increasing"),
        "{message}"
    );
}

#[test]
fn from_csv_needs_two_rows_to_derive_ts() {
    let f = fixture("t,u\n0,1\n");
    let message = invalid_message(IdData::from_csv(&f.path, &spec(&["u"], &[])));
    assert!(
        message.contains("line 2: time column 't' has a single value"),
        "{message}"
    );
    let data = IdData::from_csv(
        &f.path,
        &CsvSpec {
            ts: Some(1.0),
            ..spec(&["u"], &[])
        },
    );
    assert_eq!(data.unwrap().n_samples(), 1);
}

#[test]
fn from_csv_propagates_column_errors() {
    let f = fixture("t,u,y\n0,1,2\n1,3,nan\n");
    let error = err(IdData::from_csv(&f.path, &spec(&["u"], &["y"])));
    assert!(
        matches!(error, Error::NonFinite { index: 1, .. }),
        "{error:?}"
    );
    let error = err(IdData::from_csv(&f.path, &spec(&["u"], &["z"])));
    assert!(matches!(error, Error::MissingColumn { .. }), "{error:?}");
    let error = err(IdData::from_csv(
        &f.path,
        &CsvSpec {
            time: Some("clock".into()),
            ..spec(&["u"], &[])
        },
    ));
    assert!(
        matches!(error, Error::MissingColumn { ref column, .. } if column == "clock"),
        "{error:?}"
    );
}

#[test]
fn from_csv_names_the_file_in_data_set_errors() {
    let f = fixture("u,y\n1,2\n");
    let message = invalid_message(IdData::from_csv(&f.path, &spec(&["u"], &["U"])));
    assert!(
        message.contains("data.csv: channel name 'u' is used twice"),
        "{message}"
    );
    let bad_ts = CsvSpec {
        ts: Some(-1.0),
        ..spec(&["u"], &[])
    };
    let message = invalid_message(IdData::from_csv(&f.path, &bad_ts));
    assert!(
        message.contains("data.csv: sample time ts = -1"),
        "{message}"
    );
}

#[test]
fn from_csv_needs_a_channel() {
    let f = fixture("t,u\n0,1\n");
    let message = invalid_message(IdData::from_csv(&f.path, &spec(&[], &[])));
    assert!(message.contains("no input or output columns"), "{message}");
}

// ---------------------------------------------------------------- writing

/// Values whose text forms are hard to get exactly right.
fn awkward_values() -> Vec<f64> {
    vec![
        0.0,
        -0.0,
        0.1,
        1.0 / 3.0,
        -2.5e-7,
        1e-5,
        9_999_999_999_999_998.0,
        1e16,
        123_456_789.123_456_79,
        f64::MAX,
        f64::MIN_POSITIVE,
        5e-324,
        -f64::EPSILON,
    ]
}

#[test]
fn write_then_read_is_bit_exact() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.csv");
    let a = awkward_values();
    let b: Vec<f64> = a.iter().map(|v| -v / 3.0).collect();
    write_csv(&path, &["a", "b"], &[&a, &b]).unwrap();
    let (header, columns) = read_columns(&path, &["a", "b"]).unwrap();
    assert_eq!(header, ["a", "b"]);
    for (written, read) in [&a, &b].into_iter().zip(&columns) {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(written), bits(read));
    }
}

#[test]
fn write_uses_compact_text() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.csv");
    write_csv(&path, &["x"], &[&[1.0, 0.25, 1e-300, 2e20, -0.0]]).unwrap();
    assert_eq!(
        fs::read_to_string(&path).unwrap(),
        "x\n1\n0.25\n1e-300\n2e20\n-0\n"
    );
}

#[test]
fn write_replaces_existing_file_and_leaves_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.csv");
    fs::write(&path, "old").unwrap();
    write_csv(&path, &["x"], &[&[1.0]]).unwrap();
    assert_eq!(fs::read_to_string(&path).unwrap(), "x\n1\n");
    let names: Vec<_> = fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["out.csv"]);
}

#[test]
fn write_rejects_inconsistent_columns() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.csv");
    let message = invalid_message(write_csv(&path, &["a", "b"], &[&[1.0, 2.0], &[1.0]]));
    assert!(
        message.contains("column 'b' has 1 values but column 'a' has 2"),
        "{message}"
    );
    let message = invalid_message(write_csv(&path, &["a"], &[&[1.0], &[1.0]]));
    assert!(message.contains("1 headers for 2 columns"), "{message}");
    let message = invalid_message(write_csv(&path, &[], &[]));
    assert!(message.contains("no columns"), "{message}");
    let error = err(write_csv(
        &path,
        &["a", "b"],
        &[&[1.0, 2.0], &[1.0, f64::NAN]],
    ));
    assert!(
        matches!(error, Error::NonFiniteResult { ref key, .. } if key == "b[1]"),
        "{error:?}"
    );
    // Nothing was written.
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn write_into_missing_directory_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("absent").join("out.csv");
    // Refused when the output is registered with the one writer (io::atomic::OutputSet).
    let error = err(write_csv(&path, &["x"], &[&[1.0]]));
    let message = error.to_string();
    assert!(message.contains("out.csv"), "{message}");
    assert!(message.contains("does not exist"), "{message}");
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn to_csv_round_trips_through_from_csv() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.csv");
    // IdData refuses a sample beyond 1e150 (its square overflows): the largest it holds
    // stands in for f64::MAX, which write_then_read_is_bit_exact covers.
    let u: Vec<f64> = awkward_values()
        .into_iter()
        .map(|v| if v == f64::MAX { MAX_MAGNITUDE } else { v })
        .collect();
    let y: Vec<f64> = u.iter().map(|v| v * 0.5).collect();
    let data = IdData::siso(0.01, "u", u, "y", y).unwrap();
    data.to_csv(&path).unwrap();

    let text = fs::read_to_string(&path).unwrap();
    assert!(text.starts_with("t,u,y\n0,0,0\n0.01,"), "{text}");
    let back = IdData::from_csv(&path, &spec(&["u"], &["y"])).unwrap();
    assert!((back.ts() - 0.01).abs() < 1e-15);
    let exact = IdData::from_csv(
        &path,
        &CsvSpec {
            ts: Some(0.01),
            ..spec(&["u"], &["y"])
        },
    )
    .unwrap();
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(exact.input(0, 0)), bits(data.input(0, 0)));
    assert_eq!(bits(exact.output(0, 0)), bits(data.output(0, 0)));
    assert_eq!(exact.input_channels(), data.input_channels());
}

#[test]
fn to_csv_rejects_several_experiments_and_a_channel_named_t() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.csv");
    let one = IdData::siso(1.0, "u", vec![1.0], "y", vec![2.0]).unwrap();
    let message = invalid_message(one.clone().merge(one).unwrap().to_csv(&path));
    assert!(message.contains("this data set has 2"), "{message}");
    let named_t = IdData::siso(1.0, "t", vec![1.0], "y", vec![2.0]).unwrap();
    let message = invalid_message(named_t.to_csv(&path));
    assert!(message.contains("called 't'"), "{message}");
}

/// `TimeSteps::Ordered` (the rate-independent models' records): steps may differ, the
/// sample time is the median step (the mean of the two middle ones for an even count), two
/// samples suffice, and a clock that restarts is refused with the rule's own advice.
#[test]
fn ordered_time_steps_take_gaps_and_refuse_a_restarted_clock() {
    let spec = CsvSpec {
        inputs: vec!["u".into()],
        outputs: vec!["y".into()],
        time_steps: TimeSteps::Ordered,
        ..CsvSpec::default()
    };
    let read = |text: &str| {
        let f = fixture(text);
        IdData::from_csv(&f.path, &spec)
    };
    // steps 1, 600, 1, 7.5: the median of four is (1 + 7.5)/2
    let data = read("t,u,y\n0,0,0\n1,1,1\n601,2,2\n602,3,3\n609.5,4,4\n").unwrap();
    assert_eq!(data.ts(), 4.25);
    assert_eq!(data.input(0, 0), &[0.0, 1.0, 2.0, 3.0, 4.0]);
    assert_eq!(read("t,u,y\n3,0,0\n5,1,1\n").unwrap().ts(), 2.0);
    let e = read("t,u,y\n0,0,0\n1,1,1\n2,2,2\n0,3,3\n1,4,4\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("line 5") && e.contains("not strictly increasing") && e.contains("one clock"),
        "{e}"
    );
    assert!(!e.contains("uniform grid"), "{e}");
    // the default rule refuses the gaps
    let uniform = CsvSpec {
        time_steps: TimeSteps::Uniform,
        ..spec.clone()
    };
    let f = fixture("t,u,y\n0,0,0\n1,1,1\n601,2,2\n602,3,3\n");
    let e = IdData::from_csv(&f.path, &uniform).unwrap_err().to_string();
    assert!(
        e.contains("1 % off the mean step") && e.contains("uniform grid"),
        "{e}"
    );
}
