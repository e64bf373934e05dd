//! Streaming accumulation of the Gauss–Newton normal equations JᵀJ, Jᵀr and S = Σ r².
//!
//! Rows of J are gathered into a column-major block of [`BLOCK_ROWS`] rows; a full block adds
//! its Gram matrix to JᵀJ and its product with the residuals to Jᵀr. Only the upper triangle
//! of each block's Gram matrix is computed (JᵀJ is symmetric) and mirrored.
//!
//! Every entry is the block's column dot product summed exactly as nalgebra's
//! `gemm_tr`/`gemv_tr` (`Matrix::dot`: eight interleaved partial sums, combined as
//! ((0 + (s₀ + s₄)) + (s₁ + s₅)) + (s₂ + s₆)) + (s₃ + s₇), then the remainder in order) add
//! it, which the accumulator replaced: the normal equations are bit-identical to those of the
//! block products.

use crate::numerics::levenberg_marquardt::NormalEquations;
use nalgebra::{DMatrix, DVector};

/// Rows per block.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub const BLOCK_ROWS: usize = 512;

/// Accumulates JᵀJ, Jᵀr and Σr² row by row (see the module docs).
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub struct Accumulator {
    /// Number of columns (free parameters).
    p: usize,
    /// Rows held in the current block.
    rows: usize,
    /// The current block, column k at `k·BLOCK_ROWS`.
    block: Vec<f64>,
    residuals: Vec<f64>,
    /// JᵀJ, row-major.
    jtj: Vec<f64>,
    jtr: Vec<f64>,
    cost: f64,
}

impl Accumulator {
    /// An empty accumulator for `p` columns.
    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn new(p: usize) -> Self {
        Self {
            p,
            rows: 0,
            block: vec![0.0; BLOCK_ROWS * p],
            residuals: vec![0.0; BLOCK_ROWS],
            jtj: vec![0.0; p * p],
            jtr: vec![0.0; p],
            cost: 0.0,
        }
    }

    /// Adds the row `scale · row` of J with residual `r`, written straight into the block.
    #[inline]
    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn add_scaled(&mut self, scale: f64, row: &[f64], r: f64) {
        let columns = self.block.chunks_exact_mut(BLOCK_ROWS);
        for (column, v) in columns.zip(row) {
            column[self.rows] = scale * v;
        }
        self.residuals[self.rows] = r;
        self.cost += r * r;
        self.rows += 1;
        if self.rows == BLOCK_ROWS {
            self.flush();
        }
    }

    /// Adds the rows `from … from + r.len() − 1` of `rows` (row-major, `width` values per
    /// row, of which the last p are the row of J), each scaled by `scale`, with residuals
    /// `r`: the same rows as that many calls of [`add_scaled`](Self::add_scaled).
    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn add_rows(&mut self, scale: f64, rows: &[f64], width: usize, from: usize, r: &[f64]) {
        let lead = width - self.p;
        let mut done = 0;
        while done < r.len() {
            let take = (BLOCK_ROWS - self.rows).min(r.len() - done);
            let (at, src) = (self.rows, from + done);
            let source = rows[src * width..(src + take) * width].chunks_exact(width);
            for (i, row) in source.enumerate() {
                let columns = self.block.chunks_exact_mut(BLOCK_ROWS);
                for (column, v) in columns.zip(&row[lead..]) {
                    column[at + i] = scale * v;
                }
            }
            for (d, &v) in self.residuals[at..at + take]
                .iter_mut()
                .zip(&r[done..done + take])
            {
                *d = v;
                self.cost += v * v;
            }
            self.rows += take;
            done += take;
            if self.rows == BLOCK_ROWS {
                self.flush();
            }
        }
    }

    /// Adds the block's upper-triangular Gram matrix and its Jᵀr to the totals.
    fn flush(&mut self) {
        let (n, p) = (self.rows, self.p);
        if n == 0 {
            return;
        }
        let column = |k: usize| &self.block[k * BLOCK_ROWS..k * BLOCK_ROWS + n];
        for i in 0..p {
            for j in i..p {
                let g = dot(column(i), column(j)) + self.jtj[i * p + j];
                self.jtj[i * p + j] = g;
                self.jtj[j * p + i] = g;
            }
            self.jtr[i] += dot(column(i), &self.residuals[..n]);
        }
        self.rows = 0;
    }

    /// The accumulated normal equations.
    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn finish(mut self) -> NormalEquations {
        self.flush();
        NormalEquations {
            jtj: DMatrix::from_row_slice(self.p, self.p, &self.jtj),
            jtr: DVector::from_vec(self.jtr),
            cost: self.cost,
        }
    }
}

/// Σ aᵢbᵢ in the summation order of nalgebra's `Matrix::dot` (see the module docs).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for ((s, x), y) in acc.iter_mut().zip(x).zip(y) {
            *s += x * y;
        }
    }
    let mut res = 0.0;
    res += acc[0] + acc[4];
    res += acc[1] + acc[5];
    res += acc[2] + acc[6];
    res += acc[3] + acc[7];
    for (x, y) in ra.iter().zip(rb) {
        res += x * y;
    }
    res
}
