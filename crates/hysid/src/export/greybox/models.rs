//! The built-in grey-box models' right-hand sides and outputs (`model::greybox::models`),
//! operation for operation, with the fitted parameters as literals:
//!
//! * `bouc_wen`: ẏ = v, v̇ = (u − cL·v − kL·y − z)/mL,
//!   ż = α·v − βγ·|v|·sgn z·|z|^ν − βδ·v·|z|^ν (|z|^ν by multiplication for ν = 0, 1, 2);
//! * `rigid_body`: q̇ = v, v̇ = (g·u − Fv·v − offset − Fc·s)/M;
//! * `actuator_fixed` / `actuator_free`: the motor J·ẍ₂ = τ − g(x₁, x₄) − Fv·x₂ − Fc·s with
//!   g = k₁x₁ + k₂x₁³ + x₄, and the Dhaouadi state x₄ (the free saddle's x₃ and w as the
//!   library's).
//!
//! The Coulomb direction s is the held one inside a sliding RK4 step; otherwise sgn v while
//! moving, sgn(applied) on breaking away, and the acceleration is 0 while friction holds
//! the body (`models::coulomb_direction`). Every output is the first state.

use super::{sign0, EmitStateSpace, Point};
use crate::export::code::{lit, select, Block, Expr};
use crate::model::greybox::models::GreyBoxKind;
use crate::model::greybox::StateSpaceModel;

/// A built-in model with its parameter values θ.
pub struct BuiltIn {
    kind: GreyBoxKind,
    model: Box<dyn StateSpaceModel>,
    th: Vec<f64>,
}

impl BuiltIn {
    /// The model `kind` with the values `theta` (in the order of its parameters).
    pub fn new(kind: GreyBoxKind, theta: Vec<f64>) -> Self {
        Self {
            kind,
            model: kind.model(),
            th: theta,
        }
    }

    /// Parameter `i` (NaN when missing, which the program's check refuses).
    fn v(&self, i: usize) -> f64 {
        self.th.get(i).copied().unwrap_or(f64::NAN)
    }

    /// Parameter `i` as a literal.
    fn p(&self, i: usize) -> Expr {
        lit(self.v(i))
    }

    /// The Coulomb-friction acceleration (applied − Fc·s)/m for the velocity `v` (a
    /// state), 0 while friction holds the body at rest (`coulomb_direction`).
    fn friction(
        &self,
        b: &mut Block,
        applied: Expr,
        v: Expr,
        (fc, m): (usize, usize),
        held: Option<Expr>,
    ) -> Expr {
        let applied = b.let_("applied", applied);
        match held {
            Some(d) => (applied - self.p(fc) * d) / self.p(m),
            None => {
                let moving = v.clone().ne(0.0).or(applied.clone().abs().gt(self.p(fc)));
                let s = b.let_(
                    "s",
                    select(v.clone().ne(0.0), sign0(v), sign0(applied.clone())),
                );
                select(moving, (applied - self.p(fc) * s) / self.p(m), 0.0)
            }
        }
    }

    /// g = k₁x₁ + k₂x₁³ + x₄ (x₁³ as x₁·x₁·x₁, the value of `powi(3)`).
    fn flexibility(&self, x1: &Expr, x4: &Expr) -> Expr {
        let (k1, k2) = (self.p(actuator::K1), self.p(actuator::K2));
        let cube = x1.clone() * x1.clone() * x1.clone();
        k1 * x1.clone() + k2 * cube + x4.clone()
    }
}

/// Parameter indices of the Bouc–Wen oscillator (`bouc_wen.rs`).
mod bouc_wen {
    pub const ML: usize = 0;
    pub const CL: usize = 1;
    pub const KL: usize = 2;
    pub const ALPHA: usize = 3;
    pub const BG: usize = 4;
    pub const BD: usize = 5;
    pub const NU: usize = 6;
}

/// Parameter indices of the rigid body (`rigid_body.rs`).
mod rigid_body {
    pub const M: usize = 0;
    pub const FV: usize = 1;
    pub const FC: usize = 2;
    pub const OFFSET: usize = 3;
    pub const GAIN: usize = 4;
}

/// Parameter indices of the actuators (`actuator.rs`).
mod actuator {
    pub const J: usize = 0;
    pub const FV: usize = 1;
    pub const FC: usize = 2;
    pub const K1: usize = 3;
    pub const K2: usize = 4;
    pub const ALPHA: usize = 5;
    pub const A: usize = 6;
    pub const R: usize = 7;
    pub const M: usize = 8;
}

impl EmitStateSpace for BuiltIn {
    fn model(&self) -> &dyn StateSpaceModel {
        self.model.as_ref()
    }

    fn emit_rhs(&self, b: &mut Block, at: &Point, held: Option<Expr>) -> Vec<Expr> {
        let x = |i: usize| at.x[i].clone();
        let u = at.u[0].clone();
        match self.kind {
            GreyBoxKind::BoucWen => {
                use bouc_wen::*;
                let (y, v, z) = (x(0), x(1), x(2));
                let acc = (u - self.p(CL) * v.clone() - self.p(KL) * y - z.clone()) / self.p(ML);
                let nu = self.v(NU);
                let power = if nu == 1.0 {
                    z.clone().abs()
                } else if nu == 2.0 {
                    z.clone() * z.clone()
                } else if nu == 0.0 {
                    lit(1.0)
                } else {
                    z.clone().abs().powf(nu)
                };
                let a = b.let_("a", power);
                let sz = b.let_("sz", sign0(z));
                let dz = self.p(ALPHA) * v.clone()
                    - self.p(BG) * v.clone().abs() * sz * a.clone()
                    - self.p(BD) * v.clone() * a;
                vec![v, acc, dz]
            }
            GreyBoxKind::RigidBody => {
                use rigid_body::*;
                let v = x(1);
                let applied = self.p(GAIN) * u - self.p(FV) * v.clone() - self.p(OFFSET);
                let acc = self.friction(b, applied, v.clone(), (FC, M), held);
                vec![v, acc]
            }
            GreyBoxKind::ActuatorFixed => {
                use actuator::*;
                let (x1, x2, x4) = (x(0), x(1), x(2));
                let g = b.let_("g", self.flexibility(&x1, &x4));
                let speed = match &held {
                    Some(d) => d.clone() * x2.clone(),
                    None => x2.clone().abs(),
                };
                let applied = u - g - self.p(FV) * x2.clone();
                let acc = self.friction(b, applied, x2.clone(), (FC, J), held);
                let dx4 = lit(-self.v(ALPHA)) * speed * x4 + self.p(A) * x2.clone();
                vec![x2, acc, dx4]
            }
            GreyBoxKind::ActuatorFree => {
                use actuator::*;
                let (x1, x2, x3, x4) = (x(0), x(1), x(2), x(3));
                let g = b.let_("g", self.flexibility(&x1, &x4));
                let w = b.let_("w", x2.clone() - x3 / self.p(R));
                let applied = u - g.clone() - self.p(FV) * x2.clone();
                let acc = self.friction(b, applied, x2, (FC, J), held);
                let rm = self.v(R) * self.v(M);
                let dx3 = g / rm;
                let dx4 = lit(-self.v(ALPHA)) * w.clone().abs() * x4 + self.p(A) * w.clone();
                vec![w, acc, dx3, dx4]
            }
        }
    }

    fn emit_output(&self, _b: &mut Block, at: &Point) -> Vec<Expr> {
        vec![at.x[0].clone()]
    }
}
