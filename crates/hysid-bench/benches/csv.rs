//! Criterion benchmark of reading a long CSV file: 10⁶ rows of `t,x,y` with full-precision
//! numbers (about 45 MB, the shape of the record `bench/identify_1e6.sh` writes), read as
//! `hysid identify` reads it (in parallel chunks when rayon has two threads or more) and
//! record by record (the path every unusual file takes).
//!
//! Run with `cargo bench -p hysid-bench --bench csv`.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion};
use hysid::data::csv_io::{read_columns_by, Rows};
use hysid::data::write_csv;

/// Rows of the file read.
const ROWS: usize = 1_000_000;

/// A file of `ROWS` rows in the temporary directory, removed when dropped.
struct LongFile(PathBuf);

impl LongFile {
    /// `t` counts the rows; `x` and `y` are pseudo-random doubles in (−1, 1), written in full
    /// precision (mostly 16 or 17 significant digits, as measured records are).
    fn new() -> Self {
        let path = std::env::temp_dir().join(format!("hysid-bench-csv-{}.csv", std::process::id()));
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        let mut uniform = || {
            // xorshift64*: deterministic, and no dependency for it.
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            let bits = state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
            2.0 * (bits as f64 / (1u64 << 53) as f64) - 1.0
        };
        let t: Vec<f64> = (0..ROWS).map(|k| k as f64).collect();
        let x: Vec<f64> = (0..ROWS).map(|_| uniform()).collect();
        let y: Vec<f64> = (0..ROWS).map(|_| uniform() * 0.1).collect();
        write_csv(&path, &["t", "x", "y"], &[&t, &x, &y]).expect("the bench file is written");
        Self(path)
    }
}

impl Drop for LongFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

fn reading(c: &mut Criterion) {
    let file = LongFile::new();
    let mut group = c.benchmark_group("csv, 1e6 rows of t,x,y");
    group.sample_size(10);
    for (name, rows) in [
        ("as identify reads it", Rows::Auto),
        ("record by record", Rows::Sequential),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| black_box(read_columns_by(&file.0, &["t", "x", "y"], rows).unwrap()))
        });
    }
    group.finish();
}

criterion_group!(benches, reading);
criterion_main!(benches);
