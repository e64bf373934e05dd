//! Tapes bound to a parameter vector (`EquationModel::bind_columns`, `bind_rhs`): the same
//! values, to the bit, as the unbound tapes at that θ, on every continuous-time example
//! and at random points; fewer instructions; and the structure a simulation relies on
//! (constant Jacobian entries, whether t is read).

use crate::common;

use common::{example, Rng};
use hysid_equations::EquationModel;

const CONTINUOUS: [&str; 4] = [
    "bouc_wen.toml",
    "actuator_fixed.toml",
    "duffing.toml",
    "cascaded_tanks.toml",
];

/// Equal to the bit, or both zero (a bound tape may fold x·1 where the unbound one adds a
/// signed zero), or both NaN.
fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a == 0.0 && b == 0.0) || (a.is_nan() && b.is_nan())
}

/// θ within ±30 % of the declared values (fixed parameters kept), x and u in [−2, 2], with
/// some states exactly zero (the non-smooth points of abs, sign and powers).
fn random_point(m: &EquationModel, rng: &mut Rng) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let theta = m
        .parameters()
        .iter()
        .map(|p| {
            if p.fixed {
                p.value
            } else {
                (p.value * rng.uniform(0.7, 1.3)).clamp(p.lower, p.upper)
            }
        })
        .collect();
    let mut x: Vec<f64> = (0..m.states().len())
        .map(|_| rng.uniform(-2.0, 2.0))
        .collect();
    if rng.uniform(0.0, 1.0) < 0.25 {
        x[0] = 0.0;
    }
    let u = (0..m.inputs().len())
        .map(|_| rng.uniform(-2.0, 2.0))
        .collect();
    (theta, x, u)
}

#[test]
fn bound_tapes_give_the_unbound_values_to_the_bit() {
    let mut rng = Rng::new(12);
    for name in CONTINUOUS {
        let m = EquationModel::parse(&example(name)).unwrap();
        let (n, p) = (m.states().len(), m.parameters().len());
        let free: Vec<usize> = (0..p).filter(|&i| !m.parameters()[i].fixed).collect();
        for params in [free.clone(), free[1..].to_vec(), (0..p).collect()] {
            let columns = m.rhs_jacobian_columns(&params).unwrap();
            let k = params.len();
            for trial in 0..200 {
                let (theta, x, u) = random_point(&m, &mut rng);
                let mut bound = m.bind_columns(&columns, &theta).unwrap();
                let mut got = vec![f64::NAN; n + n * n + n * k];
                bound.fill_constants(&mut got);
                bound.eval(0.3, &x, &u, &mut got);
                let (mut dx, mut fx, mut ft) = (vec![0.0; n], vec![0.0; n * n], vec![0.0; n * k]);
                let mut s = m.scratch();
                m.rhs_jacobian_columns_with(
                    &mut s, &columns, 0.3, &x, &u, &theta, &mut dx, &mut fx, &mut ft,
                );
                let want: Vec<f64> = dx.into_iter().chain(fx).chain(ft).collect();
                for (i, (&g, &w)) in got.iter().zip(&want).enumerate() {
                    assert!(
                        same(g, w),
                        "{name} {params:?} #{trial} result {i}: {g} vs {w}"
                    );
                }
                let mut rates = m.bind_rhs(&theta).unwrap();
                let mut got = vec![f64::NAN; n];
                rates.fill_constants(&mut got);
                rates.eval(0.3, &x, &u, &mut got);
                let mut want = vec![0.0; n];
                m.rhs_with(&mut s, 0.3, &x, &u, &theta, &mut want);
                for (i, (&g, &w)) in got.iter().zip(&want).enumerate() {
                    assert!(same(g, w), "{name} rhs #{trial} state {i}: {g} vs {w}");
                }
            }
        }
    }
}

/// Bouc–Wen at ν = 1: the θ-only instructions (1/mL products, ν − 1) are computed once and
/// |z|^ν, |z|^(ν−1) reduce to |z| and 1, so at most half of the column tape is left; the
/// structural entries of ∂f/∂x are constants (ẏ = v: row 0 is (0, 1, 0); ż does not read y).
#[test]
fn binding_bouc_wen_halves_its_tape_and_exposes_its_structure() {
    let m = EquationModel::parse(&example("bouc_wen.toml")).unwrap();
    let columns = m.rhs_jacobian_columns(&[0, 1, 2, 3, 4, 5]).unwrap();
    let bound = m.bind_columns(&columns, &m.parameter_values()).unwrap();
    assert!(
        2 * bound.len() <= columns.len(),
        "{} of {}",
        bound.len(),
        columns.len()
    );
    let fx = |i: usize, j: usize| bound.constant(3 + 3 * i + j);
    assert_eq!(
        (fx(0, 0), fx(0, 1), fx(0, 2)),
        (Some(0.0), Some(1.0), Some(0.0))
    );
    assert_eq!(fx(2, 0), Some(0.0));
    // ∂ÿ/∂y = −kL/mL depends on θ alone.
    assert_eq!(fx(1, 0), Some(-5e4 / 2.0));
    assert_eq!(fx(2, 2), None);
    assert!(!bound.uses_time());
    // At ν = 1.3 the powers stay.
    let mut theta = m.parameter_values();
    theta[6] = 1.3;
    let curved = m.bind_columns(&columns, &theta).unwrap();
    assert!(curved.len() > bound.len());
    assert!(m.bind_columns(&columns, &theta[..6]).is_none());
}

#[test]
fn a_bound_tape_reports_whether_it_reads_t() {
    let text = example("duffing.toml").replace("u - c*v", "u*cos(t) - c*v");
    let m = EquationModel::parse(&text).unwrap();
    let columns = m.rhs_jacobian_columns(&[0, 1]).unwrap();
    assert!(m
        .bind_columns(&columns, &m.parameter_values())
        .unwrap()
        .uses_time());
    assert!(m.bind_rhs(&m.parameter_values()).unwrap().uses_time());
    let plain = EquationModel::parse(&example("duffing.toml")).unwrap();
    assert!(!plain
        .bind_rhs(&plain.parameter_values())
        .unwrap()
        .uses_time());
}
