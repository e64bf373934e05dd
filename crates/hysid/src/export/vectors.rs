//! Test vectors with the code (`--test-vectors`, [`ExportOptions::test_vectors`]): reference
//! inputs, the outputs the library's streams give for them, and a program that steps the
//! exported code over them and checks it reproduces them — on the host or on the target board.
//!
//! **Inputs.** A forward model gets the export's test sequence ([`super::sequence::inputs`],
//! nested reversals over the range) on every input. A compensator gets as references the
//! forward model's outputs (the library's [`crate::model::stream::Stepper`]) on that
//! sequence, then hostile samples: NaN, +∞, −∞ alone and in a burst of 7, and ±10 times the
//! references' largest magnitude alone and in bursts of 3, each between good references.
//! The range is [`ExportOptions::test_range`] (`--test-range LO:HI`) when given, else the
//! model file's `input_range`; a file with neither is refused.
//!
//! **Expected outputs.** The library's streams ([`crate::model::saved::FittedModel::stepper`],
//! [`crate::model::saved::FittedModel::compensator`] with the export's command limits),
//! the path the generated code transliterates: in double precision they are equal to the bit,
//! so the bound is 0 and the check is equality. For every output k, j the check is
//!
//! |y_kj − e_kj| ≤ B · (max e − min e),
//!
//! B = `NAME_TEST_BOUND`: 0 in double precision, in single the relative bound the header
//! states ([`super::precision::SingleBound::bound`]). In single precision the inputs (and a
//! compensator's references) are rounded to `float` before the library runs them, so that the
//! code and the library see the same samples, and each expected value is stored as a pair of
//! `float`s, e = hi + lo with hi = fl(e) and lo = fl(e − hi), checked as (y − hi) − lo:
//! the test compares with the double result to about 2⁻⁴⁸ of its magnitude without one
//! `double` operation (none may run on a single-precision FPU). Every output must also be finite; a
//! compensator's command must lie within its limits, and after the run the faults count must
//! equal the number of bad samples, the clipped count the library's (when B = 0), and the
//! diverged flag be clear.
//!
//! **C** ([`c_test`]): `NAME_test.c`, including only `"NAME.h"`, `<math.h>` (`NAN`, `INFINITY`) and
//! `<stdio.h>` for its `main`: `int NAME_test_run(void)` returns the number of failed checks and prints nothing,
//! so that a bare-metal harness can call it; `main` (left out with `-DNAME_TEST_NO_MAIN`)
//! prints one line `NAME: PASS …` or `NAME: FAIL …` and returns 0 on success, 1 otherwise.
//! The macros `HYSID_TEST_BEFORE_STEP()` and `HYSID_TEST_AFTER_STEP()` (empty unless defined)
//! surround each `NAME_step`, for a harness that times the steps.
//!
//! **Rust** ([`rust_test`]): `NAME/tests/vectors.rs`, the same tables and checks as a
//! `cargo test`.

use super::precision::Precision;
use super::ExportOptions;
use crate::model::limits::Limits;
use crate::model::saved::{FittedModel, ModelFile};
use crate::{Error, Result};

/// The reference vectors of one export.
#[derive(Clone, Debug, PartialEq)]
pub struct Vectors {
    /// The step's inputs, one row per step.
    pub inputs: Vec<Vec<f64>>,
    /// The library's outputs, one row per step.
    pub outputs: Vec<Vec<f64>>,
    /// The bound B of the check, relative to the expected outputs' range (0: equality).
    pub bound: f64,
    /// The floating-point type of the code the vectors are for.
    pub precision: Precision,
    /// A compensator's command limits (checked on every command).
    pub limits: Option<Limits>,
    /// The number of non-finite input samples (the faults count after the run).
    pub faults: usize,
    /// A compensator's clipped count after the run (the library's).
    pub clipped: Option<usize>,
}

/// The bound of the check in double precision: the generated code is the library's
/// computation, so its outputs are equal.
pub const DOUBLE_BOUND: f64 = 0.0;

/// The hostile samples appended to a compensator's references (see the [module docs](self)),
/// `good` the references they are mixed with, ±10 times their largest magnitude (at least 1).
fn hostile(good: &[f64]) -> Vec<f64> {
    let span = good.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1.0);
    let bad = [
        vec![f64::NAN],
        vec![f64::INFINITY],
        vec![f64::NEG_INFINITY],
        vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ],
        vec![10.0 * span],
        vec![-10.0 * span],
        vec![10.0 * span; 3],
        vec![-10.0 * span; 3],
    ];
    let mut out = Vec::new();
    let stride = (good.len() / (bad.len() + 1)).max(1);
    for (i, samples) in bad.iter().enumerate() {
        out.extend(samples);
        let from = (i * stride) % good.len().max(1);
        out.extend(good.iter().skip(from).take(stride.min(16)));
    }
    out
}

/// The finite part of the hostile samples appended to the references `good` (the references
/// beyond reach and the good ones between them), on which a single-precision compensator's
/// bound is measured too (`export::single_bound`).
pub(crate) fn beyond_reach(good: &[f64]) -> Vec<f64> {
    hostile(good)
        .into_iter()
        .filter(|r| r.is_finite())
        .collect()
}

/// The range of the test sequence: `--test-range`, else the file's `input_range`.
fn ranges(file: &ModelFile, options: &ExportOptions, n_inputs: usize) -> Result<Vec<[f64; 2]>> {
    if let Some(r) = options.test_range {
        return Ok(vec![[r.lo(), r.hi()]; n_inputs]);
    }
    match &file.input_range {
        Some(r) if r.len() == n_inputs && r.iter().all(|[lo, hi]| lo < hi) => Ok(r.clone()),
        _ => Err(Error::invalid_option(
            "test-range",
            "none",
            "the model file records no input range to build the test vectors on; give the \
             range of the model's input as LO:HI"
                .into(),
        )),
    }
}

/// The reference vectors of the export of `file` with `options` (see the [module
/// docs](self)) run by `model` (the file's, re-stepped for another sample time:
/// `export::model_at`); `sample_time` is the export's, `bound` the check's B.
pub fn vectors(
    file: &ModelFile,
    model: &FittedModel,
    options: &ExportOptions,
    sample_time: f64,
    bound: f64,
) -> Result<Vectors> {
    let precision = options.precision;
    // The samples the code sees: in single precision each input is a float.
    let sample = |v: f64| precision.nearest(v);
    let mut forward = model.stepper(sample_time, options.initial_output)?;
    let (n_in, n_out) = (forward.n_inputs(), forward.n_outputs());
    let inputs: Vec<Vec<f64>> = super::sequence::inputs(&ranges(file, options, n_in)?)
        .into_iter()
        .map(|u| u.into_iter().map(sample).collect())
        .collect();
    let mut outputs = Vec::with_capacity(inputs.len());
    let mut y = vec![0.0; n_out];
    for u in &inputs {
        forward.step(u, &mut y)?;
        outputs.push(y.clone());
    }
    if !options.inverse {
        return Ok(Vectors {
            inputs,
            outputs,
            bound,
            precision,
            limits: None,
            faults: 0,
            clipped: None,
        });
    }
    let good: Vec<f64> = outputs.iter().map(|y| sample(y[0])).collect();
    let mut references = good.clone();
    references.extend(hostile(&good).into_iter().map(sample));
    let limits = super::export_limits(file, options);
    let mut comp = model.compensator(sample_time)?;
    comp.set_limits(limits);
    let mut commands = Vec::with_capacity(references.len());
    for r in &references {
        commands.push(vec![comp.step(*r)?.u]);
    }
    Ok(Vectors {
        faults: references.iter().filter(|r| !r.is_finite()).count(),
        inputs: references.into_iter().map(|r| vec![r]).collect(),
        outputs: commands,
        bound,
        precision,
        limits,
        clipped: Some(comp.clipped()),
    })
}

/// The spelling of the vectors' numbers in one language and precision.
#[derive(Clone, Copy)]
struct Numbers {
    /// Rust (else C).
    rust: bool,
    /// The floating-point type.
    precision: Precision,
}

impl Numbers {
    /// The floating-point type's name.
    fn ty(self) -> &'static str {
        match (self.rust, self.precision) {
            (false, Precision::Double) => "double",
            (false, Precision::Single) => "float",
            (true, Precision::Double) => "f64",
            (true, Precision::Single) => "f32",
        }
    }

    /// `v` as a literal of the type: the shortest decimal that rounds back to it (in single
    /// precision to the `float` nearest `v`), or the constant of a non-finite value.
    fn literal(self, v: f64) -> String {
        let ty = self.ty();
        match (self.rust, v) {
            (_, v) if v.is_nan() && self.rust => format!("{ty}::NAN"),
            (_, v) if v.is_nan() => format!("({ty})NAN"),
            (true, f64::INFINITY) => format!("{ty}::INFINITY"),
            (true, f64::NEG_INFINITY) => format!("{ty}::NEG_INFINITY"),
            (false, f64::INFINITY) => format!("({ty})INFINITY"),
            (false, f64::NEG_INFINITY) => format!("-({ty})INFINITY"),
            (rust, v) => match self.precision {
                Precision::Double => format!("{v:?}"),
                Precision::Single if rust => format!("{:?}_f32", v as f32),
                Precision::Single => format!("{:?}f", v as f32),
            },
        }
    }

    /// The table `values`, one literal a line.
    fn table(self, values: impl Iterator<Item = f64>) -> String {
        values
            .map(|v| format!("    {},\n", self.literal(v)))
            .collect()
    }

    /// The expected outputs' tables: in double one, `e`; in single the pair `hi` = fl(e) and
    /// `lo` = fl(e − hi) (see the [module docs](self)).
    fn expected(self, v: &Vectors) -> (String, Option<String>) {
        let e = || v.outputs.iter().flatten().copied();
        match self.precision {
            Precision::Double => (self.table(e()), None),
            Precision::Single => (
                self.table(e().map(|e| Precision::Single.nearest(e))),
                Some(self.table(e().map(|e| e - Precision::Single.nearest(e)))),
            ),
        }
    }
}

/// The outputs' range (max − min over every output), the scale of the bound.
fn output_range(v: &Vectors) -> f64 {
    let (lo, hi) = v
        .outputs
        .iter()
        .flatten()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(*x), h.max(*x))
        });
    if hi > lo {
        hi - lo
    } else {
        0.0
    }
}

/// `NAME_test.c` for the vectors `v` of the export `name` (see the [module docs](self)).
pub fn c_test(name: &str, v: &Vectors) -> String {
    let n = Numbers {
        rust: false,
        precision: v.precision,
    };
    let ty = n.ty();
    let steps = v.inputs.len();
    let n_in = v.inputs.first().map_or(1, Vec::len);
    let n_out = v.outputs.first().map_or(1, Vec::len);
    let limit_check = match v.limits {
        Some(l) => format!(
            "            if (!(y[j] >= {lo}) || !(y[j] <= {hi})) {{\n                \
             failures++;\n            }}\n",
            lo = n.literal(l.lo()),
            hi = n.literal(l.hi())
        ),
        None => String::new(),
    };
    let clipped_check = match v.clipped {
        Some(count) if v.bound == 0.0 => format!(
            "    if ({name}_TEST_BOUND == 0.0 && {name}_clipped(&s) != (size_t){count}) {{\n        \
             failures++;\n    }}\n"
        ),
        _ => String::new(),
    };
    let (expected, low) = n.expected(v);
    let (low_table, minus_low) = match &low {
        Some(t) => (
            format!(
                "/* The low parts of the expected outputs: each is {name}_test_y + this. */\n\
                 static const {ty} {name}_test_y_lo[{len}] = {{\n{t}}};\n\n",
                len = (steps * n_out).max(1)
            ),
            format!(" - {name}_test_y_lo[at]"),
        ),
        None => (String::new(), String::new()),
    };
    let zero = n.literal(0.0);
    format!(
        "/* {name}_test.c: reference vectors of {name} and a program that checks them.\n\
         * Generated by hysid {version}; do not edit. The inputs are hysid's documented test\n\
         * sequence (nested reversals over the identified range{hostile}); the expected outputs\n\
         * are the hysid library's{single}. Each output must be within {name}_TEST_BOUND times\n\
         * the expected outputs' range (0: equal), finite{within}; after the run the faults\n\
         * count must be the number of bad samples{clip} and the diverged flag clear.\n\
         * {name}_test_run() returns the number of failed checks and prints nothing (for a\n\
         * bare-metal harness); main() is left out with -D{name}_TEST_NO_MAIN. The macros\n\
         * HYSID_TEST_BEFORE_STEP() and HYSID_TEST_AFTER_STEP() surround each step. */\n\
         #include \"{name}.h\"\n#include <math.h>\n\n\
         #ifndef HYSID_TEST_BEFORE_STEP\n#define HYSID_TEST_BEFORE_STEP()\n#endif\n\
         #ifndef HYSID_TEST_AFTER_STEP\n#define HYSID_TEST_AFTER_STEP()\n#endif\n\n\
         /* The number of steps, the bound B of the check (a harness may give another with\n\
         \x20* -D{name}_TEST_BOUND=B: a target whose libm differs from the host's in the last\n\
         \x20* bits; docs/arm.md) and the expected outputs' range. */\n\
         #define {name}_TEST_STEPS {steps}\n\
         #ifndef {name}_TEST_BOUND\n#define {name}_TEST_BOUND {bound}\n#endif\n\
         #define {name}_TEST_RANGE {range}\n\
         #define {name}_TEST_FAULTS {faults}\n\n\
         static const {ty} {name}_test_u[{len_u}] = {{\n{u}}};\n\n\
         static const {ty} {name}_test_y[{len_y}] = {{\n{expected}}};\n\n\
         {low_table}\
         /* Steps {name} over the reference inputs and counts the failed checks (0: pass). */\n\
         int {name}_test_run(void);\n\
         int {name}_test_run(void) {{\n\
         \x20   {name}_state s;\n    {ty} u[{name}_N_INPUTS];\n    {ty} y[{name}_N_OUTPUTS];\n\
         \x20   const {ty} tolerance = {name}_TEST_BOUND * {name}_TEST_RANGE;\n\
         \x20   int failures = 0;\n\
         \x20   {name}_init(&s);\n\
         \x20   for (size_t k = 0; k < (size_t){name}_TEST_STEPS; k++) {{\n\
         \x20       for (size_t i = 0; i < (size_t){name}_N_INPUTS; i++) {{\n\
         \x20           u[i] = {name}_test_u[k * (size_t){name}_N_INPUTS + i];\n        }}\n\
         \x20       HYSID_TEST_BEFORE_STEP();\n\
         \x20       {name}_step(&s, u, y);\n\
         \x20       HYSID_TEST_AFTER_STEP();\n\
         \x20       for (size_t j = 0; j < (size_t){name}_N_OUTPUTS; j++) {{\n\
         \x20           const size_t at = k * (size_t){name}_N_OUTPUTS + j;\n\
         \x20           const {ty} d = (y[j] - {name}_test_y[at]){minus_low};\n\
         \x20           if (!(y[j] - y[j] == {zero}) || !(d <= tolerance && d >= -tolerance)) {{\n\
         \x20               failures++;\n            }}\n{limit_check}        }}\n    }}\n\
         \x20   if ({name}_faults(&s) != (size_t){name}_TEST_FAULTS || s.diverged) {{\n\
         \x20       failures++;\n    }}\n{clipped_check}    return failures;\n}}\n\n\
         #ifndef {name}_TEST_NO_MAIN\n#include <stdio.h>\n\n\
         int main(void) {{\n\
         \x20   const int failures = {name}_test_run();\n\
         \x20   if (failures == 0) {{\n\
         \x20       printf(\"{name}: PASS (%d steps)\\n\", {name}_TEST_STEPS);\n        return 0;\n    }}\n\
         \x20   printf(\"{name}: FAIL (%d failed checks in %d steps)\\n\", failures, {name}_TEST_STEPS);\n\
         \x20   return 1;\n}}\n#endif\n",
        version = super::interface::VERSION,
        hostile = if v.limits.is_some() || v.clipped.is_some() {
            ", as the forward model's outputs, then NaN, +-inf and +-10 times the range, alone \
             and in bursts"
        } else {
            ""
        },
        single = if low.is_some() {
            " in double for the inputs rounded to float,\n * each as a float pair hi + lo \
             (test_y + test_y_lo)"
        } else {
            ""
        },
        within = if v.limits.is_some() {
            " and within the command limits"
        } else {
            ""
        },
        clip = if v.clipped.is_some() && v.bound == 0.0 {
            ", the clipped count the library's (when B = 0)"
        } else {
            ""
        },
        bound = n.literal(v.bound),
        range = n.literal(output_range(v)),
        faults = v.faults,
        len_u = (steps * n_in).max(1),
        len_y = (steps * n_out).max(1),
        u = n.table(v.inputs.iter().flatten().copied()),
    )
}

/// `NAME/tests/vectors.rs` for the vectors `v` of the export `name` (see the [module
/// docs](self)).
pub fn rust_test(name: &str, v: &Vectors) -> String {
    let n = Numbers {
        rust: true,
        precision: v.precision,
    };
    let ty = n.ty();
    let limits = match v.limits {
        Some(l) => format!(
            "            assert!(y[j] >= {} && y[j] <= {}, \"step {{k}}: command beyond the limits\");\n",
            n.literal(l.lo()),
            n.literal(l.hi())
        ),
        None => String::new(),
    };
    let clipped = match v.clipped {
        Some(count) if v.bound == 0.0 => format!("    assert_eq!(m.clipped(), {count});\n"),
        _ => String::new(),
    };
    let len_y = v.outputs.iter().map(Vec::len).sum::<usize>();
    let (expected, low) = n.expected(v);
    let (low_table, minus_low) = match &low {
        Some(t) => (
            format!(
                "/// The low parts of the expected outputs: each is `Y` + this.\n\
                 static Y_LO: [{ty}; {len_y}] = [\n{t}];\n\n"
            ),
            " - Y_LO[at]",
        ),
        None => (String::new(), ""),
    };
    format!(
        "//! Reference vectors of `{name}` (hysid's test sequence; the hysid library's outputs{single}):\n\
         //! each output within BOUND times the expected outputs' range (0: equal), finite{within};\n\
         //! the faults count, {clip}and the diverged flag as the library's. Generated by hysid\n\
         //! {version}; do not edit.\n\n\
         use {name}::{{Model, N_IN, N_OUT}};\n\n\
         const BOUND: {ty} = {bound};\n\
         const RANGE: {ty} = {range};\n\
         const FAULTS: usize = {faults};\n\n\
         static U: [{ty}; {len_u}] = [\n{u}];\n\n\
         static Y: [{ty}; {len_y}] = [\n{expected}];\n\n\
         {low_table}\
         #[test]\n\
         fn the_model_reproduces_the_reference_vectors() {{\n\
         \x20   let mut m = Model::new();\n\
         \x20   let tolerance = BOUND * RANGE;\n\
         \x20   for k in 0..U.len() / N_IN {{\n\
         \x20       let mut u = [0.0; N_IN];\n\
         \x20       u.copy_from_slice(&U[k * N_IN..(k + 1) * N_IN]);\n\
         \x20       let y = m.step(&u);\n\
         \x20       for j in 0..N_OUT {{\n\
         \x20           let at = k * N_OUT + j;\n\
         \x20           let d = (y[j] - Y[at]){minus_low};\n\
         \x20           assert!(y[j].is_finite(), \"step {{k}}: output not finite\");\n\
         \x20           assert!(d.abs() <= tolerance, \"step {{k}}: {{}} vs {{}}\", y[j], Y[at]);\n\
         {limits}        }}\n    }}\n\
         \x20   assert_eq!(m.faults(), FAULTS);\n\
         \x20   assert!(!m.diverged());\n{clipped}}}\n",
        version = super::interface::VERSION,
        single = if low.is_some() {
            " in double for\n//! the inputs rounded to f32, each as a pair `Y` + `Y_LO`"
        } else {
            ""
        },
        within = if v.limits.is_some() {
            ", within the command limits"
        } else {
            ""
        },
        clip = if v.clipped.is_some() && v.bound == 0.0 {
            "the clipped count "
        } else {
            ""
        },
        bound = n.literal(v.bound),
        range = n.literal(output_range(v)),
        faults = v.faults,
        len_u = v.inputs.iter().map(Vec::len).sum::<usize>(),
        u = n.table(v.inputs.iter().flatten().copied()),
    )
}
