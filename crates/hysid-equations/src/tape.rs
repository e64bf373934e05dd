//! The flat instruction tape: the live part of the graph for a set of results, compiled
//! once to instructions over a register file and evaluated without allocation.
//!
//! Register layout: the input slots (t, x, u, θ), then the constants, then one register per
//! instruction (instruction k writes register `first + k`). Every operand was computed
//! before it is read, because graph ids are a topological order.

use crate::dag::{Graph, Id, Op};
use crate::num::{self, Fn1, Fn2};

/// One instruction; operands are register numbers. One variant per operation (rather
/// than an operation code inside a variant) so that evaluation dispatches once.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Instr {
    Neg(u32),
    Sin(u32),
    Cos(u32),
    Tan(u32),
    Exp(u32),
    Ln(u32),
    Sqrt(u32),
    Abs(u32),
    Sign(u32),
    Tanh(u32),
    Atan(u32),
    FiniteOr0(u32),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Div(u32, u32),
    Pow(u32, u32),
    Min(u32, u32),
    Max(u32, u32),
    Lt(u32, u32),
    Le(u32, u32),
    Eq(u32, u32),
    Ne(u32, u32),
    And(u32, u32),
    Or(u32, u32),
    Square(u32),
    Cube(u32),
    Powi(u32, i32),
    Not(u32),
    Select(u32, u32, u32),
}

impl Instr {
    fn unary(f: Fn1, a: u32) -> Instr {
        match f {
            Fn1::Sin => Instr::Sin(a),
            Fn1::Cos => Instr::Cos(a),
            Fn1::Tan => Instr::Tan(a),
            Fn1::Exp => Instr::Exp(a),
            Fn1::Ln => Instr::Ln(a),
            Fn1::Sqrt => Instr::Sqrt(a),
            Fn1::Abs => Instr::Abs(a),
            Fn1::Sign => Instr::Sign(a),
            Fn1::Tanh => Instr::Tanh(a),
            Fn1::Atan => Instr::Atan(a),
            Fn1::FiniteOr0 => Instr::FiniteOr0(a),
        }
    }

    fn binary(f: Fn2, a: u32, b: u32) -> Instr {
        match f {
            Fn2::Add => Instr::Add(a, b),
            Fn2::Sub => Instr::Sub(a, b),
            Fn2::Mul => Instr::Mul(a, b),
            Fn2::Div => Instr::Div(a, b),
            Fn2::Pow => Instr::Pow(a, b),
            Fn2::Min => Instr::Min(a, b),
            Fn2::Max => Instr::Max(a, b),
            Fn2::Lt => Instr::Lt(a, b),
            Fn2::Le => Instr::Le(a, b),
            Fn2::Eq => Instr::Eq(a, b),
            Fn2::Ne => Instr::Ne(a, b),
            Fn2::And => Instr::And(a, b),
            Fn2::Or => Instr::Or(a, b),
        }
    }

    /// The operand registers, for dead-code elimination and renumbering.
    fn operands_mut(&mut self) -> Vec<&mut u32> {
        use Instr::*;
        match self {
            Neg(a)
            | Sin(a)
            | Cos(a)
            | Tan(a)
            | Exp(a)
            | Ln(a)
            | Sqrt(a)
            | Abs(a)
            | Sign(a)
            | Tanh(a)
            | Atan(a)
            | FiniteOr0(a)
            | Square(a)
            | Cube(a)
            | Powi(a, _)
            | Not(a) => {
                vec![a]
            }
            Add(a, b)
            | Sub(a, b)
            | Mul(a, b)
            | Div(a, b)
            | Pow(a, b)
            | Min(a, b)
            | Max(a, b)
            | Lt(a, b)
            | Le(a, b)
            | Eq(a, b)
            | Ne(a, b)
            | And(a, b)
            | Or(a, b) => {
                vec![a, b]
            }
            Select(c, a, b) => vec![c, a, b],
        }
    }

    fn power(a: u32, n: i32) -> Instr {
        match n {
            2 => Instr::Square(a),
            3 => Instr::Cube(a),
            _ => Instr::Powi(a, n),
        }
    }
}

/// A compiled tape.
#[derive(Clone, Debug, PartialEq)]
pub struct Tape {
    inputs: usize,
    consts: Vec<f64>,
    code: Vec<Instr>,
    outputs: Vec<u32>,
}

impl Tape {
    /// The tape computing `roots` of `g` over `inputs` input slots (every `Var` of the
    /// graph must be below `inputs`).
    pub fn compile(g: &Graph, inputs: usize, roots: &[Id]) -> Tape {
        let n = g.nodes.len();
        let mut live = vec![false; n];
        for &r in roots {
            live[r as usize] = true;
        }
        for id in (0..n).rev() {
            if !live[id] {
                continue;
            }
            match g.nodes[id] {
                Op::Const(_) | Op::Var(_) => {}
                Op::Neg(a) | Op::Un(_, a) | Op::Powi(a, _) | Op::Not(a) => live[a as usize] = true,
                Op::Bin(_, a, b) => {
                    live[a as usize] = true;
                    live[b as usize] = true;
                }
                Op::Select(c, a, b) => {
                    live[c as usize] = true;
                    live[a as usize] = true;
                    live[b as usize] = true;
                }
            }
        }
        let mut reg = vec![u32::MAX; n];
        let mut consts = Vec::new();
        for id in 0..n {
            if !live[id] {
                continue;
            }
            match g.nodes[id] {
                Op::Var(s) => reg[id] = s,
                Op::Const(bits) => {
                    reg[id] = (inputs + consts.len()) as u32;
                    consts.push(f64::from_bits(bits));
                }
                _ => {}
            }
        }
        let first = inputs + consts.len();
        let mut code = Vec::new();
        for id in 0..n {
            if !live[id] {
                continue;
            }
            let r = |x: Id| reg[x as usize];
            let instr = match g.nodes[id] {
                Op::Const(_) | Op::Var(_) => continue,
                Op::Neg(a) => Instr::Neg(r(a)),
                Op::Un(f, a) => Instr::unary(f, r(a)),
                Op::Bin(f, a, b) => Instr::binary(f, r(a), r(b)),
                Op::Powi(a, k) => Instr::power(r(a), k),
                Op::Not(a) => Instr::Not(r(a)),
                Op::Select(c, a, b) => Instr::Select(r(c), r(a), r(b)),
            };
            reg[id] = (first + code.len()) as u32;
            code.push(instr);
        }
        let outputs = roots.iter().map(|&r| reg[r as usize]).collect();
        Tape {
            inputs,
            consts,
            code,
            outputs,
        }
    }

    /// The tape computing only the results at positions `keep` of [`Tape::outputs`] (in
    /// that order), with the instructions and constants no kept result reads removed: a
    /// Jacobian tape restricted to some parameter columns. Every `keep` entry must be below
    /// `outputs().len()`.
    pub fn restrict(&self, keep: &[usize]) -> Tape {
        let first = self.inputs + self.consts.len();
        let mut live = vec![false; self.registers()];
        for &k in keep {
            live[self.outputs[k] as usize] = true;
        }
        let mut code = self.code.clone();
        for (k, instr) in code.iter_mut().enumerate().rev() {
            if live[first + k] {
                for a in instr.operands_mut() {
                    live[*a as usize] = true;
                }
            }
        }
        // New register numbers: inputs stay, then the live constants, then live code.
        let mut map: Vec<u32> = (0..self.registers() as u32).collect();
        let mut consts = Vec::new();
        for (c, &v) in self.consts.iter().enumerate() {
            if live[self.inputs + c] {
                map[self.inputs + c] = (self.inputs + consts.len()) as u32;
                consts.push(v);
            }
        }
        let new_first = self.inputs + consts.len();
        let mut kept = Vec::new();
        for (k, mut instr) in code.into_iter().enumerate() {
            if !live[first + k] {
                continue;
            }
            for a in instr.operands_mut() {
                *a = map[*a as usize];
            }
            map[first + k] = (new_first + kept.len()) as u32;
            kept.push(instr);
        }
        Tape {
            inputs: self.inputs,
            consts,
            code: kept,
            outputs: keep
                .iter()
                .map(|&k| map[self.outputs[k] as usize])
                .collect(),
        }
    }

    /// Registers the tape needs.
    pub fn registers(&self) -> usize {
        self.inputs + self.consts.len() + self.code.len()
    }

    /// Number of instructions.
    pub fn len(&self) -> usize {
        self.code.len()
    }

    /// Runs the tape over `regs`, whose first input-slot registers hold t, x, u, θ; the
    /// results are then in the registers [`Tape::outputs`] names.
    ///
    /// `regs` must have at least [`Tape::registers`] entries.
    #[inline]
    pub fn run(&self, regs: &mut [f64]) {
        let first = self.inputs + self.consts.len();
        regs[self.inputs..first].copy_from_slice(&self.consts);
        for (k, instr) in self.code.iter().enumerate() {
            let r = |i: u32| regs[i as usize];
            let v = match *instr {
                Instr::Neg(a) => -r(a),
                Instr::Sin(a) => r(a).sin(),
                Instr::Cos(a) => r(a).cos(),
                Instr::Tan(a) => r(a).tan(),
                Instr::Exp(a) => r(a).exp(),
                Instr::Ln(a) => r(a).ln(),
                Instr::Sqrt(a) => r(a).sqrt(),
                Instr::Abs(a) => r(a).abs(),
                Instr::Sign(a) => num::sign0(r(a)),
                Instr::Tanh(a) => r(a).tanh(),
                Instr::Atan(a) => r(a).atan(),
                Instr::FiniteOr0(a) => num::finite_or_zero(r(a)),
                Instr::Add(a, b) => r(a) + r(b),
                Instr::Sub(a, b) => r(a) - r(b),
                Instr::Mul(a, b) => r(a) * r(b),
                Instr::Div(a, b) => r(a) / r(b),
                Instr::Pow(a, b) => num::pow(r(a), r(b)),
                Instr::Min(a, b) => num::min(r(a), r(b)),
                Instr::Max(a, b) => num::max(r(a), r(b)),
                Instr::Lt(a, b) => num::truth(r(a) < r(b)),
                Instr::Le(a, b) => num::truth(r(a) <= r(b)),
                Instr::Eq(a, b) => num::truth(r(a) == r(b)),
                Instr::Ne(a, b) => num::truth(r(a) != r(b)),
                Instr::And(a, b) => num::truth(r(a) != 0.0 && r(b) != 0.0),
                Instr::Or(a, b) => num::truth(r(a) != 0.0 || r(b) != 0.0),
                Instr::Square(a) => {
                    let x = r(a);
                    x * x
                }
                Instr::Cube(a) => {
                    let x = r(a);
                    x * x * x
                }
                Instr::Powi(a, n) => num::powi(r(a), n),
                Instr::Not(a) => num::truth(r(a) == 0.0),
                Instr::Select(c, a, b) => {
                    if r(c) != 0.0 {
                        r(a)
                    } else {
                        r(b)
                    }
                }
            };
            regs[first + k] = v;
        }
    }

    /// The registers holding the results, in the order of the roots given to
    /// [`Tape::compile`].
    pub fn outputs(&self) -> &[u32] {
        &self.outputs
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_subexpressions_are_computed_once() {
        let mut g = Graph::default();
        let x = g.var(1);
        let y = g.var(2);
        let s = g.bin(Fn2::Add, x, y);
        let sin = g.un(Fn1::Sin, s);
        let cos = g.un(Fn1::Cos, s);
        let dead = g.un(Fn1::Exp, x);
        let _ = dead;
        let tape = Tape::compile(&g, 3, &[sin, cos]);
        assert_eq!(tape.len(), 3); // x+y, sin, cos; exp(x) is dead
        let mut regs = vec![0.0; tape.registers()];
        regs[1] = 0.25;
        regs[2] = 0.5;
        tape.run(&mut regs);
        let o = tape.outputs();
        assert_eq!(regs[o[0] as usize], 0.75f64.sin());
        assert_eq!(regs[o[1] as usize], 0.75f64.cos());
    }

    #[test]
    fn a_restricted_tape_computes_the_kept_results_only() {
        let mut g = Graph::default();
        let (x, y) = (g.var(1), g.var(2));
        let two = g.konst(2.0);
        let s = g.bin(Fn2::Add, x, y);
        let sin = g.un(Fn1::Sin, s);
        let scaled = g.bin(Fn2::Mul, two, y);
        let exp = g.un(Fn1::Exp, scaled);
        let tape = Tape::compile(&g, 3, &[sin, exp, s]);
        let only = tape.restrict(&[2, 0]);
        assert_eq!((tape.len(), only.len()), (4, 2)); // 2*y and exp(2*y) are dropped
        assert_eq!(only.registers(), 5); // t, x, y, x+y, sin; the constant 2 is dropped
        let mut regs = vec![0.0; only.registers()];
        regs[1] = 0.25;
        regs[2] = 0.5;
        only.run(&mut regs);
        let o = only.outputs();
        assert_eq!(regs[o[0] as usize], 0.75);
        assert_eq!(regs[o[1] as usize], 0.75f64.sin());
    }

    #[test]
    fn every_instruction_computes_what_constant_folding_computes() {
        use Fn1::*;
        use Fn2::*;
        let ones = [
            Sin, Cos, Tan, Exp, Ln, Sqrt, Abs, Sign, Tanh, Atan, FiniteOr0,
        ];
        let twos = [Add, Sub, Mul, Div, Pow, Min, Max, Lt, Le, Eq, Ne, And, Or];
        let points = [(0.7, 1.3), (-0.4, 2.0), (0.0, 0.0), (2.5, -1.5), (1.0, 1.0)];
        for (a, b) in points {
            let mut g = Graph::default();
            let (x, y) = (g.var(1), g.var(2));
            let mut roots = Vec::new();
            let mut want = Vec::new();
            for f in ones {
                roots.push(g.un(f, x));
                want.push(num::apply1(f, a));
            }
            for f in twos {
                roots.push(g.bin(f, x, y));
                want.push(num::apply2(f, a, b));
            }
            for n in [-3, 2, 3, 5] {
                roots.push(g.powi(x, n));
                want.push(num::powi(a, n));
            }
            let tape = Tape::compile(&g, 3, &roots);
            let mut regs = vec![0.0; tape.registers()];
            regs[1] = a;
            regs[2] = b;
            tape.run(&mut regs);
            for (k, (&r, w)) in tape.outputs().iter().zip(want).enumerate() {
                let got = regs[r as usize];
                assert!(
                    got == w || (got.is_nan() && w.is_nan()),
                    "#{k} at ({a}, {b}): {got} vs {w}"
                );
            }
        }
    }
}
