//! A trial point's pass that stops once the point is certain to be rejected.
//!
//! Levenberg–Marquardt accepts a trial point θ' only if its S(θ') = Σ r² is below the current
//! S (the engine's [`Trial::ceiling`]); a rejected point's S is used for nothing else. The
//! terms of S are non-negative, so the sum of the residuals simulated so far is a lower
//! bound of S(θ'): once it passes the ceiling, the rest of the pass cannot change the
//! verdict, and a sensitivity pass of a trial point far from the minimum (the first steps of
//! a fit from a poor start, whose damping is still too small) stops there instead of
//! simulating the whole record. Accepted points are simulated to the end, so every number
//! the fit reports is the one the whole pass gives.
//!
//! Rounding: a sum of k non-negative terms, in any order, is within (k − 1)·ε of the exact
//! sum (ε = 2⁻⁵³; Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., §4.2).
//! The partial sum must therefore exceed the ceiling by the relative [`MARGIN`] before the
//! pass stops; 10⁻⁶ covers records of up to 10⁹ residuals, so the whole pass's S, however
//! it is summed, would not have been below the ceiling either.
//!
//! [`Trial::ceiling`]: crate::numerics::levenberg_marquardt::Trial::ceiling

use std::sync::atomic::Ordering::Relaxed;
use std::sync::atomic::{AtomicBool, AtomicU64};

/// The relative margin by which the partial sum must exceed the ceiling (see the module
/// docs).
pub const MARGIN: f64 = 1e-6;

/// Residuals a thread sums on its own before adding them to the shared total.
const FLUSH_ROWS: usize = 1024;

/// The ceiling of one trial point's pass, shared by the threads that simulate it.
#[derive(Debug)]
pub struct Ceiling {
    /// The ceiling raised by [`MARGIN`].
    bound: f64,
    /// The squared residuals summed so far (the bits of an `f64`).
    total: AtomicU64,
    /// Set once `total` passed `bound`.
    passed: AtomicBool,
}

impl Ceiling {
    /// The ceiling of a trial point whose S must be below `cost` to be accepted.
    pub fn new(cost: f64) -> Self {
        Self {
            bound: cost * (1.0 + MARGIN),
            total: AtomicU64::new(0.0f64.to_bits()),
            passed: AtomicBool::new(false),
        }
    }

    /// True once the residuals summed so far passed the ceiling: the rest of the pass is not
    /// needed.
    pub fn passed(&self) -> bool {
        self.passed.load(Relaxed)
    }

    /// The lower bound of S the pass reached, once it passed the ceiling.
    pub fn lower_bound(&self) -> Option<f64> {
        self.passed()
            .then(|| f64::from_bits(self.total.load(Relaxed)))
    }

    /// A tally of one thread's residuals into this ceiling.
    pub fn tally(&self) -> Tally<'_> {
        Tally {
            ceiling: self,
            partial: 0.0,
            rows: 0,
        }
    }

    /// Adds `partial` to the shared total; marks the ceiling passed when the total passes it.
    fn add(&self, partial: f64) {
        let mut total = 0.0;
        // The closure always returns Some, so the update cannot fail.
        let _ = self.total.fetch_update(Relaxed, Relaxed, |bits| {
            total = f64::from_bits(bits) + partial;
            Some(total.to_bits())
        });
        if total > self.bound {
            self.passed.store(true, Relaxed);
        }
    }
}

/// One thread's running sum of squared residuals, added to its [`Ceiling`] every 1 024
/// residuals (few updates of the shared total, and a pass that stops soon after passing).
#[derive(Debug)]
pub struct Tally<'c> {
    ceiling: &'c Ceiling,
    partial: f64,
    rows: usize,
}

impl Tally<'_> {
    /// Counts residual `r`.
    #[inline]
    pub fn add(&mut self, r: f64) {
        self.partial += r * r;
        self.rows += 1;
        if self.rows == FLUSH_ROWS {
            self.ceiling.add(self.partial);
            (self.partial, self.rows) = (0.0, 0);
        }
    }

    /// [`Ceiling::passed`] of the shared ceiling.
    #[inline]
    pub fn passed(&self) -> bool {
        self.ceiling.passed()
    }
}
