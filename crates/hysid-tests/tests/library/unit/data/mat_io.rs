//! Tests of `hysid::data::mat_io`.

//! The MAT-file reader against the fixture written by `tools/reference/mat_fixture.py`
//! (SciPy's level-5 writer, compressed) from the piezo CSV record.

use hysid::data::read_columns;
use hysid::data::{CsvSpec, IdData};
use hysid::error::{Error, Result};
use std::fs;
use std::path::Path;
use std::path::PathBuf;

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/piezo_150V_1Hz.mat")
}

fn csv() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/piezo/piezo_150V_1Hz.csv")
}

fn spec(inputs: &[&str], outputs: &[&str]) -> CsvSpec {
    CsvSpec {
        inputs: inputs.iter().map(|s| s.to_string()).collect(),
        outputs: outputs.iter().map(|s| s.to_string()).collect(),
        ..CsvSpec::default()
    }
}

fn message(result: Result<IdData>) -> String {
    match result {
        Err(Error::InvalidData(m)) => m,
        other => panic!("expected InvalidData, got {other:?}"),
    }
}

#[test]
fn vectors_matrix_columns_and_rows_read_as_the_csv_record() {
    let (_, columns) = read_columns(&csv(), &["voltage_V", "displacement_um"]).unwrap();
    let data = IdData::from_mat(&fixture(), &spec(&["voltage_V"], &["displacement_um"])).unwrap();
    assert_eq!(data.input(0, 0), columns[0].as_slice());
    assert_eq!(data.output(0, 0), columns[1].as_slice());
    // The time variable t_s is found by its name: 1 kHz.
    assert!((data.ts() - 1e-3).abs() < 1e-12, "{}", data.ts());
    assert_eq!(data.experiment(0).name(), "piezo_150V_1Hz");
    // A matrix column, a row vector and a case-insensitive name give the same samples.
    let data = IdData::from_mat(
        &fixture(),
        &spec(&["record(:,2)", "voltage_row"], &["DISPLACEMENT_UM"]),
    )
    .unwrap();
    assert_eq!(data.input(0, 0), columns[0].as_slice());
    assert_eq!(data.input(0, 1), columns[0].as_slice());
    assert_eq!(data.output(0, 0), columns[1].as_slice());
    // Integer classes convert to f64.
    let data = IdData::from_mat(&fixture(), &spec(&["counts"], &[])).unwrap();
    let expected: Vec<f64> = columns[0].iter().map(|v| (10.0 * v).round()).collect();
    assert_eq!(data.input(0, 0), expected.as_slice());
}

#[test]
fn from_file_picks_the_reader_by_extension() {
    let s = spec(&["voltage_V"], &["displacement_um"]);
    let from_mat = IdData::from_file(&fixture(), &s).unwrap();
    let from_csv = IdData::from_file(&csv(), &s).unwrap();
    assert_eq!(from_mat.input(0, 0), from_csv.input(0, 0));
    assert_eq!(from_mat.output(0, 0), from_csv.output(0, 0));
    assert!((from_mat.ts() - from_csv.ts()).abs() < 1e-12);
}

#[test]
fn bad_selections_are_one_line_errors_naming_the_file() {
    let file = fixture().display().to_string();
    let cases = [
        ("nothere", "no numeric variable named 'nothere'"),
        ("record", "is a 2000×3 matrix; pick a column as record(:,k)"),
        ("record(:,4)", "has 3 column(s), not 4"),
        ("record(2,:)", "is not a variable name or name(:,k)"),
        ("z", "variable 'z' is complex"),
    ];
    for (name, expected) in cases {
        let m = message(IdData::from_mat(&fixture(), &spec(&[name], &[])));
        assert!(m.starts_with(&file) && m.contains(expected), "{name}: {m}");
        assert_eq!(m.lines().count(), 1);
    }
    let m = message(IdData::from_mat(&fixture(), &spec(&["nothere"], &[])));
    assert!(m.contains("voltage_V [2000×1]"), "{m}");
}

#[test]
fn a_time_variable_must_be_uniform() {
    let mut s = spec(&["voltage_V"], &[]);
    s.time = Some("displacement_um".into());
    let m = message(IdData::from_mat(&fixture(), &s));
    assert!(m.contains("time variable 'displacement_um'"), "{m}");
    s.ts = Some(0.5);
    assert_eq!(IdData::from_mat(&fixture(), &s).unwrap().ts(), 0.5);
}

#[test]
fn version_7_3_and_other_files_are_refused_with_the_way_out() {
    let dir = tempfile::tempdir().unwrap();
    let v73 = dir.path().join("big.mat");
    let mut bytes =
        b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Sun Nov 22 2026 HDF5 schema 1.00 ."
            .to_vec();
    bytes.resize(512, b' ');
    bytes.extend_from_slice(b"\x89HDF\r\n\x1a\n");
    fs::write(&v73, &bytes).unwrap();
    let m = message(IdData::from_mat(&v73, &spec(&["u"], &[])));
    assert!(m.contains("version 7.3") && m.contains("-v7"), "{m}");
    let text = dir.path().join("text.mat");
    fs::write(&text, "t,u\n0,1\n").unwrap();
    let m = message(IdData::from_mat(&text, &spec(&["u"], &[])));
    assert!(m.contains("is not a MAT-file"), "{m}");
    let broken = dir.path().join("broken.mat");
    let mut bytes = fs::read(fixture()).unwrap();
    bytes.truncate(400);
    fs::write(&broken, &bytes).unwrap();
    assert!(IdData::from_mat(&broken, &spec(&["voltage_V"], &[])).is_err());
}
