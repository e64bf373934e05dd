//! The flat instruction tape: the live part of the graph for a set of results, compiled
//! once to instructions over a register file and evaluated without allocation.
//!
//! Register layout: the input slots (t, x, u, θ), then the constants, then one register per
//! instruction (instruction k writes register `first + k`). Every operand was computed
//! before it is read, because graph ids are a topological order.

use crate::dag::{Graph, Id, Op};
use crate::num::{self, Fn1, Fn2};

/// One instruction; operands are register numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Instr {
    Neg(u32),
    Un(Fn1, u32),
    Bin(Fn2, u32, u32),
    Powi(u32, i32),
    Not(u32),
    Select(u32, u32, u32),
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
                Op::Un(f, a) => Instr::Un(f, r(a)),
                Op::Bin(f, a, b) => Instr::Bin(f, r(a), r(b)),
                Op::Powi(a, k) => Instr::Powi(r(a), k),
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
        let (read, write) = regs.split_at_mut(first);
        let write = &mut write[..self.code.len()];
        for k in 0..self.code.len() {
            // Operands live either before `first` or in an earlier instruction's register.
            let get = |r: u32, write: &[f64]| -> f64 {
                let r = r as usize;
                if r < first {
                    read[r]
                } else {
                    write[r - first]
                }
            };
            let v = match self.code[k] {
                Instr::Neg(a) => -get(a, write),
                Instr::Un(f, a) => num::apply1(f, get(a, write)),
                Instr::Bin(f, a, b) => num::apply2(f, get(a, write), get(b, write)),
                Instr::Powi(a, n) => num::powi(get(a, write), n),
                Instr::Not(a) => num::truth(get(a, write) == 0.0),
                Instr::Select(c, a, b) => {
                    if get(c, write) != 0.0 {
                        get(a, write)
                    } else {
                        get(b, write)
                    }
                }
            };
            write[k] = v;
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
}
