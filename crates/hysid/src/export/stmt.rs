//! Statements and helper functions of the language-neutral code ([`super::code`]), and the
//! [`Block`] that builds them.

use super::code::{local, Expr, Ty};

/// Where an assignment writes.
#[derive(Clone, Debug, PartialEq)]
pub enum Place {
    /// A mutable local.
    Local(String),
    /// A scalar field of the state.
    State(String),
    /// An element of an array field of the state.
    StateAt(String, Expr),
    /// Output `i` of the step.
    Output(usize),
}

/// A statement.
#[derive(Clone, Debug, PartialEq)]
pub enum Stmt {
    /// A new local (`mutable` when it is assigned later).
    Let {
        /// Its name.
        name: String,
        /// Its type.
        ty: Ty,
        /// Assigned again later.
        mutable: bool,
        /// Its value.
        value: Expr,
    },
    /// An assignment.
    Assign(Place, Expr),
    /// `if (c) { … } else { … }` (no `else` when empty).
    If(Expr, Vec<Stmt>, Vec<Stmt>),
    /// `for var in from..to` (an index, counting up, `to` exclusive).
    For {
        /// The loop variable (an index).
        var: String,
        /// The first value.
        from: Expr,
        /// One past the last value.
        to: Expr,
        /// The body.
        body: Vec<Stmt>,
    },
    /// `while (c) { … }`
    While(Expr, Vec<Stmt>),
    /// Leaves the innermost loop.
    Break,
    /// Returns from a helper (with a value when it has one).
    Return(Option<Expr>),
    /// A helper called for its effect on the state.
    Call(String, Vec<Expr>),
}

/// A helper function of the program: it may read and write the state.
#[derive(Clone, Debug, PartialEq)]
pub struct Function {
    /// Its name (a C identifier; the renderer prefixes the export name in C).
    pub name: String,
    /// Its parameters.
    pub params: Vec<(String, Ty)>,
    /// Its result type (none: called for its effect).
    pub ret: Option<Ty>,
    /// Its body.
    pub body: Vec<Stmt>,
}

/// A sequence of statements under construction.
#[derive(Debug, Default)]
pub struct Block {
    stmts: Vec<Stmt>,
}

impl Block {
    /// The statements built by `build` in a fresh block.
    pub fn build(build: impl FnOnce(&mut Block)) -> Vec<Stmt> {
        let mut b = Block::default();
        build(&mut b);
        b.stmts
    }

    /// The statements so far.
    pub fn finish(self) -> Vec<Stmt> {
        self.stmts
    }

    /// Appends `stmt`.
    pub fn push(&mut self, stmt: Stmt) {
        self.stmts.push(stmt);
    }

    fn declare(&mut self, name: &str, ty: Ty, mutable: bool, value: Expr) -> Expr {
        self.stmts.push(Stmt::Let {
            name: name.into(),
            ty,
            mutable,
            value,
        });
        local(name)
    }

    /// A new immutable double `name = value`; returns the local.
    pub fn let_(&mut self, name: &str, value: impl Into<Expr>) -> Expr {
        self.declare(name, Ty::F64, false, value.into())
    }
    /// A new mutable double.
    pub fn var(&mut self, name: &str, value: impl Into<Expr>) -> Expr {
        self.declare(name, Ty::F64, true, value.into())
    }
    /// A new local of type `ty`.
    pub fn local(&mut self, name: &str, ty: Ty, mutable: bool, value: Expr) -> Expr {
        self.declare(name, ty, mutable, value)
    }
    /// `name = value` for a mutable local.
    pub fn set(&mut self, name: &str, value: impl Into<Expr>) {
        self.stmts
            .push(Stmt::Assign(Place::Local(name.into()), value.into()));
    }
    /// `state.field = value`.
    pub fn set_state(&mut self, field: &str, value: impl Into<Expr>) {
        self.stmts
            .push(Stmt::Assign(Place::State(field.into()), value.into()));
    }
    /// `state.field[index] = value`.
    pub fn set_at(&mut self, field: &str, index: Expr, value: impl Into<Expr>) {
        self.stmts.push(Stmt::Assign(
            Place::StateAt(field.into(), index),
            value.into(),
        ));
    }
    /// Output `i` of the step is `value`.
    pub fn output(&mut self, i: usize, value: impl Into<Expr>) {
        self.stmts
            .push(Stmt::Assign(Place::Output(i), value.into()));
    }
    /// `if (c) { then }`.
    pub fn if_(&mut self, c: Expr, then: impl FnOnce(&mut Block)) {
        self.stmts.push(Stmt::If(c, Block::build(then), Vec::new()));
    }
    /// `if (c) { then } else { otherwise }`.
    pub fn if_else(
        &mut self,
        c: Expr,
        then: impl FnOnce(&mut Block),
        otherwise: impl FnOnce(&mut Block),
    ) {
        self.stmts
            .push(Stmt::If(c, Block::build(then), Block::build(otherwise)));
    }
    /// `for var in from..to { body(var) }`.
    pub fn for_(&mut self, var: &str, from: Expr, to: Expr, body: impl FnOnce(&mut Block, Expr)) {
        let body = Block::build(|b| body(b, local(var)));
        self.stmts.push(Stmt::For {
            var: var.into(),
            from,
            to,
            body,
        });
    }
    /// `while (c) { body }`.
    pub fn while_(&mut self, c: Expr, body: impl FnOnce(&mut Block)) {
        self.stmts.push(Stmt::While(c, Block::build(body)));
    }
    /// `break`.
    pub fn break_(&mut self) {
        self.stmts.push(Stmt::Break);
    }
    /// `return value`.
    pub fn ret(&mut self, value: impl Into<Expr>) {
        self.stmts.push(Stmt::Return(Some(value.into())));
    }
    /// `return` (from a helper without a value).
    pub fn ret_void(&mut self) {
        self.stmts.push(Stmt::Return(None));
    }
    /// The helper `name` called for its effect.
    pub fn call(&mut self, name: &str, args: Vec<Expr>) {
        self.stmts.push(Stmt::Call(name.into(), args));
    }
}

/// Every double literal of `stmts`.
pub(crate) fn literals(stmts: &[Stmt], out: &mut Vec<f64>) {
    for s in stmts {
        match s {
            Stmt::Let { value, .. } => value.literals(out),
            Stmt::Assign(place, value) => {
                if let Place::StateAt(_, i) = place {
                    i.literals(out);
                }
                value.literals(out);
            }
            Stmt::If(c, a, b) => {
                c.literals(out);
                literals(a, out);
                literals(b, out);
            }
            Stmt::For { from, to, body, .. } => {
                from.literals(out);
                to.literals(out);
                literals(body, out);
            }
            Stmt::While(c, body) => {
                c.literals(out);
                literals(body, out);
            }
            Stmt::Return(Some(e)) => e.literals(out),
            Stmt::Call(_, args) => args.iter().for_each(|a| a.literals(out)),
            Stmt::Break | Stmt::Return(None) => {}
        }
    }
}
