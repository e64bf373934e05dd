//! Every construct of the language: values, derivatives against central differences at
//! seeded random points, the conventions at non-smooth points, folding and sharing.

use crate::common;

use common::{assert_rows_close, fd_rhs, Arg, Rng};
use hysid_equations::{EquationModel, Scratch, TimeDomain};

/// A model with states (x, w), input u, parameters (p, q) and ẋ = `expr`, ẇ = `expr2`.
fn model2(expr: &str, expr2: &str) -> EquationModel {
    let text = format!(
        r#"[model]
name = "probe"
states = ["x", "w"]
inputs = ["u"]
outputs = ["y"]
[parameters]
p = 1.5
q = {{ value = 2.0 }}
[equations]
x = "{expr}"
w = "{expr2}"
[output]
y = "x"
"#
    );
    EquationModel::parse(&text).unwrap_or_else(|e| panic!("{expr}: {e}"))
}

fn model(expr: &str) -> EquationModel {
    model2(expr, "0")
}

/// (f, ∂f/∂x row, ∂f/∂θ row) of the first equation.
fn first_row(
    m: &EquationModel,
    x: f64,
    w: f64,
    u: f64,
    p: f64,
    q: f64,
) -> (f64, [f64; 2], [f64; 2]) {
    let (mut dx, mut fx, mut ft) = ([0.0; 2], [0.0; 4], [0.0; 4]);
    m.rhs_jacobians(0.0, &[x, w], &[u], &[p, q], &mut dx, &mut fx, &mut ft);
    (dx[0], [fx[0], fx[1]], [ft[0], ft[1]])
}

fn value(expr: &str, x: f64) -> f64 {
    first_row(&model(expr), x, 0.0, 0.0, 1.5, 2.0).0
}

/// Each function and operator, its domain for x, and its value as Rust computes it at
/// (x, p = 1.5·s, q = 2·s).
type Reference = fn(f64, f64, f64) -> f64;
const CASES: [(&str, f64, f64, Reference); 24] = [
    ("sin(x*p)", -3.0, 3.0, |x, p, _| (x * p).sin()),
    ("cos(x) * q", -3.0, 3.0, |x, _, q| x.cos() * q),
    ("tan(x)", -1.2, 1.2, |x, _, _| x.tan()),
    ("exp(p*x)", -2.0, 2.0, |x, p, _| (p * x).exp()),
    ("ln(x)", 0.1, 5.0, |x, _, _| x.ln()),
    ("sqrt(x + q)", -1.5, 5.0, |x, _, q| (x + q).sqrt()),
    ("abs(x - p)", -3.0, 3.0, |x, p, _| (x - p).abs()),
    ("sign(x)*p", -3.0, 3.0, |x, p, _| x.signum() * p),
    ("tanh(q*x)", -2.0, 2.0, |x, _, q| (q * x).tanh()),
    ("atan(x/p)", -3.0, 3.0, |x, p, _| (x / p).atan()),
    ("min(x, p)", -3.0, 3.0, |x, p, _| x.min(p)),
    ("max(x, p*q)", 0.0, 6.0, |x, p, q| x.max(p * q)),
    ("pow(x, p)", 0.1, 3.0, |x, p, _| x.powf(p)),
    ("x^q", 0.1, 3.0, |x, _, q| x.powf(q)),
    ("p^x", -2.0, 2.0, |x, p, _| p.powf(x)),
    ("x^3 - 2*x^2", -2.0, 2.0, |x, _, _| {
        x.powi(3) - 2.0 * x.powi(2)
    }),
    ("x^-2", 0.5, 3.0, |x, _, _| x.powi(-2)),
    ("x^0.5 * q", 0.1, 3.0, |x, _, q| x.sqrt() * q),
    ("-x^2", -2.0, 2.0, |x, _, _| -(x * x)),
    ("p/x - x/q", 0.5, 3.0, |x, p, q| p / x - x / q),
    (
        "if(x > p and not (x >= q), x^2, sin(x)*p)",
        0.0,
        3.0,
        |x, p, q| {
            if x > p && x < q {
                x * x
            } else {
                x.sin() * p
            }
        },
    ),
    (
        "if(x < 0 or x == p or x != x, 1, x*q)",
        -2.0,
        2.0,
        |x, _, q| {
            if x < 0.0 {
                1.0
            } else {
                x * q
            }
        },
    ),
    ("if(x <= p, exp(x), ln(x))", 0.5, 3.0, |x, p, _| {
        if x <= p {
            x.exp()
        } else {
            x.ln()
        }
    }),
    (
        "2*pi*x - (x - p) * (x + q) / (1 + x^2)",
        -3.0,
        3.0,
        |x, p, q| 2.0 * std::f64::consts::PI * x - (x - p) * (x + q) / (1.0 + x * x),
    ),
];

#[test]
fn every_function_has_its_value_and_central_difference_derivatives() {
    let mut rng = Rng::new(0x5eed_0010);
    for (expr, lo, hi, reference) in CASES {
        let m = model(expr);
        for _ in 0..40 {
            let x = rng.uniform(lo, hi);
            let s = rng.uniform(0.8, 1.2);
            let (p, q) = (1.5 * s, 2.0 * s);
            let (f, fx, ft) = first_row(&m, x, 0.3, 0.7, p, q);
            let want = reference(x, p, q);
            assert!(
                (f - want).abs() <= 1e-13 * want.abs().max(1.0),
                "{expr} at x={x}: {f} vs {want}"
            );
            let th = [p, q];
            let xs = [x, 0.3];
            let us = [0.7];
            let fdx = fd_rhs(&m, 0.0, &xs, &us, &th, Arg::State);
            let fdt = fd_rhs(&m, 0.0, &xs, &us, &th, Arg::Param);
            let scale = [fx[0].abs().max(ft[0].abs()).max(ft[1].abs()), 0.0];
            assert_rows_close(
                &fx,
                &fdx[..2],
                1,
                &scale,
                1e-6,
                &format!("∂/∂x {expr} at x={x}"),
            );
            assert_rows_close(
                &ft,
                &fdt[..2],
                1,
                &scale,
                1e-6,
                &format!("∂/∂θ {expr} at x={x}"),
            );
        }
    }
}

#[test]
fn derivative_conventions_at_non_smooth_points() {
    // (expression, x, p, value, ∂/∂x, ∂/∂p)
    let cases: [(&str, f64, f64, f64, f64, f64); 16] = [
        ("sign(x)", 0.0, 1.5, 0.0, 0.0, 0.0),
        ("sign(x)", -2.0, 1.5, -1.0, 0.0, 0.0),
        ("abs(x)", 0.0, 1.5, 0.0, 0.0, 0.0),
        ("abs(x)", -2.0, 1.5, 2.0, -1.0, 0.0),
        ("sqrt(x)", 0.0, 1.5, 0.0, 0.0, 0.0),
        ("x^0.5", 0.0, 1.5, 0.0, 0.0, 0.0),
        ("x^p", 0.0, 0.5, 0.0, 0.0, 0.0), // ∞ → 0, and 0^p·ln 0 → 0
        ("x^p", 0.0, 1.0, 0.0, 1.0, 0.0), // 1·0⁰ = 1 exists
        ("x^p", -2.0, 2.0, 4.0, -4.0, 0.0), // base < 0: no derivative in the exponent
        ("ln(x + 1)", -1.0, 1.5, f64::NEG_INFINITY, 0.0, 0.0),
        ("min(x, p)", 1.5, 1.5, 1.5, 1.0, 0.0), // tie: the first argument
        ("max(p, x)", 1.5, 1.5, 1.5, 0.0, 1.0),
        ("if(x > 0, x^2, -x)", 0.0, 1.5, 0.0, -1.0, 0.0),
        ("abs(x)^p", 0.0, 1.0, 0.0, 0.0, 0.0), // sign(0)·1: Bouc–Wen's |z|^ν at z = 0
        ("exp(-1/x^2)", 0.0, 1.5, 0.0, 0.0, 0.0), // ∞·0 inside the chain → 0
        ("1/x", 0.0, 1.5, f64::INFINITY, 0.0, 0.0), // the value stays infinite
    ];
    for (expr, x, p, want, dfdx, dfdp) in cases {
        let (f, fx, ft) = first_row(&model(expr), x, 0.0, 0.0, p, 2.0);
        assert_eq!(f, want, "{expr} value at x={x}");
        assert_eq!(fx[0], dfdx, "{expr} ∂/∂x at x={x}");
        assert_eq!(ft[0], dfdp, "{expr} ∂/∂p at x={x}");
        assert!(fx.iter().chain(&ft).all(|d| d.is_finite()), "{expr}");
    }
}

#[test]
fn integer_powers_are_multiplications_and_x_to_the_one_is_x() {
    let mut rng = Rng::new(0x5eed_0011);
    let cube = model("x^3");
    let pow2 = model("pow(x, 2)");
    for _ in 0..100 {
        let x = rng.uniform(-10.0, 10.0);
        // Bitwise equal to the multiplication chain (powf may differ in the last bit).
        assert_eq!(first_row(&cube, x, 0.0, 0.0, 1.5, 2.0).0, x * x * x);
        assert_eq!(first_row(&pow2, x, 0.0, 0.0, 1.5, 2.0).0, x * x);
    }
    // x^1 is x itself: no instruction at all.
    assert_eq!(model("x^1").tape_lengths()[0], 0);
    assert_eq!(model("x^3").tape_lengths()[0], 1);
}

#[test]
fn constant_folding_and_simplification_leave_no_instructions() {
    let m = model2("x*1 + 0*w + (2*3 - 6)*w + 0 - 0/u", "2*pi/pi + 1e-3*1e3");
    assert_eq!(m.tape_lengths()[0], 0);
    let mut dx = [0.0; 2];
    m.rhs(0.0, &[4.0, 5.0], &[6.0], &[1.5, 2.0], &mut dx);
    assert_eq!(dx, [4.0, 3.0]);
    assert_eq!(value("-(-x)", 2.5), 2.5);
    assert_eq!(model("-(-x)").tape_lengths()[0], 0);
    assert_eq!(model("if(1 < 2, x, exp(x))").tape_lengths()[0], 0);
}

#[test]
fn common_subexpressions_are_shared() {
    // x + w, its sine (written twice, operands swapped), the sum: three instructions.
    let m = model("sin(x + w) + sin(w + x)*1");
    assert_eq!(m.tape_lengths()[0], 3);
    // ∂/∂x and ∂/∂w of sin(x+w) share cos(x+w).
    let one = model("sin(x + w)");
    assert_eq!(one.tape_lengths()[1], 3);
}

#[test]
fn time_inputs_and_discrete_models() {
    let m = model("sin(t)*x + u");
    let mut dx = [0.0; 2];
    m.rhs(0.5, &[2.0, 0.0], &[0.25], &[1.5, 2.0], &mut dx);
    assert_eq!(dx[0], 0.5f64.sin() * 2.0 + 0.25);
    let mut fu = [0.0; 2];
    m.rhs_input_jacobian(0.5, &[2.0, 0.0], &[0.25], &[1.5, 2.0], &mut dx, &mut fu);
    assert_eq!(fu, [1.0, 0.0]);

    let d = EquationModel::parse(
        r#"[model]
name = "ar1"
time = "discrete"
states = ["x"]
inputs = ["u"]
outputs = ["y"]
units = { x = "m", y = "m" }
[parameters]
a = { value = 0.9, lower = -1, upper = 1 }
b = { value = 0.1, unit = "m/V" }
[initial]
x = { value = 0.5, fixed = false }
[equations]
x = "a*x + b*u"
[output]
y = "2*x + u"
"#,
    )
    .unwrap();
    assert_eq!(d.time_domain(), TimeDomain::Discrete);
    assert_eq!(d.initial()[0].value, 0.5);
    assert!(!d.initial()[0].fixed);
    assert_eq!(d.unit("x"), Some("m"));
    assert_eq!(d.unit("b"), Some("m/V"));
    let mut next = [0.0];
    d.rhs(3.0, &[1.0], &[2.0], &[0.9, 0.1], &mut next);
    assert_eq!(next[0], 0.9 + 0.2);
    let (mut y, mut hx, mut ht, mut hu) = ([0.0], [0.0], [0.0; 2], [0.0]);
    d.output_jacobians(&[1.0], &[2.0], &[0.9, 0.1], &mut y, &mut hx, &mut ht);
    assert_eq!((y, hx, ht), ([4.0], [2.0], [0.0, 0.0]));
    d.output_input_jacobian(&[1.0], &[2.0], &[0.9, 0.1], &mut y, &mut hu);
    assert_eq!(hu, [1.0]);
}

#[test]
fn a_caller_owned_scratch_gives_the_same_results_and_is_reused() {
    let a = model("x^2*p + sin(w*q)");
    let b = model("exp(x) - u");
    let mut s = Scratch::new();
    for (m, x) in [(&a, 0.3), (&b, -0.7), (&a, 1.1)] {
        let (mut d1, mut fx1, mut ft1) = ([0.0; 2], [0.0; 4], [0.0; 4]);
        let (mut d2, mut fx2, mut ft2) = ([0.0; 2], [0.0; 4], [0.0; 4]);
        m.rhs_jacobians_with(
            &mut s,
            0.0,
            &[x, 0.2],
            &[0.1],
            &[1.5, 2.0],
            &mut d1,
            &mut fx1,
            &mut ft1,
        );
        m.rhs_jacobians(
            0.0,
            &[x, 0.2],
            &[0.1],
            &[1.5, 2.0],
            &mut d2,
            &mut fx2,
            &mut ft2,
        );
        assert_eq!((d1, fx1, ft1), (d2, fx2, ft2));
        let mut y = [0.0];
        m.output_with(&mut s, &[x, 0.2], &[0.1], &[1.5, 2.0], &mut y);
        assert_eq!(y[0], x);
    }
}

#[test]
fn models_are_shared_across_threads() {
    fn assert_traits<T: Clone + Send + Sync + std::fmt::Debug>() {}
    assert_traits::<EquationModel>();
    let m = std::sync::Arc::new(model("x*p - w"));
    let handles: Vec<_> = (0..4)
        .map(|k| {
            let m = m.clone();
            std::thread::spawn(move || {
                let mut dx = [0.0; 2];
                m.rhs(0.0, &[k as f64, 1.0], &[0.0], &[1.5, 2.0], &mut dx);
                dx[0]
            })
        })
        .collect();
    let got: Vec<f64> = handles.into_iter().map(|h| h.join().unwrap()).collect();
    assert_eq!(got, [-1.0, 0.5, 2.0, 3.5]);
}
