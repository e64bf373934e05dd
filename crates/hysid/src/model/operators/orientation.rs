//! The turning sense of a measured hysteresis loop, read from the area between its ascending
//! and descending branches (not from the path integral of the whole record).
//!
//! **Why not ∮ y du.** Green's theorem gives the enclosed area of a *closed* path as
//! −∮ y du (counter-clockwise positive). A measured record is rarely closed: it ends at
//! another input than it started (a record cut anywhere), or it consists of several runs. The
//! path integral of an open record is the loops' area plus ∫_{u_start}^{u_end} y_s(u) du of the
//! static (centre) curve y_s, which for a narrow loop on a wide range dwarfs the loops' own
//! area and may give either sign (MODELS.md §4.8; Mayergoyz, *Mathematical Models of
//! Hysteresis and their Applications*, 2003, §1.1 for the loop's orientation).
//!
//! **Method: branch against branch, per reversal.** The input is cut into monotone segments
//! at its reversals, found with a hysteresis threshold h = [`REVERSAL_FRACTION`] × (max u −
//! min u) so that noise does not make reversals (a reversal is accepted once u has come back
//! by more than h from its running extreme). Each segment is a branch y_j(u): its samples
//! sorted by u and joined by straight lines (sorting, not a running extreme, keeps noise on u
//! from shifting a branch). Two consecutive segments, one ascending (a) and one descending (d),
//! share their reversal point, and over their common input interval [l, r] the signed area
//!
//! ```text
//!   A_j = ∫_l^r ( y_d(u) − y_a(u) ) du
//! ```
//!
//! is the area between the branches: positive when the descending branch lies above the
//! ascending one, a counter-clockwise loop (the output lags the input, as a piezo stack or a
//! magnet's B(H)); negative for a clockwise one. The static curve cancels exactly (both
//! branches are taken at the same u), so offsets, the trend (increasing or decreasing) and the
//! width of the range do not enter, and neither does where the record starts or ends.
//!
//! **Robust sum.** The junction of two runs (a jump of the input, perhaps an offset of the
//! output) makes one pair of segments that is no loop. With L_j = r − l and the mean gap
//! g_j = A_j / L_j, the gaps are clipped to ±[`CLIP`]·|g̃|, g̃ the L-weighted median gap, and
//! the statistic is A = Σ_j L_j·clip(g_j). A is a linear combination Σ c_k y_k of the samples,
//! so with σ the output noise its standard deviation is σ·‖c‖; σ is estimated robustly from
//! the residuals of each sample against the straight line through its two neighbours (where
//! the input is monotone there): σ̂ = 1.4826·median |e_k| / √(1 + λ_k² + (1 − λ_k)²). The
//! confidence is z = A / (σ̂‖c‖).
//!
//! **Static curve removed first.** The branches are straight lines between their samples,
//! and a quasi-static record (a magnet's set points) has few samples on a curved static
//! curve: the chords of a saturating curve between set points a few percent of the range
//! apart differ by more than a narrow loop's width, with a sign that depends on how the set
//! points fall, and the neighbours' residuals that measure the noise are its curvature. So
//! the method runs on r = y − ŷ_s(u), ŷ_s the least-squares cubic regression spline in u with
//! up to [`STATIC_KNOTS`] interior knots at the quantiles of u (one per 20 samples; the
//! truncated-power basis 1, t, t², t³, (t − κ)³₊ in t = (u − min u)/(max u − min u), de Boor,
//! *A Practical Guide to Splines*, 2001, ch. VIII). A function of u alone cannot take up
//! the loop (it has one value at each u, the loop two), and it cancels from the exact area
//! between the branches; what it removes is the chords' curvature. The knots are the
//! quantiles of the distinct inputs (fewer knots when the set points repeat few values,
//! at most the distinct values less five); with fewer samples than twice the spline's
//! coefficients, or a rank-deficient regression, y is used as it is.
//!
//! The loop is counter-clockwise when A > 0, clockwise when A < 0, provided g̃ has the same
//! sign and |z| ≥ [`MIN_CONFIDENCE`]; otherwise (no reversal, a loop indistinguishable from
//! noise, pairs that disagree) the orientation cannot be told and
//! [`Error::UndeterminedOrientation`] says so and names the setting that gives it.

use super::differential::LoopOrientation;
use crate::{Error, Result};

/// The reversal threshold as a fraction of the input's range (1 %): the input must come back
/// by more than this from its running extreme for a reversal to count.
pub const REVERSAL_FRACTION: f64 = 0.01;

/// The smallest confidence |z| (the robust area in units of its noise standard deviation)
/// at which an orientation is reported.
pub const MIN_CONFIDENCE: f64 = 3.0;

/// The floor of the noise level σ̂ as a fraction of the output's range (1e-5).
pub const SIGMA_FLOOR: f64 = 1e-5;

/// The clip of each pair's mean gap, in units of the weighted median gap.
pub const CLIP: f64 = 3.0;

/// The most interior knots of the static curve's regression spline (module doc), one per
/// [`SAMPLES_PER_KNOT`] samples.
pub const STATIC_KNOTS: usize = 6;

/// The samples per interior knot of the static curve's spline.
pub const SAMPLES_PER_KNOT: usize = 20;

/// y − ŷ_s(u), ŷ_s the least-squares cubic regression spline of y on u (module doc, "Static
/// curve removed first") over the input range [lo, hi]; None when the record has fewer than
/// twice the spline's coefficients or its regression is rank deficient.
fn without_static_curve(u: &[f64], y: &[f64], lo: f64, hi: f64) -> Option<Vec<f64>> {
    let n = u.len();
    let t: Vec<f64> = u.iter().map(|v| (v - lo) / (hi - lo)).collect();
    let mut sorted = t.clone();
    sorted.sort_by(f64::total_cmp);
    sorted.dedup();
    let distinct = sorted.len();
    let wanted = (n / SAMPLES_PER_KNOT)
        .min(STATIC_KNOTS)
        .min(distinct.saturating_sub(5));
    let mut knots: Vec<f64> = Vec::with_capacity(wanted);
    for j in 1..=wanted {
        let q = sorted[j * (distinct - 1) / (wanted + 1)];
        if q > 0.0 && q < 1.0 && knots.last().is_none_or(|&k| q > k) {
            knots.push(q);
        }
    }
    let p = 4 + knots.len();
    if n < 2 * p {
        return None;
    }
    let basis = |x: f64, j: usize| match j {
        0 => 1.0,
        1 => x,
        2 => x * x,
        3 => x * x * x,
        _ => (x - knots[j - 4]).max(0.0).powi(3),
    };
    let phi = nalgebra::DMatrix::from_fn(n, p, |i, j| basis(t[i], j));
    let names = vec!["the static curve's spline"; p];
    let (theta, _) =
        crate::numerics::least_squares::least_squares_estimate(&phi, y, &names).ok()?;
    Some(
        t.iter()
            .zip(y)
            .map(|(&x, &yk)| yk - (0..p).map(|j| theta[j] * basis(x, j)).sum::<f64>())
            .collect(),
    )
}

/// What the detector found ([`loop_evidence`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LoopEvidence {
    /// The turning sense.
    pub orientation: LoopOrientation,
    /// The robust area A = Σ L_j·clip(g_j) between descending and ascending branches
    /// (positive counter-clockwise), in units of u·y.
    pub area: f64,
    /// The confidence z = A / (σ̂‖c‖) (∞ for noise-free data with a loop).
    pub confidence: f64,
    /// The number of pairs of consecutive branches with a common input interval.
    pub pairs: usize,
    /// The number of input reversals found.
    pub reversals: usize,
}

fn undetermined(reason: impl Into<String>) -> Error {
    Error::UndeterminedOrientation {
        reason: reason.into(),
    }
}

/// The reversals of `u` by more than [`REVERSAL_FRACTION`] of its range: the turning points
/// the orientation is read between (a reversal within that fraction is noise or a set
/// point's overshoot, not a branch).
pub fn reversals(u: &[f64]) -> usize {
    turning_points(u).map_or(0, |(_, turns, _)| turns.len().saturating_sub(2))
}

/// The range (lo, hi) of the finite samples of `u` and its [`segments`] at the threshold
/// [`REVERSAL_FRACTION`] × (hi − lo); None when the input does not move.
fn turning_points(u: &[f64]) -> Option<((f64, f64), Vec<usize>, i8)> {
    let (lo, hi) = u
        .iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if hi <= lo {
        return None;
    }
    let (turns, first) = segments(u, REVERSAL_FRACTION * (hi - lo))?;
    Some(((lo, hi), turns, first))
}

/// The turning points of `u` (indices of the extremes at which the input reversed by more
/// than `h`), with the first and last sample; and the direction (+1 up, −1 down) of the first
/// segment. None when the input never moves by more than `h`.
fn segments(u: &[f64], h: f64) -> Option<(Vec<usize>, i8)> {
    let n = u.len();
    let (mut imin, mut imax) = (0, 0);
    let mut k = 1;
    let (mut dir, mut ext, start);
    loop {
        if k >= n {
            return None;
        }
        if u[k] > u[imax] {
            imax = k;
        }
        if u[k] < u[imin] {
            imin = k;
        }
        if u[imax] - u[imin] > h {
            // the first segment starts at the earlier extreme
            if imin < imax {
                (dir, ext, start) = (1i8, imax, imin);
            } else {
                (dir, ext, start) = (-1i8, imin, imax);
            }
            break;
        }
        k += 1;
    }
    let first = dir;
    let mut turns = vec![start];
    for (k, &uk) in u.iter().enumerate().skip(ext + 1) {
        if dir > 0 {
            if uk > u[ext] {
                ext = k;
            } else if u[ext] - uk > h {
                turns.push(ext);
                dir = -1;
                ext = k;
            }
        } else if uk < u[ext] {
            ext = k;
        } else if uk - u[ext] > h {
            turns.push(ext);
            dir = 1;
            ext = k;
        }
    }
    if *turns.last().unwrap_or(&0) != n - 1 {
        turns.push(n - 1);
    }
    Some((turns, first))
}

/// One branch: its samples (u, y, index) sorted by u.
struct Branch {
    points: Vec<(f64, f64, usize)>,
}

impl Branch {
    fn new(u: &[f64], y: &[f64], from: usize, to: usize) -> Self {
        let mut points: Vec<(f64, f64, usize)> = (from..=to).map(|k| (u[k], y[k], k)).collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        Self { points }
    }

    fn range(&self) -> (f64, f64) {
        (self.points[0].0, self.points[self.points.len() - 1].0)
    }

    /// ∫_lo^hi of the piecewise-linear branch, adding `sign` × each sample's weight in the
    /// integral to `c`.
    fn integral(&self, lo: f64, hi: f64, sign: f64, c: &mut [f64]) -> f64 {
        let mut total = 0.0;
        for w in self.points.windows(2) {
            let ((x0, y0, k0), (x1, y1, k1)) = (w[0], w[1]);
            let (a, b) = (lo.max(x0), hi.min(x1));
            if b <= a || x1 <= x0 {
                continue;
            }
            let (ta, tb) = ((a - x0) / (x1 - x0), (b - x0) / (x1 - x0));
            let w1 = (b - a) * 0.5 * (ta + tb);
            let w0 = (b - a) - w1;
            total += w0 * y0 + w1 * y1;
            c[k0] += sign * w0;
            c[k1] += sign * w1;
        }
        total
    }
}

/// The robust noise level of `y` (module doc): the median residual of each sample against
/// the line through its neighbours, where the input is strictly monotone over the three.
/// None when fewer than three such samples exist.
fn noise_level(u: &[f64], y: &[f64]) -> Option<f64> {
    let mut e: Vec<f64> = (1..u.len() - 1)
        .filter_map(|k| {
            let (a, b, c) = (u[k - 1], u[k], u[k + 1]);
            let monotone = (a < b && b < c) || (a > b && b > c);
            monotone.then(|| {
                let l = (b - a) / (c - a);
                let r = y[k] - ((1.0 - l) * y[k - 1] + l * y[k + 1]);
                r.abs() / (1.0 + l * l + (1.0 - l) * (1.0 - l)).sqrt()
            })
        })
        .collect();
    if e.len() < 3 {
        return None;
    }
    let mid = e.len() / 2;
    let (_, m, _) = e.select_nth_unstable_by(mid, f64::total_cmp);
    Some(1.4826 * *m)
}

/// The L-weighted median of `g`.
fn weighted_median(g: &[(f64, f64)]) -> f64 {
    let mut v = g.to_vec();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let half = 0.5 * v.iter().map(|p| p.1).sum::<f64>();
    let mut acc = 0.0;
    for (gj, lj) in &v {
        acc += lj;
        if acc >= half {
            return *gj;
        }
    }
    v.last().map_or(0.0, |p| p.0)
}

/// Detects the turning sense of the loop (u, y) from the area between consecutive ascending
/// and descending branches (module doc), with its evidence; an
/// [`Error::UndeterminedOrientation`] when it cannot be told.
pub fn loop_evidence(u: &[f64], y: &[f64]) -> Result<LoopEvidence> {
    let n = u.len().min(y.len());
    let (u, y) = (&u[..n], &y[..n]);
    if n < 4 {
        return Err(undetermined(format!(
            "{n} samples hold no loop; a loop needs an input that rises and falls"
        )));
    }
    if let Some(k) = u.iter().chain(y).position(|v| !v.is_finite()) {
        return Err(undetermined(format!("sample {} is not finite", k % n)));
    }
    let Some(((lo, hi), turns, first)) = turning_points(u) else {
        return Err(undetermined("the input does not move"));
    };
    let reversals = turns.len().saturating_sub(2);
    if reversals == 0 {
        return Err(undetermined(
            "the input has no reversal (a curve, not a loop)",
        ));
    }
    // the noise floor's scale: the output's own range
    let (ylo, yhi) = y
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let detrended = without_static_curve(u, y, lo, hi);
    let y = detrended.as_deref().unwrap_or(y);
    let branches: Vec<Branch> = turns
        .windows(2)
        .map(|t| Branch::new(u, y, t[0], t[1]))
        .collect();
    let mut c = vec![0.0; n];
    let mut gaps = Vec::new();
    for (j, pair) in branches.windows(2).enumerate() {
        // segment j rises when j has the first segment's parity and that one rose
        let rising_first = (j % 2 == 0) == (first > 0);
        let (rise, fall) = if rising_first {
            (&pair[0], &pair[1])
        } else {
            (&pair[1], &pair[0])
        };
        let ((a0, a1), (b0, b1)) = (rise.range(), fall.range());
        let (l, r) = (a0.max(b0), a1.min(b1));
        if r <= l {
            continue;
        }
        let area = fall.integral(l, r, 1.0, &mut c) - rise.integral(l, r, -1.0, &mut c);
        gaps.push((area / (r - l), r - l));
    }
    if gaps.is_empty() {
        return Err(undetermined("no two branches share an input interval"));
    }
    let median = weighted_median(&gaps);
    if median == 0.0 {
        return Err(undetermined("the branches coincide (no loop)"));
    }
    let bound = CLIP * median.abs();
    let area: f64 = gaps.iter().map(|(g, l)| l * g.clamp(-bound, bound)).sum();
    let spread = c.iter().map(|v| v * v).sum::<f64>().sqrt();
    let sigma = noise_level(u, y).unwrap_or_else(|| {
        // no monotone triple: the output's own spread, which no loop of these few samples
        // passes
        let m = y.iter().sum::<f64>() / n as f64;
        (y.iter().map(|v| (v - m).powi(2)).sum::<f64>() / n as f64).sqrt()
    });
    // a floor of 1e-5 of the output's range: a loop thinner than that (a record that does
    // not excite the hysteresis, rounding) is no loop to tell a direction from
    let sigma = sigma.max(SIGMA_FLOOR * (yhi - ylo));
    let confidence = if sigma * spread > 0.0 {
        area / (sigma * spread)
    } else if area != 0.0 {
        area.signum() * f64::INFINITY
    } else {
        0.0
    };
    let pairs = gaps.len();
    if area.signum() != median.signum() {
        return Err(undetermined(format!(
            "the {pairs} pairs of branches disagree on the loop's direction"
        )));
    }
    if confidence.abs() < MIN_CONFIDENCE {
        return Err(undetermined(format!(
            "the area between the branches is {:.2} times its noise level over {reversals} \
             reversal(s), below {MIN_CONFIDENCE}",
            confidence.abs()
        )));
    }
    Ok(LoopEvidence {
        orientation: if area > 0.0 {
            LoopOrientation::CounterClockwise
        } else {
            LoopOrientation::Clockwise
        },
        area,
        confidence,
        pairs,
        reversals,
    })
}

impl super::OperatorModel {
    /// The turning sense in the (u, y) plane of this operator's loop: from the stored
    /// [`super::Orientation`] for the linear-in-weights families
    /// ([`super::Orientation::loop_orientation`], reversed for the clockwise Maxwell-slip
    /// stops), the stored [`LoopOrientation`] of Jiles–Atherton and Dahl, the sign of k_w for
    /// Bouc–Wen (w's own loop is clockwise: k_w ≥ 0 clockwise) and of c − a for Duhem
    /// (counter-clockwise when c < a).
    pub fn loop_orientation(&self) -> LoopOrientation {
        use super::OperatorModel as M;
        match self {
            M::Pi(m) => m.orientation().loop_orientation(),
            M::Gpi(m) => m.orientation().loop_orientation(),
            M::Preisach(m) => m.orientation().loop_orientation(),
            M::Kp(m) => m.orientation().loop_orientation(),
            M::Backlash(m) => m.orientation().loop_orientation(),
            M::MaxwellSlip(m) => m.orientation().loop_orientation().reversed(),
            M::JilesAtherton(m) => m.orientation,
            M::Dahl(m) => m.orientation,
            M::BoucWen(m) => {
                if m.kw >= 0.0 {
                    LoopOrientation::Clockwise
                } else {
                    LoopOrientation::CounterClockwise
                }
            }
            M::Duhem(m) => {
                if m.c > m.a {
                    LoopOrientation::Clockwise
                } else {
                    LoopOrientation::CounterClockwise
                }
            }
        }
    }
}
