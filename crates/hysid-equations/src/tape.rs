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
pub(crate) enum Instr {
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
    // Superinstructions, made by `Tape::fuse` from an instruction and the single-use
    // product (or negation) it reads; each computes exactly what the pair computed.
    /// a·b + c
    MulAdd(u32, u32, u32),
    /// a·b − c
    MulSub(u32, u32, u32),
    /// c − a·b
    SubMul(u32, u32, u32),
    /// (a·b)·c
    Mul3(u32, u32, u32),
    /// −(a·b)
    NegMul(u32, u32),
    /// (−a)/b
    NegDiv(u32, u32),
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
            | Or(a, b)
            | NegMul(a, b)
            | NegDiv(a, b) => {
                vec![a, b]
            }
            Select(c, a, b)
            | MulAdd(c, a, b)
            | MulSub(c, a, b)
            | SubMul(c, a, b)
            | Mul3(c, a, b) => {
                vec![c, a, b]
            }
        }
    }

    /// The value of the instruction with operand register i read as `r(i)`.
    #[inline(always)]
    fn value(self, r: impl Fn(u32) -> f64) -> f64 {
        match self {
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
            Instr::MulAdd(a, b, c) => r(a) * r(b) + r(c),
            Instr::MulSub(a, b, c) => r(a) * r(b) - r(c),
            Instr::SubMul(c, a, b) => r(c) - r(a) * r(b),
            Instr::Mul3(a, b, c) => r(a) * r(b) * r(c),
            Instr::NegMul(a, b) => -(r(a) * r(b)),
            Instr::NegDiv(a, b) => -r(a) / r(b),
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

/// The size of the register file of [`Tape::run_code_small`].
pub const SMALL: usize = 256;

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

    /// [`Tape::run_code`] over a register file of [`SMALL`] registers, for a tape that needs
    /// at most that many ([`Tape::registers`]): every register number then fits a byte, so
    /// no read or write is bounds-checked at run time (a third of the work of a short
    /// instruction).
    #[inline]
    pub fn run_code_small(&self, regs: &mut [f64; SMALL]) {
        debug_assert!(self.registers() <= SMALL);
        let first = self.inputs + self.consts.len();
        for (k, instr) in self.code.iter().enumerate() {
            // `as u8` keeps register numbers below SMALL (they are, see above).
            let v = instr.value(|i| regs[usize::from(i as u8)]);
            regs[usize::from((first + k) as u8)] = v;
        }
    }

    /// The number of input slots (t, x, u, θ), the constants and the instructions, for
    /// [`crate::listing`].
    pub(crate) fn parts(&self) -> (usize, &[f64], &[Instr]) {
        (self.inputs, &self.consts, &self.code)
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
        self.load_constants(regs);
        self.run_code(regs);
    }

    /// Writes the constants to their registers (which the code never overwrites, so a
    /// register file reused for one tape needs this once).
    pub fn load_constants(&self, regs: &mut [f64]) {
        regs[self.inputs..self.inputs + self.consts.len()].copy_from_slice(&self.consts);
    }

    /// Runs the instructions only, the input slots and constants being in place.
    #[inline]
    pub fn run_code(&self, regs: &mut [f64]) {
        let first = self.inputs + self.consts.len();
        for (k, instr) in self.code.iter().enumerate() {
            regs[first + k] = instr.value(|i| regs[i as usize]);
        }
    }

    /// The registers holding the results, in the order of the roots given to
    /// [`Tape::compile`].
    pub fn outputs(&self) -> &[u32] {
        &self.outputs
    }
}

/// Where a register of a tape being specialised ([`Tape::bind`]) takes its value from.
#[derive(Clone, Copy)]
enum Src {
    /// A value known when the tape is specialised.
    Known(f64),
    /// A register of the specialised tape, tagged until the constants are counted
    /// (an input slot, [`CONST_TAG`] | constant number, or [`CODE_TAG`] | instruction number).
    Reg(u32),
}

const CONST_TAG: u32 = 1 << 31;
const CODE_TAG: u32 = 1 << 30;

/// What an instruction with some operands known reduces to.
enum Reduced {
    /// The value of one of its operands (an old register).
    Alias(u32),
    /// A known value.
    Value(f64),
    /// An instruction (operands in the old numbering).
    Instr(Instr),
}

/// The exact identities of the instruction set with one operand known: x·1 = x,
/// x·(−1) = −x, x/1 = x, pow(x, 1) = x, pow(x, 0) = 1 (as [`num::pow`] computes them), and
/// `if` with a known condition. Each gives the value the instruction computes, to the bit.
fn reduce(instr: Instr, known: impl Fn(u32) -> Option<f64>) -> Reduced {
    let is = |r: u32, v: f64| known(r) == Some(v);
    match instr {
        Instr::Mul(a, b) if is(b, 1.0) => Reduced::Alias(a),
        Instr::Mul(a, b) if is(a, 1.0) => Reduced::Alias(b),
        Instr::Mul(a, b) if is(b, -1.0) => Reduced::Instr(Instr::Neg(a)),
        Instr::Mul(a, b) if is(a, -1.0) => Reduced::Instr(Instr::Neg(b)),
        Instr::Div(a, b) if is(b, 1.0) => Reduced::Alias(a),
        Instr::Pow(a, b) if is(b, 1.0) => Reduced::Alias(a),
        Instr::Pow(_, b) if is(b, 0.0) => Reduced::Value(1.0),
        Instr::Select(c, a, b) => match known(c) {
            Some(v) => Reduced::Alias(if v != 0.0 { a } else { b }),
            None => Reduced::Instr(instr),
        },
        _ => Reduced::Instr(instr),
    }
}

impl Tape {
    /// The tape with the input slots from `first_bound` on fixed at `values` (parameters
    /// held for a whole simulation): every instruction that reads only fixed slots and
    /// constants is computed here, once, and becomes a constant; the exact identities of
    /// [`reduce`] remove the instructions they make trivial (pow(|z|, ν) at ν = 1); dead
    /// instructions are dropped and products are fused ([`Tape::fuse`]). The result has
    /// `first_bound` input slots and computes, in the order of [`Tape::outputs`], the same
    /// values to the bit (partial evaluation: N. D. Jones, C. K. Gomard, P. Sestoft,
    /// *Partial Evaluation and Automatic Program Generation*, 1993, ch. 1).
    ///
    /// `first_bound + values.len()` must equal the tape's number of input slots.
    pub fn bind(&self, first_bound: usize, values: &[f64]) -> Tape {
        assert_eq!(first_bound + values.len(), self.inputs, "bound slots");
        let mut src: Vec<Src> = (0..first_bound as u32).map(Src::Reg).collect();
        src.extend(values.iter().chain(&self.consts).map(|&v| Src::Known(v)));
        let mut consts: Vec<f64> = Vec::new();
        let mut code = Vec::new();
        for &instr in &self.code {
            let known = |r: u32| match src[r as usize] {
                Src::Known(v) => Some(v),
                Src::Reg(_) => None,
            };
            let reduced = match known_value(instr, known) {
                Some(v) => Reduced::Value(v),
                None => reduce(instr, known),
            };
            let next = match reduced {
                Reduced::Alias(r) => src[r as usize],
                Reduced::Value(v) => Src::Known(v),
                Reduced::Instr(mut instr) => {
                    for a in instr.operands_mut() {
                        *a = tagged(src[*a as usize], &mut consts);
                    }
                    code.push(instr);
                    Src::Reg(CODE_TAG | (code.len() - 1) as u32)
                }
            };
            src.push(next);
        }
        let outputs: Vec<u32> = self
            .outputs
            .iter()
            .map(|&o| tagged(src[o as usize], &mut consts))
            .collect();
        let base = (first_bound + consts.len()) as u32;
        let untag = |r: &mut u32| {
            *r = if *r & CONST_TAG != 0 {
                first_bound as u32 + (*r & !CONST_TAG)
            } else if *r & CODE_TAG != 0 {
                base + (*r & !CODE_TAG)
            } else {
                *r
            }
        };
        for instr in &mut code {
            instr.operands_mut().into_iter().for_each(untag);
        }
        let mut bound = Tape {
            inputs: first_bound,
            consts,
            code,
            outputs,
        };
        bound.outputs.iter_mut().for_each(untag);
        bound.all().fuse()
    }

    /// The same tape without dead instructions and constants.
    fn all(&self) -> Tape {
        self.restrict(&(0..self.outputs.len()).collect::<Vec<_>>())
    }

    /// The tape with each product (or negation) read once, and not a result, fused into
    /// the addition, subtraction, product, negation or division that reads it
    /// (superinstructions: fewer dispatches, the same operations in the same order, so the
    /// same values to the bit; a + b·c becomes b·c + a, the same IEEE 754 sum).
    pub fn fuse(&self) -> Tape {
        let first = self.inputs + self.consts.len();
        let mut uses = vec![0u32; self.registers()];
        for mut instr in self.code.iter().copied() {
            for a in instr.operands_mut() {
                uses[*a as usize] += 1;
            }
        }
        for &o in &self.outputs {
            uses[o as usize] += 1;
        }
        let mut code = self.code.clone();
        for k in 0..code.len() {
            // The instruction writing register r, if r is read only here.
            let single = |r: u32, code: &[Instr]| {
                let r = r as usize;
                (r >= first && uses[r] == 1).then(|| code[r - first])
            };
            let mul = |r: u32| match single(r, &code) {
                Some(Instr::Mul(x, y)) => Some((x, y)),
                _ => None,
            };
            let fused = match code[k] {
                Instr::Add(a, b) => mul(a)
                    .map(|(x, y)| Instr::MulAdd(x, y, b))
                    .or_else(|| mul(b).map(|(x, y)| Instr::MulAdd(x, y, a))),
                Instr::Sub(a, b) => mul(a)
                    .map(|(x, y)| Instr::MulSub(x, y, b))
                    .or_else(|| mul(b).map(|(x, y)| Instr::SubMul(a, x, y))),
                Instr::Mul(a, b) => mul(a)
                    .map(|(x, y)| Instr::Mul3(x, y, b))
                    .or_else(|| mul(b).map(|(x, y)| Instr::Mul3(x, y, a))),
                Instr::Neg(a) => mul(a).map(|(x, y)| Instr::NegMul(x, y)),
                Instr::Div(a, b) => match single(a, &code) {
                    Some(Instr::Neg(x)) => Some(Instr::NegDiv(x, b)),
                    _ => None,
                },
                _ => None,
            };
            if let Some(f) = fused {
                code[k] = f;
            }
        }
        Tape {
            inputs: self.inputs,
            consts: self.consts.clone(),
            code,
            outputs: self.outputs.clone(),
        }
        .all()
    }

    /// Whether an instruction or a result reads register `slot` (slot 0: the time t).
    pub fn reads(&self, slot: u32) -> bool {
        self.outputs.contains(&slot)
            || self
                .code
                .iter()
                .any(|i| i.clone().operands_mut().into_iter().any(|a| *a == slot))
    }

    /// The constant value of result `k` (the position in [`Tape::outputs`]), None when an
    /// instruction or an input slot computes it.
    pub fn constant_result(&self, k: usize) -> Option<f64> {
        let r = self.outputs[k] as usize;
        (r >= self.inputs && r < self.inputs + self.consts.len())
            .then(|| self.consts[r - self.inputs])
    }
}

/// The value of `instr` when every operand is known.
fn known_value(mut instr: Instr, known: impl Fn(u32) -> Option<f64>) -> Option<f64> {
    let mut local = [0.0; 3];
    for (j, a) in instr.operands_mut().into_iter().enumerate() {
        local[j] = known(*a)?;
        *a = j as u32;
    }
    Some(instr.value(|i| local[i as usize]))
}

/// The tagged register of `s`, a known value becoming a constant (one per distinct value).
fn tagged(s: Src, consts: &mut Vec<f64>) -> u32 {
    match s {
        Src::Reg(r) => r,
        Src::Known(v) => {
            let c = match consts.iter().position(|c| c.to_bits() == v.to_bits()) {
                Some(c) => c,
                None => {
                    consts.push(v);
                    consts.len() - 1
                }
            };
            CONST_TAG | c as u32
        }
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

    /// Each superinstruction replaces a pair and gives the pair's value to the bit; a
    /// product read twice is not fused.
    #[test]
    fn fused_products_give_the_same_values_with_fewer_instructions() {
        let mut g = Graph::default();
        let (a, b, c) = (g.var(1), g.var(2), g.var(3));
        let mut roots = Vec::new();
        let ab = g.bin(Fn2::Mul, a, b);
        roots.push(g.bin(Fn2::Add, ab, c)); // a·b + c
        roots.push(g.bin(Fn2::Sub, ab, c)); // a·b − c
        roots.push(g.bin(Fn2::Sub, c, ab)); // c − a·b
        roots.push(g.bin(Fn2::Mul, ab, c)); // (a·b)·c
        roots.push(g.neg(ab)); // −(a·b)
        let na = g.neg(a);
        roots.push(g.bin(Fn2::Div, na, c)); // (−a)/c
        let ac = g.bin(Fn2::Mul, a, c);
        let once = g.bin(Fn2::Add, ac, b); // a·c + b, the product read once
        roots.push(once);
        let tape = Tape::compile(&g, 4, &roots);
        let fused = tape.fuse();
        // a·b is read five times and stays; −a and a·c are read once and fuse.
        assert_eq!((tape.len(), fused.len()), (10, 8));
        for (x, y, z) in [(0.3, -1.7, 2.9), (1e-3, 7.0, -0.1), (0.0, -0.0, 1.0)] {
            let run = |t: &Tape| {
                let mut regs = vec![0.0; t.registers()];
                regs[1..4].copy_from_slice(&[x, y, z]);
                t.run(&mut regs);
                t.outputs()
                    .iter()
                    .map(|&o| regs[o as usize].to_bits())
                    .collect::<Vec<_>>()
            };
            assert_eq!(run(&tape), run(&fused));
        }
    }

    /// Binding θ computes θ-only instructions once and applies pow(x, 1) = x.
    #[test]
    fn binding_folds_what_the_bound_slots_determine() {
        let mut g = Graph::default();
        let (x, k, nu) = (g.var(1), g.var(2), g.var(3));
        let two = g.konst(2.0);
        let k2 = g.bin(Fn2::Mul, two, k);
        let p = g.bin(Fn2::Pow, x, nu);
        let root = g.bin(Fn2::Mul, k2, p); // 2k·x^ν
        let tape = Tape::compile(&g, 4, &[root]);
        assert_eq!(tape.len(), 3);
        let bound = tape.bind(2, &[3.0, 1.0]);
        assert_eq!(bound.len(), 1); // 6·x
        let mut regs = vec![0.0; bound.registers()];
        regs[1] = 0.7;
        bound.run(&mut regs);
        assert_eq!(regs[bound.outputs()[0] as usize], 6.0 * 0.7);
        let curved = tape.bind(2, &[3.0, 1.5]);
        assert_eq!(curved.len(), 2); // x^1.5, then 6·that
        assert!(!curved.reads(0) && curved.reads(1));
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
