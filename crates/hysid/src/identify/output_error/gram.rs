//! Streaming accumulation of the Gauss–Newton normal equations JᵀJ, Jᵀr and S = Σ r².
//!
//! Each row z = [J(t), r(t)] adds its outer product to the upper rows of the augmented Gram
//! matrix [JᵀJ | Jᵀr]: entry (i, j), j ≥ i, gains zᵢ·zⱼ. The rows are summed one after the
//! other into a block of [`BLOCK_ROWS`] rows, and the blocks one after the other into the
//! totals (two levels, so a long record's rounding grows with the block length and the number
//! of blocks, not with the record length). S is summed row by row. Every entry has that one
//! order of summation whichever way its rows arrive (one at a time, or a block of a
//! sensitivity pass) and whichever instruction set runs it, so the result is the same bits.
//!
//! Why this layout: the rows arrive row-major from the sensitivity pass. Updating the
//! accumulators of a whole row at once touches each value once (the row's p products per
//! parameter are one vector operation per four of them), where dot products over columns
//! first had to transpose the rows and then ran p(p + 3)/2 dependent chains. On x86-64
//! processors with AVX (detected at run time) the block kernel is `gram/tiles.rs`: the
//! sums swept in tiles that fit the registers, four lanes wide, with no fused multiply–add,
//! so the lanes round exactly as the portable kernel.

use crate::numerics::cpu::has_avx;
use crate::numerics::levenberg_marquardt::NormalEquations;
use nalgebra::{DMatrix, DVector, DVectorView};
use rayon::prelude::*;

#[cfg(target_arch = "x86_64")]
mod tiles;

/// The normal equations of a Jacobian stored by columns (each as long as `r`) and the
/// residuals r, as nalgebra's `J.tr_mul(&J)`, `J.tr_mul(&r)` and `r.norm_squared()` form them
/// from the stored block: entry (i, j) of JᵀJ is `dot` of columns i and j, (Jᵀr)ᵢ `dot` of
/// column i and r (so the same bits), here without copying the columns into one block,
/// each entry of the symmetric JᵀJ computed once (a·b and b·a are the same products summed
/// in the same order), and the dot products shared out over the rayon threads.
pub fn of_columns(columns: &[&[f64]], r: &[f64]) -> NormalEquations {
    fn view(c: &[f64]) -> DVectorView<'_, f64> {
        DVectorView::from_slice(c, c.len())
    }
    let p = columns.len();
    let res = view(r);
    // The upper triangle of JᵀJ row by row, then Jᵀr.
    let pairs: Vec<(usize, Option<usize>)> = (0..p)
        .flat_map(|i| (i..p).map(move |j| (i, Some(j))))
        .chain((0..p).map(|i| (i, None)))
        .collect();
    let dots: Vec<f64> = pairs
        .par_iter()
        .map(|&(i, j)| match j {
            Some(j) => view(columns[i]).dot(&view(columns[j])),
            None => view(columns[i]).dot(&res),
        })
        .collect();
    let mut jtj = DMatrix::zeros(p, p);
    let mut jtr = DVector::zeros(p);
    for (&(i, j), &d) in pairs.iter().zip(&dots) {
        match j {
            Some(j) => {
                jtj[(i, j)] = d;
                jtj[(j, i)] = d;
            }
            None => jtr[i] = d,
        }
    }
    NormalEquations {
        jtj,
        jtr,
        cost: res.norm_squared(),
    }
}

/// The AVX tiles' buffers (nothing on other architectures, which have no tiles).
#[cfg(target_arch = "x86_64")]
type TileScratch = tiles::Scratch;
#[cfg(not(target_arch = "x86_64"))]
type TileScratch = ();

/// Rows per block.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub const BLOCK_ROWS: usize = 512;

/// Accumulates JᵀJ, Jᵀr and Σr² row by row (see the module docs).
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub struct Accumulator {
    /// Number of columns (free parameters).
    p: usize,
    /// Rows summed into the current block.
    rows: usize,
    /// The current block's sums, row-major p × (p + 1): (i, j) at `i·(p + 1) + j`, Jᵀr in
    /// the last column. Only j ≥ i is used.
    block: Vec<f64>,
    /// The totals of the finished blocks, laid out as `block`.
    total: Vec<f64>,
    /// The current row z = [scale·J, r] of the row-by-row path (`add_to_block`).
    z: Vec<f64>,
    cost: f64,
    /// Whether blocks of rows go to the AVX tiles (the processor has AVX).
    simd: bool,
    /// The AVX tiles' buffers, made on first use.
    tiles: Option<Box<TileScratch>>,
}

impl Accumulator {
    /// An empty accumulator for `p` columns.
    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn new(p: usize) -> Self {
        Self {
            p,
            rows: 0,
            block: vec![0.0; p * (p + 1)],
            total: vec![0.0; p * (p + 1)],
            z: vec![0.0; p + 1],
            cost: 0.0,
            simd: has_avx(),
            tiles: None,
        }
    }

    /// The same accumulator with the portable block kernel even where the processor has
    /// AVX: the definition the AVX tiles are tested against.
    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn portable(mut self) -> Self {
        self.simd = false;
        self
    }

    /// Adds the row `scale · row` of J with residual `r`.
    #[inline]
    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn add_scaled(&mut self, scale: f64, row: &[f64], r: f64) {
        self.add_to_block(scale, row, r);
        self.cost += r * r;
        self.rows += 1;
        if self.rows == BLOCK_ROWS {
            self.flush();
        }
    }

    /// Adds the rows `from … from + r.len() − 1` of `rows` (row-major, `width` values per
    /// row, of which the last p are the row of J), each scaled by `scale`, with residuals
    /// `r`: the same rows as that many calls of [`add_scaled`](Self::add_scaled), the same
    /// result.
    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn add_rows(&mut self, scale: f64, rows: &[f64], width: usize, from: usize, r: &[f64]) {
        let mut done = 0;
        while done < r.len() {
            let take = (BLOCK_ROWS - self.rows).min(r.len() - done);
            let src = from + done;
            let part = &r[done..done + take];
            self.block_rows(scale, &rows[src * width..(src + take) * width], width, part);
            self.rows += take;
            done += take;
            if self.rows == BLOCK_ROWS {
                self.flush();
            }
        }
    }

    /// Sums the rows `rows` (`r.len()` of them, `width` apart) into the block and their r²
    /// into S: with the AVX tiles or a fixed-width kernel for p ≤ 12, else row by row.
    fn block_rows(&mut self, scale: f64, rows: &[f64], width: usize, r: &[f64]) {
        let (block, cost) = (&mut self.block, &mut self.cost);
        let tiles = match self.simd {
            true => Some(&mut **self.tiles.get_or_insert_with(Box::default)),
            false => None,
        };
        macro_rules! kernels {
            ($(($p:literal, $w:literal)),*) => {
                match self.p {
                    $($p => return kernel::<$p, $w>(tiles, block, cost, scale, rows, width, r),)*
                    _ => {}
                }
            };
        }
        kernels!(
            (1, 2),
            (2, 3),
            (3, 4),
            (4, 5),
            (5, 6),
            (6, 7),
            (7, 8),
            (8, 9),
            (9, 10),
            (10, 11),
            (11, 12),
            (12, 13)
        );
        for (row, &rt) in rows.chunks_exact(width).zip(r) {
            self.add_to_block(scale, &row[width - self.p..], rt);
            self.cost += rt * rt;
        }
    }

    /// Adds the outer product of z = [scale · j, r] to the upper rows of the block sums:
    /// entry (i, k), k ≥ i, gains zᵢ·zₖ.
    fn add_to_block(&mut self, scale: f64, j: &[f64], r: f64) {
        let (p, z) = (self.p, &mut self.z);
        for (z, v) in z.iter_mut().zip(j) {
            *z = scale * v;
        }
        z[p] = r;
        let w = p + 1;
        for i in 0..p {
            let zi = z[i];
            for (g, zk) in self.block[i * w + i..(i + 1) * w].iter_mut().zip(&z[i..]) {
                *g += zi * zk;
            }
        }
    }

    /// Adds the block to the totals and empties it.
    fn flush(&mut self) {
        for (t, b) in self.total.iter_mut().zip(self.block.iter_mut()) {
            *t += *b;
            *b = 0.0;
        }
        self.rows = 0;
    }

    /// The accumulated normal equations.
    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn finish(mut self) -> NormalEquations {
        self.flush();
        let (p, w) = (self.p, self.p + 1);
        let g = &self.total;
        NormalEquations {
            jtj: DMatrix::from_fn(p, p, |i, j| g[i.min(j) * w + i.max(j)]),
            jtr: DVector::from_fn(p, |i, _| g[i * w + p]),
            cost: self.cost,
        }
    }
}

/// The block kernel for P columns (W = P + 1): the AVX tiles when given their buffers,
/// else each row's products added to the block's sums in locals, and r² to S, row after
/// row (the portable kernel, see the module docs).
fn kernel<const P: usize, const W: usize>(
    tiled: Option<&mut TileScratch>,
    block: &mut [f64],
    cost: &mut f64,
    scale: f64,
    rows: &[f64],
    width: usize,
    r: &[f64],
) {
    const { assert!(W == P + 1) };
    #[cfg(target_arch = "x86_64")]
    if let Some(scratch) = tiled {
        // SAFETY: the buffers are made only when the processor has AVX (`simd`).
        return unsafe { tiles::accumulate::<P>(scratch, block, cost, scale, rows, width, r) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = tiled;
    let mut acc = [[0.0; W]; P];
    for (i, a) in acc.iter_mut().enumerate() {
        a.copy_from_slice(&block[i * W..(i + 1) * W]);
    }
    for (row, &rt) in rows.chunks_exact(width).zip(r) {
        // A row holds ŷ or other leading values, then the P values of J (`width` ≥ P by
        // construction of every block).
        let j = row
            .last_chunk::<P>()
            .expect("a row ends with the p values of J");
        let mut z = [0.0; W];
        for (z, v) in z.iter_mut().zip(j) {
            *z = scale * v;
        }
        z[P] = rt;
        *cost += rt * rt;
        // Entries j ≥ i are the sums; the few below them in the same group of four are
        // computed too (whole vectors) and never read.
        for (i, a) in acc.iter_mut().enumerate() {
            for c in (i & !3)..W {
                a[c] += z[i] * z[c];
            }
        }
    }
    for (i, a) in acc.iter().enumerate() {
        block[i * W..(i + 1) * W].copy_from_slice(a);
    }
}
