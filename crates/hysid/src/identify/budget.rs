//! Resource estimates of the recipes, made before any large allocation.
//!
//! A recipe's cost is dominated by simulations of the model over the record. For a record of
//! N samples, s integration sub-steps per sample, n states and p free parameters, one
//! simulation with forward sensitivities performs N·s steps and holds
//!
//! ```text
//!     bytes       ≈ 8 · N · (s·c + n·(1 + p) + p + 4)        (c input channels)
//!     evaluations = N · s                                    (model steps)
//! ```
//!
//! the first term being the input interpolated at the sub-steps (band-limited interpolation
//! keeps the whole upsampled record, 16 bytes per complex point), the second the states and
//! their sensitivities, the third the Jacobian of the residuals (Ljung, *System
//! Identification*, 2nd ed., 1999, §10.2). A Levenberg–Marquardt fit of I iterations performs
//! at most about I·(1 + p) such simulations; a multi-start of S starts and a bootstrap of R
//! replicates multiply the work, not the memory (the searches keep one result per start).
//!
//! The work figures predict the work a run performs — the model steps the output-error
//! engine and the cascade's grid count as they simulate ([`count`], [`counted`]; the CLI
//! reports them as `search.model_steps`) — to within a factor of three on the README's
//! commands: a search's iterations are taken at their typical count, not their cap
//! (calibrated constants below), so an estimate neither refuses a run of seconds nor hides
//! one of hours. The memory figures are upper estimates, to refuse a 13 GB allocation before
//! it starts. All arithmetic saturates at `u64::MAX`, so an absurd request gives an absurd
//! but finite figure instead of an overflow.

use super::cascade::CascadeIdentification;
use super::greybox::GreyBoxEstimation;
use super::Uncertainty;
use crate::model::greybox::{InputInterpolation, Integrator};
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

/// Memory and work of a request.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Work {
    /// Peak bytes the request allocates at once.
    pub bytes: u64,
    /// Model steps (sample × sub-step evaluations of the model equations) in total.
    pub evaluations: u64,
}

/// Model steps performed so far by this process (see [`count`]).
static COUNTED: AtomicU64 = AtomicU64::new(0);

/// Adds `steps` model steps to the process's count. The output-error engine calls it once
/// per simulated experiment: samples × steps per sample, times (1 + p) for a pass that also
/// computes p sensitivities — the unit of [`Work::evaluations`].
pub fn count(steps: u64) {
    COUNTED.fetch_add(steps, Relaxed);
}

/// Model steps counted so far by this process (every estimation in it, summed: a front end
/// running one request per process reads the request's actual work).
pub fn counted() -> u64 {
    COUNTED.load(Relaxed)
}

/// `a · b`, saturating at `u64::MAX`.
fn mul(a: u64, b: u64) -> u64 {
    a.saturating_mul(b)
}

/// A `usize` as `u64`, saturating (a `usize` wider than 64 bits is not a target).
fn wide(n: usize) -> u64 {
    u64::try_from(n).unwrap_or(u64::MAX)
}

/// Memory and work of one model simulation over `samples` samples with `substeps` steps per
/// sample, `inputs` input channels, `states` states and `parameters` sensitivities
/// (0 for a plain simulation); `band_limited` when the input is upsampled over the whole
/// record at once.
pub fn simulation(
    samples: usize,
    substeps: usize,
    inputs: usize,
    states: usize,
    parameters: usize,
    band_limited: bool,
) -> Work {
    let (n, s) = (wide(samples), wide(substeps.max(1)));
    let c = wide(inputs.max(1));
    // Complex spectrum and real upsampled copy: 16 + 8 bytes per point.
    let input = if band_limited { mul(mul(s, c), 3) } else { c };
    let state = mul(wide(states), wide(parameters).saturating_add(1));
    let per_sample = input
        .saturating_add(state)
        .saturating_add(wide(parameters))
        .saturating_add(4);
    Work {
        bytes: mul(mul(n, per_sample), 8),
        evaluations: mul(n, s),
    }
}

impl Work {
    /// The same memory, the work repeated `times` times.
    pub fn repeated(self, times: u64) -> Work {
        Work {
            bytes: self.bytes,
            evaluations: mul(self.evaluations, times),
        }
    }
}

/// Iterations the final grey-box fit typically takes from its screened start (calibrated on
/// the README's `greybox fit` and `benchmark bouc-wen` runs against the counted work,
/// [`counted`]); the screening fits are counted at their cap, which they mostly reach.
const GREYBOX_FINAL_ITERATIONS: u64 = 19;

impl GreyBoxEstimation {
    /// Memory and work of [`GreyBoxEstimation::estimate`] on `samples` samples (summed over
    /// the experiments) of a model with `inputs` input channels, `states` states and
    /// `parameters` free parameters: the screening fits of every start plus the final fit,
    /// a sensitivity pass costing 1 + p simulations.
    pub fn work_estimate(
        &self,
        samples: usize,
        inputs: usize,
        states: usize,
        parameters: usize,
    ) -> Work {
        let (substeps, steps_factor) = match self.simulation.integrator {
            Integrator::Rk4 { substeps } => (substeps, 4),
            Integrator::Newmark { substeps } => (substeps, 1),
            // Dormand–Prince: six stages a step, a few steps a sample for smooth models.
            Integrator::Adaptive { .. } => (4, 6),
        };
        let band_limited = matches!(
            self.simulation.interpolation,
            InputInterpolation::BandLimited
        );
        let one = simulation(samples, substeps, inputs, states, parameters, band_limited)
            .repeated(steps_factor);
        let per_fit = wide(parameters).saturating_add(1);
        // The final fit starts from the best screened start and converges in a few
        // iterations: its typical count, not the cap, is what it costs.
        let final_fit = mul(
            wide(self.lm.max_iterations)
                .min(GREYBOX_FINAL_ITERATIONS)
                .saturating_add(1),
            per_fit,
        );
        let screening = if self.starts > 1 {
            let screened = self
                .screening_samples
                .map_or(wide(samples), |m| wide(m).min(wide(samples)));
            let fraction = screened.max(1);
            mul(
                mul(
                    wide(self.starts),
                    wide(self.screening_iterations).saturating_add(1),
                ),
                per_fit,
            )
            .saturating_mul(fraction)
                / wide(samples).max(1)
        } else {
            0
        };
        one.repeated(final_fit.saturating_add(screening))
    }
}

/// Sensitivity passes a windowed output-error fit of the cascade typically takes (its
/// Levenberg–Marquardt iterations converge in a few; calibrated on `hysid identify cascade`
/// against the counted work, [`counted`]).
const CASCADE_WINDOW_PASSES: u64 = 10;

/// Sensitivity passes of the cascade's full-record fit after the window's (calibrated
/// likewise).
const CASCADE_FULL_PASSES: u64 = 10;

impl CascadeIdentification {
    /// Memory and work of [`CascadeIdentification::estimate`] on `samples` samples: the
    /// (α, d) grid of equation-error regressions on the window (one pass of the hysteresis
    /// basis a point), the windowed fits (the local refinements and the interval scan, a few
    /// sensitivity passes each) and, on a record longer than the window, the full-record fit,
    /// all repeated for every bootstrap replicate. Calibrated on the counted work
    /// ([`counted`]) of the project's examples from 4 000 to 10⁶ samples: within a factor of
    /// two.
    pub fn work_estimate(&self, samples: usize) -> Work {
        let p = wide(self.structure.n_params());
        let n = wide(samples);
        let window = wide(self.window.max(100)).min(n);
        let pass = p.saturating_add(1);
        let grid = mul(
            mul(wide(self.grid.alpha_points), wide(self.grid.d_points)),
            window,
        );
        let window_fits = wide(self.grid.refine)
            .saturating_add(1)
            .saturating_add(2 * wide(self.scan.min(1 << 20)) + 1);
        let windowed = mul(mul(window_fits, CASCADE_WINDOW_PASSES), mul(pass, window));
        let full = if n > window {
            mul(CASCADE_FULL_PASSES, mul(pass, n))
        } else {
            0
        };
        let once = grid.saturating_add(windowed).saturating_add(full);
        let replicates = match self.uncertainty {
            Uncertainty::Asymptotic => 0,
            Uncertainty::Bootstrap(r) => wide(r),
        };
        Work {
            bytes: mul(mul(n, p.saturating_add(4)), 16),
            evaluations: mul(once, replicates.saturating_add(1)),
        }
    }
}
