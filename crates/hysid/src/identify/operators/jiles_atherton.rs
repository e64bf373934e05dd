//! Fit of the Jiles–Atherton operator ([`JilesAtherton`]) to a measured B(H) or M(H) loop.
//!
//! **Start from the data** (after converting B to M = B/μ₀ − H):
//! * Mₛ from the saturation: a multiple ρ ∈ {1.05, 1.5, 3} of the largest |M| measured;
//! * a from the anhysteretic's reach at the loop tip: L(H_max/a) = M_max/Mₛ;
//! * k from the coercivity H_c, the mean |H| where M changes sign (k ≈ H_c; Jiles, Thoelke &
//!   Devine 1992);
//! * c ∈ {0.2, 0.7}, α = 0.05·a/Mₛ (a weak coupling), m0 = the first measured M.
//!
//! The six starts each begin a bounded Levenberg–Marquardt search of (Mₛ, a, k, c, α, m0) with
//! the physical bounds Mₛ, a, k > 0, 0 ≤ c < 1, α ≥ 0, forward finite-difference
//! sensitivities of the H-integration; the lowest criterion wins and its termination is
//! reported as it is (a search that stopped at the iteration limit says so).
//!
//! **Orientation.** B(H) loops are counter-clockwise; a clockwise loop (negative enclosed area)
//! is fitted with the operator driven by −u (the mirrored loop).
//!
//! References: Jiles & Atherton (1986); Jiles, Thoelke & Devine (1992), see
//! [`crate::model::operators::jiles_atherton`].

use super::differential_fit::{self as common, Search, Simulated};
use super::family::{FamilyOptions, Identify};
use super::OperatorFit;
use crate::model::operators::jiles_atherton::{langevin, MU0};
use crate::model::operators::{
    Anhysteretic, HysteresisOperator, JaOutput, JilesAtherton, LoopOrientation,
};
use crate::numerics::levenberg_marquardt::LmConfig;
use crate::numerics::Observer;
use crate::Result;
use std::time::Instant;

/// Options of the Jiles–Atherton fit.
#[derive(Clone, Debug)]
pub struct JilesAthertonOptions {
    /// The anhysteretic curve (default Langevin).
    pub anhysteretic: Anhysteretic,
    /// What the measured output is (default B in T, with H in A/m).
    pub output: JaOutput,
    /// Levenberg–Marquardt settings.
    pub config: LmConfig,
    /// Sees the search's starts and iterations and may stop it (see [`Search::observer`]).
    pub observer: Observer,
}

impl Default for JilesAthertonOptions {
    fn default() -> Self {
        Self {
            anhysteretic: Anhysteretic::Langevin,
            output: JaOutput::FluxDensity,
            config: common::default_config(),
            observer: Observer::none(),
        }
    }
}

/// The structure that is not estimated.
#[derive(Clone, Copy)]
struct Structure {
    anhysteretic: Anhysteretic,
    output: JaOutput,
    orientation: LoopOrientation,
}

/// θ = (Mₛ, a, k, c, α, m0), the order of [`JilesAtherton::parameters`].
fn model_of(theta: &[f64], s: Structure) -> Result<JilesAtherton> {
    let m = JilesAtherton {
        ms: theta[0],
        a: theta[1],
        k: theta[2],
        c: theta[3],
        alpha: theta[4],
        m0: theta[5],
        anhysteretic: s.anhysteretic,
        output: s.output,
        orientation: s.orientation,
    };
    m.validate()?;
    Ok(m)
}

/// Fits a Jiles–Atherton operator to the field `u` (A/m) and B (T) or M (A/m) `y`.
pub fn fit(
    u: &[f64],
    y: &[f64],
    options: &JilesAthertonOptions,
) -> Result<OperatorFit<JilesAtherton>> {
    let started = Instant::now();
    common::check_record("jiles-atherton", u, y, 6)?;
    let structure = Structure {
        anhysteretic: options.anhysteretic,
        output: options.output,
        orientation: LoopOrientation::of_loop(u, y),
    };
    let starts = data_starts(u, y, structure);
    let inf = f64::INFINITY;
    let tiny = |v: f64| 1e-9 * v;
    let s0 = &starts[0];
    let search = Search {
        free: vec![0, 1, 2, 3, 4, 5],
        lower: vec![tiny(s0[0]), tiny(s0[1]), tiny(s0[2]), 0.0, 0.0, -inf],
        upper: vec![inf, inf, inf, 1.0 - 1e-9, inf, inf],
        config: options.config.clone(),
        observer: options.observer.clone(),
    };
    let simulate = |theta: &[f64]| model_of(theta, structure)?.simulate(u);
    let problem = Simulated {
        y,
        simulate: &simulate,
        n_params: 6,
    };
    let searched = common::best_of(&problem, &starts, &search)?;
    common::report(
        model_of(&searched.best.theta, structure)?,
        u,
        y,
        &searched,
        started,
    )
}

/// The data-driven starts of the module doc.
fn data_starts(u: &[f64], y: &[f64], s: Structure) -> Vec<Vec<f64>> {
    let sign = s.orientation.sign();
    let h: Vec<f64> = u.iter().map(|v| sign * v).collect();
    let m: Vec<f64> = match s.output {
        JaOutput::Magnetisation => y.to_vec(),
        JaOutput::FluxDensity => y.iter().zip(&h).map(|(b, h)| b / MU0 - h).collect(),
    };
    let m_max = m
        .iter()
        .fold(0.0f64, |a, v| a.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    let h_max = h
        .iter()
        .fold(0.0f64, |a, v| a.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    let mut crossings = Vec::new();
    for k in 1..m.len() {
        if m[k - 1] * m[k] < 0.0 {
            let t = m[k - 1] / (m[k - 1] - m[k]);
            crossings.push((h[k - 1] + t * (h[k] - h[k - 1])).abs());
        }
    }
    let hc = if crossings.is_empty() {
        0.1 * h_max
    } else {
        crossings.iter().sum::<f64>() / crossings.len() as f64
    };
    let k0 = hc.max(1e-3 * h_max);
    let mut starts = Vec::new();
    for rho in [1.05, 1.5, 3.0] {
        let ms = rho * m_max;
        let a = h_max / inverse_langevin(1.0 / rho);
        for c in [0.2, 0.7] {
            starts.push(vec![ms, a, k0, c, 0.05 * a / ms, m[0]]);
        }
    }
    starts
}

/// x with L(x) = t for 0 < t < 1 (bisection; L is increasing).
fn inverse_langevin(t: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1e6);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if langevin(mid).0 < t {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

impl Identify for JilesAtherton {
    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>> {
        fit(
            u,
            y,
            &JilesAthertonOptions {
                observer: options.observer.clone(),
                ..JilesAthertonOptions::default()
            },
        )
    }
}
