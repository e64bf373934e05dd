//! The Newmark corrector's emitted LU solve (`export::greybox::newmark::lu_solve`) against
//! nalgebra's `LU::solve`, which the library calls: compiled as C99 with the contract's
//! flags, on random matrices of sizes 1 to 5 (real entries, and small integers whose ties
//! in a column exercise the pivot choice, row swaps and singular matrices). Every solution
//! must be nalgebra's to the bit, and every matrix nalgebra cannot solve must make the
//! helper fail.

use hysid::export::code::{call, idx, Expr, Ty};
use hysid::export::greybox::newmark::lu_solve;
use hysid::export::program::{Ns, Program};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};
use std::process::Command;

/// A program of p² + p inputs (the matrix row by row, then the right-hand side) and p + 1
/// outputs: the solution, then 1 when solved (0 when the helper failed).
fn program(p: usize) -> Program {
    let mut prog = Program::new(p * p + p, p + 1);
    let ns = Ns::new("t_");
    let jac = prog
        .field(&ns.name("jac"), Ty::F64, Some(p * p), "the matrix")
        .expect("field");
    let g = prog
        .field(&ns.name("g"), Ty::F64, Some(p), "the right-hand side")
        .expect("field");
    let solve = lu_solve(&ns, &jac, &g, p, &mut prog).expect("the helper");
    prog.infallible_step(|b| {
        for i in 0..p * p {
            b.set_at(&jac, idx(i), Expr::Input(i));
        }
        for i in 0..p {
            b.set_at(&g, idx(i), Expr::Input(p * p + i));
        }
        let ok = b.local("ok", Ty::Flag, false, call(&solve, vec![]));
        for i in 0..p {
            b.output(i, Expr::StateAt(g.clone(), Box::new(idx(i))));
        }
        b.output(p, hysid::export::code::select(ok, 1.0, 0.0));
    });
    prog
}

/// A driver that reads lines of p² + p numbers and prints the p + 1 outputs of each.
fn driver(name: &str) -> String {
    format!(
        "#include <stdio.h>\n#include \"{name}.h\"\n\
         int main(void) {{\n\
         \x20   {name}_state s;\n    double u[{name}_N_INPUTS];\n    double y[{name}_N_OUTPUTS];\n\
         \x20   {name}_init(&s);\n\
         \x20   for (;;) {{\n\
         \x20       for (size_t i = 0; i < {name}_N_INPUTS; i++) {{\n\
         \x20           if (scanf(\"%lf\", &u[i]) != 1) {{\n                return 0;\n            }}\n\
         \x20       }}\n\
         \x20       {name}_step(&s, u, y);\n\
         \x20       for (size_t i = 0; i < {name}_N_OUTPUTS; i++) {{\n\
         \x20           printf(\"%.17g \", y[i]);\n        }}\n\
         \x20       printf(\"\\n\");\n    }}\n}}\n"
    )
}

/// The systems of size p: real entries of mixed magnitudes, and small integers.
fn systems(p: usize, rng: &mut Xoshiro256PlusPlus) -> Vec<Vec<f64>> {
    (0..400)
        .map(|k| {
            (0..p * p + p)
                .map(|_| {
                    if k % 2 == 0 {
                        rng.random_range(-1.0..1.0) * 10f64.powi(rng.random_range(-3..4))
                    } else {
                        f64::from(rng.random_range(-2i32..3))
                    }
                })
                .collect()
        })
        .collect()
}

/// What the library's corrector gets: nalgebra's LU solve, or None.
fn nalgebra_solve(p: usize, values: &[f64]) -> Option<Vec<f64>> {
    let a = nalgebra::DMatrix::from_row_slice(p, p, &values[..p * p]);
    let b = nalgebra::DVector::from_column_slice(&values[p * p..]);
    a.lu().solve(&b).map(|x| x.iter().copied().collect())
}

#[test]
#[ignore = "generated code (compiled with cc and cargo): run in CI's long step, `cargo test --release -- --ignored`"]
fn the_emitted_lu_solve_is_nalgebras_to_the_bit() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let (mut swapped, mut singular, mut compared) = (0, 0, 0);
    for p in 1..=5 {
        let name = format!("lu{p}");
        let (header, source) = hysid::export::render::c::render(
            &program(p),
            &name,
            "LU test",
            1.0,
            (hysid::export::Precision::Double, 0.0),
        );
        std::fs::write(dir.path().join(format!("{name}.h")), header).expect("write");
        std::fs::write(dir.path().join(format!("{name}.c")), source).expect("write");
        std::fs::write(dir.path().join(format!("{name}_driver.c")), driver(&name)).expect("write");
        let exe = dir.path().join(&name);
        let compiled = Command::new("cc")
            .args([
                "-std=c99",
                "-Wall",
                "-Wextra",
                "-Werror",
                "-pedantic",
                "-O2",
            ])
            .arg("-o")
            .arg(&exe)
            .arg(dir.path().join(format!("{name}.c")))
            .arg(dir.path().join(format!("{name}_driver.c")))
            .arg("-lm")
            .output()
            .expect("the C compiler `cc` is needed by this test");
        assert!(
            compiled.status.success(),
            "{name}: cc failed:\n{}",
            String::from_utf8_lossy(&compiled.stderr)
        );
        let systems = systems(p, &mut rng);
        let input: String = systems
            .iter()
            .map(|s| s.iter().map(|v| format!("{v:?} ")).collect::<String>() + "\n")
            .collect();
        let input_path = dir.path().join(format!("{name}.in"));
        std::fs::write(&input_path, input).expect("write");
        let ran = Command::new(&exe)
            .stdin(std::fs::File::open(&input_path).expect("open"))
            .output()
            .expect("run the driver");
        assert!(ran.status.success(), "{name}: the driver failed");
        let text = String::from_utf8_lossy(&ran.stdout);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), systems.len(), "{name}: one line a system");
        for (values, line) in systems.iter().zip(lines) {
            let out: Vec<f64> = line
                .split_whitespace()
                .map(|v| v.parse::<f64>().unwrap_or(f64::NAN))
                .collect();
            let solved = out[p] == 1.0;
            match nalgebra_solve(p, values) {
                None => {
                    singular += 1;
                    assert!(
                        !solved,
                        "{name}: solved a system nalgebra cannot: {values:?}"
                    );
                }
                Some(x) => {
                    assert!(
                        solved,
                        "{name}: failed on a system nalgebra solves: {values:?}"
                    );
                    let bits = |v: &[f64]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                    assert_eq!(
                        bits(&out[..p]),
                        bits(&x),
                        "{name}: {values:?}: {:?} vs nalgebra's {x:?}",
                        &out[..p]
                    );
                    compared += 1;
                    let a = nalgebra::DMatrix::from_row_slice(p, p, &values[..p * p]);
                    if !a.lu().p().is_empty() {
                        swapped += 1;
                    }
                }
            }
        }
    }
    println!(
        "LU: {compared} solutions bit-identical ({swapped} with row swaps), {singular} singular"
    );
    assert!(
        swapped > 100 && singular > 10,
        "the cases exercise swaps and failures"
    );
}
