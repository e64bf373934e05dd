//! Native code without a C compiler: the functions of `source.rs` — `hysid_prepare`,
//! `hysid_eval`, `hysid_sens`, `hysid_rates` and `hysid_substeps`, with the same
//! signatures and the same numbers — emitted as x86-64 machine code in the process, in
//! well under a millisecond, where the C compiler takes about a tenth of a second.
//!
//! The code is emitted from the same split of the listing (`source::Split`: what θ alone
//! determines, prepared once per θ into `c`, and the rest), one block of straight-line
//! double arithmetic per function or RK4 stage (`block.rs`: virtual registers allocated
//! to the 16 xmm registers; `lower.rs`: each operation's instructions), in AVX encodings
//! (`asm.rs`). Each operation is one scalar IEEE 754 instruction of the tape's operation,
//! or a call of the function the tape calls (`sin`, `exp`, `pow`, … through
//! [`hysid_equations::apply1`], [`hysid_equations::apply2`], [`hysid_equations::powi`]),
//! in the listing's order; no product is fused with a sum, so every value has the tape's
//! bits. Comparisons, `min`, `max`, `sign`, the finite-or-zero of derivatives and `if` are
//! branch-free masks with the tape's semantics (ties and NaN included). The stages, stage
//! states and update of `hysid_substeps` are those of the fixed-size Rust loop
//! (`fixed_rk4`), element by element.
//!
//! Reference: the instruction encodings of the *Intel 64 and IA-32 Architectures Software
//! Developer's Manual*, vol. 2; the calling convention of the *System V Application Binary
//! Interface, AMD64 Architecture Processor Supplement* (arguments in rdi, rsi, rdx, rcx,
//! r8, r9 and xmm0–7, rbx, rbp and r12–r15 kept, the stack 16-byte aligned at a call).
//!
//! Linux on x86-64 with AVX only (elsewhere the C compiler route runs). The code lives in
//! pages mapped writable, filled, then made executable and read-only.

mod asm;
mod block;
mod lower;

use super::source::{needed, Class, Split};
use super::{Layout, Shape};
use asm::{Asm, Gpr, Mem, Rm, Scalar};
use block::{Arg, Block, Ins, V};
use hysid_equations::{Listing, Operand};
use lower::{finite, lower, Pool};
use std::ffi::CStr;

/// Whether this machine runs the generated code (x86-64 with AVX).
pub(super) fn available() -> bool {
    crate::numerics::cpu::has_avx()
}

/// Executable code and its constants (unmapped when dropped).
pub(super) struct Code {
    base: *mut u8,
    len: usize,
}

// SAFETY: the mapping is read-only once built; the functions in it keep no state.
unsafe impl Send for Code {}
// SAFETY: as above.
unsafe impl Sync for Code {}

impl Drop for Code {
    fn drop(&mut self) {
        // SAFETY: the mapping of `new`, unmapped once.
        unsafe {
            libc::munmap(self.base.cast(), self.len);
        }
    }
}

impl Code {
    /// `code` followed by the constants `pool` (at a 16-byte boundary), in new pages made
    /// executable; each `mov rbx, imm64` at `pool_fixups` is given the constants' address.
    fn new(mut code: Vec<u8>, pool: &[[u64; 2]], pool_fixups: &[usize]) -> Result<Self, String> {
        let pool_at = code.len().next_multiple_of(16);
        let len = pool_at + 16 * pool.len();
        // SAFETY: a fresh anonymous private mapping; the result is checked.
        let base = unsafe {
            libc::mmap(
                std::ptr::null_mut(),
                len.max(1),
                libc::PROT_READ | libc::PROT_WRITE,
                libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
                -1,
                0,
            )
        };
        if base == libc::MAP_FAILED {
            return Err("no memory for generated code".into());
        }
        let code_len = code.len();
        let pool_address = (base as u64) + pool_at as u64;
        for &at in pool_fixups {
            code[at..at + 8].copy_from_slice(&pool_address.to_le_bytes());
        }
        let bytes: Vec<u8> = pool
            .iter()
            .flat_map(|pair| pair.iter().flat_map(|w| w.to_le_bytes()))
            .collect();
        // SAFETY: both copies stay within the `len` bytes mapped writable above.
        unsafe {
            std::ptr::copy_nonoverlapping(code.as_ptr(), base.cast::<u8>(), code_len);
            std::ptr::copy_nonoverlapping(
                bytes.as_ptr(),
                base.cast::<u8>().add(pool_at),
                bytes.len(),
            );
        }
        let code = Self {
            base: base.cast(),
            len: len.max(1),
        };
        // SAFETY: the mapping made above, now read-only and executable.
        if unsafe { libc::mprotect(base, code.len, libc::PROT_READ | libc::PROT_EXEC) } != 0 {
            return Err("the system refuses executable pages for generated code".into());
        }
        Ok(code)
    }

    /// The address of the function at `offset`.
    pub fn entry(&self, offset: usize) -> *mut std::ffi::c_void {
        debug_assert!(offset < self.len);
        // SAFETY: within the mapping.
        unsafe { self.base.add(offset).cast() }
    }
}

/// Where each function starts in a [`Code`], by its C name.
pub(super) type Entries = Vec<(&'static CStr, usize)>;

/// The machine code of `listing` for `layout` over `shape`, and the length of its
/// prepared array: the functions `source.rs` would print, emitted here.
pub(super) fn assemble(
    listing: &Listing,
    layout: &Layout,
    shape: Shape,
) -> Result<(Code, Entries, usize), String> {
    let split = Split::new(listing);
    let mut gen = Generator {
        split: &split,
        asm: Asm::default(),
        pool: Pool::default(),
        pool_fixups: Vec::new(),
        largest_frame: 0,
    };
    let mut entries: Entries = vec![(c"hysid_prepare", gen.prepare())];
    match layout {
        Layout::Results { values, positions } => {
            entries.push((c"hysid_eval", gen.eval(*values, positions)));
        }
        Layout::Sensitivities { k, q } => {
            let n = shape.states;
            entries.push((c"hysid_sens", gen.sens(n, *k, *q)));
            entries.push((c"hysid_substeps", gen.substeps(n, *k, *q, shape.inputs)));
            let rates = gen.eval(n, &(0..n).collect::<Vec<_>>());
            entries.push((c"hysid_rates", rates));
        }
    }
    if gen.largest_frame > MAX_FRAME {
        return Err(format!(
            "the model needs a {} KiB stack frame, more than generated code takes ({} KiB)",
            gen.largest_frame / 1024,
            MAX_FRAME / 1024
        ));
    }
    let Generator {
        asm,
        pool,
        pool_fixups,
        ..
    } = gen;
    let code = Code::new(asm.finish(), &pool.entries, &pool_fixups)?;
    Ok((code, entries, split.slots))
}

/// Where a block reads its operands and writes its results.
#[derive(Clone, Copy)]
struct Env {
    t: Arg,
    x: Mem,
    u: Mem,
    /// The prepared values.
    c: Mem,
}

/// Where a stage reads S (row-major, rows of q doubles) and the coupling flags, and what it
/// does with each rate it computes.
#[derive(Clone, Copy)]
struct StageIo {
    s: Mem,
    coupled: Mem,
    /// Where the Jacobian entries prepared from θ wait made finite (entry (i, j) at
    /// i·n + j), when the caller made them so once per call.
    finite: Option<Mem>,
    then: Then,
}

/// What a stage does with each rate k it computes, element e of z = [x, S] (ẋᵢ at e = i,
/// Ṡᵢ꜀ at e = n + i·q + c).
#[derive(Clone, Copy)]
enum Then {
    /// Stores ẋ at `dx` and Ṡ at `ds` (`hysid_sens`).
    Store { dx: Mem, ds: Mem },
    /// Stores k at `k` and the next stage's state z + w·k at `out`, both in z's layout
    /// (`out` none of the memory the stage reads), w in memory: stages 1–3 of
    /// `hysid_substeps`.
    Next { k: Mem, z: Mem, w: Mem, out: Mem },
    /// z ← z + (h/6)·(k₁ + 2k₂ + 2k₃ + k₄) (`rk4::increment`, in that order), k₁ … k₃ at
    /// `k` in z's layout, k itself not stored: stage 4 of `hysid_substeps`.
    Update {
        z: Mem,
        k: [Mem; 3],
        sixth: Mem,
        two: Mem,
    },
}

struct Generator<'a> {
    split: &'a Split<'a>,
    asm: Asm,
    pool: Pool,
    /// Where `mov rbx, imm64` waits for the constants' address.
    pool_fixups: Vec<usize>,
    /// The largest stack frame of the functions so far (bytes).
    largest_frame: usize,
}

/// The largest stack frame generated code may open: far below the stack of any thread
/// that runs a simulation (a model this large runs compiled C, or the tape).
const MAX_FRAME: usize = 256 * 1024;

/// The page size the stack probes step by.
const PAGE: usize = 4096;

/// The callee-saved registers a function saves (with the return address, 56 bytes: the
/// frame below is 8 mod 16 so that calls see an aligned stack).
const SAVED: [Gpr; 6] = [Gpr::Rbx, Gpr::Rbp, Gpr::R12, Gpr::R13, Gpr::R14, Gpr::R15];

/// A frame of doubles below the saved registers.
struct Frame {
    bytes: usize,
}

impl Frame {
    /// A frame of `doubles` slots (plus 16 bytes: a 16-byte read of the last slot stays
    /// inside), 8 mod 16 bytes long.
    fn new(doubles: usize) -> Self {
        let bytes = (8 * doubles + 16).next_multiple_of(16) + 8;
        Self { bytes }
    }

    fn slot(&self, i: usize) -> Mem {
        Mem::at(Gpr::Rsp, 8 * i)
    }
}

impl Generator<'_> {
    /// Saves the callee-saved registers, opens `frame` and points rbx at the constants;
    /// returns where the function starts.
    fn prologue(&mut self, frame: &Frame) -> usize {
        let start = self.asm.code.len();
        self.largest_frame = self.largest_frame.max(frame.bytes);
        for r in SAVED {
            self.asm.push(r);
        }
        // A frame beyond i32 is refused before the code could run (MAX_FRAME).
        let bytes = i32::try_from(frame.bytes).unwrap_or(i32::MAX);
        self.asm.add_imm(Gpr::Rsp, -bytes);
        // Stack probes: each page of a large frame read from the top down, so that a
        // thread's guard page faults rather than being stepped over.
        if frame.bytes > PAGE {
            let mut below_top = frame.bytes;
            while below_top > PAGE {
                below_top -= PAGE;
                self.asm.mov_load(Gpr::Rax, Mem::at(Gpr::Rsp, below_top));
            }
            self.asm.mov_load(Gpr::Rax, Mem::at(Gpr::Rsp, 0));
        }
        self.asm.mov_imm(Gpr::Rbx, 0);
        self.pool_fixups.push(self.asm.code.len() - 8);
        start
    }

    fn epilogue(&mut self, frame: &Frame) {
        self.asm
            .add_imm(Gpr::Rsp, i32::try_from(frame.bytes).unwrap_or(i32::MAX));
        for r in SAVED.iter().rev() {
            self.asm.pop(*r);
        }
        self.asm.ret();
    }

    /// `hysid_prepare(p, c)`: the θ-only operations the others read, and the parameters,
    /// stored in their slots of c.
    fn prepare(&mut self) -> usize {
        let split = self.split;
        let ops = &split.listing.operations;
        let (p, c) = (Mem::at(Gpr::R12, 0), Mem::at(Gpr::R13, 0));
        let mut roots: Vec<Operand> = Vec::new();
        for (k, slot) in split.slot_of_value.iter().enumerate() {
            if slot.is_some() {
                roots.push(Operand::Value(k));
            }
        }
        let needed = needed(split.listing, &roots, |k| !split.varying[k]);
        let mut block = Block::default();
        let mut values: Vec<Option<V>> = vec![None; ops.len()];
        for (k, op) in ops.iter().enumerate() {
            if needed[k] {
                let read = |o: &Operand, pool: &mut Pool| match *o {
                    Operand::Parameter(i) => Arg::Mem(p.offset(i)),
                    Operand::Value(j) => Arg::V(values[j].expect("an earlier value")),
                    Operand::Constant(v) => Arg::Mem(pool.double(v)),
                    Operand::Time | Operand::State(_) | Operand::Input(_) => {
                        unreachable!("a θ-only operation")
                    }
                };
                values[k] = Some(lower(&mut block, &mut self.pool, op, read));
            }
        }
        for (i, slot) in split.slot_of_param.iter().enumerate() {
            if let Some(s) = slot {
                let v = block.in_value(Arg::Mem(p.offset(i)));
                block.push(Ins::Store {
                    src: v,
                    to: c.offset(*s),
                });
            }
        }
        for (k, slot) in split.slot_of_value.iter().enumerate() {
            if let Some(s) = slot {
                let src = values[k].expect("a prepared value is computed");
                block.push(Ins::Store {
                    src,
                    to: c.offset(*s),
                });
            }
        }
        let frame = Frame::new(block.slots());
        let start = self.prologue(&frame);
        self.asm.mov(Gpr::R12, Gpr::Rdi);
        self.asm.mov(Gpr::R13, Gpr::Rsi);
        block.emit(&mut self.asm, frame.slot(0), &[]);
        self.epilogue(&frame);
        start
    }

    /// The varying operations that `roots` need, lowered into `block` reading `env`;
    /// per operation its value.
    fn varying(&mut self, block: &mut Block, env: Env, roots: &[Operand]) -> Vec<Option<V>> {
        let split = self.split;
        let needed = needed(split.listing, roots, |k| split.varying[k]);
        let mut values: Vec<Option<V>> = vec![None; split.listing.operations.len()];
        for (k, op) in split.listing.operations.iter().enumerate() {
            if needed[k] {
                let read = |o: &Operand, pool: &mut Pool| read(split, env, &values, o, pool);
                values[k] = Some(lower(block, &mut self.pool, op, read));
            }
        }
        values
    }

    /// `hysid_eval(t, x, u, c, out)`: results 0 … `values` − 1 as computed, the others
    /// finite, result k at `out[positions[k]]`.
    fn eval(&mut self, values: usize, positions: &[usize]) -> usize {
        let split = self.split;
        let results = &split.listing.results[..positions.len()];
        let mut block = Block::default();
        // Slot 0 of the frame holds t; the values spill after it.
        let env = Env {
            t: Arg::Mem(Mem::at(Gpr::Rsp, 0)),
            x: Mem::at(Gpr::R12, 0),
            u: Mem::at(Gpr::R13, 0),
            c: Mem::at(Gpr::R14, 0),
        };
        let out = Mem::at(Gpr::R15, 0);
        let computed = self.varying(&mut block, env, results);
        for (k, (o, &position)) in results.iter().zip(positions).enumerate() {
            let value = read(split, env, &computed, o, &mut self.pool);
            let src = if k < values {
                block.in_value(value)
            } else {
                finite(&mut block, &mut self.pool, value, o)
            };
            block.push(Ins::Store {
                src,
                to: out.offset(position),
            });
        }
        let frame = Frame::new(1 + block.slots());
        let start = self.prologue(&frame);
        self.asm.store(Mem::at(Gpr::Rsp, 0), 0);
        self.asm.mov(Gpr::R12, Gpr::Rdi);
        self.asm.mov(Gpr::R13, Gpr::Rsi);
        self.asm.mov(Gpr::R14, Gpr::Rdx);
        self.asm.mov(Gpr::R15, Gpr::Rcx);
        block.emit(&mut self.asm, frame.slot(1), &[]);
        self.epilogue(&frame);
        start
    }

    /// One evaluation of ẋ and Ṡ (`source::sensitivities_source`'s `hy_sens`) into a new
    /// block: ẋ = f, then per row i and column c, d = [f_θ]ᵢ꜀ (0 for an initial-state
    /// column) plus the products [f_x]ᵢⱼ·Sⱼ꜀ in the order of j — left out for a constant
    /// zero entry, added only where `coupled[i·n + j]` for an entry prepared from θ — each
    /// rate handed to `io.then` as it is computed.
    fn stage(&mut self, env: Env, n: usize, k: usize, q: usize, io: StageIo) -> Block {
        let split = self.split;
        let results = &split.listing.results;
        let entry = |i: usize, j: usize| n + i * n + j;
        let direct = |i: usize, c: usize| n + n * n + i * k + c;
        // Without columns (a plain simulation's sub-steps) the Jacobian takes no part.
        let jacobian_rows = if q > 0 { n } else { 0 };
        let mut roots: Vec<Operand> = results[..n].to_vec();
        for i in 0..jacobian_rows {
            roots.extend((0..n).map(|j| results[entry(i, j)]));
            roots.extend((0..k).map(|c| results[direct(i, c)]));
        }
        let mut block = Block::default();
        let computed = self.varying(&mut block, env, &roots);
        let value = |o: &Operand, pool: &mut Pool| read(split, env, &computed, o, pool);
        let StageIo {
            s,
            coupled,
            finite: prepared,
            then,
        } = io;
        let rate = |block: &mut Block, k: V, e: usize| match then {
            Then::Store { dx, ds } => {
                let to = if e < n {
                    dx.offset(e)
                } else {
                    ds.offset(e - n)
                };
                block.push(Ins::Store { src: k, to });
            }
            Then::Next { k: at, z, w, out } => {
                block.push(Ins::Store {
                    src: k,
                    to: at.offset(e),
                });
                // w·k first, as base + c·k rounds.
                let wk = block.scalar(Scalar::Mul, Arg::V(k), Arg::Mem(w));
                let state = block.scalar(Scalar::Add, Arg::V(wk), Arg::Mem(z.offset(e)));
                block.push(Ins::Store {
                    src: state,
                    to: out.offset(e),
                });
            }
            Then::Update {
                z,
                k: [k1, k2, k3],
                sixth,
                two,
            } => {
                let mut sum = block.in_value(Arg::Mem(k1.offset(e)));
                for kr in [k2, k3] {
                    let twice = block.scalar(Scalar::Mul, Arg::Mem(two), Arg::Mem(kr.offset(e)));
                    sum = block.scalar(Scalar::Add, Arg::V(sum), Arg::V(twice));
                }
                let sum = block.scalar(Scalar::Add, Arg::V(sum), Arg::V(k));
                let step = block.scalar(Scalar::Mul, Arg::Mem(sixth), Arg::V(sum));
                // z[e] is read by this instruction, before the store that replaces it.
                let updated = block.scalar(Scalar::Add, Arg::V(step), Arg::Mem(z.offset(e)));
                block.push(Ins::Store {
                    src: updated,
                    to: z.offset(e),
                });
            }
        };
        for (i, o) in results[..n].iter().enumerate() {
            let v = value(o, &mut self.pool);
            let src = block.in_value(v);
            rate(&mut block, src, i);
        }
        // The Jacobian entries that take part, finite.
        let mut a: Vec<Vec<Option<(V, Class)>>> = vec![vec![None; n]; n];
        for (i, row) in a.iter_mut().enumerate().take(jacobian_rows) {
            for (j, cell) in row.iter_mut().enumerate() {
                let o = &results[entry(i, j)];
                let class = split.class(o);
                let made_finite = match (class, prepared) {
                    (Class::Zero, _) => continue,
                    (Class::Prepared, Some(at)) => block.in_value(Arg::Mem(at.offset(i * n + j))),
                    _ => {
                        let v = value(o, &mut self.pool);
                        finite(&mut block, &mut self.pool, v, o)
                    }
                };
                *cell = Some((made_finite, class));
            }
        }
        for (i, cells) in a.iter().enumerate() {
            for c in 0..q {
                // d is a fresh value (a load or a mask's result): it accumulates alone.
                let d = if c < k {
                    let o = &results[direct(i, c)];
                    let v = value(o, &mut self.pool);
                    finite(&mut block, &mut self.pool, v, o)
                } else {
                    let zero = self.pool.double(0.0);
                    block.fresh(zero)
                };
                for (j, cell) in cells.iter().enumerate() {
                    if let Some((aij, class)) = cell {
                        let flag =
                            (*class == Class::Prepared).then(|| coupled.offset_bytes(i * n + j));
                        block.push(Ins::MulAdd {
                            d,
                            a: *aij,
                            s: s.offset(j * q + c),
                            flag,
                        });
                    }
                }
                rate(&mut block, d, n + i * q + c);
            }
        }
        block
    }

    /// `hysid_sens(t, x, u, s, c, coupled, dx, ds)`.
    fn sens(&mut self, n: usize, k: usize, q: usize) -> usize {
        // Frame: t, dx, ds, then the spill slots.
        let env = Env {
            t: Arg::Mem(Mem::at(Gpr::Rsp, 0)),
            x: Mem::at(Gpr::R12, 0),
            u: Mem::at(Gpr::R13, 0),
            c: Mem::at(Gpr::R15, 0),
        };
        let io = StageIo {
            s: Mem::at(Gpr::R14, 0),
            coupled: Mem::at(Gpr::Rbp, 0),
            finite: None,
            then: Then::Store {
                dx: Mem::at(Gpr::R10, 0),
                ds: Mem::at(Gpr::R11, 0),
            },
        };
        let block = self.stage(env, n, k, q, io);
        let frame = Frame::new(3 + block.slots());
        let (dx_slot, ds_slot) = (frame.slot(1), frame.slot(2));
        let start = self.prologue(&frame);
        self.asm.store(frame.slot(0), 0);
        self.asm.mov(Gpr::R12, Gpr::Rdi);
        self.asm.mov(Gpr::R13, Gpr::Rsi);
        self.asm.mov(Gpr::R14, Gpr::Rdx);
        self.asm.mov(Gpr::R15, Gpr::Rcx);
        self.asm.mov(Gpr::Rbp, Gpr::R8);
        self.asm.mov(Gpr::R10, Gpr::R9);
        // The eighth argument, above the return address, the saved registers and the frame.
        let above = frame.bytes + 8 * SAVED.len() + 8;
        self.asm.mov_load(Gpr::R11, Mem::at(Gpr::Rsp, above));
        self.asm.mov_store(dx_slot, Gpr::R10);
        self.asm.mov_store(ds_slot, Gpr::R11);
        block.emit(
            &mut self.asm,
            frame.slot(3),
            &[(Gpr::R10, dx_slot), (Gpr::R11, ds_slot)],
        );
        self.epilogue(&frame);
        start
    }

    /// `hysid_substeps(nodes, c, coupled, m, h, x, s)`: m RK4 sub-steps of z = [x, S] (the
    /// stages of [`Self::stage`], the stage states z + (h/2)·k₁, z + (h/2)·k₂, z + h·k₃ and
    /// z ← z + (h/6)·(k₁ + 2k₂ + 2k₃ + k₄), element by element as `fixed_rk4`). Each stage
    /// forms the next stage's state (the last one z's update) element by element as it
    /// computes the rates, so every value is read back as it was stored, one double at a
    /// time. (Measured slower or no faster, paired: the updates of S four lanes at a time
    /// after each stage, from rates stored one double at a time, whose four-lane loads wait
    /// for the stores; Ṡ four lanes at a time from the stage's terms stored for it.)
    fn substeps(&mut self, n: usize, k: usize, q: usize, inputs: usize) -> usize {
        let len = n + n * q;
        // Frame: h, h/2, h/6, the pointers x and s, then z, k₁, k₂, k₃ and two stage states
        // (a stage reads one and writes the next stage's into the other), each in z's
        // layout, the n × n Jacobian entries prepared from θ made finite, then the spill
        // slots.
        let (h, half, sixth, x_ptr, s_ptr) = (0, 1, 2, 3, 4);
        let z = 5;
        let stage_k = |r: usize| z + len * (1 + r);
        let states = [z + 4 * len, z + 5 * len];
        let finite_at = z + 6 * len;
        let spill = finite_at + n * n;
        // Stage r reads z (r = 0) or the state stage r − 1 wrote.
        let stage_base = |r: usize| if r == 0 { z } else { states[(r - 1) % 2] };
        let at = |i: usize| Mem::at(Gpr::Rsp, 8 * i);
        let two = self.pool.double(2.0);
        // Stage r reads the input at node 0, 1, 1, 2 of the sub-step.
        let mut blocks = Vec::new();
        for (r, node) in [0, 1, 1, 2].into_iter().enumerate() {
            let env = Env {
                t: Arg::Mem(self.pool.double(0.0)),
                x: at(stage_base(r)),
                u: Mem::at(Gpr::R12, 8 * inputs * node),
                c: Mem::at(Gpr::R13, 0),
            };
            // Stages 2, 3 and 4 start from z + (h/2)·k₁, z + (h/2)·k₂ and z + h·k₃; stage 4
            // updates z.
            let then = if r < 3 {
                Then::Next {
                    k: at(stage_k(r)),
                    z: at(z),
                    w: at([half, half, h][r]),
                    out: at(states[r % 2]),
                }
            } else {
                Then::Update {
                    z: at(z),
                    k: [at(stage_k(0)), at(stage_k(1)), at(stage_k(2))],
                    sixth: at(sixth),
                    two,
                }
            };
            let io = StageIo {
                s: at(stage_base(r) + n),
                coupled: Mem::at(Gpr::R14, 0),
                finite: Some(at(finite_at)),
                then,
            };
            blocks.push(self.stage(env, n, k, q, io));
        }
        // Before the loop: the Jacobian entries prepared from θ made finite, once (they
        // read c alone).
        let mut prepare = Block::default();
        let env = Env {
            t: Arg::Mem(self.pool.double(0.0)),
            x: at(z),
            u: Mem::at(Gpr::R12, 0),
            c: Mem::at(Gpr::R13, 0),
        };
        let results = &self.split.listing.results;
        // None without columns: the Jacobian takes no part.
        let entries = if q > 0 { n * n } else { 0 };
        for e in 0..entries {
            let o = &results[n + e];
            if self.split.class(o) == Class::Prepared {
                let v = read(self.split, env, &[], o, &mut self.pool);
                let src = finite(&mut prepare, &mut self.pool, v, o);
                prepare.push(Ins::Store {
                    src,
                    to: at(finite_at + e),
                });
            }
        }
        let spills = blocks
            .iter()
            .chain([&prepare])
            .map(Block::slots)
            .max()
            .unwrap_or(0);
        let frame = Frame::new(spill + spills);
        let (one_half, six) = (self.pool.double(0.5), self.pool.double(6.0));
        // Element e of z in the caller's buffers: x, then S row-major.
        let caller = |e: usize, x: Gpr, s: Gpr| {
            if e < n {
                Mem::at(x, 8 * e)
            } else {
                Mem::at(s, 8 * (e - n))
            }
        };
        let start = self.prologue(&frame);
        let a = &mut self.asm;
        a.mov(Gpr::R12, Gpr::Rdi);
        a.mov(Gpr::R13, Gpr::Rsi);
        a.mov(Gpr::R14, Gpr::Rdx);
        a.movsxd(Gpr::R15, Gpr::Rcx);
        a.mov_store(at(x_ptr), Gpr::R8);
        a.mov_store(at(s_ptr), Gpr::R9);
        a.store(at(h), 0);
        a.scalar(Scalar::Mul, 1, 0, Rm::Mem(one_half));
        a.store(at(half), 1);
        a.scalar(Scalar::Div, 1, 0, Rm::Mem(six));
        a.store(at(sixth), 1);
        for e in 0..len {
            a.load(0, caller(e, Gpr::R8, Gpr::R9));
            a.store(at(z + e), 0);
        }
        prepare.emit(&mut self.asm, frame.slot(spill), &[]);
        let a = &mut self.asm;
        let (done, lp) = (a.label(), a.label());
        a.test(Gpr::R15);
        a.jump(Some(asm::cc::LESS_OR_EQUAL), done);
        a.bind(lp);
        for block in &blocks {
            block.emit(&mut self.asm, frame.slot(spill), &[]);
        }
        let a = &mut self.asm;
        a.add_imm(Gpr::R12, i32::try_from(16 * inputs).expect("few inputs"));
        a.dec(Gpr::R15);
        a.jump(Some(asm::cc::NOT_ZERO), lp);
        a.bind(done);
        a.mov_load(Gpr::Rax, at(x_ptr));
        a.mov_load(Gpr::Rcx, at(s_ptr));
        for e in 0..len {
            a.load(0, at(z + e));
            a.store(caller(e, Gpr::Rax, Gpr::Rcx), 0);
        }
        self.epilogue(&frame);
        start
    }
}

/// An operand of a varying operation or result: in memory (x, u, c, a constant, t) or a
/// value computed in the block.
fn read(split: &Split<'_>, env: Env, values: &[Option<V>], o: &Operand, pool: &mut Pool) -> Arg {
    match *o {
        Operand::Time => env.t,
        Operand::State(i) => Arg::Mem(env.x.offset(i)),
        Operand::Input(i) => Arg::Mem(env.u.offset(i)),
        Operand::Constant(v) => Arg::Mem(pool.double(v)),
        Operand::Parameter(i) => Arg::Mem(
            env.c
                .offset(split.slot_of_param[i].expect("a read parameter has a slot")),
        ),
        Operand::Value(k) if split.varying[k] => Arg::V(values[k].expect("an earlier value")),
        Operand::Value(k) => Arg::Mem(
            env.c
                .offset(split.slot_of_value[k].expect("a read value has a slot")),
        ),
    }
}
