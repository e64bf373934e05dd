//! The generated Rust crates, all linked into one program built offline.

use crate::cases::{self, Case};
use hysid::export::rust_crate;
use std::path::Path;
use std::process::Command;

/// Writes the crate of `case` under `dir` and its input file; returns the dependency line.
fn write_crate(case: &Case, dir: &Path) -> String {
    let name = &case.name;
    for f in rust_crate(&case.file, name, &case.options)
        .unwrap_or_else(|e| panic!("{name}: rust_crate failed: {e}"))
    {
        let path = dir.join("crates").join(&f.path);
        std::fs::create_dir_all(path.parent().expect("a parent")).expect("mkdir");
        std::fs::write(path, f.contents).expect("write");
    }
    std::fs::write(
        dir.join(format!("{name}.in")),
        cases::input_text(&case.input),
    )
    .expect("write");
    format!("{name} = {{ path = \"crates/{name}\" }}\n")
}

/// Builds the crates of `cases` into one program, runs each on its input and returns what
/// each printed: its outputs, a line `error` when diverged, `faults N` and, for a
/// compensator, `clipped N` (the format of [`cases::parse_outputs`]).
pub fn run_texts(cases: &[Case]) -> Vec<String> {
    let dir = tempfile::tempdir().expect("temp dir");
    let root = dir.path();
    let mut manifest = String::from(
        "[package]\nname = \"export_check\"\nversion = \"0.1.0\"\nedition = \"2021\"\n\n\
         [workspace]\n\n[dependencies]\n",
    );
    let mut main = String::from(
        "macro_rules! run {\n    ($k:ident, $name:expr $(, $clipped:ident)?) => {{\n\
         \x20       let text = std::fs::read_to_string(format!(\"{}.in\", $name)).unwrap();\n\
         \x20       let mut m = $k::Model::new();\n        let mut out = String::new();\n\
         \x20       for line in text.lines() {\n\
         \x20           let y = m.step(&[line.parse::<f64>().unwrap()]);\n\
         \x20           out.push_str(&format!(\"{:?}\\n\", y[0]));\n        }\n\
         \x20       if m.diverged() {\n            out.push_str(\"error\\n\");\n        }\n\
         \x20       out.push_str(&format!(\"faults {}\\n\", m.faults()));\n\
         \x20       $(out.push_str(&format!(\"clipped {}\\n\", m.$clipped()));)?\n\
         \x20       std::fs::write(format!(\"{}.out\", $name), out).unwrap();\n    }};\n}\n\nfn main() {\n",
    );
    for case in cases {
        manifest.push_str(&write_crate(case, root));
        let clipped = if case.options.inverse {
            ", clipped"
        } else {
            ""
        };
        main.push_str(&format!("    run!({0}, \"{0}\"{clipped});\n", case.name));
    }
    main.push_str("}\n");
    std::fs::create_dir_all(root.join("src")).expect("mkdir");
    std::fs::write(root.join("Cargo.toml"), manifest).expect("write");
    std::fs::write(root.join("src/main.rs"), main).expect("write");
    let built = Command::new(env!("CARGO"))
        .args(["build", "--release", "--offline", "--quiet"])
        .current_dir(root)
        .env("CARGO_TARGET_DIR", root.join("target"))
        .env_remove("RUSTFLAGS")
        .output()
        .expect("run cargo");
    assert!(
        built.status.success(),
        "cargo build of the generated crates failed:\n{}",
        String::from_utf8_lossy(&built.stderr)
    );
    let warnings = String::from_utf8_lossy(&built.stderr);
    assert!(
        !warnings.contains("warning"),
        "the generated crates warn:\n{warnings}"
    );
    let ran = Command::new(root.join("target/release/export_check"))
        .current_dir(root)
        .output()
        .expect("run the check program");
    assert!(
        ran.status.success(),
        "the check program failed: {}",
        String::from_utf8_lossy(&ran.stderr)
    );
    cases
        .iter()
        .map(|case| std::fs::read_to_string(root.join(format!("{}.out", case.name))).expect("read"))
        .collect()
}

#[test]
#[ignore = "generated code (compiled with cc and cargo): run in CI's long step, `cargo test --release -- --ignored`"]
fn generated_rust_equals_the_library() {
    let all = cases::all();
    let texts = run_texts(&all);
    let mut clipped = Vec::new();
    let results: Vec<(String, f64, bool)> = all
        .iter()
        .zip(&texts)
        .map(|(case, text)| {
            clipped.push(cases::parse_clipped(text));
            let (y, error) = cases::parse_outputs(text);
            (
                case.name.clone(),
                cases::relative_difference(&y, &case.expected),
                error,
            )
        })
        .collect();
    cases::check("Rust", &results);
    cases::check_clipped("Rust", &all, &clipped);
}

/// The target the embedded build is checked on: the Cortex-M4F/M7 one when the toolchain
/// has it (`rustup target add thumbv7em-none-eabihf`, as CI does), else the host.
fn embedded_target() -> Option<&'static str> {
    let installed = Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).into_owned())
        .unwrap_or_default();
    installed
        .lines()
        .any(|l| l.trim() == "thumbv7em-none-eabihf")
        .then_some("thumbv7em-none-eabihf")
}

#[test]
#[ignore = "generated code (compiled with cargo for thumbv7em): run in CI's long step, `cargo test --release -- --ignored`"]
fn generated_rust_builds_for_cortex_m_without_std_alloc_or_a_panic_path() {
    // Every case in double and, where the kind exports it, in single precision.
    let mut all = Vec::new();
    for case in cases::all() {
        let mut single = case.clone();
        single.name = format!("{}_f32", case.name);
        single.options.precision = hysid::export::Precision::Single;
        all.push(case);
        if rust_crate(&single.file, &single.name, &single.options).is_ok() {
            all.push(single);
        }
    }
    let dir = tempfile::tempdir().expect("temp dir");
    let root = dir.path();
    let mut manifest = String::from(
        "[package]\nname = \"embedded_check\"\nversion = \"0.1.0\"\nedition = \"2021\"\n\n\
         [workspace]\n\n[dependencies]\n",
    );
    // A no_std library that links every crate: it builds only if none needs std.
    let mut lib = String::from("#![no_std]\n");
    for case in &all {
        manifest.push_str(&write_crate(case, root));
        lib.push_str(&format!(
            "pub use {}::Model as {};\n",
            case.name,
            case.name.to_uppercase()
        ));
    }
    std::fs::create_dir_all(root.join("src")).expect("mkdir");
    std::fs::write(root.join("Cargo.toml"), manifest).expect("write");
    std::fs::write(root.join("src/lib.rs"), lib).expect("write");
    let target = embedded_target();
    // Clippy holds the crates to their `deny(clippy::indexing_slicing)`; the build gives
    // their object code.
    for command in ["clippy", "build"] {
        let mut args = vec![command, "--release", "--offline", "--quiet"];
        if let Some(t) = target {
            args.extend(["--target", t]);
        }
        let built = Command::new(env!("CARGO"))
            .args(&args)
            .current_dir(root)
            .env("CARGO_TARGET_DIR", root.join("target"))
            .env_remove("RUSTFLAGS")
            .output()
            .expect("run cargo");
        assert!(
            built.status.success(),
            "cargo {command} of the generated crates for {target:?} failed:\n{}",
            String::from_utf8_lossy(&built.stderr)
        );
    }
    // No symbol of a panic, an allocator or std in any crate's object code.
    let deps = root
        .join("target")
        .join(target.unwrap_or(""))
        .join("release/deps");
    let mut checked = 0;
    for case in &all {
        let prefix = format!("lib{}-", case.name);
        let rlib = std::fs::read_dir(&deps)
            .expect("the deps directory")
            .flatten()
            .map(|e| e.path())
            .find(|p| {
                let name = p.file_name().unwrap().to_string_lossy().into_owned();
                name.starts_with(&prefix) && name.ends_with(".rlib")
            })
            .unwrap_or_else(|| panic!("no rlib of {}", case.name));
        let nm = Command::new("nm")
            .args(["-C", "--undefined-only"])
            .arg(&rlib)
            .output()
            .expect("run nm");
        let symbols = String::from_utf8_lossy(&nm.stdout);
        for bad in ["panic", "alloc", "std::"] {
            let found: Vec<&str> = symbols.lines().filter(|l| l.contains(bad)).collect();
            assert!(
                found.is_empty(),
                "{}: {bad} in its object: {found:?}",
                case.name
            );
        }
        checked += 1;
    }
    assert!(checked > 50, "only {checked} crates checked");
}
