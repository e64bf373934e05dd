//! Series preparation: finite runs, and decimation of long series that keeps their
//! extremes.

use plotters::style::RGBColor;

use super::axis::AXIS_LIMIT;
use super::figure::{Series, Style};

/// Series longer than this (counting finite points) are decimated for drawing.
pub const DECIMATE_ABOVE: usize = 5_000;

/// A series ready to draw: finite, decimated, split where data was missing.
pub(super) struct Prepared<'s> {
    pub(super) label: &'s str,
    pub(super) style: Style,
    pub(super) color: RGBColor,
    pub(super) runs: Vec<Vec<(f64, f64)>>,
}

/// Beyond this many gaps we stop breaking the line: thousands of tiny
/// fragments would bloat the SVG without telling the reader anything more.
const MAX_RUNS: usize = 1_000;

pub(super) fn prepare<'s>(s: &'s Series, color: RGBColor) -> Prepared<'s> {
    let mut runs = finite_runs(&s.x, &s.y);
    if s.style == Style::Points || runs.len() > MAX_RUNS {
        runs = vec![runs.concat()];
    }
    let total: usize = runs.iter().map(Vec::len).sum();
    let bucket = bucket_len(total, s.style);
    let runs = runs
        .iter()
        .map(|r| decimate(r, bucket))
        .filter(|r| !r.is_empty())
        .collect();
    Prepared {
        label: s.label,
        style: s.style,
        color,
        runs,
    }
}

/// Maximal runs of consecutive points whose coordinates are both finite.
/// Values are clamped to the axis limit: plotters maps a point far outside
/// the axis range to a pixel with unchecked `i32` arithmetic and overflows.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn finite_runs(x: &[f64], y: &[f64]) -> Vec<Vec<(f64, f64)>> {
    let clamp = |v: f64| v.clamp(-AXIS_LIMIT, AXIS_LIMIT);
    let mut runs = Vec::new();
    let mut current = Vec::new();
    for (&xi, &yi) in x.iter().zip(y) {
        if xi.is_finite() && yi.is_finite() {
            current.push((clamp(xi), clamp(yi)));
        } else if !current.is_empty() {
            runs.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        runs.push(current);
    }
    runs
}

/// Points per decimation bucket (1 = no decimation). Markers cost more SVG
/// than polyline vertices, so they get fewer buckets.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn bucket_len(total: usize, style: Style) -> usize {
    if total <= DECIMATE_ABOVE {
        return 1;
    }
    let buckets = if style == Style::Points { 750 } else { 2_000 };
    total.div_ceil(buckets)
}

/// Keeps, per bucket of `bucket` consecutive points, those holding the
/// minimum and maximum of x and of y, in their original order. Keeping both
/// coordinates' extremes preserves the envelope of time plots *and* the
/// corners of hysteresis loops. The run's first and last points are kept so
/// the line spans the full range.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn decimate(run: &[(f64, f64)], bucket: usize) -> Vec<(f64, f64)> {
    if bucket <= 1 || run.len() <= 4 {
        return run.to_vec();
    }
    let mut out = Vec::with_capacity(run.len() / bucket * 4 + 4);
    let last_chunk = (run.len() - 1) / bucket;
    for (c, chunk) in run.chunks(bucket).enumerate() {
        let mut keep = extreme_indices(chunk);
        if c == 0 {
            keep.push(0);
        }
        if c == last_chunk {
            keep.push(chunk.len() - 1);
        }
        keep.sort_unstable();
        keep.dedup();
        out.extend(keep.iter().map(|&i| chunk[i]));
    }
    out
}

/// Indices of min x, max x, min y, max y within a non-empty chunk.
fn extreme_indices(chunk: &[(f64, f64)]) -> Vec<usize> {
    let mut idx = [0usize; 4];
    for (i, &(x, y)) in chunk.iter().enumerate() {
        if x < chunk[idx[0]].0 {
            idx[0] = i;
        }
        if x > chunk[idx[1]].0 {
            idx[1] = i;
        }
        if y < chunk[idx[2]].1 {
            idx[2] = i;
        }
        if y > chunk[idx[3]].1 {
            idx[3] = i;
        }
    }
    idx.to_vec()
}
