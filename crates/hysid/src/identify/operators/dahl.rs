//! Fit of the Dahl friction operator ([`Dahl`]) dF/dx = σ(1 − (F/F_c)·sign dx)^i to a
//! measured force–displacement loop, by the differential driver
//! ([`differential_fit`](super::differential_fit)).
//!
//! **Orientation.** A clockwise loop (Dahl's own) is fitted as it is; a counter-clockwise one
//! (detected from the sign of the enclosed area, [`LoopOrientation::of_loop`]) with the
//! operator driven by −u ([`LoopOrientation::CounterClockwise`]); the inverse of the fitted
//! operator includes the flip, so it returns an input on the measured scale.
//!
//! **What the family supplies.** With z = F/F_c and ρ = σ/F_c the equation reads
//! dz/dx = ρ·(1 − z·sign dx)^i: the force is F_c times the response z of a unit operator
//! that depends on the shape (ρ, i, z0) alone, so F_c is the linear parameter. The start grid
//! places ρ log-spaced from 0.5 to 500 per input range, i ∈ {1, 1.5, 2.5, 4} when it is
//! estimated (12 × 4 points), and z0 = F\[0\]/max|F| (|F| approaches F_c on a long branch).
//!
//! **What it cannot fit.** Driving the operator by −u mirrors its loop, which turns the
//! sense and the slope together: a Dahl loop turns clockwise where it rises and
//! counter-clockwise where it falls, whatever its parameters (its output is bounded by F_c
//! and has no linear part). A detected loop that rises counter-clockwise (a piezo stack, a
//! magnet's B(H)) or falls clockwise, with a trend that dominates the loop's width
//! (|slope|·half the input's span above the root-mean-square distance from the trend
//! line), is refused at once with [`Error::OutsideFamily`] instead of a search for the
//! best of poor fits (on the 50 001-sample piezo record it ran for minutes to 0.5 %).
//! A given orientation is fitted as asked.
//!
//! References: Dahl (1968, 1976), see [`crate::model::operators::dahl`].

use super::differential_fit::{self as driver, Basis, DifferentialFamily, LoopShape, Settings};
use super::family::{FamilyOptions, FamilySetting, Identify, FAMILY_ARX};
use super::OperatorFit;
use crate::identify::operator_cascade::OperatorCascadeIdentification;
use crate::model::operators::differential::simulate_with_tolerance;
use crate::model::operators::InitialState;
use crate::model::operators::{Dahl, LoopOrientation};
use crate::model::OperatorCascade;
use crate::numerics::levenberg_marquardt::LmConfig;
use crate::numerics::Observer;
use crate::{Error, Result};
use nalgebra::DMatrix;

/// Options of the Dahl fit.
#[derive(Clone, Debug)]
pub struct DahlOptions {
    /// The exponent i (the start when `estimate_i`), ≥ 1; default 1.
    pub i: f64,
    /// Estimate i too (default true).
    pub estimate_i: bool,
    /// Local searches on the decimated record, from the best grid points (default 3).
    pub starts: usize,
    /// Levenberg–Marquardt settings of the full-record refinement.
    pub config: LmConfig,
    /// Sees the fit's grid, starts and iterations and may stop it (see
    /// [`Settings::observer`]).
    pub observer: Observer,
    /// The loop's turning sense in the (u, y) plane; detected from the data when None
    /// ([`LoopOrientation::of_loop`]).
    pub orientation: Option<LoopOrientation>,
    /// The initial state (default: estimated, [`InitialState::Estimate`]; see
    /// [`crate::model::operators::initial_state`]).
    pub initial_state: InitialState,
}

impl Default for DahlOptions {
    fn default() -> Self {
        Self {
            i: 1.0,
            estimate_i: true,
            starts: 3,
            config: driver::default_config(),
            initial_state: InitialState::Estimate,
            observer: Observer::none(),
            orientation: None,
        }
    }
}

/// The Dahl family for the driver: θ = (σ, F_c, i, f0), the order of [`Dahl::parameters`].
struct Family {
    i: f64,
    estimate_i: bool,
    orientation: LoopOrientation,
}

impl DifferentialFamily for Family {
    type Model = Dahl;
    fn name(&self) -> &'static str {
        "dahl"
    }
    fn initial_state_index(&self) -> usize {
        3
    }
    fn model(&self, t: &[f64]) -> Result<Dahl> {
        let m = Dahl {
            sigma: t[0],
            fc: t[1],
            i: t[2],
            f0: t[3],
            orientation: self.orientation,
        };
        m.validate()?;
        Ok(m)
    }
    fn free(&self) -> Vec<usize> {
        if self.estimate_i {
            vec![0, 1, 2, 3]
        } else {
            vec![0, 1, 3]
        }
    }
    fn bounds(&self, shape: &LoopShape) -> (Vec<f64>, Vec<f64>) {
        let inf = f64::INFINITY;
        let y_scale = (shape.y_range.1 - shape.y_range.0).max(f64::MIN_POSITIVE);
        let tiny = 1e-12 * y_scale;
        (
            vec![tiny / shape.half_span(), tiny, 1.0, -inf],
            vec![inf, inf, 50.0, inf],
        )
    }
    /// Points (ρ, i, z0).
    fn shape_grid(&self, _u: &[f64], y: &[f64], shape: &LoopShape) -> Vec<Vec<f64>> {
        let span = 2.0 * shape.half_span();
        let peak = y.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let z0 = (shape.first.1 / peak).clamp(-0.95, 0.95);
        let exponents: &[f64] = if self.estimate_i {
            &[1.0, 1.5, 2.5, 4.0]
        } else {
            std::slice::from_ref(&self.i)
        };
        let mut points = Vec::new();
        for &i in exponents {
            for k in 0..12 {
                points.push(vec![0.5 * 1000f64.powf(k as f64 / 11.0) / span, i, z0]);
            }
        }
        points
    }
    fn basis(&self, p: &[f64], u: &[f64], tolerance: f64) -> Result<Basis> {
        let unit = Dahl {
            sigma: p[0],
            fc: 1.0,
            i: p[1],
            f0: p[2],
            orientation: self.orientation,
        };
        Ok(Basis {
            fixed: None,
            columns: vec![simulate_with_tolerance(&unit, u, tolerance)?],
        })
    }
    fn assemble(&self, p: &[f64], c: &[f64]) -> Option<Vec<f64>> {
        let fc = c[0];
        (fc > 0.0).then(|| vec![p[0] * fc, fc, p[1], p[2] * fc])
    }

    const UNIT_FREE: bool = true;

    /// With x = sᵤx′, F = s_y F′: dF′/dx′ = (σsᵤ/s_y)(1 − (F′/F_c′)·sign)ⁱ, F_c′ = F_c/s_y, so
    /// σ = σ′s_y/sᵤ, F_c = F_c′s_y, f0 = f0′s_y; i is unit-free (the sign flip of a
    /// counter-clockwise loop leaves the magnitudes alone).
    fn in_record_units(&self, t: &[f64], su: f64, sy: f64) -> Option<(Vec<f64>, DMatrix<f64>)> {
        Some(driver::scaled_by(t, &[sy / su, sy, 1.0, sy]))
    }
}

/// Refuses a detected loop that no Dahl operator represents (the module doc): one that
/// rises counter-clockwise or falls clockwise, its trend dominating its width.
fn check_representable(u: &[f64], y: &[f64], orientation: LoopOrientation) -> Result<()> {
    if u.len() != y.len() || u.len() < 2 || !u.iter().chain(y).all(|v| v.is_finite()) {
        // The driver's checks name what is wrong with the record.
        return Ok(());
    }
    let shape = LoopShape::of(u, y);
    let rises = shape.slope > 0.0;
    let dominant = shape.slope.abs() * shape.half_span() > shape.width;
    if !dominant || rises == (orientation == LoopOrientation::Clockwise) {
        return Ok(());
    }
    let (sense, trend) = match orientation {
        LoopOrientation::CounterClockwise => ("counter-clockwise", "rises"),
        LoopOrientation::Clockwise => ("clockwise", "falls"),
    };
    Err(Error::OutsideFamily {
        family: "dahl".into(),
        reason: format!(
            "it turns {sense} and {trend} with the input, and a Dahl loop turns clockwise \
             where it rises and counter-clockwise where it falls; fit bouc-wen, duhem or \
             jiles-atherton, or give --orientation to fit Dahl as asked"
        ),
    })
}

/// Fits a Dahl operator to displacement `u` and force `y` (module doc); a detected loop no
/// Dahl operator represents is refused ([`Error::OutsideFamily`]).
pub fn fit(u: &[f64], y: &[f64], options: &DahlOptions) -> Result<OperatorFit<Dahl>> {
    Dahl::new(1.0, 1.0, options.i)?;
    if options.orientation.is_none() && u.len() == y.len() {
        check_representable(u, y, LoopOrientation::of_loop(u, y))?;
    }
    search(u, y, options)
}

/// The search of [`fit`], for any loop: also the start of an operator cascade, whose loop
/// (u, y) carries the linear block's dynamics and gain, so that its shape says little of
/// the operator's.
fn search(u: &[f64], y: &[f64], options: &DahlOptions) -> Result<OperatorFit<Dahl>> {
    let family = Family {
        i: options.i,
        estimate_i: options.estimate_i,
        orientation: if u.len() == y.len() {
            options
                .orientation
                .unwrap_or_else(|| LoopOrientation::of_loop(u, y))
        } else {
            LoopOrientation::Clockwise
        },
    };
    let settings = Settings {
        starts: options.starts,
        config: options.config.clone(),
        observer: options.observer.clone(),
        initial_state: options.initial_state,
    };
    driver::fit(&family, u, y, &settings)
}

/// The Dahl options of the family options `options`.
fn options_of(options: &FamilyOptions) -> DahlOptions {
    DahlOptions {
        initial_state: options.initial_state,
        observer: options.observer.clone(),
        orientation: options.loop_orientation,
        ..DahlOptions::default()
    }
}

impl Identify for Dahl {
    const SETTINGS: &'static [FamilySetting] = &[FamilySetting::Orientation];

    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>> {
        fit(u, y, &options_of(options))
    }

    /// The family's search on the loop (u, y) (never refused: the loop of a cascade is the
    /// operator's through the linear block), then the ARX fit of the default start.
    fn cascade_start(
        cascade: &OperatorCascadeIdentification,
        u: &[f64],
        y: &[f64],
        options: &FamilyOptions,
    ) -> Result<(OperatorCascade, &'static str)> {
        let start = search(u, y, &options_of(options))?.model.into();
        Ok((cascade.family_arx_start(start, u, y)?, FAMILY_ARX))
    }
}
