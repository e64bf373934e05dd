//! Tests of `hysid::model::greybox::native`: the compiled form of an equation model's
//! tapes gives the tape's numbers to the bit.

use hysid::model::greybox::native::{
    Backend, Evaluator, Layout, NativeFunction, Provenance, Shape,
};
use hysid_equations::EquationModel;

/// Every operation of the language: the functions, integer and real powers (the exponent a
/// parameter equal to 1, so pow's shortcut is taken), comparisons, and/or/not, if, and a
/// literal constant.
const EVERY_OPERATION: &str = r#"
[model]
states = ["a", "b"]
inputs = ["u", "w"]
outputs = ["y", "z"]

[parameters]
k = 1.5
m = -0.75
n = 3.0
e = 1.0

[let]
q = "abs(a) + 0.5"

[equations]
a = "sin(a)*cos(b) + tan(u/7) - exp(-a^2) + ln(1 + b^2) + sqrt(abs(w) + 1) + sign(a - b)*tanh(k*u) + atan(m*w)"
b = "pow(q, n) + pow(abs(b), e) + a^-3 + b^7 + min(a, k)*max(b, m) + if(a < b and not (u >= w) or a == b, k, -m) + if(a != u, a/(b + 2.5), 0.125)"

[output]
y = "a*k + b"
z = "b"
"#;

/// A small xorshift generator: seeded, reproducible points.
struct Points(u64);

impl Points {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        // Mostly moderate values, some large, some exactly zero or negative zero.
        match self.0 % 16 {
            0 => 0.0,
            1 => -0.0,
            2 => (self.0 >> 11) as f64 * 1e-300,
            3 => ((self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 1e6,
            _ => ((self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 8.0,
        }
    }
    fn vec(&mut self, n: usize) -> Vec<f64> {
        (0..n).map(|_| self.next()).collect()
    }
}

fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

fn shape(m: &EquationModel) -> Shape {
    Shape {
        states: m.states().len(),
        inputs: m.inputs().len(),
        parameters: m.parameters().len(),
    }
}

fn results(values: usize, positions: Vec<usize>) -> Layout {
    Layout::Results { values, positions }
}

/// The routes to native code this machine has (the C compiler's on Linux).
fn backends() -> Vec<Backend> {
    let all = [Backend::Compiled];
    let here: Vec<Backend> = all.into_iter().filter(|b| b.available()).collect();
    assert!(!here.is_empty(), "no route to native code on this machine");
    here
}

/// Checks the native f, the native columns of `params` (padded to `q`, written in reverse
/// order to exercise the positions) and the native sensitivity rates of those columns
/// against the tape at 400 seeded points, and the native RK4 sub-steps of a sample against
/// the classical RK4 of those rates; the code made by `backend`.
fn check_model(m: &EquationModel, params: &[usize], q: usize, seed: u64, backend: Backend) {
    let (n, k) = (m.states().len(), params.len());
    let mut points = Points(seed);
    let theta = m.parameter_values();

    // f alone.
    let positions: Vec<usize> = (0..n).collect();
    let build = |listing: &hysid_equations::Listing, layout: Layout| {
        NativeFunction::build(listing, layout, shape(m), backend, |_| true).unwrap()
    };
    let f = build(&m.rhs_listing(), results(n, positions));
    // Columns: f, ∂f/∂x, ∂f/∂θ[params] into rows of q, the whole layout reversed.
    let columns = m.rhs_jacobian_columns(params).unwrap();
    let len = n + n * n + n * q;
    let natural: Vec<usize> = (0..n + n * n)
        .chain((0..n * k).map(|r| n + n * n + (r / k) * q + r % k))
        .collect();
    let reversed: Vec<usize> = natural.iter().map(|p| len - 1 - p).collect();
    let listing = m.columns_listing(&columns);
    let jac = build(&listing, results(n, reversed.clone()));
    let sens = build(&listing, Layout::Sensitivities { k, q });
    let coupled = vec![true; n * n];
    let rates = sens
        .rates()
        .expect("a sensitivity function carries ẋ alone");
    assert!(f.rates().is_none());

    for point in 0..400 {
        let x = points.vec(n);
        let u = points.vec(m.inputs().len());
        // Half of the points at the file's θ, half at another one.
        let th: Vec<f64> = if point % 2 == 0 {
            theta.clone()
        } else {
            theta
                .iter()
                .map(|v| v * (1.0 + 0.25 * points.next()))
                .collect()
        };
        let (mut tape, mut native, mut carried) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        m.rhs(0.0, &x, &u, &th, &mut tape);
        f.bind(&th).eval(0.0, &x, &u, &mut native);
        // ẋ alone from the sensitivity code's translation unit.
        rates.bind(&th).eval(0.0, &x, &u, &mut carried);
        for i in 0..n {
            assert!(
                same(tape[i], native[i]) && same(tape[i], carried[i]),
                "f{i} at x {x:?}, u {u:?}, θ {th:?}: tape {} native {} carried {}",
                tape[i],
                native[i],
                carried[i]
            );
        }
        let mut s = m.scratch();
        let (mut dx, mut fx, mut ft) = (vec![0.0; n], vec![0.0; n * n], vec![0.0; n * k]);
        m.rhs_jacobian_columns_with(
            &mut s, &columns, 0.0, &x, &u, &th, &mut dx, &mut fx, &mut ft,
        );
        let mut out = vec![f64::NAN; len];
        jac.bind(&th).eval(0.0, &x, &u, &mut out);
        for (r, v) in dx.iter().chain(&fx).chain(&ft).enumerate() {
            let got = out[reversed[r]];
            assert!(
                same(*v, got),
                "result {r} at x {x:?}, u {u:?}, θ {th:?}: tape {v} native {got}"
            );
        }
        // Ṡ = [f_θ, 0] + f_x·S, summed in the order of j; a constant-zero entry's product is
        // left out by the native code, which changes at most the sign of a zero.
        let s = points.vec(n * q);
        let (mut ndx, mut nds) = (vec![0.0; n], vec![0.0; n * q]);
        sens.bind(&th)
            .sensitivities(0.0, &x, &u, &s, &coupled, &mut ndx, &mut nds);
        assert!(
            dx.iter().zip(&ndx).all(|(a, b)| same(*a, *b)),
            "ẋ at x {x:?}"
        );
        for i in 0..n {
            for c in 0..q {
                let mut d = if c < k { ft[i * k + c] } else { 0.0 };
                for j in 0..n {
                    d += fx[i * n + j] * s[j * q + c];
                }
                let got = nds[i * q + c];
                assert!(
                    same(d, got) || d == got,
                    "Ṡ[{i}][{c}] at x {x:?}, u {u:?}, S {s:?}: {d} native {got}"
                );
            }
        }
        if point % 8 == 0 {
            check_substeps(&sens, &th, &x, &s, &coupled, m.inputs().len(), &mut points);
        }
    }
}

/// Three RK4 sub-steps of one sample interval by `substeps` equal to the bit the classical
/// RK4 of the rates `sensitivities` gives, stage by stage in the fixed-size loop's order.
fn check_substeps(
    sens: &std::sync::Arc<NativeFunction>,
    theta: &[f64],
    x: &[f64],
    s: &[f64],
    coupled: &[bool],
    inputs: usize,
    points: &mut Points,
) {
    let (n, m, h) = (x.len(), 3, 1.0 / 3000.0);
    let nodes: Vec<f64> = (0..(2 * m + 1) * inputs)
        .map(|_| points.next() * 0.1)
        .collect();
    let bound = sens.bind(theta);
    let (mut zx, mut zs) = (x.to_vec(), s.to_vec());
    bound.substeps(&nodes, coupled, m, h, &mut zx, &mut zs);
    let (half, sixth) = (0.5 * h, h / 6.0);
    let mut z: Vec<f64> = x.iter().chain(s).copied().collect();
    let rate = |z: &[f64], node: usize| {
        let (mut dx, mut ds) = (vec![0.0; n], vec![0.0; s.len()]);
        let u = &nodes[node * inputs..(node + 1) * inputs];
        bound.sensitivities(0.0, &z[..n], u, &z[n..], coupled, &mut dx, &mut ds);
        dx.extend(ds);
        dx
    };
    let axpy = |z: &[f64], w: f64, k: &[f64]| -> Vec<f64> {
        z.iter().zip(k).map(|(a, b)| a + w * b).collect()
    };
    for j in 0..m {
        let k1 = rate(&z, 2 * j);
        let k2 = rate(&axpy(&z, half, &k1), 2 * j + 1);
        let k3 = rate(&axpy(&z, half, &k2), 2 * j + 1);
        let k4 = rate(&axpy(&z, h, &k3), 2 * j + 2);
        for (e, v) in z.iter_mut().enumerate() {
            *v += hysid::numerics::integrate::rk4::increment(sixth, k1[e], k2[e], k3[e], k4[e]);
        }
    }
    let got: Vec<f64> = zx.iter().chain(&zs).copied().collect();
    for (e, (a, b)) in z.iter().zip(&got).enumerate() {
        assert!(same(*a, *b), "sub-steps, element {e}: RK4 {a} native {b}");
    }
}

/// An entry of ∂f/∂x that depends on θ alone is left out of Ṡ where the kernel says it is
/// uncoupled (zero for the bound θ), and only there.
#[test]
fn uncoupled_entries_are_left_out_of_the_sensitivity_rates() {
    let text = std::fs::read_to_string(format!(
        "{}/../../examples/equations/bouc_wen.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let m = EquationModel::parse(&text).unwrap();
    let theta = m.parameter_values();
    let (k, q) = (6, 6);
    let columns = m.rhs_jacobian_columns(&[0, 1, 2, 3, 4, 5]).unwrap();
    for backend in backends() {
        uncoupled_entries_are_left_out(&m, &theta, &columns, k, q, backend);
    }
}

fn uncoupled_entries_are_left_out(
    m: &EquationModel,
    theta: &[f64],
    columns: &hysid_equations::ColumnTape,
    k: usize,
    q: usize,
    backend: Backend,
) {
    let sens = NativeFunction::build(
        &m.columns_listing(columns),
        Layout::Sensitivities { k, q },
        shape(m),
        backend,
        |_| true,
    )
    .unwrap()
    .bind(theta);
    let (x, u) = ([1e-3, -2e-2, 3.0], [5.0]);
    let s: Vec<f64> = (0..18).map(|i| 0.5 + i as f64).collect();
    let run = |coupled: &[bool]| {
        let (mut dx, mut ds) = ([0.0; 3], [0.0; 18]);
        sens.sensitivities(0.0, &x, &u, &s, coupled, &mut dx, &mut ds);
        ds
    };
    let all = run(&[true; 9]);
    // ∂ẏ/∂y = −kL/mL (row 1, column 0) depends on θ alone.
    let mut without = [true; 9];
    without[3] = false;
    let dropped = run(&without);
    let fx10 = -theta[2] / theta[0];
    for c in 0..q {
        assert_ne!(all[q + c], dropped[q + c]);
        let mut d = all[q + c];
        d -= fx10 * s[c];
        assert!(
            (d - dropped[q + c]).abs() <= 1e-9 * all[q + c].abs(),
            "column {c}"
        );
        // The other rows are unchanged.
        assert_eq!(all[c].to_bits(), dropped[c].to_bits());
        assert_eq!(all[2 * q + c].to_bits(), dropped[2 * q + c].to_bits());
    }
}

/// Every operation of the language, f and Jacobian columns, at seeded points that include
/// zeros of both signs, tiny and large values, θ moved from the file's values.
#[test]
fn native_code_equals_the_tape_for_every_operation() {
    let m = EquationModel::parse(EVERY_OPERATION).unwrap();
    for backend in backends() {
        check_model(&m, &[0, 1, 2, 3], 4, 1, backend);
        check_model(&m, &[0, 1, 2, 3], 6, 2, backend);
        check_model(&m, &[3, 1], 3, 3, backend);
    }
}

/// A Jacobian entry that depends on θ alone and is not finite (∂ẋ/∂w = ln p at p = 0)
/// counts as zero in Ṡ, in the sensitivity rates and in the sub-steps (whose generated code
/// makes such entries finite once per call).
#[test]
fn jacobian_entries_of_theta_alone_are_made_finite() {
    let m = EquationModel::parse(
        r#"
[model]
name = "infinite_gain"
states = ["x", "w"]
inputs = ["u"]
outputs = ["x"]

[parameters]
p = { value = 0.0 }
g = { value = 0.5 }

[equations]
x = "w * ln(p) + g * u"
w = "-x"

[output]
x = "x"
"#,
    )
    .unwrap();
    for backend in backends() {
        check_model(&m, &[0, 1], 2, 11, backend);
    }
}

/// The example files (Bouc–Wen, Duffing, cascaded tanks, the actuator with Coulomb
/// friction, the discrete-time backlash) with their free parameters' columns.
#[test]
fn native_code_equals_the_tape_on_the_example_files() {
    let dir = format!("{}/../../examples/equations", env!("CARGO_MANIFEST_DIR"));
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let m = EquationModel::parse(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let free: Vec<usize> = (0..m.parameters().len())
            .filter(|&i| !m.parameters()[i].fixed)
            .collect();
        for backend in backends() {
            check_model(&m, &free, free.len() + m.states().len(), 7 + seen, backend);
        }
        seen += 1;
    }
    assert!(seen >= 5, "{seen} example files");
}

/// A build compiles once; the next build of the same code loads the cached object; a
/// check that fails refuses the code.
#[test]
fn the_compiled_code_is_cached_and_checked() {
    // A literal no other test or run uses: the source is new to the cache.
    let stamp = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_nanos();
    let text = format!(
        "[model]\nstates = [\"x\"]\ninputs = [\"u\"]\noutputs = [\"y\"]\n[parameters]\na = 2.0\n\
         [equations]\nx = \"-a*x + u + {stamp}e-40\"\n[output]\ny = \"x\"\n"
    );
    let m = EquationModel::parse(&text).unwrap();
    let (listing, backend) = (m.rhs_listing(), Backend::Compiled);
    let build =
        || NativeFunction::build(&listing, results(1, vec![0]), shape(&m), backend, |_| true);
    let build = || build().unwrap();
    assert!(matches!(build().provenance(), Provenance::Compiled(s) if s > 0.0));
    assert_eq!(build().provenance(), Provenance::Cached);
    for backend in backends() {
        let refused =
            NativeFunction::build(&listing, results(1, vec![0]), shape(&m), backend, |_| false);
        assert!(refused.unwrap_err().contains("does not reproduce the tape"));
    }
}

/// The evaluators' names (`HYSID_EVALUATOR`, `--evaluator`, `evaluator=`): auto, native, cc
/// and tape; `jit` (the removed in-process encoder) and anything else are refused in one
/// line that names the accepted values; every evaluator but the tape goes to the C compiler.
#[test]
fn evaluators_are_named_auto_native_cc_and_tape() {
    assert_eq!("auto".parse::<Evaluator>().unwrap(), Evaluator::Auto);
    assert_eq!("".parse::<Evaluator>().unwrap(), Evaluator::Auto);
    assert_eq!("native".parse::<Evaluator>().unwrap(), Evaluator::Native);
    assert_eq!("cc".parse::<Evaluator>().unwrap(), Evaluator::Cc);
    assert_eq!(" tape ".parse::<Evaluator>().unwrap(), Evaluator::Tape);
    for (name, said) in [
        ("fast", "'fast' is not an equation evaluator"),
        ("jit", "removed"),
    ] {
        let e = name.parse::<Evaluator>().unwrap_err().to_string();
        assert!(
            e.contains(said) && e.contains("auto, native, cc or tape") && !e.contains('\n'),
            "{e}"
        );
    }
    for evaluator in [Evaluator::Auto, Evaluator::Native, Evaluator::Cc] {
        assert_eq!(evaluator.backends(), &[Backend::Compiled]);
        assert_eq!(evaluator.name().parse::<Evaluator>().unwrap(), evaluator);
    }
    assert!(Evaluator::Tape.backends().is_empty());
    assert!(Evaluator::Cc.requires_native() && Evaluator::Native.requires_native());
    assert!(!Evaluator::Auto.requires_native() && !Evaluator::Tape.requires_native());
}

/// A random expression over the states a, b, the inputs u, w and the parameters k, m, n, e
/// of `depth` levels, every operation of the language drawn (seeded).
fn random_expression(points: &mut Points, depth: usize) -> String {
    let mut pick = |n: u64| {
        points.next();
        (points.0 >> 17) % n
    };
    if depth == 0 {
        let leaves = ["a", "b", "u", "w", "k", "m", "n", "e", "0.5", "2", "-1.25"];
        return leaves[pick(leaves.len() as u64) as usize].to_string();
    }
    let op = pick(22);
    let sub = |points: &mut Points| random_expression(points, depth - 1);
    let (x, y) = (sub(points), sub(points));
    match op {
        0 => format!("({x} + {y})"),
        1 => format!("({x} - {y})"),
        2 => format!("({x} * {y})"),
        3 => format!("({x} / (1 + abs({y})))"),
        4 => format!("sin({x})"),
        5 => format!("cos({x}) * {y}"),
        6 => format!("tanh({x})"),
        7 => format!("atan({x})"),
        8 => format!("exp(-abs({x}))"),
        9 => format!("ln(1 + {x}^2)"),
        10 => format!("sqrt(abs({x}))"),
        11 => format!("sign({x}) * {y}"),
        12 => format!("min({x}, {y})"),
        13 => format!("max({x}, {y})"),
        14 => format!("pow(abs({x}) + 0.1, e)"),
        15 => format!("pow(abs({x}) + 0.1, {y})"),
        16 => format!("({x})^3"),
        17 => format!("({x})^-2"),
        18 => format!("if({x} < {y}, {x}, -{y})"),
        19 => format!("if({x} >= {y} and not ({x} == {y}) or {y} != 0.5, {y}, {x})"),
        20 => format!("(({x}) * ({x}) + ({y}) * ({x}) - ({y}) * ({y}))"),
        _ => format!("tan({x} * 0.1)"),
    }
}

/// Seeded random files of deep expressions, whose tapes keep more values alive than there
/// are registers (the generated code's allocation spills and reloads): each route's f,
/// Jacobian columns, sensitivity rates and sub-steps equal the tape's to the bit.
#[test]
fn native_code_equals_the_tape_on_random_expressions() {
    let mut points = Points(0x9e37_79b9_7f4a_7c15);
    for case in 0..12 {
        let (fa, fb) = (
            random_expression(&mut points, 4),
            random_expression(&mut points, 4),
        );
        let text = format!(
            "[model]\nstates = [\"a\", \"b\"]\ninputs = [\"u\", \"w\"]\noutputs = [\"y\"]\n\
             [parameters]\nk = 1.5\nm = -0.75\nn = 3.0\ne = 1.0\n\
             [equations]\na = \"{fa}\"\nb = \"{fb}\"\n[output]\ny = \"a\"\n"
        );
        let m = EquationModel::parse(&text).unwrap_or_else(|e| panic!("{e:?}\n{text}"));
        for backend in backends() {
            check_model(&m, &[0, 1, 2, 3], 6, 100 + case, backend);
        }
    }
}
