//! Identification of a Prandtl–Ishlinskii operator by non-negative least squares.
//!
//! y = c + a₀u + Σᵢ aᵢ F_{rᵢ}\[u\] is linear in (a₀, a₁ … aₙ, c) once the thresholds are fixed
//! on a grid over the input range (default rᵢ = i·(max u − min u)/(2(n+1))): each play output
//! is one pass over the data, the (n + 2)² normal equations are accumulated once, and the
//! weights are the NNLS solution (aᵢ ≥ 0 keeps the operator monotone and its analytic inverse
//! valid; c is free). Standard deviations: σ²(ΦᵀΦ)⁻¹ restricted to the free set, σ² = RSS/(N − p);
//! a weight held at 0 has none. The count n can also be chosen by validation
//! ([`PiOptions::select`]).
//!
//! With [`PiOptions::envelope`] the regression also has the d + 1 slope values of a monotone
//! static envelope E(u) on the core input's range (`model::operators::envelope`, a cubic:
//! three columns, each E for a unit slope vector), held ≥ 0 by the same NNLS, for a static
//! curve the plays cannot follow (a saturating magnet). The envelope then takes the place of
//! a₀u: the slope values sum the Bernstein basis to one, so a₀u + E(u) is E with every slope
//! value raised by a₀ (and a constant), and a₀ would be undetermined; a₀ = 0 is fitted.
//!
//! A clockwise loop is fitted in the inverse parameterisation (u = G\[y\], thresholds over the
//! output range) and Γ = G⁻¹ (Kuhnen 2003); the reported weights are then those of G.
//!
//! Reference: K. Kuhnen, "Modeling, identification and compensation of complex hysteretic
//! nonlinearities: a modified Prandtl–Ishlinskii approach", European Journal of Control 9
//! (2003) 407–418.

use super::family::{FamilyOptions, FamilySetting, Identify};
use super::linear_support::{
    check_data, core_path, finish, fit_initial_state, orientation, solve_weights, threshold_grid,
    unscaled, GramAccumulator, Spread,
};
use super::model_size::{choose_thresholds, PlayVariant};
use super::OperatorFit;
use crate::identify::operator_cascade::{
    monotone_weights, OperatorCascadeIdentification, RANK_ONE,
};
use crate::model::operators::{
    envelope, initial_state, play, validate_thresholds, Envelope, InitialStateUsed, Orientation,
    PrandtlIshlinskii,
};
use crate::model::OperatorCascade;
use crate::numerics::metrics;
use crate::{Error, Result};
use std::time::Instant;

/// Options of the PI identification.
#[derive(Clone, Debug, PartialEq)]
pub struct PiOptions {
    /// Number of thresholds n of the default grid (10).
    pub thresholds: usize,
    /// An explicit threshold grid (strictly increasing, > 0) instead of the default one.
    pub grid: Option<Vec<f64>>,
    /// The orientation; detected from the data when None.
    pub orientation: Option<Orientation>,
    /// Candidate counts to choose n from by validation: each is fitted on the first 70 % of the
    /// data and the one with the best fit % on the last 30 % is refitted on all of it.
    pub select: Option<Vec<usize>>,
    /// The declared initial state the plays start from (None: from 0, demagnetised): the
    /// regressors run through its history first (`linear_support::core_path`).
    pub initial_state: Option<InitialStateUsed>,
    /// Fit a cubic static envelope E(u) beside the plays (`model::operators::envelope`).
    pub envelope: bool,
}

impl Default for PiOptions {
    fn default() -> Self {
        Self {
            thresholds: 10,
            grid: None,
            orientation: None,
            select: None,
            initial_state: None,
            envelope: false,
        }
    }
}

/// Fits a PI operator to input `u` and output `y`.
pub fn fit(u: &[f64], y: &[f64], options: &PiOptions) -> Result<OperatorFit<PrandtlIshlinskii>> {
    if let Some(candidates) = &options.select {
        return fit_selected(u, y, options, candidates);
    }
    let start = Instant::now();
    // a given grid is checked before the data are read for the orientation
    if let Some(g) = &options.grid {
        validate_thresholds("r", g)?;
    }
    let o = orientation(u, y, options.orientation)?;
    let (x, v) = o.core_data(u, y);
    let grid = match &options.grid {
        Some(g) => g.clone(),
        None => threshold_grid(&x, options.thresholds)?,
    };
    validate_thresholds("r", &grid)?;
    let shape = match options.envelope {
        true => Envelope::over(&x, envelope::CUBIC),
        false => None,
    };
    let d = shape.as_ref().map_or(0, |e| e.slopes().len());
    // the weights, c and a₀ or the envelope's slope values (which hold a₀)
    check_data(u, y, grid.len() + 1 + d.max(1))?;
    let reach = 2.0 * grid.last().copied().unwrap_or(0.0);
    let (path, skip) = core_path(options.initial_state, &x, reach);
    let mut columns = Vec::with_capacity(grid.len() + 2 + d);
    // a₀'s column, or with an envelope (which holds a₀u) a zero one: a₀ = 0
    columns.push(match shape {
        Some(_) => vec![0.0; x.len()],
        None => x.clone(),
    });
    columns.extend(grid.iter().map(|&r| play(&path, r).split_off(skip)));
    if let Some(e) = &shape {
        columns.extend(e.columns(&x));
    }
    columns.push(vec![1.0; x.len()]);
    let (g, b, yy, n) = GramAccumulator::from_columns(&columns, &v);
    let mut unconstrained = vec![false; columns.len()];
    unconstrained[columns.len() - 1] = true;
    let sol = solve_weights(&g, &b, yy, n, &unconstrained, None)?;
    let m = grid.len();
    let fitted_envelope = shape
        .map(|e| e.with_slopes(sol.x[m + 1..m + 1 + d].iter().map(|c| c.max(0.0)).collect()))
        .transpose()?;
    let model = PrandtlIshlinskii::with_static_envelope(
        sol.x[0],
        sol.x[1..=m].to_vec(),
        grid,
        sol.x[m + 1 + d],
        o,
        fitted_envelope,
    )
    .map_err(|e| Error::NotExciting {
        channel: "u".into(),
        reason: format!("no monotone PI operator fits these data ({e})"),
    })?;
    // (a0, w₁…w_m, r₁…r_m, c[, e₀…e_d, e_lo, e_hi]): the thresholds and the envelope's range
    // are given, not estimated.
    let map = unscaled(
        [(d == 0).then_some(0)]
            .into_iter()
            .chain((1..=m).map(Some))
            .chain(std::iter::repeat_n(None, m))
            .chain([Some(m + 1 + d)])
            .chain((m + 1..m + 1 + d).map(Some))
            .chain(std::iter::repeat_n(None, if d > 0 { 2 } else { 0 })),
    );
    Ok(finish(
        model,
        o,
        options.initial_state,
        u,
        y,
        Spread::of(&sol, &map),
        sol.iterations,
        1,
        sol.converged,
        start,
    ))
}

/// Chooses the number of thresholds by validation on the last 30 % of the data.
fn fit_selected(
    u: &[f64],
    y: &[f64],
    options: &PiOptions,
    candidates: &[usize],
) -> Result<OperatorFit<PrandtlIshlinskii>> {
    let split = u.len() * 7 / 10;
    let mut best: Option<(f64, usize)> = None;
    for &n in candidates {
        let opts = PiOptions {
            thresholds: n,
            select: None,
            grid: None,
            ..options.clone()
        };
        let Ok(f) = fit(&u[..split], &y[..split], &opts) else {
            continue;
        };
        let Ok(sim) = initial_state::simulate(&f.model, f.initial_state, u) else {
            continue;
        };
        let score = metrics::fit_percent(&y[split..], &sim[split..]);
        if best.is_none_or(|(s, _)| score > s) {
            best = Some((score, n));
        }
    }
    let (_, n) = best.ok_or_else(|| {
        Error::invalid_option(
            "threshold_counts",
            "none",
            "no candidate threshold count could be fitted; give counts >= 1".into(),
        )
    })?;
    fit(
        u,
        y,
        &PiOptions {
            thresholds: n,
            select: None,
            grid: None,
            ..options.clone()
        },
    )
}

impl Identify for PrandtlIshlinskii {
    const SETTINGS: &'static [FamilySetting] = &[
        FamilySetting::Thresholds,
        FamilySetting::ThresholdGrid,
        FamilySetting::Orientation,
        FamilySetting::Envelope,
    ];

    /// With [`FamilyOptions::choose_thresholds`] (and no explicit grid) the count and the
    /// placement (uniform or geometric, `linear_support::geometric_thresholds`) and, under
    /// [`EnvelopeChoice::Auto`](super::family::EnvelopeChoice), the static envelope are chosen
    /// on a held-out part ([`model_size`](super::model_size)); otherwise the `thresholds`
    /// uniform grid or the given one, with an envelope only when one is asked for.
    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>> {
        let given = options.given_orientation(u, y)?;
        let request = options.initial_state;
        if options.choose_thresholds && options.threshold_grid.is_none() {
            let o = orientation(u, y, given)?;
            let variants: Vec<PlayVariant> = (options.envelope.variants().iter())
                .map(|&envelope| PlayVariant {
                    envelope,
                    ..PlayVariant::PLAIN
                })
                .collect();
            return choose_thresholds(u, y, o, 2, &variants, request, |u, y, size, start| {
                let settings = PiOptions {
                    grid: Some(size.grid.clone()),
                    orientation: Some(o),
                    initial_state: start.state,
                    envelope: size.variant.envelope,
                    ..PiOptions::default()
                };
                fit(u, y, &settings)
            });
        }
        fit_initial_state(request, u, |start| {
            let settings = PiOptions {
                thresholds: options.thresholds,
                grid: options.threshold_grid.clone(),
                orientation: given,
                select: None,
                initial_state: start.state,
                envelope: options.envelope.fixed(),
            };
            fit(u, y, &settings)
        })
    }

    /// The over-parameterised equation error in the basis u, F_{rᵢ}\[u\], 1 with a rank-one
    /// factorisation ([`crate::identify::operator_cascade`]); weights projected onto the
    /// monotone set.
    fn cascade_start(
        cascade: &OperatorCascadeIdentification,
        u: &[f64],
        y: &[f64],
        options: &FamilyOptions,
    ) -> Result<(OperatorCascade, &'static str)> {
        let start = cascade.superposition_start(u, y, options, play)?;
        let (theta, n) = (&start.theta, start.grid.len());
        let (a0, weights) = monotone_weights(theta[0], &theta[1..=n]);
        let op = PrandtlIshlinskii::new(a0, weights, start.grid, theta[n + 1], start.orientation)?;
        Ok((cascade.cascade(op.into(), start.a, start.b)?, RANK_ONE))
    }
}
