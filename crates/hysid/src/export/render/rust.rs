//! `no_std` Rust rendering: `src/lib.rs` of a crate with `pub struct Model` (the state),
//! `Model::new`, `Model::reset`, `Model::step`, `Model::error`, `Model::faults`,
//! `Model::diverged`, the constants `N_IN`, `N_OUT`,
//! `SAMPLE_TIME`, the tables as `const` arrays and the helpers as private methods; and its
//! `Cargo.toml`, whose one dependency is `libm` (the math functions of `core`-only Rust).

use super::{comment_lines, float_digits, Printer, Syntax, ATOM};
use crate::export::code::{Math, Ty};
use crate::export::precision::Precision;
use crate::export::program::{Program, CLIPPED_FIELD};

/// The Rust spelling in `precision`.
#[derive(Clone, Copy)]
struct Rust {
    precision: Precision,
}

impl Rust {
    /// The Rust type of `ty`.
    fn ty(&self, ty: Ty) -> &'static str {
        match (ty, self.precision) {
            (Ty::F64, Precision::Double) => "f64",
            (Ty::F64, Precision::Single) => "f32",
            (Ty::Index, _) => "usize",
            (Ty::Flag, _) => "bool",
        }
    }

    /// The zero of `ty`.
    fn zero(&self, ty: Ty) -> String {
        match ty {
            Ty::F64 => self.literal(0.0),
            Ty::Index => "0".into(),
            Ty::Flag => "false".into(),
        }
    }
}

impl Syntax for Rust {
    fn literal(&self, v: f64) -> String {
        match self.precision {
            Precision::Double => float_digits(v, self.precision),
            Precision::Single => format!("{}_f32", float_digits(v, self.precision)),
        }
    }
    fn single(&self) -> bool {
        self.precision.is_single()
    }
    fn state(&self, field: &str) -> String {
        format!("self.{field}")
    }
    fn table(&self, name: &str) -> String {
        name.into()
    }
    fn math(&self, f: Math) -> String {
        match self.precision {
            Precision::Double => format!("libm::{}", f.name()),
            Precision::Single => format!("libm::{}f", f.name()),
        }
    }
    fn call(&self, name: &str, args: &[String]) -> String {
        format!("self.{name}({})", args.join(", "))
    }
    fn flag(&self, v: bool) -> &'static str {
        if v {
            "true"
        } else {
            "false"
        }
    }
    fn nan(&self) -> &'static str {
        match self.precision {
            Precision::Double => "f64::NAN",
            Precision::Single => "f32::NAN",
        }
    }
    fn is_finite(&self, x: (String, u8)) -> (String, u8) {
        let receiver = if x.1 >= ATOM {
            x.0
        } else {
            format!("({})", x.0)
        };
        (format!("{receiver}.is_finite()"), ATOM)
    }
    fn cast(&self, x: (String, u8), ty: Ty) -> (String, u8) {
        let operand = if x.1 >= ATOM {
            x.0
        } else {
            format!("({})", x.0)
        };
        // `x as usize < y` would read as generic arguments: a cast is always parenthesised
        // inside a larger expression.
        (format!("{operand} as {}", self.ty(ty)), 0)
    }
    fn select(&self, c: String, a: String, b: String) -> (String, u8) {
        (format!("if {c} {{ {a} }} else {{ {b} }}"), 0)
    }
    fn declare(&self, name: &str, ty: Ty, mutable: bool, value: String) -> String {
        let m = if mutable { "mut " } else { "" };
        format!("let {m}{name}: {} = {value};", self.ty(ty))
    }
    fn for_head(&self, var: &str, from: String, to: String) -> String {
        format!("for {var} in {from}..{to}")
    }
    fn cond_head(&self, keyword: &str, c: String) -> String {
        format!("{keyword} {c}")
    }
    /// A computed index reads through `get`: no bounds-check panic can be reached (an
    /// index past the end, which the program never forms, would read 0). A literal index
    /// is checked by the compiler.
    fn element(&self, array: String, i: String, constant: bool) -> String {
        match constant {
            true => format!("{array}[{i}]"),
            false => format!("{array}.get({i}).copied().unwrap_or_default()"),
        }
    }
    /// A computed index writes through `get_mut` (an index past the end would store
    /// nothing), for the reason of [`Syntax::element`].
    fn store(&self, array: String, i: String, constant: bool, value: String) -> String {
        match constant {
            true => format!("{array}[{i}] = {value};"),
            // The value first, in a block of its own: it may read the same array.
            false => format!(
                "{{ let stored = {value}; if let Some(slot) = {array}.get_mut({i}) {{ *slot = stored; }} }}"
            ),
        }
    }
}

/// `Cargo.toml` of the crate `name`.
pub fn cargo_toml(name: &str, description: &str) -> String {
    format!(
        "[package]\nname = \"{name}\"\nversion = \"0.1.0\"\nedition = \"2021\"\n\
         description = \"{}\"\npublish = false\n\n[lib]\npath = \"src/lib.rs\"\n\n\
         [dependencies]\nlibm = \"0.2\"\n",
        description.replace('\\', "\\\\").replace('"', "\\\"")
    )
}

/// `src/lib.rs` of `program` in `numbers.0`, opening with `comment` as the crate's
/// documentation; `numbers.1` is the bound `BOUND` of single precision in the output's
/// units (0 in double).
pub fn lib_rs(
    program: &Program,
    comment: &str,
    sample_time: f64,
    numbers: (Precision, f64),
) -> String {
    let (precision, bound) = numbers;
    let syntax = Rust { precision };
    let real = syntax.ty(Ty::F64);
    let p = Printer::new(&syntax);
    let mut r = comment_lines(comment, "//! ");
    // Generated code: clippy's style lints do not apply; indexing that could panic does.
    r.push_str("#![no_std]\n#![allow(clippy::all)]\n#![deny(clippy::indexing_slicing)]\n\n");
    r.push_str(&format!(
        "/// The number of inputs of [`Model::step`].\npub const N_IN: usize = {};\n\
         /// The number of outputs of [`Model::step`].\npub const N_OUT: usize = {};\n\
         /// The period of a step in seconds.\npub const SAMPLE_TIME: {real} = {};\n\n",
        program.n_inputs,
        program.n_outputs,
        syntax.literal(sample_time)
    ));
    r.push_str(&format!(
        "/// The largest |output − the library's double output| this code is held to, in the\n\
         /// output's units: 0 in double precision (bit-identical), the measured bound in\n\
         /// single (see the crate's documentation).\npub const BOUND: f64 = {bound:?};\n\n"
    ));
    for t in &program.tables {
        let values: Vec<String> = t.values.iter().map(|v| syntax.literal(*v)).collect();
        r.push_str(&format!(
            "const {}: [{real}; {}] = [{}];\n",
            t.name,
            t.values.len(),
            values.join(", ")
        ));
    }
    if !program.tables.is_empty() {
        r.push('\n');
    }
    r.push_str(
        "/// The model's whole state (fixed size, no allocation).\n\
         #[derive(Clone, Debug, PartialEq)]\npub struct Model {\n",
    );
    for f in &program.fields {
        let ty = match f.len {
            Some(n) => format!("[{}; {n}]", syntax.ty(f.ty)),
            None => syntax.ty(f.ty).to_string(),
        };
        r.push_str(&format!("    /// {}\n    {}: {ty},\n", f.doc, f.name));
    }
    r.push_str("}\n\nimpl Default for Model {\n    fn default() -> Self {\n        Self::new()\n    }\n}\n\n");
    r.push_str("impl Model {\n    /// The model in its initial state.\n    pub fn new() -> Self {\n        let mut model = Model {\n");
    for f in &program.fields {
        let value = match f.len {
            Some(n) => format!("[{}; {n}]", syntax.zero(f.ty)),
            None => syntax.zero(f.ty),
        };
        r.push_str(&format!("            {}: {value},\n", f.name));
    }
    r.push_str("        };\n        model.reset();\n        model\n    }\n\n");
    r.push_str("    /// Returns the model to its initial state.\n    pub fn reset(&mut self) {\n");
    for f in &program.fields {
        let value = match f.len {
            Some(n) => format!("[{}; {n}]", syntax.zero(f.ty)),
            None => syntax.zero(f.ty),
        };
        r.push_str(&format!("        self.{} = {value};\n", f.name));
    }
    p.stmts(&program.init, 2, &mut r);
    r.push_str("    }\n\n");
    r.push_str(
        "    /// True when the last sample was bad (not finite): the state stayed and the outputs\n\
         \x20   /// repeated the last good ones; cleared by the next good sample.\n\
         \x20   pub fn error(&self) -> bool {\n        self.error\n    }\n\n\
         \x20   /// The number of bad (non-finite) samples since [`Model::reset`].\n\
         \x20   pub fn faults(&self) -> usize {\n        self.faults\n    }\n\n\
         \x20   /// True once a step could not be computed (a divergence, a budget or capacity\n\
         \x20   /// overflow); the outputs then hold their last values until [`Model::reset`].\n\
         \x20   pub fn diverged(&self) -> bool {\n        self.diverged\n    }\n\n",
    );
    if program.counts_clipped() {
        r.push_str(&format!(
            "    /// The number of steps since [`Model::reset`] whose reference lay beyond the\n\
             \x20   /// reachable range and was clipped (the library's `Compensator::clipped`).\n\
             \x20   pub fn clipped(&self) -> usize {{\n        self.{CLIPPED_FIELD}\n    }}\n\n"
        ));
    }
    r.push_str(&format!(
        "    /// One sample: the output at this sample for the input `u`; then the state\n\
         \x20   /// advances to the next sample.\n\
         \x20   pub fn step(&mut self, u: &[{real}; N_IN]) -> [{real}; N_OUT] {{\n\
         \x20       let mut y = [{}; N_OUT];\n",
        syntax.literal(0.0)
    ));
    p.stmts(&program.step, 2, &mut r);
    r.push_str("        y\n    }\n");
    for f in &program.functions {
        let params: Vec<String> = f
            .params
            .iter()
            .map(|(n, t)| format!("{n}: {}", syntax.ty(*t)))
            .collect();
        let ret = f
            .ret
            .map(|t| format!(" -> {}", syntax.ty(t)))
            .unwrap_or_default();
        r.push_str(&format!(
            "\n    #[allow(unused_variables)]\n    fn {}(&mut self, {}){ret} {{\n",
            f.name,
            params.join(", ")
        ));
        p.stmts(&f.body, 2, &mut r);
        r.push_str("    }\n");
    }
    r.push_str("}\n");
    r
}
