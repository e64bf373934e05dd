//! A rigid body with viscous and Coulomb friction and a constant force offset.
//!
//! # Equations
//!
//! ```text
//! M q̈ + Fv q̇ + Fc sgn(q̇) + offset = g·u
//! ```
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

use super::sign0;
use crate::data::Channel;
use crate::estimate::{Parameter, ParameterSet};
use crate::greybox::StateSpaceModel;

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
            Parameter::new("Fv", 0.0).unit("N*s/m"),
            Parameter::new("Fc", 0.0).unit("N"),
            Parameter::new("offset", 0.0).unit("N"),
            Parameter::new("gain", 1.0).fixed(true),
        ])
        .expect("unique names")
    }

    fn rhs(&self, _t: f64, x: &[f64], u: &[f64], th: &[f64], dx: &mut [f64]) {
        let v = x[1];
        dx[0] = v;
        dx[1] = (th[GAIN] * u[0] - th[FV] * v - th[FC] * sign0(v) - th[OFFSET]) / th[M];
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
        let v = x[1];
        let m = th[M];
        let p = th.len();
        fx.fill(0.0);
        ft.fill(0.0);
        fx[1] = 1.0;
        fx[3] = -th[FV] / m;
        let acc = (th[GAIN] * u[0] - th[FV] * v - th[FC] * sign0(v) - th[OFFSET]) / m;
        ft[p + M] = -acc / m;
        ft[p + FV] = -v / m;
        ft[p + FC] = -sign0(v) / m;
        ft[p + OFFSET] = -1.0 / m;
        ft[p + GAIN] = u[0] / m;
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
}
