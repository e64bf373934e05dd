//! The grid's two streaming kernels with 4-lane AVX registers, for x86-64 processors that have
//! AVX (detected at run time, [`available`]).
//!
//! Both compute exactly what the portable code of the parent module computes, in the same
//! order: a dot product's four partial sums (element i goes to sum i mod 4) are the four
//! lanes of one register, and each lane adds its products one after the other as the
//! portable loop does. No fused multiply–add is used (it would round once where the portable
//! code rounds twice), so the results are the same bits on every processor.
//!
//! Why by hand: the compiler's vectoriser regroups the portable loops across the dot products
//! (one register holding lanes of two different sums, shuffled every iteration) instead of
//! keeping each product's four sums in one register.

pub use crate::numerics::cpu::has_avx as available;

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::{
    __m256d, _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_set1_pd, _mm256_setzero_pd,
    _mm256_storeu_pd, _mm256_sub_pd,
};

/// The four lanes of `v`, in order.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn lanes(v: __m256d) -> [f64; 4] {
    let mut out = [0.0; 4];
    // SAFETY: `out` holds four values.
    unsafe { _mm256_storeu_pd(out.as_mut_ptr(), v) };
    out
}

/// Four values of `values` from `at` as a register.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn load(values: &[f64], at: usize) -> __m256d {
    let four: &[f64; 4] = values[at..at + 4].try_into().expect("four values");
    // SAFETY: `four` is four consecutive values.
    unsafe { _mm256_loadu_pd(four.as_ptr()) }
}

/// Σ aᵢ·bₖᵢ for each of the K vectors bₖ (over the shortest length), summed as the parent
/// module's `dot_group_portable` sums: lanes over the rows in fours, then
/// (s₀ + s₁) + (s₂ + s₃) + the tail.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
pub fn dot_group<const K: usize>(a: &[f64], b: [&[f64]; K]) -> [f64; K] {
    let n = b.iter().fold(a.len(), |n, b| n.min(b.len()));
    let (a, b) = (&a[..n], b.map(|b| &b[..n]));
    let body = n / 4 * 4;
    let mut acc = [_mm256_setzero_pd(); K];
    for i in (0..body).step_by(4) {
        let x = load(a, i);
        for (acc, b) in acc.iter_mut().zip(&b) {
            *acc = _mm256_add_pd(*acc, _mm256_mul_pd(x, load(b, i)));
        }
    }
    std::array::from_fn(|k| {
        let tail: f64 = a[body..]
            .iter()
            .zip(&b[k][body..])
            .map(|(x, y)| x * y)
            .sum();
        let s = lanes(acc[k]);
        (s[0] + s[1]) + (s[2] + s[3]) + tail
    })
}

/// Σₜ rₜ² with rₜ = ((target(t) − w₀·col₀(t)) − w₁·col₁(t)) − …, the columns in order, and
/// the squares summed as a dot product of r with itself is summed (see the module docs).
/// Every column is at least as long as `target`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
pub fn residual_squares(target: &[f64], columns: &[(&[f64], f64)]) -> f64 {
    let n = target.len();
    let columns: Vec<(&[f64], __m256d)> = columns
        .iter()
        .map(|&(col, w)| (&col[..n], _mm256_set1_pd(w)))
        .collect();
    let body = n / 4 * 4;
    let mut acc = _mm256_setzero_pd();
    for t in (0..body).step_by(4) {
        let mut r = load(target, t);
        for &(col, w) in &columns {
            r = _mm256_sub_pd(r, _mm256_mul_pd(w, load(col, t)));
        }
        acc = _mm256_add_pd(acc, _mm256_mul_pd(r, r));
    }
    let tail: f64 = (body..n)
        .map(|t| {
            let r = columns
                .iter()
                .fold(target[t], |r, &(col, w)| r - lanes(w)[0] * col[t]);
            r * r
        })
        .sum();
    let s = lanes(acc);
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}
