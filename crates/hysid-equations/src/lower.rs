//! From syntax tree to graph: names resolved, conditions kept apart from numbers, constants
//! folded and checked (a division by an identically zero expression, a non-finite constant).

use std::collections::HashMap;

use crate::ast::{BinOp, Expr, ExprKind, Func, SyntaxError};
use crate::dag::{Graph, Id};
use crate::num::{Fn1, Fn2};

/// What a name stands for.
#[derive(Clone, Copy, Debug)]
pub enum Binding {
    /// A variable in an input slot (state, input or parameter).
    Slot(u32),
    /// A `[let]` quantity: its node, and whether it depends on time.
    Let(Id, bool),
}

/// The names an expression may use.
#[derive(Debug, Default)]
pub struct Scope {
    /// Names usable here.
    pub names: HashMap<String, Binding>,
    /// Every `[let]` quantity: its place in `[let]` and its line in the file.
    pub lets: HashMap<String, (usize, usize)>,
    /// The place in `[let]` of the quantity being defined (None outside `[let]`): a use of
    /// it is a cycle, a use of a later one a forward reference.
    pub defining: Option<usize>,
    /// Whether `t` is allowed (not in `[output]`).
    pub time_allowed: bool,
    /// The section named in messages (`[equations]`, …).
    pub section: &'static str,
    /// ("states", names), ("inputs", …), ("parameters", …) for the unknown-name message.
    pub groups: Vec<(&'static str, Vec<String>)>,
    /// `[let]` names in file order.
    pub let_order: Vec<String>,
}

impl Scope {
    /// "states: x, v; parameters: m, c; let: spring": the names usable here (built only
    /// for a message, so that reading a long file stays linear).
    fn listing(&self) -> String {
        let visible = self.defining.unwrap_or(self.let_order.len());
        self.groups
            .iter()
            .map(|(k, v)| (*k, &v[..]))
            .chain(std::iter::once(("let", &self.let_order[..visible])))
            .filter(|(_, v)| !v.is_empty())
            .map(|(k, v)| format!("{k}: {}", v.join(", ")))
            .collect::<Vec<_>>()
            .join("; ")
    }
}

/// Whether a value is a number or a condition.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Number,
    Condition,
}

/// A lowered expression: its node and whether it depends on time.
#[derive(Clone, Copy, Debug)]
pub struct Lowered {
    /// The node.
    pub id: Id,
    /// Whether t appears in it (directly or through `[let]`).
    pub uses_time: bool,
}

/// Lowers `e` (a number-valued expression) into `g`.
pub fn lower(g: &mut Graph, scope: &Scope, e: &Expr) -> Result<Lowered, SyntaxError> {
    let mut uses_time = false;
    let id = number(g, scope, e, &mut uses_time)?;
    Ok(Lowered { id, uses_time })
}

fn err(pos: usize, message: impl Into<String>) -> SyntaxError {
    SyntaxError {
        pos,
        message: message.into(),
    }
}

fn number(g: &mut Graph, s: &Scope, e: &Expr, t: &mut bool) -> Result<Id, SyntaxError> {
    let (id, kind) = value(g, s, e, t)?;
    if kind == Kind::Condition {
        return Err(err(
            e.pos,
            "a condition is used as a number; conditions (comparisons, and, or, not) go into if(condition, a, b)",
        ));
    }
    Ok(id)
}

fn condition(g: &mut Graph, s: &Scope, e: &Expr, t: &mut bool) -> Result<Id, SyntaxError> {
    let (id, kind) = value(g, s, e, t)?;
    if kind == Kind::Number {
        return Err(err(
            e.pos,
            "a number is used as a condition; compare it, e.g. 'x > 0' or 'x != 0'",
        ));
    }
    Ok(id)
}

fn value(g: &mut Graph, s: &Scope, e: &Expr, t: &mut bool) -> Result<(Id, Kind), SyntaxError> {
    let out = match &e.kind {
        ExprKind::Num(v) => (g.konst(*v), Kind::Number),
        ExprKind::Name(name) => (name_value(g, s, name, e.pos, t)?, Kind::Number),
        ExprKind::Neg(a) => {
            let a = number(g, s, a, t)?;
            (g.neg(a), Kind::Number)
        }
        ExprKind::Not(a) => {
            let a = condition(g, s, a, t)?;
            (g.not(a), Kind::Condition)
        }
        ExprKind::Binary(op, a, b) => binary(g, s, *op, a, b, e.pos, t)?,
        ExprKind::Call(f, args) => (call(g, s, *f, args, t)?, Kind::Number),
    };
    if let Some(v) = g.constant(out.0) {
        if !v.is_finite() {
            return Err(err(
                e.pos,
                format!("this expression is the non-finite constant {v} (e.g. ln(0), sqrt(-1), 1/0 after folding)"),
            ));
        }
    }
    Ok(out)
}

fn name_value(
    g: &mut Graph,
    s: &Scope,
    name: &str,
    pos: usize,
    t: &mut bool,
) -> Result<Id, SyntaxError> {
    if let Some(b) = s.names.get(name) {
        return match *b {
            Binding::Slot(slot) => Ok(g.var(slot)),
            Binding::Let(id, uses_time) => {
                if uses_time && !s.time_allowed {
                    return Err(err(
                        pos,
                        format!(
                            "'{name}' depends on the time t, which {} cannot use",
                            s.section
                        ),
                    ));
                }
                *t |= uses_time;
                Ok(id)
            }
        };
    }
    match name {
        "t" if s.time_allowed => {
            *t = true;
            Ok(g.var(0))
        }
        "t" => Err(err(
            pos,
            format!(
                "the time t is not allowed in {}: outputs are functions of states, inputs and parameters",
                s.section
            ),
        )),
        "pi" => Ok(g.konst(std::f64::consts::PI)),
        _ if s.lets.contains_key(name) => {
            let (place, line) = s.lets[name];
            if s.defining == Some(place) {
                Err(err(
                    pos,
                    format!("cycle in [let]: '{name}' is defined in terms of itself"),
                ))
            } else {
                Err(err(
                    pos,
                    format!(
                        "forward reference in [let]: '{name}' is defined later (line {line}); [let] quantities may use only earlier ones"
                    ),
                ))
            }
        }
        _ if Func::by_name(name).is_some() || matches!(name, "and" | "or" | "not") => Err(err(
            pos,
            format!("'{name}' is a reserved word (a function or logical operator), not a value"),
        )),
        _ => Err(err(
            pos,
            format!("unknown name '{name}' ({})", s.listing()),
        )),
    }
}

fn binary(
    g: &mut Graph,
    s: &Scope,
    op: BinOp,
    a: &Expr,
    b: &Expr,
    pos: usize,
    t: &mut bool,
) -> Result<(Id, Kind), SyntaxError> {
    let logic = match op {
        BinOp::And => Some(Fn2::And),
        BinOp::Or => Some(Fn2::Or),
        _ => None,
    };
    if let Some(f) = logic {
        let x = condition(g, s, a, t)?;
        let y = condition(g, s, b, t)?;
        return Ok((g.bin(f, x, y), Kind::Condition));
    }
    let x = number(g, s, a, t)?;
    let y = number(g, s, b, t)?;
    let (f, x, y, kind) = match op {
        BinOp::Add => (Fn2::Add, x, y, Kind::Number),
        BinOp::Sub => (Fn2::Sub, x, y, Kind::Number),
        BinOp::Mul => (Fn2::Mul, x, y, Kind::Number),
        BinOp::Div => {
            if g.constant(y) == Some(0.0) {
                return Err(err(
                    pos,
                    "division by an expression that is identically zero (after constant folding)",
                ));
            }
            (Fn2::Div, x, y, Kind::Number)
        }
        BinOp::Pow => (Fn2::Pow, x, y, Kind::Number),
        BinOp::Lt => (Fn2::Lt, x, y, Kind::Condition),
        BinOp::Le => (Fn2::Le, x, y, Kind::Condition),
        BinOp::Gt => (Fn2::Lt, y, x, Kind::Condition),
        BinOp::Ge => (Fn2::Le, y, x, Kind::Condition),
        BinOp::Eq => (Fn2::Eq, x, y, Kind::Condition),
        BinOp::Ne => (Fn2::Ne, x, y, Kind::Condition),
        BinOp::And => (Fn2::And, x, y, Kind::Condition),
        BinOp::Or => (Fn2::Or, x, y, Kind::Condition),
    };
    Ok((g.bin(f, x, y), kind))
}

fn call(g: &mut Graph, s: &Scope, f: Func, args: &[Expr], t: &mut bool) -> Result<Id, SyntaxError> {
    if f == Func::If {
        let c = condition(g, s, &args[0], t)?;
        let a = number(g, s, &args[1], t)?;
        let b = number(g, s, &args[2], t)?;
        return Ok(g.select(c, a, b));
    }
    let mut ids = Vec::with_capacity(args.len());
    for a in args {
        ids.push(number(g, s, a, t)?);
    }
    let id = match f {
        Func::Sin => g.un(Fn1::Sin, ids[0]),
        Func::Cos => g.un(Fn1::Cos, ids[0]),
        Func::Tan => g.un(Fn1::Tan, ids[0]),
        Func::Exp => g.un(Fn1::Exp, ids[0]),
        Func::Ln => g.un(Fn1::Ln, ids[0]),
        Func::Sqrt => g.un(Fn1::Sqrt, ids[0]),
        Func::Abs => g.un(Fn1::Abs, ids[0]),
        Func::Sign => g.un(Fn1::Sign, ids[0]),
        Func::Tanh => g.un(Fn1::Tanh, ids[0]),
        Func::Atan => g.un(Fn1::Atan, ids[0]),
        Func::Min => g.bin(Fn2::Min, ids[0], ids[1]),
        Func::Max => g.bin(Fn2::Max, ids[0], ids[1]),
        Func::Pow => g.bin(Fn2::Pow, ids[0], ids[1]),
        Func::If => g.select(ids[0], ids[1], ids[2]),
    };
    Ok(id)
}
