//! The x86-64 instructions the in-process code generator emits, encoded into a byte
//! buffer: scalar double arithmetic and comparisons and 128-bit bitwise operations in their
//! VEX (AVX) encodings, and the few general-purpose instructions of a function's frame,
//! pointers and loop.
//!
//! Every memory operand is `[base + disp32]` (no index register). Encodings from the
//! *Intel 64 and IA-32 Architectures Software Developer's Manual*, vol. 2 (§2.3, the VEX
//! prefix; the instruction pages of `VADDSD`, `VCMPSD`, `VANDPD`, `VMOVSD`, `MOV`, `CALL`).

/// A general-purpose register, numbered as the encoding numbers it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[allow(dead_code)] // the full register file, named as the manual names it
pub(super) enum Gpr {
    Rax = 0,
    Rcx = 1,
    Rdx = 2,
    Rbx = 3,
    Rsp = 4,
    Rbp = 5,
    Rsi = 6,
    Rdi = 7,
    R8 = 8,
    R9 = 9,
    R10 = 10,
    R11 = 11,
    R12 = 12,
    R13 = 13,
    R14 = 14,
    R15 = 15,
}

/// `[base + disp]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) struct Mem {
    pub base: Gpr,
    pub disp: i32,
}

impl Mem {
    pub fn at(base: Gpr, disp: usize) -> Self {
        Self {
            base,
            disp: i32::try_from(disp).expect("frame offsets fit 32 bits"),
        }
    }

    /// The byte `index` places further.
    pub fn offset_bytes(self, index: usize) -> Self {
        Self {
            base: self.base,
            disp: self.disp + i32::try_from(index).expect("offsets fit 32 bits"),
        }
    }

    /// The double `index` places further.
    pub fn offset(self, index: usize) -> Self {
        Self {
            base: self.base,
            disp: self.disp + i32::try_from(8 * index).expect("offsets fit 32 bits"),
        }
    }
}

/// An xmm register (0–15).
pub(super) type Xmm = u8;

/// A register or memory operand.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Rm {
    Xmm(Xmm),
    Mem(Mem),
}

/// Scalar double operations `dst = a op b` (`VADDSD` …, prefix F2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scalar {
    Add = 0x58,
    Mul = 0x59,
    Sub = 0x5C,
    Div = 0x5E,
    Sqrt = 0x51,
}

/// 128-bit bitwise operations (`VANDPD` …, prefix 66); `AndNot` is (¬a) ∧ b.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Logic {
    And = 0x54,
    AndNot = 0x55,
    Or = 0x56,
    Xor = 0x57,
}

/// `VCMPSD` predicates (quiet: no exception on a quiet NaN; ordered ones false on NaN).
pub(super) mod pred {
    pub const EQ_OQ: u8 = 0x00;
    pub const NEQ_UQ: u8 = 0x04;
    pub const LT_OQ: u8 = 0x11;
    pub const LE_OQ: u8 = 0x12;
    pub const GE_OQ: u8 = 0x1D;
    pub const GT_OQ: u8 = 0x1E;
}

/// A position in the code a jump goes to, bound once.
#[derive(Clone, Copy, Debug)]
pub(super) struct Label(usize);

/// The code being assembled, with the jumps waiting for their labels.
#[derive(Default)]
pub(super) struct Asm {
    pub code: Vec<u8>,
    labels: Vec<Option<usize>>,
    /// (where the rel32 is, the label it reaches)
    fixups: Vec<(usize, Label)>,
}

const PP_66: u8 = 1;
const PP_F2: u8 = 3;
const MAP_0F: u8 = 1;

impl Asm {
    fn bytes(&mut self, b: &[u8]) {
        self.code.extend_from_slice(b);
    }

    /// ModRM (and SIB, disp32) of `reg` with `rm`.
    fn modrm(&mut self, reg: u8, rm: Rm) {
        match rm {
            Rm::Xmm(r) => self.code.push(0xC0 | (reg & 7) << 3 | (r & 7)),
            Rm::Mem(m) => {
                let base = m.base as u8;
                self.code.push(0x80 | (reg & 7) << 3 | (base & 7));
                if base & 7 == 4 {
                    self.code.push(0x24); // SIB: no index, base
                }
                self.bytes(&m.disp.to_le_bytes());
            }
        }
    }

    /// A three-byte VEX instruction of map 0F, 128-bit, W0: `reg` the ModRM.reg operand,
    /// `v` the extra source (vvvv), `rm` the ModRM.rm operand.
    fn vex(&mut self, pp: u8, opcode: u8, reg: u8, v: u8, rm: Rm) {
        let b = match rm {
            Rm::Xmm(r) => r >> 3,
            Rm::Mem(m) => (m.base as u8) >> 3,
        };
        let r = reg >> 3;
        self.bytes(&[
            0xC4,
            (r ^ 1) << 7 | 1 << 6 | (b ^ 1) << 5 | MAP_0F,
            ((!v) & 15) << 3 | pp,
            opcode,
        ]);
        self.modrm(reg, rm);
    }

    /// `dst = a op b` (for `Sqrt`: dst = √b, the upper half from a).
    pub fn scalar(&mut self, op: Scalar, dst: Xmm, a: Xmm, b: Rm) {
        self.vex(PP_F2, op as u8, dst, a, b);
    }

    /// `dst = mask(a pred b)`: all ones where it holds, else zero (low lane).
    pub fn cmp(&mut self, predicate: u8, dst: Xmm, a: Xmm, b: Rm) {
        self.vex(PP_F2, 0xC2, dst, a, b);
        self.code.push(predicate);
    }

    /// `dst = a op b` bitwise over 128 bits (a memory `b` is read as 16 bytes).
    pub fn logic(&mut self, op: Logic, dst: Xmm, a: Xmm, b: Rm) {
        self.vex(PP_66, op as u8, dst, a, b);
    }

    /// Flags of the unordered comparison of `a` with `b` (`VUCOMISD`): ZF where equal,
    /// ZF, PF and CF where unordered (a NaN).
    pub fn ucomi(&mut self, a: Xmm, b: Rm) {
        self.vex(PP_66, 0x2E, a, 0, b);
    }

    /// `dst = [m]` (the upper half zeroed).
    pub fn load(&mut self, dst: Xmm, m: Mem) {
        self.vex(PP_F2, 0x10, dst, 0, Rm::Mem(m));
    }

    /// `[m] = src`.
    pub fn store(&mut self, m: Mem, src: Xmm) {
        self.vex(PP_F2, 0x11, src, 0, Rm::Mem(m));
    }

    /// `dst = src` (`VMOVAPD`).
    pub fn copy(&mut self, dst: Xmm, src: Xmm) {
        if dst != src {
            self.vex(PP_66, 0x28, dst, 0, Rm::Xmm(src));
        }
    }

    fn rex_w(&mut self, reg: u8, rm: u8) {
        self.code.push(0x48 | (reg >> 3) << 2 | (rm >> 3));
    }

    pub fn push(&mut self, r: Gpr) {
        let r = r as u8;
        if r >= 8 {
            self.code.push(0x41);
        }
        self.code.push(0x50 | (r & 7));
    }

    pub fn pop(&mut self, r: Gpr) {
        let r = r as u8;
        if r >= 8 {
            self.code.push(0x41);
        }
        self.code.push(0x58 | (r & 7));
    }

    /// `dst = imm` (64 bits).
    pub fn mov_imm(&mut self, dst: Gpr, imm: u64) {
        self.rex_w(0, dst as u8);
        self.code.push(0xB8 | (dst as u8 & 7));
        self.bytes(&imm.to_le_bytes());
    }

    /// `dst = src`.
    pub fn mov(&mut self, dst: Gpr, src: Gpr) {
        self.rex_w(src as u8, dst as u8);
        self.code.push(0x89);
        self.code
            .push(0xC0 | (src as u8 & 7) << 3 | (dst as u8 & 7));
    }

    /// `dst = [m]` (64 bits).
    pub fn mov_load(&mut self, dst: Gpr, m: Mem) {
        self.rex_w(dst as u8, m.base as u8);
        self.code.push(0x8B);
        self.modrm(dst as u8, Rm::Mem(m));
    }

    /// `[m] = src` (64 bits).
    pub fn mov_store(&mut self, m: Mem, src: Gpr) {
        self.rex_w(src as u8, m.base as u8);
        self.code.push(0x89);
        self.modrm(src as u8, Rm::Mem(m));
    }

    /// `dst = sign-extended src` (32 → 64 bits, `MOVSXD`).
    pub fn movsxd(&mut self, dst: Gpr, src: Gpr) {
        self.rex_w(dst as u8, src as u8);
        self.code.push(0x63);
        self.code
            .push(0xC0 | (dst as u8 & 7) << 3 | (src as u8 & 7));
    }

    /// `dst += imm` (`ADD`/`SUB` r/m64, imm32).
    pub fn add_imm(&mut self, dst: Gpr, imm: i32) {
        self.rex_w(0, dst as u8);
        self.code.push(0x81);
        self.code.push(0xC0 | (dst as u8 & 7));
        self.bytes(&imm.to_le_bytes());
    }

    /// `dst -= 1`, setting the zero flag.
    pub fn dec(&mut self, dst: Gpr) {
        self.rex_w(0, dst as u8);
        self.code.push(0xFF);
        self.code.push(0xC8 | (dst as u8 & 7));
    }

    /// Flags of `r & r`.
    pub fn test(&mut self, r: Gpr) {
        self.rex_w(r as u8, r as u8);
        self.code.push(0x85);
        self.code.push(0xC0 | (r as u8 & 7) << 3 | (r as u8 & 7));
    }

    /// Flags of `byte [m] - 0`.
    pub fn cmp_byte_zero(&mut self, m: Mem) {
        if m.base as u8 >= 8 {
            self.code.push(0x41);
        }
        self.code.push(0x80);
        self.modrm(7, Rm::Mem(m));
        self.code.push(0);
    }

    /// `call r`.
    pub fn call(&mut self, r: Gpr) {
        if r as u8 >= 8 {
            self.code.push(0x41);
        }
        self.code.push(0xFF);
        self.code.push(0xD0 | (r as u8 & 7));
    }

    pub fn ret(&mut self) {
        self.code.push(0xC3);
    }

    pub fn label(&mut self) -> Label {
        self.labels.push(None);
        Label(self.labels.len() - 1)
    }

    pub fn bind(&mut self, l: Label) {
        self.labels[l.0] = Some(self.code.len());
    }

    /// A jump to `l`: `cc` the condition code (4 = equal/zero, 5 = not equal, 0xE = less
    /// or equal), None unconditional.
    pub fn jump(&mut self, cc: Option<u8>, l: Label) {
        match cc {
            Some(cc) => self.bytes(&[0x0F, 0x80 | cc]),
            None => self.code.push(0xE9),
        }
        self.fixups.push((self.code.len(), l));
        self.bytes(&[0; 4]);
    }

    /// The code with every jump resolved.
    pub fn finish(mut self) -> Vec<u8> {
        for &(at, l) in &self.fixups {
            let target = self.labels[l.0].expect("every label is bound");
            let rel = target as i64 - (at as i64 + 4);
            let rel = i32::try_from(rel).expect("jumps within 2 GiB");
            self.code[at..at + 4].copy_from_slice(&rel.to_le_bytes());
        }
        self.code
    }
}

/// Condition codes of [`Asm::jump`].
pub(super) mod cc {
    pub const ZERO: u8 = 0x4;
    pub const NOT_ZERO: u8 = 0x5;
    pub const LESS_OR_EQUAL: u8 = 0xE;
    pub const PARITY: u8 = 0xA;
}
