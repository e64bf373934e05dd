//! SVG plots for identification results: time responses, hysteresis loops,
//! parameter-convergence grids and input signals.
//!
//! Everything is rendered into an in-memory SVG document first and then
//! written atomically (`<path>.tmp` followed by a rename), so a reader never
//! sees a half-written file. Text is emitted as SVG `<text>` elements with a
//! generic `sans-serif` family, which means no font files are needed to
//! produce a plot; the viewer picks whatever sans-serif font it has.
//!
//! Odd data never panics: non-finite values are skipped (lines are broken at
//! them), empty figures get a "no data" note, constant series get a padded
//! axis, and very long series are decimated for drawing while keeping their
//! extremes.
#![warn(missing_docs)]

use std::borrow::Cow;
use std::fs;
use std::path::Path;

use anyhow::Context;
use plotters::chart::SeriesAnno;
use plotters::coord::ranged1d::{KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::{DashedPathElement, MultiLineText};
use plotters::prelude::*;

/// Default canvas size of a single-panel plot, in pixels.
pub const DEFAULT_SIZE: (u32, u32) = (900, 600);

/// Default size of one cell in [`plot_panels`], in pixels.
pub const DEFAULT_CELL_SIZE: (u32, u32) = (480, 330);

/// Series longer than this (counting finite points) are decimated for drawing.
pub const DECIMATE_ABOVE: usize = 5_000;

/// How a series is drawn. The colour comes from a fixed palette, chosen by
/// the series' position in its [`Figure`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Solid line through the points.
    Line,
    /// Dashed line through the points (e.g. reference values, model output).
    DashedLine,
    /// Unconnected markers (e.g. raw measurements).
    Points,
}

/// One labelled data series. `x` and `y` are paired element by element; if
/// their lengths differ, the extra elements of the longer one are ignored.
///
/// The data is a [`Cow`] so that borrowed slices (the normal case) and small
/// owned helpers such as [`hline`] fit in the same figure.
#[derive(Debug, Clone)]
pub struct Series<'a> {
    /// Legend text; an empty label keeps the series out of the legend.
    pub label: &'a str,
    /// Abscissa values.
    pub x: Cow<'a, [f64]>,
    /// Ordinate values.
    pub y: Cow<'a, [f64]>,
    /// Line or marker style.
    pub style: Style,
}

impl<'a> Series<'a> {
    /// Series from any borrowed slice or owned vector of `x` and `y`.
    pub fn new(
        label: &'a str,
        x: impl Into<Cow<'a, [f64]>>,
        y: impl Into<Cow<'a, [f64]>>,
        style: Style,
    ) -> Self {
        Series {
            label,
            x: x.into(),
            y: y.into(),
            style,
        }
    }

    /// Solid line through `(x[i], y[i])`.
    pub fn line(label: &'a str, x: &'a [f64], y: &'a [f64]) -> Self {
        Self::new(label, x, y, Style::Line)
    }

    /// Dashed line through `(x[i], y[i])`.
    pub fn dashed(label: &'a str, x: &'a [f64], y: &'a [f64]) -> Self {
        Self::new(label, x, y, Style::DashedLine)
    }

    /// Markers at `(x[i], y[i])`.
    pub fn points(label: &'a str, x: &'a [f64], y: &'a [f64]) -> Self {
        Self::new(label, x, y, Style::Points)
    }

    /// `y` against its sample index `0, 1, 2, …` (e.g. an input signal).
    pub fn indexed(label: &'a str, y: &'a [f64], style: Style) -> Self {
        let x: Vec<f64> = (0..y.len()).map(|i| i as f64).collect();
        Self::new(label, x, y, style)
    }
}

/// Dashed horizontal reference line at `y` spanning `x_range`, e.g. the true
/// value of a parameter in a convergence plot.
pub fn hline(label: &str, x_range: (f64, f64), y: f64) -> Series<'_> {
    Series::new(
        label,
        vec![x_range.0, x_range.1],
        vec![y, y],
        Style::DashedLine,
    )
}

/// One chart: title, axis labels (put units in them, e.g. `"time [s]"`) and
/// any number of series sharing the axes.
#[derive(Debug, Clone)]
pub struct Figure<'a> {
    /// Chart title (may be empty).
    pub title: &'a str,
    /// Horizontal axis label, with unit.
    pub x_label: &'a str,
    /// Vertical axis label, with unit.
    pub y_label: &'a str,
    /// Series drawn in order; later series are drawn on top.
    pub series: Vec<Series<'a>>,
    /// Canvas size in pixels used by [`plot`]; ignored inside [`plot_panels`].
    pub size: (u32, u32),
}

impl<'a> Figure<'a> {
    /// Empty figure of [`DEFAULT_SIZE`].
    pub fn new(title: &'a str, x_label: &'a str, y_label: &'a str) -> Self {
        Figure {
            title,
            x_label,
            y_label,
            series: Vec::new(),
            size: DEFAULT_SIZE,
        }
    }

    /// Adds a series (builder style).
    pub fn with(mut self, series: Series<'a>) -> Self {
        self.series.push(series);
        self
    }
}

/// Renders `fig` as a single-panel SVG at `path` (written atomically).
///
/// The canvas is `fig.size`, clamped to at least 200×150 px.
pub fn plot(path: &Path, fig: &Figure) -> anyhow::Result<()> {
    let size = clamp_size(fig.size);
    let svg = render(size, |root| draw_figure(root, fig, &Theme::SINGLE))?;
    write_atomic(path, &svg)
}

/// Renders `panels` as a grid with `columns` columns (rows as needed) under a
/// common `title`, each cell [`DEFAULT_CELL_SIZE`]. Panels share nothing:
/// each has its own axes, ranges and legend.
pub fn plot_panels(
    path: &Path,
    title: &str,
    panels: &[Figure],
    columns: usize,
) -> anyhow::Result<()> {
    let (cols, rows) = grid_shape(panels.len(), columns);
    let (cw, ch) = DEFAULT_CELL_SIZE;
    let title_h = if title.is_empty() {
        0
    } else {
        GRID_TITLE_HEIGHT
    };
    let (cols, rows) = (u32::try_from(cols), u32::try_from(rows));
    let (cols, rows) = (cols.unwrap_or(u32::MAX), rows.unwrap_or(u32::MAX));
    let size = (
        cw.saturating_mul(cols),
        ch.saturating_mul(rows).saturating_add(title_h),
    );
    plot_panels_sized(path, title, panels, columns, size)
}

/// Like [`plot_panels`] but with an explicit overall canvas `size`.
pub fn plot_panels_sized(
    path: &Path,
    title: &str,
    panels: &[Figure],
    columns: usize,
    size: (u32, u32),
) -> anyhow::Result<()> {
    let size = clamp_size(size);
    let svg = render(size, |root| draw_grid(root, title, panels, columns))?;
    write_atomic(path, &svg)
}

/// One panel per parameter: its value per iteration, and the true value when known.
pub fn convergence(
    path: &Path,
    title: &str,
    names: &[String],
    history: &[Vec<f64>],
    truth: Option<&[f64]>,
) -> anyhow::Result<()> {
    let iterations: Vec<f64> = (0..history.len()).map(|i| i as f64).collect();
    let columns: Vec<Vec<f64>> = (0..names.len())
        .map(|j| history.iter().map(|h| h[j]).collect())
        .collect();
    let range = (0.0, (history.len().max(2) - 1) as f64);
    let panels: Vec<Figure> = names
        .iter()
        .enumerate()
        .map(|(j, name)| {
            let mut fig = Figure::new(name, "iteration", name).with(Series::new(
                "estimate",
                iterations.as_slice(),
                columns[j].as_slice(),
                Style::Line,
            ));
            if let Some(t) = truth {
                fig = fig.with(hline("true", range, t[j]));
            }
            fig
        })
        .collect();
    plot_panels(path, title, &panels, 2)
}

// ---------------------------------------------------------------------------
// Rendering plumbing
// ---------------------------------------------------------------------------

type Area<'b> = DrawingArea<SVGBackend<'b>, Shift>;
type Chart<'b> = ChartContext<'b, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Vertical space reserved for the overall title of a panel grid.
const GRID_TITLE_HEIGHT: u32 = 50;

/// Tableau-10: familiar from matplotlib, distinguishable for most forms of
/// colour blindness in its first few entries, which are the ones we mostly use.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

const TEXT_COLOR: RGBColor = RGBColor(40, 40, 40);
const FONT: &str = "sans-serif";

/// Font sizes and tick counts; panels in a grid use smaller ones.
struct Theme {
    title: u32,
    desc: u32,
    tick: u32,
    legend: u32,
    x_ticks: usize,
    y_ticks: usize,
    margin: u32,
}

impl Theme {
    const SINGLE: Theme = Theme {
        title: 24,
        desc: 19,
        tick: 16,
        legend: 16,
        x_ticks: 10,
        y_ticks: 8,
        margin: 14,
    };
    const PANEL: Theme = Theme {
        title: 19,
        desc: 16,
        tick: 15,
        legend: 14,
        x_ticks: 6,
        y_ticks: 6,
        margin: 10,
    };
}

fn clamp_size((w, h): (u32, u32)) -> (u32, u32) {
    // Below this the fixed label areas would leave no room for data and
    // plotters' layout arithmetic could go negative.
    (w.max(200), h.max(150))
}

/// Runs `draw` on a fresh SVG canvas and returns the finished document.
fn render<F>(size: (u32, u32), draw: F) -> anyhow::Result<String>
where
    F: FnOnce(&Area) -> anyhow::Result<()>,
{
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    Ok(svg)
}

/// Writes `contents` to `<path>.tmp` and renames it over `path`, so readers
/// never observe a partially written plot.
fn write_atomic(path: &Path, contents: &str) -> anyhow::Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = Path::new(&tmp);
    fs::write(tmp, contents).with_context(|| format!("writing plot to {}", tmp.display()))?;
    fs::rename(tmp, path).map_err(|e| {
        let _ = fs::remove_file(tmp);
        anyhow::Error::new(e).context(format!("renaming plot to {}", path.display()))
    })
}

fn grid_shape(n: usize, columns: usize) -> (usize, usize) {
    let cols = columns.clamp(1, n.max(1));
    (cols, n.div_ceil(cols).max(1))
}

fn draw_grid(root: &Area, title: &str, panels: &[Figure], columns: usize) -> anyhow::Result<()> {
    let body = if title.is_empty() {
        root.clone()
    } else {
        let style = (FONT, Theme::SINGLE.title).into_font().color(&TEXT_COLOR);
        root.titled(title, style)?
    };
    let (cols, rows) = grid_shape(panels.len(), columns);
    for (cell, fig) in body.split_evenly((rows, cols)).iter().zip(panels) {
        draw_figure(cell, fig, &Theme::PANEL)?;
    }
    Ok(())
}

// ---------------------------------------------------------------------------
// One chart
// ---------------------------------------------------------------------------

fn draw_figure(area: &Area, fig: &Figure, theme: &Theme) -> anyhow::Result<()> {
    let prepared: Vec<Prepared> = fig
        .series
        .iter()
        .enumerate()
        .map(|(i, s)| prepare(s, i))
        .collect();
    let bounds = Bounds::of(&fig.series);
    let (xr, yr) = bounds.axis_ranges(x_is_monotone(&fig.series));
    let xf = AxisFormat::new(xr, theme.x_ticks);
    let yf = AxisFormat::new(yr, theme.y_ticks);

    let mut chart = build_chart(area, fig.title, theme, xr, yr, &yf)?;
    draw_mesh(&mut chart, fig, theme, &xf, &yf)?;
    for p in &prepared {
        draw_series(&mut chart, p)?;
    }
    if bounds.is_empty() {
        draw_no_data(&chart, theme)?;
    }
    draw_legend(&mut chart, &prepared, theme)?;
    Ok(())
}

fn build_chart<'b>(
    area: &Area<'b>,
    title: &str,
    theme: &Theme,
    xr: (f64, f64),
    yr: (f64, f64),
    yf: &AxisFormat,
) -> anyhow::Result<Chart<'b>> {
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(theme.margin)
        // Extra room on the right so the last x tick label is not clipped.
        .margin_right(theme.margin + 16)
        .x_label_area_size(x_label_area(theme))
        .y_label_area_size(y_label_area(theme, yf));
    if !title.is_empty() {
        builder.caption(title, (FONT, theme.title).into_font().color(&TEXT_COLOR));
    }
    Ok(builder.build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)?)
}

/// Approximate rendered width of `text` at plotters font `size`. The SVG
/// backend writes `font-size = size / 1.24` and sans-serif digits are about
/// 0.55 em wide; being slightly generous avoids clipped tick labels.
fn text_width(text: &str, size: u32) -> u32 {
    let em = f64::from(size) / 1.24;
    (text.chars().count() as f64 * em * 0.58).ceil() as u32
}

fn x_label_area(theme: &Theme) -> u32 {
    // Tick labels, a gap, then the axis description below them.
    theme.tick + theme.desc + 22
}

fn y_label_area(theme: &Theme, yf: &AxisFormat) -> u32 {
    let widest = yf
        .tick_labels()
        .iter()
        .map(|s| text_width(s, theme.tick))
        .max()
        .unwrap_or(0);
    widest + theme.desc + 24
}

fn draw_mesh(
    chart: &mut Chart,
    fig: &Figure,
    theme: &Theme,
    xf: &AxisFormat,
    yf: &AxisFormat,
) -> anyhow::Result<()> {
    let fx = |v: &f64| xf.format(*v);
    let fy = |v: &f64| yf.format(*v);
    let x_desc = xf.describe(fig.x_label);
    let y_desc = yf.describe(fig.y_label);
    chart
        .configure_mesh()
        .x_labels(theme.x_ticks)
        .y_labels(theme.y_ticks)
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .x_desc(x_desc)
        .y_desc(y_desc)
        .label_style((FONT, theme.tick).into_font().color(&TEXT_COLOR))
        .axis_desc_style((FONT, theme.desc).into_font().color(&TEXT_COLOR))
        .axis_style(RGBColor(90, 90, 90))
        .bold_line_style(BLACK.mix(0.14))
        .light_line_style(BLACK.mix(0.05))
        .max_light_lines(4)
        .draw()?;
    Ok(())
}

fn draw_no_data(chart: &Chart, theme: &Theme) -> anyhow::Result<()> {
    let area = chart.plotting_area().strip_coord_spec();
    let (w, h) = area.dim_in_pixel();
    let style = (FONT, theme.desc)
        .into_font()
        .color(&RGBColor(150, 150, 150))
        .pos(plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Center,
            plotters::style::text_anchor::VPos::Center,
        ));
    area.draw(&Text::new("no data", (w as i32 / 2, h as i32 / 2), style))?;
    Ok(())
}

// ---------------------------------------------------------------------------
// Series preparation: finite runs and decimation
// ---------------------------------------------------------------------------

/// A series ready to draw: finite, decimated, split where data was missing.
struct Prepared<'s> {
    label: &'s str,
    style: Style,
    color: RGBColor,
    runs: Vec<Vec<(f64, f64)>>,
}

/// Beyond this many gaps we stop breaking the line: thousands of tiny
/// fragments would bloat the SVG without telling the reader anything more.
const MAX_RUNS: usize = 1_000;

fn prepare<'s>(s: &'s Series, index: usize) -> Prepared<'s> {
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
        color: PALETTE[index % PALETTE.len()],
        runs,
    }
}

/// Maximal runs of consecutive points whose coordinates are both finite.
/// Values are clamped to the axis limit: plotters maps a point far outside
/// the axis range to a pixel with unchecked `i32` arithmetic and overflows.
fn finite_runs(x: &[f64], y: &[f64]) -> Vec<Vec<(f64, f64)>> {
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
fn bucket_len(total: usize, style: Style) -> usize {
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
fn decimate(run: &[(f64, f64)], bucket: usize) -> Vec<(f64, f64)> {
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

// ---------------------------------------------------------------------------
// Axis ranges and tick labels
// ---------------------------------------------------------------------------

/// Data extent over all finite points of a figure.
struct Bounds {
    x: (f64, f64),
    y: (f64, f64),
}

/// Axis limits are clamped here: plotters' tick search loops forever on an
/// infinite span, which two finite values near ±f64::MAX would produce.
const AXIS_LIMIT: f64 = 1e300;

impl Bounds {
    fn of(series: &[Series]) -> Bounds {
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

    fn is_empty(&self) -> bool {
        self.x.0 > self.x.1
    }

    /// Axis ranges: y padded by 5 %; x tight when every series runs
    /// monotonically along x (time, index, iteration), padded otherwise
    /// (loops), so curves do not touch the frame.
    fn axis_ranges(&self, x_monotone: bool) -> ((f64, f64), (f64, f64)) {
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
fn pad_range((lo, hi): (f64, f64), frac: f64) -> (f64, f64) {
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

fn x_is_monotone(series: &[Series]) -> bool {
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
struct AxisFormat {
    exp: i32,
    decimals: usize,
    ticks: Vec<f64>,
}

impl AxisFormat {
    fn new((lo, hi): (f64, f64), n_ticks: usize) -> AxisFormat {
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

    fn format(&self, v: f64) -> String {
        let s = v * 10f64.powi(-self.exp);
        let text = format!("{:.*}", self.decimals, s);
        // Rounding can yield "-0.0", which looks like a bug to a reader.
        if text.starts_with('-') && text[1..].chars().all(|c| c == '0' || c == '.') {
            text[1..].to_string()
        } else {
            text
        }
    }

    fn tick_labels(&self) -> Vec<String> {
        self.ticks.iter().map(|&t| self.format(t)).collect()
    }

    fn describe(&self, label: &str) -> String {
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

// ---------------------------------------------------------------------------
// Drawing series and legend
// ---------------------------------------------------------------------------

const LINE_WIDTH: u32 = 2;
const MARKER_RADIUS: u32 = 2;
const SWATCH: i32 = 22;

/// Dashes plotters may emit per series; each dash is its own SVG element, so
/// dense noisy data would otherwise produce tens of megabytes.
const MAX_DASHES: f64 = 1_500.0;

fn draw_series(chart: &mut Chart, p: &Prepared) -> anyhow::Result<()> {
    let style = p.color.stroke_width(LINE_WIDTH);
    let dash = dash_pattern(chart, p);
    let mut first = true;
    let empty: [Vec<(f64, f64)>; 1] = [Vec::new()];
    // An empty series still gets drawn once so it keeps its legend entry.
    let runs = if p.runs.is_empty() {
        &empty[..]
    } else {
        &p.runs[..]
    };
    for run in runs {
        let pts = run.iter().copied();
        let anno = match p.style {
            Style::Line => chart.draw_series(LineSeries::new(pts, style))?,
            Style::DashedLine => {
                chart.draw_series(DashedLineSeries::new(pts, dash.0, dash.1, style))?
            }
            Style::Points => {
                chart.draw_series(pts.map(|c| Circle::new(c, MARKER_RADIUS, p.color.filled())))?
            }
        };
        if first && !p.label.is_empty() {
            attach_legend(anno, p.label, p.style, p.color);
        }
        first = false;
    }
    Ok(())
}

/// Dash and gap length in pixels: 9/5 normally, stretched for very long
/// paths so the dash count stays under [`MAX_DASHES`].
fn dash_pattern(chart: &Chart, p: &Prepared) -> (i32, i32) {
    if p.style != Style::DashedLine {
        return (9, 5);
    }
    let length: f64 = p.runs.iter().map(|r| pixel_length(chart, r)).sum();
    let period = (length / MAX_DASHES).max(14.0);
    let dash = (period * 0.64).round() as i32;
    (dash, (period.round() as i32 - dash).max(1))
}

fn pixel_length(chart: &Chart, run: &[(f64, f64)]) -> f64 {
    let px: Vec<(i32, i32)> = run.iter().map(|c| chart.backend_coord(c)).collect();
    px.windows(2)
        .map(|w| f64::from(w[1].0 - w[0].0).hypot(f64::from(w[1].1 - w[0].1)))
        .sum()
}

/// Registers the legend entry. One closure per style because plotters'
/// legend callbacks must return a single concrete element type (boxing into
/// `DynElement` forces a `'static` backend, which the string backend is not).
fn attach_legend(anno: &mut SeriesAnno<SVGBackend>, label: &str, kind: Style, color: RGBColor) {
    let style = color.stroke_width(LINE_WIDTH);
    let anno = anno.label(label);
    match kind {
        Style::Line => {
            anno.legend(move |(x, y)| PathElement::new(vec![(x, y), (x + SWATCH, y)], style))
        }
        Style::DashedLine => anno.legend(move |(x, y)| {
            DashedPathElement::new(vec![(x, y), (x + SWATCH, y)], 7, 4, style)
        }),
        Style::Points => anno.legend(move |(x, y)| {
            Circle::new((x + SWATCH / 2, y), MARKER_RADIUS + 1, color.filled())
        }),
    };
}

fn draw_legend(chart: &mut Chart, prepared: &[Prepared], theme: &Theme) -> anyhow::Result<()> {
    let labels: Vec<&str> = prepared
        .iter()
        .map(|p| p.label)
        .filter(|l| !l.is_empty())
        .collect();
    if labels.is_empty() {
        return Ok(());
    }
    let font = (FONT, theme.legend).into_font().color(&TEXT_COLOR);
    let position = quietest_corner(chart, prepared, legend_box(&labels, theme));
    chart
        .configure_series_labels()
        .position(position)
        .margin(LEGEND_MARGIN)
        .legend_area_size(SWATCH + 8)
        .label_font(font)
        .background_style(WHITE.mix(0.88))
        .border_style(BLACK.mix(0.3))
        .draw()?;
    Ok(())
}

const LEGEND_MARGIN: i32 = 8;

/// Legend size in pixels, computed the way plotters lays it out.
fn legend_box(labels: &[&str], theme: &Theme) -> (i32, i32) {
    let font = (FONT, theme.legend).into_font();
    let mut text = MultiLineText::<(i32, i32), &str>::new((0, 0), font);
    for l in labels {
        text.push_line(*l);
    }
    let (w, h) = text
        .estimate_dimension()
        .unwrap_or((200, 20 * labels.len() as i32));
    (w + SWATCH + 8 + 2 * LEGEND_MARGIN, h + 2 * LEGEND_MARGIN)
}

/// The legend position whose box covers the fewest drawn points (sampled
/// along lines every few pixels). Corners are preferred, upper right first;
/// edge midpoints are used only when they are strictly emptier.
fn quietest_corner(
    chart: &Chart,
    prepared: &[Prepared],
    (w, h): (i32, i32),
) -> SeriesLabelPosition {
    use SeriesLabelPosition::*;
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let inset = 5; // plotters' fixed offset of the legend from the frame
    let (left, right, hmid) = (
        xs.start + inset,
        xs.end - inset - w,
        (xs.start + xs.end - w) / 2,
    );
    let (top, bottom, vmid) = (
        ys.start + inset,
        ys.end - inset - h,
        (ys.start + ys.end - h) / 2,
    );
    let boxes = [
        (UpperRight, right, top),
        (UpperLeft, left, top),
        (LowerRight, right, bottom),
        (LowerLeft, left, bottom),
        (MiddleRight, right, vmid),
        (MiddleLeft, left, vmid),
        (UpperMiddle, hmid, top),
        (LowerMiddle, hmid, bottom),
    ];
    let samples = path_samples(chart, prepared);
    // A curve merely grazing the legend frame also looks cluttered.
    let pad = 6;
    let hits = |x0: i32, y0: i32| {
        samples
            .iter()
            .filter(|&&(x, y)| {
                x >= x0 - pad && x <= x0 + w + pad && y >= y0 - pad && y <= y0 + h + pad
            })
            .count()
    };
    boxes
        .into_iter()
        .min_by_key(|&(_, x0, y0)| hits(x0, y0))
        .map(|(pos, _, _)| pos)
        .unwrap_or(UpperRight)
}

/// Pixel positions along every drawn path, including points interpolated on
/// long segments so a straight line through a corner counts as covering it.
fn path_samples(chart: &Chart, prepared: &[Prepared]) -> Vec<(i32, i32)> {
    let mut out = Vec::new();
    for p in prepared {
        for run in &p.runs {
            let px: Vec<(i32, i32)> = run.iter().map(|c| chart.backend_coord(c)).collect();
            out.extend(px.iter().copied());
            if p.style != Style::Points {
                px.windows(2)
                    .for_each(|w| interpolate(w[0], w[1], &mut out));
            }
        }
    }
    out
}

fn interpolate(a: (i32, i32), b: (i32, i32), out: &mut Vec<(i32, i32)>) {
    let len = f64::from(b.0 - a.0).hypot(f64::from(b.1 - a.1));
    // Capped so a dense noisy trace cannot blow up the sample count.
    let n = ((len / 8.0) as usize).min(64);
    for k in 1..n {
        let t = k as f64 / n as f64;
        let x = f64::from(a.0) + t * f64::from(b.0 - a.0);
        let y = f64::from(a.1) + t * f64::from(b.1 - a.1);
        out.push((x as i32, y as i32));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimation_keeps_extremes_in_order() {
        let run: Vec<(f64, f64)> = (0..100_000)
            .map(|i| (i as f64, ((i * 7919) % 1000) as f64))
            .collect();
        let d = decimate(&run, bucket_len(run.len(), Style::Line));
        assert!(d.len() <= 2_000 * 4 + 2);
        assert!(d.windows(2).all(|w| w[0].0 < w[1].0), "order preserved");
        let ymax = d.iter().map(|p| p.1).fold(f64::MIN, f64::max);
        let ymin = d.iter().map(|p| p.1).fold(f64::MAX, f64::min);
        assert_eq!((ymin, ymax), (0.0, 999.0));
        assert_eq!(d.first(), run.first());
        assert_eq!(d.last(), run.last());
    }

    #[test]
    fn runs_break_at_non_finite() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let y = [1.0, f64::NAN, 2.0, 3.0, f64::INFINITY, 4.0];
        let runs = finite_runs(&x, &y);
        assert_eq!(
            runs,
            vec![
                vec![(0.0, 1.0)],
                vec![(2.0, 2.0), (3.0, 3.0)],
                vec![(5.0, 4.0)]
            ]
        );
    }

    #[test]
    fn constant_and_degenerate_ranges_are_padded() {
        assert_eq!(pad_range((0.0, 0.0), 0.05), (-1.0, 1.0));
        let (lo, hi) = pad_range((5.0, 5.0), 0.05);
        assert!(lo < 5.0 && hi > 5.0);
        let (lo, hi) = pad_range((-f64::MAX, f64::MAX), 0.05);
        assert!((hi - lo).is_finite());
    }

    #[test]
    fn tick_labels_share_decimals() {
        let f = AxisFormat::new((0.0, 1.0), 6);
        assert_eq!(f.format(0.5), "0.5");
        assert_eq!(f.format(0.0), "0.0");
        let f = AxisFormat::new((0.0, 2e-6), 6);
        assert_eq!(f.exp, -6);
        assert!(f.describe("k [N/m]").contains("1e-6"));
        assert_eq!(AxisFormat::new((-1.0, 1.0), 5).format(-1e-12), "0.0");
    }
}

#[cfg(test)]
mod render_tests;
