//! The equation-error cost of the over-parameterised regression of the global (α, d) search at
//! one grid point, in two passes over the record and without allocation per point.
//!
//! # Equations
//!
//! For fixed α and d the basis signals of the Coleman–Hodgdon recursion are
//!
//! ```text
//! ψᵢ(t) = (1 − α|Δx(t)|) ψᵢ(t−1) + uᵢ(t),  ψᵢ(0) = 0
//! u_m1 = α|Δx|(x(1−h) + d·sgn(x)h),   u_m2 = α|Δx|(x·h − d·sgn(x)h),
//! u_c1 = (1−h)Δx,                      u_c2 = h·Δx,          h(t) = (|x(t)| > d)
//! ```
//!
//! (ch4: m1 and c1 only), and the over-parameterised regression (Bai 1998) is
//! y(t) = φ(t)ᵀθ + e(t) with φ(t) = [−y(t−1)…−y(t−n), ψᵢ(t−k−j+1) for j = 1…m, i ∈ ℓ].
//! Its least-squares solution solves the column-scaled normal equations
//! S⁻¹ΦᵀΦS⁻¹ (Sθ) = S⁻¹Φᵀy, S = diag‖Φ columns‖, by Cholesky; the cost is
//! V(α, d) = Σₜ (y(t) − φ(t)ᵀθ)².
//!
//! # Why it is fast
//!
//! No regressor matrix is built: every column of Φ is a contiguous slice of y or of one ψᵢ
//! (shifted by its lag), so ΦᵀΦ, Φᵀy and the residual are dot products and vector updates of
//! slices. The block of lagged outputs in ΦᵀΦ and Φᵀy does not depend on (α, d)
//! and is computed once per record; every buffer lives in a [`Scratch`] reused from point to
//! point. The recursions of ψ are sequential in t, and one grid point's two or four of them
//! leave the processor waiting on each multiply–add: [`EquationError::costs`] runs the
//! recursions of up to [`BATCH`] points of one α in the same loop, independent chains that
//! overlap, and gives each point the bits [`EquationError::cost`] gives it.
//!
//! Reference: E.-W. Bai, "An optimal two-stage identification algorithm for
//! Hammerstein–Wiener nonlinear systems", Automatica 34(3), 1998.

use crate::model::coleman_hodgdon::switching;
use crate::model::ChForm;

#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub mod simd;

/// The record and structure of one global search, with the (α, d)-independent part of the
/// normal equations.
pub struct EquationError<'a> {
    form: ChForm,
    na: usize,
    nb: usize,
    delay: usize,
    x: &'a [f64],
    y: &'a [f64],
    /// First regression row: max(n, k + m − 1).
    t0: usize,
    /// Number of material coefficients ℓ (2 or 4).
    nl: usize,
    /// Σ y(t−a−1)y(t−b−1) over the rows, a, b < n (row-major).
    lag_gram: Vec<f64>,
    /// Σ −y(t−a−1)y(t) over the rows.
    lag_rhs: Vec<f64>,
}

/// Grid points whose basis signals [`EquationError::costs`] computes together (in one loop
/// over t). Four: the stage-A grid's 64 thresholds per α split evenly, and four points' ψ
/// (0.6 MB for a 10 000-sample window of ch4) stay in the second-level cache.
pub const BATCH: usize = 4;

/// Buffers of one evaluation, reused from grid point to grid point.
pub struct Scratch {
    /// ψ of up to [`BATCH`] points: point b's signal i at `psi[(b·NL + i)·N + t]` (room
    /// for one point at first, grown by the first batch of more).
    psi: Vec<f64>,
    /// 1 − α|Δx(t)|, the basis signals' common decay.
    decay: Vec<f64>,
    residual: Vec<f64>,
    gram: Vec<f64>,
    rhs: Vec<f64>,
    scale: Vec<f64>,
}

impl<'a> EquationError<'a> {
    /// The regression of `y` on the basis signals of `x` for the cascade with hysteresis
    /// `form`, n = `na`, m = `nb` and delay k = `delay`.
    pub fn new(
        form: ChForm,
        na: usize,
        nb: usize,
        delay: usize,
        x: &'a [f64],
        y: &'a [f64],
    ) -> Self {
        let nl = match form {
            ChForm::Saturated4 => 2,
            ChForm::General6 => 4,
        };
        let t0 = na.max(delay + nb - 1);
        let mut lag_gram = vec![0.0; na * na];
        let mut lag_rhs = vec![0.0; na];
        for t in t0..y.len().min(x.len()) {
            for a in 0..na {
                let ya = -y[t - a - 1];
                lag_rhs[a] += ya * y[t];
                for b in 0..na {
                    lag_gram[a * na + b] += ya * -y[t - b - 1];
                }
            }
        }
        Self {
            form,
            na,
            nb,
            delay,
            x,
            y,
            t0,
            nl,
            lag_gram,
            lag_rhs,
        }
    }

    /// Empty buffers for [`cost`](Self::cost).
    pub fn scratch(&self) -> Scratch {
        let cols = self.cols();
        Scratch {
            psi: vec![0.0; self.len() * self.nl],
            decay: vec![0.0; self.len()],
            residual: Vec::with_capacity(self.len()),
            gram: vec![0.0; cols * cols],
            rhs: vec![0.0; cols],
            scale: vec![0.0; cols],
        }
    }

    fn len(&self) -> usize {
        self.x.len().min(self.y.len())
    }

    fn cols(&self) -> usize {
        self.na + self.nb * self.nl
    }

    /// The least-squares cost V(α, d); None when there are too few rows, a regressor column
    /// vanishes or the normal equations are not positive definite.
    pub fn cost(&self, alpha: f64, d: f64, s: &mut Scratch) -> Option<f64> {
        self.costs(alpha, &[d], s)[0]
    }

    /// [`cost`](Self::cost) at (α, dᵦ) for each of up to [`BATCH`] thresholds `ds` (entry b;
    /// the entries past `ds` are None), the same bits as one call per point: the points' ψ
    /// recursions run in one loop (see the module docs), each with the operations of one.
    pub fn costs(&self, alpha: f64, ds: &[f64], s: &mut Scratch) -> [Option<f64>; BATCH] {
        let mut costs = [None; BATCH];
        let (n, cols) = (self.len(), self.cols());
        let block = n * self.nl;
        let enough_rows = n.checked_sub(self.t0).is_some_and(|rows| rows > cols);
        // A scratch made for a record of another length is refused, as is a batch too large.
        let fits = s.decay.len() == n && s.gram.len() == cols * cols;
        if !enough_rows || !fits || ds.is_empty() || ds.len() > BATCH {
            return costs;
        }
        if s.psi.len() < ds.len() * block {
            s.psi.resize(ds.len() * block, 0.0);
        }
        let psi = &mut s.psi[..ds.len() * block];
        basis_signals_batch(self.form, &self.x[..n], alpha, ds, psi, &mut s.decay);
        // One pass of the hysteresis basis over the record a point (the work count).
        super::budget::count(u64::try_from(n * ds.len()).unwrap_or(u64::MAX));
        for (b, cost) in costs.iter_mut().take(ds.len()).enumerate() {
            *cost = self.cost_of(b * block, s);
        }
        costs
    }

    /// The cost of the point whose ψ starts at `s.psi[at]`.
    fn cost_of(&self, at: usize, s: &mut Scratch) -> Option<f64> {
        let cols = self.cols();
        let psi = &s.psi[at..at + self.len() * self.nl];
        self.normal_equations(psi, &mut s.gram, &mut s.rhs);
        for c in 0..cols {
            s.scale[c] = s.gram[c * cols + c].sqrt();
            if s.scale[c] == 0.0 || !s.scale[c].is_finite() {
                return None;
            }
        }
        for i in 0..cols {
            s.rhs[i] /= s.scale[i];
            for j in 0..cols {
                s.gram[i * cols + j] /= s.scale[i] * s.scale[j];
            }
        }
        cholesky_solve(&mut s.gram, &mut s.rhs, cols)?;
        for (theta, scale) in s.rhs.iter_mut().zip(&s.scale) {
            *theta /= scale;
        }
        Some(self.residual_sum(psi, &s.rhs, &mut s.residual))
    }

    /// Column c of Φ over the rows t0…N−1, as a slice of y or ψ and the sign it carries
    /// (the lagged outputs enter as −y).
    #[inline]
    fn column<'s>(&'s self, c: usize, psi: &'s [f64]) -> (&'s [f64], f64) {
        let (n, t0) = (self.len(), self.t0);
        if c < self.na {
            (&self.y[t0 - c - 1..n - c - 1], -1.0)
        } else {
            let (j, i) = ((c - self.na) / self.nl, (c - self.na) % self.nl);
            let lag = self.delay + j;
            (&psi[i * n + t0 - lag..i * n + n - lag], 1.0)
        }
    }

    /// ΦᵀΦ and Φᵀy into the scratch as dot products of columns (contiguous slices), the
    /// lagged-output block from the cache.
    fn normal_equations(&self, psi: &[f64], gram: &mut [f64], rhs: &mut [f64]) {
        let (na, cols) = (self.na, self.cols());
        let target = &self.y[self.t0..self.len()];
        let mut partners: Vec<&[f64]> = Vec::with_capacity(cols + 1);
        let mut products = vec![0.0; cols + 1];
        for c in 0..cols {
            let (col, sign) = self.column(c, psi);
            // Column c against every later ψ column, and against y once c is a ψ column.
            partners.clear();
            partners.extend((c.max(na)..cols).map(|c2| self.column(c2, psi).0));
            if c >= na {
                partners.push(target);
            }
            dots(
                col,
                &partners,
                &mut products[..partners.len()],
                simd::available(),
            );
            for (c2, &product) in (c.max(na)..cols).zip(&products) {
                let g = sign * self.column(c2, psi).1 * product;
                gram[c * cols + c2] = g;
                gram[c2 * cols + c] = g;
            }
            rhs[c] = if c < na {
                self.lag_rhs[c]
            } else {
                products[partners.len() - 1]
            };
        }
        for a in 0..na {
            for b in 0..na {
                gram[a * cols + b] = self.lag_gram[a * na + b];
            }
        }
    }

    /// Σ (y(t) − φ(t)ᵀθ)² (see [`residual_squares`]); `r` is the portable path's buffer.
    fn residual_sum(&self, psi: &[f64], theta: &[f64], r: &mut Vec<f64>) -> f64 {
        let columns: Vec<(&[f64], f64)> = theta
            .iter()
            .enumerate()
            .map(|(c, &th)| {
                let (col, sign) = self.column(c, psi);
                (col, sign * th)
            })
            .collect();
        residual_squares(&self.y[self.t0..self.len()], &columns, r, simd::available())
    }
}

/// Σₜ (y(t) − Σ_c w_c·col_c(t))² over the rows of `target`, each residual formed in column
/// order and the squares summed as [`dot`] sums them. The portable path builds the residual
/// vector in `r` column by column, then takes its dot product with itself; with `simd` (AVX,
/// see [`simd::available`]) one pass forms four residuals at a time in registers and sums
/// their squares in the four partial sums of [`dot`] — the same operations in the same
/// order, so the same bits.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn residual_squares(
    target: &[f64],
    columns: &[(&[f64], f64)],
    r: &mut Vec<f64>,
    simd: bool,
) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if simd {
        // SAFETY: `simd` is only set when the processor has AVX.
        return unsafe { simd::residual_squares(target, columns) };
    }
    let _ = simd;
    r.clear();
    r.extend_from_slice(target);
    for &(col, w) in columns {
        for (ri, ci) in r.iter_mut().zip(col) {
            *ri -= w * ci;
        }
    }
    dot(r, r)
}

/// ψ of the module docs for the hysteresis `form` over the non-empty input `x`, signal i at
/// `psi[i·N + t]` (N = x.len(); `psi` holds 2 or 4 signals); `decay` (N values) is scratch.
pub(super) fn basis_signals(
    form: ChForm,
    x: &[f64],
    alpha: f64,
    d: f64,
    psi: &mut [f64],
    decay: &mut [f64],
) {
    basis_signals_batch(form, x, alpha, &[d], psi, decay);
}

/// [`basis_signals`] of the points (α, dᵦ) for each of the 1 to [`BATCH`] thresholds `ds`,
/// point b's signals one after the other from `psi[b·NL·N]` on.
///
/// Two passes: the inputs uᵢ(t) and the decay 1 − α|Δx(t)| of every sample first (no
/// dependence between samples, so the loop runs four samples at a time with AVX when the
/// processor has it), then the recursions, whose only work per sample is then one multiply
/// and one add per signal, all the points' in one loop. The operations are the formula's, in
/// its order: the same bits as one pass per point.
fn basis_signals_batch(
    form: ChForm,
    x: &[f64],
    alpha: f64,
    ds: &[f64],
    psi: &mut [f64],
    decay: &mut [f64],
) {
    match form {
        ChForm::Saturated4 => basis_signals_of::<2>(x, alpha, ds, psi, decay),
        ChForm::General6 => basis_signals_of::<4>(x, alpha, ds, psi, decay),
    }
}

/// [`basis_signals_batch`] for NL = 2 (ch4) or 4 (ch6) material coefficients. NL and the
/// number of points are constants so that the recursions' states stay in registers.
fn basis_signals_of<const NL: usize>(
    x: &[f64],
    alpha: f64,
    ds: &[f64],
    psi: &mut [f64],
    decay: &mut [f64],
) {
    let n = x.len();
    let decay = &mut decay[..n];
    let psi = &mut psi[..ds.len() * NL * n];
    // Every point writes the same decay (it depends on α alone).
    for (&d, point) in ds.iter().zip(psi.chunks_exact_mut(NL * n)) {
        #[cfg(target_arch = "x86_64")]
        if simd::available() {
            // SAFETY: the processor has AVX, the only requirement of `basis_inputs_avx`.
            unsafe { basis_inputs_avx::<NL>(x, alpha, d, point, decay) };
        } else {
            basis_inputs::<NL>(x, alpha, d, point, decay);
        }
        #[cfg(not(target_arch = "x86_64"))]
        basis_inputs::<NL>(x, alpha, d, point, decay);
    }
    match ds.len() {
        1 => recursions::<NL, 1>(psi, decay),
        2 => recursions::<NL, 2>(psi, decay),
        3 => recursions::<NL, 3>(psi, decay),
        _ => recursions::<NL, BATCH>(psi, decay),
    }
}

/// ψ(t) = decay(t)·ψ(t−1) + u(t) in place over the inputs u, for the NL signals of each of
/// B points (`psi` holds B·NL signals of N = `decay.len()` samples, one after the other).
fn recursions<const NL: usize, const B: usize>(psi: &mut [f64], decay: &[f64]) {
    let n = decay.len();
    let mut points = psi.chunks_exact_mut(NL * n);
    let mut columns: [[&mut [f64]; NL]; B] =
        std::array::from_fn(|_| signals::<NL>(points.next().expect("B points"), n));
    let mut past = [[0.0; NL]; B];
    for (t, &decay) in decay.iter().enumerate().skip(1) {
        for (point, state) in columns.iter_mut().zip(&mut past) {
            for (column, p) in point.iter_mut().zip(state.iter_mut()) {
                *p = decay * *p + column[t];
                column[t] = *p;
            }
        }
    }
}

/// The NL signals of `psi` (signal i at `psi[i·N + t]`, N = `n`), one slice each.
fn signals<const NL: usize>(psi: &mut [f64], n: usize) -> [&mut [f64]; NL] {
    let mut columns = psi.chunks_exact_mut(n);
    std::array::from_fn(|_| columns.next().expect("NL signals"))
}

/// [`basis_inputs`] compiled for AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn basis_inputs_avx<const NL: usize>(
    x: &[f64],
    alpha: f64,
    d: f64,
    psi: &mut [f64],
    decay: &mut [f64],
) {
    basis_inputs::<NL>(x, alpha, d, psi, decay);
}

/// uᵢ(t) into `psi` (signal i at `psi[i·N + t]`, uᵢ(0) = 0) and 1 − α|Δx(t)| into `decay`.
#[inline(always)]
fn basis_inputs<const NL: usize>(
    x: &[f64],
    alpha: f64,
    d: f64,
    psi: &mut [f64],
    decay: &mut [f64],
) {
    let n = x.len();
    let mut columns = signals::<NL>(psi, n);
    for column in &mut columns {
        column[0] = 0.0;
    }
    decay[0] = 1.0;
    for t in 1..n {
        let dx = x[t] - x[t - 1];
        let adx = dx.abs();
        let h = switching(x[t], d);
        let sgn = if x[t] > 0.0 {
            1.0
        } else if x[t] < 0.0 {
            -1.0
        } else {
            0.0
        };
        decay[t] = 1.0 - alpha * adx;
        columns[0][t] = alpha * adx * (x[t] * (1.0 - h) + d * sgn * h);
        if NL == 2 {
            columns[1][t] = (1.0 - h) * dx;
        } else {
            columns[1][t] = alpha * adx * (x[t] * h - d * sgn * h);
            columns[2][t] = (1.0 - h) * dx;
            columns[3][t] = h * dx;
        }
    }
}

/// Σ aᵢbᵢ with four partial sums (independent chains the compiler can vectorise).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    dot_group_portable::<1>(a, [b])[0]
}

/// `out[j]` = [`dot`]`(a, b[j])`, the dot products taken four at a time (the last two or
/// three together too): a is read once per group and the group's partial sums are
/// independent chains. Each product is summed exactly as [`dot`] sums it, also with `simd`
/// (AVX, see [`simd::available`]), where a product's four partial sums are the four lanes of
/// one register.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn dots(a: &[f64], b: &[&[f64]], out: &mut [f64], simd: bool) {
    let mut quads = b.chunks_exact(4);
    let mut results = out.chunks_exact_mut(4);
    for (group, result) in quads.by_ref().zip(results.by_ref()) {
        result.copy_from_slice(&dot_group::<4>(
            a,
            [group[0], group[1], group[2], group[3]],
            simd,
        ));
    }
    match (quads.remainder(), results.into_remainder()) {
        ([b0, b1, b2], result) => result.copy_from_slice(&dot_group::<3>(a, [b0, b1, b2], simd)),
        ([b0, b1], result) => result.copy_from_slice(&dot_group::<2>(a, [b0, b1], simd)),
        ([b0], [result]) => *result = dot_group::<1>(a, [b0], simd)[0],
        _ => {}
    }
}

/// [`dot`] of `a` with each of K vectors, in one pass over a (with AVX when `simd`).
fn dot_group<const K: usize>(a: &[f64], b: [&[f64]; K], simd: bool) -> [f64; K] {
    #[cfg(target_arch = "x86_64")]
    if simd {
        // SAFETY: `simd` is only set when the processor has AVX.
        return unsafe { simd::dot_group(a, b) };
    }
    let _ = simd;
    dot_group_portable(a, b)
}

/// [`dot`] of `a` with each of K vectors, in one pass over a: the portable code, the
/// definition of the summation order.
#[inline(always)]
fn dot_group_portable<const K: usize>(a: &[f64], b: [&[f64]; K]) -> [f64; K] {
    let n = b.iter().fold(a.len(), |n, b| n.min(b.len()));
    let body = n / 4 * 4;
    let mut acc = [[0.0; 4]; K];
    for i in (0..body).step_by(4) {
        let x: &[f64; 4] = a[i..i + 4].try_into().expect("four values");
        for (acc, b) in acc.iter_mut().zip(&b) {
            let y: &[f64; 4] = b[i..i + 4].try_into().expect("four values");
            for ((acc, x), y) in acc.iter_mut().zip(x).zip(y) {
                *acc += x * y;
            }
        }
    }
    std::array::from_fn(|k| {
        let tail: f64 = a[body..n]
            .iter()
            .zip(&b[k][body..n])
            .map(|(x, y)| x * y)
            .sum();
        (acc[k][0] + acc[k][1]) + (acc[k][2] + acc[k][3]) + tail
    })
}

/// Solves A z = b in place (b becomes z) for a symmetric positive definite `n × n` row-major
/// A, overwritten by its Cholesky factor; None when A is not positive definite.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn cholesky_solve(a: &mut [f64], b: &mut [f64], n: usize) -> Option<()> {
    for j in 0..n {
        let mut diag = a[j * n + j];
        for k in 0..j {
            diag -= a[j * n + k] * a[j * n + k];
        }
        if !(diag > 0.0 && diag.is_finite()) {
            return None;
        }
        let ljj = diag.sqrt();
        a[j * n + j] = ljj;
        for i in j + 1..n {
            let mut v = a[i * n + j];
            for k in 0..j {
                v -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = v / ljj;
        }
    }
    for i in 0..n {
        let mut v = b[i];
        for k in 0..i {
            v -= a[i * n + k] * b[k];
        }
        b[i] = v / a[i * n + i];
    }
    for i in (0..n).rev() {
        let mut v = b[i];
        for k in i + 1..n {
            v -= a[k * n + i] * b[k];
        }
        b[i] = v / a[i * n + i];
    }
    Some(())
}
