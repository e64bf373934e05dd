//! Multi-start: several starting points drawn inside the bounds, fitted in parallel, the best
//! kept — against the local minima that are the top complaint about `nlgreyest`.
//!
//! # Drawing the starts
//!
//! The user's starting point is always the first start. The others draw every free
//! parameter independently (seeded):
//!
//! * both bounds finite: log-uniform on [min, max] when 0 < min and max/min ≥ 10 (bounds a
//!   decade or more wide), uniform otherwise;
//! * an infinite bound: log-uniform within a factor 2 of the initial value (sign kept),
//!   cut to the bounds; uniform on [−1, 1] cut to the bounds when the initial value is 0.

use super::output_error::OutputErrorFit;
use crate::model::ParameterSet;
use crate::{Error, Result};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;

/// How one start fared.
#[derive(Clone, Debug, serde::Serialize)]
pub struct StartOutcome {
    /// The starting values (full parameter vector).
    pub start: Vec<f64>,
    /// The criterion after the fit (infinite when it failed).
    pub cost: f64,
    /// Why its fit stopped, or what went wrong.
    pub termination: String,
}

/// `n` starting points for `params` (see the module docs); the first is `params` itself.
pub fn draw_starts(params: &ParameterSet, n: usize, seed: u64) -> Vec<ParameterSet> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut starts = vec![params.clone()];
    for _ in 1..n {
        let mut p = params.clone();
        for i in params.free_indices() {
            let q = p.get_mut(i);
            q.value = draw(q.value, q.min, q.max, &mut rng);
        }
        starts.push(p);
    }
    starts
}

fn draw(value: f64, min: f64, max: f64, rng: &mut Xoshiro256PlusPlus) -> f64 {
    if min.is_finite() && max.is_finite() {
        return if min > 0.0 && max / min >= 10.0 {
            (min.ln() + rng.random::<f64>() * (max / min).ln()).exp()
        } else {
            min + rng.random::<f64>() * (max - min)
        };
    }
    let v = if value == 0.0 {
        rng.random_range(-1.0..1.0)
    } else {
        value * 2f64.powf(rng.random_range(-1.0..1.0))
    };
    v.clamp(min, max)
}

/// Fits every start with `fit` in parallel and returns the best fit with every outcome.
/// Errors only when no start could be fitted.
pub fn best_of(
    starts: &[ParameterSet],
    fit: &(dyn Fn(&ParameterSet) -> Result<OutputErrorFit> + Sync),
) -> Result<(OutputErrorFit, Vec<StartOutcome>)> {
    let results: Vec<Result<OutputErrorFit>> = starts.par_iter().map(fit).collect();
    let mut outcomes = Vec::with_capacity(starts.len());
    let mut best: Option<OutputErrorFit> = None;
    let mut first_error = None;
    for (start, result) in starts.iter().zip(results) {
        match result {
            Ok(f) => {
                outcomes.push(StartOutcome {
                    start: start.values(),
                    cost: f.report.cost,
                    termination: f.report.termination.to_string(),
                });
                if best.as_ref().is_none_or(|b| f.report.cost < b.report.cost) {
                    best = Some(f);
                }
            }
            Err(e) => {
                outcomes.push(StartOutcome {
                    start: start.values(),
                    cost: f64::INFINITY,
                    termination: e.to_string(),
                });
                first_error.get_or_insert(e);
            }
        }
    }
    match best {
        Some(b) => Ok((b, outcomes)),
        None => Err(first_error.unwrap_or_else(|| {
            Error::invalid_option("starts", 0, "multi-start needs at least one start".into())
        })),
    }
}
