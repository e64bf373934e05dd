//! The Bouc–Wen oscillator's sensitivity right-hand side on fixed-size arrays, for
//! [`crate::model::greybox::fixed_rk4`]: the point derivatives of
//! `bouc_wen::local_derivatives`, shared with [`BoucWen::rhs_sensitivities`](super::BoucWen), with what depends on θ alone (1/mL and the
//! first Jacobian row's entries) computed once per simulation instead of once per stage, and
//! the direct term ∂f/∂θ of each column picked from a table built once.
//!
//! Equations and reference: see [`super::BoucWen`] (Noël & Schoukens 2016).

use super::bouc_wen::{local_derivatives, LocalDerivatives, CL, KL, ML, NU, ZERO_SLOT};
use crate::model::greybox::fixed_rk4::{self, FixedSensitivityRhs, Rk4Sensitivities, SampleSink};
use crate::model::greybox::StateSpaceModel;
use crate::Result;

/// The largest number of sensitivity columns with a fixed-size path: the seven parameters and
/// the three initial states.
const MAX_COLUMNS: usize = 10;

/// The Bouc–Wen right-hand side with its parameters bound (see the module docs).
struct Kernel<const Q: usize> {
    theta: [f64; 7],
    /// 1/mL.
    inv_m: f64,
    /// ∂ÿ/∂(y, ẏ, z) = (−kL/mL, −cL/mL, −1/mL).
    f1: [f64; 3],
    /// Whether ν has a sensitivity column (its direct term needs ln|z|).
    with_nu: bool,
    /// Per column, the slot of its direct term: the parameter index, or [`ZERO_SLOT`].
    direct: [usize; Q],
}

impl<const Q: usize> Kernel<Q> {
    fn new(run: &Rk4Sensitivities<'_>) -> Option<Self> {
        let theta: [f64; 7] = run.theta.try_into().ok()?;
        let mut direct = [ZERO_SLOT; Q];
        for (slot, &i) in direct.iter_mut().zip(run.params) {
            *slot = i.min(ZERO_SLOT);
        }
        let inv_m = 1.0 / theta[ML];
        Some(Self {
            theta,
            inv_m,
            f1: [-theta[KL] * inv_m, -theta[CL] * inv_m, -inv_m],
            with_nu: run.params.contains(&NU),
            direct,
        })
    }
}

impl<const Q: usize> FixedSensitivityRhs<3, Q> for Kernel<Q> {
    #[inline(always)]
    fn eval(
        &mut self,
        x: &[f64; 3],
        u: &[f64],
        s: &[[f64; Q]; 3],
        dx: &mut [f64; 3],
        ds: &mut [[f64; Q]; 3],
    ) {
        let local = local_derivatives(&self.theta, self.inv_m, *x, u[0], self.with_nu);
        *dx = local.dx;
        let [f10, f11, f12] = self.f1;
        let LocalDerivatives {
            f21, f22, d1, d2, ..
        } = local;
        let [s0, s1, s2] = s;
        ds[0] = *s1;
        for c in 0..Q {
            let slot = self.direct[c];
            ds[1][c] = d1[slot] + f10 * s0[c] + f11 * s1[c] + f12 * s2[c];
            ds[2][c] = d2[slot] + f21 * s1[c] + f22 * s2[c];
        }
    }
}

/// ẋ alone, for a plain simulation (no sensitivity column): [`BoucWen::rhs`](super::BoucWen)
/// itself, called statically, so the same bits as the generic path.
struct Rates {
    theta: [f64; 7],
}

impl FixedSensitivityRhs<3, 0> for Rates {
    #[inline(always)]
    fn eval(
        &mut self,
        x: &[f64; 3],
        u: &[f64],
        _s: &[[f64; 0]; 3],
        dx: &mut [f64; 3],
        _ds: &mut [[f64; 0]; 3],
    ) {
        super::BoucWen.rhs(0.0, x, u, &self.theta, dx);
    }
}

/// Runs the fixed-size path for the run's column count (none: a plain simulation), None
/// when there is none (more columns than [`MAX_COLUMNS`], or a θ of another length).
pub(super) fn simulate(
    run: &Rk4Sensitivities<'_>,
    on_sample: &mut SampleSink<'_>,
) -> Option<Result<()>> {
    fn with<const Q: usize>(
        run: &Rk4Sensitivities<'_>,
        on_sample: &mut SampleSink<'_>,
    ) -> Option<Result<()>> {
        let mut kernel = Kernel::<Q>::new(run)?;
        Some(fixed_rk4::simulate::<_, 3, Q>(&mut kernel, run, on_sample))
    }
    const { assert!(MAX_COLUMNS == 10) };
    match run.columns() {
        0 => {
            let mut rates = Rates {
                theta: run.theta.try_into().ok()?,
            };
            Some(fixed_rk4::simulate::<_, 3, 0>(&mut rates, run, on_sample))
        }
        1 => with::<1>(run, on_sample),
        2 => with::<2>(run, on_sample),
        3 => with::<3>(run, on_sample),
        4 => with::<4>(run, on_sample),
        5 => with::<5>(run, on_sample),
        6 => with::<6>(run, on_sample),
        7 => with::<7>(run, on_sample),
        8 => with::<8>(run, on_sample),
        9 => with::<9>(run, on_sample),
        10 => with::<10>(run, on_sample),
        _ => None,
    }
}
