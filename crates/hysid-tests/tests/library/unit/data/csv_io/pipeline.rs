//! Tests of `hysid::data::csv_io::pipeline`.

use hysid::data::{CsvSpec, IdData};
use hysid::Error;

fn spec() -> CsvSpec {
    CsvSpec {
        inputs: vec!["x".into()],
        outputs: vec!["y".into()],
        ..CsvSpec::default()
    }
}

/// A file of several batches with `bad` written in place of row `row`'s y cell.
fn file(rows: usize, row: usize, bad: &str) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("long.csv");
    let mut text = String::from("t,x,y\n");
    for k in 0..rows {
        let y = if k == row {
            bad.to_string()
        } else {
            format!("{}", 0.5 * k as f64)
        };
        text.push_str(&format!("{k},{},{y}\n", k as f64 * 0.25));
    }
    std::fs::write(&path, text).unwrap();
    (dir, path)
}

#[test]
fn every_row_is_read_in_order() {
    let rows = 3 * hysid::data::csv_io::pipeline::BATCH + 17;
    let (_dir, path) = file(rows, usize::MAX, "");
    let data = IdData::from_csv(&path, &spec()).unwrap();
    let x = data.experiment(0).input(0);
    let y = data.experiment(0).output(0);
    assert_eq!(x.len(), rows);
    assert!((0..rows).all(|k| x[k] == k as f64 * 0.25 && y[k] == 0.5 * k as f64));
}

/// Errors in a late batch name their line, as in a sequential read.
#[test]
fn errors_in_a_late_batch_name_their_line() {
    let row = 2 * hysid::data::csv_io::pipeline::BATCH + 5;
    let (_dir, path) = file(3 * hysid::data::csv_io::pipeline::BATCH, row, "oops");
    match IdData::from_csv(&path, &spec()) {
        Err(Error::NotNumeric { line, text, .. }) => {
            assert_eq!((line, text.as_str()), (row as u64 + 2, "oops"))
        }
        other => panic!("{other:?}"),
    }
    let (_dir, path) = file(3 * hysid::data::csv_io::pipeline::BATCH, row, "1,2");
    match IdData::from_csv(&path, &spec()) {
        Err(Error::Csv { line, message, .. }) => {
            assert_eq!(line, row as u64 + 2);
            assert!(message.contains("fields"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}
