//! The generated C, compiled with the contract's flags and run by a small driver.

use crate::cases::{self, Case};
use hysid::export::c_code;
use hysid::model::operators::OperatorModel;
use hysid::model::saved::FittedModel;
use std::path::Path;
use std::process::Command;

/// The flags of the contract.
const FLAGS: [&str; 6] = [
    "-std=c99",
    "-Wall",
    "-Wextra",
    "-Werror",
    "-pedantic",
    "-O2",
];

pub fn driver(name: &str, inverse: bool) -> String {
    let clipped = if inverse {
        format!("    printf(\"clipped %zu\\n\", {name}_clipped(&s));\n")
    } else {
        String::new()
    };
    format!(
        "#include <stdio.h>\n#include \"{name}.h\"\n\
         int main(int argc, char **argv) {{\n\
         \x20   {name}_state s;\n    double u[{name}_N_INPUTS];\n    double y[{name}_N_OUTPUTS];\n\
         \x20   FILE *in = argc > 1 ? fopen(argv[1], \"r\") : NULL;\n\
         \x20   if (in == NULL) {{\n        return 3;\n    }}\n\
         \x20   {name}_init(&s);\n\
         \x20   while (fscanf(in, \"%lf\", &u[0]) == 1) {{\n\
         \x20       {name}_step(&s, u, y);\n        printf(\"%.17g\\n\", y[0]);\n    }}\n\
         \x20   fclose(in);\n    if (s.diverged) {{\n        printf(\"error\\n\");\n    }}\n\
         \x20   printf(\"faults %zu\\n\", {name}_faults(&s));\n{clipped}    return 0;\n}}\n"
    )
}

/// Compiles the C files `sources` of `dir` with `flags` (and `-lm`) into the executable
/// `dir/name`; a compiler error fails the test with its output.
pub fn compile(dir: &Path, name: &str, flags: &[&str], sources: &[&str]) -> std::path::PathBuf {
    let exe = dir.join(name);
    let compiled = Command::new("cc")
        .args(flags)
        .arg("-o")
        .arg(&exe)
        .args(sources.iter().map(|s| dir.join(s)))
        .arg("-lm")
        .output()
        .expect("the C compiler `cc` is needed by this test (install gcc or clang)");
    assert!(
        compiled.status.success(),
        "{name}: cc failed:\n{}",
        String::from_utf8_lossy(&compiled.stderr)
    );
    exe
}

/// Compiles and runs the C of `case` in `dir`: the outputs, the diverged flag and, for a
/// compensator, its clipped count.
pub fn run(case: &Case, dir: &Path) -> (Vec<f64>, bool, Option<usize>) {
    let text = run_text(case, dir);
    let (y, error) = cases::parse_outputs(&text);
    (y, error, cases::parse_clipped(&text))
}

/// Compiles and runs the C of `case` in `dir`: what the driver printed.
pub fn run_text(case: &Case, dir: &Path) -> String {
    let name = &case.name;
    let code = c_code(&case.file, name, &case.options)
        .unwrap_or_else(|e| panic!("{name}: c_code failed: {e}"));
    std::fs::write(dir.join(format!("{name}.h")), &code.header).expect("write");
    std::fs::write(dir.join(format!("{name}.c")), &code.source).expect("write");
    std::fs::write(
        dir.join(format!("{name}_driver.c")),
        driver(name, case.options.inverse),
    )
    .expect("write");
    std::fs::write(
        dir.join(format!("{name}.in")),
        cases::input_text(&case.input),
    )
    .expect("write");
    let exe = compile(
        dir,
        name,
        &FLAGS,
        &[&format!("{name}.c"), &format!("{name}_driver.c")],
    );
    let ran = Command::new(&exe)
        .arg(dir.join(format!("{name}.in")))
        .output()
        .expect("run the driver");
    assert!(ran.status.success(), "{name}: the driver failed");
    String::from_utf8_lossy(&ran.stdout).into_owned()
}

#[test]
#[ignore = "generated code (compiled with cc and cargo): run in CI's long step, `cargo test --release -- --ignored`"]
fn generated_c_equals_the_library() {
    let dir = tempfile::tempdir().expect("temp dir");
    let all = cases::all();
    let mut clipped = Vec::new();
    let results: Vec<(String, f64, bool)> = all
        .iter()
        .map(|case| {
            let (y, error, count) = run(case, dir.path());
            clipped.push(count);
            (
                case.name.clone(),
                cases::relative_difference(&y, &case.expected),
                error,
            )
        })
        .collect();
    cases::check("C", &results);
    cases::check_clipped("C", &all, &clipped);
}

#[test]
#[ignore = "generated code (compiled with cc and cargo): run in CI's long step, `cargo test --release -- --ignored`"]
fn a_preisach_memory_beyond_its_capacity_sets_the_error_flag() {
    let op = OperatorModel::examples()
        .expect("examples")
        .into_iter()
        .find(|op| op.family().name() == "preisach")
        .expect("the registry has preisach");
    let n = op.as_operator().parameters().len();
    let model = FittedModel::operator(op, vec![f64::NAN; n]);
    // Ever smaller alternations: each sample leaves one more nested extremum.
    let input: Vec<f64> = (0..150)
        .map(|k| if k % 2 == 0 { 1.0 } else { -1.0 } * (0.95 - k as f64 / 200.0))
        .collect();
    let expected = model.simulate(&[&input], 1.0, None).expect("simulate")[0].clone();
    let case = Case {
        name: "preisach_deep".into(),
        file: model.to_file(),
        options: hysid::export::ExportOptions::default(),
        input,
        expected,
        clipped: None,
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let (y, error, _) = run(&case, dir.path());
    assert!(
        error,
        "64 memory points were exceeded without the error flag"
    );
    let fits = hysid::export::families::preisach::MEMORY_POINTS - 1;
    assert_eq!(
        y[..fits],
        case.expected[..fits],
        "the outputs before the overflow"
    );
    assert!(
        y[fits..].iter().all(|v| *v == y[fits - 1]),
        "the outputs hold after the overflow"
    );
}

#[test]
#[ignore = "generated code (compiled with cc and cargo): run in CI's long step, `cargo test --release -- --ignored`"]
fn a_diverging_grey_box_sets_the_error_flag_where_the_library_fails() {
    // x' = a·x² + u blows up in finite time: the library's simulate fails at a sample, the
    // generated step sets the flag there and holds the last finite output.
    let text = "[model]\nstates = [\"x\"]\ninputs = [\"u\"]\noutputs = [\"y\"]\n\
                [parameters]\na = 5.0\n[equations]\nx = \"a*x*x + u\"\n[output]\ny = \"x\"\n";
    let model = crate::greybox::equations(text, hysid::model::greybox::Simulation::default());
    let input = vec![1.0; 400];
    let failed = model
        .simulate(&[&input], 0.01, None)
        .expect_err("a blow-up");
    let case = Case {
        name: "blowup".into(),
        file: model.to_file(),
        options: hysid::export::ExportOptions {
            sample_time: Some(0.01),
            ..hysid::export::ExportOptions::default()
        },
        input,
        expected: Vec::new(),
        clipped: None,
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let (y, error, _) = run(&case, dir.path());
    assert!(error, "no error flag although the library failed: {failed}");
    assert!(
        y.iter().all(|v| v.is_finite()),
        "the outputs hold finite values"
    );
    let last = *y.last().expect("outputs");
    let held = y.iter().rev().take_while(|v| **v == last).count();
    assert!(held > 1, "the outputs hold after the failure");
}
