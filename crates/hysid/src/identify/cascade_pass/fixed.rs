//! Fixed-width instances of the cascade passes for the common shapes (ch4/ch6, n ≤ 3,
//! m ≤ 3): the widths are const generics, so every per-sample loop has a length known to the
//! compiler, the rows live in arrays, and the ŷ ring is a four-slot array indexed by a mask.
//!
//! The operations and their order are those of the generic passes of the parent module
//! (the equations are in its docs), so the results are bit-identical; shapes outside the
//! instantiated set return `None` and the caller runs the generic pass.

use crate::model::HysteresisCascade;

/// Slots of the ŷ ring: lags 1 … n with n ≤ 3 fit, and the current sample is written after
/// the lags are read.
const OUT_SLOTS: usize = 4;

/// The (form width, n, m) of a cascade.
fn shape(cascade: &HysteresisCascade) -> (usize, usize, usize) {
    let lin = &cascade.linear;
    (cascade.hysteresis.form().n_params(), lin.na(), lin.nb())
}

/// The coefficients of A and B as arrays (their lengths are checked by the dispatch).
fn coefficients<const NA: usize, const M: usize>(
    cascade: &HysteresisCascade,
) -> Option<([f64; NA], [f64; M])> {
    let lin = &cascade.linear;
    Some((lin.a().try_into().ok()?, lin.b().try_into().ok()?))
}

/// The sensitivity recursion of the parent module for a fixed shape: NH hysteresis
/// parameters, n = NA, m = M and P = NH + M − 1 + NA parameters in all. Calls
/// `on_row(t, ŷ(t), ∂ŷ(t)/∂θ_free)` for every sample and returns the first sample whose
/// output is not finite (outer `None` when the widths do not match the cascade).
fn recursion_fixed<const NH: usize, const NA: usize, const M: usize, const P: usize>(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    free: &[usize],
    mut on_row: impl FnMut(usize, f64, &[f64]),
) -> Option<Option<usize>> {
    let (a, b) = coefficients::<NA, M>(cascade)?;
    if NH + M - 1 + NA != P || free.iter().any(|&i| i >= P) {
        return None;
    }
    let ch = &cascade.hysteresis;
    let k = cascade.linear.delay();
    // v(t) and s(t) are read at lags k … k+m−1: a ring of power-of-two length, lag = mask.
    let mask = (k + M).next_power_of_two() - 1;
    let mut ring_v = vec![0.0; mask + 1];
    let mut ring_s = vec![[0.0; NH]; mask + 1];
    let mut out_y = [0.0; OUT_SLOTS];
    let mut out_dy = [[0.0; P]; OUT_SLOTS];
    let mut row = vec![0.0; free.len()];
    let (mut v, mut s, mut partial) = (0.0, [0.0; NH], [0.0; NH]);
    let mut failed = None;
    for t in 0..x.len() {
        if t > 0 {
            let outside = ch.outside_at(x, t, h);
            let factor = ch.step_partials_in(v, x[t - 1], x[t], outside, &mut partial);
            v = ch.step_in(v, x[t - 1], x[t], outside);
            for (si, pi) in s.iter_mut().zip(&partial) {
                *si = factor * *si + pi;
            }
        }
        ring_v[t & mask] = v;
        ring_s[t & mask] = s;
        let mut u = [0.0; P];
        let mut yhat = 0.0;
        for (j, &bj) in b.iter().enumerate() {
            if t >= k + j {
                let slot = (t - k - j) & mask;
                let past_v = ring_v[slot];
                yhat += bj * past_v;
                for (ui, si) in u[..NH].iter_mut().zip(&ring_s[slot]) {
                    *ui += bj * si;
                }
                if j > 0 {
                    u[NH + j - 1] = past_v;
                }
            }
        }
        // u becomes ∂ŷ(t) in place: ∂ŷ(t) = u(t) − Σ aᵢ ∂ŷ(t−i).
        for (i, &ai) in a.iter().enumerate() {
            if t > i {
                let slot = (t - i - 1) % OUT_SLOTS;
                let past_y = out_y[slot];
                yhat -= ai * past_y;
                u[NH + M - 1 + i] -= past_y;
                for (d, pd) in u.iter_mut().zip(&out_dy[slot]) {
                    *d -= ai * pd;
                }
            }
        }
        if !yhat.is_finite() && failed.is_none() {
            failed = Some(t);
        }
        out_y[t % OUT_SLOTS] = yhat;
        out_dy[t % OUT_SLOTS] = u;
        for (r, &i) in row.iter_mut().zip(free) {
            *r = u[i];
        }
        on_row(t, yhat, &row);
    }
    Some(failed)
}

/// The simulation of the parent module ([`super::simulate_into`]) for n = NA, m = M;
/// `None` (and `y` untouched) when the widths do not match the cascade.
fn simulate_fixed<const NA: usize, const M: usize>(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    y: &mut Vec<f64>,
) -> Option<()> {
    let (a, b) = coefficients::<NA, M>(cascade)?;
    let ch = &cascade.hysteresis;
    let k = cascade.linear.delay();
    let mask = (k + M).next_power_of_two() - 1;
    let mut ring_v = vec![0.0; mask + 1];
    let mut out_y = [0.0; OUT_SLOTS];
    y.clear();
    y.reserve(x.len());
    let mut v_prev = 0.0;
    for t in 0..x.len() {
        let vt = if t == 0 {
            0.0
        } else {
            let outside = ch.outside_at(x, t, h);
            ch.step_in(v_prev, x[t - 1], x[t], outside)
        };
        ring_v[t & mask] = vt;
        v_prev = vt;
        let mut acc = 0.0;
        for (i, &ai) in a.iter().enumerate() {
            if t > i {
                acc -= ai * out_y[(t - i - 1) % OUT_SLOTS];
            }
        }
        for (j, &bj) in b.iter().enumerate() {
            if t >= k + j {
                acc += bj * ring_v[(t - k - j) & mask];
            }
        }
        out_y[t % OUT_SLOTS] = acc;
        y.push(acc);
    }
    Some(())
}

/// Runs the fixed-width sensitivity recursion when the cascade's shape has an instance
/// (ch4 or ch6, n ≤ 3, m ≤ 3): `Some(first non-finite sample)`, else `None`.
#[doc(hidden)] // reached by the white-box tests in tests/library/unit
pub fn recursion(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    free: &[usize],
    on_row: impl FnMut(usize, f64, &[f64]),
) -> Option<Option<usize>> {
    macro_rules! instances {
        ($(($nh:literal, $na:literal, $m:literal, $p:literal)),* $(,)?) => {
            match shape(cascade) {
                $(($nh, $na, $m) => recursion_fixed::<$nh, $na, $m, $p>(cascade, x, h, free, on_row),)*
                _ => None,
            }
        };
    }
    instances!(
        (4, 0, 1, 4),
        (4, 0, 2, 5),
        (4, 0, 3, 6),
        (4, 1, 1, 5),
        (4, 1, 2, 6),
        (4, 1, 3, 7),
        (4, 2, 1, 6),
        (4, 2, 2, 7),
        (4, 2, 3, 8),
        (4, 3, 1, 7),
        (4, 3, 2, 8),
        (4, 3, 3, 9),
        (6, 0, 1, 6),
        (6, 0, 2, 7),
        (6, 0, 3, 8),
        (6, 1, 1, 7),
        (6, 1, 2, 8),
        (6, 1, 3, 9),
        (6, 2, 1, 8),
        (6, 2, 2, 9),
        (6, 2, 3, 10),
        (6, 3, 1, 9),
        (6, 3, 2, 10),
        (6, 3, 3, 11),
    )
}

/// Runs the fixed-width simulation when n ≤ 3 and m ≤ 3; `None` (and `y` untouched)
/// otherwise.
#[doc(hidden)] // reached by the white-box tests in tests/library/unit
pub fn simulate(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    y: &mut Vec<f64>,
) -> Option<()> {
    macro_rules! instances {
        ($(($na:literal, $m:literal)),* $(,)?) => {
            match (cascade.linear.na(), cascade.linear.nb()) {
                $(($na, $m) => simulate_fixed::<$na, $m>(cascade, x, h, y),)*
                _ => None,
            }
        };
    }
    instances!(
        (0, 1),
        (0, 2),
        (0, 3),
        (1, 1),
        (1, 2),
        (1, 3),
        (2, 1),
        (2, 2),
        (2, 3),
        (3, 1),
        (3, 2),
        (3, 3),
    )
}
