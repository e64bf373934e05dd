//! The SVG writer: a [`Figure`] or a grid of them rendered into an in-memory SVG document
//! with plotters' string backend.
//!
//! Text is emitted as SVG `<text>` elements with the generic `sans-serif` family, so no font
//! files are needed; the viewer picks whatever sans-serif font it has.

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::axis::{x_is_monotone, AxisFormat, Bounds};
use super::figure::{hline, Figure, Series, Style, DEFAULT_CELL_SIZE};
use super::legend;
use super::prepare::{prepare, Prepared};
use crate::error::{Error, Result};

/// `fig` as a single-panel SVG document.
///
/// The canvas is `fig.size`, clamped to at least 200×150 px.
pub fn render(fig: &Figure) -> Result<String> {
    let size = clamp_size(fig.size);
    canvas(size, |root| draw_figure(root, fig, &Theme::SINGLE))
}

/// `panels` as an SVG grid with `columns` columns (rows as needed) under a
/// common `title`, each cell [`DEFAULT_CELL_SIZE`]. Panels share nothing:
/// each has its own axes, ranges and legend.
pub fn render_panels(title: &str, panels: &[Figure], columns: usize) -> Result<String> {
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
    render_panels_sized(title, panels, columns, size)
}

/// Like [`render_panels`] but with an explicit overall canvas `size`.
pub fn render_panels_sized(
    title: &str,
    panels: &[Figure],
    columns: usize,
    size: (u32, u32),
) -> Result<String> {
    let size = clamp_size(size);
    canvas(size, |root| draw_grid(root, title, panels, columns))
}

/// One panel per parameter (two columns): its value per iteration, and the true value when
/// known.
pub fn convergence(
    title: &str,
    names: &[String],
    history: &[Vec<f64>],
    truth: Option<&[f64]>,
) -> Result<String> {
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
    render_panels(title, &panels, 2)
}

// ---------------------------------------------------------------------------

pub(super) type Area<'b> = DrawingArea<SVGBackend<'b>, Shift>;
pub(super) type Chart<'b> =
    ChartContext<'b, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

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

pub(super) const TEXT_COLOR: RGBColor = RGBColor(40, 40, 40);
pub(super) const FONT: &str = "sans-serif";

/// Font sizes and tick counts; panels in a grid use smaller ones.
pub(super) struct Theme {
    title: u32,
    desc: u32,
    tick: u32,
    pub(super) legend: u32,
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
fn canvas<F>(size: (u32, u32), draw: F) -> Result<String>
where
    F: FnOnce(&Area) -> Result<()>,
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

fn grid_shape(n: usize, columns: usize) -> (usize, usize) {
    let cols = columns.clamp(1, n.max(1));
    (cols, n.div_ceil(cols).max(1))
}

fn draw_grid(root: &Area, title: &str, panels: &[Figure], columns: usize) -> Result<()> {
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

fn draw_figure(area: &Area, fig: &Figure, theme: &Theme) -> Result<()> {
    let prepared: Vec<Prepared> = fig
        .series
        .iter()
        .enumerate()
        .map(|(i, s)| prepare(s, PALETTE[i % PALETTE.len()]))
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
    legend::draw_legend(&mut chart, &prepared, theme)?;
    Ok(())
}

fn build_chart<'b>(
    area: &Area<'b>,
    title: &str,
    theme: &Theme,
    xr: (f64, f64),
    yr: (f64, f64),
    yf: &AxisFormat,
) -> Result<Chart<'b>> {
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
) -> Result<()> {
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

fn draw_no_data(chart: &Chart, theme: &Theme) -> Result<()> {
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

/// Stroke width of lines, in pixels.
pub(super) const LINE_WIDTH: u32 = 2;
/// Radius of a point marker, in pixels.
pub(super) const MARKER_RADIUS: u32 = 2;

/// Dashes plotters may emit per series; each dash is its own SVG element, so
/// dense noisy data would otherwise produce tens of megabytes.
const MAX_DASHES: f64 = 1_500.0;

fn draw_series(chart: &mut Chart, p: &Prepared) -> Result<()> {
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
            legend::attach_legend(anno, p.label, p.style, p.color);
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

/// A plotters drawing error as the library's error (the SVG backend writes into a string, so
/// this is an internal failure of the plot layout, never of the data).
impl<E: std::error::Error + Send + Sync> From<DrawingAreaErrorKind<E>> for Error {
    fn from(e: DrawingAreaErrorKind<E>) -> Self {
        Error::Plot(e.to_string())
    }
}
