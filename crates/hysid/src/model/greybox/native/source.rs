//! A listing ([`hysid_equations::Listing`]) printed as C99 functions:
//!
//! ```c
//! void hysid_prepare(const double *p, double *c);
//! /* either the listing's results (results_source) */
//! void hysid_eval(double t, const double *x, const double *u, const double *c, double *out);
//! /* or, for a column tape, ẋ and the sensitivity rates, and ẋ alone (sensitivities_source) */
//! void hysid_sens(double t, const double *x, const double *u, const double *s,
//!                 const double *c, const unsigned char *coupled, double *dx, double *ds);
//! void hysid_rates(double t, const double *x, const double *u, const double *c, double *dx);
//! /* and one sample interval's RK4 sub-steps of x and S (substeps_source) */
//! void hysid_substeps(const double *nodes, const double *c, const unsigned char *coupled,
//!                     int m, double h, double *x, double *s);
//! ```
//!
//! `hysid_prepare` computes, once per parameter vector θ = `p`, every operation that reads
//! neither t, x nor u, and stores in `c` what the other function reads of them (the
//! parameters themselves included); that function computes the rest at (t, x, u). Results
//! that are derivatives are made finite by the language's convention (a non-finite
//! derivative is 0). Every pointer is `restrict`: the caller's buffers never overlap.
//!
//! One C statement per operation, in the listing's order, with the tape's scalar semantics
//! ([`hysid_equations::apply1`], [`hysid_equations::apply2`], [`hysid_equations::powi`]):
//! `sign 0 = 0`, `min`/`max` taking the first argument on ties, truth values 1 and 0,
//! `pow(a, 1) = a` and `pow(a, 0) = 1`, integer powers by the same multiplications, and
//! the libm functions the tape calls (`sin`, `exp`, `log`, `pow`, …). Compiled without
//! contraction of a·b + c into a fused multiply–add and without value-changing
//! optimisations (no `-ffast-math`), each statement rounds as the tape's operation does,
//! so the numbers are the tape's to the bit; the module that loads the code checks that
//! on sample points before using it ([`super::NativeFunction`]).

use hysid_equations::{Fn1, Fn2, Listing, Operand, Operation};
use std::fmt::Write;

/// The C text of a listing and the length of the `c` array its functions share.
pub(super) struct Source {
    /// The C99 translation unit.
    pub text: String,
    /// How many doubles `hysid_prepare` writes to `c`.
    pub prepared: usize,
}

/// What a result (or operand) of the evaluation is, for the code that reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Class {
    /// A constant that reads as zero once made finite: a term it multiplies is left out.
    Zero,
    /// Another constant.
    Constant,
    /// Prepared from θ alone (constant within one simulation).
    Prepared,
    /// Computed from t, x or u at every evaluation.
    Varying,
}

/// A listing split into what θ alone determines (`hysid_prepare`) and the rest.
pub(super) struct Split<'a> {
    pub listing: &'a Listing,
    /// Per operation, whether it reads t, x or u (directly or through another).
    pub varying: Vec<bool>,
    /// Per parameter, its slot in `c` (when the evaluating code reads it).
    pub slot_of_param: Vec<Option<usize>>,
    /// Per θ-only operation, its slot in `c` (when the evaluating code reads it).
    pub slot_of_value: Vec<Option<usize>>,
    /// The length of `c`.
    pub slots: usize,
    /// The body of `hysid_prepare`.
    prepare: String,
    /// Per varying operation, its statement `const double vK = …;`.
    body: Vec<Option<String>>,
}

impl<'a> Split<'a> {
    pub fn new(listing: &'a Listing) -> Self {
        let varying = varying_operations(listing);
        let mut split = Split {
            listing,
            slot_of_param: Vec::new(),
            slot_of_value: vec![None; listing.operations.len()],
            slots: 0,
            prepare: String::new(),
            body: vec![None; listing.operations.len()],
            varying,
        };
        // The slots of `c`: every parameter and every θ-only value that the varying part
        // or a result reads.
        for (k, op) in listing.operations.iter().enumerate() {
            if split.varying[k] {
                for o in operands(op) {
                    split.need(&o);
                }
            }
        }
        for o in &listing.results {
            split.need(o);
        }
        for (k, op) in listing.operations.iter().enumerate() {
            let text = expression(op, &|o| {
                if split.varying[k] {
                    split.read(o)
                } else {
                    prepare_operand(o)
                }
            });
            let statement = format!("    const double v{k} = {text};\n");
            if split.varying[k] {
                split.body[k] = Some(statement);
            } else {
                split.prepare.push_str(&statement);
            }
        }
        for (i, slot) in split.slot_of_param.iter().enumerate() {
            if let Some(s) = slot {
                let _ = writeln!(split.prepare, "    c[{s}] = p[{i}];");
            }
        }
        for (k, slot) in split.slot_of_value.iter().enumerate() {
            if let Some(s) = slot {
                let _ = writeln!(split.prepare, "    c[{s}] = v{k};");
            }
        }
        split
    }

    fn need(&mut self, o: &Operand) {
        match *o {
            Operand::Parameter(i) => {
                if self.slot_of_param.len() <= i {
                    self.slot_of_param.resize(i + 1, None);
                }
                if self.slot_of_param[i].is_none() {
                    self.slot_of_param[i] = Some(self.slots);
                    self.slots += 1;
                }
            }
            Operand::Value(k) if !self.varying[k] && self.slot_of_value[k].is_none() => {
                self.slot_of_value[k] = Some(self.slots);
                self.slots += 1;
            }
            _ => {}
        }
    }

    /// An operand as the evaluating function reads it.
    fn read(&self, o: &Operand) -> String {
        match *o {
            Operand::Time => "t".into(),
            Operand::State(i) => format!("x[{i}]"),
            Operand::Input(i) => format!("u[{i}]"),
            Operand::Constant(v) => literal(v),
            Operand::Parameter(i) => format!("c[{}]", self.slot_of_param[i].expect("slot")),
            Operand::Value(k) if self.varying[k] => format!("v{k}"),
            Operand::Value(k) => format!("c[{}]", self.slot_of_value[k].expect("slot")),
        }
    }

    /// Result k as a derivative reads it: finite (by the convention), and its class.
    fn derivative(&self, k: usize) -> (String, Class) {
        let o = &self.listing.results[k];
        (format!("hy_finite({})", self.read(o)), self.class(o))
    }

    /// What an operand read as a derivative is (a constant reads as its finite value).
    pub fn class(&self, o: &Operand) -> Class {
        match *o {
            Operand::Constant(v) if v.is_finite() && v != 0.0 => Class::Constant,
            Operand::Constant(_) => Class::Zero,
            Operand::Parameter(_) => Class::Prepared,
            Operand::Value(j) if !self.varying[j] => Class::Prepared,
            _ => Class::Varying,
        }
    }

    /// The translation unit: the prelude, `hysid_prepare`, then each function (signature,
    /// tail, and the results the tail reads), whose body is the varying operations those
    /// results need followed by its tail, then `after` (functions that call those).
    fn finish(self, functions: &[(&str, &str, &[Operand])], after: &str) -> Source {
        let mut text = format!(
            "/* Generated by hysid {version} from an equation file's tape; see \
             model/greybox/native. */\n\
             #include <math.h>\n\n\
             {PRELUDE}\n\
             /* {slots} prepared values. */\n\
             void hysid_prepare(const double *restrict p, double *restrict c) {{\n    (void)p;\n    (void)c;\n\
             {prepare}}}\n",
            version = env!("CARGO_PKG_VERSION"),
            slots = self.slots,
            prepare = self.prepare,
        );
        for (signature, tail, roots) in functions {
            let used = needed(self.listing, roots, |k| self.varying[k]);
            let body: String = self
                .body
                .iter()
                .zip(used)
                .filter_map(|(statement, used)| statement.as_deref().filter(|_| used))
                .collect();
            let _ = write!(text, "\n{signature} {{\n{body}{tail}}}\n");
        }
        text.push_str(after);
        Source {
            text,
            prepared: self.slots,
        }
    }
}

/// `hysid_eval(t, x, u, c, out)` for `listing` (see the module docs): `values` results as
/// computed, the rest finite; result k written at `out[positions[k]]`.
pub(super) fn results_source(listing: &Listing, values: usize, positions: &[usize]) -> Source {
    let split = Split::new(listing);
    let mut tail = String::from("    (void)t;\n    (void)x;\n    (void)u;\n    (void)c;\n");
    for (k, &p) in positions.iter().enumerate().take(listing.results.len()) {
        let v = if k < values {
            split.read(&listing.results[k])
        } else {
            split.derivative(k).0
        };
        let _ = writeln!(tail, "    out[{p}] = {v};");
    }
    split.finish(
        &[(
            "void hysid_eval(double t, const double *restrict x, const double *restrict u, \
             const double *restrict c, double *restrict out)",
            &tail,
            &listing.results,
        )],
        "",
    )
}

/// `hysid_sens(x, u, s, c, coupled, dx, ds)` for the listing of a column tape of n states
/// and k parameter columns (results f, ∂f/∂x, ∂f/∂θ as
/// [`hysid_equations::EquationModel::columns_listing`] lays them out), for sensitivities of q ≥ k
/// columns (row-major n × q, the last q − k initial-state columns without a direct term):
///
/// ```text
/// ẋ = f        Ṡᵢ꜀ = [f_θ]ᵢ꜀ + Σⱼ [f_x]ᵢⱼ · Sⱼ꜀   (j in order)
/// ```
///
/// summed in the order of the Rust kernel (`equation_kernel`): the direct term (0 in an
/// initial-state column), then the products j = 0, 1, …; a product whose Jacobian entry is
/// a constant zero is left out, and one whose entry depends on θ alone is added only where
/// `coupled[i·n + j]` (the kernel's flags: false where the bound entry is zero), so every
/// value is the kernel's.
pub(super) fn sensitivities_source(
    listing: &Listing,
    n: usize,
    k: usize,
    q: usize,
    inputs: usize,
) -> Source {
    let split = Split::new(listing);
    let mut tail = String::from(
        "    (void)t;\n    (void)x;\n    (void)u;\n    (void)s;\n    (void)c;\n    (void)coupled;\n",
    );
    for i in 0..n {
        let _ = writeln!(tail, "    dx[{i}] = {};", split.read(&listing.results[i]));
    }
    let entries: Vec<Vec<(String, Class)>> = (0..n)
        .map(|i| (0..n).map(|j| split.derivative(n + i * n + j)).collect())
        .collect();
    for (i, row) in entries.iter().enumerate() {
        for (j, (a, class)) in row.iter().enumerate() {
            if *class != Class::Zero {
                let _ = writeln!(tail, "    const double a{i}_{j} = {a};");
            }
            if *class == Class::Prepared {
                let _ = writeln!(tail, "    const int on{i}_{j} = coupled[{}];", i * n + j);
            }
        }
    }
    for (i, row) in entries.iter().enumerate() {
        for col in 0..q {
            let direct = if col < k {
                split.derivative(n + n * n + i * k + col).0
            } else {
                "0.0".into()
            };
            let _ = writeln!(tail, "    {{\n        double d = {direct};");
            for (j, (_, class)) in row.iter().enumerate() {
                let term = format!("d += a{i}_{j} * s[{}];", j * q + col);
                match class {
                    Class::Zero => {}
                    Class::Prepared => {
                        let _ = writeln!(tail, "        if (on{i}_{j}) {{ {term} }}");
                    }
                    Class::Constant | Class::Varying => {
                        let _ = writeln!(tail, "        {term}");
                    }
                }
            }
            let _ = writeln!(tail, "        ds[{}] = d;\n    }}", i * q + col);
        }
    }
    // ẋ alone, for the plain simulations of the same fit: the signature of `hysid_eval`
    // (results 0 … n − 1 at their own positions), from the same prepared values.
    let mut rates = String::from("    (void)t;\n    (void)x;\n    (void)u;\n    (void)c;\n");
    for i in 0..n {
        let _ = writeln!(rates, "    dx[{i}] = {};", split.read(&listing.results[i]));
    }
    split.finish(
        &[
            (
                "static HY_INLINE void hy_sens(double t, const double *restrict x, \
                 const double *restrict u, const double *restrict s, const double *restrict c, \
                 const unsigned char *restrict coupled, double *restrict dx, \
                 double *restrict ds)",
                &tail,
                &listing.results,
            ),
            (
                "void hysid_rates(double t, const double *restrict x, const double *restrict u, \
                 const double *restrict c, double *restrict dx)",
                &rates,
                &listing.results[..n],
            ),
        ],
        &substeps_source(n, n * q, inputs),
    )
}

/// `hysid_sens`, the exported form of `hy_sens`, and `hysid_substeps(nodes, c, coupled, m,
/// h, x, s)`: m classical RK4 sub-steps of size h of x and S (`nq` = n·q entries) over one
/// sample interval, the input read at the interval's 2m + 1 half-step nodes (node-major,
/// `inputs` values each: sub-step j reads nodes 2j, 2j + 1 and 2j + 2) — the stages, stage
/// states and update of the fixed-size Rust loop (`fixed_rk4`), each element by the same
/// operations in the same order:
///
/// ```text
/// k₁ = F(z, u₂ⱼ)   k₂ = F(z + (h/2)·k₁, u₂ⱼ₊₁)   k₃ = F(z + (h/2)·k₂, u₂ⱼ₊₁)   k₄ = F(z + h·k₃, u₂ⱼ₊₂)
/// z ← z + (h/6)·(k₁ + 2k₂ + 2k₃ + k₄)
/// ```
///
/// One call per sample instead of one per stage: the stages' loop runs in the compiled code.
fn substeps_source(n: usize, nq: usize, inputs: usize) -> String {
    let (n_len, nq_len) = (n.max(1), nq.max(1));
    format!(
        "
void hysid_sens(double t, const double *restrict x, const double *restrict u,
                const double *restrict s, const double *restrict c,
                const unsigned char *restrict coupled, double *restrict dx, double *restrict ds) {{
    hy_sens(t, x, u, s, c, coupled, dx, ds);
}}

void hysid_substeps(const double *restrict nodes, const double *restrict c,
                    const unsigned char *restrict coupled, int m, double h,
                    double *restrict x, double *restrict s) {{
    const double half = 0.5 * h, sixth = h / 6.0;
    double kx[4][{n_len}], ks[4][{nq_len}], xt[{n_len}], st[{nq_len}];
    int j, r, i;
    for (j = 0; j < m; j++) {{
        const double *u = nodes + 2 * j * {inputs};
        for (r = 0; r < 4; r++) {{
            /* Stage r at z (r = 0) or at the stage state; its input node. */
            const double *u_r = u + (r == 0 ? 0 : (r == 3 ? 2 : 1)) * {inputs};
            hy_sens(0.0, r == 0 ? x : xt, u_r, r == 0 ? s : st, c, coupled, kx[r], ks[r]);
            if (r < 3) {{
                const double w = r == 2 ? h : half;
                for (i = 0; i < {n}; i++) {{ xt[i] = x[i] + w * kx[r][i]; }}
                for (i = 0; i < {nq}; i++) {{ st[i] = s[i] + w * ks[r][i]; }}
            }}
        }}
        for (i = 0; i < {n}; i++) {{
            x[i] += sixth * (kx[0][i] + 2.0 * kx[1][i] + 2.0 * kx[2][i] + kx[3][i]);
        }}
        for (i = 0; i < {nq}; i++) {{
            s[i] += sixth * (ks[0][i] + 2.0 * ks[1][i] + 2.0 * ks[2][i] + ks[3][i]);
        }}
    }}
}}
"
    )
}

/// The helpers with the tape's scalar semantics.
const PRELUDE: &str = "\
#if defined(__GNUC__)
#define HY_INLINE inline __attribute__((always_inline))
#else
#define HY_INLINE inline
#endif
static inline double hy_sign(double a) { return a > 0.0 ? 1.0 : (a < 0.0 ? -1.0 : 0.0); }
static inline double hy_pow(double a, double b) { return b == 1.0 ? a : (b == 0.0 ? 1.0 : pow(a, b)); }
static inline double hy_min(double a, double b) { return a <= b ? a : b; }
static inline double hy_max(double a, double b) { return a >= b ? a : b; }
static inline double hy_finite(double a) { return isfinite(a) ? a : 0.0; }
static inline double hy_powi(double x, int n) {
    unsigned int e;
    double base = x, acc = 1.0;
    switch (n) {
    case 0: return 1.0;
    case 1: return x;
    case 2: return x * x;
    case 3: return x * x * x;
    case 4: { double s = x * x; return s * s; }
    default: break;
    }
    e = n < 0 ? 0u - (unsigned int)n : (unsigned int)n;
    while (e > 0u) {
        if (e & 1u) { acc *= base; }
        base *= base;
        e >>= 1;
    }
    return n < 0 ? 1.0 / acc : acc;
}
";

/// Per operation, whether it reads t, x or u (directly or through an earlier operation).
fn varying_operations(listing: &Listing) -> Vec<bool> {
    let mut varying = vec![false; listing.operations.len()];
    for (k, op) in listing.operations.iter().enumerate() {
        varying[k] = operands(op).iter().any(|o| match *o {
            Operand::Time | Operand::State(_) | Operand::Input(_) => true,
            Operand::Value(j) => varying[j],
            Operand::Parameter(_) | Operand::Constant(_) => false,
        });
    }
    varying
}

/// Per operation, whether `roots` need it (through operations that `keep` holds for).
pub(super) fn needed(
    listing: &Listing,
    roots: &[Operand],
    keep: impl Fn(usize) -> bool,
) -> Vec<bool> {
    let mut needed = vec![false; listing.operations.len()];
    for o in roots {
        if let Operand::Value(k) = *o {
            needed[k] = keep(k);
        }
    }
    for k in (0..listing.operations.len()).rev() {
        if needed[k] {
            for o in operands(&listing.operations[k]) {
                if let Operand::Value(j) = o {
                    if keep(j) {
                        needed[j] = true;
                    }
                }
            }
        }
    }
    needed
}

/// The operands an operation reads.
pub(super) fn operands(op: &Operation) -> Vec<Operand> {
    match *op {
        Operation::Neg(a) | Operation::Unary(_, a) | Operation::Powi(a, _) | Operation::Not(a) => {
            vec![a]
        }
        Operation::Binary(_, a, b) => vec![a, b],
        Operation::Select(c, a, b) => vec![c, a, b],
    }
}

/// An operand as `hysid_prepare` reads it (θ-only operations read p and earlier locals).
fn prepare_operand(o: &Operand) -> String {
    match *o {
        Operand::Parameter(i) => format!("p[{i}]"),
        Operand::Value(k) => format!("v{k}"),
        Operand::Constant(v) => literal(v),
        // A θ-only operation reads none of these.
        Operand::Time | Operand::State(_) | Operand::Input(_) => unreachable!("varying operand"),
    }
}

/// The C expression of one operation over operands read by `read`.
fn expression(op: &Operation, read: &dyn Fn(&Operand) -> String) -> String {
    match op {
        Operation::Neg(a) => format!("-{}", read(a)),
        Operation::Unary(f, a) => {
            let a = read(a);
            match f {
                Fn1::Sin => format!("sin({a})"),
                Fn1::Cos => format!("cos({a})"),
                Fn1::Tan => format!("tan({a})"),
                Fn1::Exp => format!("exp({a})"),
                Fn1::Ln => format!("log({a})"),
                Fn1::Sqrt => format!("sqrt({a})"),
                Fn1::Abs => format!("fabs({a})"),
                Fn1::Sign => format!("hy_sign({a})"),
                Fn1::Tanh => format!("tanh({a})"),
                Fn1::Atan => format!("atan({a})"),
                Fn1::FiniteOr0 => format!("hy_finite({a})"),
            }
        }
        Operation::Binary(f, a, b) => {
            let (a, b) = (read(a), read(b));
            let truth = |c: String| format!("(({c}) ? 1.0 : 0.0)");
            match f {
                Fn2::Add => format!("{a} + {b}"),
                Fn2::Sub => format!("{a} - {b}"),
                Fn2::Mul => format!("{a} * {b}"),
                Fn2::Div => format!("{a} / {b}"),
                Fn2::Pow => format!("hy_pow({a}, {b})"),
                Fn2::Min => format!("hy_min({a}, {b})"),
                Fn2::Max => format!("hy_max({a}, {b})"),
                Fn2::Lt => truth(format!("{a} < {b}")),
                Fn2::Le => truth(format!("{a} <= {b}")),
                Fn2::Eq => truth(format!("{a} == {b}")),
                Fn2::Ne => truth(format!("{a} != {b}")),
                Fn2::And => truth(format!("{a} != 0.0 && {b} != 0.0")),
                Fn2::Or => truth(format!("{a} != 0.0 || {b} != 0.0")),
            }
        }
        Operation::Powi(a, n) => format!("hy_powi({}, {n})", read(a)),
        Operation::Not(a) => format!("(({} == 0.0) ? 1.0 : 0.0)", read(a)),
        Operation::Select(c, a, b) => {
            format!("(({} != 0.0) ? {} : {})", read(c), read(a), read(b))
        }
    }
}

/// A double as a C literal that reads back to the same bits (Rust's shortest round-trip
/// form), parenthesised when negative; NaN and infinities through `<math.h>`.
fn literal(v: f64) -> String {
    if v.is_nan() {
        "NAN".into()
    } else if v.is_infinite() {
        if v > 0.0 { "INFINITY" } else { "(-INFINITY)" }.into()
    } else if v.is_sign_negative() {
        format!("({v:e})")
    } else {
        format!("{v:e}")
    }
}
