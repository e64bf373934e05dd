//! The triangular factor of the augmented matrix [Φ y] by Householder reflections applied to
//! blocks of rows, for the tall least-squares problems of iterations (N ≫ p).
//!
//! # Method
//!
//! The running factor T ((p+1) × (p+1), upper triangular) and the next block of rows B are
//! stacked, [T; B], and brought back to triangular form by p+1 Householder reflections
//! H = I − τuuᵀ, one per column j. Below the diagonal, T is zero in column j, so u has one
//! entry in T's row j (u₀ = 1) and the rest in the block:
//!
//! ```text
//! β = −sign(t_jj)·‖(t_jj, b_j)‖,   v = b_j/(t_jj − β),   τ = (β − t_jj)/β
//! for c > j:  w = t_jc + vᵀb_c,   t_jc ← t_jc − τw,   b_c ← b_c − τw·v
//! ```
//!
//! (the reflector of LAPACK's `dlarfg`; Golub & Van Loan, *Matrix Computations*, 4th ed.,
//! §5.1.2). After the last block, T is the R of a Householder QR of [Φ y] up to the signs of
//! its rows: its top-left p × p part is Φ's R, its last column above the corner is Qᵀy, and
//! the corner's square is the residual sum of squares ‖y − Φθ̂‖² (Golub & Van Loan §5.3.3).
//! The block recursion is sequential TSQR (Demmel, Grigori, Hoemmen & Langou,
//! "Communication-optimal parallel and sequential QR and LU factorizations", SIAM J. Sci.
//! Comput. 34(1), 2012).
//!
//! # Why
//!
//! A column-by-column Householder QR sweeps the whole N × p matrix once per column; at
//! N = 10⁴ and p = 7 (the key-term iteration's regression) the matrix outgrows the
//! second-level cache, and the sweeps, not the arithmetic, set the pace. Here each block of
//! 256 rows stays in the first-level cache while all p+1 reflections pass over it, so the
//! record is read once. The sums over a block's rows run in eight lanes in a fixed order
//! (no fused multiply–add), so the result is the same on every x86-64 processor, with or
//! without AVX.

use nalgebra::DMatrix;

/// Rows per block: with p + 1 = 8 columns a block is 16 KiB, half the first-level cache
/// (64 rows: 1.3 times the time per factor, 512: the same as 256).
const BLOCK_ROWS: usize = 256;

/// The upper triangular factor of [Φ y], (p+1) × (p+1), row-major.
pub(super) struct Augmented {
    width: usize,
    t: Vec<f64>,
}

impl Augmented {
    /// Entry (i, j) of the factor (zero below the diagonal).
    pub(super) fn at(&self, i: usize, j: usize) -> f64 {
        self.t[i * self.width + j]
    }
}

/// The triangular factor of [Φ y] (see the module docs); `y` has Φ's number of rows.
pub(super) fn factor_augmented(phi: &DMatrix<f64>, y: &[f64]) -> Augmented {
    #[cfg(target_arch = "x86_64")]
    {
        if crate::numerics::cpu::has_avx() {
            // SAFETY: the processor has AVX, the only requirement of `factor_avx`.
            return unsafe { factor_avx(phi, y) };
        }
    }
    factor_portable(phi, y)
}

/// [`factor_portable`] compiled for AVX: the same operations in the same order.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn factor_avx(phi: &DMatrix<f64>, y: &[f64]) -> Augmented {
    factor_portable(phi, y)
}

/// The block recursion of the module docs.
#[inline(always)]
fn factor_portable(phi: &DMatrix<f64>, y: &[f64]) -> Augmented {
    let (n, p) = phi.shape();
    let width = p + 1;
    let mut factor = Augmented {
        width,
        t: vec![0.0; width * width],
    };
    // The block column-major, column c at c·BLOCK_ROWS; Φ is column-major too.
    let mut block = vec![0.0; BLOCK_ROWS * width];
    let columns = phi.as_slice();
    let mut first = 0;
    while first < n {
        let rows = BLOCK_ROWS.min(n - first);
        for (c, column) in block.chunks_exact_mut(BLOCK_ROWS).enumerate() {
            let source = match c < p {
                true => &columns[c * n + first..c * n + first + rows],
                false => &y[first..first + rows],
            };
            column[..rows].copy_from_slice(source);
        }
        reduce(&mut factor, &mut block, rows);
        first += rows;
    }
    factor
}

/// Folds the first `rows` rows of `block` into the factor: [T; B] made triangular again.
#[inline(always)]
fn reduce(factor: &mut Augmented, block: &mut [f64], rows: usize) {
    let width = factor.width;
    let t = &mut factor.t;
    for j in 0..width {
        let (done, rest) = block.split_at_mut((j + 1) * BLOCK_ROWS);
        let v = &mut done[j * BLOCK_ROWS..j * BLOCK_ROWS + rows];
        let tail = dot(v, v);
        if tail == 0.0 {
            // The block is zero in this column already: H = I.
            continue;
        }
        let x0 = t[j * width + j];
        let norm = (x0 * x0 + tail).sqrt();
        let beta = if x0 >= 0.0 { -norm } else { norm };
        // x0 − β has |β| ≥ |x0| added with x0's sign: no cancellation.
        let scale = 1.0 / (x0 - beta);
        v.iter_mut().for_each(|e| *e *= scale);
        let tau = (beta - x0) / beta;
        t[j * width + j] = beta;
        for (k, column) in rest.chunks_exact_mut(BLOCK_ROWS).enumerate() {
            let c = j + 1 + k;
            let w = tau * (t[j * width + c] + dot(v, &column[..rows]));
            t[j * width + c] -= w;
            column[..rows]
                .iter_mut()
                .zip(v.iter())
                .for_each(|(b, v)| *b -= w * v);
        }
    }
}

/// Σ aᵢbᵢ in eight lanes (i mod 8), combined pairwise: ((l₀+l₁)+(l₂+l₃))+((l₄+l₅)+(l₆+l₇)).
/// The lanes are two arrays of four, one vector register each with AVX.
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let (mut low, mut high) = ([0.0; 4], [0.0; 4]);
    let (a8, b8) = (a.chunks_exact(8), b.chunks_exact(8));
    let (a_tail, b_tail) = (a8.remainder(), b8.remainder());
    for (x, y) in a8.zip(b8) {
        for k in 0..4 {
            low[k] += x[k] * y[k];
            high[k] += x[4 + k] * y[4 + k];
        }
    }
    for (k, (x, y)) in a_tail.iter().zip(b_tail).enumerate() {
        match k < 4 {
            true => low[k] += x * y,
            false => high[k - 4] += x * y,
        }
    }
    ((low[0] + low[1]) + (low[2] + low[3])) + ((high[0] + high[1]) + (high[2] + high[3]))
}
