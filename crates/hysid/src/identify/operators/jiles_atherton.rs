//! Fit of the Jiles–Atherton operator ([`JilesAtherton`]) to a measured B(H) or M(H) loop, by
//! the differential driver ([`differential_fit`](super::differential_fit)).
//!
//! **What the family supplies.** With m = M/Mₛ and ᾱ = α·Mₛ the equations of the module
//! [`crate::model::operators::jiles_atherton`] read, in m,
//! m_an = L((H + ᾱ·m)/a), dm_irr/dH = (m_an − m_irr)/(δk − ᾱ·(m_an − m_irr)): the
//! magnetisation is Mₛ times the response m of a unit operator (Mₛ = 1) that depends on the
//! shape (a, k, c, ᾱ, m0/Mₛ) alone, and B = μ₀·H + μ₀·Mₛ·m. Mₛ is the linear parameter.
//! The start grid is placed from the loop (after converting B to M = B/μ₀ − H):
//! * the saturation ratio ρ = Mₛ/max|M| ∈ {1.05, 1.5, 3} gives a from the anhysteretic's
//!   reach at the loop tip, L(H_max/a) = 1/ρ;
//! * k ∈ {½, 1, 2}·H_c, H_c the coercivity (the mean |H| where M changes sign; k ≈ H_c,
//!   Jiles, Thoelke & Devine 1992);
//! * c ∈ {0.2, 0.45, 0.7}, ᾱ ∈ {0, 0.05, 0.3}·a, m0/Mₛ = M\[0\]/(ρ·max|M|).
//!
//! The search box is the physical one: Mₛ, a, k > 0, 0 ≤ c < 1, α ≥ 0.
//!
//! **Orientation.** B(H) loops are counter-clockwise; a clockwise loop (negative enclosed area)
//! is fitted with the operator driven by −u (the mirrored loop).
//!
//! References: Jiles & Atherton (1986); Jiles, Thoelke & Devine (1992), see
//! [`crate::model::operators::jiles_atherton`].

use super::differential_fit::{self as driver, Basis, DifferentialFamily, LoopShape, Settings};
use super::family::{FamilyOptions, FamilySetting, Identify};
use super::OperatorFit;
use crate::model::operators::differential::simulate_with_tolerance;
use crate::model::operators::jiles_atherton::{langevin, MU0};
use crate::model::operators::InitialState;
use crate::model::operators::{Anhysteretic, JaOutput, JilesAtherton, LoopOrientation};
use crate::numerics::levenberg_marquardt::LmConfig;
use crate::numerics::Observer;
use crate::Result;

/// Options of the Jiles–Atherton fit.
#[derive(Clone, Debug)]
pub struct JilesAthertonOptions {
    /// The anhysteretic curve (default Langevin).
    pub anhysteretic: Anhysteretic,
    /// What the measured output is (default B in T, with H in A/m).
    pub output: JaOutput,
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

impl Default for JilesAthertonOptions {
    fn default() -> Self {
        Self {
            anhysteretic: Anhysteretic::Langevin,
            output: JaOutput::FluxDensity,
            config: driver::default_config(),
            initial_state: InitialState::Estimate,
            observer: Observer::none(),
            orientation: None,
        }
    }
}

/// Local searches on the decimated record.
const STARTS: usize = 4;

/// The Jiles–Atherton family for the driver: θ = (Mₛ, a, k, c, α, m0), the order of
/// [`JilesAtherton::parameters`].
struct Family {
    anhysteretic: Anhysteretic,
    output: JaOutput,
    orientation: LoopOrientation,
}

impl Family {
    fn operator(&self, t: &[f64], output: JaOutput) -> JilesAtherton {
        JilesAtherton {
            ms: t[0],
            a: t[1],
            k: t[2],
            c: t[3],
            alpha: t[4],
            m0: t[5],
            anhysteretic: self.anhysteretic,
            output,
            orientation: self.orientation,
        }
    }

    /// The field H = ±u and the magnetisation M of the measured loop.
    fn field_and_magnetisation(&self, u: &[f64], y: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let s = self.orientation.sign();
        let h: Vec<f64> = u.iter().map(|v| s * v).collect();
        let m = match self.output {
            JaOutput::Magnetisation => y.to_vec(),
            JaOutput::FluxDensity => y.iter().zip(&h).map(|(b, h)| b / MU0 - h).collect(),
        };
        (h, m)
    }
}

impl DifferentialFamily for Family {
    type Model = JilesAtherton;
    fn name(&self) -> &'static str {
        "jiles-atherton"
    }
    fn initial_state_index(&self) -> usize {
        5
    }
    fn model(&self, t: &[f64]) -> Result<JilesAtherton> {
        let m = self.operator(t, self.output);
        m.validate()?;
        Ok(m)
    }
    fn free(&self) -> Vec<usize> {
        vec![0, 1, 2, 3, 4, 5]
    }
    fn bounds(&self, shape: &LoopShape) -> (Vec<f64>, Vec<f64>) {
        let inf = f64::INFINITY;
        let h = shape.half_span();
        let m_scale = match self.output {
            JaOutput::Magnetisation => shape.y_range.1 - shape.y_range.0,
            JaOutput::FluxDensity => (shape.y_range.1 - shape.y_range.0) / MU0,
        }
        .max(f64::MIN_POSITIVE);
        (
            vec![1e-9 * m_scale, 1e-9 * h, 1e-9 * h, 0.0, 0.0, -inf],
            vec![inf, inf, inf, 1.0 - 1e-9, inf, inf],
        )
    }
    /// A magnetisation M = B/μ₀ − H that falls as H rises (the least-squares slope dM/dH
    /// ≤ 0) is no ferromagnet's: a record in other units than A/m and T.
    fn unfit_reason(&self, u: &[f64], y: &[f64]) -> String {
        let (h, m) = self.field_and_magnetisation(u, y);
        let slope = LoopShape::of(&h, &m).slope;
        if self.output == JaOutput::FluxDensity && slope <= 0.0 {
            format!(
                "its magnetisation M = B/μ₀ − H falls as H rises (dM/dH = {slope:.3}), which \
                 no ferromagnet's does: Jiles–Atherton takes H in A/m and B in T; convert the \
                 record to those units"
            )
        } else {
            driver::NO_START.into()
        }
    }
    /// Points (a, k, c, ᾱ, m0/Mₛ).
    fn shape_grid(&self, u: &[f64], y: &[f64], _shape: &LoopShape) -> Vec<Vec<f64>> {
        let (h, m) = self.field_and_magnetisation(u, y);
        let peak = |v: &[f64]| {
            v.iter()
                .fold(0.0f64, |a, x| a.max(x.abs()))
                .max(f64::MIN_POSITIVE)
        };
        let (m_max, h_max) = (peak(&m), peak(&h));
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
        }
        .max(1e-3 * h_max);
        let mut points = Vec::new();
        for rho in [1.05, 1.5, 3.0] {
            let a = h_max / inverse_langevin(1.0 / rho);
            let z0 = m[0] / (rho * m_max);
            for k in [0.5, 1.0, 2.0].map(|f| f * hc) {
                for c in [0.2, 0.45, 0.7] {
                    for alpha in [0.0, 0.05, 0.3].map(|f| f * a) {
                        points.push(vec![a, k, c, alpha, z0]);
                    }
                }
            }
        }
        points
    }
    fn basis(&self, p: &[f64], u: &[f64], tolerance: f64) -> Result<Basis> {
        let unit = self.operator(
            &[1.0, p[0], p[1], p[2], p[3], p[4]],
            JaOutput::Magnetisation,
        );
        let mut m = simulate_with_tolerance(&unit, u, tolerance)?;
        let fixed = match self.output {
            JaOutput::Magnetisation => None,
            JaOutput::FluxDensity => {
                m.iter_mut().for_each(|v| *v *= MU0);
                let s = self.orientation.sign();
                Some(u.iter().map(|v| MU0 * s * v).collect())
            }
        };
        Ok(Basis {
            fixed,
            columns: vec![m],
        })
    }
    fn assemble(&self, p: &[f64], c: &[f64]) -> Option<Vec<f64>> {
        let ms = c[0];
        (ms > 0.0).then(|| vec![ms, p[0], p[1], p[2], p[3] / ms, p[4] * ms])
    }
}

/// Fits a Jiles–Atherton operator to the field `u` (A/m) and B (T) or M (A/m) `y`.
pub fn fit(
    u: &[f64],
    y: &[f64],
    options: &JilesAthertonOptions,
) -> Result<OperatorFit<JilesAtherton>> {
    let family = Family {
        anhysteretic: options.anhysteretic,
        output: options.output,
        orientation: if u.len() == y.len() {
            options
                .orientation
                .unwrap_or_else(|| LoopOrientation::of_loop(u, y))
        } else {
            LoopOrientation::CounterClockwise
        },
    };
    let settings = Settings {
        starts: STARTS,
        config: options.config.clone(),
        observer: options.observer.clone(),
        initial_state: options.initial_state,
    };
    driver::fit(&family, u, y, &settings)
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
    const SETTINGS: &'static [FamilySetting] = &[FamilySetting::Orientation];

    fn identify(u: &[f64], y: &[f64], options: &FamilyOptions) -> Result<OperatorFit<Self>> {
        fit(
            u,
            y,
            &JilesAthertonOptions {
                initial_state: options.initial_state,
                observer: options.observer.clone(),
                orientation: options.loop_orientation,
                ..JilesAthertonOptions::default()
            },
        )
    }
}
