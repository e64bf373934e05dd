//! Tests of `hysid::model::operators::preisach`.

use hysid::model::operators::preisach::{regressors, Grid, Memory};
use hysid::model::operators::HysteresisOperator;
use hysid::model::operators::Orientation;
use hysid::model::operators::*;

pub(crate) fn example(n: usize, a0: f64, o: Orientation) -> Preisach {
    let cells = n * (n + 1) / 2;
    let w: Vec<f64> = (0..cells)
        .map(|k| 0.05 + 0.1 * ((k * 7 % 11) as f64) / 11.0)
        .collect();
    Preisach::new(-2.0, 2.0, n, w, a0, 0.3, o).unwrap()
}

pub(crate) fn input(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            1.9 * (1.0 - 0.8 * t) * (41.0 * t).sin() + 0.25 * (157.0 * t).sin()
        })
        .collect()
}

#[test]
fn wiping_out_keeps_alternating_dominant_extrema() {
    let g = Grid {
        lower: -2.0,
        upper: 2.0,
        n: 4,
    };
    let mut m = Memory::new(&g);
    for x in [1.0, -1.0, 0.5, -0.5, 0.2] {
        m.apply(&g, x);
    }
    assert_eq!(m.points(), vec![-2.0, 1.0, -1.0, 0.5, -0.5, 0.2]);
    m.apply(&g, 0.7); // passes 0.5: wipes (0.5, −0.5)
    assert_eq!(m.points(), vec![-2.0, 1.0, -1.0, 0.7]);
    m.apply(&g, -1.5); // passes −1: wipes (−1, 0.7)... back to the first descent
    assert_eq!(m.points(), vec![-2.0, 1.0, -1.5]);
    m.apply(&g, 3.0); // positive saturation
    assert_eq!(m.points(), vec![-2.0, 2.0]);
    m.apply(&g, -3.0); // negative saturation
    assert_eq!(m.points(), vec![-2.0]);
}

#[test]
fn everett_simulation_equals_the_sum_over_relay_cells() {
    let p = example(6, 0.2, Orientation::default());
    let u = input(1500);
    let y = p.simulate(&u).unwrap();
    let mut memory = Memory::new(p.grid());
    let mut phi = vec![0.0; p.grid().cells()];
    for (k, &x) in u.iter().enumerate() {
        memory.apply(p.grid(), x);
        regressors(p.grid(), &memory, &mut phi);
        let direct: f64 =
            p.offset() + p.a0() * x + phi.iter().zip(p.weights()).map(|(f, w)| f * w).sum::<f64>();
        assert!(
            (direct - y[k]).abs() < 1e-12,
            "sample {k}: {direct} vs {}",
            y[k]
        );
    }
    // saturation: ±Σw
    let total: f64 = p.weights().iter().sum();
    let ys = p.simulate(&[5.0, -5.0]).unwrap();
    assert!(
        (ys[0] - (0.3 + 1.0 + total)).abs() < 1e-12 && (ys[1] - (0.3 - 1.0 - total)).abs() < 1e-12
    );
}

#[test]
fn numerical_inverse_round_trip_both_orientations() {
    let u = input(1200);
    for o in [Orientation::COUNTER_CLOCKWISE, Orientation::CLOCKWISE] {
        let p = example(5, 0.3, o);
        let reference = p.simulate(&u).unwrap();
        let inv = p.invert(&reference).unwrap();
        let err = inv
            .predicted
            .iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-6 && inv.clipped.is_empty(), "{o:?} {err}");
    }
    // without a reversible part the output saturates: beyond is clipped
    let p = example(4, 0.0, Orientation::default());
    let total: f64 = p.weights().iter().sum();
    let inv = p.invert(&[0.0, 0.3 + total + 1.0, 0.5]).unwrap();
    assert_eq!(inv.clipped, vec![1]);
    assert!(
        (inv.predicted[1] - (0.3 + total)).abs() < 1e-9 && (inv.predicted[2] - 0.5).abs() < 1e-9
    );
}

/// The bounded inverse (bisection over the grid levels and the memory's corners, then the
/// cell's quadratic) solves G(x) = r to rounding on references that are no model's output:
/// a seeded random walk with reversals of every size, beyond the grid's output range at
/// times, on planes of 1 to 20 levels, with and without the linear term.
#[test]
fn the_bounded_inverse_solves_arbitrary_references_to_rounding() {
    let mut uniform = crate::unit::test_signals::xorshift_uniform(0x2545_f491_4f6c_dd1du64);
    for n in [1, 2, 5, 20] {
        for a0 in [0.3, 0.0] {
            let p = example(n, a0, Orientation::default());
            let (lo, hi) = {
                let y = p.simulate(&[-2.0, 2.0]).unwrap();
                (y[0], y[1])
            };
            let mut r = Vec::new();
            let mut x = 0.5 * (lo + hi);
            for _ in 0..2000 {
                x += (uniform() - 0.5) * (hi - lo) * uniform().powi(3) * 1.5;
                r.push(x);
            }
            let inv = p.invert(&r).unwrap();
            for (k, (&rk, &yk)) in r.iter().zip(&inv.predicted).enumerate() {
                let reached = a0 > 0.0 || (rk > lo + 1e-9 && rk < hi - 1e-9);
                if reached {
                    assert!(
                        (yk - rk).abs() <= 1e-9 * (1.0 + rk.abs()),
                        "n {n} a0 {a0} sample {k}: G(G⁻¹(r)) = {yk} for r = {rk}"
                    );
                    assert!(
                        !inv.clipped.contains(&k),
                        "n {n} a0 {a0} sample {k} clipped"
                    );
                } else if rk < lo - 1e-9 || rk > hi + 1e-9 {
                    assert!(inv.clipped.contains(&k), "n {n} sample {k} beyond reach");
                }
            }
        }
    }
}

/// The inverse's O(1) Everett function (row and column sums) equals the simulation's (cut
/// cells summed) up to rounding, on every pair of a fine grid of (α, β) — inside cells, on
/// levels, on the diagonal and beyond the plane.
#[test]
fn the_everett_function_by_sums_equals_the_cell_sum() {
    for n in [1, 3, 20] {
        let p = example(n, 0.2, Orientation::default());
        let total: f64 = p.weights().iter().sum();
        for a in 0..=97 {
            for b in 0..=97 {
                let (alpha, beta) = (-2.3 + 4.6 * a as f64 / 97.0, -2.3 + 4.6 * b as f64 / 97.0);
                let (direct, by_sums) = (p.everett(alpha, beta), p.everett_by_sums(alpha, beta));
                assert!(
                    (direct - by_sums).abs() <= 1e-13 * total,
                    "n {n}: E({alpha}, {beta}) = {direct} vs {by_sums}"
                );
            }
        }
        // on the levels themselves
        for i in 0..=n {
            for j in 0..=i {
                let (alpha, beta) = (p.grid().level(i), p.grid().level(j));
                let d = (p.everett(alpha, beta) - p.everett_by_sums(alpha, beta)).abs();
                assert!(d <= 1e-13 * total, "n {n}: levels {i}, {j}: {d}");
            }
        }
    }
}
