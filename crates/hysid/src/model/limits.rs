//! Command limits and the rule for non-finite samples: the two safety rules every
//! compensator and stream obeys, defined here once and used by the library's streams
//! ([`crate::model::stream`]), batch compensation ([`crate::model::compensate`]) and the
//! exported code (`crate::export`), which prints the same comparisons (`docs/export.md`,
//! "Limits and bad samples").
//!
//! # Limits
//!
//! A compensator's command u is limited to the actuator's range \[lo, hi\]:
//!
//! u' = lo if u < lo, hi if u > hi, u otherwise,
//!
//! and a step whose command was changed counts as clipped (a reference beyond reach gets the
//! nearest reachable command). The default range is the model file's `input_range` (the
//! minimum and maximum of the fitted data's input, [`input_range_of`]); `--limits LO:HI`
//! (Python `limits=(lo, hi)`) replaces it. The limit acts on the command only: the inverse's
//! state follows the reference as given, and the step's `predicted` output is the model's
//! output for the command before the limit.
//!
//! # Non-finite samples
//!
//! A NaN or ±∞ input (a reference for a compensator) leaves the state unchanged: the step
//! outputs the last good value — before any good sample, a compensator the midpoint of its
//! limits ([`Limits::midpoint`]; 0 without limits), a forward model 0 — and counts a fault.
//! The flag "the last sample was bad" clears at the next good sample, which gives exactly
//! what it would have given had the bad one never come ([`is_bad`]).

use crate::data::IdData;
use crate::{Error, Result};

/// The range \[lo, hi\] a compensator's command is limited to (see the [module doc](self)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    lo: f64,
    hi: f64,
}

impl Limits {
    /// The limits \[lo, hi\]; errors unless both are finite and lo ≤ hi.
    pub fn new(lo: f64, hi: f64) -> Result<Self> {
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(Error::invalid_option(
                "limits",
                format!("{lo}:{hi}"),
                "the command limits must be two finite numbers LO:HI with LO <= HI".into(),
            ));
        }
        Ok(Self { lo, hi })
    }

    /// The limits written `LO:HI` (the `--limits` option), e.g. `-10:150`.
    pub fn parse(text: &str) -> Result<Self> {
        let bad = || {
            Error::invalid_option(
                "limits",
                text,
                "write the command limits as LO:HI, two finite numbers with LO <= HI (e.g. \
                 -10:150)"
                    .into(),
            )
        };
        let (lo, hi) = text.split_once(':').ok_or_else(bad)?;
        let lo: f64 = lo.trim().parse().map_err(|_| bad())?;
        let hi: f64 = hi.trim().parse().map_err(|_| bad())?;
        Self::new(lo, hi).map_err(|_| bad())
    }

    /// The limits of a model file's input `input` (its `input_range`), None when the file
    /// has none (a file of an earlier version) or no such input.
    pub fn of_range(input_range: Option<&[[f64; 2]]>, input: usize) -> Option<Self> {
        let [lo, hi] = *input_range?.get(input)?;
        Self::new(lo, hi).ok()
    }

    /// The lower limit.
    pub fn lo(&self) -> f64 {
        self.lo
    }

    /// The upper limit.
    pub fn hi(&self) -> f64 {
        self.hi
    }

    /// (lo + hi)/2: what a compensator commands before its first good reference.
    pub fn midpoint(&self) -> f64 {
        0.5 * (self.lo + self.hi)
    }

    /// The command `u` limited to \[lo, hi\], and whether it was changed (clipped). A NaN
    /// passes unchanged (it is caught as a divergence by the caller).
    pub fn apply(&self, u: f64) -> (f64, bool) {
        if u < self.lo {
            (self.lo, true)
        } else if u > self.hi {
            (self.hi, true)
        } else {
            (u, false)
        }
    }
}

/// True for a sample the streams skip (see the [module doc](self)): any value not finite.
pub fn is_bad(values: &[f64]) -> bool {
    values.iter().any(|v| !v.is_finite())
}

/// The `input_range` a model file records: \[min, max\] of each input channel over every
/// experiment of `data`, the data the model was fitted on.
pub fn input_range_of(data: &IdData) -> Vec<[f64; 2]> {
    (0..data.input_channels().len())
        .map(|ch| {
            let mut range = [f64::INFINITY, f64::NEG_INFINITY];
            for e in data.experiments() {
                for &v in e.input(ch) {
                    range[0] = range[0].min(v);
                    range[1] = range[1].max(v);
                }
            }
            range
        })
        .collect()
}
