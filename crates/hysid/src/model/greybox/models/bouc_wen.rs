//! The Bouc–Wen oscillator of the hysteretic benchmark (Noël & Schoukens 2016).
//!
//! # Equations (docs/benchmarks.md §1.1, VERIFIED)
//!
//! ```text
//! mL ÿ + cL ẏ + kL y + z = u
//! ż = α ẏ − β (γ |ẏ| |z|^(ν−1) z + δ ẏ |z|^ν)
//! ```
//!
//! States x = (y, ẏ, z), input u (force, N), output y (displacement, m). Only α and the
//! products βγ, βδ are identifiable (β cannot be separated from γ and δ), so the model is
//! parameterised in them:
//!
//! | symbol | name | meaning | unit | default (benchmark) | bounds |
//! | --- | --- | --- | --- | --- | --- |
//! | mL | `mL` | mass | kg | 2 | > 0 |
//! | cL | `cL` | viscous damping | N·s/m | 10 | ≥ 0 |
//! | kL | `kL` | linear stiffness | N/m | 5·10⁴ | ≥ 0 |
//! | α | `alpha` | hysteretic stiffness | N/m | 5·10⁴ | ≥ 0 |
//! | βγ | `beta_gamma` | hysteresis shape | m⁻ᵛ | 800 | free |
//! | βδ | `beta_delta` | hysteresis shape | m⁻ᵛ | −1100 | free |
//! | ν | `nu` | exponent (fixed at 1 by default) | – | 1 | [0.1, 10] |
//!
//! Small-motion natural frequency √((kL + α)/mL)/2π = 35.59 Hz.
//!
//! References: J.P. Noël, M. Schoukens, "Hysteretic benchmark with a dynamic nonlinearity",
//! Workshop on Nonlinear System Identification Benchmarks, 2016; M. Schoukens, J.P. Noël,
//! IFAC World Congress 2017.

use super::sign0;
use crate::data::Channel;
use crate::model::greybox::fixed_rk4::{Rk4Sensitivities, SampleSink};
use crate::model::greybox::{JacobianScratch, StateSpaceModel};
use crate::model::{Parameter, ParameterSet};

/// The Bouc–Wen oscillator (see the module docs).
///
/// ```
/// use hysid::model::greybox::models::BoucWen;
/// use hysid::model::greybox::StateSpaceModel;
/// let p = BoucWen.parameters();
/// assert_eq!(p.names(), ["mL", "cL", "kL", "alpha", "beta_gamma", "beta_delta", "nu"]);
/// assert!(p.get(6).fixed);
/// ```
#[derive(Clone, Copy, Debug, Default)]
pub struct BoucWen;

/// Indices into θ.
pub(super) const ML: usize = 0;
pub(super) const CL: usize = 1;
pub(super) const KL: usize = 2;
pub(super) const ALPHA: usize = 3;
pub(super) const BG: usize = 4;
pub(super) const BD: usize = 5;
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub const NU: usize = 6;

impl StateSpaceModel for BoucWen {
    fn kind(&self) -> &'static str {
        "bouc_wen"
    }

    fn states(&self) -> Vec<Channel> {
        vec![
            Channel::new("y").with_unit("m"),
            Channel::new("v").with_unit("m/s"),
            Channel::new("z").with_unit("N"),
        ]
    }

    fn inputs(&self) -> Vec<Channel> {
        vec![Channel::new("u").with_unit("N")]
    }

    fn outputs(&self) -> Vec<Channel> {
        vec![Channel::new("y").with_unit("m")]
    }

    fn parameters(&self) -> ParameterSet {
        ParameterSet::new(vec![
            Parameter::new("mL", 2.0)
                .unit("kg")
                .bounds(1e-9, f64::INFINITY),
            Parameter::new("cL", 10.0)
                .unit("N*s/m")
                .bounds(0.0, f64::INFINITY),
            Parameter::new("kL", 5e4)
                .unit("N/m")
                .bounds(0.0, f64::INFINITY),
            Parameter::new("alpha", 5e4)
                .unit("N/m")
                .bounds(0.0, f64::INFINITY),
            Parameter::new("beta_gamma", 800.0).unit("1/m^nu"),
            Parameter::new("beta_delta", -1100.0).unit("1/m^nu"),
            Parameter::new("nu", 1.0).bounds(0.1, 10.0).fixed(true),
        ])
        .expect("unique names")
    }

    #[inline]
    fn rhs(&self, _t: f64, x: &[f64], u: &[f64], th: &[f64], dx: &mut [f64]) {
        let (y, v, z) = (x[0], x[1], x[2]);
        dx[0] = v;
        dx[1] = (u[0] - th[CL] * v - th[KL] * y - z) / th[ML];
        let a = abs_pow(z, th[NU]);
        dx[2] = th[ALPHA] * v - th[BG] * v.abs() * sign0(z) * a - th[BD] * v * a;
    }

    fn output(&self, x: &[f64], _u: &[f64], _theta: &[f64], y: &mut [f64]) {
        y[0] = x[0];
    }

    fn rhs_jacobians(
        &self,
        _t: f64,
        x: &[f64],
        u: &[f64],
        th: &[f64],
        fx: &mut [f64],
        ft: &mut [f64],
    ) -> bool {
        let (y, v, z) = (x[0], x[1], x[2]);
        let nu = th[NU];
        let a = abs_pow(z, nu);
        // d|z|^ν/dz = ν|z|^(ν−1)·sgn z, d(sgn z·|z|^ν)/dz = ν|z|^(ν−1); |z|^(ν−1) → 1 at
        // z = 0 for ν = 1, the only exponent for which z = 0 is not a singular point.
        let da = if z == 0.0 {
            if nu == 1.0 {
                1.0
            } else {
                0.0
            }
        } else {
            nu * abs_pow(z, nu - 1.0)
        };
        let m = th[ML];
        // One division; the six entries divided by m multiply by its reciprocal.
        let inv_m = 1.0 / m;
        fx.fill(0.0);
        ft.fill(0.0);
        fx[1] = 1.0; // ∂ẏ/∂v
        fx[3] = -th[KL] * inv_m;
        fx[4] = -th[CL] * inv_m;
        fx[5] = -inv_m;
        fx[7] = th[ALPHA] - th[BG] * sign0(v) * sign0(z) * a - th[BD] * a;
        fx[8] = -th[BG] * v.abs() * da - th[BD] * v * da * sign0(z);
        let p = th.len();
        let acc = (u[0] - th[CL] * v - th[KL] * y - z) / m;
        ft[p + ML] = -acc * inv_m;
        ft[p + CL] = -v * inv_m;
        ft[p + KL] = -y * inv_m;
        let ln = if z == 0.0 { 0.0 } else { z.abs().ln() };
        ft[2 * p + ALPHA] = v;
        ft[2 * p + BG] = -v.abs() * sign0(z) * a;
        ft[2 * p + BD] = -v * a;
        ft[2 * p + NU] = -(th[BG] * v.abs() * sign0(z) + th[BD] * v) * a * ln;
        true
    }

    fn output_jacobians(
        &self,
        _x: &[f64],
        _u: &[f64],
        _theta: &[f64],
        hx: &mut [f64],
        ht: &mut [f64],
    ) -> bool {
        hx.fill(0.0);
        ht.fill(0.0);
        hx[0] = 1.0;
        true
    }

    fn output_jacobians_are_constant(&self) -> bool {
        true
    }

    fn output_reads_input(&self) -> bool {
        false
    }

    fn mechanical_dofs(&self) -> Option<usize> {
        Some(1)
    }

    /// The fused form of `rhs` and `rhs_jacobians` (same values, same order of operations):
    /// only the six non-constant Jacobian entries are formed, and ln|z| (∂ż/∂ν) only when ν
    /// is among `params`.
    fn rhs_sensitivities(
        &self,
        _t: f64,
        x: &[f64],
        u: &[f64],
        th: &[f64],
        _held: Option<f64>,
        params: &[usize],
        s: &[f64],
        _scratch: &mut JacobianScratch,
        dx: &mut [f64],
        ds: &mut [f64],
    ) -> bool {
        let inv_m = 1.0 / th[ML];
        let local = local_derivatives(th, inv_m, [x[0], x[1], x[2]], u[0], params.contains(&NU));
        dx.copy_from_slice(&local.dx);
        // Row 1 of ∂f/∂x depends on θ only (row 0 is [0, 1, 0]).
        let (f10, f11, f12) = (-th[KL] * inv_m, -th[CL] * inv_m, -inv_m);
        let LocalDerivatives {
            f21, f22, d1, d2, ..
        } = local;
        let q = s.len() / 3;
        let (s0, rest) = s.split_at(q);
        let (s1, s2) = rest.split_at(q);
        let (ds0, rest) = ds.split_at_mut(q);
        let (ds1, ds2) = rest.split_at_mut(q);
        ds0.copy_from_slice(s1);
        // Parameter columns (with their direct terms) first, then the initial-state columns;
        // zipped slices of one length, so the loops carry no bounds checks or lookups.
        let np = params.len().min(q);
        let parameter_columns = ds1[..np]
            .iter_mut()
            .zip(&mut ds2[..np])
            .zip(&s0[..np])
            .zip(&s1[..np])
            .zip(&s2[..np])
            .zip(params);
        for (((((o1, o2), a), b), c), &i) in parameter_columns {
            let slot = i.min(ZERO_SLOT);
            let (direct1, direct2) = (d1[slot], d2[slot]);
            *o1 = direct1 + f10 * a + f11 * b + f12 * c;
            *o2 = direct2 + f21 * b + f22 * c;
        }
        let state_columns = ds1[np..]
            .iter_mut()
            .zip(&mut ds2[np..])
            .zip(&s0[np..])
            .zip(&s1[np..])
            .zip(&s2[np..]);
        for ((((o1, o2), a), b), c) in state_columns {
            *o1 = 0.0 + f10 * a + f11 * b + f12 * c;
            *o2 = 0.0 + f21 * b + f22 * c;
        }
        true
    }

    /// The fixed-size path of the private `bouc_wen_kernel` module: the same numbers as the generic one.
    fn fixed_rk4_sensitivities(
        &self,
        run: &Rk4Sensitivities<'_>,
        on_sample: &mut SampleSink<'_>,
    ) -> Option<crate::Result<()>> {
        super::bouc_wen_kernel::simulate(run, on_sample)
    }
}

/// Slot of [`LocalDerivatives::d1`] and [`LocalDerivatives::d2`] that holds zero: the direct
/// term of a column that is not a model parameter (an initial state).
pub(super) const ZERO_SLOT: usize = 7;

/// ẋ and the state-dependent entries of the Jacobians at one point, shared by the generic
/// sensitivity path ([`BoucWen::rhs_sensitivities`]) and the fixed-size one
/// (`bouc_wen_kernel`), so that both compute them by the same operations.
pub(super) struct LocalDerivatives {
    /// ẋ = (ẏ, ÿ, ż).
    pub dx: [f64; 3],
    /// ∂ż/∂ẏ = α − β_γ·sign(ẏ)·sign(z)·|z|^ν − β_δ·|z|^ν.
    pub f21: f64,
    /// ∂ż/∂z = −(β_γ·|ẏ| + β_δ·ẏ·sign(z))·ν|z|^(ν−1).
    pub f22: f64,
    /// Row 1 of ∂f/∂θ by parameter index, [`ZERO_SLOT`] zero.
    pub d1: [f64; 8],
    /// Row 2 of ∂f/∂θ by parameter index, [`ZERO_SLOT`] zero; ∂ż/∂ν only `with_nu`
    /// (it needs ln|z|).
    pub d2: [f64; 8],
}

/// [`LocalDerivatives`] at state x = (y, ẏ, z) and input u, with 1/m_L given (a kernel
/// computes it once per simulation; it is the same number either way).
#[inline(always)]
pub(super) fn local_derivatives(
    th: &[f64],
    inv_m: f64,
    [y, v, z]: [f64; 3],
    u: f64,
    with_nu: bool,
) -> LocalDerivatives {
    let nu = th[NU];
    let a = abs_pow(z, nu);
    let sz = sign0(z);
    let acc = (u - th[CL] * v - th[KL] * y - z) / th[ML];
    let da = if z == 0.0 {
        if nu == 1.0 {
            1.0
        } else {
            0.0
        }
    } else {
        nu * abs_pow(z, nu - 1.0)
    };
    let mut d1 = [0.0; 8];
    let mut d2 = [0.0; 8];
    d1[ML] = -acc * inv_m;
    d1[CL] = -v * inv_m;
    d1[KL] = -y * inv_m;
    d2[ALPHA] = v;
    d2[BG] = -v.abs() * sz * a;
    d2[BD] = -v * a;
    if with_nu {
        let ln = if z == 0.0 { 0.0 } else { z.abs().ln() };
        d2[NU] = -(th[BG] * v.abs() * sz + th[BD] * v) * a * ln;
    }
    LocalDerivatives {
        dx: [
            v,
            acc,
            th[ALPHA] * v - th[BG] * v.abs() * sz * a - th[BD] * v * a,
        ],
        f21: th[ALPHA] - th[BG] * sign0(v) * sz * a - th[BD] * a,
        f22: -th[BG] * v.abs() * da - th[BD] * v * da * sz,
        d1,
        d2,
    }
}

/// |z|^ν with the exponents that occur in practice (ν = 1, the benchmark's, and ν = 2)
/// computed without `powf`: exactly equal, and several times cheaper.
#[inline]
pub(super) fn abs_pow(z: f64, nu: f64) -> f64 {
    if nu == 1.0 {
        z.abs()
    } else if nu == 2.0 {
        z * z
    } else if nu == 0.0 {
        1.0
    } else {
        z.abs().powf(nu)
    }
}
