//! Axis ranges and tick labels: the data extent, padding, and a common power of ten with a
//! fixed decimal count per axis.

use plotters::coord::ranged1d::{KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;

use super::figure::Series;

/// Data extent over all finite points of a figure.
pub(super) struct Bounds {
    x: (f64, f64),
    y: (f64, f64),
}

/// Axis limits are clamped here: plotters' tick search loops forever on an
/// infinite span, which two finite values near ±f64::MAX would produce.
pub(super) const AXIS_LIMIT: f64 = 1e300;

impl Bounds {
    pub(super) fn of(series: &[Series]) -> Bounds {
        let mut b = Bounds {
            x: (f64::INFINITY, f64::NEG_INFINITY),
            y: (f64::INFINITY, f64::NEG_INFINITY),
        };
        for s in series {
            for (&x, &y) in s.x.iter().zip(s.y.iter()) {
                if x.is_finite() && y.is_finite() {
                    b.x = (b.x.0.min(x), b.x.1.max(x));
                    b.y = (b.y.0.min(y), b.y.1.max(y));
                }
            }
        }
        b
    }

    pub(super) fn is_empty(&self) -> bool {
        self.x.0 > self.x.1
    }

    /// Axis ranges: y padded by 5 %; x tight when every series runs
    /// monotonically along x (time, index, iteration), padded otherwise
    /// (loops), so curves do not touch the frame.
    pub(super) fn axis_ranges(&self, x_monotone: bool) -> ((f64, f64), (f64, f64)) {
        if self.is_empty() {
            return ((0.0, 1.0), (0.0, 1.0));
        }
        let x_pad = if x_monotone { 0.0 } else { 0.04 };
        (pad_range(self.x, x_pad), pad_range(self.y, 0.05))
    }
}

/// Widens `(lo, hi)` by `frac` of its span on each side; a (numerically)
/// constant range is widened to ±10 % of its value, or ±1 around zero, so
/// the flat line sits mid-plot and tick labels stay meaningful.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn pad_range((lo, hi): (f64, f64), frac: f64) -> (f64, f64) {
    let lo = lo.clamp(-AXIS_LIMIT, AXIS_LIMIT);
    let hi = hi.clamp(-AXIS_LIMIT, AXIS_LIMIT);
    let span = hi - lo;
    let mag = lo.abs().max(hi.abs());
    if span <= mag * 1e-9 || span == 0.0 {
        let c = 0.5 * (lo + hi);
        let d = if c == 0.0 { 1.0 } else { c.abs() * 0.1 };
        return (c - d, c + d);
    }
    (lo - span * frac, hi + span * frac)
}

pub(super) fn x_is_monotone(series: &[Series]) -> bool {
    series.iter().all(|s| {
        let (mut up, mut down) = (true, true);
        let mut prev: Option<f64> = None;
        for &x in s.x.iter().filter(|v| v.is_finite()) {
            if let Some(p) = prev {
                up &= p <= x;
                down &= p >= x;
            }
            prev = Some(x);
        }
        up || down
    })
}

/// How tick values on one axis are printed: a common power of ten (shown
/// in the axis label, as engineering notation) and a fixed decimal count so
/// all labels line up ("0.0 0.5 1.0", not "0 0.5 1").
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub struct AxisFormat {
    pub(super) exp: i32,
    decimals: usize,
    ticks: Vec<f64>,
}

impl AxisFormat {
    /// The power of ten factored out of the tick labels.
    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn exp(&self) -> i32 {
        self.exp
    }
}

impl AxisFormat {
    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn new((lo, hi): (f64, f64), n_ticks: usize) -> AxisFormat {
        let ticks = RangedCoordf64::from(lo..hi).key_points(n_ticks.max_num_points());
        let exp = engineering_exponent(lo.abs().max(hi.abs()));
        let scale = 10f64.powi(-exp);
        let scaled: Vec<f64> = ticks.iter().map(|t| t * scale).collect();
        AxisFormat {
            exp,
            decimals: decimals_for(&scaled),
            ticks,
        }
    }

    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn format(&self, v: f64) -> String {
        let s = v * 10f64.powi(-self.exp);
        let text = format!("{:.*}", self.decimals, s);
        // Rounding can yield "-0.0", which looks like a bug to a reader.
        if text.starts_with('-') && text[1..].chars().all(|c| c == '0' || c == '.') {
            text[1..].to_string()
        } else {
            text
        }
    }

    pub(super) fn tick_labels(&self) -> Vec<String> {
        self.ticks.iter().map(|&t| self.format(t)).collect()
    }

    #[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
    pub fn describe(&self, label: &str) -> String {
        if self.exp == 0 {
            label.to_string()
        } else {
            format!("{label}  (×1e{})", self.exp)
        }
    }
}

/// Multiple of three to factor out of tick labels, or 0 when plain numbers
/// read fine (sample indices up to millions, values down to 0.001).
fn engineering_exponent(mag: f64) -> i32 {
    if mag == 0.0 || (1e-3..1e7).contains(&mag) {
        return 0;
    }
    (mag.log10().floor() / 3.0).floor() as i32 * 3
}

/// Fewest decimals (≤ 12) that print every tick exactly enough to tell it
/// apart from its neighbours.
fn decimals_for(ticks: &[f64]) -> usize {
    let step = ticks
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(f64::INFINITY, f64::min);
    if !step.is_finite() || step == 0.0 {
        return 2;
    }
    let tol = step * 1e-3;
    (0..=12)
        .find(|&d| {
            let p = 10f64.powi(d as i32);
            ticks.iter().all(|t| ((t * p).round() / p - t).abs() <= tol)
        })
        .unwrap_or(12)
}
