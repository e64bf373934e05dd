//! Tests of `hysid::identify::output_error::gram`.

use hysid::identify::output_error::gram::*;
use nalgebra::{DMatrix, DVector};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

/// The accumulated normal equations equal, bit for bit, those of nalgebra's block
/// products (the accumulator they replaced) on random rows, with a partial last block.
#[test]
fn normal_equations_equal_block_products() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(13);
    for p in [1, 3, 7, 11] {
        let n = 3 * BLOCK_ROWS + 37;
        let rows: Vec<Vec<f64>> = (0..n)
            .map(|_| (0..p).map(|_| rng.random_range(-1.0..1.0)).collect())
            .collect();
        let res: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut acc = Accumulator::new(p);
        for (row, &r) in rows.iter().zip(&res) {
            acc.add_scaled(-0.75, row, r);
        }
        let got = acc.finish();
        let (mut jtj, mut jtr) = (DMatrix::zeros(p, p), DVector::zeros(p));
        for start in (0..n).step_by(BLOCK_ROWS) {
            let len = BLOCK_ROWS.min(n - start);
            let j = DMatrix::from_fn(len, p, |i, k| -0.75 * rows[start + i][k]);
            let r = DVector::from_column_slice(&res[start..start + len]);
            jtj.gemm_tr(1.0, &j, &j, 1.0);
            jtr.gemv_tr(1.0, &j, &r, 1.0);
        }
        let cost = res.iter().fold(0.0, |s, r| s + r * r);
        assert_eq!(got.jtj, jtj, "p = {p}");
        assert_eq!(got.jtr, jtr, "p = {p}");
        assert_eq!(got.cost, cost, "p = {p}");
    }
}

/// Rows added a column-major block at a time (blocks of uneven lengths, the first rows of
/// one left out, a stride longer than the block) give the normal equations of the same
/// rows added one by one, bit for bit.
#[test]
fn block_rows_equal_single_rows() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(29);
    for p in [1, 4, 7] {
        let n = 2 * BLOCK_ROWS + 301;
        let rows: Vec<Vec<f64>> = (0..n)
            .map(|_| (0..p).map(|_| rng.random_range(-1.0..1.0)).collect())
            .collect();
        let res: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let skip = 5;
        let mut single = Accumulator::new(p);
        for (row, &r) in rows.iter().zip(&res).skip(skip) {
            single.add_scaled(-0.5, row, r);
        }
        let mut blocks = Accumulator::new(p);
        let (mut start, mut len) = (0, 7);
        while start < n {
            let end = (start + len).min(n);
            // Two leading values per row that are not part of J (as ŷ in a sensitivity block).
            let width = p + 2;
            let mut block = vec![f64::NAN; width * (end - start)];
            for (out, row) in block.chunks_exact_mut(width).zip(&rows[start..end]) {
                out[2..].copy_from_slice(row);
            }
            let from = skip.saturating_sub(start).min(end - start);
            blocks.add_rows(-0.5, &block, width, from, &res[start + from..end]);
            start = end;
            len = len * 3 + 1;
        }
        let (a, b) = (single.finish(), blocks.finish());
        assert_eq!(a.jtj, b.jtj, "p = {p}");
        assert_eq!(a.jtr, b.jtr, "p = {p}");
        assert_eq!(a.cost, b.cost, "p = {p}");
    }
}
