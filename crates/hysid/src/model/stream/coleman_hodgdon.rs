//! The Coleman–Hodgdon hysteresis one sample at a time, and its inverse.
//!
//! Forward: y₀ is the initial output (the measured one, or 0), then
//! y_t = y_{t−1} + α|Δx|(f(x_t) − y_{t−1}) + g(x_t)Δx ([`ColemanHodgdon::step`]), a sample with
//! α|Δx| > 1 refused as the batch refuses it. Inverse: the per-sample solve of
//! [`crate::model::compensate`] (its module doc); the batch compensation is a loop over it.

use super::{InverseKernel, Kernel};
use crate::model::coleman_hodgdon::InitialOutput;
use crate::model::operators::{solve_monotone, Branch, CompensatorStep};
use crate::model::ColemanHodgdon;
use crate::{Error, Result};

/// The hysteresis streamed from the initial output `v0`.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct HysteresisStream {
    ch: ColemanHodgdon,
    v0: f64,
    /// (x_{t−1}, y_{t−1}) after the first sample.
    last: Option<(f64, f64)>,
}

impl HysteresisStream {
    pub(super) fn new(ch: ColemanHodgdon, v0: f64) -> Self {
        Self { ch, v0, last: None }
    }

    /// y_t for x_t = `x` (`t` the sample's index).
    pub(super) fn next(&mut self, t: usize, x: f64) -> Result<f64> {
        let y = match self.last {
            None => self.v0,
            Some((x_prev, y_prev)) => {
                let dx = x - x_prev;
                let product = self.ch.alpha() * dx.abs();
                // The batch's `ColemanHodgdon::check_rate`, one sample at a time.
                if product > 1.0 + 1e-12 {
                    return Err(Error::RateLimit {
                        index: t,
                        alpha: self.ch.alpha(),
                        dx,
                        product,
                    });
                }
                self.ch.step(y_prev, x_prev, x)
            }
        };
        self.last = Some((x, y));
        Ok(y)
    }

    pub(super) fn restart(&mut self) {
        self.last = None;
    }
}

impl Kernel for HysteresisStream {
    fn reset(&mut self) {
        self.restart();
    }
    fn step(&mut self, k: usize, u: &[f64], y: &mut [f64]) -> Result<()> {
        y[0] = self.next(k, u[0])?;
        Ok(())
    }
}

/// The hysteresis' inverse streamed (module doc of [`crate::model::compensate`]).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct HysteresisInverse {
    ch: ColemanHodgdon,
    initial: InitialOutput,
    /// The largest step the recursion admits (1/α; unbounded for α = 0).
    reach: f64,
    /// (x_{t−1}, y_{t−1}) after the first sample.
    last: Option<(f64, f64)>,
}

impl HysteresisInverse {
    pub(super) fn new(ch: ColemanHodgdon, initial: InitialOutput) -> Self {
        let alpha = ch.alpha();
        let reach = if alpha > 0.0 {
            1.0 / alpha
        } else {
            f64::MAX.sqrt()
        };
        Self {
            ch,
            initial,
            reach,
            last: None,
        }
    }

    /// The first sample: the output starts at r₀ (a measured start) or 0, the input where the
    /// anhysteretic f equals it; r₀ counts as clipped when the start misses it.
    fn first(&self, r: f64) -> (f64, f64, bool) {
        let y0 = match self.initial {
            InitialOutput::Measured => r,
            InitialOutput::Zero => 0.0,
        };
        let x0 = anhysteretic_inverse(&self.ch, y0, self.reach);
        (x0, y0, (y0 - r).abs() > 1e-12 * (1.0 + r.abs()))
    }

    /// A later sample: x_t with y_t = r_t by bracketing on |Δx| ≤ 1/α.
    fn later(&self, (x_prev, y_prev): (f64, f64), target: f64) -> (f64, f64, bool) {
        let (ch, reach) = (&self.ch, self.reach);
        let step = |v: f64| ch.step(y_prev, x_prev, v.clamp(x_prev - reach, x_prev + reach));
        let branch = Branch {
            center: x_prev,
            span: reach,
            unbounded_below: false,
            unbounded_above: false,
        };
        let (x, clip) = solve_monotone(step, target, branch);
        let x = x.clamp(x_prev - reach, x_prev + reach);
        let y = ch.step(y_prev, x_prev, x);
        // The recursion need not be monotone on every branch of every model: a solve that
        // missed counts as clipped too.
        (
            x,
            y,
            clip || (y - target).abs() > 1e-9 * (1.0 + target.abs()),
        )
    }
}

impl InverseKernel for HysteresisInverse {
    fn reset(&mut self) {
        self.last = None;
    }
    fn step(&mut self, _k: usize, r: f64) -> Result<CompensatorStep> {
        let (u, predicted, clipped) = match self.last {
            None => self.first(r),
            Some(last) => self.later(last, r),
        };
        self.last = Some((u, predicted));
        Ok(CompensatorStep {
            u,
            predicted,
            clipped,
        })
    }
}

/// x with f(x) = v for the odd, piecewise-linear material function f, or 0 when f is flat.
fn anhysteretic_inverse(ch: &ColemanHodgdon, v: f64, reach: f64) -> f64 {
    let branch = Branch {
        center: 0.0,
        span: ch.d().abs().max(1.0).min(reach),
        unbounded_below: true,
        unbounded_above: true,
    };
    if ch.m1() <= 0.0 {
        return 0.0;
    }
    let (x, _) = solve_monotone(|x| ch.f(x), v, branch);
    if x.is_finite() {
        x
    } else {
        0.0
    }
}
