//! Identification of generalised Maxwell-slip elements (rate-independent part).
//!
//! F = c + k₀x + Σᵢ kᵢ E_{δᵢ}\[x\] is linear in the stiffnesses once the slip widths δᵢ = Wᵢ/kᵢ
//! are fixed on a grid over the displacement range (default δᵢ = i·(max x − min x)/(2(n+1))):
//! kᵢ ≥ 0 by non-negative least squares on the stop-operator outputs (c free), Wᵢ = kᵢδᵢ, and
//! the standard deviations σ(Wᵢ) = δᵢσ(kᵢ). Elements whose stiffness lands on 0 are absent.
//! The elements' own loop is clockwise (the force leads the displacement), so a detected
//! clockwise loop is fitted directly and a counter-clockwise one in the inverse
//! parameterisation (x = G\[F\], `Orientation::inverse`).
//!
//! References: V. Lampaert, F. Al-Bender, J. Swevers, "A generalized Maxwell-slip friction
//! model appropriate for control purposes", Proc. PhysCon 2003; F. Al-Bender, V. Lampaert,
//! J. Swevers, IEEE Trans. Automatic Control 50 (2005) 1883–1887.

use super::family::{FamilyOptions, FamilySetting, Identify};
use super::linear_support::{
    check_data, core_path, finish, fit_initial_state, orientation, solve_weights, threshold_grid,
    GramAccumulator, Spread,
};
use super::model_size::{choose_thresholds, PlayVariant};
use super::OperatorFit;
use crate::identify::operator_cascade::{OperatorCascadeIdentification, RANK_ONE};
use crate::model::operators::{
    stop, validate_thresholds, InitialStateUsed, MaxwellSlip, Orientation,
};
use crate::model::OperatorCascade;
use crate::{Error, Result};
use std::time::Instant;

/// Options of the Maxwell-slip identification.
#[derive(Clone, Debug, PartialEq)]
pub struct MaxwellSlipOptions {
    /// Number of elements n of the default width grid (10).
    pub elements: usize,
    /// An explicit grid of slip widths δᵢ (strictly increasing, > 0).
    pub widths: Option<Vec<f64>>,
    /// Include a linear spring k₀ (an element that never slips); true by default.
    pub linear_spring: bool,
    /// The orientation; detected from the data when None.
    pub orientation: Option<Orientation>,
    /// The declared initial state the elements start from (None: unstretched, demagnetised).
    pub initial_state: Option<InitialStateUsed>,
}

impl Default for MaxwellSlipOptions {
    fn default() -> Self {
        Self {
            elements: 10,
            widths: None,
            linear_spring: true,
            orientation: None,
            initial_state: None,
        }
    }
}

/// The orientation detected from the data, for the stop operators: their own loop is
/// clockwise (the force leads the displacement), so a detected clockwise loop is the direct
/// form and a counter-clockwise one the inverse.
fn detected_orientation(u: &[f64], y: &[f64]) -> Result<Orientation> {
    let d = orientation(u, y, None)?;
    Ok(Orientation {
        inverse: !d.inverse,
        ..d
    })
}

/// Fits Maxwell-slip elements to displacement `u` and force `y`.
pub fn fit(u: &[f64], y: &[f64], options: &MaxwellSlipOptions) -> Result<OperatorFit<MaxwellSlip>> {
    let start = Instant::now();
    let o = match options.orientation {
        Some(o) => o,
        None => detected_orientation(u, y)?,
    };
    let (x, v) = o.core_data(u, y);
    let widths = match &options.widths {
        Some(w) => w.clone(),
        None => threshold_grid(&x, options.elements)?,
    };
    validate_thresholds("delta", &widths)?;
    check_data(u, y, widths.len() + 2)?;
    let reach = 2.0 * widths.last().copied().unwrap_or(0.0);
    let (path, skip) = core_path(options.initial_state, &x, reach);
    let mut columns = Vec::with_capacity(widths.len() + 2);
    if options.linear_spring {
        columns.push(x.clone());
    }
    columns.extend(widths.iter().map(|&d| stop(&path, d).split_off(skip)));
    columns.push(vec![1.0; x.len()]);
    let (g, b, yy, n) = GramAccumulator::from_columns(&columns, &v);
    let p = columns.len();
    let mut unconstrained = vec![false; p];
    unconstrained[p - 1] = true;
    let sol = solve_weights(&g, &b, yy, n, &unconstrained, None)?;
    let first = usize::from(options.linear_spring);
    let m = widths.len();
    let k0 = if options.linear_spring { sol.x[0] } else { 0.0 };
    let k = sol.x[first..first + m].to_vec();
    let model = MaxwellSlip::new(k0, k, widths.clone(), sol.x[p - 1], o).map_err(|e| {
        Error::NotExciting {
            channel: "u".into(),
            reason: format!("no Maxwell-slip model fits these data ({e})"),
        }
    })?;
    // (k0, k₁…k_m, the break-away forces fᵢ = kᵢ δᵢ, c).
    let map: Vec<Option<(usize, f64)>> = [options.linear_spring.then_some((0, 1.0))]
        .into_iter()
        .chain((0..m).map(|i| Some((first + i, 1.0))))
        .chain((0..m).map(|i| Some((first + i, widths[i]))))
        .chain([Some((p - 1, 1.0))])
        .collect();
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

impl Identify for MaxwellSlip {
    const SETTINGS: &'static [FamilySetting] = &[
        FamilySetting::Thresholds,
        FamilySetting::ThresholdGrid,
        FamilySetting::Orientation,
    ];

    /// With [`FamilyOptions::choose_thresholds`] (and no explicit widths) the element count
    /// and the widths' placement are chosen on a held-out part as for PI
    /// ([`model_size`](super::model_size)).
    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>> {
        // the stops' own loop is clockwise: a given turning sense maps the other way
        let given = match (options.orientation, options.loop_orientation) {
            (Some(o), _) => Some(o),
            (None, Some(l)) => Some(Orientation::for_loop(
                l.reversed(),
                Orientation::trend(u, y)?,
            )),
            (None, None) => None,
        };
        let request = options.initial_state;
        if options.choose_thresholds && options.threshold_grid.is_none() {
            let o = match given {
                Some(o) => o,
                None => detected_orientation(u, y)?,
            };
            return choose_thresholds(
                u,
                y,
                o,
                2,
                &[PlayVariant::PLAIN],
                request,
                |u, y, size, start| {
                    let settings = MaxwellSlipOptions {
                        widths: Some(size.grid.clone()),
                        orientation: Some(o),
                        initial_state: start.state,
                        ..MaxwellSlipOptions::default()
                    };
                    fit(u, y, &settings)
                },
            );
        }
        fit_initial_state(request, u, |start| {
            let settings = MaxwellSlipOptions {
                elements: options.thresholds,
                widths: options.threshold_grid.clone(),
                orientation: given,
                initial_state: start.state,
                ..MaxwellSlipOptions::default()
            };
            fit(u, y, &settings)
        })
    }

    /// The over-parameterised equation error in the basis u, E_{δᵢ}\[u\], 1 with a rank-one
    /// factorisation ([`crate::identify::operator_cascade`]); stiffnesses clipped at 0.
    fn cascade_start(
        cascade: &OperatorCascadeIdentification,
        u: &[f64],
        y: &[f64],
        options: &FamilyOptions,
    ) -> Result<(OperatorCascade, &'static str)> {
        let start = cascade.superposition_start(u, y, options, stop)?;
        let (theta, n) = (&start.theta, start.grid.len());
        let k: Vec<f64> = theta[1..=n].iter().map(|v| v.max(0.0)).collect();
        let op = MaxwellSlip::new(
            theta[0].max(0.0),
            k,
            start.grid,
            theta[n + 1],
            start.orientation,
        )?;
        Ok((cascade.cascade(op.into(), start.a, start.b)?, RANK_ONE))
    }
}
