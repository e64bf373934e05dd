//! Fit of the static Bouc–Wen operator ([`BoucWen`]) y = k_x·u + k_w·w,
//! dw = (A − (β·sign(du·w) + γ)|w|ⁿ) du, A = 1, to a measured loop.
//!
//! **Start from the data.** The loop orientation (the sign of the enclosed area,
//! [`LoopOrientation::of_loop`]) fixes the sign of k_w: k_w ≥ 0 for a clockwise loop (the
//! orientation of w itself), ≤ 0 for a counter-clockwise one, and the search keeps it. For a grid of saturation levels
//! w_s = (β + γ)^{-1/n} (2 %…100 % of the input's half range) and ratios γ/β ∈ {−½, 0, ½, 1},
//! the state w is simulated and (k_x, k_w) solved by linear least squares (y is linear in
//! them); the best grid points start a bounded Levenberg–Marquardt search of
//! (k_x, k_w, β, γ, \[n\], w0), forward finite-difference sensitivities.
//!
//! References: Ismail, Ikhouane & Rodellar (2009); Ikhouane & Rodellar (2007), see
//! [`crate::model::operators::bouc_wen`].

use super::differential_fit::{self as common, Search, Simulated};
use super::family::{FamilyOptions, Identify};
use super::OperatorFit;
use crate::model::operators::{BoucWen, HysteresisOperator, InputOde, LoopOrientation};
use crate::numerics::levenberg_marquardt::LmConfig;
use crate::numerics::Observer;
use crate::Result;
use std::time::Instant;

/// Options of the Bouc–Wen fit.
#[derive(Clone, Debug)]
pub struct BoucWenOptions {
    /// The exponent n (the start when `estimate_n`), ≥ 1; default 1.
    pub n: f64,
    /// Estimate n too (default false: n fixed).
    pub estimate_n: bool,
    /// Number of grid points that start a search (default 3).
    pub starts: usize,
    /// Levenberg–Marquardt settings.
    pub config: LmConfig,
    /// Sees the search's starts and iterations and may stop it (see [`Search::observer`]).
    pub observer: Observer,
}

impl Default for BoucWenOptions {
    fn default() -> Self {
        Self {
            n: 1.0,
            estimate_n: false,
            starts: 3,
            config: common::default_config(),
            observer: Observer::none(),
        }
    }
}

/// θ = (k_x, k_w, A, β, γ, n, w0), the order of [`BoucWen::parameters`].
fn model_of(theta: &[f64]) -> Result<BoucWen> {
    let m = BoucWen {
        kx: theta[0],
        kw: theta[1],
        a: theta[2],
        beta: theta[3],
        gamma: theta[4],
        n: theta[5],
        w0: theta[6],
    };
    m.validate()?;
    Ok(m)
}

/// Fits a Bouc–Wen operator to input `u` and output `y` (module doc).
pub fn fit(u: &[f64], y: &[f64], options: &BoucWenOptions) -> Result<OperatorFit<BoucWen>> {
    let started = Instant::now();
    let free: Vec<usize> = if options.estimate_n {
        vec![0, 1, 3, 4, 5, 6]
    } else {
        vec![0, 1, 3, 4, 6]
    };
    common::check_record("bouc-wen", u, y, free.len())?;
    BoucWen::new(1.0, 1.0, 1.0, 0.0, options.n)?;
    // The w loop is clockwise: k_w > 0 for a clockwise loop, < 0 for a counter-clockwise one.
    let sign = -LoopOrientation::of_loop(u, y).sign();
    let starts = grid_starts(u, y, options.n, sign, options.starts.max(1))?;
    let inf = f64::INFINITY;
    let (kw_lo, kw_hi) = if sign > 0.0 { (0.0, inf) } else { (-inf, 0.0) };
    let search = Search {
        free,
        lower: vec![-inf, kw_lo, 0.0, 0.0, -inf, 1.0, -inf],
        upper: vec![inf, kw_hi, inf, inf, inf, 20.0, inf],
        config: options.config.clone(),
        observer: options.observer.clone(),
    };
    let simulate = |theta: &[f64]| model_of(theta)?.simulate(u);
    let problem = Simulated {
        y,
        simulate: &simulate,
        n_params: 7,
    };
    let searched = common::best_of(&problem, &starts, &search)?;
    common::report(model_of(&searched.best.theta)?, u, y, &searched, started)
}

/// The best grid points (module doc) as full parameter vectors.
fn grid_starts(u: &[f64], y: &[f64], n: f64, sign: f64, keep: usize) -> Result<Vec<Vec<f64>>> {
    let (lo, hi) = common::range(u);
    let half = 0.5 * (hi - lo);
    let mut scored = Vec::new();
    for ws in [0.02, 0.05, 0.1, 0.2, 0.5, 1.0].map(|f| f * half) {
        for q in [-0.5, 0.0, 0.5, 1.0] {
            let beta = 1.0 / (ws.powf(n) * (1.0 + q));
            let m = BoucWen::new(0.0, 1.0, beta, q * beta, n)?;
            let Ok(w) = crate::model::operators::differential::states(&m, u) else {
                continue;
            };
            let Some((k, sse)) = common::linear_fit(&[u, &w], y) else {
                continue;
            };
            if k[1] * sign < 0.0 {
                continue;
            }
            scored.push((
                sse,
                vec![k[0], k[1], 1.0, beta, q * beta, n, m.initial_state()],
            ));
        }
    }
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut starts: Vec<Vec<f64>> = scored.into_iter().take(keep).map(|s| s.1).collect();
    if starts.is_empty() {
        // No grid point has the loop's orientation: start from a thin loop of that sign.
        let beta = 1.0 / (0.1 * half).powf(n);
        starts.push(vec![
            0.0,
            sign * 1e-3 * common::range(y).1.abs(),
            1.0,
            beta,
            0.0,
            n,
            0.0,
        ]);
    }
    Ok(starts)
}

impl Identify for BoucWen {
    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>> {
        fit(
            u,
            y,
            &BoucWenOptions {
                observer: options.observer.clone(),
                ..BoucWenOptions::default()
            },
        )
    }
}
