//! A streaming program in the language-neutral code of [`super::code`]: the fields of its
//! fixed-size state, its constant tables, its helper functions, the initialisation and the
//! step. The model kinds and families build one; a renderer prints it as C or Rust.

use super::code::{literals, select, Block, Expr, Function, Stmt, Ty};
use crate::model::limits::Limits;
use crate::{Error, Result};
use std::ops::Not;

/// A field of the state struct: a scalar, or an array of fixed length.
#[derive(Clone, Debug, PartialEq)]
pub struct Field {
    /// Its name (a C identifier).
    pub name: String,
    /// Its type.
    pub ty: Ty,
    /// The array length, or None for a scalar.
    pub len: Option<usize>,
    /// What it holds, one line (a comment in the header).
    pub doc: String,
}

/// A constant table (`static const double` / `const [f64; N]`).
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// Its name (upper case).
    pub name: String,
    /// Its values.
    pub values: Vec<f64>,
}

/// The name of the state's flag "the last sample was bad" (a non-finite input, skipped by
/// the rule of [`crate::model::limits`]; cleared by the next good sample); every program has
/// it.
pub const ERROR_FIELD: &str = "error";
/// The name of the state's count of bad samples since init (`NAME_faults`, `Model::faults`).
pub const FAULTS_FIELD: &str = "faults";
/// The name of the state's latched flag: set when a step could not be computed (see
/// [`Program::fallible_step`]: a divergence, a budget or capacity overflow); every program
/// has it.
pub const DIVERGED_FIELD: &str = "diverged";
/// The name of the state's copy of the last good outputs, held on a bad sample and once
/// diverged.
const HELD_FIELD: &str = "held";
/// The name of a compensator's flag "this step clipped its reference" (see
/// [`Program::count_clipped`]): the inverse emitters set it where the library's
/// `CompensatorStep::clipped` is true.
pub const CLIP_FIELD: &str = "clip";
/// The name of a compensator's count of the steps that clipped since init (the library's
/// `Compensator::clipped`), read by the generated `NAME_clipped` / `Model::clipped`.
pub const CLIPPED_FIELD: &str = "clipped_steps";

/// A streaming program: state, tables, helpers, initialisation and step.
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    /// The number of inputs of the step.
    pub n_inputs: usize,
    /// The number of outputs of the step.
    pub n_outputs: usize,
    /// The state's fields, the error flag first.
    pub fields: Vec<Field>,
    /// The constant tables.
    pub tables: Vec<Table>,
    /// The helper functions, in the order they were added.
    pub functions: Vec<Function>,
    /// The initialisation, after every field has been set to zero.
    pub init: Vec<Stmt>,
    /// The step: reads the inputs, writes every output.
    pub step: Vec<Stmt>,
    /// The worst case of the step's loops, one sentence per part that has them, for every
    /// input sequence (the header's "Worst case" lines; `docs/export.md`, "A bounded step").
    pub worst_case: Vec<String>,
}

impl Program {
    /// Records the worst case of a part of the step (one sentence; see
    /// [`Program::worst_case`]). A sentence recorded twice is kept once.
    pub fn bound(&mut self, sentence: impl Into<String>) {
        let sentence = sentence.into();
        if !self.worst_case.contains(&sentence) {
            self.worst_case.push(sentence);
        }
    }

    /// The header's lines on the worst case: every recorded sentence, or that the step has
    /// no loop whose count depends on the input.
    pub fn worst_case_comment(&self) -> String {
        let body = if self.worst_case.is_empty() {
            "the step's loops run a fixed number of times (none depends on the input).".to_string()
        } else {
            self.worst_case.join(" ")
        };
        let mut out = String::new();
        let mut line = String::from("Worst case, for every input sequence:");
        for word in body.split(' ') {
            if line.len() + 1 + word.len() > 88 {
                out.push_str(&line);
                out.push('\n');
                line = word.to_string();
            } else {
                line.push(' ');
                line.push_str(word);
            }
        }
        out.push_str(&line);
        out.push('\n');
        out
    }

    /// An empty program of `n_inputs` inputs and `n_outputs` outputs.
    pub fn new(n_inputs: usize, n_outputs: usize) -> Self {
        let mut program = Self {
            n_inputs,
            n_outputs,
            fields: Vec::new(),
            tables: Vec::new(),
            functions: Vec::new(),
            init: Vec::new(),
            step: Vec::new(),
            worst_case: Vec::new(),
        };
        program.fields.push(Field {
            name: ERROR_FIELD.into(),
            ty: Ty::Flag,
            len: None,
            doc: "nonzero when the last sample was bad (not finite): the state stayed and the \
                  outputs repeat the last good ones; cleared by the next good sample"
                .into(),
        });
        program.fields.push(Field {
            name: FAULTS_FIELD.into(),
            ty: Ty::Index,
            len: None,
            doc: "the bad (non-finite) samples since init".into(),
        });
        program.fields.push(Field {
            name: DIVERGED_FIELD.into(),
            ty: Ty::Flag,
            len: None,
            doc: "nonzero once a step could not be computed; the outputs then hold their last \
                  values until the next init"
                .into(),
        });
        program
    }

    fn check_new(&self, name: &str) -> Result<()> {
        let taken = self.fields.iter().any(|f| f.name == name)
            || self.tables.iter().any(|t| t.name == name)
            || self.functions.iter().any(|f| f.name == name);
        if taken {
            return Err(Error::Unsupported(format!(
                "export: the generated name '{name}' is used twice; this is a bug of hysid's \
                 exporter, please report it"
            )));
        }
        Ok(())
    }

    /// Makes the program a compensator that counts its clipped steps: adds the flag
    /// [`CLIP_FIELD`], which the inverse emitters set, and the count [`CLIPPED_FIELD`]; the
    /// step ([`count_clip`]) clears the flag before and counts it after the solve.
    pub fn count_clipped(&mut self) -> Result<()> {
        self.field(
            CLIP_FIELD,
            Ty::Flag,
            None,
            "nonzero when this step clipped its reference to the reachable range",
        )?;
        self.field(
            CLIPPED_FIELD,
            Ty::Index,
            None,
            "the steps that clipped their reference since init",
        )?;
        Ok(())
    }

    /// True for a compensator that counts its clipped steps ([`Program::count_clipped`]).
    pub fn counts_clipped(&self) -> bool {
        self.fields.iter().any(|f| f.name == CLIPPED_FIELD)
    }

    /// Adds a state field; returns its name.
    pub fn field(&mut self, name: &str, ty: Ty, len: Option<usize>, doc: &str) -> Result<String> {
        self.check_new(name)?;
        self.fields.push(Field {
            name: name.into(),
            ty,
            len,
            doc: doc.into(),
        });
        Ok(name.into())
    }

    /// Adds a constant table; returns its name.
    pub fn table(&mut self, name: &str, values: Vec<f64>) -> Result<String> {
        self.check_new(name)?;
        self.tables.push(Table {
            name: name.into(),
            values,
        });
        Ok(name.into())
    }

    /// Adds a helper function; returns its name.
    pub fn function(
        &mut self,
        name: &str,
        params: &[(&str, Ty)],
        ret: Option<Ty>,
        body: impl FnOnce(&mut Block),
    ) -> Result<String> {
        self.check_new(name)?;
        self.functions.push(Function {
            name: name.into(),
            params: params.iter().map(|(n, t)| (n.to_string(), *t)).collect(),
            ret,
            body: Block::build(body),
        });
        Ok(name.into())
    }

    /// True when a helper `name` exists.
    pub fn has_function(&self, name: &str) -> bool {
        self.functions.iter().any(|f| f.name == name)
    }

    /// Appends initialisation statements.
    pub fn init(&mut self, build: impl FnOnce(&mut Block)) {
        self.init.extend(Block::build(build));
    }

    /// Makes the step fallible and safe on bad input. A sample with a non-finite input is
    /// skipped by the rule of [`crate::model::limits`]: the flag [`ERROR_FIELD`] is set, the
    /// count [`FAULTS_FIELD`] goes up, the state stays and the outputs repeat the last good
    /// ones (a field `held`: 0 at init, or [`Program::hold_initially`]). A good sample clears
    /// the flag and runs `body`, which computes the outputs into the locals `y0`, `y1`, …
    /// that it declares; once a helper has set [`DIVERGED_FIELD`] the outputs hold their last
    /// values and later steps compute nothing until the next init.
    pub fn fallible_step(&mut self, body: impl FnOnce(&mut Block)) -> Result<()> {
        let n = self.n_outputs;
        let held = self.field(HELD_FIELD, Ty::F64, Some(n), "the last good outputs")?;
        let diverged = Expr::State(DIVERGED_FIELD.into());
        let hold = |b: &mut Block| {
            for i in 0..n {
                b.output(i, Expr::StateAt(held.clone(), Box::new(Expr::Index(i))));
            }
        };
        let bad = (0..self.n_inputs)
            .map(|i| Expr::Input(i).is_finite().not())
            .reduce(Expr::or)
            .unwrap_or(Expr::Flag(false));
        self.step = Block::build(|b| {
            b.if_else(diverged.clone(), hold, |b| {
                b.if_else(
                    bad,
                    |b| {
                        b.set_state(ERROR_FIELD, Expr::Flag(true));
                        b.set_state(
                            FAULTS_FIELD,
                            Expr::State(FAULTS_FIELD.into()) + Expr::Index(1),
                        );
                        hold(b);
                    },
                    |b| {
                        b.set_state(ERROR_FIELD, Expr::Flag(false));
                        body(b);
                        b.if_else(diverged.clone(), hold, |b| {
                            for i in 0..n {
                                let y = Expr::Local(format!("y{i}"));
                                b.set_at(&held, Expr::Index(i), y.clone());
                                b.output(i, y);
                            }
                        });
                    },
                );
            });
        });
        Ok(())
    }

    /// Sets the outputs a fallible step repeats on a bad sample before any good one (0
    /// otherwise): a compensator's midpoint of its limits.
    pub fn hold_initially(&mut self, values: &[f64]) {
        self.init(|b| {
            for (i, v) in values.iter().enumerate() {
                b.set_at(HELD_FIELD, Expr::Index(i), Expr::from(*v));
            }
        });
    }

    /// The step without failure: `body` writes every output.
    pub fn infallible_step(&mut self, body: impl FnOnce(&mut Block)) {
        self.step = Block::build(body);
    }

    /// Every double constant of the program: its tables' values and its literals.
    pub fn literals(&self) -> Vec<f64> {
        let mut values: Vec<f64> = self.tables.iter().flat_map(|t| t.values.clone()).collect();
        literals(&self.init, &mut values);
        literals(&self.step, &mut values);
        for f in &self.functions {
            literals(&f.body, &mut values);
        }
        values
    }

    /// Refuses a program with a non-finite literal (a model whose derived constants
    /// overflow).
    pub fn check(&self) -> Result<()> {
        match self.literals().iter().find(|v| !v.is_finite()) {
            Some(v) => Err(Error::InvalidModel(format!(
                "a constant of the model is {v}; the exported code needs finite constants \
                 (refit or rescale the model)"
            ))),
            None => Ok(()),
        }
    }
}

/// Emits into `b` the step `solve` of a program, and when `counting` (a compensator that counts
/// its clipped steps, [`Program::counts_clipped`]) clears the clip flag before it and adds the
/// flag to the count after it (a step that set the diverged flag is not counted: the
/// library's step failed).
pub fn count_clip(counting: bool, b: &mut Block, solve: impl FnOnce(&mut Block)) {
    if !counting {
        solve(b);
        return;
    }
    b.set_state(CLIP_FIELD, Expr::Flag(false));
    solve(b);
    let counted = Expr::State(CLIP_FIELD.into()).and(Expr::State(DIVERGED_FIELD.into()).not());
    b.if_(counted, |b| {
        b.set_state(
            CLIPPED_FIELD,
            Expr::State(CLIPPED_FIELD.into()) + Expr::Index(1),
        )
    });
}

/// Emits into `b` "this step clipped its reference when `condition`" for a compensator's
/// inverse emitter (the flag [`CLIP_FIELD`] of [`Program::count_clipped`]).
pub fn mark_clip(b: &mut Block, condition: Expr) {
    b.if_(condition, |b| b.set_state(CLIP_FIELD, Expr::Flag(true)));
}

/// Emits into `b` the command `value` limited to `limits` (the library's
/// [`Limits::apply`](crate::model::limits::Limits::apply), the same comparisons: lo if
/// value < lo, hi if value > hi, else value) into the local `name`, marking the step clipped
/// where it was changed; returns the local.
pub fn limit(b: &mut Block, name: &str, value: Expr, limits: &Limits) -> Expr {
    let (lo, hi) = (Expr::from(limits.lo()), Expr::from(limits.hi()));
    let below = value.clone().lt(lo.clone());
    let above = value.clone().gt(hi.clone());
    mark_clip(b, below.clone().or(above.clone()));
    b.let_(name, select(below, lo, select(above, hi, value)))
}

/// The names of one component of a program (an operator, a linear block): every field,
/// table and helper it adds carries its prefix, so that components never collide.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Ns {
    prefix: String,
}

impl Ns {
    /// The namespace with prefix `prefix` (e.g. `op_`).
    pub fn new(prefix: &str) -> Self {
        Self {
            prefix: prefix.into(),
        }
    }
    /// A nested namespace, `prefix` + `inner` + `_`.
    pub fn sub(&self, inner: &str) -> Self {
        Self::new(&format!("{}{inner}_", self.prefix))
    }
    /// The full name of `name` in this namespace.
    pub fn name(&self, name: &str) -> String {
        format!("{}{name}", self.prefix)
    }
    /// The full, upper-case name of the table `name`.
    pub fn table(&self, name: &str) -> String {
        self.name(name).to_ascii_uppercase()
    }
    /// The scalar field `name`.
    pub fn state(&self, name: &str) -> Expr {
        Expr::State(self.name(name))
    }
    /// Element `i` of the array field `name`.
    pub fn at(&self, name: &str, i: Expr) -> Expr {
        Expr::StateAt(self.name(name), Box::new(i))
    }
    /// Element `i` of the table `name`.
    pub fn tab(&self, name: &str, i: Expr) -> Expr {
        Expr::Table(self.table(name), Box::new(i))
    }
    /// A call of the helper `name` of this namespace.
    pub fn call(&self, name: &str, args: Vec<Expr>) -> Expr {
        Expr::Call(self.name(name), args)
    }
}
