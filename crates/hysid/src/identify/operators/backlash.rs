//! Identification of backlash y = c + g·F_r\[u\] from data alone.
//!
//! For a fixed half-width r the model is linear in (g, c), so the criterion is profiled over
//! r on a grid rₖ = k·(max u − min u)/(2P), k = 0 … P − 1, with the closed-form least-squares
//! (g, c) at each; the best point starts a Levenberg–Marquardt polish of (g, r, c) with the
//! exact Jacobian \[F_r[u\], g·∂F_r/∂r, 1], where ∂zₖ/∂r = −1 while the play is dragged up
//! (zₖ = uₖ − r), +1 while dragged down (zₖ = uₖ + r) and ∂zₖ₋₁/∂r while it holds. Standard
//! deviations σ²(JᵀJ)⁻¹ at the optimum. A clockwise loop is fitted as u = c + g·F_r\[y\]
//! (Γ = G⁻¹, the right inverse).
//!
//! Reference: M. A. Krasnosel'skii, A. V. Pokrovskii, *Systems with Hysteresis*, Springer 1989.

use super::family::{FamilyOptions, FamilySetting, Identify};
use super::linear_support::{
    check_data, core_path, finish, fit_initial_state, orientation, range, unscaled, Spread,
};
use super::OperatorFit;
use crate::identify::operator_cascade::{
    oriented, OperatorCascadeIdentification, RankOne, RANK_ONE,
};
use crate::model::operators::{play, play_step, Backlash, InitialStateUsed, Orientation};
use crate::model::OperatorCascade;
use crate::{Error, Result};
use nalgebra::{DMatrix, Matrix3, Vector3};
use std::time::Instant;

/// Options of the backlash identification.
#[derive(Clone, Debug, PartialEq)]
pub struct BacklashOptions {
    /// Points of the profile over r (60).
    pub profile_points: usize,
    /// Maximum Levenberg–Marquardt iterations (100).
    pub max_iterations: usize,
    /// The orientation; detected from the data when None.
    pub orientation: Option<Orientation>,
    /// The declared initial state the play starts from (None: from 0, demagnetised).
    pub initial_state: Option<InitialStateUsed>,
}

impl Default for BacklashOptions {
    fn default() -> Self {
        Self {
            profile_points: 60,
            max_iterations: 100,
            orientation: None,
            initial_state: None,
        }
    }
}

/// The play output and its derivative with respect to r over the record `x`, the play first
/// run through the declared `history` (empty: from 0).
fn play_with_sensitivity(history: &[f64], x: &[f64], r: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut z, mut s) = (0.0, 0.0);
    let mut out = (Vec::with_capacity(x.len()), Vec::with_capacity(x.len()));
    for (k, &xk) in history.iter().chain(x).enumerate() {
        let next = play_step(z, xk, r);
        if next == xk - r && next != z {
            s = -1.0;
        } else if next == xk + r && next != z {
            s = 1.0;
        } else if next != z {
            s = 0.0;
        }
        z = next;
        if k >= history.len() {
            out.0.push(z);
            out.1.push(s);
        }
    }
    out
}

/// Closed-form (g, c, rss) of v ≈ g·z + c.
fn gain_offset(z: &[f64], v: &[f64]) -> (f64, f64, f64) {
    let n = z.len() as f64;
    let (mz, mv) = (z.iter().sum::<f64>() / n, v.iter().sum::<f64>() / n);
    let szz: f64 = z.iter().map(|a| (a - mz).powi(2)).sum();
    let szv: f64 = z.iter().zip(v).map(|(a, b)| (a - mz) * (b - mv)).sum();
    let g = if szz > 0.0 { szv / szz } else { 0.0 };
    let c = mv - g * mz;
    let rss = z.iter().zip(v).map(|(a, b)| (b - g * a - c).powi(2)).sum();
    (g, c, rss)
}

fn rss_at(history: &[f64], x: &[f64], v: &[f64], theta: &Vector3<f64>) -> f64 {
    let mut z = history
        .iter()
        .fold(0.0, |z, &xk| play_step(z, xk, theta[1]));
    x.iter()
        .zip(v)
        .map(|(&xk, &vk)| {
            z = play_step(z, xk, theta[1]);
            (vk - theta[0] * z - theta[2]).powi(2)
        })
        .sum()
}

/// Fits backlash to input `u` and output `y`.
pub fn fit(u: &[f64], y: &[f64], options: &BacklashOptions) -> Result<OperatorFit<Backlash>> {
    let start = Instant::now();
    check_data(u, y, 3)?;
    if options.profile_points < 2 {
        return Err(Error::invalid_option(
            "profile_points",
            options.profile_points,
            "backlash: give at least 2 profile points".into(),
        ));
    }
    let o = orientation(u, y, options.orientation)?;
    let (x, v) = o.core_data(u, y);
    let (lo, hi) = range(&x);
    // a play of half-width r ≤ (hi − lo)/2 is wiped by the history's excursion of 2 (hi − lo)
    let (path, skip) = core_path(options.initial_state, &x, 0.0);
    let history = &path[..skip];
    let step = (hi - lo) / (2.0 * options.profile_points as f64);
    let mut evaluations = 0;
    let mut best = (f64::INFINITY, Vector3::zeros());
    for k in 0..options.profile_points {
        let r = k as f64 * step;
        let (z, _) = play_with_sensitivity(history, &x, r);
        let (g, c, rss) = gain_offset(&z, &v);
        evaluations += 1;
        if g > 0.0 && rss < best.0 {
            best = (rss, Vector3::new(g, r, c));
        }
    }
    if !best.0.is_finite() {
        return Err(Error::NotExciting {
            channel: "u".into(),
            reason: "no positive backlash gain fits these data; check the columns".into(),
        });
    }
    let (theta, jtj, iterations, evals, converged) =
        polish(history, &x, &v, best, options.max_iterations);
    evaluations += evals;
    let n = x.len();
    let rss = rss_at(history, &x, &v, &theta);
    let sigma2 = rss / (n.saturating_sub(3).max(1)) as f64;
    let spread = match jtj.try_inverse() {
        Some(inv) => {
            let c = DMatrix::from_fn(3, 3, |i, j| sigma2 * inv[(i, j)]);
            let std: Vec<Option<f64>> = (0..3).map(|i| Some(c[(i, i)].max(0.0).sqrt())).collect();
            Spread::mapped(&std, &c, &unscaled((0..3).map(Some)))
        }
        None => Spread {
            std: vec![None; 3],
            covariance: vec![vec![0.0; 3]; 3],
        },
    };
    let model = Backlash::new(theta[0], theta[1].max(0.0), theta[2], o)?;
    Ok(finish(
        model,
        o,
        options.initial_state,
        u,
        y,
        spread,
        iterations,
        evaluations,
        converged,
        start,
    ))
}

/// Levenberg–Marquardt on (g, r, c) from the profile's best point.
fn polish(
    history: &[f64],
    x: &[f64],
    v: &[f64],
    start: (f64, Vector3<f64>),
    max_iterations: usize,
) -> (Vector3<f64>, Matrix3<f64>, usize, usize, bool) {
    let (mut rss, mut theta) = start;
    let mut mu = 1e-3;
    let mut evaluations = 0;
    let scale: f64 = v.iter().map(|a| a * a).sum::<f64>().max(f64::MIN_POSITIVE);
    for it in 0..max_iterations {
        let (z, s) = play_with_sensitivity(history, x, theta[1]);
        let (mut jtj, mut jte) = (Matrix3::zeros(), Vector3::zeros());
        for k in 0..x.len() {
            let j = Vector3::new(z[k], theta[0] * s[k], 1.0);
            let e = v[k] - theta[0] * z[k] - theta[2];
            jtj += j * j.transpose();
            jte += j * e;
        }
        if rss <= 1e-28 * scale {
            return (theta, jtj, it, evaluations, true);
        }
        let mut accepted = false;
        for _ in 0..30 {
            let mut a = jtj;
            for i in 0..3 {
                a[(i, i)] += mu * jtj[(i, i)].max(1e-300);
            }
            let Some(delta) = a.lu().solve(&jte) else {
                mu *= 10.0;
                continue;
            };
            let mut next = theta + delta;
            next[1] = next[1].max(0.0);
            let r_next = rss_at(history, x, v, &next);
            evaluations += 1;
            if r_next < rss {
                let small = (next - theta).norm() <= 1e-13 * (1.0 + theta.norm());
                let flat = rss - r_next <= 1e-15 * rss;
                theta = next;
                rss = r_next;
                mu = (mu / 10.0).max(1e-12);
                accepted = true;
                if small || flat {
                    let (z, s) = play_with_sensitivity(history, x, theta[1]);
                    let jtj = jacobian_gram(&z, &s, theta[0]);
                    return (theta, jtj, it + 1, evaluations, true);
                }
                break;
            }
            mu *= 10.0;
        }
        if !accepted {
            // no step decreases the criterion: a (local) minimum to working precision
            return (theta, jtj, it + 1, evaluations, true);
        }
    }
    let (z, s) = play_with_sensitivity(history, x, theta[1]);
    (
        theta,
        jacobian_gram(&z, &s, theta[0]),
        max_iterations,
        evaluations,
        false,
    )
}

fn jacobian_gram(z: &[f64], s: &[f64], g: f64) -> Matrix3<f64> {
    let mut jtj = Matrix3::zeros();
    for k in 0..z.len() {
        let j = Vector3::new(z[k], g * s[k], 1.0);
        jtj += j * j.transpose();
    }
    jtj
}

impl Identify for Backlash {
    const SETTINGS: &'static [FamilySetting] = &[FamilySetting::Orientation];

    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>> {
        let request = options.initial_state;
        let given = options.given_orientation(u, y)?;
        fit_initial_state(request, u, |start| {
            let settings = BacklashOptions {
                orientation: given,
                initial_state: start.state,
                ..BacklashOptions::default()
            };
            fit(u, y, &settings)
        })
    }

    /// A profile over the half-width r = k·(max u − min u)/(2P), k = 0 … P − 1 (P the default
    /// profile points): at each r the equation error in the basis F_r\[u\], 1 with a rank-one
    /// factorisation, keeping the r of least equation error.
    fn cascade_start(
        cascade: &OperatorCascadeIdentification,
        u: &[f64],
        y: &[f64],
        _options: &FamilyOptions,
    ) -> Result<(OperatorCascade, &'static str)> {
        let points = BacklashOptions::default().profile_points;
        let (lo, hi) = range(u);
        let step = (hi - lo) / (2.0 * points as f64);
        let ones = vec![1.0; u.len()];
        let mut best: Option<(f64, RankOne)> = None;
        for i in 0..points {
            let r = i as f64 * step;
            let Ok(fit) = cascade.rank_one(y, &[play(u, r), ones.clone()]) else {
                continue;
            };
            if best.as_ref().is_none_or(|(_, b)| fit.sse < b.sse) {
                best = Some((r, fit));
            }
        }
        let (r, RankOne { a, b, theta, .. }) = best.ok_or_else(|| Error::NotExciting {
            channel: "u".into(),
            reason: "no backlash width gives a regular cascade regression; check the columns"
                .into(),
        })?;
        let (theta, o) = oriented(theta, |t| t[0]);
        let g = theta[0].max(f64::MIN_POSITIVE.sqrt());
        let op = Backlash::new(g, r, theta[1], o)?;
        Ok((cascade.cascade(op.into(), a, b)?, RANK_ONE))
    }
}
