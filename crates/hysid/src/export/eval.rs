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

use super::code::{BinOp, Expr, Math, Place, Stmt, Ty};
use super::program::Program;
use crate::{Error, Result};
use std::collections::HashMap;
use std::rc::Rc;

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
    /// True for `f32`: selects the single-precision value of an [`Expr::Typed`] constant.
    const SINGLE: bool;
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
    ($t:ty, $single:expr) => {
        impl Real for $t {
            const SINGLE: bool = $single;
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
real!(f32, true);
real!(f64, false);

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

// The program resolved for running: every name replaced by an index (a field, a table, a
// helper, a local's slot in its function's frame), so that a step costs no lookup.

/// A resolved expression.
enum E {
    Lit(Value<f64>),
    Local(usize),
    Field(usize, Option<Box<E>>),
    Table(usize, Box<E>),
    Input(usize),
    Neg(Box<E>),
    Not(Box<E>),
    And(Box<E>, Box<E>),
    Or(Box<E>, Box<E>),
    Bin(BinOp, Box<E>, Box<E>),
    Math(Math, Vec<E>),
    IsFinite(Box<E>),
    ToFloat(Box<E>),
    ToIndex(Box<E>),
    Select(Box<E>, Box<E>, Box<E>),
    Call(usize, Vec<E>),
}

/// Where a resolved assignment writes.
enum P {
    Local(usize),
    Field(usize, Option<E>),
    Output(usize),
}

/// A resolved statement.
enum S {
    Set(P, E),
    If(E, Vec<S>, Vec<S>),
    For(usize, E, E, Vec<S>),
    While(E, Vec<S>),
    Break,
    Return(Option<E>),
    Call(usize, Vec<E>),
}

/// A resolved helper: its body and the size of its frame (its parameters first).
struct F {
    body: Vec<S>,
    slots: usize,
}

/// Resolves names while compiling one function (or the init, or the step).
struct Resolver<'a> {
    fields: &'a HashMap<&'a str, usize>,
    tables: &'a HashMap<&'a str, usize>,
    functions: &'a HashMap<&'a str, usize>,
    scope: Vec<(&'a str, usize)>,
    slots: usize,
    /// The code is single precision ([`Expr::Typed`] takes its second value).
    single: bool,
}

impl<'a> Resolver<'a> {
    fn declare(&mut self, name: &'a str) -> usize {
        let slot = self.slots;
        self.slots += 1;
        self.scope.push((name, slot));
        slot
    }

    fn local(&self, name: &str) -> Result<usize> {
        self.scope
            .iter()
            .rev()
            .find(|(n, _)| *n == name)
            .map(|(_, s)| *s)
            .ok_or_else(|| bug(format!("the local '{name}' is not declared")))
    }

    fn field(&self, name: &str) -> Result<usize> {
        self.fields
            .get(name)
            .copied()
            .ok_or_else(|| bug(format!("the field '{name}' does not exist")))
    }

    fn function(&self, name: &str) -> Result<usize> {
        self.functions
            .get(name)
            .copied()
            .ok_or_else(|| bug(format!("the helper '{name}' does not exist")))
    }

    fn block(&mut self, stmts: &'a [Stmt]) -> Result<Vec<S>> {
        let mark = self.scope.len();
        let out = stmts
            .iter()
            .map(|s| self.stmt(s))
            .collect::<Result<Vec<_>>>();
        self.scope.truncate(mark);
        out
    }

    fn stmt(&mut self, s: &'a Stmt) -> Result<S> {
        Ok(match s {
            Stmt::Let { name, value, .. } => {
                let value = self.expr(value)?;
                S::Set(P::Local(self.declare(name)), value)
            }
            Stmt::Assign(place, value) => {
                let place = match place {
                    Place::Local(name) => P::Local(self.local(name)?),
                    Place::State(field) => P::Field(self.field(field)?, None),
                    Place::StateAt(field, i) => P::Field(self.field(field)?, Some(self.expr(i)?)),
                    Place::Output(i) => P::Output(*i),
                };
                S::Set(place, self.expr(value)?)
            }
            Stmt::If(c, a, b) => S::If(self.expr(c)?, self.block(a)?, self.block(b)?),
            Stmt::For {
                var,
                from,
                to,
                body,
            } => {
                let (from, to) = (self.expr(from)?, self.expr(to)?);
                let mark = self.scope.len();
                let slot = self.declare(var);
                let body = self.block(body)?;
                self.scope.truncate(mark);
                S::For(slot, from, to, body)
            }
            Stmt::While(c, body) => S::While(self.expr(c)?, self.block(body)?),
            Stmt::Break => S::Break,
            Stmt::Return(e) => S::Return(e.as_ref().map(|e| self.expr(e)).transpose()?),
            Stmt::Call(name, args) => S::Call(self.function(name)?, self.exprs(args)?),
        })
    }

    fn exprs(&mut self, es: &'a [Expr]) -> Result<Vec<E>> {
        es.iter().map(|e| self.expr(e)).collect()
    }

    fn boxed(&mut self, e: &'a Expr) -> Result<Box<E>> {
        Ok(Box::new(self.expr(e)?))
    }

    fn expr(&mut self, e: &'a Expr) -> Result<E> {
        Ok(match e {
            Expr::F64(v) => E::Lit(Value::F(*v)),
            Expr::Typed(d, s) => E::Lit(Value::F(if self.single { *s } else { *d })),
            Expr::Nan => E::Lit(Value::F(f64::NAN)),
            Expr::Index(i) => E::Lit(Value::I(*i)),
            Expr::Flag(b) => E::Lit(Value::B(*b)),
            Expr::Local(name) => E::Local(self.local(name)?),
            Expr::State(field) => E::Field(self.field(field)?, None),
            Expr::StateAt(field, i) => E::Field(self.field(field)?, Some(self.boxed(i)?)),
            Expr::Table(name, i) => E::Table(
                self.tables
                    .get(name.as_str())
                    .copied()
                    .ok_or_else(|| bug(format!("the table '{name}' does not exist")))?,
                self.boxed(i)?,
            ),
            Expr::Input(i) => E::Input(*i),
            Expr::Neg(a) => E::Neg(self.boxed(a)?),
            Expr::Not(a) => E::Not(self.boxed(a)?),
            Expr::Bin(BinOp::And, a, b) => E::And(self.boxed(a)?, self.boxed(b)?),
            Expr::Bin(BinOp::Or, a, b) => E::Or(self.boxed(a)?, self.boxed(b)?),
            Expr::Bin(op, a, b) => E::Bin(*op, self.boxed(a)?, self.boxed(b)?),
            Expr::Math(f, args) => E::Math(*f, self.exprs(args)?),
            Expr::IsFinite(a) => E::IsFinite(self.boxed(a)?),
            Expr::ToF64(a) => E::ToFloat(self.boxed(a)?),
            Expr::ToIndex(a) => E::ToIndex(self.boxed(a)?),
            Expr::Select(c, a, b) => E::Select(self.boxed(c)?, self.boxed(a)?, self.boxed(b)?),
            Expr::Call(name, args) => E::Call(self.function(name)?, self.exprs(args)?),
        })
    }
}

/// The resolved code of a program: its helpers, initialisation and step.
struct Code {
    functions: Vec<F>,
    init: F,
    step: F,
}

/// A program's state, running in the type `R`.
pub struct Machine<R> {
    /// Each field's length and type, for the reset.
    shapes: Vec<(usize, Ty)>,
    field_names: Vec<String>,
    fields: Vec<Vec<Value<R>>>,
    tables: Vec<Vec<R>>,
    code: Rc<Code>,
    /// The statements executed so far, and the most allowed ([`Machine::limit`]).
    ops: u64,
    budget: u64,
    n_inputs: usize,
    inputs: Vec<R>,
    outputs: Vec<R>,
}

impl<R: Real> Machine<R> {
    /// The program `program` after its initialisation (`NAME_init`, `Model::new`).
    pub fn new(program: &Program) -> Result<Self> {
        let fields = index_by_name(&program.fields, |f| &f.name);
        let tables = index_by_name(&program.tables, |t| &t.name);
        let functions = index_by_name(&program.functions, |f| &f.name);
        let compile = |params: &[(String, Ty)], body: &[Stmt]| -> Result<F> {
            let mut r = Resolver {
                fields: &fields,
                tables: &tables,
                functions: &functions,
                scope: Vec::new(),
                slots: 0,
                single: R::SINGLE,
            };
            for (name, _) in params {
                r.declare(name);
            }
            let body = r.block(body)?;
            Ok(F {
                body,
                slots: r.slots,
            })
        };
        let code = Code {
            functions: program
                .functions
                .iter()
                .map(|f| compile(&f.params, &f.body))
                .collect::<Result<_>>()?,
            init: compile(&[], &program.init)?,
            step: compile(&[], &program.step)?,
        };
        let mut m = Self {
            shapes: program
                .fields
                .iter()
                .map(|f| (f.len.unwrap_or(1).max(1), f.ty))
                .collect(),
            field_names: program.fields.iter().map(|f| f.name.clone()).collect(),
            fields: Vec::new(),
            tables: program
                .tables
                .iter()
                .map(|t| t.values.iter().map(|&v| R::of(v)).collect())
                .collect(),
            code: Rc::new(code),
            ops: 0,
            budget: u64::MAX,
            n_inputs: program.n_inputs,
            inputs: vec![R::of(0.0); program.n_inputs],
            outputs: vec![R::of(0.0); program.n_outputs],
        };
        m.reset()?;
        Ok(m)
    }

    /// Back to the initial state.
    pub fn reset(&mut self) -> Result<()> {
        self.fields = self
            .shapes
            .iter()
            .map(|&(n, ty)| vec![Value::zero(ty); n])
            .collect();
        let code = Rc::clone(&self.code);
        self.run_body(&code.init, Vec::new()).map(|_| ())
    }

    /// One step: the outputs for the inputs `u` (rounded to `R`).
    pub fn step(&mut self, u: &[f64]) -> Result<Vec<R>> {
        if u.len() != self.n_inputs {
            return Err(bug(format!(
                "{} inputs given to a step of {}",
                u.len(),
                self.n_inputs
            )));
        }
        for (slot, &v) in self.inputs.iter_mut().zip(u) {
            *slot = R::of(v);
        }
        let code = Rc::clone(&self.code);
        self.run_body(&code.step, Vec::new())?;
        Ok(self.outputs.clone())
    }

    /// The statements executed since [`Machine::new`].
    pub fn ops(&self) -> u64 {
        self.ops
    }

    /// Stops the machine with an error once it has executed `budget` statements in all.
    pub fn limit(&mut self, budget: u64) {
        self.budget = budget;
    }

    /// The scalar field `name` as an index (e.g. the faults count).
    pub fn index_field(&self, name: &str) -> Option<usize> {
        let i = self.field_names.iter().position(|n| n == name)?;
        match self.fields.get(i)?.first()? {
            Value::I(i) => Some(*i),
            _ => None,
        }
    }

    /// Runs `f` with a frame starting with `args`.
    fn run_body(&mut self, f: &F, mut args: Vec<Value<R>>) -> Result<Option<Value<R>>> {
        args.resize(f.slots.max(args.len()), Value::I(0));
        let mut frame = args;
        match self.block(&f.body, &mut frame)? {
            Flow::Return(v) => Ok(v),
            _ => Ok(None),
        }
    }

    fn block(&mut self, stmts: &[S], frame: &mut [Value<R>]) -> Result<Flow<R>> {
        for s in stmts {
            match self.stmt(s, frame)? {
                Flow::Next => {}
                other => return Ok(other),
            }
        }
        Ok(Flow::Next)
    }

    fn stmt(&mut self, s: &S, frame: &mut [Value<R>]) -> Result<Flow<R>> {
        self.ops += 1;
        if self.ops > self.budget {
            return Err(Error::Unsupported(format!(
                "the program ran beyond its budget of {} statements",
                self.budget
            )));
        }
        match s {
            S::Set(place, value) => {
                let v = self.expr(value, frame)?;
                match place {
                    P::Local(slot) => frame[*slot] = v,
                    P::Field(f, at) => {
                        let i = match at {
                            Some(i) => self.index(i, frame)?,
                            None => 0,
                        };
                        *self
                            .fields
                            .get_mut(*f)
                            .and_then(|f| f.get_mut(i))
                            .ok_or_else(|| bug(format!("a field element [{i}] out of range")))? = v;
                    }
                    P::Output(i) => {
                        let f = float_of(v)?;
                        *self
                            .outputs
                            .get_mut(*i)
                            .ok_or_else(|| bug(format!("output {i} out of range")))? = f;
                    }
                }
            }
            S::If(c, then, otherwise) => {
                return if self.flag(c, frame)? {
                    self.block(then, frame)
                } else {
                    self.block(otherwise, frame)
                };
            }
            S::For(slot, from, to, body) => {
                let (from, to) = (self.index(from, frame)?, self.index(to, frame)?);
                for i in from..to {
                    frame[*slot] = Value::I(i);
                    match self.block(body, frame)? {
                        Flow::Next => {}
                        Flow::Break => break,
                        ret @ Flow::Return(_) => return Ok(ret),
                    }
                }
            }
            S::While(c, body) => {
                while self.flag(c, frame)? {
                    match self.block(body, frame)? {
                        Flow::Next => {}
                        Flow::Break => break,
                        ret @ Flow::Return(_) => return Ok(ret),
                    }
                }
            }
            S::Break => return Ok(Flow::Break),
            S::Return(e) => {
                let v = e.as_ref().map(|e| self.expr(e, frame)).transpose()?;
                return Ok(Flow::Return(v));
            }
            S::Call(f, args) => {
                self.call(*f, args, frame)?;
            }
        }
        Ok(Flow::Next)
    }

    fn call(&mut self, f: usize, args: &[E], frame: &mut [Value<R>]) -> Result<Option<Value<R>>> {
        let values = args
            .iter()
            .map(|a| self.expr(a, frame))
            .collect::<Result<Vec<_>>>()?;
        let code = Rc::clone(&self.code);
        let body = code
            .functions
            .get(f)
            .ok_or_else(|| bug(format!("helper {f} out of range")))?;
        self.run_body(body, values)
    }

    fn float(&mut self, e: &E, frame: &mut [Value<R>]) -> Result<R> {
        let v = self.expr(e, frame)?;
        float_of(v)
    }

    fn index(&mut self, e: &E, frame: &mut [Value<R>]) -> Result<usize> {
        match self.expr(e, frame)? {
            Value::I(i) => Ok(i),
            other => Err(bug(format!("an index expected, {other:?} found"))),
        }
    }

    fn flag(&mut self, e: &E, frame: &mut [Value<R>]) -> Result<bool> {
        match self.expr(e, frame)? {
            Value::B(b) => Ok(b),
            other => Err(bug(format!("a flag expected, {other:?} found"))),
        }
    }

    fn expr(&mut self, e: &E, frame: &mut [Value<R>]) -> Result<Value<R>> {
        Ok(match e {
            E::Lit(Value::F(v)) => Value::F(R::of(*v)),
            E::Lit(Value::I(i)) => Value::I(*i),
            E::Lit(Value::B(b)) => Value::B(*b),
            E::Local(slot) => frame[*slot],
            E::Field(f, at) => {
                let i = match at {
                    Some(i) => self.index(i, frame)?,
                    None => 0,
                };
                self.fields
                    .get(*f)
                    .and_then(|f| f.get(i))
                    .copied()
                    .ok_or_else(|| bug(format!("a field element [{i}] out of range")))?
            }
            E::Table(t, i) => {
                let i = self.index(i, frame)?;
                Value::F(
                    self.tables
                        .get(*t)
                        .and_then(|t| t.get(i))
                        .copied()
                        .ok_or_else(|| bug(format!("a table element [{i}] out of range")))?,
                )
            }
            E::Input(i) => Value::F(
                *self
                    .inputs
                    .get(*i)
                    .ok_or_else(|| bug(format!("input {i} out of range")))?,
            ),
            E::Neg(a) => Value::F(-self.float(a, frame)?),
            E::Not(a) => Value::B(!self.flag(a, frame)?),
            E::And(a, b) => Value::B(self.flag(a, frame)? && self.flag(b, frame)?),
            E::Or(a, b) => Value::B(self.flag(a, frame)? || self.flag(b, frame)?),
            E::Bin(op, a, b) => {
                let (a, b) = (self.expr(a, frame)?, self.expr(b, frame)?);
                binary(*op, a, b)?
            }
            E::Math(f, args) => {
                let mut xs = [R::of(0.0); 2];
                for (slot, a) in xs.iter_mut().zip(args) {
                    *slot = self.float(a, frame)?;
                }
                Value::F(R::math(*f, xs[0], xs[1]))
            }
            E::IsFinite(a) => Value::B(self.float(a, frame)?.finite()),
            E::ToFloat(a) => Value::F(R::of_index(self.index(a, frame)?)),
            E::ToIndex(a) => Value::I(self.float(a, frame)?.index()),
            E::Select(c, a, b) => {
                if self.flag(c, frame)? {
                    self.expr(a, frame)?
                } else {
                    self.expr(b, frame)?
                }
            }
            E::Call(f, args) => self
                .call(*f, args, frame)?
                .ok_or_else(|| bug(format!("helper {f} returned no value")))?,
        })
    }
}

/// Each item's position, by its name.
fn index_by_name<T>(items: &[T], name: impl Fn(&T) -> &String) -> HashMap<&str, usize> {
    items
        .iter()
        .enumerate()
        .map(|(i, item)| (name(item).as_str(), i))
        .collect()
}

/// The float in `v`, else a bug.
fn float_of<R: Real>(v: Value<R>) -> Result<R> {
    match v {
        Value::F(x) => Ok(x),
        other => Err(bug(format!("a float expected, {other:?} found"))),
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
    Ok(run_counted::<R>(program, inputs, u64::MAX)?.0)
}

/// [`run`] within `budget` statements; also the statements executed.
fn run_counted<R: Real>(
    program: &Program,
    inputs: &[Vec<f64>],
    budget: u64,
) -> Result<(Vec<Vec<f64>>, u64)> {
    let mut m = Machine::<R>::new(program)?;
    m.limit(budget);
    let out = inputs
        .iter()
        .map(|u| Ok(m.step(u)?.into_iter().map(Real::wide).collect()))
        .collect::<Result<Vec<_>>>()?;
    Ok((out, m.ops()))
}

/// The most statements the double run of [`measure`] may execute (a few seconds).
pub const MEASURE_WORK: u64 = 50_000_000;

/// How many times the statements of the double run a float run may execute
/// ([`measure`]).
pub const FLOAT_WORK: u64 = 4;

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
///
/// The float run may execute at most [`FLOAT_WORK`] times the statements of the double one
/// (plus 1000 a sample): a step whose loops stop on tolerances below the resolution of
/// `float` runs to its iteration caps instead, and is refused with that reason.
pub fn measure(program: &Program, inputs: &[Vec<f64>]) -> Result<Deviation> {
    let (double, ops) = run_counted::<f64>(program, inputs, MEASURE_WORK).map_err(|_| {
        Error::Unsupported(format!(
            "single precision: measuring the float code's bound would run beyond \
             {MEASURE_WORK:e} statements of the exporter's interpreter on the {} samples of \
             the test record (a step of many iterations: the differential families' \
             inverses); export in double (--precision double)",
            inputs.len()
        ))
    })?;
    let rounded: Vec<Vec<f64>> = inputs
        .iter()
        .map(|row| row.iter().map(|&v| v as f32 as f64).collect())
        .collect();
    let budget = FLOAT_WORK * ops + 1000 * inputs.len() as u64;
    let single = run_counted::<f32>(program, &rounded, budget)
        .map_err(|_| {
            Error::Unsupported(format!(
                "single precision: the float step works more than {FLOAT_WORK} times as long \
                 as the double one (its iterations stop on tolerances finer than float \
                 resolution); export in double (--precision double)"
            ))
        })?
        .0;
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
