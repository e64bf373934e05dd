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

#[test]
#[ignore = "generated code (compiled with cc and cargo): run in CI's long step, `cargo test --release -- --ignored`"]
fn generated_rust_equals_the_library() {
    let all = cases::all();
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
         \x20       $(out.push_str(&format!(\"clipped {}\\n\", m.$clipped()));)?\n\
         \x20       std::fs::write(format!(\"{}.out\", $name), out).unwrap();\n    }};\n}\n\nfn main() {\n",
    );
    for case in &all {
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
    let mut clipped = Vec::new();
    let results: Vec<(String, f64, bool)> = all
        .iter()
        .map(|case| {
            let text =
                std::fs::read_to_string(root.join(format!("{}.out", case.name))).expect("read");
            clipped.push(cases::parse_clipped(&text));
            let (y, error) = cases::parse_outputs(&text);
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
