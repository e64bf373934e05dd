//! Property tests (seeded, deterministic): no input makes `EquationModel::parse` panic, and
//! well-formed random expressions evaluate as a straightforward recursive interpreter of
//! the syntax tree says.

use std::cell::Cell;
use std::collections::HashMap;

use hysid_equations::ast::{self, BinOp, Expr, ExprKind, Func};
use hysid_equations::EquationModel;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// A runner with a fixed seed and no failure files: every run draws the same cases.
fn runner(cases: u32, seed: u8) -> TestRunner {
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    TestRunner::new_with_rng(
        config,
        TestRng::from_seed(RngAlgorithm::ChaCha, &[seed; 32]),
    )
}

const VALID: &str = r#"[model]
name = "duffing"
states = ["x", "v"]
inputs = ["u"]
outputs = ["y"]
[parameters]
m  = { value = 1.0, lower = 0.0, unit = "kg" }
k3 = { value = 0.0, upper = 1e6 }
[initial]
x = { value = 0.0, fixed = true }
[let]
spring = "x + k3*x^3"
[equations]
x = "v"
v = "(u - v - spring) / m"
[output]
y = "x"
"#;

#[test]
fn random_bytes_never_panic() {
    runner(10_000, 1)
        .run(&proptest::collection::vec(any::<u8>(), 0..400), |bytes| {
            let text = String::from_utf8_lossy(&bytes);
            let _ = EquationModel::parse(&text);
            Ok(())
        })
        .unwrap();
}

#[test]
fn mutated_model_files_never_panic() {
    // A valid file with a random stretch replaced by characters of the language, so that
    // the cases get past the TOML layer into names, numbers and expressions.
    let alphabet: Vec<char> = "xvumk3 +-*/^()=,<>!.e1029\"'[]{}_sintanifpowabs\n"
        .chars()
        .collect();
    let strategy = (
        0..VALID.len(),
        0usize..12,
        proptest::collection::vec(0..alphabet.len(), 0..12),
    );
    runner(10_000, 2)
        .run(&strategy, |(at, cut, picks)| {
            let mut at = at;
            while !VALID.is_char_boundary(at) {
                at -= 1;
            }
            let mut end = (at + cut).min(VALID.len());
            while !VALID.is_char_boundary(end) {
                end -= 1;
            }
            let insert: String = picks.iter().map(|&i| alphabet[i]).collect();
            let text = format!("{}{}{}", &VALID[..at], insert, &VALID[end..]);
            if let Err(e) = EquationModel::parse(&text) {
                prop_assert!(!e.to_string().contains('\n'));
                prop_assert!(e.line >= 1 && e.column >= 1);
            }
            Ok(())
        })
        .unwrap();
}

/// Random expression strings over the language's tokens (mostly malformed).
#[test]
fn random_expression_strings_never_panic() {
    let tokens = [
        "x", "v", "u", "m", "k3", "t", "pi", "spring", "1", "2.5", "1e-3", "1e999", "0", "+", "-",
        "*", "/", "^", "(", ")", ",", "<", "<=", ">", ">=", "==", "!=", "and", "or", "not", "sin",
        "cos", "tan", "exp", "ln", "sqrt", "abs", "sign", "tanh", "atan", "min", "max", "pow",
        "if", "1.2.3", "$", "=",
    ];
    let strategy = proptest::collection::vec(0..tokens.len(), 0..30);
    runner(10_000, 3)
        .run(&strategy, |picks| {
            let expr: Vec<&str> = picks.iter().map(|&i| tokens[i]).collect();
            let text = VALID.replace(
                "\"(u - v - spring) / m\"",
                &format!("\"{}\"", expr.join(" ")),
            );
            if let Ok(m) = EquationModel::parse(&text) {
                let (mut dx, mut fx, mut ft) = ([0.0; 2], [0.0; 4], [0.0; 4]);
                m.rhs_jacobians(
                    0.1,
                    &[0.2, -0.3],
                    &[0.4],
                    &[1.0, 0.5],
                    &mut dx,
                    &mut fx,
                    &mut ft,
                );
            }
            Ok(())
        })
        .unwrap();
}

// ---- Well-formed expressions against a recursive interpreter. ----

fn number_expr() -> impl Strategy<Value = String> {
    let leaf = prop_oneof![
        Just("x".to_string()),
        Just("v".to_string()),
        Just("u".to_string()),
        Just("p".to_string()),
        Just("q".to_string()),
        Just("t".to_string()),
        Just("pi".to_string()),
        (0u32..40).prop_map(|k| format!("{}", f64::from(k) / 4.0)),
        (1u32..9).prop_map(|k| format!("{k}e-1")),
    ];
    leaf.prop_recursive(5, 48, 3, |inner| {
        let cond = (inner.clone(), inner.clone(), 0usize..6).prop_map(|(a, b, k)| {
            let op = ["<", "<=", ">", ">=", "==", "!="][k];
            format!("{a} {op} {b}")
        });
        let cond = prop_oneof![
            cond.clone(),
            (cond.clone(), cond.clone(), any::<bool>())
                .prop_map(|(a, b, and)| format!("({a}) {} ({b})", if and { "and" } else { "or" })),
            cond.prop_map(|c| format!("not ({c})")),
        ];
        prop_oneof![
            (inner.clone(), inner.clone(), 0usize..4).prop_map(|(a, b, k)| {
                let op = ["+", "-", "*", "/"][k];
                format!("({a} {op} {b})")
            }),
            (inner.clone(), 0i32..5).prop_map(|(a, n)| format!("{a}^{n}")),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("abs({a})^({b})")),
            inner.clone().prop_map(|a| format!("-{a}")),
            (inner.clone(), 0usize..10).prop_map(|(a, k)| {
                let f = [
                    "sin", "cos", "tan", "exp", "ln", "sqrt", "abs", "sign", "tanh", "atan",
                ][k];
                format!("{f}({a})")
            }),
            (inner.clone(), inner.clone(), 0usize..3).prop_map(|(a, b, k)| {
                let f = ["min", "max", "pow"][k];
                format!("{f}({a}, {b})")
            }),
            (cond, inner.clone(), inner).prop_map(|(c, a, b)| format!("if({c}, {a}, {b})")),
        ]
    })
}

/// Whether `e` contains no name but `pi` (its value is fixed at parse time).
fn is_constant(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::Num(_) => true,
        ExprKind::Name(n) => n == "pi",
        ExprKind::Neg(a) | ExprKind::Not(a) => is_constant(a),
        ExprKind::Binary(_, a, b) => is_constant(a) && is_constant(b),
        ExprKind::Call(_, args) => args.iter().all(is_constant),
    }
}

fn truth(b: bool) -> f64 {
    if b {
        1.0
    } else {
        0.0
    }
}

/// a^b as the language defines it: a literal integer exponent (|n| ≤ 64) by repeated
/// multiplication, anything else by powf.
fn power(a: f64, b: f64, exponent: &Expr) -> f64 {
    if is_constant(exponent) && b.fract() == 0.0 && b.abs() <= 64.0 {
        let n = b.abs() as u32;
        let mut acc = 1.0;
        let (mut base, mut e) = (a, n);
        // The same square-and-multiply order as the language (plain products up to 4).
        match n {
            0 => acc = 1.0,
            1 => acc = a,
            2 => acc = a * a,
            3 => acc = a * a * a,
            4 => acc = (a * a) * (a * a),
            _ => {
                while e > 0 {
                    if e & 1 == 1 {
                        acc *= base;
                    }
                    base *= base;
                    e >>= 1;
                }
            }
        }
        if b < 0.0 {
            1.0 / acc
        } else {
            acc
        }
    } else {
        a.powf(b)
    }
}

/// The recursive interpreter.
fn eval(e: &Expr, env: &HashMap<&str, f64>) -> f64 {
    match &e.kind {
        ExprKind::Num(v) => *v,
        ExprKind::Name(n) if n == "pi" => std::f64::consts::PI,
        ExprKind::Name(n) => env[n.as_str()],
        ExprKind::Neg(a) => -eval(a, env),
        ExprKind::Not(a) => truth(eval(a, env) == 0.0),
        ExprKind::Binary(op, a, b) => {
            let (x, y) = (eval(a, env), eval(b, env));
            match op {
                BinOp::Add => x + y,
                BinOp::Sub => x - y,
                BinOp::Mul => x * y,
                BinOp::Div => x / y,
                BinOp::Pow => power(x, y, b),
                BinOp::Lt => truth(x < y),
                BinOp::Le => truth(x <= y),
                BinOp::Gt => truth(x > y),
                BinOp::Ge => truth(x >= y),
                BinOp::Eq => truth(x == y),
                BinOp::Ne => truth(x != y),
                BinOp::And => truth(x != 0.0 && y != 0.0),
                BinOp::Or => truth(x != 0.0 || y != 0.0),
            }
        }
        ExprKind::Call(f, args) => {
            let a: Vec<f64> = args.iter().map(|x| eval(x, env)).collect();
            match f {
                Func::Sin => a[0].sin(),
                Func::Cos => a[0].cos(),
                Func::Tan => a[0].tan(),
                Func::Exp => a[0].exp(),
                Func::Ln => a[0].ln(),
                Func::Sqrt => a[0].sqrt(),
                Func::Abs => a[0].abs(),
                Func::Sign => {
                    if a[0] > 0.0 {
                        1.0
                    } else if a[0] < 0.0 {
                        -1.0
                    } else {
                        0.0
                    }
                }
                Func::Tanh => a[0].tanh(),
                Func::Atan => a[0].atan(),
                Func::Min => {
                    if a[0] <= a[1] {
                        a[0]
                    } else {
                        a[1]
                    }
                }
                Func::Max => {
                    if a[0] >= a[1] {
                        a[0]
                    } else {
                        a[1]
                    }
                }
                Func::Pow => power(a[0], a[1], &args[1]),
                Func::If => {
                    if a[0] != 0.0 {
                        a[1]
                    } else {
                        a[2]
                    }
                }
            }
        }
    }
}

#[test]
fn well_formed_expressions_match_the_recursive_interpreter() {
    let point = (
        -2.0f64..2.0,
        -2.0f64..2.0,
        -2.0f64..2.0,
        0.1f64..2.0,
        -2.0f64..2.0,
        0.0f64..5.0,
    );
    let (compared, refused) = (Cell::new(0usize), Cell::new(0usize));
    runner(10_000, 4)
        .run(&(number_expr(), point), |(expr, (x, v, u, p, q, t))| {
            let text = format!(
                "[model]\nstates = [\"x\", \"v\"]\ninputs = [\"u\"]\noutputs = [\"y\"]\n[parameters]\np = 1.0\nq = 1.0\n[equations]\nx = \"{expr}\"\nv = \"0\"\n[output]\ny = \"x\"\n"
            );
            let tree = ast::parse(&expr).map_err(|e| TestCaseError::fail(format!("{expr}: {e:?}")))?;
            let model = match EquationModel::parse(&text) {
                Ok(m) => m,
                Err(e) => {
                    // Only folding may refuse a well-formed expression.
                    prop_assert!(
                        e.message.contains("identically zero") || e.message.contains("non-finite constant"),
                        "{expr}: {e}"
                    );
                    refused.set(refused.get() + 1);
                    return Ok(());
                }
            };
            let env: HashMap<&str, f64> =
                [("x", x), ("v", v), ("u", u), ("p", p), ("q", q), ("t", t)].into_iter().collect();
            let want = eval(&tree, &env);
            let mut dx = [0.0; 2];
            model.rhs(t, &[x, v], &[u], &[p, q], &mut dx);
            // Simplification may turn a NaN or ∞ into a number (x·0 = 0, x − x = 0), never
            // the other way round: compare where the interpreter is finite.
            if want.is_finite() {
                prop_assert!(
                    (dx[0] - want).abs() <= 1e-12 * want.abs().max(1.0),
                    "{expr} at x={x} v={v} u={u} p={p} q={q} t={t}: tape {} vs interpreter {want}",
                    dx[0]
                );
                compared.set(compared.get() + 1);
            }
            Ok(())
        })
        .unwrap();
    let (compared, refused) = (compared.get(), refused.get());
    eprintln!("compared {compared} finite values, {refused} refused by folding");
    assert!(compared > 5_000, "too few finite cases: {compared}");
}
