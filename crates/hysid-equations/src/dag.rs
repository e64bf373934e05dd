//! The expression graph: hash-consed (one node per distinct operation on distinct
//! operands, so common subexpressions are shared), folded and simplified as it is built,
//! and differentiated symbolically.
//!
//! Children are always created before their parents, so node ids are a topological order:
//! every walk below is a loop over ids, never a recursion (hostile files cannot exhaust
//! the stack).

use std::collections::HashMap;

use crate::num::{self, Fn1, Fn2};

/// A node id (index into [`Graph::nodes`]).
pub type Id = u32;

/// One node.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Op {
    /// A constant (bits of the f64, so that the node can be hashed).
    Const(u64),
    /// The variable in input slot `n` (time, a state, an input or a parameter).
    Var(u32),
    /// −a
    Neg(Id),
    /// f(a)
    Un(Fn1, Id),
    /// f(a, b)
    Bin(Fn2, Id, Id),
    /// aⁿ for a literal integer n (multiplications)
    Powi(Id, i32),
    /// not a (a is a truth value 0/1)
    Not(Id),
    /// if c then a else b
    Select(Id, Id, Id),
}

/// The graph.
#[derive(Clone, Debug, Default)]
pub struct Graph {
    /// Nodes in creation (= topological) order.
    pub nodes: Vec<Op>,
    index: HashMap<Op, Id>,
}

/// Largest |n| for which a literal integer exponent becomes a multiplication chain.
const MAX_POWI: f64 = 64.0;

impl Graph {
    /// The node for `op`, created if new.
    fn intern(&mut self, op: Op) -> Id {
        if let Some(&id) = self.index.get(&op) {
            return id;
        }
        let id = self.nodes.len() as Id;
        self.nodes.push(op);
        self.index.insert(op, id);
        id
    }

    /// The constant value of node `id`, if it is a constant.
    pub fn constant(&self, id: Id) -> Option<f64> {
        match self.nodes[id as usize] {
            Op::Const(bits) => Some(f64::from_bits(bits)),
            _ => None,
        }
    }

    fn is(&self, id: Id, v: f64) -> bool {
        self.constant(id) == Some(v)
    }

    /// The constant `v` (−0 is stored as +0 so that equal constants share a node).
    pub fn konst(&mut self, v: f64) -> Id {
        let v = if v == 0.0 { 0.0 } else { v };
        self.intern(Op::Const(v.to_bits()))
    }

    /// The variable in input slot `slot`.
    pub fn var(&mut self, slot: u32) -> Id {
        self.intern(Op::Var(slot))
    }

    /// −a
    pub fn neg(&mut self, a: Id) -> Id {
        if let Some(v) = self.constant(a) {
            return self.konst(-v);
        }
        if let Op::Neg(inner) = self.nodes[a as usize] {
            return inner;
        }
        self.intern(Op::Neg(a))
    }

    /// f(a)
    pub fn un(&mut self, f: Fn1, a: Id) -> Id {
        if let Some(v) = self.constant(a) {
            return self.konst(num::apply1(f, v));
        }
        self.intern(Op::Un(f, a))
    }

    /// a op b, folded and simplified (x+0, x·0, x·1, x/1, x−x, x^n, …).
    pub fn bin(&mut self, f: Fn2, a: Id, b: Id) -> Id {
        if let (Some(x), Some(y)) = (self.constant(a), self.constant(b)) {
            return self.konst(num::apply2(f, x, y));
        }
        match f {
            Fn2::Add if self.is(a, 0.0) => return b,
            Fn2::Add if self.is(b, 0.0) => return a,
            Fn2::Sub if self.is(b, 0.0) => return a,
            Fn2::Sub if self.is(a, 0.0) => return self.neg(b),
            Fn2::Sub if a == b => return self.konst(0.0),
            Fn2::Mul if self.is(a, 0.0) || self.is(b, 0.0) => return self.konst(0.0),
            Fn2::Mul if self.is(a, 1.0) => return b,
            Fn2::Mul if self.is(b, 1.0) => return a,
            Fn2::Mul if self.is(a, -1.0) => return self.neg(b),
            Fn2::Mul if self.is(b, -1.0) => return self.neg(a),
            Fn2::Div if self.is(b, 1.0) => return a,
            Fn2::Div if self.is(b, -1.0) => return self.neg(a),
            Fn2::Div if self.is(a, 0.0) => return self.konst(0.0),
            Fn2::Pow => {
                if let Some(n) = self.constant(b) {
                    if n.fract() == 0.0 && n.abs() <= MAX_POWI {
                        return self.powi(a, n as i32);
                    }
                }
                if self.is(a, 1.0) {
                    return self.konst(1.0);
                }
            }
            Fn2::Min | Fn2::Max if a == b => return a,
            Fn2::And | Fn2::Or => {
                // Truth values are 0/1, so a constant operand decides or drops out.
                let (c, other) = match (self.constant(a), self.constant(b)) {
                    (Some(c), _) => (c, b),
                    (_, Some(c)) => (c, a),
                    _ => (f64::NAN, a),
                };
                if !c.is_nan() {
                    let decides = (f == Fn2::And) == (c == 0.0);
                    return if decides {
                        self.konst(num::truth(c != 0.0))
                    } else {
                        other
                    };
                }
            }
            _ => {}
        }
        // Commutative operations in a canonical order, so that a+b and b+a share a node.
        let (a, b) = match f {
            Fn2::Add | Fn2::Mul | Fn2::Eq | Fn2::Ne | Fn2::And | Fn2::Or if b < a => (b, a),
            _ => (a, b),
        };
        self.intern(Op::Bin(f, a, b))
    }

    /// aⁿ as multiplications (a⁰ = 1, a¹ = a).
    pub fn powi(&mut self, a: Id, n: i32) -> Id {
        if let Some(v) = self.constant(a) {
            return self.konst(num::powi(v, n));
        }
        match n {
            0 => self.konst(1.0),
            1 => a,
            _ => self.intern(Op::Powi(a, n)),
        }
    }

    /// not a
    pub fn not(&mut self, a: Id) -> Id {
        if let Some(v) = self.constant(a) {
            return self.konst(num::truth(v == 0.0));
        }
        self.intern(Op::Not(a))
    }

    /// if c then a else b
    pub fn select(&mut self, c: Id, a: Id, b: Id) -> Id {
        if let Some(v) = self.constant(c) {
            return if v != 0.0 { a } else { b };
        }
        if a == b {
            return a;
        }
        self.intern(Op::Select(c, a, b))
    }

    fn add(&mut self, a: Id, b: Id) -> Id {
        self.bin(Fn2::Add, a, b)
    }
    fn sub(&mut self, a: Id, b: Id) -> Id {
        self.bin(Fn2::Sub, a, b)
    }
    fn mul(&mut self, a: Id, b: Id) -> Id {
        self.bin(Fn2::Mul, a, b)
    }
    fn div(&mut self, a: Id, b: Id) -> Id {
        self.bin(Fn2::Div, a, b)
    }
    fn finite(&mut self, a: Id) -> Id {
        self.un(Fn1::FiniteOr0, a)
    }

    /// ∂node/∂(variable in `slot`) for every node id below `limit` (the nodes that existed
    /// before any differentiation), by forward accumulation over the topological order.
    ///
    /// Conventions (see the crate docs): sign′ = 0; abs′ = sign; min/max/if differentiate
    /// the selected argument; factors that are infinite or undefined (√ at 0, ln at 0, a^b
    /// at a = 0 with b < 1, ∂a^b/∂b at a ≤ 0) are taken as 0.
    pub fn derivative(&mut self, limit: usize, slot: u32) -> Vec<Id> {
        let zero = self.konst(0.0);
        let one = self.konst(1.0);
        let mut d: Vec<Id> = Vec::with_capacity(limit);
        for id in 0..limit {
            let node = id as Id;
            let di = match self.nodes[id] {
                Op::Const(_) => zero,
                Op::Var(s) => {
                    if s == slot {
                        one
                    } else {
                        zero
                    }
                }
                Op::Neg(a) => self.neg(d[a as usize]),
                Op::Un(f, a) => {
                    let da = d[a as usize];
                    if da == zero {
                        zero
                    } else {
                        let factor = self.factor1(f, a, node);
                        self.mul(factor, da)
                    }
                }
                Op::Bin(f, a, b) => self.derivative2(f, a, b, node, d[a as usize], d[b as usize]),
                Op::Powi(a, n) => {
                    let da = d[a as usize];
                    if da == zero {
                        zero
                    } else {
                        let k = self.konst(f64::from(n));
                        let p = self.powi(a, n - 1);
                        let factor = self.mul(k, p);
                        self.mul(factor, da)
                    }
                }
                Op::Not(_) => zero,
                Op::Select(c, a, b) => self.select(c, d[a as usize], d[b as usize]),
            };
            d.push(di);
        }
        d
    }

    /// f′(a) for the node `me` = f(a).
    fn factor1(&mut self, f: Fn1, a: Id, me: Id) -> Id {
        let one = self.konst(1.0);
        match f {
            Fn1::Sin => self.un(Fn1::Cos, a),
            Fn1::Cos => {
                let s = self.un(Fn1::Sin, a);
                self.neg(s)
            }
            Fn1::Tan => {
                let sq = self.powi(me, 2);
                self.add(one, sq)
            }
            Fn1::Exp => me,
            Fn1::Ln => {
                let r = self.div(one, a);
                self.finite(r)
            }
            Fn1::Sqrt => {
                let half = self.konst(0.5);
                let r = self.div(half, me);
                self.finite(r)
            }
            Fn1::Abs => self.un(Fn1::Sign, a),
            Fn1::Sign => self.konst(0.0),
            Fn1::Tanh => {
                let sq = self.powi(me, 2);
                self.sub(one, sq)
            }
            Fn1::Atan => {
                let sq = self.powi(a, 2);
                let den = self.add(one, sq);
                self.div(one, den)
            }
            // Only derivative nodes use it and they are not differentiated again; keep the
            // convention's spirit (a finite factor) if that ever changes.
            Fn1::FiniteOr0 => one,
        }
    }

    /// d(a op b) from da and db, for the node `me` = a op b.
    fn derivative2(&mut self, f: Fn2, a: Id, b: Id, me: Id, da: Id, db: Id) -> Id {
        let zero = self.konst(0.0);
        match f {
            Fn2::Add => self.add(da, db),
            Fn2::Sub => self.sub(da, db),
            Fn2::Mul => {
                let l = self.mul(da, b);
                let r = self.mul(a, db);
                self.add(l, r)
            }
            Fn2::Div => {
                // (da − q·db)/b with q = a/b already computed.
                let qdb = self.mul(me, db);
                let num = self.sub(da, qdb);
                self.div(num, b)
            }
            Fn2::Pow => {
                let mut total = zero;
                if da != zero {
                    let one = self.konst(1.0);
                    let bm1 = self.sub(b, one);
                    let p = self.bin(Fn2::Pow, a, bm1);
                    let bp = self.mul(b, p);
                    let factor = self.finite(bp);
                    total = self.mul(factor, da);
                }
                if db != zero {
                    let ln = self.un(Fn1::Ln, a);
                    let pl = self.mul(me, ln);
                    let factor = self.finite(pl);
                    let term = self.mul(factor, db);
                    total = self.add(total, term);
                }
                total
            }
            Fn2::Min => {
                let c = self.bin(Fn2::Le, a, b);
                self.select(c, da, db)
            }
            Fn2::Max => {
                let c = self.bin(Fn2::Le, b, a);
                self.select(c, da, db)
            }
            Fn2::Lt | Fn2::Le | Fn2::Eq | Fn2::Ne | Fn2::And | Fn2::Or => zero,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hash_consing_shares_and_orders_commutative_operands() {
        let mut g = Graph::default();
        let x = g.var(1);
        let y = g.var(2);
        let a = g.bin(Fn2::Add, x, y);
        let b = g.bin(Fn2::Add, y, x);
        assert_eq!(a, b);
        let s1 = g.un(Fn1::Sin, a);
        let s2 = g.un(Fn1::Sin, b);
        assert_eq!(s1, s2);
        let n = g.nodes.len();
        let _ = g.bin(Fn2::Mul, s1, s2);
        assert_eq!(g.nodes.len(), n + 1);
    }

    #[test]
    fn folding_and_simplification() {
        let mut g = Graph::default();
        let x = g.var(1);
        let zero = g.konst(0.0);
        let one = g.konst(1.0);
        let two = g.konst(2.0);
        let three = g.konst(3.0);
        assert_eq!(g.bin(Fn2::Mul, x, zero), zero);
        assert_eq!(g.bin(Fn2::Mul, one, x), x);
        assert_eq!(g.bin(Fn2::Add, x, zero), x);
        assert_eq!(g.bin(Fn2::Sub, x, x), zero);
        assert_eq!(g.bin(Fn2::Div, x, one), x);
        assert_eq!(g.bin(Fn2::Pow, x, one), x);
        let six = g.bin(Fn2::Mul, two, three);
        assert_eq!(g.constant(six), Some(6.0));
        let p = g.bin(Fn2::Pow, x, three);
        assert_eq!(g.nodes[p as usize], Op::Powi(x, 3));
        let nx = g.neg(x);
        assert_eq!(g.neg(nx), x);
        let c = g.bin(Fn2::Lt, one, two);
        assert_eq!(g.select(c, x, zero), x);
        let s = g.un(Fn1::Sqrt, two);
        assert_eq!(g.constant(s), Some(2f64.sqrt()));
    }

    #[test]
    fn derivative_of_product_and_power() {
        let mut g = Graph::default();
        let x = g.var(1);
        let y = g.var(2);
        let xy = g.bin(Fn2::Mul, x, y);
        let x3 = g.powi(x, 3);
        let e = g.bin(Fn2::Add, xy, x3);
        let n = g.nodes.len();
        let dx = g.derivative(n, 1)[e as usize];
        let dy = g.derivative(n, 2)[e as usize];
        assert_eq!(dy, x);
        // ∂/∂x = y + 3x²
        match g.nodes[dx as usize] {
            Op::Bin(Fn2::Add, _, _) => {}
            other => panic!("{other:?}"),
        }
        let dt = g.derivative(n, 0)[e as usize];
        assert_eq!(g.constant(dt), Some(0.0));
    }
}
