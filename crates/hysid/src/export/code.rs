//! The language-neutral code of an export: expressions, statements and helper functions that
//! the C and Rust renderers ([`super::render`]) print.
//!
//! An expression is a tree, printed with exactly the grouping of the tree (every binary
//! operator left-associative, a right operand of equal precedence parenthesised), so that the
//! generated code performs the library's floating-point operations in the library's order.
//! Literals are printed as the shortest decimal that reads back to the same `f64`
//! (`{:?}`), which always holds a `.` or an `e`; a negative literal is parenthesised inside a
//! larger expression.
//!
//! Emitters build code with [`Block`] and Rust's arithmetic operators on [`Expr`]:
//!
//! ```text
//! let z = b.let_("z", Expr::from(u - r).max((u + r).min(ns.state("z"))));
//! ```

use std::ops::{Add, Div, Mul, Neg, Not, Sub};

pub(crate) use super::stmt::literals;
pub use super::stmt::{Block, Function, Place, Stmt};

/// The type of a value: a double, an array index, or a flag.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ty {
    /// `double` / `f64`.
    F64,
    /// `size_t` / `usize`.
    Index,
    /// `int` (0 or 1) / `bool`.
    Flag,
}

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
    /// `==`
    Eq,
    /// `!=`
    Ne,
    /// `&&`
    And,
    /// `||`
    Or,
}

impl BinOp {
    /// The operator's symbol, the same in C and Rust.
    pub fn symbol(self) -> &'static str {
        match self {
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Lt => "<",
            BinOp::Le => "<=",
            BinOp::Gt => ">",
            BinOp::Ge => ">=",
            BinOp::Eq => "==",
            BinOp::Ne => "!=",
            BinOp::And => "&&",
            BinOp::Or => "||",
        }
    }

    /// The binding strength (higher binds tighter); comparisons share one level and are
    /// never chained (Rust forbids it).
    pub fn precedence(self) -> u8 {
        match self {
            BinOp::Or => 1,
            BinOp::And => 2,
            BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge | BinOp::Eq | BinOp::Ne => 3,
            BinOp::Add | BinOp::Sub => 5,
            BinOp::Mul | BinOp::Div => 6,
        }
    }
}

/// A function of C's `<math.h>` (and of the `libm` crate, under the same name). Each is the
/// correctly rounded operation or the platform's implementation of it, as the library's
/// `f64` methods are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Math {
    /// |x|
    Fabs,
    /// max(x, y) (the non-NaN one)
    Fmax,
    /// min(x, y) (the non-NaN one)
    Fmin,
    /// ⌊x⌋
    Floor,
    /// √x
    Sqrt,
    /// xʸ
    Pow,
    /// eˣ
    Exp,
    /// ln x
    Log,
    /// tanh x
    Tanh,
    /// sinh x
    Sinh,
    /// sin x
    Sin,
    /// cos x
    Cos,
    /// tan x
    Tan,
    /// atan x
    Atan,
    /// |x| with the sign of y
    Copysign,
}

impl Math {
    /// The function's name in C and in the `libm` crate.
    pub fn name(self) -> &'static str {
        match self {
            Math::Fabs => "fabs",
            Math::Fmax => "fmax",
            Math::Fmin => "fmin",
            Math::Floor => "floor",
            Math::Sqrt => "sqrt",
            Math::Pow => "pow",
            Math::Exp => "exp",
            Math::Log => "log",
            Math::Tanh => "tanh",
            Math::Sinh => "sinh",
            Math::Sin => "sin",
            Math::Cos => "cos",
            Math::Tan => "tan",
            Math::Atan => "atan",
            Math::Copysign => "copysign",
        }
    }
}

/// An expression.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A double literal (finite; checked when the program is rendered).
    F64(f64),
    /// A constant that depends on the code's floating-point type ([`typed`]): the first
    /// value in double precision (printed exactly as [`Expr::F64`] would print it, so the
    /// double code is unchanged), the second in single precision. For tolerances tied to the
    /// type's resolution, such as the machine epsilon ([`epsilon`]).
    Typed(f64, f64),
    /// Not a number (`NAN` / `f64::NAN`).
    Nan,
    /// An index literal.
    Index(usize),
    /// A flag literal.
    Flag(bool),
    /// A local variable or parameter.
    Local(String),
    /// A scalar field of the state.
    State(String),
    /// An element of an array field of the state.
    StateAt(String, Box<Expr>),
    /// An element of a constant table.
    Table(String, Box<Expr>),
    /// Input `i` of the step.
    Input(usize),
    /// −x
    Neg(Box<Expr>),
    /// !x (a flag)
    Not(Box<Expr>),
    /// x op y
    Bin(BinOp, Box<Expr>, Box<Expr>),
    /// A `<math.h>` function.
    Math(Math, Vec<Expr>),
    /// x is finite (`isfinite` / `f64::is_finite`).
    IsFinite(Box<Expr>),
    /// An index as a double.
    ToF64(Box<Expr>),
    /// A non-negative finite double below 2⁵³ as an index (truncated).
    ToIndex(Box<Expr>),
    /// `c ? a : b`
    Select(Box<Expr>, Box<Expr>, Box<Expr>),
    /// A call of a helper function of the program.
    Call(String, Vec<Expr>),
}

impl From<f64> for Expr {
    fn from(v: f64) -> Self {
        Expr::F64(v)
    }
}

impl From<usize> for Expr {
    fn from(i: usize) -> Self {
        Expr::Index(i)
    }
}

/// A double literal.
pub fn lit(v: f64) -> Expr {
    Expr::F64(v)
}

/// A constant of the code's floating-point type: `double` in double precision, `single` in
/// single precision ([`Expr::Typed`]).
pub fn typed(double: f64, single: f64) -> Expr {
    Expr::Typed(double, single)
}

/// The machine epsilon ε of the code's floating-point type, the gap between 1 and the next
/// larger number: 2⁻⁵² = `DBL_EPSILON` (`f64::EPSILON`) in double, 2⁻²³ = `FLT_EPSILON`
/// (`f32::EPSILON`) in single (IEEE 754-2008, binary64 and binary32). A stopping test such
/// as |b − a| ≤ 2ε·|a| that is reachable in double is then reachable in float too.
pub fn epsilon() -> Expr {
    typed(f64::EPSILON, f32::EPSILON as f64)
}

/// The smallest positive normal number of the code's type: `DBL_MIN` (2⁻¹⁰²²) in double,
/// `FLT_MIN` (2⁻¹²⁶) in single (`f64::MIN_POSITIVE` would round to 0 in `float`).
pub fn min_positive() -> Expr {
    typed(f64::MIN_POSITIVE, f32::MIN_POSITIVE as f64)
}

/// An index literal.
pub fn idx(i: usize) -> Expr {
    Expr::Index(i)
}

/// A local variable (or parameter) by name.
pub fn local(name: &str) -> Expr {
    Expr::Local(name.into())
}

/// A call of the helper `name`.
pub fn call(name: &str, args: Vec<Expr>) -> Expr {
    Expr::Call(name.into(), args)
}

/// `c ? a : b`.
pub fn select(c: Expr, a: impl Into<Expr>, b: impl Into<Expr>) -> Expr {
    Expr::Select(Box::new(c), Box::new(a.into()), Box::new(b.into()))
}

impl Expr {
    fn bin(self, op: BinOp, other: impl Into<Expr>) -> Expr {
        Expr::Bin(op, Box::new(self), Box::new(other.into()))
    }
    fn math1(self, f: Math) -> Expr {
        Expr::Math(f, vec![self])
    }
    /// max(self, other) as `f64::max` (`fmax`).
    pub fn max(self, other: impl Into<Expr>) -> Expr {
        Expr::Math(Math::Fmax, vec![self, other.into()])
    }
    /// min(self, other) as `f64::min` (`fmin`).
    pub fn min(self, other: impl Into<Expr>) -> Expr {
        Expr::Math(Math::Fmin, vec![self, other.into()])
    }
    /// |self|
    pub fn abs(self) -> Expr {
        self.math1(Math::Fabs)
    }
    /// ⌊self⌋
    pub fn floor(self) -> Expr {
        self.math1(Math::Floor)
    }
    /// √self
    pub fn sqrt(self) -> Expr {
        self.math1(Math::Sqrt)
    }
    /// selfᵉ as `f64::powf` (`pow`).
    pub fn powf(self, e: impl Into<Expr>) -> Expr {
        Expr::Math(Math::Pow, vec![self, e.into()])
    }
    /// exp(self)
    pub fn exp(self) -> Expr {
        self.math1(Math::Exp)
    }
    /// ln(self)
    pub fn ln(self) -> Expr {
        self.math1(Math::Log)
    }
    /// tanh(self)
    pub fn tanh(self) -> Expr {
        self.math1(Math::Tanh)
    }
    /// sinh(self)
    pub fn sinh(self) -> Expr {
        self.math1(Math::Sinh)
    }
    /// `f64::signum` for a non-NaN value: ±1 with the sign of self (+1 for +0).
    pub fn signum(self) -> Expr {
        Expr::Math(Math::Copysign, vec![lit(1.0), self])
    }
    /// `f64::clamp(lo, hi)` for a non-NaN range: lo below, hi above, self otherwise.
    /// `self` is evaluated up to three times; pass a local.
    pub fn clamp(self, lo: impl Into<Expr>, hi: impl Into<Expr>) -> Expr {
        let (lo, hi) = (lo.into(), hi.into());
        select(
            self.clone().lt(lo.clone()),
            lo,
            select(self.clone().gt(hi.clone()), hi, self),
        )
    }
    /// self is finite.
    pub fn is_finite(self) -> Expr {
        Expr::IsFinite(Box::new(self))
    }
    /// An index as a double.
    pub fn to_f64(self) -> Expr {
        Expr::ToF64(Box::new(self))
    }
    /// A non-negative double as an index (truncated).
    pub fn to_index(self) -> Expr {
        Expr::ToIndex(Box::new(self))
    }
    /// self < other
    pub fn lt(self, other: impl Into<Expr>) -> Expr {
        self.bin(BinOp::Lt, other)
    }
    /// self <= other
    pub fn le(self, other: impl Into<Expr>) -> Expr {
        self.bin(BinOp::Le, other)
    }
    /// self > other
    pub fn gt(self, other: impl Into<Expr>) -> Expr {
        self.bin(BinOp::Gt, other)
    }
    /// self >= other
    pub fn ge(self, other: impl Into<Expr>) -> Expr {
        self.bin(BinOp::Ge, other)
    }
    /// self == other
    pub fn eq(self, other: impl Into<Expr>) -> Expr {
        self.bin(BinOp::Eq, other)
    }
    /// self != other
    pub fn ne(self, other: impl Into<Expr>) -> Expr {
        self.bin(BinOp::Ne, other)
    }
    /// self && other
    pub fn and(self, other: impl Into<Expr>) -> Expr {
        self.bin(BinOp::And, other)
    }
    /// self || other
    pub fn or(self, other: impl Into<Expr>) -> Expr {
        self.bin(BinOp::Or, other)
    }

    /// Every double literal of the expression, for the finiteness check.
    pub(crate) fn literals(&self, out: &mut Vec<f64>) {
        match self {
            Expr::F64(v) => out.push(*v),
            Expr::Typed(d, s) => out.extend([*d, *s]),
            Expr::Nan
            | Expr::Index(_)
            | Expr::Flag(_)
            | Expr::Local(_)
            | Expr::State(_)
            | Expr::Input(_) => {}
            Expr::StateAt(_, e)
            | Expr::Table(_, e)
            | Expr::Neg(e)
            | Expr::Not(e)
            | Expr::IsFinite(e)
            | Expr::ToF64(e)
            | Expr::ToIndex(e) => e.literals(out),
            Expr::Bin(_, a, b) => {
                a.literals(out);
                b.literals(out);
            }
            Expr::Select(c, a, b) => {
                c.literals(out);
                a.literals(out);
                b.literals(out);
            }
            Expr::Math(_, args) | Expr::Call(_, args) => {
                args.iter().for_each(|a| a.literals(out));
            }
        }
    }
}

macro_rules! arithmetic {
    ($($trait:ident $method:ident $op:ident),*) => {$(
        impl<T: Into<Expr>> $trait<T> for Expr {
            type Output = Expr;
            fn $method(self, other: T) -> Expr {
                self.bin(BinOp::$op, other)
            }
        }
        impl $trait<Expr> for f64 {
            type Output = Expr;
            fn $method(self, other: Expr) -> Expr {
                Expr::F64(self).bin(BinOp::$op, other)
            }
        }
    )*};
}
arithmetic!(Add add Add, Sub sub Sub, Mul mul Mul, Div div Div);

/// !self, for a flag.
impl Not for Expr {
    type Output = Expr;
    fn not(self) -> Expr {
        Expr::Not(Box::new(self))
    }
}

impl Neg for Expr {
    type Output = Expr;
    fn neg(self) -> Expr {
        Expr::Neg(Box::new(self))
    }
}
