//! Fit of the Duhem / Coleman–Hodgdon operator ([`Duhem`])
//! dy = α|du|(a·u + b − y) + c·du to a measured loop, by the differential driver
//! ([`differential_fit`](super::differential_fit)).
//!
//! **What the family supplies.** For fixed α the equation is linear in y and in its forcing,
//! so the output is the combination a·y_a + b·y_b + c·y_c + y0·y_0 of four basis responses
//! (the operator with one of a, b, c, y0 set to 1 and the others to 0): a, b, c and y0 are the
//! linear parameters, α the only shape parameter. The start grid places α log-spaced from
//! 0.3 to 300 per input range (the branches settle within a few 1/α of input).
//!
//! **Orientation** needs no special handling: the sign of c − a is the loop's orientation and
//! the linear solve finds it from the data.
//!
//! Reference: Coleman & Hodgdon (1986), see [`crate::model::operators::duhem`].

use super::differential_fit::{self as driver, Basis, DifferentialFamily, LoopShape, Settings};
use super::family::{FamilyOptions, FamilySetting, Identify};
use super::OperatorFit;
use crate::model::operators::differential::simulate_with_tolerance;
use crate::model::operators::Duhem;
use crate::model::operators::InitialState;
use crate::numerics::levenberg_marquardt::LmConfig;
use crate::numerics::Observer;
use crate::Result;
use nalgebra::DMatrix;

/// Options of the Duhem fit.
#[derive(Clone, Debug)]
pub struct DuhemOptions {
    /// Local searches on the decimated record, from the best grid points (default 3).
    pub starts: usize,
    /// Levenberg–Marquardt settings of the full-record refinement.
    pub config: LmConfig,
    /// Sees the fit's grid, starts and iterations and may stop it (see
    /// [`Settings::observer`]).
    pub observer: Observer,
    /// The initial state (default: estimated, [`InitialState::Estimate`]; see
    /// [`crate::model::operators::initial_state`]).
    pub initial_state: InitialState,
}

impl Default for DuhemOptions {
    fn default() -> Self {
        Self {
            starts: 3,
            config: driver::default_config(),
            initial_state: InitialState::Estimate,
            observer: Observer::none(),
        }
    }
}

/// The Duhem family for the driver: θ = (α, a, b, c, y0), the order of
/// [`Duhem::parameters`].
struct Family;

impl DifferentialFamily for Family {
    type Model = Duhem;
    fn name(&self) -> &'static str {
        "duhem"
    }
    fn initial_state_index(&self) -> usize {
        4
    }
    fn model(&self, t: &[f64]) -> Result<Duhem> {
        let m = Duhem {
            alpha: t[0],
            a: t[1],
            b: t[2],
            c: t[3],
            y0: t[4],
        };
        m.validate()?;
        Ok(m)
    }
    fn free(&self) -> Vec<usize> {
        vec![0, 1, 2, 3, 4]
    }
    fn bounds(&self, shape: &LoopShape) -> (Vec<f64>, Vec<f64>) {
        let inf = f64::INFINITY;
        let alpha_min = 1e-9 / shape.half_span();
        (vec![alpha_min, -inf, -inf, -inf, -inf], vec![inf; 5])
    }
    /// Points (α).
    fn shape_grid(&self, _u: &[f64], _y: &[f64], shape: &LoopShape) -> Vec<Vec<f64>> {
        let span = 2.0 * shape.half_span();
        (0..24)
            .map(|k| vec![0.3 * 1000f64.powf(k as f64 / 23.0) / span])
            .collect()
    }
    fn basis(&self, p: &[f64], u: &[f64], tolerance: f64) -> Result<Basis> {
        let response = |a: f64, b: f64, c: f64, y0: f64| {
            let m = Duhem {
                alpha: p[0],
                a,
                b,
                c,
                y0,
            };
            simulate_with_tolerance(&m, u, tolerance)
        };
        Ok(Basis {
            fixed: None,
            columns: vec![
                response(1.0, 0.0, 0.0, 0.0)?,
                response(0.0, 1.0, 0.0, 0.0)?,
                response(0.0, 0.0, 1.0, 0.0)?,
                response(0.0, 0.0, 0.0, 1.0)?,
            ],
        })
    }
    fn assemble(&self, p: &[f64], c: &[f64]) -> Option<Vec<f64>> {
        Some(vec![p[0], c[0], c[1], c[2], c[3]])
    }

    const UNIT_FREE: bool = true;

    /// With u = sᵤu′, y = s_y y′: dy′ = αsᵤ|du′|((a sᵤ/s_y)u′ + b/s_y − y′) + (c sᵤ/s_y)du′, so
    /// α = α′/sᵤ, a = a′s_y/sᵤ, b = b′s_y, c = c′s_y/sᵤ, y0 = y0′s_y.
    fn in_record_units(&self, t: &[f64], su: f64, sy: f64) -> Option<(Vec<f64>, DMatrix<f64>)> {
        Some(driver::scaled_by(t, &[1.0 / su, sy / su, sy, sy / su, sy]))
    }
}

/// Fits a Duhem operator to input `u` and output `y` (module doc).
pub fn fit(u: &[f64], y: &[f64], options: &DuhemOptions) -> Result<OperatorFit<Duhem>> {
    let settings = Settings {
        starts: options.starts,
        config: options.config.clone(),
        observer: options.observer.clone(),
        initial_state: options.initial_state,
    };
    driver::fit(&Family, u, y, &settings)
}

impl Identify for Duhem {
    const SETTINGS: &'static [FamilySetting] = &[];

    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>> {
        fit(
            u,
            y,
            &DuhemOptions {
                initial_state: options.initial_state,
                observer: options.observer.clone(),
                ..DuhemOptions::default()
            },
        )
    }
}
