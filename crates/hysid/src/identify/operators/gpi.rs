//! Identification of Kuhnen's modified Prandtl–Ishlinskii operator G = S∘H.
//!
//! Following Kuhnen (2003) the fit is done in the *equation error* S⁻¹\[y\] = H\[u\], which is
//! linear in the weights: with S⁻¹(v) = v + Σⱼ d'ⱼ·S_{z'ⱼ}(v) (one-sided dead zones
//! S_z(v) = max(v − z, 0) for z > 0, min(v − z, 0) for z < 0; d'₀ = 1 fixes the common scale of
//! H and S⁻¹),
//!
//! v = c + a₀u + Σᵢ aᵢ F_{rᵢ}\[u\] − Σⱼ d'ⱼ S_{z'ⱼ}(v),
//!
//! solved by NNLS with aᵢ ≥ 0 and the d'ⱼ free; if the free d' make S⁻¹ non-monotone, the fit
//! is repeated with d'ⱼ ≥ 0 (a convex S⁻¹, always invertible). S is then the analytic inverse
//! of S⁻¹. The dead-zone thresholds lie in the output range: by default z'ⱼ = j·max v/(m+1)
//! above 0 and j·min v/(m+1) below, m per side. The criterion is the equation error, not the
//! output error; the reported fit % is that of the simulated output. Standard deviations are
//! given for H's weights; those of S's weights (a non-linear function of d') are not
//! propagated (None).
//!
//! Reference: K. Kuhnen, "Modeling, identification and compensation of complex hysteretic
//! nonlinearities: a modified Prandtl–Ishlinskii approach", European Journal of Control 9
//! (2003) 407–418.

use super::family::DEAD_ZONE_CANDIDATES;
use super::family::{FamilyOptions, FamilySetting, Identify};
use super::linear_support::{
    check_data, core_path, finish, fit_initial_state, orientation, range, solve_weights,
    threshold_grid, unscaled, GramAccumulator, Spread,
};
use super::model_size::{choose_thresholds, PlayVariant};
use super::OperatorFit;
use crate::model::operators::{
    play, validate_thresholds, DeadZones, GeneralizedPi, InitialStateUsed, Orientation,
    PrandtlIshlinskii,
};
use crate::{Error, Result};
use std::time::Instant;

/// Options of the modified-PI identification.
#[derive(Clone, Debug, PartialEq)]
pub struct GpiOptions {
    /// Number of play thresholds n of the default grid (10).
    pub thresholds: usize,
    /// An explicit play threshold grid.
    pub grid: Option<Vec<f64>>,
    /// Dead zones per side m of the default dead-zone grid (4).
    pub dead_zones: usize,
    /// Explicit dead-zone thresholds of S⁻¹: (upper, increasing > 0; lower, decreasing < 0).
    pub dead_zone_grid: Option<(Vec<f64>, Vec<f64>)>,
    /// The placement of the default dead-zone grid (uniform).
    pub dead_zone_placement: ZonePlacement,
    /// The orientation; detected from the data when None.
    pub orientation: Option<Orientation>,
    /// The declared initial state the plays start from (None: from 0, demagnetised).
    pub initial_state: Option<InitialStateUsed>,
}

impl Default for GpiOptions {
    fn default() -> Self {
        Self {
            thresholds: 10,
            grid: None,
            dead_zones: 4,
            dead_zone_grid: None,
            dead_zone_placement: ZonePlacement::Uniform,
            orientation: None,
            initial_state: None,
        }
    }
}

/// One-sided dead zone S_z(v).
fn dead_zone(v: &[f64], z: f64) -> Vec<f64> {
    v.iter()
        .map(|&x| {
            if z > 0.0 {
                (x - z).max(0.0)
            } else {
                (x - z).min(0.0)
            }
        })
        .collect()
}

/// Where the default dead zones of S⁻¹ lie in the output range [lo, hi], m per side.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ZonePlacement {
    /// Equally spaced: z⁺ⱼ = j·hi/(m + 1) above 0, z⁻ⱼ = j·lo/(m + 1) below (Kuhnen 2003).
    #[default]
    Uniform,
    /// Where the data are (MODELS.md §4.8): z⁺ⱼ the j/(m + 1) quantile of the positive
    /// outputs, z⁻ⱼ that of the negative ones. A saturating record (a magnet's field) crowds
    /// its outputs where the static curve bends, and there S needs its pieces; uniform
    /// zones spend them on a few samples near 0.
    Quantile,
}

/// The default dead-zone thresholds inside the output range ([`ZonePlacement`]), m per
/// side (fewer where quantiles coincide).
fn dead_zone_grid(v: &[f64], m: usize, placement: ZonePlacement) -> (Vec<f64>, Vec<f64>) {
    let (lo, hi) = range(v);
    let side = |end: f64| -> Vec<f64> {
        let mut zones: Vec<f64> = match placement {
            ZonePlacement::Uniform => (1..=m).map(|j| j as f64 * end / (m + 1) as f64).collect(),
            ZonePlacement::Quantile => {
                let mut beyond: Vec<f64> = v.iter().copied().filter(|&x| x * end > 0.0).collect();
                beyond.sort_by(|a, b| a.abs().total_cmp(&b.abs()));
                match beyond.len() {
                    0 => Vec::new(),
                    n => (1..=m).map(|j| beyond[j * (n - 1) / (m + 1)]).collect(),
                }
            }
        };
        zones.retain(|&z| z > lo && z < hi);
        zones.dedup();
        zones
    };
    (
        if hi > 0.0 { side(hi) } else { Vec::new() },
        if lo < 0.0 { side(lo) } else { Vec::new() },
    )
}

/// Fits a modified PI operator to input `u` and output `y`.
pub fn fit(u: &[f64], y: &[f64], options: &GpiOptions) -> Result<OperatorFit<GeneralizedPi>> {
    let start = Instant::now();
    let o = orientation(u, y, options.orientation)?;
    let (x, v) = o.core_data(u, y);
    let grid = match &options.grid {
        Some(g) => g.clone(),
        None => threshold_grid(&x, options.thresholds)?,
    };
    validate_thresholds("r", &grid)?;
    let (upper, lower) = match &options.dead_zone_grid {
        Some(g) => g.clone(),
        None => dead_zone_grid(&v, options.dead_zones, options.dead_zone_placement),
    };
    validate_thresholds("zp", &upper)?;
    let neg: Vec<f64> = lower.iter().map(|z| -z).collect();
    validate_thresholds("zn", &neg)?;
    let m = grid.len();
    let nz = upper.len() + lower.len();
    check_data(u, y, m + 2 + nz)?;
    let reach = 2.0 * grid.last().copied().unwrap_or(0.0);
    let (path, skip) = core_path(options.initial_state, &x, reach);
    let mut columns = Vec::with_capacity(m + 2 + nz);
    columns.push(x.clone());
    columns.extend(grid.iter().map(|&r| play(&path, r).split_off(skip)));
    columns.push(vec![1.0; x.len()]);
    columns.extend(upper.iter().chain(&lower).map(|&z| dead_zone(&v, z)));
    // the dead-zone columns enter as −S_z(v), so that their coefficients are d'
    for col in &mut columns[m + 2..] {
        col.iter_mut().for_each(|c| *c = -*c);
    }
    let (g, b, yy, n) = GramAccumulator::from_columns(&columns, &v);
    let p = columns.len();
    let mut fitted = None;
    let mut total_iterations = 0;
    for free_dead_zones in [true, false] {
        let (g2, b2) = (&g, &b);
        let unconstrained: Vec<bool> = (0..p)
            .map(|k| k == m + 1 || (free_dead_zones && k > m + 1))
            .collect();
        let sol = solve_weights(g2, b2, yy, n, &unconstrained, None)?;
        total_iterations += sol.iterations;
        let d: Vec<f64> = sol.x[m + 2..].to_vec();
        let pairs = |zs: &[f64], ds: &[f64]| {
            zs.iter()
                .copied()
                .zip(ds.iter().copied())
                .collect::<Vec<_>>()
        };
        let inverse_s = DeadZones::new(
            1.0,
            pairs(&upper, &d[..upper.len()]),
            pairs(&lower, &d[upper.len()..]),
        );
        if let Ok(s_inv) = inverse_s {
            fitted = Some((sol, s_inv));
            break;
        }
    }
    let (sol, s_inv) = fitted.ok_or_else(|| Error::NotExciting {
        channel: "y".into(),
        reason: "no monotone dead-zone map fits these data".into(),
    })?;
    let h = PrandtlIshlinskii::new(
        sol.x[0],
        sol.x[1..=m].to_vec(),
        grid,
        sol.x[m + 1],
        Orientation::default(),
    )
    .map_err(|e| Error::NotExciting {
        channel: "u".into(),
        reason: format!("no monotone modified PI operator fits these data ({e})"),
    })?;
    let model = GeneralizedPi::new(h, s_inv.inverse(), o);
    // (a0, w, r, c, then the dead-zone map's 1 + 2 nz, which the weights' covariance
    // does not cover).
    let map = unscaled(
        (0..=m)
            .map(Some)
            .chain(std::iter::repeat_n(None, m))
            .chain([Some(m + 1)])
            .chain(std::iter::repeat_n(None, 1 + 2 * nz)),
    );
    Ok(finish(
        model,
        o,
        options.initial_state,
        u,
        y,
        Spread::of(&sol, &map),
        total_iterations,
        2,
        sol.converged,
        start,
    ))
}

impl Identify for GeneralizedPi {
    const SETTINGS: &'static [FamilySetting] = &[
        FamilySetting::Thresholds,
        FamilySetting::ThresholdGrid,
        FamilySetting::DeadZones,
        FamilySetting::Orientation,
    ];

    /// With [`FamilyOptions::choose_thresholds`] (and no explicit grid) the threshold count
    /// and placement are chosen on a held-out part as for PI
    /// ([`model_size`](super::model_size)), and with [`FamilyOptions::choose_dead_zones`]
    /// the dead zones per side of S among [`DEAD_ZONE_CANDIDATES`], uniform and at the
    /// outputs' quantiles ([`ZonePlacement`]), with them (the static map of a saturating
    /// record needs more of them, where its outputs crowd).
    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>> {
        let given = options.given_orientation(u, y)?;
        let request = options.initial_state;
        if options.choose_thresholds && options.threshold_grid.is_none() {
            let o = orientation(u, y, given)?;
            // the dead-zone counts tried with the plays, or the one given (in `extra`)
            let (extra, variants) = if options.choose_dead_zones {
                let variants = [ZonePlacement::Uniform, ZonePlacement::Quantile]
                    .iter()
                    .flat_map(|&placement| {
                        DEAD_ZONE_CANDIDATES.map(|m| PlayVariant {
                            dead_zones: Some((m, placement)),
                            ..PlayVariant::PLAIN
                        })
                    })
                    .collect();
                (2, variants)
            } else {
                (2 + 2 * options.dead_zones, vec![PlayVariant::PLAIN])
            };
            return choose_thresholds(u, y, o, extra, &variants, request, |u, y, size, start| {
                let (dead_zones, dead_zone_placement) = size
                    .variant
                    .dead_zones
                    .unwrap_or((options.dead_zones, ZonePlacement::Uniform));
                let settings = GpiOptions {
                    grid: Some(size.grid.clone()),
                    dead_zones,
                    dead_zone_placement,
                    orientation: Some(o),
                    initial_state: start.state,
                    ..GpiOptions::default()
                };
                fit(u, y, &settings)
            });
        }
        fit_initial_state(request, u, |start| {
            let settings = GpiOptions {
                thresholds: options.thresholds,
                grid: options.threshold_grid.clone(),
                dead_zones: options.dead_zones,
                orientation: given,
                initial_state: start.state,
                ..GpiOptions::default()
            };
            fit(u, y, &settings)
        })
    }
}
