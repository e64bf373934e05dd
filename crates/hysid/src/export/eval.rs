//! An interpreter of the language-neutral program ([`super::program::Program`]) in either
//! floating-point type: what the generated code computes, run inside hysid.
//!
//! The export uses it to measure, before it writes a single-precision file, how far the
//! `float` code strays from the `double` one ([`measure`], the bound the header states, see
//! `docs/export.md`, "Single precision"), and to compute reference vectors. The interpreter
//! performs the program's operations in the program's order, with the semantics the
//! renderers print:
//!
//! * a literal is the `f64` rounded to the working type (`(float)v` / `v as f32`); an index
//!   becomes a float by the same rounding, a float an index by truncation;
//! * `&&`, `||` and `c ? a : b` evaluate only what C and Rust evaluate;
//! * `fmax`/`fmin` return the non-NaN argument, else the comparison's winner, else the
//!   second (the C helpers of [`super::render::c`]); the other math functions are the
//!   platform's (`f64::sin`, `f32::sin`, … call the C library's `sin` / `sinf`);
//! * index arithmetic wraps, as `size_t` does in C.
//!
//! In `f64` it is the double export to the bit (a test compares it with the library on every
//! exported kind); in `f32` it is the single export up to the target's math library (its
//! `sinf`, `expf`, `powf` may differ from the host's by an ulp), which the stated bound's
//! margin covers.

use super::code::{BinOp, Expr, Function, Math, Place, Stmt, Ty};
use super::program::Program;
use crate::{Error, Result};
use std::collections::HashMap;

/// A floating-point type the generated code may compute in: `f64` (double) or `f32`
/// (single).
pub trait Real:
    Copy
    + PartialOrd
    + std::fmt::Debug
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
    + std::ops::Neg<Output = Self>
{
    /// The literal `v` in this type (rounded to nearest).
    fn of(v: f64) -> Self;
    /// The value as an `f64` (exact).
    fn wide(self) -> f64;
    /// An index as this type (rounded to nearest).
    fn of_index(i: usize) -> Self;
    /// Truncated to an index (the C cast `(size_t)x`, Rust's `x as usize`).
    fn index(self) -> usize;
    /// Not a number.
    fn nan() -> Self;
    /// True when finite.
    fn finite(self) -> bool;
    /// The `<math.h>` function `f` of `a` (and `b`).
    fn math(f: Math, a: Self, b: Self) -> Self;
}

macro_rules! real {
    ($t:ty) => {
        impl Real for $t {
            fn of(v: f64) -> Self {
                v as $t
            }
            fn wide(self) -> f64 {
                self as f64
            }
            fn of_index(i: usize) -> Self {
                i as $t
            }
            fn index(self) -> usize {
                self as usize
            }
            fn nan() -> Self {
                <$t>::NAN
            }
            fn finite(self) -> bool {
                self.is_finite()
            }
            fn math(f: Math, a: Self, b: Self) -> Self {
                match f {
                    Math::Fabs => a.abs(),
                    Math::Floor => a.floor(),
                    Math::Sqrt => a.sqrt(),
                    Math::Pow => a.powf(b),
                    Math::Exp => a.exp(),
                    Math::Log => a.ln(),
                    Math::Tanh => a.tanh(),
                    Math::Sinh => a.sinh(),
                    Math::Sin => a.sin(),
                    Math::Cos => a.cos(),
                    Math::Tan => a.tan(),
                    Math::Atan => a.atan(),
                    Math::Copysign => a.copysign(b),
                    // The C helpers' rule: the non-NaN argument, else the winner, else the
                    // second.
                    Math::Fmax if a.is_nan() => b,
                    Math::Fmax if b.is_nan() || a > b => a,
                    Math::Fmax => b,
                    Math::Fmin if a.is_nan() => b,
                    Math::Fmin if b.is_nan() || a < b => a,
                    Math::Fmin => b,
                }
            }
        }
    };
}
real!(f32);
real!(f64);

/// A value of the program: a float, an index or a flag.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Value<R> {
    F(R),
    I(usize),
    B(bool),
}

impl<R: Real> Value<R> {
    fn zero(ty: Ty) -> Self {
        match ty {
            Ty::F64 => Value::F(R::of(0.0)),
            Ty::Index => Value::I(0),
            Ty::Flag => Value::B(false),
        }
    }
}

/// How a statement ended.
enum Flow<R> {
    Next,
    Break,
    Return(Option<Value<R>>),
}

/// The error of a program the interpreter cannot run: a bug of the exporter (the renderers
/// would print code that does not compile, or reads out of bounds).
fn bug(what: String) -> Error {
    Error::Unsupported(format!(
        "export: {what} in the generated program; this is a bug of hysid's exporter, please \
         report it"
    ))
}

/// A program's state, running in the type `R`.
pub struct Machine<'p, R> {
    program: &'p Program,
    fields: HashMap<&'p str, Vec<Value<R>>>,
    tables: HashMap<&'p str, Vec<R>>,
    functions: HashMap<&'p str, &'p Function>,
    locals: Vec<(&'p str, Value<R>)>,
    inputs: Vec<R>,
    outputs: Vec<R>,
}

impl<'p, R: Real> Machine<'p, R> {
    /// The program `program` after its initialisation (`NAME_init`, `Model::new`).
    pub fn new(program: &'p Program) -> Result<Self> {
        let mut m = Self {
            program,
            fields: HashMap::new(),
            tables: program
                .tables
                .iter()
                .map(|t| {
                    (
                        t.name.as_str(),
                        t.values.iter().map(|&v| R::of(v)).collect(),
                    )
                })
                .collect(),
            functions: program
                .functions
                .iter()
                .map(|f| (f.name.as_str(), f))
                .collect(),
            locals: Vec::new(),
            inputs: vec![R::of(0.0); program.n_inputs],
            outputs: vec![R::of(0.0); program.n_outputs],
        };
        m.reset()?;
        Ok(m)
    }

    /// Back to the initial state.
    pub fn reset(&mut self) -> Result<()> {
        self.fields = self
            .program
            .fields
            .iter()
            .map(|f| {
                (
                    f.name.as_str(),
                    vec![Value::zero(f.ty); f.len.unwrap_or(1).max(1)],
                )
            })
            .collect();
        self.locals.clear();
        let init = &self.program.init;
        self.block(init)?;
        Ok(())
    }

    /// One step: the outputs for the inputs `u` (rounded to `R`).
    pub fn step(&mut self, u: &[f64]) -> Result<Vec<R>> {
        if u.len() != self.program.n_inputs {
            return Err(bug(format!(
                "{} inputs given to a step of {}",
                u.len(),
                self.program.n_inputs
            )));
        }
        self.inputs = u.iter().map(|&v| R::of(v)).collect();
        self.locals.clear();
        let step = &self.program.step;
        self.block(step)?;
        Ok(self.outputs.clone())
    }

    /// The scalar field `name` as an index (e.g. the faults count).
    pub fn index_field(&self, name: &str) -> Option<usize> {
        match self.fields.get(name)?.first()? {
            Value::I(i) => Some(*i),
            _ => None,
        }
    }

    /// The statements `stmts` in a scope of their own.
    fn block(&mut self, stmts: &'p [Stmt]) -> Result<Flow<R>> {
        let mark = self.locals.len();
        let mut flow = Flow::Next;
        for s in stmts {
            flow = self.stmt(s)?;
            if !matches!(flow, Flow::Next) {
                break;
            }
        }
        self.locals.truncate(mark);
        Ok(flow)
    }

    fn stmt(&mut self, s: &'p Stmt) -> Result<Flow<R>> {
        match s {
            Stmt::Let { name, value, .. } => {
                let v = self.expr(value)?;
                self.locals.push((name.as_str(), v));
            }
            Stmt::Assign(place, value) => {
                let v = self.expr(value)?;
                match place {
                    Place::Local(name) => *self.local_mut(name)? = v,
                    Place::State(field) => *self.field_mut(field, 0)? = v,
                    Place::StateAt(field, i) => {
                        let i = self.index(i)?;
                        *self.field_mut(field, i)? = v;
                    }
                    Place::Output(i) => {
                        let f = self.float_value(v)?;
                        *self
                            .outputs
                            .get_mut(*i)
                            .ok_or_else(|| bug(format!("output {i} out of range")))? = f;
                    }
                }
            }
            Stmt::If(c, then, otherwise) => {
                return if self.flag(c)? {
                    self.block(then)
                } else {
                    self.block(otherwise)
                };
            }
            Stmt::For {
                var,
                from,
                to,
                body,
            } => {
                let (from, to) = (self.index(from)?, self.index(to)?);
                for i in from..to {
                    self.locals.push((var.as_str(), Value::I(i)));
                    let flow = self.block(body)?;
                    self.locals.pop();
                    match flow {
                        Flow::Next => {}
                        Flow::Break => break,
                        ret @ Flow::Return(_) => return Ok(ret),
                    }
                }
            }
            Stmt::While(c, body) => {
                while self.flag(c)? {
                    match self.block(body)? {
                        Flow::Next => {}
                        Flow::Break => break,
                        ret @ Flow::Return(_) => return Ok(ret),
                    }
                }
            }
            Stmt::Break => return Ok(Flow::Break),
            Stmt::Return(e) => {
                let v = e.as_ref().map(|e| self.expr(e)).transpose()?;
                return Ok(Flow::Return(v));
            }
            Stmt::Call(name, args) => {
                self.call(name, args)?;
            }
        }
        Ok(Flow::Next)
    }

    fn local_mut(&mut self, name: &str) -> Result<&mut Value<R>> {
        self.locals
            .iter_mut()
            .rev()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| v)
            .ok_or_else(|| bug(format!("the local '{name}' is not declared")))
    }

    fn field_mut(&mut self, name: &str, i: usize) -> Result<&mut Value<R>> {
        self.fields
            .get_mut(name)
            .and_then(|f| f.get_mut(i))
            .ok_or_else(|| bug(format!("the field '{name}[{i}]' does not exist")))
    }

    fn field(&self, name: &str, i: usize) -> Result<Value<R>> {
        self.fields
            .get(name)
            .and_then(|f| f.get(i))
            .copied()
            .ok_or_else(|| bug(format!("the field '{name}[{i}]' does not exist")))
    }

    fn call(&mut self, name: &str, args: &'p [Expr]) -> Result<Option<Value<R>>> {
        let f = *self
            .functions
            .get(name)
            .ok_or_else(|| bug(format!("the helper '{name}' does not exist")))?;
        let values = args
            .iter()
            .map(|a| self.expr(a))
            .collect::<Result<Vec<_>>>()?;
        // The callee sees its parameters only: its frame starts above the caller's locals,
        // which stay untouched below it.
        let saved = std::mem::take(&mut self.locals);
        for ((param, _), v) in f.params.iter().zip(values) {
            self.locals.push((param.as_str(), v));
        }
        let flow = self.block(&f.body);
        self.locals = saved;
        match flow? {
            Flow::Return(v) => Ok(v),
            _ => Ok(None),
        }
    }

    fn float_value(&self, v: Value<R>) -> Result<R> {
        match v {
            Value::F(x) => Ok(x),
            other => Err(bug(format!("a float expected, {other:?} found"))),
        }
    }

    fn float(&mut self, e: &'p Expr) -> Result<R> {
        let v = self.expr(e)?;
        self.float_value(v)
    }

    fn index(&mut self, e: &'p Expr) -> Result<usize> {
        match self.expr(e)? {
            Value::I(i) => Ok(i),
            other => Err(bug(format!("an index expected, {other:?} found"))),
        }
    }

    fn flag(&mut self, e: &'p Expr) -> Result<bool> {
        match self.expr(e)? {
            Value::B(b) => Ok(b),
            other => Err(bug(format!("a flag expected, {other:?} found"))),
        }
    }

    fn expr(&mut self, e: &'p Expr) -> Result<Value<R>> {
        Ok(match e {
            Expr::F64(v) => Value::F(R::of(*v)),
            Expr::Nan => Value::F(R::nan()),
            Expr::Index(i) => Value::I(*i),
            Expr::Flag(b) => Value::B(*b),
            Expr::Local(name) => self
                .locals
                .iter()
                .rev()
                .find(|(n, _)| n == name)
                .map(|(_, v)| *v)
                .ok_or_else(|| bug(format!("the local '{name}' is not declared")))?,
            Expr::State(field) => self.field(field, 0)?,
            Expr::StateAt(field, i) => {
                let i = self.index(i)?;
                self.field(field, i)?
            }
            Expr::Table(name, i) => {
                let i = self.index(i)?;
                let v = self
                    .tables
                    .get(name.as_str())
                    .and_then(|t| t.get(i))
                    .copied()
                    .ok_or_else(|| {
                        bug(format!("the table element '{name}[{i}]' does not exist"))
                    })?;
                Value::F(v)
            }
            Expr::Input(i) => Value::F(
                *self
                    .inputs
                    .get(*i)
                    .ok_or_else(|| bug(format!("input {i} out of range")))?,
            ),
            Expr::Neg(a) => Value::F(-self.float(a)?),
            Expr::Not(a) => Value::B(!self.flag(a)?),
            Expr::Bin(BinOp::And, a, b) => Value::B(self.flag(a)? && self.flag(b)?),
            Expr::Bin(BinOp::Or, a, b) => Value::B(self.flag(a)? || self.flag(b)?),
            Expr::Bin(op, a, b) => {
                let (a, b) = (self.expr(a)?, self.expr(b)?);
                binary(*op, a, b)?
            }
            Expr::Math(f, args) => {
                let mut xs = [R::of(0.0); 2];
                for (slot, a) in xs.iter_mut().zip(args) {
                    *slot = self.float(a)?;
                }
                Value::F(R::math(*f, xs[0], xs[1]))
            }
            Expr::IsFinite(a) => Value::B(self.float(a)?.finite()),
            Expr::ToF64(a) => Value::F(R::of_index(self.index(a)?)),
            Expr::ToIndex(a) => Value::I(self.float(a)?.index()),
            Expr::Select(c, a, b) => {
                if self.flag(c)? {
                    self.expr(a)?
                } else {
                    self.expr(b)?
                }
            }
            Expr::Call(name, args) => self
                .call(name, args)?
                .ok_or_else(|| bug(format!("the helper '{name}' returned no value")))?,
        })
    }
}

/// `a op b` for operands of one type (not `&&`/`||`).
fn binary<R: Real>(op: BinOp, a: Value<R>, b: Value<R>) -> Result<Value<R>> {
    use BinOp::*;
    Ok(match (a, b) {
        (Value::F(x), Value::F(y)) => match op {
            Add => Value::F(x + y),
            Sub => Value::F(x - y),
            Mul => Value::F(x * y),
            Div => Value::F(x / y),
            Lt => Value::B(x < y),
            Le => Value::B(x <= y),
            Gt => Value::B(x > y),
            Ge => Value::B(x >= y),
            Eq => Value::B(x == y),
            Ne => Value::B(x != y),
            And | Or => return Err(bug("'&&' or '||' on floats".into())),
        },
        (Value::I(x), Value::I(y)) => match op {
            Add => Value::I(x.wrapping_add(y)),
            Sub => Value::I(x.wrapping_sub(y)),
            Mul => Value::I(x.wrapping_mul(y)),
            Div => Value::I(
                x.checked_div(y)
                    .ok_or_else(|| bug("an index divided by zero".into()))?,
            ),
            Lt => Value::B(x < y),
            Le => Value::B(x <= y),
            Gt => Value::B(x > y),
            Ge => Value::B(x >= y),
            Eq => Value::B(x == y),
            Ne => Value::B(x != y),
            And | Or => return Err(bug("'&&' or '||' on indices".into())),
        },
        (Value::B(x), Value::B(y)) => match op {
            Eq => Value::B(x == y),
            Ne => Value::B(x != y),
            _ => return Err(bug(format!("the operator {} on flags", op.symbol()))),
        },
        (a, b) => {
            return Err(bug(format!(
                "the operator {} on {a:?} and {b:?}",
                op.symbol()
            )))
        }
    })
}

/// The outputs of `program` in the type `R` on the input rows `inputs`, from its initial
/// state.
pub fn run<R: Real>(program: &Program, inputs: &[Vec<f64>]) -> Result<Vec<Vec<f64>>> {
    let mut m = Machine::<R>::new(program)?;
    inputs
        .iter()
        .map(|u| Ok(m.step(u)?.into_iter().map(Real::wide).collect()))
        .collect()
}

/// How far the single-precision program strays from the double one on a record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Deviation {
    /// The largest |single − double| over the record and the outputs.
    pub max_abs: f64,
    /// The output's range on the record (max − min of the double outputs, the widest of the
    /// outputs; 1 when the outputs are constant).
    pub range: f64,
}

impl Deviation {
    /// The largest |single − double| ÷ (output range): the figure the header states.
    pub fn relative(&self) -> f64 {
        self.max_abs / self.range
    }
}

/// The deviation of `program` run in `f32` from the same program run in `f64`, on the input
/// rows `inputs` (each input rounded to `f32` for the single run, as a caller of the float
/// code holds them). Samples where the double output is not finite count as infinitely far
/// unless the single one is the same non-finite value.
pub fn measure(program: &Program, inputs: &[Vec<f64>]) -> Result<Deviation> {
    let double = run::<f64>(program, inputs)?;
    let rounded: Vec<Vec<f64>> = inputs
        .iter()
        .map(|row| row.iter().map(|&v| v as f32 as f64).collect())
        .collect();
    let single = run::<f32>(program, &rounded)?;
    let mut max_abs: f64 = 0.0;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (d, s) in double.iter().zip(&single) {
        for (&a, &b) in d.iter().zip(s) {
            if a.is_finite() {
                lo = lo.min(a);
                hi = hi.max(a);
            }
            let gap = if a == b || (a.is_nan() && b.is_nan()) {
                0.0
            } else {
                (a - b).abs()
            };
            max_abs = max_abs.max(if gap.is_nan() { f64::INFINITY } else { gap });
        }
    }
    let range = if hi > lo { hi - lo } else { 1.0 };
    Ok(Deviation { max_abs, range })
}
