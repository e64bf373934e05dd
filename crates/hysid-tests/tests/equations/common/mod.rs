//! Shared test helpers: a seeded generator and central-difference Jacobians.
#![allow(dead_code)]

use hysid_equations::EquationModel;

/// SplitMix64 (Steele, Lea, Flood 2014): a tiny seeded generator, so that every random
/// point of the tests is reproducible.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * unit
    }
}

/// Path of an example file.
pub fn example(name: &str) -> String {
    let path = format!(
        "{}/../../examples/equations/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// Which argument of f a central difference perturbs.
#[derive(Clone, Copy, Debug)]
pub enum Arg {
    State,
    Param,
    Input,
}

/// Central-difference Jacobian of the right-hand side (rows: equations, columns: the
/// entries of `arg`), step 1e-6 relative to each entry (1e-9 absolute below 1e-3).
pub fn fd_rhs(m: &EquationModel, t: f64, x: &[f64], u: &[f64], th: &[f64], arg: Arg) -> Vec<f64> {
    let n = x.len();
    let base: &[f64] = match arg {
        Arg::State => x,
        Arg::Param => th,
        Arg::Input => u,
    };
    let cols = base.len();
    let mut jac = vec![0.0; n * cols];
    for j in 0..cols {
        let h = 1e-6 * base[j].abs().max(1e-3);
        let eval = |delta: f64| {
            let mut v = base.to_vec();
            v[j] += delta;
            let mut dx = vec![0.0; n];
            match arg {
                Arg::State => m.rhs(t, &v, u, th, &mut dx),
                Arg::Param => m.rhs(t, x, u, &v, &mut dx),
                Arg::Input => m.rhs(t, x, &v, th, &mut dx),
            }
            dx
        };
        let (plus, minus) = (eval(h), eval(-h));
        for i in 0..n {
            jac[i * cols + j] = (plus[i] - minus[i]) / (2.0 * h);
        }
    }
    jac
}

/// Central-difference Jacobian of the output map.
pub fn fd_output(m: &EquationModel, x: &[f64], u: &[f64], th: &[f64], arg: Arg) -> Vec<f64> {
    let ny = m.outputs().len();
    let base: &[f64] = match arg {
        Arg::State => x,
        Arg::Param => th,
        Arg::Input => u,
    };
    let cols = base.len();
    let mut jac = vec![0.0; ny * cols];
    for j in 0..cols {
        let h = 1e-6 * base[j].abs().max(1e-3);
        let eval = |delta: f64| {
            let mut v = base.to_vec();
            v[j] += delta;
            let mut y = vec![0.0; ny];
            match arg {
                Arg::State => m.output(&v, u, th, &mut y),
                Arg::Param => m.output(x, u, &v, &mut y),
                Arg::Input => m.output(x, &v, th, &mut y),
            }
            y
        };
        let (plus, minus) = (eval(h), eval(-h));
        for i in 0..ny {
            jac[i * cols + j] = (plus[i] - minus[i]) / (2.0 * h);
        }
    }
    jac
}

/// Asserts `got` ≈ `want` to `rel` relative, each row judged against the row's largest
/// entry over `row_scale` (so that entries that are zero up to rounding compare sensibly);
/// returns the largest relative difference seen.
pub fn assert_rows_close(
    got: &[f64],
    want: &[f64],
    rows: usize,
    row_scale: &[f64],
    rel: f64,
    what: &str,
) -> f64 {
    let mut worst = 0.0f64;
    assert_eq!(got.len(), want.len(), "{what}: lengths");
    let cols = got.len().checked_div(rows).unwrap_or(0);
    for i in 0..rows {
        for j in 0..cols {
            let (g, w) = (got[i * cols + j], want[i * cols + j]);
            let scale = w.abs().max(g.abs()).max(1e-3 * row_scale[i]);
            if scale > 0.0 {
                worst = worst.max((g - w).abs() / scale);
            }
            assert!(
                (g - w).abs() <= rel * scale,
                "{what}[{i}][{j}]: got {g:e}, want {w:e} (scale {scale:e})"
            );
        }
    }
    worst
}
