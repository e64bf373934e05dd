//! Operations of a listing as instructions of a block (`block.rs`), with the tape's scalar
//! semantics ([`hysid_equations::apply1`], [`hysid_equations::apply2`],
//! [`hysid_equations::powi`]): the arithmetic as scalar IEEE 754 instructions; `abs` and
//! negation as bit masks; comparisons, `min`, `max`, `sign`, `if`, `and`, `or`, `not` and the
//! finite-or-zero of derivatives as branch-free comparison masks (ties take the first
//! argument, NaN compares false, truth values 1 and 0); `pow` with its shortcuts (`a¹ = a`,
//! `a⁰ = 1`) inline and the library call otherwise; integer powers up to 4 by the same
//! multiplications; the other functions (`sin`, `exp`, `ln`, …) by calls of the functions
//! the tape calls. The constants they read are kept once each in a [`Pool`].

use super::asm::{pred, Gpr, Logic, Mem, Scalar};
use super::block::{self, Arg, Block, V};
use hysid_equations::{Fn1, Fn2, Operand, Operation};
use std::collections::HashMap;

/// 16-byte constants (a double and a zero, or a mask), each stored once.
#[derive(Default)]
pub(super) struct Pool {
    pub entries: Vec<[u64; 2]>,
    index: HashMap<[u64; 2], usize>,
}

impl Pool {
    fn entry(&mut self, pair: [u64; 2]) -> Mem {
        let n = self.entries.len();
        let i = *self.index.entry(pair).or_insert(n);
        if i == n {
            self.entries.push(pair);
        }
        Mem::at(Gpr::Rbx, 16 * i)
    }

    pub fn double(&mut self, v: f64) -> Mem {
        self.entry([v.to_bits(), 0])
    }

    /// |·|: every bit but the sign.
    fn abs_mask(&mut self) -> Mem {
        self.entry([!(1u64 << 63); 2])
    }

    /// −·: the sign bit.
    fn sign_mask(&mut self) -> Mem {
        self.entry([1u64 << 63, 0])
    }
}

/// `value` (operand `o`) made finite: 0 where infinite or NaN. A constant is folded.
pub(super) fn finite(block: &mut Block, pool: &mut Pool, value: Arg, o: &Operand) -> V {
    if let Operand::Constant(c) = *o {
        // A value of its own: the caller may accumulate into it.
        return block.fresh(pool.double(hysid_equations::apply1(Fn1::FiniteOr0, c)));
    }
    let v = block.in_value(value);
    finite_value(block, pool, v)
}

/// v where |v| < ∞, else +0.
fn finite_value(block: &mut Block, pool: &mut Pool, v: V) -> V {
    let abs = block.logic(Logic::And, Arg::V(v), Arg::Mem(pool.abs_mask()));
    let infinity = pool.double(f64::INFINITY);
    let is_finite = block.cmp(pred::LT_OQ, Arg::V(abs), Arg::Mem(infinity));
    block.logic(Logic::And, Arg::V(is_finite), Arg::V(v))
}

/// `mask ? a : b` (a mask of all ones or zeros).
fn select(block: &mut Block, mask: V, a: V, b: V) -> V {
    let keep = block.logic(Logic::And, Arg::V(mask), Arg::V(a));
    let other = block.logic(Logic::AndNot, Arg::V(mask), Arg::V(b));
    block.logic(Logic::Or, Arg::V(keep), Arg::V(other))
}

/// 1 where `mask`, else 0.
fn truth(block: &mut Block, pool: &mut Pool, mask: V) -> V {
    block.logic(Logic::And, Arg::V(mask), Arg::Mem(pool.double(1.0)))
}

/// Operation `op` as instructions of `block`, its operands read by `read`.
pub(super) fn lower(
    block: &mut Block,
    pool: &mut Pool,
    op: &Operation,
    mut read: impl FnMut(&Operand, &mut Pool) -> Arg,
) -> V {
    let zero = |pool: &mut Pool| Arg::Mem(pool.double(0.0));
    match *op {
        Operation::Neg(a) => {
            let a = read(&a, pool);
            block.logic(Logic::Xor, a, Arg::Mem(pool.sign_mask()))
        }
        Operation::Unary(f, a) => {
            let a = read(&a, pool);
            match f {
                Fn1::Abs => block.logic(Logic::And, a, Arg::Mem(pool.abs_mask())),
                Fn1::Sqrt => {
                    let a = block.in_value(a);
                    block.scalar(Scalar::Sqrt, Arg::V(a), Arg::V(a))
                }
                Fn1::FiniteOr0 => {
                    let a = block.in_value(a);
                    finite_value(block, pool, a)
                }
                Fn1::Sign => {
                    let a = block.in_value(a);
                    let positive = block.cmp(pred::GT_OQ, Arg::V(a), zero(pool));
                    let negative = block.cmp(pred::LT_OQ, Arg::V(a), zero(pool));
                    let one = block.logic(Logic::And, Arg::V(positive), Arg::Mem(pool.double(1.0)));
                    let minus =
                        block.logic(Logic::And, Arg::V(negative), Arg::Mem(pool.double(-1.0)));
                    block.logic(Logic::Or, Arg::V(one), Arg::V(minus))
                }
                Fn1::Sin | Fn1::Cos | Fn1::Tan | Fn1::Exp | Fn1::Ln | Fn1::Tanh | Fn1::Atan => {
                    block.call(unary(f), a, a)
                }
            }
        }
        Operation::Binary(f, a, b) => {
            let (a, b) = (read(&a, pool), read(&b, pool));
            match f {
                Fn2::Add => block.scalar(Scalar::Add, a, b),
                Fn2::Sub => block.scalar(Scalar::Sub, a, b),
                Fn2::Mul => block.scalar(Scalar::Mul, a, b),
                Fn2::Div => block.scalar(Scalar::Div, a, b),
                Fn2::Pow => {
                    let (one, zero) = (pool.double(1.0), pool.double(0.0));
                    block.pow(pow, a, b, one, zero)
                }
                Fn2::Min | Fn2::Max => {
                    let (a, b) = (block.in_value(a), block.in_value(b));
                    let p = if f == Fn2::Min {
                        pred::LE_OQ
                    } else {
                        pred::GE_OQ
                    };
                    let first = block.cmp(p, Arg::V(a), Arg::V(b));
                    select(block, first, a, b)
                }
                Fn2::Lt | Fn2::Le | Fn2::Eq | Fn2::Ne => {
                    let p = match f {
                        Fn2::Lt => pred::LT_OQ,
                        Fn2::Le => pred::LE_OQ,
                        Fn2::Eq => pred::EQ_OQ,
                        _ => pred::NEQ_UQ,
                    };
                    let mask = block.cmp(p, a, b);
                    truth(block, pool, mask)
                }
                Fn2::And | Fn2::Or => {
                    let ma = block.cmp(pred::NEQ_UQ, a, zero(pool));
                    let mb = block.cmp(pred::NEQ_UQ, b, zero(pool));
                    let op = if f == Fn2::And { Logic::And } else { Logic::Or };
                    let mask = block.logic(op, Arg::V(ma), Arg::V(mb));
                    truth(block, pool, mask)
                }
            }
        }
        // The multiplications of `hysid_equations::powi` for n ≤ 4, else its loop.
        Operation::Powi(a, n) => {
            let a = read(&a, pool);
            match n {
                0 => block.in_value(Arg::Mem(pool.double(1.0))),
                1 => block.in_value(a),
                2 => block.scalar(Scalar::Mul, a, a),
                3 => {
                    let square = block.scalar(Scalar::Mul, a, a);
                    block.scalar(Scalar::Mul, Arg::V(square), a)
                }
                4 => {
                    let square = block.scalar(Scalar::Mul, a, a);
                    block.scalar(Scalar::Mul, Arg::V(square), Arg::V(square))
                }
                _ => block.call(powi, a, Arg::Mem(pool.double(f64::from(n)))),
            }
        }
        Operation::Not(a) => {
            let a = read(&a, pool);
            let mask = block.cmp(pred::EQ_OQ, a, zero(pool));
            truth(block, pool, mask)
        }
        Operation::Select(c, a, b) => {
            let (c, a, b) = (read(&c, pool), read(&a, pool), read(&b, pool));
            let (a, b) = (block.in_value(a), block.in_value(b));
            let mask = block.cmp(pred::NEQ_UQ, c, zero(pool));
            select(block, mask, a, b)
        }
    }
}

/// The tape's aᵇ ([`hysid_equations::apply2`]) for generated code.
extern "C" fn pow(a: f64, b: f64) -> f64 {
    hysid_equations::apply2(Fn2::Pow, a, b)
}

/// The tape's aⁿ ([`hysid_equations::powi`]), n passed as a double.
extern "C" fn powi(a: f64, n: f64) -> f64 {
    hysid_equations::powi(a, n as i32)
}

/// The tape's f(a) ([`hysid_equations::apply1`]) for generated code (b unused).
fn unary(f: Fn1) -> block::Helper {
    macro_rules! helper {
        ($f:expr) => {{
            extern "C" fn helper(a: f64, _: f64) -> f64 {
                hysid_equations::apply1($f, a)
            }
            helper
        }};
    }
    match f {
        Fn1::Sin => helper!(Fn1::Sin),
        Fn1::Cos => helper!(Fn1::Cos),
        Fn1::Tan => helper!(Fn1::Tan),
        Fn1::Exp => helper!(Fn1::Exp),
        Fn1::Ln => helper!(Fn1::Ln),
        Fn1::Sqrt => helper!(Fn1::Sqrt),
        Fn1::Abs => helper!(Fn1::Abs),
        Fn1::Sign => helper!(Fn1::Sign),
        Fn1::Tanh => helper!(Fn1::Tanh),
        Fn1::Atan => helper!(Fn1::Atan),
        Fn1::FiniteOr0 => helper!(Fn1::FiniteOr0),
    }
}
