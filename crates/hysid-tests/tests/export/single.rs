//! Single precision (`--precision single`): the exporter's interpreter in double equals the
//! library to the bit on every case (so the bound it measures compares the float code with
//! the library's numbers); the float C of every case compiles with the embedded flags
//! (`-Wdouble-promotion -Wconversion -Werror`) and stays within its header's `NAME_BOUND`
//! and within 1e-4 of the range of the library's output, on the model's own data and on a
//! fresh reference; every case exports but the listed refusals ([`REFUSED`], each with its
//! reason); the float Rust of a few kinds, forward and inverse, likewise.

use crate::cases::{self, Case};
use hysid::export::eval;
use hysid::export::{c_code, program, rust_crate, ExportOptions, Precision};
use hysid::model::compensate::compensate;
use std::path::Path;
use std::process::Command;

/// The bar: 1e-4 of the output's range.
const SINGLE_BAR: f64 = 1e-4;

/// The cases refused in single precision, each with its reason (docs/export.md, "Single
/// precision"); every other case must export. A refusal that disappears, or a new one, fails
/// the test.
const REFUSED: [(&str, &str); 13] = [
    // Saturating models: beyond the saturation the output is flat in the command, the
    // command is not determined by the output, and the float and double solves settle on
    // different commands of the same output (d far above 1e-4 of the command's range).
    ("maxwell_slip_saturating_inverse_f32", "above the bound"),
    (
        "cascade_maxwell_slip_saturating_inverse_f32",
        "above the bound",
    ),
    ("preisach_saturating_inverse_f32", "above the bound"),
    ("preisach_saturating_beyond_f32", "above the bound"),
    // The Dahl operator saturates too: references beyond its reach, and after a declared
    // history, whose long excursion leaves F within 1e-5 of saturation: the first command's
    // output is flat in it below float resolution, and every later command carries its
    // offset (a Dahl output depends on the command only through its moves).
    ("dahl_beyond_f32", "above the bound"),
    ("dahl_descending_beyond_f32", "above the bound"),
    ("dahl_ascending_inverse_f32", "above the bound"),
    ("dahl_ascending_beyond_f32", "beyond 5e7 statements"),
    // The operator cascade with backlash: the dead band, where the output is flat in the
    // command (open: not analysed further).
    ("cascade_backlash_inverse_f32", "above the bound"),
    ("cascade_backlash_beyond_f32", "above the bound"),
    // The grey-box Newmark model with a non-uniform sample time (open: 5e-2 with the float
    // corrector tolerances).
    ("gb_bouc_wen_newmark_nu_f32", "above the bound"),
    // Differential inverses on 3000 references beyond reach: every sample brackets in vain
    // over the whole span, beyond the measurement's work (5e7 statements) in double.
    ("jiles_atherton_beyond_f32", "beyond 5e7 statements"),
    ("cascade_dahl_beyond_f32", "beyond 5e7 statements"),
];

/// The models with an integrator (a rigid body's position), whose float error grows with
/// the record's path: the bound measured on one record is exceeded on the fresh one (by a
/// factor of about 2), which is held to the bar only.
const INTEGRATING: [&str; 2] = ["gb_rigid_body_zoh_f32", "gb_rigid_body_linear_f32"];

/// The embedded engineer's flags.
const FLAGS: [&str; 9] = [
    "-std=c99",
    "-O2",
    "-Wall",
    "-Wextra",
    "-Werror",
    "-pedantic",
    "-Wdouble-promotion",
    "-Wconversion",
    "-Wfloat-conversion",
];

/// `case` in single precision, its bound measured on its own input (`--data`).
fn single(case: &Case) -> Case {
    Case {
        name: format!("{}_f32", case.name),
        file: case.file.clone(),
        options: ExportOptions {
            precision: Precision::Single,
            bound_record: Some(case.input.iter().map(|v| vec![*v]).collect()),
            ..case.options.clone()
        },
        input: case.input.clone(),
        expected: case.expected.clone(),
        clipped: case.clipped,
    }
}

/// A driver reading doubles, stepping in float, printing the outputs.
fn driver(name: &str) -> String {
    format!(
        "#include <stdio.h>\n#include \"{name}.h\"\n\
         int main(int argc, char **argv) {{\n\
         \x20   {name}_state s;\n    float u[{name}_N_INPUTS];\n    float y[{name}_N_OUTPUTS];\n\
         \x20   double v;\n\
         \x20   FILE *in = argc > 1 ? fopen(argv[1], \"r\") : NULL;\n\
         \x20   if (in == NULL) {{\n        return 3;\n    }}\n\
         \x20   {name}_init(&s);\n\
         \x20   while (fscanf(in, \"%lf\", &v) == 1) {{\n\
         \x20       u[0] = (float)v;\n\
         \x20       {name}_step(&s, u, y);\n        printf(\"%.9g\\n\", (double)y[0]);\n    }}\n\
         \x20   fclose(in);\n    if (s.diverged) {{\n        printf(\"error\\n\");\n    }}\n\
         \x20   printf(\"bound %.17g\\n\", {name}_BOUND);\n    return 0;\n}}\n"
    )
}

/// Compiles the float C of `case` in `dir`: the executable, or the export's refusal (a
/// one-line reason starting "single precision:").
fn compile(case: &Case, dir: &Path) -> Result<std::path::PathBuf, String> {
    let name = &case.name;
    let code = match c_code(&case.file, name, &case.options) {
        Ok(code) => code,
        Err(e) => {
            let text = e.to_string();
            assert!(
                text.starts_with("single precision:") && !text.contains('\n'),
                "{name}: not a documented refusal: {text}"
            );
            return Err(text);
        }
    };
    assert!(
        code.header.contains(&format!(
            "{name}_step({name}_state *s, const float *u, float *y)"
        )),
        "{name}: the float API"
    );
    let code_lines = |text: &str| -> bool {
        text.lines()
            .map(str::trim_start)
            .filter(|l| !l.starts_with('*') && !l.starts_with("/*"))
            .any(|l| l.contains("double"))
    };
    assert!(
        !code_lines(&code.source) && !code_lines(&code.header.replace("BOUND", "")),
        "{name}: a double in the float code"
    );
    std::fs::write(dir.join(format!("{name}.h")), &code.header).expect("write");
    std::fs::write(dir.join(format!("{name}.c")), &code.source).expect("write");
    std::fs::write(dir.join(format!("{name}_driver.c")), driver(name)).expect("write");
    let exe = crate::c_target::compile(
        dir,
        name,
        &FLAGS,
        &[&format!("{name}.c"), &format!("{name}_driver.c")],
    );
    Ok(exe)
}

/// Runs `exe` on `input`: the outputs, the diverged flag and `NAME_BOUND`.
fn run(exe: &Path, input: &[f64], dir: &Path, tag: &str) -> (Vec<f64>, bool, f64) {
    let path = dir.join(format!("{tag}.in"));
    std::fs::write(&path, cases::input_text(input)).expect("write");
    let ran = Command::new(exe)
        .arg(&path)
        .output()
        .expect("run the driver");
    assert!(ran.status.success(), "{tag}: the driver failed");
    let text = String::from_utf8_lossy(&ran.stdout).into_owned();
    let bound = text
        .lines()
        .find_map(|l| l.strip_prefix("bound "))
        .and_then(|b| b.trim().parse::<f64>().ok())
        .expect("the bound line");
    let kept: String = text
        .lines()
        .filter(|l| !l.starts_with("bound "))
        .map(|l| format!("{l}\n"))
        .collect();
    let (y, error) = cases::parse_outputs(&kept);
    (y, error, bound)
}

/// max |a − b| over the samples.
fn max_gap(got: &[f64], expected: &[f64]) -> f64 {
    assert_eq!(got.len(), expected.len());
    got.iter()
        .zip(expected)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
}

/// The library's outputs for a fresh input: the models' outputs (or the compensators'
/// commands) on another seeded signal, case by case (by name); the grey-box cases on their
/// own input reversed. A forward case that starts from a measured output given at export
/// (`initial_output`, the Coleman–Hodgdon hysteresis saved with `initial_output: measured`)
/// is simulated from that same output: the exported code starts there whatever its input.
fn fresh(all: &[Case]) -> Vec<(Vec<f64>, Vec<f64>)> {
    let other: Vec<Case> = cases::all_on(
        &cases::signal(3000, 99)
            .iter()
            .map(|v| 0.9 * v)
            .collect::<Vec<_>>(),
    );
    all.iter()
        .map(|case| {
            if let Some(o) = other.iter().find(|o| o.name == case.name) {
                if let (Some(y0), false) = (case.options.initial_output, case.options.inverse) {
                    let model = cases::model_of(case);
                    let ts = case.options.sample_time.unwrap_or(1e-3);
                    let y = model.simulate(&[&o.input], ts, Some(y0)).expect("simulate");
                    return (o.input.clone(), y[0].clone());
                }
                return (o.input.clone(), o.expected.clone());
            }
            let model = cases::model_of(case);
            let input: Vec<f64> = case.input.iter().rev().copied().collect();
            let ts = case.options.sample_time.unwrap_or(1e-3);
            let expected = if case.options.inverse {
                compensate(&model, &input).expect("compensate").u
            } else {
                model.simulate(&[&input], ts, None).expect("simulate")[0].clone()
            };
            (input, expected)
        })
        .collect()
}

#[test]
#[ignore = "every case through the interpreter (minutes): run in CI's long step, `cargo test --release -- --ignored`"]
fn the_interpreter_in_double_equals_the_library_to_the_bit() {
    let mut failed = Vec::new();
    for case in cases::all() {
        let prog = program(&case.file, &case.options)
            .unwrap_or_else(|e| panic!("{}: program failed: {e}", case.name));
        let rows: Vec<Vec<f64>> = case.input.iter().map(|v| vec![*v]).collect();
        let y = eval::run::<f64>(&prog, &rows).expect("the interpreter");
        let got: Vec<f64> = y.iter().map(|r| r[0]).collect();
        if got.len() != case.expected.len()
            || got
                .iter()
                .zip(&case.expected)
                .any(|(a, b)| a.to_bits() != b.to_bits())
        {
            failed.push(format!(
                "{} (max gap {:e})",
                case.name,
                max_gap(&got, &case.expected)
            ));
        }
    }
    assert!(failed.is_empty(), "not bit-identical: {failed:?}");
}

#[test]
#[ignore = "generated code (compiled with cc and cargo): run in CI's long step, `cargo test --release -- --ignored`"]
fn single_c_is_within_its_bound_on_own_data_and_a_fresh_reference() {
    let dir = tempfile::tempdir().expect("temp dir");
    let all = cases::all();
    let fresh = fresh(&all);
    let mut rows = Vec::new();
    let mut failed = Vec::new();
    let mut passed = 0;
    for (case, (fresh_in, fresh_out)) in all.iter().zip(&fresh) {
        let case = single(case);
        let started = std::time::Instant::now();
        let exe = match compile(&case, dir.path()) {
            Ok(exe) => exe,
            Err(reason) => {
                let expected = REFUSED.iter().find(|(name, _)| *name == case.name);
                match expected {
                    Some((_, why)) if reason.contains(why) => {}
                    _ => failed.push(format!("{} refused: {reason}", case.name)),
                }
                rows.push(format!("{:<44} refused: {reason}", case.name));
                continue;
            }
        };
        let seconds = started.elapsed().as_secs_f64();
        passed += 1;
        let (y, error, bound) = run(&exe, &case.input, dir.path(), &case.name);
        assert!(!error, "{}: diverged in float", case.name);
        let gap = max_gap(&y, &case.expected);
        let own = cases::relative_difference(&y, &case.expected);
        let (y2, _, _) = run(&exe, fresh_in, dir.path(), &format!("{}_fresh", case.name));
        let other = cases::relative_difference(&y2, fresh_out);
        let fresh_gap = max_gap(&y2, fresh_out);
        rows.push(format!(
            "{:<44} own {own:.2e}  fresh {other:.2e} of the range; |y - library| {gap:.2e} \
             and {fresh_gap:.2e} within the bound {bound:.2e}; export {seconds:.1} s",
            case.name
        ));
        // The measured bound is the float code against the double code on the own data;
        // the library is the double code to the bit (the test above; c_target). The fresh
        // reference was not measured: the bound's margin must cover it.
        let fresh_bound = if INTEGRATING.contains(&case.name.as_str()) {
            f64::INFINITY
        } else {
            bound
        };
        if REFUSED.iter().any(|(name, _)| *name == case.name) {
            failed.push(format!("{}: exported, but listed as refused", case.name));
        }
        if !(gap <= bound && fresh_gap <= fresh_bound && own <= SINGLE_BAR && other <= SINGLE_BAR) {
            failed.push(case.name.clone());
        }
    }
    println!("{}", rows.join("\n"));
    assert!(
        failed.is_empty(),
        "beyond the bound: {failed:?}\n{}",
        rows.join("\n")
    );
    // Every case but the listed refusals was exported (checked above, case by case).
    assert_eq!(passed + REFUSED.len(), all.len(), "{passed} exported");
}

#[test]
#[ignore = "generated code (compiled with cc and cargo): run in CI's long step, `cargo test --release -- --ignored`"]
fn single_rust_is_within_its_bound() {
    let picked = [
        "pi_forward",
        "pi_inverse",
        "preisach_forward",
        "preisach_inverse",
        "bouc_wen_forward",
        "bouc_wen_inverse",
        "gb_bouc_wen_zoh",
    ];
    let all: Vec<Case> = cases::all()
        .into_iter()
        .filter(|c| picked.contains(&c.name.as_str()))
        .map(|c| single(&c))
        .collect();
    assert_eq!(all.len(), picked.len(), "the picked cases exist");
    let dir = tempfile::tempdir().expect("temp dir");
    let root = dir.path();
    let mut manifest = String::from(
        "[package]\nname = \"single_check\"\nversion = \"0.1.0\"\nedition = \"2021\"\n\n\
         [workspace]\n\n[dependencies]\n",
    );
    let mut main = String::from("fn main() {\n");
    for case in &all {
        let name = &case.name;
        for f in rust_crate(&case.file, name, &case.options)
            .unwrap_or_else(|e| panic!("{name}: rust_crate failed: {e}"))
        {
            let path = root.join("crates").join(&f.path);
            std::fs::create_dir_all(path.parent().expect("a parent")).expect("mkdir");
            std::fs::write(path, f.contents).expect("write");
        }
        std::fs::write(
            root.join(format!("{name}.in")),
            cases::input_text(&case.input),
        )
        .expect("write");
        manifest.push_str(&format!("{name} = {{ path = \"crates/{name}\" }}\n"));
        main.push_str(&format!(
            "    {{\n        let text = std::fs::read_to_string(\"{name}.in\").unwrap();\n\
             \x20       let mut m = {name}::Model::new();\n        let mut out = String::new();\n\
             \x20       for line in text.lines() {{\n\
             \x20           let u: f32 = line.parse::<f64>().unwrap() as f32;\n\
             \x20           let y: [f32; {name}::N_OUT] = m.step(&[u]);\n\
             \x20           out.push_str(&format!(\"{{:?}}\\n\", y[0] as f64));\n        }}\n\
             \x20       out.push_str(&format!(\"bound {{:?}}\\n\", {name}::BOUND));\n\
             \x20       std::fs::write(\"{name}.out\", out).unwrap();\n    }}\n"
        ));
    }
    main.push_str("}\n");
    std::fs::create_dir_all(root.join("src")).expect("mkdir");
    std::fs::write(root.join("Cargo.toml"), manifest).expect("write");
    std::fs::write(root.join("src/main.rs"), main).expect("write");
    let built = Command::new(env!("CARGO"))
        .args(["run", "--release", "--offline", "--quiet"])
        .current_dir(root)
        .env("CARGO_TARGET_DIR", root.join("target"))
        .output()
        .expect("cargo");
    assert!(
        built.status.success(),
        "cargo run failed:\n{}",
        String::from_utf8_lossy(&built.stderr)
    );
    for case in &all {
        let text = std::fs::read_to_string(root.join(format!("{}.out", case.name))).expect("out");
        let bound: f64 = text
            .lines()
            .find_map(|l| l.strip_prefix("bound "))
            .and_then(|b| b.parse().ok())
            .expect("bound");
        let y: Vec<f64> = text
            .lines()
            .filter(|l| !l.starts_with("bound "))
            .map(|l| l.parse().expect("a number"))
            .collect();
        let gap = max_gap(&y, &case.expected);
        let relative = cases::relative_difference(&y, &case.expected);
        assert!(
            gap <= bound && relative <= SINGLE_BAR,
            "{}: gap {gap:e} > bound {bound:e} or {relative:e} of the range",
            case.name
        );
    }
}
