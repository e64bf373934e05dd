//! A tape as a listing: the operations that compute f or h, in the order the tape performs
//! them, each reading the time, a state, an input, a parameter, a constant or the value of an
//! earlier operation. A code generator prints it statement by statement and so computes
//! what the tape computes, operation for operation ([`EquationModel::rhs_listing`]).
//!
//! [`EquationModel::rhs_listing`]: crate::EquationModel::rhs_listing

use crate::num::{Fn1, Fn2};
use crate::tape::{Instr, Tape};

/// What an operation reads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Operand {
    /// The time t (0 in an output listing, which never reads it).
    Time,
    /// State `i` (the order of [`EquationModel::states`](crate::EquationModel::states)).
    State(usize),
    /// Input `i`.
    Input(usize),
    /// Parameter `i` (the order of θ).
    Parameter(usize),
    /// A constant.
    Constant(f64),
    /// The value of operation `k` of the listing (always an earlier one).
    Value(usize),
}

/// One operation, with the scalar semantics of the tape: [`Operation::Unary`] and
/// [`Operation::Binary`] as [`apply1`](crate::apply1) and [`apply2`](crate::apply2) compute
/// them (truth values are 1 and 0), [`Operation::Powi`] as [`powi`](crate::powi).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Operation {
    /// −a
    Neg(Operand),
    /// f(a)
    Unary(Fn1, Operand),
    /// f(a, b)
    Binary(Fn2, Operand, Operand),
    /// aⁿ by multiplications.
    Powi(Operand, i32),
    /// 1 where a = 0, else 0.
    Not(Operand),
    /// a where c ≠ 0, else b: `Select(c, a, b)`.
    Select(Operand, Operand, Operand),
}

/// The operations of a tape in its order and the operands holding its results (f: one per
/// state; h: one per output).
#[derive(Clone, Debug, PartialEq)]
pub struct Listing {
    /// The operations; operation k may read the values of operations 0 … k − 1.
    pub operations: Vec<Operation>,
    /// The results, in the order of the states (or outputs).
    pub results: Vec<Operand>,
}

/// The listing of `tape` over the input slots t, `n_states` states, `n_inputs` inputs and
/// the parameters. A fused instruction (of a bound tape) is listed as the two operations it
/// performs.
pub(crate) fn of(tape: &Tape, n_states: usize, n_inputs: usize) -> Listing {
    let (inputs, consts, code) = tape.parts();
    let first = inputs + consts.len();
    // The listing's operation holding each instruction's value.
    let mut value_of: Vec<usize> = Vec::with_capacity(code.len());
    let operand = |r: u32, value_of: &[usize]| -> Operand {
        let r = r as usize;
        match r {
            0 => Operand::Time,
            _ if r <= n_states => Operand::State(r - 1),
            _ if r <= n_states + n_inputs => Operand::Input(r - 1 - n_states),
            _ if r < inputs => Operand::Parameter(r - 1 - n_states - n_inputs),
            _ if r < first => Operand::Constant(consts[r - inputs]),
            _ => Operand::Value(value_of[r - first]),
        }
    };
    let mut operations: Vec<Operation> = Vec::with_capacity(code.len());
    for &instr in code {
        let o = |r: u32| operand(r, &value_of);
        let un = |f: Fn1, a: u32| Operation::Unary(f, o(a));
        let bin = |f: Fn2, a: u32, b: u32| Operation::Binary(f, o(a), o(b));
        // A fused pair: the inner operation, then the outer one reading it.
        let pair = |inner: Operation, outer: &dyn Fn(Operand) -> Operation| {
            let at = Operand::Value(operations.len());
            [inner, outer(at)]
        };
        let listed: Vec<Operation> = match instr {
            Instr::Neg(a) => vec![Operation::Neg(o(a))],
            Instr::Sin(a) => vec![un(Fn1::Sin, a)],
            Instr::Cos(a) => vec![un(Fn1::Cos, a)],
            Instr::Tan(a) => vec![un(Fn1::Tan, a)],
            Instr::Exp(a) => vec![un(Fn1::Exp, a)],
            Instr::Ln(a) => vec![un(Fn1::Ln, a)],
            Instr::Sqrt(a) => vec![un(Fn1::Sqrt, a)],
            Instr::Abs(a) => vec![un(Fn1::Abs, a)],
            Instr::Sign(a) => vec![un(Fn1::Sign, a)],
            Instr::Tanh(a) => vec![un(Fn1::Tanh, a)],
            Instr::Atan(a) => vec![un(Fn1::Atan, a)],
            Instr::FiniteOr0(a) => vec![un(Fn1::FiniteOr0, a)],
            Instr::Add(a, b) => vec![bin(Fn2::Add, a, b)],
            Instr::Sub(a, b) => vec![bin(Fn2::Sub, a, b)],
            Instr::Mul(a, b) => vec![bin(Fn2::Mul, a, b)],
            Instr::Div(a, b) => vec![bin(Fn2::Div, a, b)],
            Instr::Pow(a, b) => vec![bin(Fn2::Pow, a, b)],
            Instr::Min(a, b) => vec![bin(Fn2::Min, a, b)],
            Instr::Max(a, b) => vec![bin(Fn2::Max, a, b)],
            Instr::Lt(a, b) => vec![bin(Fn2::Lt, a, b)],
            Instr::Le(a, b) => vec![bin(Fn2::Le, a, b)],
            Instr::Eq(a, b) => vec![bin(Fn2::Eq, a, b)],
            Instr::Ne(a, b) => vec![bin(Fn2::Ne, a, b)],
            Instr::And(a, b) => vec![bin(Fn2::And, a, b)],
            Instr::Or(a, b) => vec![bin(Fn2::Or, a, b)],
            Instr::Square(a) => vec![Operation::Powi(o(a), 2)],
            Instr::Cube(a) => vec![Operation::Powi(o(a), 3)],
            Instr::Powi(a, n) => vec![Operation::Powi(o(a), n)],
            Instr::Not(a) => vec![Operation::Not(o(a))],
            Instr::Select(c, a, b) => vec![Operation::Select(o(c), o(a), o(b))],
            Instr::MulAdd(a, b, c) => pair(bin(Fn2::Mul, a, b), &|p| {
                Operation::Binary(Fn2::Add, p, o(c))
            })
            .to_vec(),
            Instr::MulSub(a, b, c) => pair(bin(Fn2::Mul, a, b), &|p| {
                Operation::Binary(Fn2::Sub, p, o(c))
            })
            .to_vec(),
            Instr::SubMul(c, a, b) => pair(bin(Fn2::Mul, a, b), &|p| {
                Operation::Binary(Fn2::Sub, o(c), p)
            })
            .to_vec(),
            Instr::Mul3(a, b, c) => pair(bin(Fn2::Mul, a, b), &|p| {
                Operation::Binary(Fn2::Mul, p, o(c))
            })
            .to_vec(),
            Instr::NegMul(a, b) => pair(bin(Fn2::Mul, a, b), &Operation::Neg).to_vec(),
            Instr::NegDiv(a, b) => pair(Operation::Neg(o(a)), &|p| {
                Operation::Binary(Fn2::Div, p, o(b))
            })
            .to_vec(),
        };
        operations.extend(listed);
        value_of.push(operations.len() - 1);
    }
    Listing {
        operations,
        results: tape
            .outputs()
            .iter()
            .map(|&r| operand(r, &value_of))
            .collect(),
    }
}
