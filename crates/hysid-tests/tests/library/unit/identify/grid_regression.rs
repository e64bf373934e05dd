//! Tests of `hysid::identify::grid_regression`.

use hysid::identify::global::basis_signals;
use hysid::identify::grid_regression::*;
use hysid::model::ChForm;
use nalgebra::{DMatrix, DVector};

/// The cost agrees with a plain least-squares fit on the explicit regressor matrix, for
/// both forms and a grid point away from the truth (so the cost is not zero).
#[test]
fn cost_matches_explicit_least_squares() {
    let x: Vec<f64> = (0..3000)
        .map(|t| 5.0 * (t as f64 * 0.05).sin() * (1.0 + 0.3 * (t as f64 * 0.003).cos()))
        .collect();
    let y: Vec<f64> = (0..x.len())
        .map(|t| (t as f64 * 0.031).sin() + 0.2 * (t as f64 * 0.17).cos())
        .collect();
    for (form, nl) in [(ChForm::Saturated4, 2), (ChForm::General6, 4)] {
        let (na, nb, k) = (2, 2, 1);
        let reg = EquationError::new(form, na, nb, k, &x, &y);
        let mut s = reg.scratch();
        let (alpha, d) = (0.25, 2.2);
        let cost = reg.cost(alpha, d, &mut s).unwrap();
        let psi = basis_signals(form, &x, alpha, d);
        let t0 = 2;
        let cols = na + nb * nl;
        let phi = DMatrix::from_fn(x.len() - t0, cols, |r, c| {
            let t = r + t0;
            if c < na {
                -y[t - c - 1]
            } else {
                psi[(c - na) % nl][t - k - (c - na) / nl]
            }
        });
        let target = DVector::from_column_slice(&y[t0..]);
        let theta = phi.clone().svd(true, true).solve(&target, 1e-14).unwrap();
        let expected = (target - phi * theta).norm_squared();
        assert!(
            (cost - expected).abs() < 1e-9 * expected,
            "{form:?}: {cost} vs {expected}"
        );
    }
}

#[test]
fn cholesky_solves_a_known_system() {
    // A = [[4, 2], [2, 3]], b = A·[1, −2] = [0, −4].
    let mut a = [4.0, 2.0, 2.0, 3.0];
    let mut b = [0.0, -4.0];
    cholesky_solve(&mut a, &mut b, 2).unwrap();
    assert!((b[0] - 1.0).abs() < 1e-15 && (b[1] + 2.0).abs() < 1e-15);
    let mut singular = [1.0, 1.0, 1.0, 1.0];
    assert!(cholesky_solve(&mut singular, &mut b, 2).is_none());
}

/// Seeded values of mixed signs and magnitudes (so the order of summation shows in the bits).
fn random_values(seed: u64, n: usize) -> Vec<f64> {
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::{RngExt, SeedableRng};
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..n)
        .map(|_| rng.random_range(-1.0..1.0) * 10f64.powi(rng.random_range(-3..4)))
        .collect()
}

/// The AVX dot products (when the processor has AVX) are the portable ones bit for bit, for
/// groups of one to seven products and every length of tail; the portable ones equal a
/// plain sum in the documented order (lanes i mod 4, then (s₀ + s₁) + (s₂ + s₃) + tail).
#[test]
fn dot_products_are_the_same_bits_with_and_without_simd() {
    for n in [0, 1, 3, 4, 5, 6, 7, 8, 101, 1000] {
        let a = random_values(n as u64, n);
        let bs: Vec<Vec<f64>> = (0..7)
            .map(|k| random_values(100 + k, n + k as usize))
            .collect();
        for k in 1..=7 {
            let b: Vec<&[f64]> = bs[..k].iter().map(|b| b.as_slice()).collect();
            let mut portable = vec![0.0; k];
            dots(&a, &b, &mut portable, false);
            for (j, b) in b.iter().enumerate() {
                let body = n / 4 * 4;
                let mut s = [0.0; 4];
                for i in 0..body {
                    s[i % 4] += a[i] * b[i];
                }
                let tail: f64 = (body..n).map(|i| a[i] * b[i]).sum();
                let expected = (s[0] + s[1]) + (s[2] + s[3]) + tail;
                assert_eq!(
                    portable[j].to_bits(),
                    expected.to_bits(),
                    "n {n}, k {k}, j {j}"
                );
            }
            if simd::available() {
                let mut fast = vec![0.0; k];
                dots(&a, &b, &mut fast, true);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&fast), bits(&portable), "n {n}, k {k}");
            }
        }
    }
}

/// The one-pass AVX residual sum of squares (when the processor has AVX) is the portable
/// two-step one (residual vector, then its dot product) bit for bit.
#[test]
fn residual_squares_are_the_same_bits_with_and_without_simd() {
    for n in [0, 1, 2, 3, 4, 5, 9, 1000, 1003] {
        let target = random_values(7 + n as u64, n);
        let cols: Vec<Vec<f64>> = (0..6).map(|c| random_values(50 + c, n + 2)).collect();
        let weights = random_values(99, 6);
        for used in 0..=6 {
            let columns: Vec<(&[f64], f64)> = cols[..used]
                .iter()
                .zip(&weights)
                .map(|(c, &w)| (c.as_slice(), w))
                .collect();
            let mut r = Vec::new();
            let portable = residual_squares(&target, &columns, &mut r, false);
            let mut residual = target.clone();
            for (c, w) in &columns {
                for (ri, ci) in residual.iter_mut().zip(c.iter()) {
                    *ri -= w * ci;
                }
            }
            let plain: f64 = residual.iter().map(|r| r * r).sum();
            assert!(
                (portable - plain).abs() <= 1e-12 * plain.abs().max(1e-300),
                "n {n}"
            );
            if simd::available() {
                let fast = residual_squares(&target, &columns, &mut r, true);
                assert_eq!(fast.to_bits(), portable.to_bits(), "n {n}, {used} columns");
            }
        }
    }
}

/// The two-pass basis signals (inputs first, then the recursions) are bit for bit the
/// one-pass recursion of the module docs, for both forms, with samples at zero and exactly
/// at the threshold.
#[test]
fn basis_signals_are_the_one_pass_recursion() {
    let mut x = random_values(3, 2003);
    x[10] = 0.0;
    x[11] = 0.0;
    x[500] = 0.7;
    x[501] = -0.7;
    for (form, nl) in [(ChForm::Saturated4, 2), (ChForm::General6, 4)] {
        for (alpha, d) in [(0.01, 0.7), (0.2, 0.05), (1e-4, 3.0)] {
            let psi = basis_signals(form, &x, alpha, d);
            let mut past = vec![0.0; nl];
            for t in 1..x.len() {
                let dx = x[t] - x[t - 1];
                let adx = dx.abs();
                let h = if x[t].abs() > d { 1.0 } else { 0.0 };
                let sgn = if x[t] > 0.0 {
                    1.0
                } else if x[t] < 0.0 {
                    -1.0
                } else {
                    0.0
                };
                let u = if nl == 2 {
                    vec![
                        alpha * adx * (x[t] * (1.0 - h) + d * sgn * h),
                        (1.0 - h) * dx,
                    ]
                } else {
                    vec![
                        alpha * adx * (x[t] * (1.0 - h) + d * sgn * h),
                        alpha * adx * (x[t] * h - d * sgn * h),
                        (1.0 - h) * dx,
                        h * dx,
                    ]
                };
                for i in 0..nl {
                    past[i] = (1.0 - alpha * adx) * past[i] + u[i];
                    assert_eq!(psi[i][t].to_bits(), past[i].to_bits(), "{form:?} ψ{i}({t})");
                }
            }
            assert!(psi.iter().all(|s| s[0] == 0.0));
        }
    }
}

/// Scoring up to `BATCH` thresholds of one α together (their ψ recursions interleaved) gives
/// every point the bits of scoring it alone, for both forms, full and partial batches, and
/// points whose regression fails (d beyond the input: a column vanishes).
#[test]
fn batched_costs_are_the_single_point_costs_bit_for_bit() {
    let x: Vec<f64> = (0..2500)
        .map(|t| 4.0 * (t as f64 * 0.041).sin() * (1.0 + 0.4 * (t as f64 * 0.0047).cos()))
        .collect();
    let y: Vec<f64> = (0..x.len())
        .map(|t| (t as f64 * 0.029).sin() + 0.3 * (t as f64 * 0.13).cos())
        .collect();
    for form in [ChForm::Saturated4, ChForm::General6] {
        let reg = EquationError::new(form, 2, 2, 1, &x, &y);
        let (mut single, mut batch) = (reg.scratch(), reg.scratch());
        let ds = [0.4, 1.1, 2.3, 3.2, 9.0];
        for alpha in [0.02, 0.3] {
            for len in 1..=BATCH {
                for start in 0..=ds.len() - len {
                    let chunk = &ds[start..start + len];
                    let costs = reg.costs(alpha, chunk, &mut batch);
                    for (b, &d) in chunk.iter().enumerate() {
                        let alone = reg.cost(alpha, d, &mut single);
                        assert_eq!(
                            costs[b].map(f64::to_bits),
                            alone.map(f64::to_bits),
                            "{form:?} alpha {alpha} d {d} in a batch of {len}"
                        );
                    }
                    assert!(costs[len..].iter().all(Option::is_none));
                }
            }
        }
        assert!(reg.costs(0.3, &[], &mut batch).iter().all(Option::is_none));
        assert!(reg
            .costs(0.3, &[1.0; BATCH + 1], &mut batch)
            .iter()
            .all(Option::is_none));
    }
}

/// A scratch made for another regression (another length or other orders) is refused: the
/// costs are None, nothing indexes past its buffers.
#[test]
fn a_scratch_of_another_regression_is_refused() {
    let x: Vec<f64> = (0..600).map(|t| 3.0 * (t as f64 * 0.07).sin()).collect();
    let y: Vec<f64> = (0..600).map(|t| (t as f64 * 0.05).cos()).collect();
    let reg = EquationError::new(ChForm::Saturated4, 2, 2, 1, &x, &y);
    let shorter = EquationError::new(ChForm::Saturated4, 2, 2, 1, &x[..500], &y[..500]);
    let other_orders = EquationError::new(ChForm::Saturated4, 3, 2, 1, &x, &y);
    assert!(reg.cost(0.3, 1.0, &mut reg.scratch()).is_some());
    for mut foreign in [shorter.scratch(), other_orders.scratch()] {
        assert!(reg
            .costs(0.3, &[1.0, 2.0], &mut foreign)
            .iter()
            .all(Option::is_none));
    }
}
