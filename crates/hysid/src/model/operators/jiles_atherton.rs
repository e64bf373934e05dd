//! The Jiles–Atherton model of ferromagnetic hysteresis (Jiles & Atherton 1986), as an
//! operator from the field H (A/m) to the magnetisation M (A/m) or the flux density B (T).
//!
//! # Equations
//!
//! ```text
//! H_e   = H + α·M                                  effective field
//! M_an  = Mₛ·(coth(H_e/a) − a/H_e)                 anhysteretic (Langevin)
//! M     = M_irr + M_rev,   M_rev = c·(M_an − M_irr)
//! dM_irr/dH = (M_an − M_irr) / (δ·k − α·(M_an − M_irr)),   δ = sign(dH)
//!           = 0 when (M_an − M_irr) and δ have opposite signs
//! ```
//!
//! The state integrated is the total magnetisation M, from which M_irr = (M − c·M_an)/(1 − c);
//! with M_an' = dM_an/dH_e, differentiating M = (1 − c)·M_irr + c·M_an(H + αM) gives the
//! explicit rate (Jiles, Thoelke & Devine 1992)
//!
//! ```text
//! dM/dH = [ (1 − c)·dM_irr/dH + c·M_an' ] / (1 − α·c·M_an')
//! ```
//!
//! integrated in H with error control ([`super::differential`]). The Langevin function uses its
//! series x/3 − x³/45 + 2x⁵/945 − x⁷/4725 for |x| < 0.1 (where coth x − 1/x cancels).
//! [`Anhysteretic::Tanh`] is the modified anhysteretic M_an = Mₛ·tanh(H_e/a) (Takács 2001).
//! The output is M, or B = μ₀(H + M) with μ₀ = 4π·10⁻⁷ H/m ([`JaOutput`]).
//!
//! A point where the model is not physical — δk − α(M_an − M_irr) of the wrong sign, or
//! 1 − α·c·M_an' ≤ 0 — makes the simulation fail with [`crate::Error::Diverged`].
//!
//! # Initial state and orientation
//! `m0` is the magnetisation at the first sample (0: demagnetised; a measured loop that starts
//! at its tip starts at the tip's M). B(H) loops are counter-clockwise; for a clockwise loop
//! the operator is driven by −u ([`LoopOrientation::Clockwise`]): H = −u, a mirrored loop.
//!
//! # References
//! * D. C. Jiles, D. L. Atherton, "Theory of ferromagnetic hysteresis", J. Magn. Magn. Mater.
//!   61 (1986) 48–60.
//! * D. C. Jiles, J. B. Thoelke, M. K. Devine, "Numerical determination of hysteresis
//!   parameters for the modeling of magnetic properties using the theory of ferromagnetic
//!   hysteresis", IEEE Trans. Magn. 28 (1992) 27–35.
//! * J. Takács, "A phenomenological mathematical model of hysteresis", COMPEL 20 (2001)
//!   1002–1015.

use super::differential::{self, InputOde, InputOdeSensitivity, LoopOrientation};
use super::{HysteresisOperator, Inversion};
use crate::model::Parameter;
use crate::model::ParameterSet;
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// Vacuum permeability μ₀ = 4π·10⁻⁷ H/m.
pub const MU0: f64 = 4.0e-7 * std::f64::consts::PI;

/// The anhysteretic magnetisation curve.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Anhysteretic {
    /// M_an = Mₛ·(coth(H_e/a) − a/H_e) (Jiles & Atherton 1986).
    Langevin,
    /// The modified form M_an = Mₛ·tanh(H_e/a) (Takács 2001).
    Tanh,
}

/// What the operator outputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JaOutput {
    /// The magnetisation M (A/m).
    Magnetisation,
    /// The flux density B = μ₀(H + M) (T).
    FluxDensity,
}

/// A Jiles–Atherton operator (see the module doc for the equations).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JilesAtherton {
    /// Saturation magnetisation Mₛ (A/m), > 0.
    pub ms: f64,
    /// Shape parameter a of the anhysteretic (A/m), > 0.
    pub a: f64,
    /// Pinning parameter k (A/m), > 0.
    pub k: f64,
    /// Reversibility c, 0 ≤ c < 1.
    pub c: f64,
    /// Inter-domain coupling α, ≥ 0.
    pub alpha: f64,
    /// Magnetisation at the first sample (A/m).
    pub m0: f64,
    /// The anhysteretic curve.
    pub anhysteretic: Anhysteretic,
    /// M or B.
    pub output: JaOutput,
    /// Clockwise: driven by −u.
    pub orientation: LoopOrientation,
}

impl JilesAtherton {
    /// A validated operator (Langevin anhysteretic, output B, counter-clockwise, m0 = 0).
    pub fn new(ms: f64, a: f64, k: f64, c: f64, alpha: f64) -> Result<Self> {
        let model = Self {
            ms,
            a,
            k,
            c,
            alpha,
            m0: 0.0,
            anhysteretic: Anhysteretic::Langevin,
            output: JaOutput::FluxDensity,
            orientation: LoopOrientation::CounterClockwise,
        };
        model.validate()?;
        Ok(model)
    }

    /// Checks the values: Mₛ, a, k > 0, 0 ≤ c < 1, α ≥ 0, all finite.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &str, value: f64, reason: &str| {
            Err(Error::InvalidParameter {
                name: name.into(),
                value,
                reason: reason.into(),
            })
        };
        for (name, v) in [("Ms", self.ms), ("a", self.a), ("k", self.k)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(name, v, "must be finite and > 0");
            }
        }
        if !(self.c.is_finite() && (0.0..1.0).contains(&self.c)) {
            return bad("c", self.c, "must satisfy 0 <= c < 1");
        }
        if !(self.alpha.is_finite() && self.alpha >= 0.0) {
            return bad("alpha", self.alpha, "must be finite and >= 0");
        }
        if !self.m0.is_finite() {
            return bad("m0", self.m0, "must be finite");
        }
        Ok(())
    }

    /// M_an(H_e) and dM_an/dH_e.
    pub fn anhysteretic(&self, he: f64) -> (f64, f64) {
        let x = he / self.a;
        let (l, dl) = match self.anhysteretic {
            Anhysteretic::Langevin => langevin(x),
            Anhysteretic::Tanh => {
                let t = x.tanh();
                (t, 1.0 - t * t)
            }
        };
        (self.ms * l, self.ms / self.a * dl)
    }

    /// dM/dH at field h, magnetisation m, field direction δ (module doc).
    fn dm_dh(&self, h: f64, m: f64, delta: f64) -> f64 {
        let (man, dman) = self.anhysteretic(h + self.alpha * m);
        let mirr = (m - self.c * man) / (1.0 - self.c);
        let gap = man - mirr;
        let dmirr = if gap * delta > 0.0 {
            let den = delta * self.k - self.alpha * gap;
            if den * delta <= 0.0 {
                return f64::NAN;
            }
            gap / den
        } else {
            0.0
        };
        let den = 1.0 - self.alpha * self.c * dman;
        if den <= 0.0 {
            return f64::NAN;
        }
        ((1.0 - self.c) * dmirr + self.c * dman) / den
    }
}

/// L(x) = coth x − 1/x and L'(x) = 1/x² − 1/sinh² x, by their series near 0.
pub fn langevin(x: f64) -> (f64, f64) {
    if x.abs() < 0.1 {
        let x2 = x * x;
        let l = x * (1.0 / 3.0 - x2 * (1.0 / 45.0 - x2 * (2.0 / 945.0 - x2 / 4725.0)));
        let dl = 1.0 / 3.0 - x2 * (1.0 / 15.0 - x2 * (2.0 / 189.0 - x2 / 675.0));
        (l, dl)
    } else {
        let s = x.sinh();
        let dl = if s.is_finite() {
            1.0 / (x * x) - 1.0 / (s * s)
        } else {
            1.0 / (x * x)
        };
        (1.0 / x.tanh() - 1.0 / x, dl)
    }
}

impl InputOde for JilesAtherton {
    fn slope(&self, u: f64, m: f64, direction: f64) -> f64 {
        let s = self.orientation.sign();
        s * self.dm_dh(s * u, m, s * direction)
    }
    fn output(&self, u: f64, m: f64) -> f64 {
        match self.output {
            JaOutput::Magnetisation => m,
            JaOutput::FluxDensity => MU0 * (self.orientation.sign() * u + m),
        }
    }
    fn initial_state(&self) -> f64 {
        self.m0
    }
    fn state_scale(&self) -> f64 {
        self.ms
    }
    fn max_substep(&self) -> f64 {
        0.25 * self.a.min(self.k)
    }
    fn inversion_span(&self) -> f64 {
        1e4 * (self.a + self.k)
    }
}

/// A value with its derivatives with respect to (M, Mₛ, a, k, c, α): forward-mode
/// differentiation of [`JilesAtherton::dm_dh`] for the sensitivities.
#[derive(Clone, Copy)]
struct Dual {
    v: f64,
    d: [f64; 6],
}

impl Dual {
    fn constant(v: f64) -> Self {
        Self { v, d: [0.0; 6] }
    }
    fn variable(v: f64, index: usize) -> Self {
        let mut d = [0.0; 6];
        d[index] = 1.0;
        Self { v, d }
    }
    /// g(self) for g with value `g` and derivative `dg` at self.v (the chain rule).
    fn map(self, g: f64, dg: f64) -> Self {
        Self {
            v: g,
            d: self.d.map(|x| dg * x),
        }
    }
    fn zip(self, o: Self, v: f64, f: impl Fn(f64, f64) -> f64) -> Self {
        let mut d = [0.0; 6];
        for (i, d) in d.iter_mut().enumerate() {
            *d = f(self.d[i], o.d[i]);
        }
        Self { v, d }
    }
}

impl std::ops::Add for Dual {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        self.zip(o, self.v + o.v, |a, b| a + b)
    }
}

impl std::ops::Sub for Dual {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        self.zip(o, self.v - o.v, |a, b| a - b)
    }
}

impl std::ops::Mul for Dual {
    type Output = Self;
    #[allow(clippy::suspicious_arithmetic_impl)] // the product rule
    fn mul(self, o: Self) -> Self {
        let (x, y) = (self.v, o.v);
        self.zip(o, x * y, |a, b| a * y + x * b)
    }
}

impl std::ops::Div for Dual {
    type Output = Self;
    #[allow(clippy::suspicious_arithmetic_impl)] // the quotient rule
    fn div(self, o: Self) -> Self {
        let (x, y) = (self.v, o.v);
        self.zip(o, x / y, |a, b| (a * y - x * b) / (y * y))
    }
}

/// L(x), L'(x) and L''(x) of the anhysteretic shape (Langevin or tanh). For the Langevin
/// function L'' = −2/x³ + 2·coth x·csch² x is formed from coth x = L + 1/x and
/// csch² x = 1/x² − L' (no further transcendental function), by its series near 0.
fn shape_with_curvature(kind: Anhysteretic, x: f64) -> (f64, f64, f64) {
    match kind {
        Anhysteretic::Langevin => {
            let (l, dl) = langevin(x);
            let ddl = if x.abs() < 0.1 {
                let x2 = x * x;
                x * (-2.0 / 15.0 + x2 * (8.0 / 189.0 - x2 * 6.0 / 675.0))
            } else {
                let r = 1.0 / x;
                -2.0 * r * r * r + 2.0 * (l + r) * (r * r - dl)
            };
            (l, dl, ddl)
        }
        Anhysteretic::Tanh => {
            let t = x.tanh();
            let dl = 1.0 - t * t;
            (t, dl, -2.0 * t * dl)
        }
    }
}

impl JilesAtherton {
    /// [`dm_dh`](Self::dm_dh) with its derivatives with respect to (M, Mₛ, a, k, c, α); None
    /// where the model is not physical (the same tests as `dm_dh`).
    fn dm_dh_dual(&self, h: f64, m: f64, delta: f64) -> Option<Dual> {
        let one = Dual::constant(1.0);
        let (m, ms, a, k, c, alpha) = (
            Dual::variable(m, 0),
            Dual::variable(self.ms, 1),
            Dual::variable(self.a, 2),
            Dual::variable(self.k, 3),
            Dual::variable(self.c, 4),
            Dual::variable(self.alpha, 5),
        );
        let x = (Dual::constant(h) + alpha * m) / a;
        let (l, dl, ddl) = shape_with_curvature(self.anhysteretic, x.v);
        let man = ms * x.map(l, dl);
        let dman = ms / a * x.map(dl, ddl);
        let mirr = (m - c * man) / (one - c);
        let gap = man - mirr;
        let dmirr = if gap.v * delta > 0.0 {
            let den = Dual::constant(delta) * k - alpha * gap;
            if den.v * delta <= 0.0 {
                return None;
            }
            gap / den
        } else {
            Dual::constant(0.0)
        };
        let den = one - alpha * c * dman;
        if den.v <= 0.0 {
            return None;
        }
        Some(((one - c) * dmirr + c * dman) / den)
    }
}

/// θ = (Mₛ, a, k, c, α, m0): the partials of dM/dH by forward-mode differentiation of its
/// formula (module doc), with L'' = −2/x³ + 2·cosh x/sinh³ x (series near 0) or
/// −2·tanh x·(1 − tanh² x); ∂B/∂M = μ₀ (∂M/∂M = 1); ∂M(u\[0\])/∂m0 = 1.
impl InputOdeSensitivity for JilesAtherton {
    fn n_parameters(&self) -> usize {
        6
    }
    fn slope_partials(&self, u: f64, m: f64, direction: f64, dtheta: &mut [f64]) -> (f64, f64) {
        let s = self.orientation.sign();
        match self.dm_dh_dual(s * u, m, s * direction) {
            Some(g) => {
                // The value is `dm_dh`'s, operation for operation: the slope's very bits.
                let f = s * g.v;
                for (j, d) in dtheta.iter_mut().take(5).enumerate() {
                    *d = s * g.d[j + 1];
                }
                dtheta[5] = 0.0;
                (f, s * g.d[0])
            }
            None => {
                dtheta.fill(f64::NAN);
                (f64::NAN, f64::NAN)
            }
        }
    }
    fn output_partials(&self, _u: f64, _m: f64, dtheta: &mut [f64]) -> f64 {
        dtheta.fill(0.0);
        match self.output {
            JaOutput::Magnetisation => 1.0,
            JaOutput::FluxDensity => MU0,
        }
    }
    fn initial_state_partials(&self, dtheta: &mut [f64]) {
        dtheta.copy_from_slice(&[0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
    }
}

super::streaming::differential_streaming!(JilesAtherton);

impl HysteresisOperator for JilesAtherton {
    fn family(&self) -> &'static str {
        <Self as super::OperatorFamily>::NAME
    }
    fn parameters(&self) -> ParameterSet {
        let p = vec![
            Parameter::new("Ms", self.ms)
                .unit("A/m")
                .bounds(0.0, f64::INFINITY),
            Parameter::new("a", self.a)
                .unit("A/m")
                .bounds(0.0, f64::INFINITY),
            Parameter::new("k", self.k)
                .unit("A/m")
                .bounds(0.0, f64::INFINITY),
            Parameter::new("c", self.c).bounds(0.0, 1.0),
            Parameter::new("alpha", self.alpha).bounds(0.0, f64::INFINITY),
            Parameter::new("m0", self.m0).unit("A/m"),
        ];
        ParameterSet::new(p).expect("distinct names")
    }
    fn simulate(&self, u: &[f64]) -> Result<Vec<f64>> {
        self.validate()?;
        differential::simulate(self, u)
    }
    fn invert(&self, reference: &[f64]) -> Result<Inversion> {
        self.validate()?;
        differential::invert(self, reference)
    }
    /// 100 of the family's longest sub-steps (its input scale): the state forgets its start
    /// over that distance.
    fn memory_reach(&self) -> f64 {
        100.0 * InputOde::max_substep(self)
    }
}

impl super::OperatorFamily for JilesAtherton {
    const NAME: &'static str = "jiles-atherton";
    const TITLE: &'static str = "Jiles & Atherton (1986)";

    fn example() -> Result<Self> {
        // The classic parameters of Jiles & Atherton (1986), with H in A/m.
        Self::new(1.6e6, 1100.0, 400.0, 0.2, 1.6e-3)
    }

    fn checked(self) -> Result<Self> {
        self.validate()?;
        Ok(self)
    }

    fn with_values(&self, values: &[f64]) -> Result<Self> {
        let [ms, a, k, c, alpha, m0] = super::registry::values_array(self, values)?;
        let next = Self {
            ms,
            a,
            k,
            c,
            alpha,
            m0,
            ..self.clone()
        };
        next.validate()?;
        Ok(next)
    }

    /// None: B = μ₀(H + M) has no output scale apart from the loop's shape.
    fn output_scale(&self) -> Option<Vec<usize>> {
        None
    }
}
