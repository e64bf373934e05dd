//! SVG plots of identification results: time responses, hysteresis loops,
//! parameter-convergence grids, residual correlations and input signals.
//!
//! * [`figure`]: what a plot shows — [`Figure`], [`Series`], [`Style`];
//! * `axis`: axis ranges and tick labels; `prepare`: finite runs and decimation;
//!   `svg` and `legend`: the SVG writer (plotters' string backend);
//! * [`sets`]: the figure set of each identification (cascade, hysteresis, grey-box, the
//!   Bouc–Wen benchmark's test records, the actuator), returned as [`Svg`] documents for a
//!   front end to write.
//!
//! Everything is rendered into an in-memory SVG document; writing it is the caller's
//! business (the command line writes a plot directory through
//! [`crate::io::atomic::OutputSet`]).
//!
//! Odd data never panics: non-finite values are skipped (lines are broken at them), empty
//! figures get a "no data" note, constant series get a padded axis, and very long series are
//! decimated for drawing while keeping their extremes.

#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub mod axis;
pub mod figure;
mod legend;
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub mod prepare;
pub mod sets;
mod svg;

pub use figure::{hline, Figure, Series, Style, DEFAULT_CELL_SIZE, DEFAULT_SIZE};
pub use prepare::DECIMATE_ABOVE;
pub use sets::{
    actuator_figures, benchmark_test_figures, cascade_figures, greybox_figures, hysteresis_figures,
    operator_cascade_figures,
};
pub use svg::{convergence, render, render_panels, render_panels_sized};

/// One finished plot: its file name (e.g. `loops.svg`) and its SVG document.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Svg {
    /// File name within a plot directory.
    pub name: String,
    /// The SVG document.
    pub svg: String,
}
