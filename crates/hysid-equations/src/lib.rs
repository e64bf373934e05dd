//! # hysid-equations: grey-box state-space models written as equations
//!
//! A model is a small TOML file. It is parsed once into a shared expression graph,
//! simplified, differentiated symbolically with respect to every state, parameter and
//! input, and compiled into flat instruction tapes, so that one pass computes
//!
//! ```text
//! ẋ = f(t, x, u, θ)          (or x[k+1] = f(t, x[k], u[k], θ) in discrete time)
//! y = h(x, u, θ)
//! ```
//!
//! together with ∂f/∂x, ∂f/∂θ (and ∂h/∂x, ∂h/∂θ; ∂f/∂u, ∂h/∂u on request) at compiled
//! speed and without allocation. The sensitivities are exact (up to rounding), not finite
//! differences.
//!
//! ## Example: the Duffing oscillator
//!
//! m ẍ + c ẋ + k x + k3 x³ = u (G. Duffing, *Erzwungene Schwingungen bei veränderlicher
//! Eigenfrequenz*, 1918):
//!
//! ```
//! use hysid_equations::EquationModel;
//!
//! let model = EquationModel::parse(r#"
//! [model]
//! name = "duffing"
//! states = ["x", "v"]
//! inputs = ["u"]
//! outputs = ["y"]
//! units = { x = "m", v = "m/s", u = "N", y = "m" }
//!
//! [parameters]
//! m  = { value = 1.0, lower = 0.0, unit = "kg" }
//! c  = { value = 0.1, lower = 0.0, unit = "N s/m" }
//! k  = { value = 1.0, unit = "N/m" }
//! k3 = { value = 0.0, unit = "N/m^3", fixed = false, upper = 1e6 }
//!
//! [initial]
//! x = { value = 0.0, fixed = true }
//! v = { value = 0.0, fixed = true }
//!
//! [let]
//! spring = "k*x + k3*x^3"
//!
//! [equations]
//! x = "v"
//! v = "(u - c*v - spring) / m"
//!
//! [output]
//! y = "x"
//! "#).unwrap();
//!
//! let theta = [2.0, 0.5, 3.0, 4.0]; // m, c, k, k3
//! let (x, u) = ([0.5, 1.0], [1.0]);
//! let (mut dx, mut fx, mut ft) = ([0.0; 2], [0.0; 4], [0.0; 8]);
//! model.rhs_jacobians(0.0, &x, &u, &theta, &mut dx, &mut fx, &mut ft);
//! assert_eq!(dx, [1.0, (1.0 - 0.5 - 1.5 - 0.5) / 2.0]);
//! assert_eq!(fx, [0.0, 1.0, -(3.0 + 3.0 * 4.0 * 0.25) / 2.0, -0.5 / 2.0]); // ∂f/∂x
//! assert_eq!(ft[4..], [0.375, -0.5, -0.25, -0.0625]); // ∂v̇/∂(m, c, k, k3)
//!
//! let err = EquationModel::parse("[model]\nstates = [\"x\"]\noutputs = [\"y\"]\n\
//!     [equations]\nx = \"-kk*x\"\n[output]\ny = \"x\"").unwrap_err();
//! assert_eq!(err.to_string(), "line 5, column 7: unknown name 'kk' (states: x)");
//! ```
//!
//! ## The file
//!
//! | table | key | meaning |
//! | --- | --- | --- |
//! | `[model]` | `name` | model name (string; default `"model"`) |
//! | | `states` | state names, the order of x (at least one) |
//! | | `inputs` | input names, the order of u (may be empty or absent) |
//! | | `outputs` | output names, the order of y (at least one) |
//! | | `time` | `"continuous"` (default): `[equations]` give dx/dt; `"discrete"`: they give `x[k+1]` from `x[k]`, `u[k]` |
//! | | `units` | optional table `name = "unit"` for states, inputs and outputs |
//! | `[parameters]` | `name = { … }` | `value` (required, finite), `lower` (default −∞), `upper` (default +∞), `unit` (default none), `fixed` (default false); `name = 1.5` is short for `{ value = 1.5 }`. The order of the file is the order of θ. |
//! | `[initial]` | `state = { … }` | optional: `value` (finite), `fixed` (default true: known; false: to be estimated); `x = 0.5` is short for `{ value = 0.5 }`. A state not listed starts at 0, fixed. |
//! | `[let]` | `name = "expr"` | optional named intermediate quantities, evaluated in file order; each may use the ones before it (not itself, not later ones) |
//! | `[equations]` | `state = "expr"` | exactly one per state |
//! | `[output]` | `output = "expr"` | exactly one per listed output |
//!
//! Names (states, inputs, parameters, `[let]` quantities) are identifiers (a letter or `_`,
//! then letters, digits or `_`), distinct, and not reserved: `t`, `pi`, `and`, `or`, `not`
//! and the function names are reserved. Outputs have their own name space, so an output
//! may be called like the state it measures (`y = "y"`). An expression may also be
//! written as a bare TOML number (`x = 0`).
//!
//! **Discrete time.** With `time = "discrete"` the entry `x = "…"` of `[equations]` is
//! x\[k+1\] as a function of x\[k\], u\[k\], θ and t = t_k; the Jacobians are those of
//! this map, so hysid propagates sensitivities by the chain rule
//! S\[k+1\] = (∂f/∂x)·S\[k\] + ∂f/∂θ. A value used by several next states (a "new" value
//! within the step) is written once in `[let]`:
//!
//! ```
//! let model = hysid_equations::EquationModel::parse(r#"
//! [model]
//! time = "discrete"
//! states = ["z", "x"]
//! inputs = ["u"]
//! outputs = ["y"]
//! [parameters]
//! r = 0.2
//! a = 0.9
//! b = 0.1
//! [let]
//! played = "max(u - r, min(u + r, z))"
//! [equations]
//! z = "played"
//! x = "a*x + b*played"
//! [output]
//! y = "x"
//! "#).unwrap();
//! let mut next = [0.0; 2];
//! model.rhs(0.0, &[0.0, 1.0], &[1.0], &[0.2, 0.9, 0.1], &mut next);
//! assert_eq!(next, [0.8, 0.9 + 0.1 * 0.8]); // the play is dragged up to u − r
//! ```
//!
//! **Time.** `t` may appear in `[let]` and `[equations]`. It is refused in `[output]`
//! (directly or through a `[let]` quantity that uses it): outputs are h(x, u, θ), as in
//! hysid's state-space models, so [`EquationModel::output`] takes no time.
//!
//! ## Expressions
//!
//! ```text
//! expr    := and ("or" and)*
//! and     := not ("and" not)*
//! not     := "not" not | compare
//! compare := sum (("<" | "<=" | ">" | ">=" | "==" | "!=") sum)?
//! sum     := product (("+" | "-") product)*
//! product := unary (("*" | "/") unary)*
//! unary   := ("-" | "+") unary | power
//! power   := atom ("^" unary)?
//! atom    := number | name | function "(" expr ("," expr)* ")" | "(" expr ")"
//! ```
//!
//! * `^` is right-associative (`a^b^c = a^(b^c)`) and binds tighter than a unary sign:
//!   `-x^2 = -(x^2)`, `2^-x = 2^(-x)`.
//! * Numbers are decimal with an optional exponent: `2`, `0.5`, `.5`, `5.`, `1.5e-3`,
//!   `2E+4`. Anything else starting with a digit (`1.2.3`, `2x`, `1e`) is a bad number;
//!   one outside the range of f64 (`1e999`) is refused as non-finite.
//! * `pi` is π.
//! * Comparisons (`< <= > >= == !=`) and `and`, `or`, `not` make *conditions*, which are
//!   allowed only as the first argument of `if` and as operands of `and`/`or`/`not`; a
//!   number is never a condition. Comparisons do not chain (`a < b < c` is refused).
//! * Nesting deeper than 200 levels, or a syntax tree taller than 1000 (e.g. a sum of
//!   1000 terms), is refused: split the expression with `[let]`.
//!
//! | function | value | derivative used |
//! | --- | --- | --- |
//! | `sin(x)` `cos(x)` `tan(x)` | as usual | cos x, −sin x, 1 + tan²x |
//! | `exp(x)` | eˣ | eˣ |
//! | `ln(x)` | natural log | 1/x; **0 at x = 0** |
//! | `sqrt(x)` | √x | 1/(2√x); **0 at x = 0** |
//! | `abs(x)` | \|x\| | sign x; **0 at x = 0** |
//! | `sign(x)` | −1, 0 (at 0), 1 | **0 everywhere** |
//! | `tanh(x)` `atan(x)` | as usual | 1 − tanh²x, 1/(1 + x²) |
//! | `min(a, b)` `max(a, b)` | the smaller / larger; **ties: a** | that of the selected argument |
//! | `pow(a, b)`, `a^b` | a^b | b·a^(b−1)·a′ + a^b·ln a·b′ (see below) |
//! | `if(c, a, b)` | a where c holds, else b | that of the selected branch |
//!
//! **Integer powers.** `a^n` and `pow(a, n)` with an exponent that folds to an integer
//! constant |n| ≤ 64 are computed by multiplication (`x^2 = x·x`, `x^3 = x·x·x`, negative
//! n as 1/xⁿ), not by `powf`; `x^1` is `x` and `x^0` is 1. Their derivative is n·xⁿ⁻¹.
//!
//! ## Differentiation conventions
//!
//! Derivatives are symbolic (forward accumulation over the expression graph), with these
//! conventions wherever the derivative does not exist or is infinite, so that a finite
//! simulation never yields NaN sensitivities:
//!
//! * sign′(x) = 0; abs′(x) = sign(x), hence abs′(0) = 0.
//! * min, max and if differentiate the argument they select (ties of min/max: the first).
//! * A derivative *factor* that is infinite or NaN is taken as 0: √ at 0, ln at 0, a^b at
//!   a = 0 with b < 1 (e.g. `x^0.5` at 0), and ∂a^b/∂b = a^b·ln a at a ≤ 0 (where ln a is
//!   undefined; for a < 0 only integer b give a real a^b anyway). The factor b·a^(b−1) at
//!   a = 0, b = 1 is 1 (0⁰ = 1).
//! * Last, any Jacobian entry that still comes out infinite or NaN is reported as 0: a
//!   chain of finite factors can still meet ∞·0, as in `exp(-1/x^2)` at x = 0, whose value
//!   is 0 and whose derivative is 0. Values are never altered this way.
//! * Consequence worth knowing: `sign(z)*abs(z)^nu` (the Bouc–Wen |z|^(ν−1)z) has
//!   derivative 0 in z at exactly z = 0, a set of measure zero.
//!
//! Values keep IEEE semantics: `ln` of a negative number or `sqrt(-1)` evaluated at run
//! time give NaN, as in Rust. Constant subexpressions are folded when the file is read
//! and a non-finite constant (`ln(0)`, `sqrt(-1)`, `1e308*10`) is refused there.
//!
//! ## Simplification and compilation
//!
//! The graph is hash-consed: one node per distinct operation on distinct operands
//! (commutative operands in canonical order, so `x*y` and `y*x` are one node), so common
//! subexpressions — also between f, its derivatives and h — are computed once. It is
//! simplified as it is built: constants are folded, and `x+0`, `x−0`, `0−x`, `x−x`,
//! `x·0`, `x·1`, `x·(−1)`, `x/1`, `0/x`, `−(−x)`, `1^x`, `min(x, x)`, `if` with a constant
//! condition or equal branches reduce. Six tapes are compiled from it (f; f with
//! ∂f/∂x, ∂f/∂θ; f with ∂f/∂u; the same three for h), each only the instructions its
//! results need, over one register file. Evaluation writes registers only: it never
//! allocates, neither with a caller-owned [`Scratch`] (`*_with` methods) nor with the
//! per-thread scratch the plain `&self` methods use (grown once per thread).
//!
//! A simulation holds θ fixed, so it can bind it ([`EquationModel::bind_columns`],
//! [`EquationModel::bind_rhs`], giving a [`BoundColumns`]): the tape is partially evaluated
//! with θ known — every instruction reading only parameters and constants is computed once,
//! the exact identities x·1 = x, x·(−1) = −x, x/1 = x, pow(x, 1) = x, pow(x, 0) = 1 and
//! `if` with a known condition apply — then each product read once is fused with the
//! addition, subtraction, product or negation reading it (superinstructions). The bound
//! tape computes the unbound tape's values to the bit, with about half the instructions
//! for Bouc–Wen at ν = 1, over a register file of 256 entries read without bounds checks.
//!
//! ## Errors
//!
//! Every problem is one [`EquationError`], displayed on one line as
//! `line L, column C: message`, pointing into the file (inside expression strings too):
//! TOML syntax; unknown table or key; a missing `[model]`, `[equations]` or `[output]`;
//! a name that is not an identifier, reserved or used twice; an unknown name (the message
//! lists the names that exist); an unknown function or a wrong argument count; a state
//! without an equation or an equation for a non-state; an output without an expression or
//! an expression for an output not listed; a cycle or forward reference in `[let]`; a
//! division by an expression that is identically zero after constant folding; a bad or
//! non-finite number; unbalanced parentheses; a parameter whose value is outside its
//! bounds or whose lower bound exceeds its upper bound; a condition used as a number or
//! a number as a condition; `t` in `[output]`.

pub mod ast;
mod dag;
mod error;
mod file;
mod listing;
mod lower;
mod model;
mod num;
mod tape;

pub use error::EquationError;
pub use listing::{Listing, Operand, Operation};
pub use model::{
    BoundColumns, ColumnTape, EquationModel, InitialSpec, ParameterSpec, Scratch, TimeDomain,
};
pub use num::{apply1, apply2, powi, Fn1, Fn2};
