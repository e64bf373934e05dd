//! C99 rendering: `NAME.h` (the state struct, the constants, the two functions) and `NAME.c`
//! (the tables as `static const`, the helpers as `static` functions taking the state, init and
//! step; in `NAME.c` the state is the parameter `state`, a name no emitter gives a local). No heap, no globals; `NAME.c` includes only `NAME.h`, `<math.h>` and `<stddef.h>`.
//! An array field or table of length 0 is given one unused element (C has no empty arrays).

use super::{comment_lines, float_digits, Printer, Syntax, ATOM, UNARY};
use crate::export::code::{Math, Ty};
use crate::export::precision::Precision;
use crate::export::program::{Program, CLIPPED_FIELD, FAULTS_FIELD};

/// The C spelling, for the export `name` in `precision`.
#[derive(Clone, Copy)]
struct C<'a> {
    name: &'a str,
    precision: Precision,
}

impl C<'_> {
    /// The C type of `ty`.
    fn ty(&self, ty: Ty) -> &'static str {
        match (ty, self.precision) {
            (Ty::F64, Precision::Double) => "double",
            (Ty::F64, Precision::Single) => "float",
            (Ty::Index, _) => "size_t",
            (Ty::Flag, _) => "int",
        }
    }

    /// The suffix of a float literal and of a `<math.h>` function (`f` in single).
    fn suffix(&self) -> &'static str {
        match self.precision {
            Precision::Double => "",
            Precision::Single => "f",
        }
    }
}

impl Syntax for C<'_> {
    fn literal(&self, v: f64) -> String {
        format!("{}{}", float_digits(v, self.precision), self.suffix())
    }
    fn single(&self) -> bool {
        self.precision.is_single()
    }
    fn state(&self, field: &str) -> String {
        format!("state->{field}")
    }
    fn table(&self, name: &str) -> String {
        format!("{}_{name}", self.name)
    }
    fn math(&self, f: Math) -> String {
        match f {
            // Inline helpers (see `MINMAX`): `fmax`/`fmin` are library calls at -O2 without
            // -ffinite-math-only (three quarters of a PI step with 20 plays:
            // `bench/export_steps.sh`).
            Math::Fmax | Math::Fmin => format!("{}_math_{}{}", self.name, f.name(), self.suffix()),
            _ => format!("{}{}", f.name(), self.suffix()),
        }
    }
    fn call(&self, name: &str, args: &[String]) -> String {
        let mut all = vec!["state".to_string()];
        all.extend(args.iter().cloned());
        format!("{}_{name}({})", self.name, all.join(", "))
    }
    fn flag(&self, v: bool) -> &'static str {
        if v {
            "1"
        } else {
            "0"
        }
    }
    /// `<math.h>`'s `NAN` is a float constant: cast in double, so that no float is promoted
    /// (`-Wdouble-promotion`).
    fn nan(&self) -> &'static str {
        match self.precision {
            Precision::Double => "((double)NAN)",
            Precision::Single => "NAN",
        }
    }
    fn is_finite(&self, x: (String, u8)) -> (String, u8) {
        (format!("isfinite({})", x.0), ATOM)
    }
    fn cast(&self, x: (String, u8), ty: Ty) -> (String, u8) {
        let operand = if x.1 > UNARY {
            x.0
        } else {
            format!("({})", x.0)
        };
        (format!("({}){operand}", self.ty(ty)), UNARY)
    }
    fn select(&self, c: String, a: String, b: String) -> (String, u8) {
        (format!("({c}) ? ({a}) : ({b})"), 0)
    }
    fn declare(&self, name: &str, ty: Ty, _mutable: bool, value: String) -> String {
        format!("{} {name} = {value};", self.ty(ty))
    }
    fn for_head(&self, var: &str, from: String, to: String) -> String {
        format!("for (size_t {var} = {from}; {var} < {to}; {var}++)")
    }
    fn cond_head(&self, keyword: &str, c: String) -> String {
        format!("{keyword} ({c})")
    }
}

/// The two files (`NAME.h`, `NAME.c`) of `program` in `numbers.0`, each opening with
/// `comment`; `numbers.1` is the bound `NAME_BOUND` of single precision in the output's
/// units (0 in double).
pub fn render(
    program: &Program,
    name: &str,
    comment: &str,
    sample_time: f64,
    numbers: (Precision, f64),
) -> (String, String) {
    let (precision, bound) = numbers;
    let syntax = C { name, precision };
    (
        header(program, syntax, comment, sample_time, bound),
        source(program, syntax, comment),
    )
}

/// `NAME_math_fmax` and `NAME_math_fmin`: C99's `fmax`/`fmin` (the non-NaN argument when
/// one is NaN) as `static` functions the compiler inlines, with glibc's x86-64 choice between
/// equal arguments (the second, so −0 and +0 come out as from `fmax`/`fmin` there). Each is
/// written only when the code uses it (`-Wall -Werror` rejects an unused `static` function).
const MINMAX: [(&str, &str); 2] = [
    ("fmax", "return x > y ? x : y;"),
    ("fmin", "return x < y ? x : y;"),
];

fn block_comment(text: &str) -> String {
    format!("/*\n{} */\n", comment_lines(text, " * "))
}

fn header(program: &Program, syntax: C, comment: &str, sample_time: f64, bound: f64) -> String {
    let name = syntax.name;
    let real = syntax.ty(Ty::F64);
    let guard = format!("{}_H_INCLUDED", name.to_ascii_uppercase());
    let mut h = block_comment(comment);
    h.push_str(&format!(
        "#ifndef {guard}\n#define {guard}\n\n#include <stddef.h>\n\n"
    ));
    h.push_str(&format!(
        "/* The number of inputs and outputs of {name}_step, and its period in seconds. */\n\
         #define {name}_N_INPUTS {}\n#define {name}_N_OUTPUTS {}\n#define {name}_SAMPLE_TIME {}\n\n",
        program.n_inputs,
        program.n_outputs,
        syntax.literal(sample_time)
    ));
    h.push_str(&format!(
        "/* The largest |output - the library's double output| this code is held to, in the\n\
         \x20* output's units: 0 in double precision (bit-identical), the measured bound in single\n\
         \x20* (see the opening comment). A double constant, for test programs. */\n\
         #define {name}_BOUND {bound:?}\n\n"
    ));
    h.push_str(&format!(
        "/* The model's whole state: it may live on the stack or in a static. */\n\
         typedef struct {name}_state {{\n"
    ));
    for f in &program.fields {
        let len = f.len.map(|n| format!("[{}]", n.max(1))).unwrap_or_default();
        h.push_str(&format!(
            "    {} {}{len}; /* {} */\n",
            syntax.ty(f.ty),
            f.name,
            f.doc
        ));
    }
    h.push_str(&format!("}} {name}_state;\n\n"));
    h.push_str(&format!(
        "/* Sets *s to the model's initial state. */\n\
         void {name}_init({name}_state *s);\n\n\
         /* One sample: reads u[0 .. {name}_N_INPUTS), writes y[0 .. {name}_N_OUTPUTS) (the\n\
         \x20* output at this sample) and advances *s to the next sample. */\n\
         void {name}_step({name}_state *s, const {real} *u, {real} *y);\n\n"
    ));
    if program.counts_clipped() {
        h.push_str(&format!(
            "/* The number of steps since {name}_init whose reference lay beyond the reachable\n\
             \x20* range or whose command lay beyond the limits, and was clipped (the library's\n\
             \x20* Compensator::clipped). */\n\
             size_t {name}_clipped(const {name}_state *s);\n\n"
        ));
    }
    h.push_str(&format!(
        "/* The number of bad (non-finite) input samples since {name}_init: each left the state\n\
         \x20* unchanged and repeated the last good outputs (s->error: the last sample was bad). */\n\
         size_t {name}_faults(const {name}_state *s);\n\n"
    ));
    h.push_str(&format!("#endif /* {guard} */\n"));
    h
}

fn source(program: &Program, syntax: C, comment: &str) -> String {
    let name = syntax.name;
    let real = syntax.ty(Ty::F64);
    let p = Printer::new(&syntax);
    let mut c = block_comment(comment);
    c.push_str(&format!(
        "#include \"{name}.h\"\n#include <math.h>\n#include <stddef.h>\n\n"
    ));
    for t in &program.tables {
        let mut values: Vec<String> = t.values.iter().map(|v| syntax.literal(*v)).collect();
        if values.is_empty() {
            values.push(syntax.literal(0.0));
        }
        c.push_str(&format!(
            "static const {real} {}[{}] = {{{}}};\n",
            syntax.table(&t.name),
            values.len(),
            values.join(", ")
        ));
    }
    if !program.tables.is_empty() {
        c.push('\n');
    }
    let tables_end = c.len();
    let signature = |f: &crate::export::code::Function| {
        let mut params = vec![format!("{name}_state *state")];
        params.extend(
            f.params
                .iter()
                .map(|(n, t)| format!("{} {n}", syntax.ty(*t))),
        );
        let ret = f.ret.map_or("void", |t| syntax.ty(t));
        format!("static {ret} {name}_{}({})", f.name, params.join(", "))
    };
    for f in &program.functions {
        c.push_str(&format!("{};\n", signature(f)));
    }
    if !program.functions.is_empty() {
        c.push('\n');
    }
    for f in &program.functions {
        c.push_str(&format!("{} {{\n    (void)state;\n", signature(f)));
        for (n, _) in &f.params {
            c.push_str(&format!("    (void){n};\n"));
        }
        p.stmts(&f.body, 1, &mut c);
        c.push_str("}\n\n");
    }
    c.push_str(&format!("void {name}_init({name}_state *state) {{\n"));
    for f in &program.fields {
        let zero = match f.ty {
            Ty::F64 => syntax.literal(0.0),
            Ty::Index | Ty::Flag => "0".into(),
        };
        match f.len {
            Some(n) => c.push_str(&format!(
                "    for (size_t i = 0; i < {}; i++) {{\n        state->{}[i] = {zero};\n    }}\n",
                n.max(1),
                f.name
            )),
            None => c.push_str(&format!("    state->{} = {zero};\n", f.name)),
        }
    }
    p.stmts(&program.init, 1, &mut c);
    c.push_str("}\n\n");
    c.push_str(&format!(
        "void {name}_step({name}_state *state, const {real} *u, {real} *y) {{\n    (void)u;\n"
    ));
    p.stmts(&program.step, 1, &mut c);
    c.push_str("}\n");
    if program.counts_clipped() {
        c.push_str(&format!(
            "\nsize_t {name}_clipped(const {name}_state *s) {{\n    return s->{CLIPPED_FIELD};\n}}\n"
        ));
    }
    c.push_str(&format!(
        "\nsize_t {name}_faults(const {name}_state *s) {{\n    return s->{FAULTS_FIELD};\n}}\n"
    ));
    let mut helpers = String::new();
    for (f, body) in MINMAX {
        let helper = format!("{name}_math_{f}{}", syntax.suffix());
        if c[tables_end..].contains(&format!("{helper}(")) {
            helpers.push_str(&format!(
                "static {real} {helper}({real} x, {real} y) {{\n    \
                 if (isnan(x)) return y;\n    if (isnan(y)) return x;\n    {body}\n}}\n\n"
            ));
        }
    }
    c.insert_str(tables_end, &helpers);
    c
}
