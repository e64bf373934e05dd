//! What a plot shows: [`Figure`]s of labelled [`Series`], each drawn in a [`Style`].
//!
//! A figure is a description only; \[`super::svg`\] renders it.

use std::borrow::Cow;

/// Default canvas size of a single-panel plot, in pixels.
pub const DEFAULT_SIZE: (u32, u32) = (900, 600);

/// Default size of one cell in [`super::render_panels`], in pixels.
pub const DEFAULT_CELL_SIZE: (u32, u32) = (480, 330);

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
    /// Canvas size in pixels used by [`super::render`]; ignored inside [`super::render_panels`].
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
