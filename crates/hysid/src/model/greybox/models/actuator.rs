//! The two-mass linear actuator with a Dhaouadi hysteresis in its flexibility (Gunnar,
//! Wernholt, Hovland & Brogårdh 2006).
//!
//! # Equations (docs/models/actuator.md §1, SEED)
//!
//! States x1 = θ − z/r (torsion of the flexibility), x2 = θ̇ (motor speed), x3 = ż (saddle
//! speed), x4 (hysteresis torque); input τ (motor torque); output x1.
//!
//! ```text
//! ẋ1 = x2 − x3/r
//! ẋ2 = (−Fv x2 − Fc sgn(x2) − g(x) + τ)/J
//! ẋ3 = g(x)/(r m)
//! ẋ4 = −α|x2 − x3/r| x4 + A (x2 − x3/r)
//! g(x) = k1 x1 + k2 x1³ + x4
//! ```
//!
//! Coulomb friction at rest holds the motor while |τ − g| ≤ Fc (stick–slip, integrated by
//! [`crate::model::greybox::stick_slip`]; sgn(0) is otherwise undefined and a plain integrator
//! chatters there).
//!
//! With the saddle fixed (x3 = 0; steps 2 and 3 of the paper) the states are (x1, x2, x4):
//! ẋ1 = x2, ẋ2 = (−Fv x2 − Fc sgn(x2) − g + τ)/J, ẋ4 = −α|x2|x4 + A x2.
//!
//! | symbol | name | meaning | unit | default (Table I, m67) |
//! | --- | --- | --- | --- | --- |
//! | J | `J` | motor-side inertia | N·m·s² | 4.991·10⁻⁴ |
//! | Fv | `Fv` | viscous friction | N·m·s | 1.413·10⁻³ |
//! | Fc | `Fc` | Coulomb friction | N·m | 2.065·10⁻¹ |
//! | k1 | `k1` | linear stiffness | N·m/rad | 11.31 |
//! | k2 | `k2` | cubic stiffness | N·m/rad³ | 144.3 |
//! | α | `alpha` | hysteresis rate | 1/rad | 112.50 |
//! | A | `A` | hysteresis stiffness | N·m/rad | 42.49 |
//! | r | `r` | gear ratio (saddle free; known, fixed) | m/rad | 1.867·10⁻³ |
//! | m | `m` | saddle mass (saddle free; known, fixed) | kg | 1.2 |

use super::{coulomb_direction, sign0};
use crate::data::Channel;
use crate::model::greybox::StateSpaceModel;
use crate::model::{Parameter, ParameterSet};

/// The actuator with the saddle fixed: states (x1, x2, x4).
#[derive(Clone, Copy, Debug, Default)]
pub struct ActuatorFixed;

/// The actuator with the saddle free: states (x1, x2, x3, x4).
#[derive(Clone, Copy, Debug, Default)]
pub struct ActuatorFree;

const J: usize = 0;
const FV: usize = 1;
const FC: usize = 2;
const K1: usize = 3;
const K2: usize = 4;
const ALPHA: usize = 5;
const A: usize = 6;
const R: usize = 7;
const M: usize = 8;

/// The seven physical parameters with Table I's m67 values.
fn actuator_parameters() -> Vec<Parameter> {
    vec![
        Parameter::new("J", 4.991e-4)
            .unit("N*m*s^2")
            .bounds(1e-12, f64::INFINITY),
        Parameter::new("Fv", 1.413e-3)
            .unit("N*m*s")
            .bounds(0.0, f64::INFINITY),
        Parameter::new("Fc", 2.065e-1)
            .unit("N*m")
            .bounds(0.0, f64::INFINITY),
        Parameter::new("k1", 11.31).unit("N*m/rad"),
        Parameter::new("k2", 144.3).unit("N*m/rad^3"),
        Parameter::new("alpha", 112.50)
            .unit("1/rad")
            .bounds(0.0, f64::INFINITY),
        Parameter::new("A", 42.49).unit("N*m/rad"),
    ]
}

/// (ẋ2, friction direction) at motor speed x2, flexibility torque g and input τ, or None
/// while Coulomb friction holds the motor at rest; `held` forces the friction direction
/// (inside a sliding RK4 step, see [`crate::model::greybox::stick_slip`]).
#[inline]
fn motor_acceleration(
    th: &[f64],
    x2: f64,
    g: f64,
    tau: f64,
    held: Option<f64>,
) -> Option<(f64, f64)> {
    let applied = tau - g - th[FV] * x2;
    held.or_else(|| coulomb_direction(x2, applied, th[FC]))
        .map(|s| ((applied - th[FC] * s) / th[J], s))
}

/// Row ẋ2 = (τ − Fv x2 − Fc s − g)/J of ∂f/∂x (`fx_row`; `columns` are the places of x1,
/// x2 and x4 in the state) and of ∂f/∂θ (`ft_row`), for the motion (ẋ2, s) of
/// [`motor_acceleration`].
#[allow(clippy::too_many_arguments)]
fn motor_row(
    th: &[f64],
    x1: f64,
    x2: f64,
    dg: f64,
    (acc, s): (f64, f64),
    [c1, c2, c4]: [usize; 3],
    fx_row: &mut [f64],
    ft_row: &mut [f64],
) {
    let j = th[J];
    fx_row[c1] = -dg / j;
    fx_row[c2] = -th[FV] / j;
    fx_row[c4] = -1.0 / j;
    ft_row[J] = -acc / j;
    ft_row[FV] = -x2 / j;
    ft_row[FC] = -s / j;
    ft_row[K1] = -x1 / j;
    ft_row[K2] = -x1.powi(3) / j;
}

/// The flexibility torque g = k1 x1 + k2 x1³ + x4 and its derivative ∂g/∂x1.
#[inline]
fn flexibility(th: &[f64], x1: f64, x4: f64) -> (f64, f64) {
    (
        th[K1] * x1 + th[K2] * x1.powi(3) + x4,
        th[K1] + 3.0 * th[K2] * x1 * x1,
    )
}

impl StateSpaceModel for ActuatorFixed {
    fn kind(&self) -> &'static str {
        "actuator_fixed"
    }

    fn states(&self) -> Vec<Channel> {
        vec![
            Channel::new("x1").with_unit("rad"),
            Channel::new("x2").with_unit("rad/s"),
            Channel::new("x4").with_unit("N*m"),
        ]
    }

    fn inputs(&self) -> Vec<Channel> {
        vec![Channel::new("tau").with_unit("N*m")]
    }

    fn outputs(&self) -> Vec<Channel> {
        vec![Channel::new("x1").with_unit("rad")]
    }

    fn parameters(&self) -> ParameterSet {
        ParameterSet::new(actuator_parameters()).expect("unique names")
    }

    fn rhs(&self, _t: f64, x: &[f64], u: &[f64], th: &[f64], dx: &mut [f64]) {
        fixed_rhs(x, u, th, None, dx);
    }

    fn rhs_sliding(&self, _t: f64, x: &[f64], u: &[f64], th: &[f64], d: f64, dx: &mut [f64]) {
        fixed_rhs(x, u, th, Some(d), dx);
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
        fixed_jacobians(x, u, th, None, fx, ft);
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
        fixed_jacobians(x, u, th, Some(d), fx, ft);
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

/// The saddle-fixed right-hand side; with `held` = Some(d) the motion is taken to be in
/// direction d (friction and |x2| of the hysteresis on that branch).
fn fixed_rhs(x: &[f64], u: &[f64], th: &[f64], held: Option<f64>, dx: &mut [f64]) {
    let (x1, x2, x4) = (x[0], x[1], x[2]);
    let (g, _) = flexibility(th, x1, x4);
    let speed = held.map_or(x2.abs(), |d| d * x2);
    dx[0] = x2;
    dx[1] = motor_acceleration(th, x2, g, u[0], held).map_or(0.0, |(acc, _)| acc);
    dx[2] = -th[ALPHA] * speed * x4 + th[A] * x2;
}

/// ∂f/∂x and ∂f/∂θ of [`fixed_rhs`].
fn fixed_jacobians(
    x: &[f64],
    u: &[f64],
    th: &[f64],
    held: Option<f64>,
    fx: &mut [f64],
    ft: &mut [f64],
) {
    let (x1, x2, x4) = (x[0], x[1], x[2]);
    let (g, dg) = flexibility(th, x1, x4);
    let p = th.len();
    let direction = held.unwrap_or(sign0(x2));
    let speed = direction * x2;
    fx.fill(0.0);
    ft.fill(0.0);
    fx[1] = 1.0;
    fx[7] = -th[ALPHA] * direction * x4 + th[A];
    fx[8] = -th[ALPHA] * speed;
    // While the motor sticks ẋ2 is identically zero: row 1 stays zero.
    if let Some(motion) = motor_acceleration(th, x2, g, u[0], held) {
        motor_row(
            th,
            x1,
            x2,
            dg,
            motion,
            [0, 1, 2],
            &mut fx[3..6],
            &mut ft[p..2 * p],
        );
    }
    ft[2 * p + ALPHA] = -speed * x4;
    ft[2 * p + A] = x2;
}

impl StateSpaceModel for ActuatorFree {
    fn kind(&self) -> &'static str {
        "actuator_free"
    }

    fn states(&self) -> Vec<Channel> {
        vec![
            Channel::new("x1").with_unit("rad"),
            Channel::new("x2").with_unit("rad/s"),
            Channel::new("x3").with_unit("m/s"),
            Channel::new("x4").with_unit("N*m"),
        ]
    }

    fn inputs(&self) -> Vec<Channel> {
        vec![Channel::new("tau").with_unit("N*m")]
    }

    fn outputs(&self) -> Vec<Channel> {
        vec![Channel::new("x1").with_unit("rad")]
    }

    fn parameters(&self) -> ParameterSet {
        let mut p = actuator_parameters();
        p.push(
            Parameter::new("r", 1.867e-3)
                .unit("m/rad")
                .bounds(1e-12, f64::INFINITY)
                .fixed(true),
        );
        p.push(
            Parameter::new("m", 1.2)
                .unit("kg")
                .bounds(1e-12, f64::INFINITY)
                .fixed(true),
        );
        ParameterSet::new(p).expect("unique names")
    }

    fn rhs(&self, _t: f64, x: &[f64], u: &[f64], th: &[f64], dx: &mut [f64]) {
        free_rhs(x, u, th, None, dx);
    }

    fn rhs_sliding(&self, _t: f64, x: &[f64], u: &[f64], th: &[f64], d: f64, dx: &mut [f64]) {
        free_rhs(x, u, th, Some(d), dx);
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
        free_jacobians(x, u, th, None, fx, ft);
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
        free_jacobians(x, u, th, Some(d), fx, ft);
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

    fn stick_slip_velocity(&self) -> Option<usize> {
        Some(1)
    }
}

/// The saddle-free right-hand side; `held` as in [`fixed_rhs`] (the hysteresis follows the
/// torsion rate w = x2 − x3/r, which the friction direction does not hold).
fn free_rhs(x: &[f64], u: &[f64], th: &[f64], held: Option<f64>, dx: &mut [f64]) {
    let (x1, x2, x3, x4) = (x[0], x[1], x[2], x[3]);
    let (g, _) = flexibility(th, x1, x4);
    let w = x2 - x3 / th[R];
    dx[0] = w;
    dx[1] = motor_acceleration(th, x2, g, u[0], held).map_or(0.0, |(acc, _)| acc);
    dx[2] = g / (th[R] * th[M]);
    dx[3] = -th[ALPHA] * w.abs() * x4 + th[A] * w;
}

/// ∂f/∂x and ∂f/∂θ of [`free_rhs`].
fn free_jacobians(
    x: &[f64],
    u: &[f64],
    th: &[f64],
    held: Option<f64>,
    fx: &mut [f64],
    ft: &mut [f64],
) {
    let (x1, x2, x3, x4) = (x[0], x[1], x[2], x[3]);
    let (g, dg) = flexibility(th, x1, x4);
    let (r, m) = (th[R], th[M]);
    let w = x2 - x3 / r;
    let dw = -th[ALPHA] * sign0(w) * x4 + th[A]; // ∂ẋ4/∂w
    let p = th.len();
    fx.fill(0.0);
    ft.fill(0.0);
    // Row 0: ẋ1 = x2 − x3/r.
    fx[1] = 1.0;
    fx[2] = -1.0 / r;
    ft[R] = x3 / (r * r);
    // Row 1: ẋ2 (identically zero while the motor sticks).
    if let Some(motion) = motor_acceleration(th, x2, g, u[0], held) {
        motor_row(
            th,
            x1,
            x2,
            dg,
            motion,
            [0, 1, 3],
            &mut fx[4..8],
            &mut ft[p..2 * p],
        );
    }
    // Row 2: ẋ3 = g/(r m).
    fx[8] = dg / (r * m);
    fx[11] = 1.0 / (r * m);
    ft[2 * p + K1] = x1 / (r * m);
    ft[2 * p + K2] = x1.powi(3) / (r * m);
    ft[2 * p + R] = -g / (r * r * m);
    ft[2 * p + M] = -g / (r * m * m);
    // Row 3: ẋ4 = −α|w|x4 + A w.
    fx[13] = dw;
    fx[14] = -dw / r;
    fx[15] = -th[ALPHA] * w.abs();
    ft[3 * p + ALPHA] = -w.abs() * x4;
    ft[3 * p + A] = w;
    ft[3 * p + R] = dw * x3 / (r * r);
}
