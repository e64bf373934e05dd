//! The shipped example files: they parse, their Jacobians equal central differences, and
//! Bouc–Wen and the fixed-saddle actuator equal hand-written transcriptions of hysid's
//! built-in models.

use crate::common;

use common::{assert_rows_close, example, fd_output, fd_rhs, Arg, Rng};
use hysid_equations::{EquationModel, TimeDomain};

const EXAMPLES: [&str; 5] = [
    "bouc_wen.toml",
    "actuator_fixed.toml",
    "duffing.toml",
    "cascaded_tanks.toml",
    "backlash_first_order.toml",
];

fn load(name: &str) -> EquationModel {
    EquationModel::parse(&example(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn every_example_parses_with_its_declared_shape() {
    let shapes = [
        ("bouc_wen.toml", 3, 1, 1, 7),
        ("actuator_fixed.toml", 3, 1, 1, 7),
        ("duffing.toml", 2, 1, 1, 4),
        ("cascaded_tanks.toml", 2, 1, 1, 9),
        ("backlash_first_order.toml", 2, 1, 1, 3),
    ];
    for (name, n, m, ny, p) in shapes {
        let model = load(name);
        assert_eq!(model.states().len(), n, "{name}");
        assert_eq!(model.inputs().len(), m, "{name}");
        assert_eq!(model.outputs().len(), ny, "{name}");
        assert_eq!(model.parameters().len(), p, "{name}");
        assert_eq!(model.initial().len(), n, "{name}");
        let time = if name == "backlash_first_order.toml" {
            TimeDomain::Discrete
        } else {
            TimeDomain::Continuous
        };
        assert_eq!(model.time_domain(), time, "{name}");
        assert_eq!(model.source(), example(name));
    }
}

#[test]
fn bouc_wen_declares_the_built_in_parameterisation() {
    let m = load("bouc_wen.toml");
    let names: Vec<&str> = m.parameters().iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        ["mL", "cL", "kL", "alpha", "beta_gamma", "beta_delta", "nu"]
    );
    assert_eq!(
        m.parameter_values(),
        [2.0, 10.0, 5e4, 5e4, 800.0, -1100.0, 1.0]
    );
    let nu = &m.parameters()[6];
    assert!(nu.fixed && nu.lower == 0.1 && nu.upper == 10.0);
    assert_eq!(m.parameters()[0].lower, 1e-9);
    assert_eq!(m.parameters()[4].lower, f64::NEG_INFINITY);
    assert_eq!(m.states(), ["y", "v", "z"]);
    assert_eq!(m.unit("z"), Some("N"));
    assert_eq!(m.unit("cL"), Some("N*s/m"));
}

/// A random operating point of each example: (t, x, u, θ).
fn point(name: &str, rng: &mut Rng, m: &EquationModel) -> (f64, Vec<f64>, Vec<f64>, Vec<f64>) {
    let t = rng.uniform(0.0, 10.0);
    let mut th: Vec<f64> = m
        .parameter_values()
        .iter()
        .map(|v| v * rng.uniform(0.8, 1.2))
        .collect();
    let (x, u) = match name {
        "bouc_wen.toml" => {
            th[6] = rng.uniform(0.5, 2.0); // ν away from 1 too, to exercise |z|^ν
            (
                vec![
                    rng.uniform(-1e-3, 1e-3),
                    rng.uniform(-0.05, 0.05),
                    rng.uniform(-50.0, 50.0),
                ],
                vec![rng.uniform(-100.0, 100.0)],
            )
        }
        "actuator_fixed.toml" => (
            vec![
                rng.uniform(-0.05, 0.05),
                rng.uniform(-2.0, 2.0),
                rng.uniform(-1.0, 1.0),
            ],
            vec![rng.uniform(-2.0, 2.0)],
        ),
        "duffing.toml" => {
            th[3] = rng.uniform(-1.0, 1.0);
            (
                vec![rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0)],
                vec![rng.uniform(-1.0, 1.0)],
            )
        }
        "backlash_first_order.toml" => (
            // z anywhere around u: inside the play band and clamped on either side.
            vec![rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)],
            vec![rng.uniform(-1.0, 1.0)],
        ),
        _ => {
            // Half the points with the upper tank overflowing (x1 above x1max = 10), and
            // the lower one in and above the sensor range.
            let x1 = if rng.uniform(0.0, 1.0) < 0.5 {
                rng.uniform(0.5, 9.5)
            } else {
                rng.uniform(10.5, 12.0)
            };
            (
                vec![x1, rng.uniform(0.5, 12.0)],
                vec![rng.uniform(0.5, 8.0)],
            )
        }
    };
    (t, x, u, th)
}

#[test]
fn every_example_jacobian_equals_central_differences() {
    let mut rng = Rng::new(0x5eed_0001);
    for name in EXAMPLES {
        let m = load(name);
        let (n, p, mi, ny) = (
            m.states().len(),
            m.parameters().len(),
            m.inputs().len(),
            m.outputs().len(),
        );
        let mut worst = 0.0f64;
        for _ in 0..50 {
            let (t, x, u, th) = point(name, &mut rng, &m);
            let (mut dx, mut fx, mut ft) = (vec![0.0; n], vec![0.0; n * n], vec![0.0; n * p]);
            m.rhs_jacobians(t, &x, &u, &th, &mut dx, &mut fx, &mut ft);
            let mut plain = vec![0.0; n];
            m.rhs(t, &x, &u, &th, &mut plain);
            assert_eq!(dx, plain, "{name}: f from both tapes");
            let scale: Vec<f64> = (0..n)
                .map(|i| {
                    fx[i * n..(i + 1) * n]
                        .iter()
                        .chain(&ft[i * p..(i + 1) * p])
                        .fold(0.0f64, |a, b| a.max(b.abs()))
                })
                .collect();
            let ctx = format!("{name} at x={x:?} u={u:?} θ={th:?}");
            worst = worst.max(assert_rows_close(
                &fx,
                &fd_rhs(&m, t, &x, &u, &th, Arg::State),
                n,
                &scale,
                1e-6,
                &format!("∂f/∂x {ctx}"),
            ));
            worst = worst.max(assert_rows_close(
                &ft,
                &fd_rhs(&m, t, &x, &u, &th, Arg::Param),
                n,
                &scale,
                1e-6,
                &format!("∂f/∂θ {ctx}"),
            ));
            let mut fu = vec![0.0; n * mi];
            m.rhs_input_jacobian(t, &x, &u, &th, &mut dx, &mut fu);
            worst = worst.max(assert_rows_close(
                &fu,
                &fd_rhs(&m, t, &x, &u, &th, Arg::Input),
                n,
                &scale,
                1e-6,
                &format!("∂f/∂u {ctx}"),
            ));

            let (mut y, mut hx, mut ht) = (vec![0.0; ny], vec![0.0; ny * n], vec![0.0; ny * p]);
            m.output_jacobians(&x, &u, &th, &mut y, &mut hx, &mut ht);
            let ones = vec![1.0; ny];
            worst = worst.max(assert_rows_close(
                &hx,
                &fd_output(&m, &x, &u, &th, Arg::State),
                ny,
                &ones,
                1e-6,
                &format!("∂h/∂x {ctx}"),
            ));
            worst = worst.max(assert_rows_close(
                &ht,
                &fd_output(&m, &x, &u, &th, Arg::Param),
                ny,
                &ones,
                1e-6,
                &format!("∂h/∂θ {ctx}"),
            ));
        }
        eprintln!("{name}: worst relative difference to central differences {worst:e}");
        assert!(worst < 1e-6);
    }
}

// ---- Hand-written transcriptions of hysid's built-in models (crates/hysid/src/greybox/
// models/{bouc_wen,actuator}.rs), for the equations-versus-built-in check. ----

fn sign0(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Bouc–Wen f, ∂f/∂x, ∂f/∂θ as the built-in model computes them.
fn bouc_wen_builtin(
    x: &[f64],
    u: &[f64],
    th: &[f64],
    dx: &mut [f64],
    fx: &mut [f64],
    ft: &mut [f64],
) {
    const ML: usize = 0;
    const CL: usize = 1;
    const KL: usize = 2;
    const ALPHA: usize = 3;
    const BG: usize = 4;
    const BD: usize = 5;
    const NU: usize = 6;
    let (y, v, z) = (x[0], x[1], x[2]);
    let nu = th[NU];
    let a = z.abs().powf(nu);
    dx[0] = v;
    dx[1] = (u[0] - th[CL] * v - th[KL] * y - z) / th[ML];
    dx[2] = th[ALPHA] * v - th[BG] * v.abs() * sign0(z) * a - th[BD] * v * a;
    let da = if z == 0.0 {
        if nu == 1.0 {
            1.0
        } else {
            0.0
        }
    } else {
        nu * z.abs().powf(nu - 1.0)
    };
    let m = th[ML];
    fx.fill(0.0);
    ft.fill(0.0);
    fx[1] = 1.0;
    fx[3] = -th[KL] / m;
    fx[4] = -th[CL] / m;
    fx[5] = -1.0 / m;
    fx[7] = th[ALPHA] - th[BG] * sign0(v) * sign0(z) * a - th[BD] * a;
    fx[8] = -th[BG] * v.abs() * da - th[BD] * v * da * sign0(z);
    let p = th.len();
    let acc = (u[0] - th[CL] * v - th[KL] * y - z) / m;
    ft[p + ML] = -acc / m;
    ft[p + CL] = -v / m;
    ft[p + KL] = -y / m;
    let ln = if z == 0.0 { 0.0 } else { z.abs().ln() };
    ft[2 * p + ALPHA] = v;
    ft[2 * p + BG] = -v.abs() * sign0(z) * a;
    ft[2 * p + BD] = -v * a;
    ft[2 * p + NU] = -(th[BG] * v.abs() * sign0(z) + th[BD] * v) * a * ln;
}

/// Fixed-saddle actuator f, ∂f/∂x, ∂f/∂θ as the built-in model computes them while the
/// motor moves (x2 ≠ 0).
fn actuator_builtin(
    x: &[f64],
    u: &[f64],
    th: &[f64],
    dx: &mut [f64],
    fx: &mut [f64],
    ft: &mut [f64],
) {
    const J: usize = 0;
    const FV: usize = 1;
    const FC: usize = 2;
    const K1: usize = 3;
    const K2: usize = 4;
    const ALPHA: usize = 5;
    const A: usize = 6;
    let (x1, x2, x4) = (x[0], x[1], x[2]);
    let g = th[K1] * x1 + th[K2] * x1.powi(3) + x4;
    let dg = th[K1] + 3.0 * th[K2] * x1 * x1;
    let s = sign0(x2);
    let applied = u[0] - g - th[FV] * x2;
    let acc = (applied - th[FC] * s) / th[J];
    dx[0] = x2;
    dx[1] = acc;
    dx[2] = -th[ALPHA] * x2.abs() * x4 + th[A] * x2;
    let p = th.len();
    let j = th[J];
    fx.fill(0.0);
    ft.fill(0.0);
    fx[1] = 1.0;
    fx[3] = -dg / j;
    fx[4] = -th[FV] / j;
    fx[5] = -1.0 / j;
    fx[7] = -th[ALPHA] * s * x4 + th[A];
    fx[8] = -th[ALPHA] * s * x2;
    ft[p + J] = -acc / j;
    ft[p + FV] = -x2 / j;
    ft[p + FC] = -s / j;
    ft[p + K1] = -x1 / j;
    ft[p + K2] = -x1.powi(3) / j;
    ft[2 * p + ALPHA] = -s * x2 * x4;
    ft[2 * p + A] = x2;
}

type Builtin = fn(&[f64], &[f64], &[f64], &mut [f64], &mut [f64], &mut [f64]);

fn compare_with_builtin(name: &str, builtin: Builtin, seed: u64) {
    let m = load(name);
    let (n, p) = (m.states().len(), m.parameters().len());
    let mut rng = Rng::new(seed);
    let mut worst = 0.0f64;
    for k in 0..200 {
        let (t, x, u, mut th) = point(name, &mut rng, &m);
        if name == "bouc_wen.toml" && k % 2 == 0 {
            th[6] = 1.0; // the fixed default ν as well as free ones
        }
        let (mut dx, mut fx, mut ft) = (vec![0.0; n], vec![0.0; n * n], vec![0.0; n * p]);
        m.rhs_jacobians(t, &x, &u, &th, &mut dx, &mut fx, &mut ft);
        let (mut bdx, mut bfx, mut bft) = (vec![0.0; n], vec![0.0; n * n], vec![0.0; n * p]);
        builtin(&x, &u, &th, &mut bdx, &mut bfx, &mut bft);
        for (got, want, what) in [(&dx, &bdx, "f"), (&fx, &bfx, "∂f/∂x"), (&ft, &bft, "∂f/∂θ")]
        {
            for (g, w) in got.iter().zip(want.iter()) {
                let err = (g - w).abs() / w.abs().max(1e-300);
                if *w != 0.0 {
                    worst = worst.max(err);
                }
                assert!(
                    (g - w).abs() <= 1e-12 * w.abs().max(1e-9),
                    "{name} {what} at x={x:?} θ={th:?}: {got:?} vs {want:?}"
                );
            }
        }
    }
    eprintln!("{name}: worst relative difference to the built-in transcription {worst:e}");
}

#[test]
fn bouc_wen_equals_the_built_in_model() {
    compare_with_builtin("bouc_wen.toml", bouc_wen_builtin, 0x5eed_0002);
}

#[test]
fn actuator_fixed_equals_the_built_in_model_away_from_rest() {
    compare_with_builtin("actuator_fixed.toml", actuator_builtin, 0x5eed_0003);
}

#[test]
fn cascaded_tanks_overflow_and_pump_dead_zone() {
    let m = load("cascaded_tanks.toml");
    let th = m.parameter_values();
    let (k1, k2, k3, k4, k5, x1max, kw, u0) =
        (th[0], th[1], th[2], th[3], th[4], th[5], th[6], th[8]);
    let mut dx = [0.0; 2];
    // Above the brim: the overflow kw·(x1 − x1max) leaves the upper tank, k5 of it reaches
    // the lower one.
    let (x1, x2, u) = (x1max + 0.5, 4.0, 6.0);
    m.rhs(0.0, &[x1, x2], &[u], &th, &mut dx);
    let q = kw * 0.5;
    approx::assert_relative_eq!(
        dx[0],
        k4 * (u - u0) - k1 * x1.sqrt() - q,
        max_relative = 1e-14
    );
    approx::assert_relative_eq!(
        dx[1],
        k2 * x1.sqrt() + k5 * q - k3 * x2.sqrt(),
        max_relative = 1e-14
    );
    // Below the brim the Torricelli law alone; below the dead zone no inflow.
    m.rhs(0.0, &[4.0, x2], &[u], &th, &mut dx);
    approx::assert_relative_eq!(dx[0], k4 * (u - u0) - k1 * 2.0, max_relative = 1e-14);
    m.rhs(0.0, &[4.0, x2], &[u0 / 2.0], &th, &mut dx);
    approx::assert_relative_eq!(dx[0], -k1 * 2.0, max_relative = 1e-14);
    // The sensor saturates at 10 V.
    let mut y = [0.0];
    m.output(&[4.0, 11.0], &[u], &th, &mut y);
    assert_eq!(y[0], 10.0);
}

#[test]
fn duffing_is_the_cubic_oscillator() {
    let m = load("duffing.toml");
    let th = [2.0, 0.3, 5.0, 7.0];
    let (x, v, u) = (0.4, -1.1, 0.25);
    let mut dx = [0.0; 2];
    m.rhs(0.0, &[x, v], &[u], &th, &mut dx);
    assert_eq!(dx[0], v);
    approx::assert_relative_eq!(
        dx[1],
        (u - 0.3 * v - 5.0 * x - 7.0 * x * x * x) / 2.0,
        max_relative = 1e-15
    );
}

/// A tape restricted to some ∂f/∂θ columns gives, bit for bit, the same f, ∂f/∂x and those
/// columns as the full Jacobian tape, and is shorter when a column is left out.
#[test]
fn column_tapes_equal_the_full_jacobian_columns() {
    let mut rng = Rng::new(0x5eed_0002);
    for name in EXAMPLES {
        let m = load(name);
        let (n, p) = (m.states().len(), m.parameters().len());
        let all: Vec<usize> = (0..p).collect();
        let subsets = [all.clone(), (0..p - 1).collect(), vec![p - 1, 0], vec![]];
        assert!(m.rhs_jacobian_columns(&[p]).is_none(), "{name}");
        let full_len = m.tape_lengths()[1];
        assert_eq!(m.rhs_jacobian_columns(&all).unwrap().len(), full_len);
        let mut s = m.scratch();
        for cols in &subsets {
            let tape = m.rhs_jacobian_columns(cols).unwrap();
            assert!(tape.len() <= full_len, "{name}");
            assert_eq!(tape.params(), cols.as_slice());
            for _ in 0..10 {
                let (t, x, u, th) = point(name, &mut rng, &m);
                let (mut dx, mut fx, mut ft) = (vec![0.0; n], vec![0.0; n * n], vec![0.0; n * p]);
                m.rhs_jacobians(t, &x, &u, &th, &mut dx, &mut fx, &mut ft);
                let k = cols.len();
                let (mut dx2, mut fx2, mut ft2) =
                    (vec![0.0; n], vec![0.0; n * n], vec![0.0; n * k]);
                m.rhs_jacobian_columns_with(
                    &mut s, &tape, t, &x, &u, &th, &mut dx2, &mut fx2, &mut ft2,
                );
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&dx2), bits(&dx), "{name} {cols:?}: f");
                assert_eq!(bits(&fx2), bits(&fx), "{name} {cols:?}: ∂f/∂x");
                let want: Vec<f64> = (0..n)
                    .flat_map(|i| cols.iter().map(move |&c| (i, c)))
                    .map(|(i, c)| ft[i * p + c])
                    .collect();
                assert_eq!(bits(&ft2), bits(&want), "{name} {cols:?}: ∂f/∂θ");
            }
        }
    }
    // Bouc–Wen without ν: ∂f/∂ν = −(…)·|z|^ν·ln|z| is no longer computed.
    let m = load("bouc_wen.toml");
    let six = m.rhs_jacobian_columns(&[0, 1, 2, 3, 4, 5]).unwrap();
    assert!(six.len() < m.tape_lengths()[1]);
}

/// An output reads the input when it is the input or when the tape computes it (which may
/// read anything); an output that is a state, a parameter or a constant does not.
#[test]
fn outputs_that_read_the_input_are_told_apart() {
    let model = |output: &str| {
        EquationModel::parse(&format!(
            r#"
[model]
name = "first_order"
states = ["x"]
inputs = ["u"]
outputs = ["y"]

[parameters]
a = {{ value = 2.0 }}

[equations]
x = "-a*x + u"

[output]
y = "{output}"
"#
        ))
        .unwrap()
    };
    for (output, reads) in [
        ("x", false),
        ("a", false),
        ("1.5", false),
        ("u", true),
        ("x + u", true),
        ("2*x", true),
    ] {
        assert_eq!(model(output).output_reads_inputs(), reads, "y = {output}");
    }
    assert!(model("x").constant_output_jacobians().is_some());
    assert!(model("2*x").constant_output_jacobians().is_none());
}
