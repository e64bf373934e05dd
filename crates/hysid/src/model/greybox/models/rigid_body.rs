//! A rigid body with viscous and Coulomb friction and a constant force offset.
//!
//! # Equations
//!
//! ```text
//! M q̈ + Fv q̇ + Fc sgn(q̇) + offset = g·u
//! ```
//!
//! At rest, friction holds the body while |g·u − offset| ≤ Fc (stick–slip, integrated by
//! [`crate::model::greybox::stick_slip`]).
//!
//! States x = (q, q̇), input u (drive signal), output q (position). g converts the drive
//! signal into force (1 when u is already a force; 35.15 N/V for the EMPS positioning system).
//! The same structure, Jt θ̈ + Fv θ̇ + Fc sgn(θ̇) = τ, is the rigid-body step of Gunnar et al.
//! (2006).
//!
//! | symbol | name | meaning | unit | default |
//! | --- | --- | --- | --- | --- |
//! | M | `M` | mass or inertia | kg (kg·m²) | 1 |
//! | Fv | `Fv` | viscous friction | N·s/m | 0 |
//! | Fc | `Fc` | Coulomb friction | N | 0 |
//! | offset | `offset` | force offset | N | 0 |
//! | g | `gain` | drive gain (fixed by default) | N/unit(u) | 1 |
//!
//! References: M. Gautier, W. Khalil, "Direct calculation of minimum set of inertial
//! parameters of serial robots", IEEE Trans. Robotics and Automation 6(3), 1990 (the friction
//! model); A. Janot, M. Gautier, M. Brunot, "Data set and reference models of EMPS", 2019.

use super::coulomb_direction;
use crate::data::Channel;
use crate::model::greybox::StateSpaceModel;
use crate::model::{Parameter, ParameterSet};

/// The rigid body with friction (see the module docs).
#[derive(Clone, Copy, Debug, Default)]
pub struct RigidBody;

const M: usize = 0;
const FV: usize = 1;
const FC: usize = 2;
const OFFSET: usize = 3;
const GAIN: usize = 4;

impl StateSpaceModel for RigidBody {
    fn kind(&self) -> &'static str {
        "rigid_body"
    }

    fn states(&self) -> Vec<Channel> {
        vec![
            Channel::new("q").with_unit("m"),
            Channel::new("qd").with_unit("m/s"),
        ]
    }

    fn inputs(&self) -> Vec<Channel> {
        vec![Channel::new("u")]
    }

    fn outputs(&self) -> Vec<Channel> {
        vec![Channel::new("q").with_unit("m")]
    }

    fn parameters(&self) -> ParameterSet {
        ParameterSet::new(vec![
            Parameter::new("M", 1.0)
                .unit("kg")
                .bounds(1e-12, f64::INFINITY),
            // Friction dissipates: Fv ≥ 0, Fc ≥ 0.
            Parameter::new("Fv", 0.0)
                .unit("N*s/m")
                .bounds(0.0, f64::INFINITY),
            Parameter::new("Fc", 0.0)
                .unit("N")
                .bounds(0.0, f64::INFINITY),
            Parameter::new("offset", 0.0).unit("N"),
            Parameter::new("gain", 1.0).fixed(true),
        ])
        .expect("unique names")
    }

    fn rhs(&self, _t: f64, x: &[f64], u: &[f64], th: &[f64], dx: &mut [f64]) {
        let v = x[1];
        dx[0] = v;
        dx[1] = acceleration(v, u[0], th, None).map_or(0.0, |(acc, _)| acc);
    }

    fn rhs_sliding(&self, _t: f64, x: &[f64], u: &[f64], th: &[f64], d: f64, dx: &mut [f64]) {
        dx[0] = x[1];
        dx[1] = acceleration(x[1], u[0], th, Some(d)).map_or(0.0, |(acc, _)| acc);
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
        jacobians(x, u, th, None, fx, ft);
        true
    }

    fn rhs_jacobians_sliding(
        &self,
        _t: f64,
        x: &[f64],
        u: &[f64],
        th: &[f64],
        d: f64,
        fx: &mut [f64],
        ft: &mut [f64],
    ) -> bool {
        jacobians(x, u, th, Some(d), fx, ft);
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

    fn mechanical_dofs(&self) -> Option<usize> {
        Some(1)
    }

    fn stick_slip_velocity(&self) -> Option<usize> {
        Some(1)
    }
}

/// (q̈, friction direction) at velocity v and input u, or None while friction holds the body
/// at rest; `held` forces the friction direction (inside a sliding RK4 step, see
/// [`crate::model::greybox::stick_slip`]).
#[inline]
fn acceleration(v: f64, u: f64, th: &[f64], held: Option<f64>) -> Option<(f64, f64)> {
    let applied = th[GAIN] * u - th[FV] * v - th[OFFSET];
    held.or_else(|| coulomb_direction(v, applied, th[FC]))
        .map(|s| ((applied - th[FC] * s) / th[M], s))
}

/// ∂f/∂x and ∂f/∂θ; while the body sticks its acceleration is identically zero (row 1 zero).
fn jacobians(x: &[f64], u: &[f64], th: &[f64], held: Option<f64>, fx: &mut [f64], ft: &mut [f64]) {
    let v = x[1];
    let m = th[M];
    let p = th.len();
    fx.fill(0.0);
    ft.fill(0.0);
    fx[1] = 1.0;
    if let Some((acc, s)) = acceleration(v, u[0], th, held) {
        fx[3] = -th[FV] / m;
        ft[p + M] = -acc / m;
        ft[p + FV] = -v / m;
        ft[p + FC] = -s / m;
        ft[p + OFFSET] = -1.0 / m;
        ft[p + GAIN] = u[0] / m;
    }
}
