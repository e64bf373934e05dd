//! The legend: one entry per labelled series, placed in the corner of the chart that
//! covers the fewest drawn points.

use plotters::chart::SeriesAnno;
use plotters::element::{DashedPathElement, MultiLineText};
use plotters::prelude::*;

use super::figure::Style;
use super::prepare::Prepared;
use super::svg::{Chart, Theme, FONT, LINE_WIDTH, MARKER_RADIUS, TEXT_COLOR};
use crate::error::Result;

/// Width of a legend swatch in pixels.
const SWATCH: i32 = 22;

/// Registers the legend entry. One closure per style because plotters'
/// legend callbacks must return a single concrete element type (boxing into
/// `DynElement` forces a `'static` backend, which the string backend is not).
pub(super) fn attach_legend(
    anno: &mut SeriesAnno<SVGBackend>,
    label: &str,
    kind: Style,
    color: RGBColor,
) {
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

pub(super) fn draw_legend(chart: &mut Chart, prepared: &[Prepared], theme: &Theme) -> Result<()> {
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
