//! Straight-line blocks of double arithmetic over virtual registers, and their register
//! allocation into the 16 xmm registers.
//!
//! A block is built first ([`Block`]: one instruction per operation, operands virtual
//! registers or memory), then emitted ([`Block::emit`]) with Belady's rule: when no register
//! is free, the value whose next use is furthest away leaves its register (stored to its
//! frame slot the first time). A value whose last use has passed frees its register at
//! once. A call clobbers every xmm register: the values still needed are stored first and
//! reloaded where next used. Every block starts and ends with no value in a register.
//!
//! Reference: L. A. Belady, "A study of replacement algorithms for a virtual-storage
//! computer", *IBM Systems Journal* 5(2), 1966 (the furthest-next-use rule).

use super::asm::{cc, Asm, Gpr, Logic, Mem, Rm, Scalar, Xmm};

/// A function generated code calls: `f(a, b)` (the C calling convention).
pub(super) type Helper = extern "C" fn(f64, f64) -> f64;

/// A virtual register: a double computed once (or an accumulator, [`Ins::MulAdd`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct V(usize);

/// An operand: a virtual register or a double in memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Arg {
    V(V),
    Mem(Mem),
}

/// One instruction of a block.
#[derive(Clone, Copy, Debug)]
pub(super) enum Ins {
    /// `dst = a op b`.
    Scalar { op: Scalar, dst: V, a: V, b: Arg },
    /// `dst = mask(a pred b)`.
    Cmp { pred: u8, dst: V, a: V, b: Arg },
    /// `dst = a op b` bitwise; `b` a value or a 16-byte constant.
    Logic { op: Logic, dst: V, a: V, b: Arg },
    /// `dst = f(a, b)`.
    Call { f: Helper, dst: V, a: Arg, b: Arg },
    /// `dst = aᵇ` with the tape's shortcuts taken inline: `a` where b = 1, 1 where b = 0,
    /// else `f(a, b)` (a call that leaves every register as it was).
    Pow {
        f: Helper,
        dst: V,
        a: V,
        b: V,
        one: Mem,
        zero: Mem,
    },
    /// `dst = a` (a load); `reread` when the memory holds the value for the whole block,
    /// so that an eviction need not store it (it is read again from `a`).
    Load { dst: V, a: Mem, reread: bool },
    /// `[to] = src`.
    Store { src: V, to: Mem },
    /// `d = d + a·[s]`, only where the byte at `flag` is non-zero when given.
    MulAdd {
        d: V,
        a: V,
        s: Mem,
        flag: Option<Mem>,
    },
}

impl Ins {
    /// The values the instruction reads (an accumulator counts as read).
    fn reads(&self) -> [Option<V>; 2] {
        let v = |a: &Arg| match a {
            Arg::V(v) => Some(*v),
            Arg::Mem(_) => None,
        };
        match self {
            Ins::Call { a, b, .. } => [v(a), v(b)],
            Ins::Scalar { a, b, .. } | Ins::Cmp { a, b, .. } | Ins::Logic { a, b, .. } => {
                [Some(*a), v(b)]
            }
            Ins::Pow { a, b, .. } => [Some(*a), Some(*b)],
            Ins::Load { .. } => [None, None],
            Ins::Store { src, .. } => [Some(*src), None],
            Ins::MulAdd { d, a, .. } => [Some(*d), Some(*a)],
        }
    }
}

/// A block under construction.
#[derive(Default)]
pub(super) struct Block {
    ins: Vec<Ins>,
    values: usize,
    /// The value each memory operand was loaded into (the block's memory is read-only
    /// to it but for its stores of results, which it never reads back).
    loaded: std::collections::HashMap<Mem, V>,
}

impl Block {
    /// A new virtual register.
    pub fn value(&mut self) -> V {
        self.values += 1;
        V(self.values - 1)
    }

    pub fn push(&mut self, ins: Ins) {
        self.ins.push(ins);
    }

    /// `op(a, b)` into a new value.
    pub fn scalar(&mut self, op: Scalar, a: Arg, b: Arg) -> V {
        let a = self.in_value(a);
        let dst = self.value();
        self.push(Ins::Scalar { op, dst, a, b });
        dst
    }

    /// The mask of `a pred b` into a new value.
    pub fn cmp(&mut self, pred: u8, a: Arg, b: Arg) -> V {
        let a = self.in_value(a);
        let dst = self.value();
        self.push(Ins::Cmp { pred, dst, a, b });
        dst
    }

    /// `a op b` bitwise into a new value (a loaded first when in memory).
    pub fn logic(&mut self, op: Logic, a: Arg, b: Arg) -> V {
        let a = self.in_value(a);
        let dst = self.value();
        self.push(Ins::Logic { op, dst, a, b });
        dst
    }

    /// `f(a, b)` into a new value.
    pub fn call(&mut self, f: Helper, a: Arg, b: Arg) -> V {
        let dst = self.value();
        self.push(Ins::Call { f, dst, a, b });
        dst
    }

    /// `aᵇ` into a new value, the shortcuts b = 1 and b = 0 inline (`one` and `zero` the
    /// constants 1 and 0).
    pub fn pow(&mut self, f: Helper, a: Arg, b: Arg, one: Mem, zero: Mem) -> V {
        let (a, b) = (self.in_value(a), self.in_value(b));
        let dst = self.value();
        self.push(Ins::Pow {
            f,
            dst,
            a,
            b,
            one,
            zero,
        });
        dst
    }

    /// `a` as a value (loaded when in memory).
    /// `a` as a value to read (memory loaded once per block).
    pub fn in_value(&mut self, a: Arg) -> V {
        match a {
            Arg::V(v) => v,
            Arg::Mem(m) => {
                if let Some(&v) = self.loaded.get(&m) {
                    return v;
                }
                let dst = self.value();
                self.push(Ins::Load {
                    dst,
                    a: m,
                    reread: true,
                });
                self.loaded.insert(m, dst);
                dst
            }
        }
    }

    /// A new value loaded from `m`, of its own: an accumulator ([`Ins::MulAdd`]) starts so.
    pub fn fresh(&mut self, m: Mem) -> V {
        let dst = self.value();
        self.push(Ins::Load {
            dst,
            a: m,
            reread: false,
        });
        dst
    }

    /// How many frame slots (doubles) the block's values may need.
    pub fn slots(&self) -> usize {
        self.values
    }

    /// Emits the block; value v is spilled to `[spill + 8v]`. After a call, the
    /// general-purpose registers `restore` lists are reloaded from their slots (the bases
    /// that live in caller-saved registers).
    pub fn emit(&self, asm: &mut Asm, spill: Mem, restore: &[(Gpr, Mem)]) {
        let mut uses: Vec<Vec<usize>> = vec![Vec::new(); self.values];
        for (p, ins) in self.ins.iter().enumerate() {
            for v in ins.reads().into_iter().flatten() {
                uses[v.0].push(p);
            }
        }
        let mut state = State {
            asm,
            spill,
            uses,
            cursor: vec![0; self.values],
            home: vec![None; self.values],
            saved: vec![false; self.values],
            origin: vec![None; self.values],
            holder: [None; 16],
        };
        for (p, ins) in self.ins.iter().enumerate() {
            state.emit(p, ins, restore);
        }
    }
}

/// Register allocation state while emitting.
struct State<'a> {
    asm: &'a mut Asm,
    spill: Mem,
    /// Per value, the instructions that read it, in order.
    uses: Vec<Vec<usize>>,
    /// Per value, how many of its uses have passed.
    cursor: Vec<usize>,
    /// Per value, the register holding it.
    home: Vec<Option<Xmm>>,
    /// Per value, whether its slot holds its current value.
    saved: Vec<bool>,
    /// Per value loaded from memory that holds it for the whole block: that memory, its
    /// slot.
    origin: Vec<Option<Mem>>,
    /// Per register, the value it holds.
    holder: [Option<V>; 16],
}

impl State<'_> {
    fn slot(&self, v: V) -> Mem {
        self.origin[v.0].unwrap_or(self.spill.offset(v.0))
    }

    /// The next instruction at or after `p` reading v (usize::MAX: none).
    fn next_use(&self, v: V, p: usize) -> usize {
        self.uses[v.0][self.cursor[v.0]..]
            .iter()
            .copied()
            .find(|&u| u >= p)
            .unwrap_or(usize::MAX)
    }

    /// A register for a new value at instruction p, none of `pinned` taken.
    fn free_register(&mut self, p: usize, pinned: &[Xmm]) -> Xmm {
        if let Some(r) =
            (0..16u8).find(|&r| self.holder[r as usize].is_none() && !pinned.contains(&r))
        {
            return r;
        }
        let (r, v) = (0..16u8)
            .filter(|r| !pinned.contains(r))
            .map(|r| {
                (
                    r,
                    self.holder[r as usize].expect("every register holds a value"),
                )
            })
            .max_by_key(|&(_, v)| self.next_use(v, p))
            .expect("fewer than 16 registers are pinned");
        self.evict(v);
        r
    }

    /// Moves v out of its register (stored first unless its slot holds it).
    fn evict(&mut self, v: V) {
        let r = self.home[v.0]
            .take()
            .expect("an evicted value is in a register");
        if !self.saved[v.0] {
            let slot = self.slot(v);
            self.asm.store(slot, r);
            self.saved[v.0] = true;
        }
        self.holder[r as usize] = None;
    }

    /// v in a register (loaded from its slot when it is not).
    fn reg(&mut self, v: V, p: usize, pinned: &[Xmm]) -> Xmm {
        if let Some(r) = self.home[v.0] {
            return r;
        }
        let r = self.free_register(p, pinned);
        let slot = self.slot(v);
        self.asm.load(r, slot);
        self.bind(v, r);
        r
    }

    fn bind(&mut self, v: V, r: Xmm) {
        self.home[v.0] = Some(r);
        self.holder[r as usize] = Some(v);
    }

    /// An operand as ModRM.rm: its register, its slot when it is not in one, or memory.
    fn rm(&self, a: Arg) -> Rm {
        match a {
            Arg::V(v) => match self.home[v.0] {
                Some(r) => Rm::Xmm(r),
                None => Rm::Mem(self.slot(v)),
            },
            Arg::Mem(m) => Rm::Mem(m),
        }
    }

    /// Marks instruction p's reads as done, freeing the registers of values not read
    /// again.
    fn retire(&mut self, ins: &Ins) {
        for v in ins.reads().into_iter().flatten() {
            self.cursor[v.0] += 1;
            if self.cursor[v.0] >= self.uses[v.0].len() {
                if let Some(r) = self.home[v.0].take() {
                    self.holder[r as usize] = None;
                }
            }
        }
    }

    /// A new register for `dst` (written, so its slot is stale).
    fn define(&mut self, dst: V, p: usize) -> Xmm {
        let r = self.free_register(p, &[]);
        self.bind(dst, r);
        self.saved[dst.0] = false;
        r
    }

    /// The registers of a two-source instruction `ins` (`a` a value, `b` in a register or
    /// memory) and of its destination, which may take a source's register (the instruction
    /// reads its sources before it writes), even one whose value is evicted to make room.
    fn binary(&mut self, ins: &Ins, dst: V, a: V, b: Arg, p: usize) -> (Xmm, Xmm, Rm) {
        let ra = self.reg(a, p, &[]);
        let rb = self.rm(b);
        self.retire(ins);
        (self.define(dst, p), ra, rb)
    }

    fn emit(&mut self, p: usize, ins: &Ins, restore: &[(Gpr, Mem)]) {
        match *ins {
            Ins::Scalar { op, dst, a, b } => {
                let (rd, ra, rb) = self.binary(ins, dst, a, b, p);
                self.asm.scalar(op, rd, ra, rb);
            }
            Ins::Cmp { pred, dst, a, b } => {
                let (rd, ra, rb) = self.binary(ins, dst, a, b, p);
                self.asm.cmp(pred, rd, ra, rb);
            }
            Ins::Logic { op, dst, a, b } => {
                let ra = self.reg(a, p, &[]);
                // A value is read from its register (its slot holds 8 bytes, not 16).
                let rb = match b {
                    Arg::V(v) => Rm::Xmm(self.reg(v, p, &[ra])),
                    Arg::Mem(m) => Rm::Mem(m),
                };
                self.retire(ins);
                let rd = self.define(dst, p);
                self.asm.logic(op, rd, ra, rb);
            }
            Ins::Pow {
                f,
                dst,
                a,
                b,
                one,
                zero,
            } => {
                // Every register is chosen before the branches, so the allocation is the
                // same on each path.
                let ra = self.reg(a, p, &[]);
                let rb = self.reg(b, p, &[ra]);
                let rd = self.free_register(p, &[ra, rb]);
                let asm = &mut *self.asm;
                let (not_one, not_zero, done) = (asm.label(), asm.label(), asm.label());
                asm.ucomi(rb, Rm::Mem(one));
                asm.jump(Some(cc::NOT_ZERO), not_one);
                asm.jump(Some(cc::PARITY), not_one);
                asm.copy(rd, ra);
                asm.jump(None, done);
                asm.bind(not_one);
                asm.ucomi(rb, Rm::Mem(zero));
                asm.jump(Some(cc::NOT_ZERO), not_zero);
                asm.jump(Some(cc::PARITY), not_zero);
                asm.load(rd, one);
                asm.jump(None, done);
                asm.bind(not_zero);
                // The call: every register's value to its slot and back, the result
                // through the destination's slot.
                let held: Vec<(Xmm, V)> = (0..16u8)
                    .filter_map(|r| self.holder[r as usize].map(|v| (r, v)))
                    .collect();
                for &(r, v) in &held {
                    // A value read from memory of the block's is read from there again.
                    if self.origin[v.0].is_none() {
                        let slot = self.slot(v);
                        self.asm.store(slot, r);
                    }
                }
                let (slot_a, slot_b) = (self.slot(a), self.slot(b));
                self.asm.load(0, slot_a);
                self.asm.load(1, slot_b);
                self.asm.mov_imm(Gpr::Rax, f as *const () as u64);
                self.asm.call(Gpr::Rax);
                for &(g, m) in restore {
                    self.asm.mov_load(g, m);
                }
                let result = self.slot(dst);
                self.asm.store(result, 0);
                for &(r, v) in &held {
                    let slot = self.slot(v);
                    self.asm.load(r, slot);
                }
                self.asm.load(rd, result);
                self.asm.bind(done);
                self.retire(ins);
                self.bind(dst, rd);
                self.saved[dst.0] = false;
            }
            Ins::Load { dst, a, reread } => {
                let rd = self.define(dst, p);
                self.asm.load(rd, a);
                if reread {
                    self.origin[dst.0] = Some(a);
                    self.saved[dst.0] = true;
                }
            }
            Ins::Store { src, to } => {
                let r = self.reg(src, p, &[]);
                self.asm.store(to, r);
                self.retire(ins);
            }
            Ins::MulAdd { d, a, s, flag } => {
                // Both in registers and a scratch register taken before the branch, so
                // the allocation is the same whether the product is added or not.
                let rd = self.reg(d, p, &[]);
                let ra = self.reg(a, p, &[rd]);
                let scratch = self.free_register(p, &[rd, ra]);
                let skip = flag.map(|flag| {
                    let skip = self.asm.label();
                    self.asm.cmp_byte_zero(flag);
                    self.asm.jump(Some(cc::ZERO), skip);
                    skip
                });
                self.asm.scalar(Scalar::Mul, scratch, ra, Rm::Mem(s));
                self.asm.scalar(Scalar::Add, rd, rd, Rm::Xmm(scratch));
                if let Some(skip) = skip {
                    self.asm.bind(skip);
                }
                self.saved[d.0] = false;
                self.retire(ins);
            }
            Ins::Call { f, dst, a, b } => {
                // Every value read later leaves its register (the callee may change
                // them all); the arguments go to xmm0 and xmm1.
                for r in 0..16 {
                    if let Some(v) = self.holder[r] {
                        if self.next_use(v, p + 1) != usize::MAX {
                            self.evict(v);
                        }
                    }
                }
                let (ma, mb) = (self.rm(a), self.rm(b));
                match (ma, mb) {
                    (Rm::Xmm(xa), Rm::Xmm(xb)) => {
                        // Registers of values read for the last time: move without
                        // overwriting one with the other.
                        if xb == 0 && xa == 1 {
                            self.asm.copy(2, 1);
                            self.asm.copy(1, 0);
                            self.asm.copy(0, 2);
                        } else if xb == 0 {
                            self.asm.copy(1, 0);
                            self.asm.copy(0, xa);
                        } else {
                            self.asm.copy(0, xa);
                            self.asm.copy(1, xb);
                        }
                    }
                    (Rm::Xmm(xa), Rm::Mem(m)) => {
                        self.asm.copy(0, xa);
                        self.asm.load(1, m);
                    }
                    (Rm::Mem(m), Rm::Xmm(xb)) => {
                        self.asm.copy(1, xb);
                        self.asm.load(0, m);
                    }
                    (Rm::Mem(m), Rm::Mem(n)) => {
                        self.asm.load(0, m);
                        self.asm.load(1, n);
                    }
                }
                self.retire(ins);
                for r in 0..16 {
                    if let Some(v) = self.holder[r].take() {
                        self.home[v.0] = None;
                    }
                }
                self.asm.mov_imm(Gpr::Rax, f as *const () as u64);
                self.asm.call(Gpr::Rax);
                for &(g, m) in restore {
                    self.asm.mov_load(g, m);
                }
                self.bind(dst, 0);
                self.saved[dst.0] = false;
            }
        }
    }
}
