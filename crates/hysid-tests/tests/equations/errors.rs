//! Every class of malformed file: one line, with the line and column in the file.

use hysid_equations::EquationModel;

const BASE: &str = r#"[model]
name = "duffing"
states = ["x", "v"]
inputs = ["u"]
outputs = ["y"]

[parameters]
m  = { value = 1.0, lower = 0.0 }
c  = { value = 0.1, lower = 0.0 }
k  = { value = 1.0 }
k3 = { value = 0.0, upper = 1e6 }

[let]
spring = "k*x + k3*x^3"

[equations]
x = "v"
v = "(u - c*v - spring) / m"

[output]
y = "x"
"#;

/// BASE with `from` replaced by `to` (which must occur).
fn with(from: &str, to: &str) -> String {
    assert!(BASE.contains(from), "{from}");
    BASE.replacen(from, to, 1)
}

/// The error of `text`, as displayed.
fn error(text: &str) -> String {
    let e = EquationModel::parse(text).expect_err("the file should be refused");
    let shown = e.to_string();
    assert!(!shown.contains('\n'), "one line: {shown}");
    assert_eq!(
        shown,
        format!("line {}, column {}: {}", e.line, e.column, e.message)
    );
    shown
}

fn check(text: &str, want: &str) {
    assert_eq!(error(text), want);
}

#[test]
fn the_base_file_is_valid() {
    let m = EquationModel::parse(BASE).unwrap();
    assert_eq!(m.states(), ["x", "v"]);
}

#[test]
fn unknown_name() {
    check(
        &with("spring = \"k*x", "spring = \"kk*x"),
        "line 14, column 11: unknown name 'kk' (states: x, v; inputs: u; parameters: m, c, k, k3)",
    );
    check(
        &with("(u - c*v - spring) / m", "(u - c*v - spring) / mm"),
        "line 18, column 27: unknown name 'mm' (states: x, v; inputs: u; parameters: m, c, k, k3; let: spring)",
    );
}

#[test]
fn unknown_function_and_wrong_argument_count() {
    check(
        &with("x = \"v\"", "x = \"sinh(v)\""),
        "line 17, column 6: unknown function 'sinh' (functions: sin, cos, tan, exp, ln, sqrt, abs, sign, tanh, atan, min, max, pow, if)",
    );
    check(
        &with("x = \"v\"", "x = \"max(v)\""),
        "line 17, column 6: max() takes 2 arguments, not 1",
    );
    check(
        &with("x = \"v\"", "x = \"if(v > 0, v)\""),
        "line 17, column 6: if() takes 3 arguments, not 2",
    );
}

#[test]
fn state_without_equation_and_equation_for_a_non_state() {
    check(
        &with("x = \"v\"\n", ""),
        "line 3, column 12: 'x' has no expression in [equations] (line 16); add x = \"…\"",
    );
    check(
        &with("x = \"v\"\n", "x = \"v\"\nw = \"x\"\n"),
        "line 18, column 1: [equations] has an entry for 'w', which is not a state (x, v)",
    );
}

#[test]
fn output_not_listed_or_missing() {
    check(
        &with("y = \"x\"", "y = \"x\"\nz = \"v\""),
        "line 22, column 1: [output] has an entry for 'z', which is not a listed output (y)",
    );
    check(
        &with("outputs = [\"y\"]", "outputs = [\"y\", \"speed\"]"),
        "line 5, column 18: 'speed' has no expression in [output] (line 20); add speed = \"…\"",
    );
}

#[test]
fn cycle_and_forward_reference_in_let() {
    check(
        &with("spring = \"k*x + k3*x^3\"", "spring = \"k*x + spring\""),
        "line 14, column 17: cycle in [let]: 'spring' is defined in terms of itself",
    );
    check(
        &with("spring = \"k*x + k3*x^3\"", "spring = \"k*x + cubic\"\ncubic = \"k3*x^3\""),
        "line 14, column 17: forward reference in [let]: 'cubic' is defined later (line 15); [let] quantities may use only earlier ones",
    );
}

#[test]
fn division_by_an_identically_zero_expression() {
    check(
        &with("/ m\"", "/ (m - m)\""),
        "line 18, column 25: division by an expression that is identically zero (after constant folding)",
    );
    check(
        &with("x = \"v\"", "x = \"v / (2*0.5 - 1)\""),
        "line 17, column 8: division by an expression that is identically zero (after constant folding)",
    );
}

#[test]
fn bad_numbers_and_non_finite_numbers() {
    check(
        &with("x = \"v\"", "x = \"1.2.3*v\""),
        "line 17, column 6: bad number '1.2.3' (write e.g. 2, 0.5, 1.5e-3)",
    );
    check(
        &with("x = \"v\"", "x = \"v + 1e999\""),
        "line 17, column 10: non-finite number '1e999' (outside the range of f64)",
    );
    check(
        &with("k  = { value = 1.0 }", "k  = { value = nan }"),
        "line 10, column 16: non-finite number NaN for the value of parameter 'k'",
    );
    check(
        &with("k  = { value = 1.0 }", "k  = { value = inf }"),
        "line 10, column 16: non-finite number inf for the value of parameter 'k'",
    );
    check(
        &with("x = \"v\"", "x = \"ln(0) * v\""),
        "line 17, column 6: this expression is the non-finite constant -inf (e.g. ln(0), sqrt(-1), 1/0 after folding)",
    );
}

#[test]
fn unbalanced_parentheses() {
    check(
        &with("x = \"v\"", "x = \"(v + 1\""),
        "line 17, column 6: unbalanced parentheses: this '(' is never closed",
    );
    check(
        &with("x = \"v\"", "x = \"v + 1)\""),
        "line 17, column 11: unbalanced parentheses: ')' without a matching '('",
    );
}

#[test]
fn parameter_bounds() {
    check(
        &with(
            "c  = { value = 0.1, lower = 0.0 }",
            "c  = { value = -0.1, lower = 0.0 }",
        ),
        "line 9, column 16: parameter 'c': value -0.1 is outside its bounds [0, inf]",
    );
    check(
        &with("k3 = { value = 0.0, upper = 1e6 }", "k3 = { value = 0.0, lower = 2.0, upper = 1.0 }"),
        "line 11, column 42: parameter 'k3': lower bound 2 exceeds upper bound 1 (or a bound is infinite on the wrong side)",
    );
}

#[test]
fn duplicate_names() {
    check(
        &with("states = [\"x\", \"v\"]", "states = [\"x\", \"x\"]"),
        "line 3, column 17: duplicate name 'x' (already a state)",
    );
    check(
        &with("k  = { value = 1.0 }", "u  = { value = 1.0 }"),
        "line 10, column 1: duplicate name 'u' (already an input)",
    );
    check(
        &with("spring = \"k*x + k3*x^3\"", "m = \"k*x\""),
        "line 14, column 1: duplicate name 'm' (already a parameter)",
    );
}

#[test]
fn reserved_words_and_invalid_names() {
    check(
        &with("inputs = [\"u\"]", "inputs = [\"sin\"]"),
        "line 4, column 12: 'sin' is a reserved word (t, pi, and, or, not and the function names); rename it",
    );
    check(
        &with("k  = { value = 1.0 }", "t  = { value = 1.0 }"),
        "line 10, column 1: 't' is a reserved word (t, pi, and, or, not and the function names); rename it",
    );
    check(
        &with("inputs = [\"u\"]", "inputs = [\"2u\"]"),
        "line 4, column 12: '2u' is not a valid name (a letter or _, then letters, digits or _)",
    );
}

#[test]
fn time_in_output_is_refused() {
    check(
        &with("y = \"x\"", "y = \"x*t\""),
        "line 21, column 8: the time t is not allowed in [output]: outputs are functions of states, inputs and parameters",
    );
    check(
        &with("spring = \"k*x + k3*x^3\"", "spring = \"k*x*t\"")
            .replace("y = \"x\"", "y = \"spring\""),
        "line 21, column 6: 'spring' depends on the time t, which [output] cannot use",
    );
}

#[test]
fn conditions_and_numbers_do_not_mix() {
    check(
        &with("x = \"v\"", "x = \"v > 0\""),
        "line 17, column 8: a condition is used as a number; conditions (comparisons, and, or, not) go into if(condition, a, b)",
    );
    check(
        &with("x = \"v\"", "x = \"if(v, 1, 0)\""),
        "line 17, column 9: a number is used as a condition; compare it, e.g. 'x > 0' or 'x != 0'",
    );
}

#[test]
fn structure_errors() {
    check(
        &with("name = \"duffing\"", "name = \"duffing\"\ncolour = \"red\""),
        "line 3, column 1: unknown key 'colour' in [model] (allowed: name, states, inputs, outputs, time, units)",
    );
    check(
        &with("k  = { value = 1.0 }", "k  = { value = 1.0, lowr = 0.0 }"),
        "line 10, column 21: unknown key 'lowr' in [parameters] k (allowed: value, lower, upper, unit, fixed)",
    );
    check(
        &with("[let]", "[lets]"),
        "line 13, column 2: unknown key 'lets' in the file (allowed: [model], [parameters], [initial], [let], [equations], [output])",
    );
    check(
        &with("inputs = [\"u\"]", "inputs = [\"u\"]\ntime = \"hybrid\""),
        "line 5, column 8: time = \"hybrid\" is neither \"continuous\" nor \"discrete\"",
    );
    check(
        &with("x = \"v\"", "x = true"),
        "line 17, column 5: the expression for 'x' must be a string like \"k*x\", not a boolean",
    );
    check(
        &with(
            "[output]\ny = \"x\"\n",
            "[initial]\nq = 1.0\n[output]\ny = \"x\"\n",
        ),
        "line 21, column 1: initial value for 'q', which is not a state (states: x, v)",
    );
}

#[test]
fn toml_syntax_errors_are_located() {
    let e = EquationModel::parse(&with("x = \"v\"", "x = \"v")).unwrap_err();
    assert_eq!(e.line, 17);
    assert!(e.message.starts_with("TOML syntax"), "{}", e.message);
    let e = EquationModel::parse("[model\nname = 1").unwrap_err();
    assert_eq!(e.line, 1);
}

#[test]
fn columns_count_characters_and_follow_multi_line_strings() {
    // A non-ASCII comment before the expression on the same line is impossible in TOML,
    // but a non-ASCII character inside the string counts as one column.
    check(
        &with("x = \"v\"", "x = \"v + 0*u + é\""),
        "line 17, column 16: unexpected character 'é'",
    );
    check(
        &with("x = \"v\"", "x = \"\"\"\nv +\n   kk\"\"\""),
        "line 19, column 4: unknown name 'kk' (states: x, v; inputs: u; parameters: m, c, k, k3; let: spring)",
    );
}

#[test]
fn hostile_sizes_are_refused_without_overflowing_the_stack() {
    // Deep TOML nesting, deep expression nesting, long [let] chains.
    for text in [
        format!("a = {}", "[".repeat(50_000)),
        format!("a = {}", "{ b = ".repeat(50_000)),
        with(
            "x = \"v\"",
            &format!("x = \"{}v{}\"", "(".repeat(10_000), ")".repeat(10_000)),
        ),
        with("x = \"v\"", &format!("x = \"{}v\"", "-".repeat(10_000))),
        with(
            "x = \"v\"",
            &format!("x = \"{}\"", vec!["v"; 20_000].join("+")),
        ),
    ] {
        assert!(EquationModel::parse(&text).is_err());
    }
    // A chain of 2000 [let] quantities, each using the previous one, is fine: the graph
    // is walked in loops, not recursively.
    let mut lets = String::from("l0 = \"x\"\n");
    for k in 1..2000 {
        lets.push_str(&format!("l{k} = \"0.5*l{} + v\"\n", k - 1));
    }
    let text = with(
        "spring = \"k*x + k3*x^3\"\n",
        &format!("spring = \"k*x + k3*x^3\"\n{lets}"),
    )
    .replace("x = \"v\"", "x = \"l1999\"");
    let m = EquationModel::parse(&text).unwrap();
    let (mut dx, mut fx, mut ft) = ([0.0; 2], [0.0; 4], [0.0; 8]);
    m.rhs_jacobians(
        0.0,
        &[1.0, 0.0],
        &[0.0],
        &[1.0, 0.1, 1.0, 0.0],
        &mut dx,
        &mut fx,
        &mut ft,
    );
    // l_k = 0.5^k x at v = 0, ∂/∂v = Σ 0.5^j ≈ 2.
    assert!(dx[0].abs() < 1e-300);
    approx::assert_relative_eq!(fx[1], 2.0, max_relative = 1e-12);
}
