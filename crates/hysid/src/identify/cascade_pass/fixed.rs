//! Fixed-width instances of the cascade passes for the common shapes (ch4/ch6, n ≤ 3,
//! m ≤ 3): the widths are const generics, so every per-sample loop has a length known to the
//! compiler, and the last n values of ŷ and ∂ŷ are arrays shifted by value, indexed only by
//! constants, so that they stay in registers. Rows are written whole into the hand-over block
//! (`[ŷ, ∂ŷ/∂θ]`, all P sensitivities; the free ones are picked per block when some are
//! fixed), and the first rows, which lack some lags, run as a separate instance of the same
//! loop, so the others carry no test of t.
//!
//! The operations and their order are those of the generic passes of the parent module
//! (the equations are in its docs), so the results are bit-identical; shapes outside the
//! instantiated set return `None` and the caller runs the generic pass.

use super::Block;
use crate::model::{ColemanHodgdon, HysteresisCascade};

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

/// What the fixed-width recursion carries from one sample to the next besides the rings of
/// v and s: v(t), s(t) and the last n values of ŷ and ∂ŷ (newest first, shifted by value). A
/// plain value, so that inside [`fill`] it lives in registers.
#[derive(Clone, Copy)]
struct Carry<const NH: usize, const NA: usize, const P: usize> {
    v: f64,
    s: [f64; NH],
    y_lag: [f64; NA],
    dy_lag: [[f64; P]; NA],
}

/// The rings of v(t) and s(t) over the lags k … k+m−1 (power-of-two length: a lag is a mask).
struct Rings<const NH: usize> {
    mask: usize,
    v: Vec<f64>,
    s: Vec<[f64; NH]>,
}

impl<const NH: usize> Rings<NH> {
    fn new(k: usize, m: usize) -> Self {
        let len = (k + m).next_power_of_two();
        Self {
            mask: len - 1,
            v: vec![0.0; len],
            s: vec![[0.0; NH]; len],
        }
    }
}

/// The model constants one row of the recursion reads.
struct Constants<'a, const NA: usize, const M: usize> {
    ch: &'a ColemanHodgdon,
    a: [f64; NA],
    b: [f64; M],
    k: usize,
}

/// Row t of the recursion: (ŷ(t), ∂ŷ(t)/∂θ). `WARM` rows (t < max(k + m − 1, n)) skip the
/// lags that fall before the record; the other rows have every lag.
#[inline(always)]
fn row<const WARM: bool, const NH: usize, const NA: usize, const M: usize, const P: usize>(
    c: &mut Carry<NH, NA, P>,
    rings: &mut Rings<NH>,
    constants: &Constants<'_, NA, M>,
    x: &[f64],
    t: usize,
    outside: bool,
) -> (f64, [f64; P]) {
    let (a, b, k, mask) = (&constants.a, &constants.b, constants.k, rings.mask);
    if t > 0 {
        let mut partial = [0.0; NH];
        let ch = constants.ch;
        let factor = ch.step_partials_in(c.v, x[t - 1], x[t], outside, &mut partial);
        c.v = ch.step_in(c.v, x[t - 1], x[t], outside);
        for (si, pi) in c.s.iter_mut().zip(&partial) {
            *si = factor * *si + pi;
        }
    }
    rings.v[t & mask] = c.v;
    rings.s[t & mask] = c.s;
    // ŷ(t) with the operations of the simulation, in its order (A's terms, then B's), so
    // that the pass's ŷ is the simulated output bit for bit and can serve as the residuals.
    let mut yhat = 0.0;
    for (i, &ai) in a.iter().enumerate() {
        if !WARM || t > i {
            yhat -= ai * c.y_lag[i];
        }
    }
    for (j, &bj) in b.iter().enumerate() {
        if !WARM || t >= k + j {
            yhat += bj * rings.v[(t - k - j) & mask];
        }
    }
    let mut u = [0.0; P];
    for (j, &bj) in b.iter().enumerate() {
        if !WARM || t >= k + j {
            let slot = (t - k - j) & mask;
            let past_v = rings.v[slot];
            for (ui, si) in u[..NH].iter_mut().zip(&rings.s[slot]) {
                *ui += bj * si;
            }
            if j > 0 {
                u[NH + j - 1] = past_v;
            }
        }
    }
    // u becomes ∂ŷ(t) in place: ∂ŷ(t) = u(t) − Σ aᵢ ∂ŷ(t−i).
    for (i, &ai) in a.iter().enumerate() {
        if !WARM || t > i {
            let past_y = c.y_lag[i];
            u[NH + M - 1 + i] -= past_y;
            for (d, pd) in u.iter_mut().zip(&c.dy_lag[i]) {
                *d -= ai * pd;
            }
        }
    }
    for i in (1..NA).rev() {
        c.y_lag[i] = c.y_lag[i - 1];
        c.dy_lag[i] = c.dy_lag[i - 1];
    }
    if NA > 0 {
        c.y_lag[0] = yhat;
        c.dy_lag[0] = u;
    }
    (yhat, u)
}

/// Rows `t0 …` into `rows`, each `[ŷ, ∂ŷ/∂θ]` with all P sensitivities. Every index into a
/// row is a constant, so ∂ŷ stays in registers (a gather by the free indices here would
/// keep it in memory and stall every row on the store-to-load forwarding of its copy).
#[inline(always)]
fn fill<const WARM: bool, const NH: usize, const NA: usize, const M: usize, const P: usize>(
    carry: &mut Carry<NH, NA, P>,
    rings: &mut Rings<NH>,
    constants: &Constants<'_, NA, M>,
    (x, h): (&[f64], Option<&[bool]>),
    t0: usize,
    rows: &mut [f64],
) -> bool {
    let mut c = *carry;
    // Whether every ŷ is finite, noted as the rows are made: a search of the block afterwards
    // would read it all again (a megabyte, out of the first-level caches) on the side of the
    // pass that bounds it.
    let mut finite = true;
    for (i, out) in rows.chunks_exact_mut(1 + P).enumerate() {
        let t = t0 + i;
        let outside = constants.ch.outside_at(x, t, h);
        let (yhat, u) = row::<WARM, NH, NA, M, P>(&mut c, rings, constants, x, t, outside);
        finite &= yhat.is_finite();
        out[0] = yhat;
        out[1..].copy_from_slice(&u);
    }
    *carry = c;
    finite
}

/// The sensitivity recursion of the parent module for a fixed shape: NH hysteresis
/// parameters, n = NA, m = M and P = NH + M − 1 + NA parameters in all. Writes the rows into
/// `block` and hands every full block (and the last one) to `on_block`; returns the first
/// sample whose output is not finite (outer `None` when the widths do not match the cascade).
///
/// On x86-64 the loop is compiled for AVX only ([`recursion_fixed_avx`], detected at run
/// time): the same operations in the same order, but with sixteen 4-lane registers the carry
/// stays in registers and the row's updates take a quarter fewer instructions. No fused
/// multiply–add is enabled, so every lane rounds as the scalar code does: the rows are the
/// same bits on every processor. An x86-64 processor without AVX (made before 2011) gets
/// `None`, i.e. the generic pass, which gives the same bits more slowly: a baseline copy of
/// all 24 shapes would double their compile time (the test command's critical path) for
/// machines that hardly exist. Other architectures compile the loop as it is.
#[inline(never)] // one function per shape: each gets its own register allocation
fn recursion_fixed<const NH: usize, const NA: usize, const M: usize, const P: usize>(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    free: &[usize],
    block: &mut Block,
    on_block: &mut dyn FnMut(&mut Block),
) -> Option<Option<usize>> {
    #[cfg(target_arch = "x86_64")]
    {
        if !crate::numerics::cpu::has_avx() {
            return None;
        }
        // SAFETY: the processor has AVX, the only requirement of `recursion_fixed_avx`.
        unsafe { recursion_fixed_avx::<NH, NA, M, P>(cascade, x, h, free, block, on_block) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    recursion_fixed_body::<NH, NA, M, P>(cascade, x, h, free, block, on_block)
}

/// [`recursion_fixed_body`] compiled for AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn recursion_fixed_avx<const NH: usize, const NA: usize, const M: usize, const P: usize>(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    free: &[usize],
    block: &mut Block,
    on_block: &mut dyn FnMut(&mut Block),
) -> Option<Option<usize>> {
    recursion_fixed_body::<NH, NA, M, P>(cascade, x, h, free, block, on_block)
}

/// The loop of [`recursion_fixed`].
#[inline(always)]
fn recursion_fixed_body<const NH: usize, const NA: usize, const M: usize, const P: usize>(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    free: &[usize],
    block: &mut Block,
    on_block: &mut dyn FnMut(&mut Block),
) -> Option<Option<usize>> {
    let (a, b) = coefficients::<NA, M>(cascade)?;
    if NH + M - 1 + NA != P || free.iter().any(|&i| i >= P) {
        return None;
    }
    let k = cascade.linear.delay();
    let constants = Constants {
        ch: &cascade.hysteresis,
        a,
        b,
        k,
    };
    // Rows before this one lack a lag of v (t < k + m − 1) or of ŷ (t < n).
    let warm = (k + M - 1).max(NA);
    let mut carry = Carry::<NH, NA, P> {
        v: 0.0,
        s: [0.0; NH],
        y_lag: [0.0; NA],
        dy_lag: [[0.0; P]; NA],
    };
    let mut rings = Rings::<NH>::new(k, M);
    let mut failed = None;
    let mut t0 = 0;
    // With every parameter free the rows go straight into the block; otherwise into full
    // rows first, then their free columns into the block.
    let all = free.len() == P && free.iter().enumerate().all(|(c, &f)| c == f);
    let mut full = if all {
        Vec::new()
    } else {
        vec![0.0; block.capacity * (1 + P)]
    };
    while t0 < x.len() {
        let n = block.capacity.min(x.len() - t0);
        let rows = if all {
            &mut block.rows[..n * (1 + P)]
        } else {
            &mut full[..n * (1 + P)]
        };
        let cold = warm.saturating_sub(t0).min(n);
        let (head, tail) = rows.split_at_mut(cold * (1 + P));
        let signals = (x, h);
        let warm_finite =
            fill::<true, NH, NA, M, P>(&mut carry, &mut rings, &constants, signals, t0, head);
        let finite = fill::<false, NH, NA, M, P>(
            &mut carry,
            &mut rings,
            &constants,
            signals,
            t0 + cold,
            tail,
        );
        if failed.is_none() && !(warm_finite && finite) {
            failed = rows
                .iter()
                .step_by(1 + P)
                .position(|v| !v.is_finite())
                .map(|i| t0 + i);
        }
        if !all {
            select_columns(&full[..n * (1 + P)], 1 + P, free, &mut block.rows);
        }
        block.start = t0;
        block.len = n;
        on_block(block);
        t0 += n;
    }
    Some(failed)
}

/// The simulation of the parent module ([`super::simulate_into`]) for n = NA, m = M;
/// `None` (and `y` untouched) when the widths do not match the cascade.
#[inline(never)] // one function per shape: each gets its own register allocation
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
    // ŷ(t−1−i) at i, shifted by value: constant indices keep it in registers.
    let mut y_lag = [0.0; NA];
    // Written by index, not pushed: a push's possible reallocation is a call that keeps
    // the loop's values in memory. (The caller's buffer usually has the length already.)
    y.resize(x.len(), 0.0);
    let mut v_prev = 0.0;
    for (t, out) in y.iter_mut().enumerate() {
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
                acc -= ai * y_lag[i];
            }
        }
        for (j, &bj) in b.iter().enumerate() {
            if t >= k + j {
                acc += bj * ring_v[(t - k - j) & mask];
            }
        }
        for i in (1..NA).rev() {
            y_lag[i] = y_lag[i - 1];
        }
        if NA > 0 {
            y_lag[0] = acc;
        }
        *out = acc;
    }
    Some(())
}

/// Copies ŷ and the columns `free` of the full rows `full` (`width` values each) into
/// `rows`, row by row.
fn select_columns(full: &[f64], width: usize, free: &[usize], rows: &mut [f64]) {
    for (source, out) in full
        .chunks_exact(width)
        .zip(rows.chunks_exact_mut(1 + free.len()))
    {
        out[0] = source[0];
        for (o, &f) in out[1..].iter_mut().zip(free) {
            *o = source[1 + f];
        }
    }
}

/// Runs the fixed-width sensitivity recursion when the cascade's shape has an instance
/// (ch4 or ch6, n ≤ 3, m ≤ 3), writing the rows into `block` and handing every full block
/// (and the last one) to `on_block`: `Some(first non-finite sample)`, else `None` (and
/// `on_block` not called).
pub(super) fn recursion_blocks(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    free: &[usize],
    block: &mut Block,
    on_block: &mut dyn FnMut(&mut Block),
) -> Option<Option<usize>> {
    macro_rules! instances {
        ($(($nh:literal, $na:literal, $m:literal, $p:literal)),* $(,)?) => {
            match shape(cascade) {
                $(($nh, $na, $m) => recursion_fixed::<$nh, $na, $m, $p>(cascade, x, h, free, block, on_block),)*
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

/// [`recursion_blocks`] row by row: `on_row(t, ŷ(t), ∂ŷ(t)/∂θ_free)` for every sample.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn recursion(
    cascade: &HysteresisCascade,
    x: &[f64],
    h: Option<&[bool]>,
    free: &[usize],
    mut on_row: impl FnMut(usize, f64, &[f64]),
) -> Option<Option<usize>> {
    let mut block = Block::new(free.len(), super::SEQUENTIAL_ROWS);
    recursion_blocks(cascade, x, h, free, &mut block, &mut |b| {
        b.each_row(&mut on_row)
    })
}

/// Runs the fixed-width simulation when n ≤ 3 and m ≤ 3; `None` (and `y` untouched)
/// otherwise.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
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
