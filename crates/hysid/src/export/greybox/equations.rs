//! Equation-file models (`hysid-equations`): f and h printed from the model's compiled
//! listing ([`hysid_equations::Listing`]), one local per operation in the order the
//! library's tape performs them, with its scalar semantics — `min`/`max` taking the first
//! argument on ties, `sign 0 = 0`, truth values 1 and 0, `pow(a, 1) = a` and
//! `pow(a, 0) = 1`, integer powers by the same multiplications — and the fitted parameters
//! as literals.

use super::{sign0, EmitStateSpace, Point};
use crate::export::code::{lit, local, select, Block, Expr, Math};
use crate::model::greybox::equation_model::EquationStateSpace;
use crate::model::greybox::StateSpaceModel;
use hysid_equations::{Fn1, Fn2, Listing, Operand, Operation};

/// An equation-file model with its parameter values θ.
pub struct Equations {
    model: EquationStateSpace,
    theta: Vec<f64>,
}

impl Equations {
    /// The model `model` with the values `theta` (in the file's order).
    pub fn new(model: EquationStateSpace, theta: Vec<f64>) -> Self {
        Self { model, theta }
    }
}

impl EmitStateSpace for Equations {
    fn model(&self) -> &dyn StateSpaceModel {
        &self.model
    }
    fn emit_rhs(&self, b: &mut Block, at: &Point, _held: Option<Expr>) -> Vec<Expr> {
        let listing = self.model.equations().rhs_listing();
        emit(b, &listing, "f", at, &self.theta)
    }
    fn emit_output(&self, b: &mut Block, at: &Point) -> Vec<Expr> {
        let listing = self.model.equations().output_listing();
        emit(b, &listing, "h", at, &self.theta)
    }
}

/// Emits the operations of `listing` as locals `{prefix}{k}`; returns its results.
fn emit(b: &mut Block, listing: &Listing, prefix: &str, at: &Point, theta: &[f64]) -> Vec<Expr> {
    let operand = |o: &Operand| -> Expr {
        match *o {
            Operand::Time => at.t.clone(),
            Operand::State(i) => at.x[i].clone(),
            Operand::Input(i) => at.u[i].clone(),
            Operand::Parameter(i) => lit(theta.get(i).copied().unwrap_or(f64::NAN)),
            Operand::Constant(v) => lit(v),
            Operand::Value(k) => local(&format!("{prefix}{k}")),
        }
    };
    for (k, op) in listing.operations.iter().enumerate() {
        let name = format!("{prefix}{k}");
        let value = match op {
            Operation::Neg(a) => -operand(a),
            Operation::Unary(f, a) => unary(*f, operand(a)),
            Operation::Binary(f, a, b) => binary(*f, operand(a), operand(b)),
            Operation::Powi(a, n) => powi(b, &name, operand(a), *n),
            Operation::Not(a) => truth(operand(a).eq(0.0)),
            Operation::Select(c, a, e) => select(operand(c).ne(0.0), operand(a), operand(e)),
        };
        b.let_(&name, value);
    }
    listing.results.iter().map(operand).collect()
}

/// 1 where `c` holds, else 0.
fn truth(c: Expr) -> Expr {
    select(c, 1.0, 0.0)
}

/// f(a) (`num::apply1`).
fn unary(f: Fn1, a: Expr) -> Expr {
    let math = |m: Math| Expr::Math(m, vec![a.clone()]);
    match f {
        Fn1::Sin => math(Math::Sin),
        Fn1::Cos => math(Math::Cos),
        Fn1::Tan => math(Math::Tan),
        Fn1::Exp => math(Math::Exp),
        Fn1::Ln => math(Math::Log),
        Fn1::Sqrt => math(Math::Sqrt),
        Fn1::Abs => math(Math::Fabs),
        Fn1::Sign => sign0(a),
        Fn1::Tanh => math(Math::Tanh),
        Fn1::Atan => math(Math::Atan),
        Fn1::FiniteOr0 => select(a.clone().is_finite(), a, 0.0),
    }
}

/// f(a, b) (`num::apply2`).
fn binary(f: Fn2, a: Expr, b: Expr) -> Expr {
    match f {
        Fn2::Add => a + b,
        Fn2::Sub => a - b,
        Fn2::Mul => a * b,
        Fn2::Div => a / b,
        Fn2::Pow => match b {
            Expr::F64(1.0) => a,
            Expr::F64(0.0) => lit(1.0),
            Expr::F64(_) => a.powf(b),
            _ => select(
                b.clone().eq(1.0),
                a.clone(),
                select(b.clone().eq(0.0), 1.0, a.powf(b)),
            ),
        },
        Fn2::Min => select(a.clone().le(b.clone()), a, b),
        Fn2::Max => select(a.clone().ge(b.clone()), a, b),
        Fn2::Lt => truth(a.lt(b)),
        Fn2::Le => truth(a.le(b)),
        Fn2::Eq => truth(a.eq(b)),
        Fn2::Ne => truth(a.ne(b)),
        Fn2::And => truth(a.ne(0.0).and(b.ne(0.0))),
        Fn2::Or => truth(a.ne(0.0).or(b.ne(0.0))),
    }
}

/// aⁿ by the multiplications of `num::powi` (its squares as locals `{name}_s{i}`).
fn powi(b: &mut Block, name: &str, a: Expr, n: i32) -> Expr {
    match n {
        0 => lit(1.0),
        1 => a,
        2 => a.clone() * a,
        3 => a.clone() * a.clone() * a,
        4 => {
            let s = b.let_(&format!("{name}_s"), a.clone() * a);
            s.clone() * s
        }
        _ => {
            let mut e = n.unsigned_abs();
            let (mut base, mut acc) = (a, lit(1.0));
            let mut i = 0;
            while e > 0 {
                if e & 1 == 1 {
                    acc = b.let_(&format!("{name}_a{i}"), acc * base.clone());
                }
                e >>= 1;
                if e > 0 {
                    base = b.let_(&format!("{name}_b{i}"), base.clone() * base);
                }
                i += 1;
            }
            if n < 0 {
                1.0 / acc
            } else {
                acc
            }
        }
    }
}
