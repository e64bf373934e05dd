//! Fit of the Duhem / Coleman–Hodgdon operator ([`Duhem`])
//! dy = α|du|(a·u + b − y) + c·du to a measured loop.
//!
//! **Start from the data.** For fixed α the output is linear in (a, b, c, y0) — the equation
//! is linear in y and in the forcing — so for a grid of α (1 to 200 per input range) the four
//! basis responses are simulated and (a, b, c, y0) solved by linear least squares; the best
//! grid points start a bounded Levenberg–Marquardt search of all five (α > 0), forward
//! finite-difference sensitivities.
//!
//! **Orientation** needs no special handling: the sign of c − a is the loop's orientation and
//! the linear start finds it from the data.
//!
//! Reference: Coleman & Hodgdon (1986), see [`crate::model::operators::duhem`].

use super::differential_fit::{self as common, Search, Simulated};
use super::family::{FamilyOptions, Identify};
use super::OperatorFit;
use crate::model::operators::{Duhem, HysteresisOperator};
use crate::numerics::levenberg_marquardt::LmConfig;
use crate::numerics::Observer;
use crate::Result;
use std::time::Instant;

/// Options of the Duhem fit.
#[derive(Clone, Debug)]
pub struct DuhemOptions {
    /// Number of grid points that start a search (default 3).
    pub starts: usize,
    /// Levenberg–Marquardt settings.
    pub config: LmConfig,
    /// Sees the search's starts and iterations and may stop it (see [`Search::observer`]).
    pub observer: Observer,
}

impl Default for DuhemOptions {
    fn default() -> Self {
        Self {
            starts: 3,
            config: common::default_config(),
            observer: Observer::none(),
        }
    }
}

/// θ = (α, a, b, c, y0), the order of [`Duhem::parameters`].
fn model_of(theta: &[f64]) -> Result<Duhem> {
    let m = Duhem {
        alpha: theta[0],
        a: theta[1],
        b: theta[2],
        c: theta[3],
        y0: theta[4],
    };
    m.validate()?;
    Ok(m)
}

/// Fits a Duhem operator to input `u` and output `y` (module doc).
pub fn fit(u: &[f64], y: &[f64], options: &DuhemOptions) -> Result<OperatorFit<Duhem>> {
    let started = Instant::now();
    common::check_record("duhem", u, y, 5)?;
    let starts = grid_starts(u, y, options.starts.max(1))?;
    let inf = f64::INFINITY;
    let search = Search {
        free: vec![0, 1, 2, 3, 4],
        lower: vec![0.0, -inf, -inf, -inf, -inf],
        upper: vec![inf; 5],
        config: options.config.clone(),
        observer: options.observer.clone(),
    };
    let simulate = |theta: &[f64]| model_of(theta)?.simulate(u);
    let problem = Simulated {
        y,
        simulate: &simulate,
        n_params: 5,
    };
    let searched = common::best_of(&problem, &starts, &search)?;
    common::report(model_of(&searched.best.theta)?, u, y, &searched, started)
}

/// The best grid points of α with (a, b, c, y0) by linear least squares.
fn grid_starts(u: &[f64], y: &[f64], keep: usize) -> Result<Vec<Vec<f64>>> {
    let (lo, hi) = common::range(u);
    let span = hi - lo;
    let mut scored = Vec::new();
    for alpha in [1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0].map(|f| f / span) {
        let basis = |a: f64, b: f64, c: f64, y0: f64| {
            let m = Duhem { alpha, a, b, c, y0 };
            m.simulate(u)
        };
        let (Ok(pa), Ok(pb), Ok(pc), Ok(p0)) = (
            basis(1.0, 0.0, 0.0, 0.0),
            basis(0.0, 1.0, 0.0, 0.0),
            basis(0.0, 0.0, 1.0, 0.0),
            basis(0.0, 0.0, 0.0, 1.0),
        ) else {
            continue;
        };
        if let Some((k, sse)) = common::linear_fit(&[&pa, &pb, &pc, &p0], y) {
            scored.push((sse, vec![alpha, k[0], k[1], k[2], k[3]]));
        }
    }
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    let starts: Vec<Vec<f64>> = scored.into_iter().take(keep).map(|s| s.1).collect();
    if starts.is_empty() {
        return Err(crate::Error::NotExciting {
            channel: "input".into(),
            reason: "no Duhem start could be solved for; the loop is degenerate".into(),
        });
    }
    Ok(starts)
}

impl Identify for Duhem {
    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>> {
        fit(
            u,
            y,
            &DuhemOptions {
                observer: options.observer.clone(),
                ..DuhemOptions::default()
            },
        )
    }
}
