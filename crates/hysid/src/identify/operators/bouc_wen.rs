//! Fit of the static Bouc–Wen operator ([`BoucWen`]) y = k_x·u + k_w·w,
//! dw = (A − (β·sign(du·w) + γ)|w|ⁿ) du, A = 1, to a measured loop, by the differential
//! driver ([`differential_fit`](super::differential_fit)).
//!
//! **What the family supplies.**
//! * *Linear parameters* k_x, k_w: for fixed (β, γ, n, w0) the output is the combination
//!   k_x·u + k_w·w of the input and the state.
//! * *Orientation*: the loop's (the sign of the enclosed area, [`LoopOrientation::of_loop`])
//!   fixes the sign of k_w — k_w ≥ 0 for a clockwise loop (the orientation of w itself), ≤ 0
//!   for a counter-clockwise one — and the search keeps it.
//! * *Search coordinates* (k_x, k_w, A, s, d, n, w0) with s = β + γ and d = β − γ: the bounded
//!   classes β > 0, −β < γ ≤ β are the box s > 0, d ≥ 0, where the engine's projection keeps
//!   every trial point simulable (in (β, γ) the constraint γ ≤ β is not a box, and trials past it
//!   fail).
//! * *Start grid* over the shape: 12 saturation levels w_s = (β + γ)^{−1/n} from 1 % to 4 times
//!   the input's half range (log-spaced) times the ratios γ/β ∈ {−0.9, −0.5, 0, 0.5, 0.9, 1}
//!   (and n ∈ {1, 1.5, 2, 3} when n is estimated).
//!
//! References: Ismail, Ikhouane & Rodellar (2009); Ikhouane & Rodellar (2007), see
//! [`crate::model::operators::bouc_wen`].

use super::differential_fit::{self as driver, Basis, DifferentialFamily, LoopShape, Settings};
use super::family::{FamilyOptions, FamilySetting, Identify};
use super::OperatorFit;
use crate::model::operators::differential::states_with_tolerance;
use crate::model::operators::InitialState;
use crate::model::operators::{BoucWen, LoopOrientation};
use crate::numerics::levenberg_marquardt::LmConfig;
use crate::numerics::Observer;
use crate::Result;
use nalgebra::DMatrix;

/// Options of the Bouc–Wen fit.
#[derive(Clone, Debug)]
pub struct BoucWenOptions {
    /// The exponent n (the start when `estimate_n`), ≥ 1; default 1.
    pub n: f64,
    /// Estimate n too (default false: n fixed).
    pub estimate_n: bool,
    /// Local searches on the decimated record, from the best grid points (default 4).
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

impl Default for BoucWenOptions {
    fn default() -> Self {
        Self {
            n: 1.0,
            estimate_n: false,
            starts: 4,
            config: driver::default_config(),
            initial_state: InitialState::Estimate,
            observer: Observer::none(),
            orientation: None,
        }
    }
}

/// The Bouc–Wen family for the driver: θ = (k_x, k_w, A, β, γ, n, w0), the order of
/// [`BoucWen::parameters`]; φ = (k_x, k_w, A, β + γ, β − γ, n, w0).
struct Family {
    n: f64,
    estimate_n: bool,
    /// +1: k_w ≥ 0 (clockwise loop), −1: k_w ≤ 0.
    sign: f64,
}

impl DifferentialFamily for Family {
    type Model = BoucWen;
    fn name(&self) -> &'static str {
        "bouc-wen"
    }
    fn initial_state_index(&self) -> usize {
        6
    }
    fn model(&self, t: &[f64]) -> Result<BoucWen> {
        let m = BoucWen {
            kx: t[0],
            kw: t[1],
            a: t[2],
            beta: t[3],
            gamma: t[4],
            n: t[5],
            w0: t[6],
        };
        m.validate()?;
        Ok(m)
    }
    fn free(&self) -> Vec<usize> {
        if self.estimate_n {
            vec![0, 1, 3, 4, 5, 6]
        } else {
            vec![0, 1, 3, 4, 6]
        }
    }
    fn bounds(&self, _shape: &LoopShape) -> (Vec<f64>, Vec<f64>) {
        let inf = f64::INFINITY;
        let (kw_lo, kw_hi) = if self.sign > 0.0 {
            (0.0, inf)
        } else {
            (-inf, 0.0)
        };
        (
            vec![-inf, kw_lo, 0.0, 1e-300, 0.0, 1.0, -inf],
            vec![inf, kw_hi, inf, inf, inf, 20.0, inf],
        )
    }
    fn theta_of(&self, p: &[f64]) -> Vec<f64> {
        vec![
            p[0],
            p[1],
            p[2],
            0.5 * (p[3] + p[4]),
            0.5 * (p[3] - p[4]),
            p[5],
            p[6],
        ]
    }
    fn phi_of(&self, t: &[f64]) -> Vec<f64> {
        vec![t[0], t[1], t[2], t[3] + t[4], t[3] - t[4], t[5], t[6]]
    }
    fn chain(&self, dt: &[f64], dp: &mut [f64]) {
        dp.copy_from_slice(dt);
        dp[3] = 0.5 * (dt[3] + dt[4]);
        dp[4] = 0.5 * (dt[3] - dt[4]);
    }
    /// Points (β, γ, n).
    fn shape_grid(&self, _u: &[f64], _y: &[f64], shape: &LoopShape) -> Vec<Vec<f64>> {
        let half = shape.half_span();
        let exponents: &[f64] = if self.estimate_n {
            &[1.0, 1.5, 2.0, 3.0]
        } else {
            std::slice::from_ref(&self.n)
        };
        let mut points = Vec::new();
        for &n in exponents {
            for k in 0..12 {
                // 1 % … 400 % of the half range, log-spaced.
                let ws = half * 0.01 * 400f64.powf(k as f64 / 11.0);
                for q in [-0.9, -0.5, 0.0, 0.5, 0.9, 1.0] {
                    let beta = 1.0 / (ws.powf(n) * (1.0 + q));
                    points.push(vec![beta, q * beta, n]);
                }
            }
        }
        points
    }
    fn basis(&self, p: &[f64], u: &[f64], tolerance: f64) -> Result<Basis> {
        let m = BoucWen::new(0.0, 1.0, p[0], p[1], p[2])?;
        Ok(Basis {
            fixed: None,
            columns: vec![u.to_vec(), states_with_tolerance(&m, u, tolerance)?],
        })
    }
    fn assemble(&self, p: &[f64], c: &[f64]) -> Option<Vec<f64>> {
        (c[1] * self.sign >= 0.0).then(|| vec![c[0], c[1], 1.0, p[0], p[1], p[2], 0.0])
    }

    const UNIT_FREE: bool = true;

    /// With w = sᵤw′ (w has the input's units, A = 1): dw′/du′ = A − (β·sign + γ)sᵤⁿ|w′|ⁿ
    /// and y/s_y = (k_x sᵤ/s_y)u′ + (k_w sᵤ/s_y)w′, so k_x = k_x′s_y/sᵤ, k_w = k_w′s_y/sᵤ,
    /// β = β′sᵤ⁻ⁿ, γ = γ′sᵤ⁻ⁿ (∂β/∂n = −β ln sᵤ), w0 = w0′sᵤ; A and n are unit-free.
    fn in_record_units(&self, t: &[f64], su: f64, sy: f64) -> Option<(Vec<f64>, DMatrix<f64>)> {
        let n = t[5];
        let shrink = su.powf(-n);
        let theta = vec![
            t[0] * sy / su,
            t[1] * sy / su,
            t[2],
            t[3] * shrink,
            t[4] * shrink,
            n,
            t[6] * su,
        ];
        let mut j = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![
            sy / su,
            sy / su,
            1.0,
            shrink,
            shrink,
            1.0,
            su,
        ]));
        j[(3, 5)] = -theta[3] * su.ln();
        j[(4, 5)] = -theta[4] * su.ln();
        Some((theta, j))
    }
}

/// Fits a Bouc–Wen operator to input `u` and output `y` (module doc).
pub fn fit(u: &[f64], y: &[f64], options: &BoucWenOptions) -> Result<OperatorFit<BoucWen>> {
    BoucWen::new(1.0, 1.0, 1.0, 0.0, options.n)?;
    // The w loop is clockwise: k_w > 0 for a clockwise loop, < 0 for a counter-clockwise one.
    let family = Family {
        n: options.n,
        estimate_n: options.estimate_n,
        sign: if u.len() == y.len() {
            -options
                .orientation
                .unwrap_or_else(|| LoopOrientation::of_loop(u, y))
                .sign()
        } else {
            1.0
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

impl Identify for BoucWen {
    const SETTINGS: &'static [FamilySetting] = &[FamilySetting::Orientation];

    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>> {
        fit(
            u,
            y,
            &BoucWenOptions {
                initial_state: options.initial_state,
                observer: options.observer.clone(),
                orientation: options.loop_orientation,
                ..BoucWenOptions::default()
            },
        )
    }
}
