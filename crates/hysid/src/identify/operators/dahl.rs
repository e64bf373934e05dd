//! Fit of the Dahl friction operator ([`Dahl`]) dF/dx = σ(1 − (F/F_c)·sign dx)^i to a
//! measured force–displacement loop.
//!
//! **Orientation.** A clockwise loop (Dahl's own) is fitted as it is; a counter-clockwise one
//! (detected from the sign of the enclosed area, [`LoopOrientation::of_loop`]) with the
//! operator driven by −u ([`LoopOrientation::CounterClockwise`]); the inverse of the fitted
//! operator includes the flip, so it returns an input on the measured scale.
//!
//! **Start from the data.** With i = 1 the equation reads dF/dx = σ − ρ·sign(dx)·F,
//! ρ = σ/F_c, so for fixed ρ the force is linear in (σ, f0): f0·e^{−ρ·TV(x)} (TV the total
//! variation travelled) plus σ times the unit-σ response. A grid of ρ (1 to 200 per input
//! range) with (σ, f0) by linear least squares gives the starts of a bounded
//! Levenberg–Marquardt search of (σ, F_c, \[i\], f0), forward finite-difference sensitivities.
//!
//! References: Dahl (1968, 1976), see [`crate::model::operators::dahl`].

use super::differential_fit::{self as common, Search, Simulated};
use super::family::{FamilyOptions, Identify};
use super::OperatorFit;
use crate::model::operators::{Dahl, HysteresisOperator, LoopOrientation};
use crate::numerics::levenberg_marquardt::LmConfig;
use crate::numerics::Observer;
use crate::Result;
use std::time::Instant;

/// Options of the Dahl fit.
#[derive(Clone, Debug)]
pub struct DahlOptions {
    /// The exponent i (the start when `estimate_i`), ≥ 1; default 1.
    pub i: f64,
    /// Estimate i too (default true).
    pub estimate_i: bool,
    /// Number of grid points that start a search (default 3).
    pub starts: usize,
    /// Levenberg–Marquardt settings.
    pub config: LmConfig,
    /// Sees the search's starts and iterations and may stop it (see [`Search::observer`]).
    pub observer: Observer,
}

impl Default for DahlOptions {
    fn default() -> Self {
        Self {
            i: 1.0,
            estimate_i: true,
            starts: 3,
            config: common::default_config(),
            observer: Observer::none(),
        }
    }
}

/// θ = (σ, F_c, i, f0), the order of [`Dahl::parameters`].
fn model_of(theta: &[f64], orientation: LoopOrientation) -> Result<Dahl> {
    let m = Dahl {
        sigma: theta[0],
        fc: theta[1],
        i: theta[2],
        f0: theta[3],
        orientation,
    };
    m.validate()?;
    Ok(m)
}

/// Fits a Dahl operator to displacement `u` and force `y` (module doc).
pub fn fit(u: &[f64], y: &[f64], options: &DahlOptions) -> Result<OperatorFit<Dahl>> {
    let started = Instant::now();
    let free: Vec<usize> = if options.estimate_i {
        vec![0, 1, 2, 3]
    } else {
        vec![0, 1, 3]
    };
    common::check_record("dahl", u, y, free.len())?;
    Dahl::new(1.0, 1.0, options.i)?;
    let orientation = LoopOrientation::of_loop(u, y);
    let starts = grid_starts(u, y, options.i, orientation, options.starts.max(1))?;
    let inf = f64::INFINITY;
    let search = Search {
        free,
        lower: vec![0.0, 0.0, 1.0, -inf],
        upper: vec![inf, inf, 50.0, inf],
        config: options.config.clone(),
        observer: options.observer.clone(),
    };
    let simulate = |theta: &[f64]| model_of(theta, orientation)?.simulate(u);
    let problem = Simulated {
        y,
        simulate: &simulate,
        n_params: 4,
    };
    let searched = common::best_of(&problem, &starts, &search)?;
    common::report(
        model_of(&searched.best.theta, orientation)?,
        u,
        y,
        &searched,
        started,
    )
}

/// The best grid points of ρ = σ/F_c with (σ, f0) by linear least squares (i = 1).
fn grid_starts(
    u: &[f64],
    y: &[f64],
    i: f64,
    orientation: LoopOrientation,
    keep: usize,
) -> Result<Vec<Vec<f64>>> {
    let (lo, hi) = common::range(u);
    let span = hi - lo;
    let mut travelled = vec![0.0; u.len()];
    for k in 1..u.len() {
        travelled[k] = travelled[k - 1] + (u[k] - u[k - 1]).abs();
    }
    let mut scored = Vec::new();
    for rho in [1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 200.0].map(|f| f / span) {
        let unit = Dahl {
            sigma: 1.0,
            fc: 1.0 / rho,
            i: 1.0,
            f0: 0.0,
            orientation,
        };
        let Ok(p_sigma) = unit.simulate(u) else {
            continue;
        };
        let p_f0: Vec<f64> = travelled.iter().map(|t| (-rho * t).exp()).collect();
        if let Some((k, sse)) = common::linear_fit(&[&p_sigma, &p_f0], y) {
            if k[0] > 0.0 {
                scored.push((sse, vec![k[0], k[0] / rho, i, k[1]]));
            }
        }
    }
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    let starts: Vec<Vec<f64>> = scored.into_iter().take(keep).map(|s| s.1).collect();
    if starts.is_empty() {
        return Err(crate::Error::NotExciting {
            channel: "input".into(),
            reason: "no Dahl start with σ > 0 fits the loop; is it a friction loop?".into(),
        });
    }
    Ok(starts)
}

impl Identify for Dahl {
    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>> {
        fit(
            u,
            y,
            &DahlOptions {
                observer: options.observer.clone(),
                ..DahlOptions::default()
            },
        )
    }
}
