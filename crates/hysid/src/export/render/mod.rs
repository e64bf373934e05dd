//! The renderers: a [`Program`](super::program::Program) printed as C99 ([`c`]) or as `no_std`
//! Rust ([`rust`]). Both print expressions and statements through one printer (`Printer`)
//! that asks a `Syntax` for the few things the two languages spell differently (state
//! access `s->x` / `self.x`, `fabs` / `libm::fabs`, casts, the conditional expression,
//! declarations and loops). Both print in either [`Precision`]: the type `Ty::F64` is
//! `double`/`f64` or `float`/`f32`, a literal the `f64` constant or its nearest `float`
//! (`float_digits`), a math function `sin` or `sinf`.

pub mod c;
pub mod rust;

use super::code::{Expr, Math, Place, Stmt, Ty};
use super::precision::Precision;

/// The precedence of an atom (a name, a literal, a call): never parenthesised.
const ATOM: u8 = 10;
/// The precedence of a prefix operator (`-x`, `!x`, a C cast).
const UNARY: u8 = 8;

/// What C and Rust spell differently.
pub(crate) trait Syntax {
    /// The literal `v` (finite; `v` rounded to the precision's type).
    fn literal(&self, v: f64) -> String;
    /// True when the code is single precision (selects [`Expr::Typed`]'s second value).
    fn single(&self) -> bool;
    /// The scalar field `field` of the state.
    fn state(&self, field: &str) -> String;
    /// The constant table `name`.
    fn table(&self, name: &str) -> String;
    /// The math function `f`.
    fn math(&self, f: Math) -> String;
    /// A call of the helper `name` with printed arguments.
    fn call(&self, name: &str, args: &[String]) -> String;
    /// A flag literal.
    fn flag(&self, v: bool) -> &'static str;
    /// Not a number.
    fn nan(&self) -> &'static str;
    /// `x is finite` from the printed x and its precedence.
    fn is_finite(&self, x: (String, u8)) -> (String, u8);
    /// A cast of the printed x (with its precedence) to `ty`.
    fn cast(&self, x: (String, u8), ty: Ty) -> (String, u8);
    /// `c ? a : b` from printed top-level parts.
    fn select(&self, c: String, a: String, b: String) -> (String, u8);
    /// The declaration of a local.
    fn declare(&self, name: &str, ty: Ty, mutable: bool, value: String) -> String;
    /// The head of a counting loop `for var in from..to`.
    fn for_head(&self, var: &str, from: String, to: String) -> String;
    /// The head of `if`/`while` with a printed condition (`if (c)` / `if c`).
    fn cond_head(&self, keyword: &str, c: String) -> String;
    /// Element `i` (printed) of the printed array `array`; `constant` when `i` is a literal
    /// (which the compiler checks against the array's length). By default `array[i]`.
    fn element(&self, array: String, i: String, constant: bool) -> String {
        let _ = constant;
        format!("{array}[{i}]")
    }
    /// The statement storing the printed `value` in element `i` of `array` (see
    /// [`Syntax::element`]). By default `array[i] = value;`.
    fn store(&self, array: String, i: String, constant: bool, value: String) -> String {
        format!("{} = {value};", self.element(array, i, constant))
    }
}

/// Prints expressions and statements in one language.
pub(crate) struct Printer<'a> {
    syntax: &'a dyn Syntax,
}

impl<'a> Printer<'a> {
    /// A printer for `syntax`.
    pub(crate) fn new(syntax: &'a dyn Syntax) -> Self {
        Self { syntax }
    }

    /// `e` at the top level (no enclosing operator).
    pub(crate) fn top(&self, e: &Expr) -> String {
        self.expr(e).0
    }

    /// `e` as an operand that needs precedence at least `min`.
    fn operand(&self, e: &Expr, min: u8) -> String {
        let (s, p) = self.expr(e);
        if p >= min {
            s
        } else {
            format!("({s})")
        }
    }

    /// `e` printed, with its precedence.
    fn expr(&self, e: &Expr) -> (String, u8) {
        let x = self.syntax;
        match e {
            Expr::F64(v) => {
                // A negative literal is parenthesised whenever it is an operand.
                (x.literal(*v), if v.is_sign_negative() { 0 } else { ATOM })
            }
            Expr::Typed(d, s) => {
                let v = if x.single() { *s } else { *d };
                (x.literal(v), if v.is_sign_negative() { 0 } else { ATOM })
            }
            Expr::Nan => (x.nan().into(), ATOM),
            Expr::Index(i) => (i.to_string(), ATOM),
            Expr::Flag(b) => (x.flag(*b).into(), ATOM),
            Expr::Local(name) => (name.clone(), ATOM),
            Expr::State(field) => (x.state(field), ATOM),
            Expr::StateAt(field, i) => {
                (x.element(x.state(field), self.top(i), is_literal(i)), ATOM)
            }
            Expr::Table(name, i) => (x.element(x.table(name), self.top(i), is_literal(i)), ATOM),
            Expr::Input(i) => (format!("u[{i}]"), ATOM),
            Expr::Neg(a) => (format!("-{}", self.operand(a, UNARY + 1)), UNARY),
            Expr::Not(a) => (format!("!{}", self.operand(a, UNARY + 1)), UNARY),
            Expr::Bin(op, a, b) => {
                let p = op.precedence();
                // Comparisons are never chained; every operator groups to the left, so a
                // right operand of the same precedence keeps its parentheses.
                let left_min = if p == 3 { p + 1 } else { p };
                let s = format!(
                    "{} {} {}",
                    self.operand(a, left_min),
                    op.symbol(),
                    self.operand(b, p + 1)
                );
                (s, p)
            }
            Expr::Math(f, args) => {
                let args: Vec<String> = args.iter().map(|a| self.top(a)).collect();
                (format!("{}({})", x.math(*f), args.join(", ")), ATOM)
            }
            Expr::IsFinite(a) => x.is_finite(self.expr(a)),
            Expr::ToF64(a) => x.cast(self.expr(a), Ty::F64),
            Expr::ToIndex(a) => x.cast(self.expr(a), Ty::Index),
            Expr::Select(c, a, b) => x.select(self.top(c), self.top(a), self.top(b)),
            Expr::Call(name, args) => {
                let args: Vec<String> = args.iter().map(|a| self.top(a)).collect();
                (x.call(name, &args), ATOM)
            }
        }
    }

    /// The statements `stmts` at indentation `depth` (four spaces a level) into `out`.
    pub(crate) fn stmts(&self, stmts: &[Stmt], depth: usize, out: &mut String) {
        for s in stmts {
            self.stmt(s, depth, out);
        }
    }

    fn line(depth: usize, text: &str, out: &mut String) {
        out.push_str(&"    ".repeat(depth));
        out.push_str(text);
        out.push('\n');
    }

    fn stmt(&self, s: &Stmt, depth: usize, out: &mut String) {
        let x = self.syntax;
        match s {
            Stmt::Let {
                name,
                ty,
                mutable,
                value,
            } => Self::line(depth, &x.declare(name, *ty, *mutable, self.top(value)), out),
            Stmt::Assign(place, value) => {
                let value = self.top(value);
                let line = match place {
                    Place::Local(name) => format!("{name} = {value};"),
                    Place::State(field) => format!("{} = {value};", x.state(field)),
                    Place::StateAt(field, i) => {
                        x.store(x.state(field), self.top(i), is_literal(i), value)
                    }
                    Place::Output(i) => format!("y[{i}] = {value};"),
                };
                Self::line(depth, &line, out);
            }
            Stmt::If(c, then, otherwise) => {
                Self::line(
                    depth,
                    &format!("{} {{", x.cond_head("if", self.top(c))),
                    out,
                );
                self.stmts(then, depth + 1, out);
                if otherwise.is_empty() {
                    Self::line(depth, "}", out);
                } else {
                    Self::line(depth, "} else {", out);
                    self.stmts(otherwise, depth + 1, out);
                    Self::line(depth, "}", out);
                }
            }
            Stmt::For {
                var,
                from,
                to,
                body,
            } => {
                let head = x.for_head(var, self.top(from), self.top(to));
                Self::line(depth, &format!("{head} {{"), out);
                self.stmts(body, depth + 1, out);
                Self::line(depth, "}", out);
            }
            Stmt::While(c, body) => {
                Self::line(
                    depth,
                    &format!("{} {{", x.cond_head("while", self.top(c))),
                    out,
                );
                self.stmts(body, depth + 1, out);
                Self::line(depth, "}", out);
            }
            Stmt::Break => Self::line(depth, "break;", out),
            Stmt::Return(Some(e)) => Self::line(depth, &format!("return {};", self.top(e)), out),
            Stmt::Return(None) => Self::line(depth, "return;", out),
            Stmt::Call(name, args) => {
                let args: Vec<String> = args.iter().map(|a| self.top(a)).collect();
                Self::line(depth, &format!("{};", x.call(name, &args)), out);
            }
        }
    }
}

/// True when the index `i` is a literal.
fn is_literal(i: &Expr) -> bool {
    matches!(i, Expr::Index(_))
}

/// `text` as comment lines with the prefix `lead` (`" * "`, `"//! "`), one per line.
pub(crate) fn comment_lines(text: &str, lead: &str) -> String {
    text.lines()
        .map(|l| format!("{lead}{l}").trim_end().to_string() + "\n")
        .collect()
}

/// The shortest decimal digits that read back to `v` in `precision`'s type (`v` first
/// rounded to the nearest `float` in single precision); always with a `.` or an `e`, no
/// suffix.
pub(crate) fn float_digits(v: f64, precision: Precision) -> String {
    match precision {
        Precision::Double => format!("{v:?}"),
        Precision::Single => format!("{:?}", v as f32),
    }
}
