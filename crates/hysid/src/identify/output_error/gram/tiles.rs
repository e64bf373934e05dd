//! The block kernel of the Gram accumulator with 4-lane AVX registers, tiled so that the
//! sums stay in registers (x86-64 processors with AVX, detected by the caller).
//!
//! The augmented Gram block [JᵀJ | Jᵀr] of p ≤ 12 columns has up to 12 rows of up to four
//! registers: more sums than the sixteen registers hold, so the compiled row loop kept
//! them in memory, loading and storing every sum for every row. Here each chunk of rows is
//! first turned into z = [scale·J, r] (zero-padded to whole registers), then swept once per
//! tile of at most four Gram rows × three registers (twelve sums, three z registers and one
//! broadcast: the sixteen registers), each sum in one register lane for the whole chunk.
//!
//! Every sum still gains its products row after row, each product zᵢ·zₖ rounded on its own
//! and added on its own (no fused multiply–add), and S = Σ r² is summed row by row: the same
//! operations in the same order as the portable kernel, so the same bits.

use std::arch::x86_64::{
    __m256d, _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_set1_pd, _mm256_storeu_pd,
};

/// The largest number of columns p the tiles handle.
const MAX_P: usize = 12;

/// Values per row of z and of the padded sums: p + 1 ≤ 13 rounded up to whole registers.
const Z: usize = 16;

/// Rows of z formed at a time (8 KB, in the first-level cache while the tiles sweep it).
const CHUNK: usize = 64;

/// The tiles' buffers, kept by the accumulator from block to block: rows of z, and the
/// block sums padded to whole registers. Entries past p + 1 stay zero, so the padding lanes
/// only ever add 0·zᵢ.
pub(super) struct Scratch {
    z: Vec<[f64; Z]>,
    sums: [f64; MAX_P * Z],
}

impl Default for Scratch {
    fn default() -> Self {
        Self {
            z: vec![[0.0; Z]; CHUNK],
            sums: [0.0; MAX_P * Z],
        }
    }
}

/// Adds the rows of J in `rows` (`width` ≥ P values per row, J the last P of them), each
/// scaled by `scale`, with residuals `r`, to the row-major P × (P + 1) block sums `block`,
/// and r² to `cost`, row by row. Requires P ≤ [`MAX_P`] and AVX.
#[target_feature(enable = "avx")]
pub(super) fn accumulate<const P: usize>(
    scratch: &mut Scratch,
    block: &mut [f64],
    cost: &mut f64,
    scale: f64,
    rows: &[f64],
    width: usize,
    r: &[f64],
) {
    const { assert!(P <= MAX_P) };
    let (p, w) = (P, P + 1);
    let registers = w.div_ceil(4);
    let Scratch { z, sums } = scratch;
    for (padded, sums) in sums.chunks_exact_mut(Z).zip(block.chunks_exact(w)) {
        padded[..w].copy_from_slice(sums);
    }
    let mut s = *cost;
    for (rows, r) in rows.chunks(CHUNK * width).zip(r.chunks(CHUNK)) {
        let z = &mut z[..r.len()];
        for ((zt, row), &rt) in z.iter_mut().zip(rows.chunks_exact(width)).zip(r) {
            let j = row
                .last_chunk::<P>()
                .expect("a row ends with the p values of J");
            for (zc, j) in zt.iter_mut().zip(j) {
                *zc = scale * j;
            }
            zt[p] = rt;
            s += rt * rt;
        }
        // Gram rows 4g … 4g + 3 from register g on (the sums left of the diagonal's register
        // are never needed), at most three registers per sweep.
        for first_row in (0..p).step_by(4) {
            let rows_here = (p - first_row).min(4);
            let mut register = first_row / 4;
            while register < registers {
                let here = (registers - register).min(3);
                sweep(sums, z, first_row, rows_here, register, here);
                register += here;
            }
        }
    }
    for (sums, padded) in block.chunks_exact_mut(w).zip(sums.chunks_exact(Z)) {
        sums.copy_from_slice(&padded[..w]);
    }
    *cost = s;
}

/// One tile: Gram rows `first_row …` (`rows` of them) × registers `register …` (`count` of
/// them), the tile's shape made a constant so that its sums are registers.
#[target_feature(enable = "avx")]
fn sweep(
    sums: &mut [f64; MAX_P * Z],
    z: &[[f64; Z]],
    first_row: usize,
    rows: usize,
    register: usize,
    count: usize,
) {
    macro_rules! shapes {
        ($(($r:literal, $c:literal)),*) => {
            match (rows, count) {
                $(($r, $c) => tile::<$r, $c>(sums, z, first_row, register),)*
                _ => unreachable!("tiles are at most 4 rows by 3 registers"),
            }
        };
    }
    shapes!(
        (1, 1),
        (1, 2),
        (1, 3),
        (2, 1),
        (2, 2),
        (2, 3),
        (3, 1),
        (3, 2),
        (3, 3),
        (4, 1),
        (4, 2),
        (4, 3)
    );
}

/// The tile of R Gram rows from `first_row` and C registers from `register`: the sums
/// loaded once, every row of z added (zᵢ broadcast, times z's registers), stored once.
#[target_feature(enable = "avx")]
#[inline]
fn tile<const R: usize, const C: usize>(
    sums: &mut [f64; MAX_P * Z],
    z: &[[f64; Z]],
    first_row: usize,
    register: usize,
) {
    let column = 4 * register;
    assert!(
        first_row + R <= MAX_P && column + 4 * C <= Z,
        "the tile lies inside the sums"
    );
    let at = |i: usize, c: usize| (first_row + i) * Z + column + 4 * c;
    // SAFETY (every load and store below): the assertion keeps each four-value access
    // inside `sums` (MAX_P rows of Z) or inside one row of z (Z values).
    let mut acc: [[__m256d; C]; R] = std::array::from_fn(|i| {
        std::array::from_fn(|c| unsafe { _mm256_loadu_pd(sums.as_ptr().add(at(i, c))) })
    });
    for zt in z {
        let zc: [__m256d; C] =
            std::array::from_fn(|c| unsafe { _mm256_loadu_pd(zt.as_ptr().add(column + 4 * c)) });
        for (i, acc) in acc.iter_mut().enumerate() {
            let zi = _mm256_set1_pd(zt[first_row + i]);
            for (acc, &zc) in acc.iter_mut().zip(&zc) {
                *acc = _mm256_add_pd(*acc, _mm256_mul_pd(zi, zc));
            }
        }
    }
    for (i, acc) in acc.iter().enumerate() {
        for (c, &acc) in acc.iter().enumerate() {
            unsafe { _mm256_storeu_pd(sums.as_mut_ptr().add(at(i, c)), acc) };
        }
    }
}
