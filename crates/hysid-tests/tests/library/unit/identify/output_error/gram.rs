//! Tests of `hysid::identify::output_error::gram`.

use hysid::identify::output_error::gram::*;
use nalgebra::{DMatrix, DVector};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

/// Random rows of J (p columns) and residuals, n of them.
fn random_rows(seed: u64, p: usize, n: usize) -> (Vec<Vec<f64>>, Vec<f64>) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let rows: Vec<Vec<f64>> = (0..n)
        .map(|_| (0..p).map(|_| rng.random_range(-1.0..1.0)).collect())
        .collect();
    let res: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
    (rows, res)
}

/// The accumulated normal equations are, bit for bit, the sums in the order the module
/// documents (row after row within a block of `BLOCK_ROWS`, block after block), written out
/// here by hand, with a partial last block; S is summed row by row.
#[test]
fn normal_equations_are_the_documented_sums() {
    for p in [1, 3, 7, 11, 13] {
        let n = 3 * BLOCK_ROWS + 37;
        let (rows, res) = random_rows(13, p, n);
        let mut acc = Accumulator::new(p);
        for (row, &r) in rows.iter().zip(&res) {
            acc.add_scaled(-0.75, row, r);
        }
        let got = acc.finish();
        let (mut jtj, mut jtr) = (DMatrix::zeros(p, p), DVector::zeros(p));
        for start in (0..n).step_by(BLOCK_ROWS) {
            let (mut block, mut block_r) = (DMatrix::zeros(p, p), DVector::zeros(p));
            for t in start..(start + BLOCK_ROWS).min(n) {
                let z: Vec<f64> = rows[t].iter().map(|v| -0.75 * v).collect();
                for i in 0..p {
                    for j in i..p {
                        block[(i, j)] += z[i] * z[j];
                    }
                    block_r[i] += z[i] * res[t];
                }
            }
            jtj += block;
            jtr += block_r;
        }
        let jtj = DMatrix::from_fn(p, p, |i, j| jtj[(i.min(j), i.max(j))]);
        let cost = res.iter().fold(0.0, |s, r| s + r * r);
        assert_eq!(got.jtj, jtj, "p = {p}");
        assert_eq!(got.jtr, jtr, "p = {p}");
        assert_eq!(got.cost, cost, "p = {p}");
    }
}

/// The normal equations agree with nalgebra's products JᵀJ, Jᵀr of the whole matrix within
/// the bound of two summation orders, 2·n·ε·Σ|aᵢbᵢ| per entry.
#[test]
fn normal_equations_agree_with_matrix_products() {
    for p in [1, 4, 7, 11] {
        let n = 5 * BLOCK_ROWS + 11;
        let (rows, res) = random_rows(17, p, n);
        let mut acc = Accumulator::new(p);
        for (row, &r) in rows.iter().zip(&res) {
            acc.add_scaled(-1.5, row, r);
        }
        let got = acc.finish();
        let j = DMatrix::from_fn(n, p, |t, k| -1.5 * rows[t][k]);
        let r = DVector::from_column_slice(&res);
        let (jtj, jtr) = (j.tr_mul(&j), j.tr_mul(&r));
        let (ja, ra) = (j.abs(), r.abs());
        let (bound_jtj, bound_jtr) = (ja.tr_mul(&ja), ja.tr_mul(&ra));
        let tol = 2.0 * n as f64 * f64::EPSILON;
        for i in 0..p {
            for k in 0..p {
                let e = (got.jtj[(i, k)] - jtj[(i, k)]).abs();
                assert!(e <= tol * bound_jtj[(i, k)], "p = {p}, ({i}, {k}): {e:e}");
            }
            let e = (got.jtr[i] - jtr[i]).abs();
            assert!(e <= tol * bound_jtr[i], "p = {p}, {i}: {e:e}");
        }
    }
}

/// Rows added a row-major block at a time (blocks of uneven lengths, the first rows of one
/// left out, a stride longer than the row of J) give the normal equations of the same rows
/// added one by one, bit for bit: the fixed-width kernels (p ≤ 12) and the general path
/// (p = 13).
#[test]
fn block_rows_equal_single_rows() {
    for p in [1, 4, 7, 11, 13] {
        let n = 2 * BLOCK_ROWS + 301;
        let (rows, res) = random_rows(29, p, n);
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

/// The block kernels give the same bits on every instruction set: blocks of rows through
/// the AVX tiles (where the processor has AVX) and through the portable kernel, for every
/// fixed width p ≤ 12, chunk boundaries and a partial last block included.
#[test]
fn avx_tiles_equal_portable_kernel() {
    for p in 1..=12 {
        let n = 2 * BLOCK_ROWS + 77;
        let (rows, res) = random_rows(31 + p as u64, p, n);
        let width = p + 1;
        let mut block = vec![f64::NAN; width * n];
        for (out, row) in block.chunks_exact_mut(width).zip(&rows) {
            out[1..].copy_from_slice(row);
        }
        let (mut tiles, mut portable) = (Accumulator::new(p), Accumulator::new(p).portable());
        for acc in [&mut tiles, &mut portable] {
            let mut start = 0;
            for len in [1, 63, 64, 65, 700, 5, n] {
                let end = (start + len).min(n);
                acc.add_rows(
                    -0.25,
                    &block[start * width..end * width],
                    width,
                    0,
                    &res[start..end],
                );
                start = end;
            }
        }
        let (a, b) = (tiles.finish(), portable.finish());
        assert_eq!(a.jtj, b.jtj, "p = {p}");
        assert_eq!(a.jtr, b.jtr, "p = {p}");
        assert_eq!(a.cost, b.cost, "p = {p}");
    }
}

/// The normal equations of a Jacobian given by its columns are nalgebra's products of the
/// stored block, bit for bit: `J.tr_mul(&J)`, `J.tr_mul(&r)` and `r.norm_squared()`, for
/// column counts and lengths on either side of the dot product's eight-way unrolling.
#[test]
fn columns_give_the_block_products() {
    for (p, n) in [(1, 5), (2, 8), (3, 9), (6, 40_960), (7, 1_003)] {
        let (rows, res) = random_rows(29 + p as u64, p, n);
        let block = DMatrix::from_fn(n, p, |t, k| rows[t][k]);
        let stored: Vec<Vec<f64>> = (0..p)
            .map(|k| block.column(k).iter().copied().collect())
            .collect();
        let columns: Vec<&[f64]> = stored.iter().map(Vec::as_slice).collect();
        let got = of_columns(&columns, &res);
        let r = DVector::from_column_slice(&res);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(got.jtj.as_slice()),
            bits(block.tr_mul(&block).as_slice()),
            "p {p}, n {n}"
        );
        assert_eq!(
            bits(got.jtr.as_slice()),
            bits(block.tr_mul(&r).as_slice()),
            "p {p}, n {n}"
        );
        assert_eq!(got.cost.to_bits(), r.norm_squared().to_bits());
    }
}
