//! The compiled model: specifications, and f, h with their Jacobians on flat tapes.

use std::cell::RefCell;
use std::collections::HashMap;
use std::fmt;

use crate::ast;
use crate::dag::{Graph, Id};
use crate::error::{line_column, EquationError};
use crate::file::{self, ExprText, FileModel, Named};
use crate::listing::{self, Listing};
use crate::lower::{lower, Binding, Scope};
use crate::num::finite_or_zero;
use crate::tape::{Tape, SMALL};

/// Whether `[equations]` give derivatives or next states.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimeDomain {
    /// ẋ = f(t, x, u, θ) (`time = "continuous"`, the default).
    Continuous,
    /// `x[k+1] = f(t, x[k], u[k], θ)` (`time = "discrete"`).
    Discrete,
}

/// A parameter as the file declares it.
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterSpec {
    /// Name in expressions.
    pub name: String,
    /// Initial (or fixed) value.
    pub value: f64,
    /// Lower bound (−∞ when not given).
    pub lower: f64,
    /// Upper bound (+∞ when not given).
    pub upper: f64,
    /// Unit (free text, empty when not given).
    pub unit: String,
    /// Whether the value is held fixed during estimation (default false).
    pub fixed: bool,
}

/// The initial value of a state as the file declares it (0, fixed, when not given).
#[derive(Clone, Debug, PartialEq)]
pub struct InitialSpec {
    /// State name.
    pub state: String,
    /// Value at the first sample.
    pub value: f64,
    /// Whether it is known (true, the default) or to be estimated (false).
    pub fixed: bool,
}

/// The six tapes of a model.
#[derive(Clone, Debug)]
struct Tapes {
    /// f
    f: Tape,
    /// f, ∂f/∂x, ∂f/∂θ
    f_jac: Tape,
    /// f, ∂f/∂u
    f_u: Tape,
    /// h
    h: Tape,
    /// h, ∂h/∂x, ∂h/∂θ
    h_jac: Tape,
    /// h, ∂h/∂u
    h_u: Tape,
}

/// A grey-box state-space model read from an equation file (the language is described
/// in the crate docs):
///
/// ```text
/// ẋ = f(t, x, u, θ)   (or x[k+1] = f(t, x[k], u[k], θ) for time = "discrete")
/// y = h(x, u, θ)
/// ```
///
/// Parsed and differentiated once; f, h and their Jacobians are then evaluated from flat
/// instruction tapes without allocating (with a caller-owned [`Scratch`], or with a
/// per-thread one by the plain methods).
#[derive(Clone)]
pub struct EquationModel {
    source: String,
    name: String,
    time: TimeDomain,
    states: Vec<String>,
    inputs: Vec<String>,
    outputs: Vec<String>,
    units: Vec<(String, String)>,
    parameters: Vec<ParameterSpec>,
    initial: Vec<InitialSpec>,
    tapes: Tapes,
    registers: usize,
    /// h when its tape computes nothing (see [`DirectOutput`]).
    direct_output: Option<DirectOutput>,
}

/// h of a model whose outputs are states, inputs, parameters or constants (y = x₀, say):
/// its tape has no instruction, so y is read where it is and the Jacobians ∂h/∂x and
/// ∂h/∂θ, derivatives of plain reads, are constants computed once — per sample, an output
/// costs a few loads instead of a pass over a register file.
#[derive(Clone, Debug)]
struct DirectOutput {
    /// The input slot (t, x, u, θ) or constant of each output.
    y: Vec<Read>,
    /// ∂h/∂x, ny×n row-major.
    hx: Vec<f64>,
    /// ∂h/∂θ, ny×p row-major.
    htheta: Vec<f64>,
}

/// Where a direct output reads its value.
#[derive(Clone, Copy, Debug)]
enum Read {
    State(usize),
    Input(usize),
    Parameter(usize),
    Constant(f64),
}

impl DirectOutput {
    /// The direct form of h (tape `h`, with its Jacobians `h_jac`), None when either tape
    /// computes something.
    fn of(h: &Tape, h_jac: &Tape, n: usize, m: usize, p: usize) -> Option<Self> {
        let (inputs, consts, code) = h.parts();
        let (jac_inputs, jac_consts, jac_code) = h_jac.parts();
        if !code.is_empty() || !jac_code.is_empty() {
            return None;
        }
        let read = |r: u32| -> Option<Read> {
            let r = r as usize;
            Some(match r {
                // An output never reads t (the language refuses it in [output]).
                0 => return None,
                _ if r <= n => Read::State(r - 1),
                _ if r <= n + m => Read::Input(r - 1 - n),
                _ if r < inputs => Read::Parameter(r - 1 - n - m),
                _ => Read::Constant(consts[r - inputs]),
            })
        };
        let y = h
            .outputs()
            .iter()
            .map(|&r| read(r))
            .collect::<Option<Vec<_>>>()?;
        // The Jacobian results: constants of the h_jac tape (a derivative of a plain read
        // is 0 or 1), finite by convention.
        let constant = |r: u32| -> Option<f64> {
            let r = r as usize;
            (r >= jac_inputs).then(|| finite_or_zero(jac_consts[r - jac_inputs]))
        };
        let ny = y.len();
        let derivatives = h_jac.outputs()[ny..]
            .iter()
            .map(|&r| constant(r))
            .collect::<Option<Vec<_>>>()?;
        let (hx, htheta) = derivatives.split_at(ny * n);
        (htheta.len() == ny * p).then(|| Self {
            y,
            hx: hx.to_vec(),
            htheta: htheta.to_vec(),
        })
    }

    #[inline]
    fn output(&self, x: &[f64], u: &[f64], theta: &[f64], y: &mut [f64]) {
        for (o, read) in y.iter_mut().zip(&self.y) {
            *o = match *read {
                Read::State(i) => x[i],
                Read::Input(i) => u[i],
                Read::Parameter(i) => theta[i],
                Read::Constant(v) => v,
            };
        }
    }
}

impl fmt::Debug for EquationModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("EquationModel")
            .field("name", &self.name)
            .field("time", &self.time)
            .field("states", &self.states)
            .field("inputs", &self.inputs)
            .field("outputs", &self.outputs)
            .field(
                "parameters",
                &self.parameters.iter().map(|p| &p.name).collect::<Vec<_>>(),
            )
            .field("tape_lengths", &self.tape_lengths())
            .finish()
    }
}

/// Registers for evaluating a model without allocation; one per thread or caller.
///
/// Grows on first use with a model that needs more registers, then never allocates again.
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    regs: Vec<f64>,
}

impl Scratch {
    /// An empty scratch (it grows to the size a model needs on first use).
    pub fn new() -> Self {
        Self::default()
    }

    fn regs(&mut self, n: usize) -> &mut [f64] {
        if self.regs.len() < n {
            self.regs.resize(n, 0.0);
        }
        &mut self.regs[..n]
    }
}

/// The tape of f, ∂f/∂x and the columns ∂f/∂θ\[params\] only, for the parameters a fit
/// estimates ([`EquationModel::rhs_jacobian_columns`]): the derivatives with respect to the
/// other parameters, and everything only they read, are not computed.
#[derive(Clone, Debug)]
pub struct ColumnTape {
    params: Vec<usize>,
    tape: Tape,
}

impl ColumnTape {
    /// The parameter indices of the ∂f/∂θ columns, in order.
    pub fn params(&self) -> &[usize] {
        &self.params
    }

    /// Number of instructions.
    pub fn len(&self) -> usize {
        self.tape.len()
    }

    /// True for a tape without instructions (f and its Jacobians are all inputs or
    /// constants).
    pub fn is_empty(&self) -> bool {
        self.tape.len() == 0
    }
}

/// A [`ColumnTape`] (or the tape of f) specialised to one parameter vector θ, for a
/// simulation that holds θ fixed ([`EquationModel::bind_columns`],
/// [`EquationModel::bind_rhs`]): what depends on θ alone is computed once, and the rest runs
/// over a register file of its own, from (t, x, u).
#[derive(Clone, Debug)]
pub struct BoundColumns {
    tape: Tape,
    regs: Box<[f64; SMALL]>,
    states: usize,
    inputs: usize,
    /// Where [`Self::eval`] writes each result (the layout of [`Self::eval`] unless
    /// [`Self::place`] moved them).
    positions: Vec<usize>,
    /// The values of f that depend on (t, x, u): (position, register).
    values: Vec<(usize, u8)>,
    /// The derivatives that depend on (t, x, u): (position, register).
    derivatives: Vec<(usize, u8)>,
}

impl BoundColumns {
    /// None when the tape needs more than [`SMALL`] registers.
    fn new(tape: Tape, states: usize, inputs: usize) -> Option<Self> {
        if tape.registers() > SMALL {
            return None;
        }
        let mut regs = Box::new([0.0; SMALL]);
        tape.load_constants(&mut regs[..]);
        let mut bound = Self {
            positions: (0..tape.outputs().len()).collect(),
            tape,
            regs,
            states,
            inputs,
            values: Vec::new(),
            derivatives: Vec::new(),
        };
        bound.place(|k| k);
        Some(bound)
    }

    /// Makes [`Self::eval`] write result k (in the layout [`Self::eval`] describes) at
    /// `position(k)` of its output instead, e.g. ∂f/∂θ rows padded to a wider stride.
    pub fn place(&mut self, position: impl Fn(usize) -> usize) {
        self.positions = (0..self.tape.outputs().len()).map(position).collect();
        let varying = (0..self.positions.len()).filter(|&k| self.tape.constant_result(k).is_none());
        let (values, derivatives): (Vec<usize>, Vec<usize>) =
            varying.partition(|&k| k < self.states);
        // Registers fit a byte: checked in `new`.
        let at = |k: usize| (self.positions[k], self.tape.outputs()[k] as u8);
        self.values = values.into_iter().map(at).collect();
        self.derivatives = derivatives.into_iter().map(at).collect();
    }

    /// Number of instructions run per evaluation.
    pub fn len(&self) -> usize {
        self.tape.len()
    }

    /// True when no instruction is left (the results are constants or inputs).
    pub fn is_empty(&self) -> bool {
        self.tape.len() == 0
    }

    /// Number of results: n + n² + n·k for columns, n for f.
    pub fn results(&self) -> usize {
        self.tape.outputs().len()
    }

    /// Whether a result reads the time t.
    pub fn uses_time(&self) -> bool {
        self.tape.reads(0)
    }

    /// The value of result `k` (layout of [`Self::eval`]) when it does not depend on
    /// (t, x, u): a Jacobian entry that is zero for this θ, say. Derivatives are reported
    /// finite as [`Self::eval`] reports them.
    pub fn constant(&self, k: usize) -> Option<f64> {
        let v = self.tape.constant_result(k)?;
        Some(if k < self.states {
            v
        } else {
            finite_or_zero(v)
        })
    }

    /// Writes the results that do not depend on (t, x, u) at their positions in `out`
    /// ([`Self::eval`] leaves them alone): once per buffer.
    pub fn fill_constants(&self, out: &mut [f64]) {
        for (k, &p) in self.positions.iter().enumerate() {
            if let Some(v) = self.constant(k) {
                out[p] = v;
            }
        }
    }

    /// The results at (t, x, u) into `out` — f, then (for columns) ∂f/∂x (n×n row-major)
    /// and the bound columns of ∂f/∂θ (n×k row-major), or where [`Self::place`] put them —
    /// writing only the entries that depend on (t, x, u) (the others:
    /// [`Self::fill_constants`]), with the values of
    /// [`EquationModel::rhs_jacobian_columns_with`] (or [`EquationModel::rhs_with`]) at the
    /// bound θ, to the bit.
    ///
    /// # Panics
    /// If x or u are shorter than the model's lengths, or `out` than the positions.
    #[inline]
    pub fn eval(&mut self, t: f64, x: &[f64], u: &[f64], out: &mut [f64]) {
        let (n, m) = (self.states, self.inputs);
        let regs = &mut *self.regs;
        regs[0] = t;
        regs[1..1 + n].copy_from_slice(x);
        regs[1 + n..1 + n + m].copy_from_slice(u);
        self.run(out);
    }

    /// [`Self::eval`] for a state of N entries known at compile time: x and u reach the
    /// registers as single moves (a `copy_from_slice` of a few entries of run-time length
    /// is a library call, which costs as much as several instructions of the tape).
    ///
    /// # Panics
    /// If N is not the number of states, or u or `out` are too short.
    #[inline]
    pub fn eval_fixed<const N: usize>(&mut self, t: f64, x: &[f64; N], u: &[f64], out: &mut [f64]) {
        assert_eq!(N, self.states, "states");
        let regs = &mut *self.regs;
        regs[0] = t;
        for (i, &v) in x.iter().enumerate() {
            regs[1 + i] = v;
        }
        match u {
            [u0] if self.inputs == 1 => regs[1 + N] = *u0,
            _ => regs[1 + N..1 + N + self.inputs].copy_from_slice(&u[..self.inputs]),
        }
        self.run(out);
    }

    /// Runs the code over the loaded registers and writes the varying results.
    #[inline(always)]
    fn run(&mut self, out: &mut [f64]) {
        let regs = &mut *self.regs;
        self.tape.run_code_small(regs);
        for &(k, r) in &self.values {
            out[k] = regs[usize::from(r)];
        }
        for &(k, r) in &self.derivatives {
            // Derivatives finite by convention (see the crate docs).
            out[k] = finite_or_zero(regs[usize::from(r)]);
        }
    }
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = const { RefCell::new(Scratch { regs: Vec::new() }) };
}

impl EquationModel {
    /// Reads, checks, differentiates and compiles a model file.
    ///
    /// Every problem is an [`EquationError`] with the line and column in `text`.
    pub fn parse(text: &str) -> Result<Self, EquationError> {
        let fm = file::read(text)?;
        compile(text, fm)
    }

    /// The file text the model was parsed from (saved models embed it).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// `[model] name`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// State names in order (the order of x).
    pub fn states(&self) -> &[String] {
        &self.states
    }

    /// Input names in order (the order of u).
    pub fn inputs(&self) -> &[String] {
        &self.inputs
    }

    /// Output names in order (the order of y).
    pub fn outputs(&self) -> &[String] {
        &self.outputs
    }

    /// `[model] units`: (state, input or output name, unit) in file order.
    pub fn units(&self) -> &[(String, String)] {
        &self.units
    }

    /// The unit of a state, input, output or parameter, if the file gives one.
    pub fn unit(&self, name: &str) -> Option<&str> {
        self.units
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, u)| u.as_str())
            .or_else(|| {
                self.parameters
                    .iter()
                    .find(|p| p.name == name && !p.unit.is_empty())
                    .map(|p| p.unit.as_str())
            })
    }

    /// Parameters in file order (the order of θ).
    pub fn parameters(&self) -> &[ParameterSpec] {
        &self.parameters
    }

    /// θ at the declared values.
    pub fn parameter_values(&self) -> Vec<f64> {
        self.parameters.iter().map(|p| p.value).collect()
    }

    /// Initial values, one per state in state order.
    pub fn initial(&self) -> &[InitialSpec] {
        &self.initial
    }

    /// Continuous or discrete time.
    pub fn time_domain(&self) -> TimeDomain {
        self.time
    }

    /// Instruction counts of the tapes (f, f+∂f/∂x+∂f/∂θ, f+∂f/∂u, h, h+∂h/∂x+∂h/∂θ,
    /// h+∂h/∂u).
    pub fn tape_lengths(&self) -> [usize; 6] {
        let t = &self.tapes;
        [
            t.f.len(),
            t.f_jac.len(),
            t.f_u.len(),
            t.h.len(),
            t.h_jac.len(),
            t.h_u.len(),
        ]
    }

    /// A scratch already sized for this model.
    pub fn scratch(&self) -> Scratch {
        Scratch {
            regs: vec![0.0; self.registers],
        }
    }

    /// Runs `tape` at (t, x, u, θ) and copies the results to `out`: the values first, then
    /// the Jacobian blocks (with an infinite or NaN entry reported as 0).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn eval(
        &self,
        s: &mut Scratch,
        tape: &Tape,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        out: &mut [&mut [f64]],
    ) {
        let (n, m, p) = (self.states.len(), self.inputs.len(), self.parameters.len());
        assert!(
            x.len() == n && u.len() == m && theta.len() == p,
            "EquationModel '{}': expected {n} states, {m} inputs, {p} parameters, got {}, {}, {}",
            self.name,
            x.len(),
            u.len(),
            theta.len()
        );
        let regs = s.regs(self.registers);
        regs[0] = t;
        regs[1..1 + n].copy_from_slice(x);
        regs[1 + n..1 + n + m].copy_from_slice(u);
        regs[1 + n + m..1 + n + m + p].copy_from_slice(theta);
        tape.run(regs);
        let mut results = tape.outputs().iter();
        for (k, dst) in out.iter_mut().enumerate() {
            for (d, r) in dst.iter_mut().zip(&mut results) {
                let v = regs[*r as usize];
                // Values as computed; derivatives finite by convention (see the crate docs).
                *d = if k == 0 { v } else { finite_or_zero(v) };
            }
        }
    }

    /// ∂h/∂x (ny×n) and ∂h/∂θ (ny×p), row-major, when they do not depend on (x, u, θ):
    /// every output is a state, an input, a parameter or a constant (y = x₀, say). None
    /// otherwise.
    pub fn constant_output_jacobians(&self) -> Option<(&[f64], &[f64])> {
        self.direct_output
            .as_ref()
            .map(|d| (d.hx.as_slice(), d.htheta.as_slice()))
    }

    /// Whether y = h(x, u, θ) may read an input: false only when every output is a state, a
    /// parameter or a constant (the outputs computed by the tape count as reading).
    pub fn output_reads_inputs(&self) -> bool {
        self.direct_output
            .as_ref()
            .is_none_or(|d| d.y.iter().any(|r| matches!(r, Read::Input(_))))
    }

    /// The lengths `eval` asserts, for the paths that do not run a tape.
    #[inline]
    fn check_point(&self, x: &[f64], u: &[f64], theta: &[f64]) {
        let (n, m, p) = (self.states.len(), self.inputs.len(), self.parameters.len());
        assert!(
            x.len() == n && u.len() == m && theta.len() == p,
            "EquationModel '{}': expected {n} states, {m} inputs, {p} parameters, got {}, {}, {}",
            self.name,
            x.len(),
            u.len(),
            theta.len()
        );
    }

    fn with_thread_scratch<R>(&self, f: impl FnOnce(&mut Scratch) -> R) -> R {
        SCRATCH.with(|cell| match cell.try_borrow_mut() {
            Ok(mut s) => f(&mut s),
            // Only reachable if evaluation were re-entered on one thread; stay correct.
            Err(_) => f(&mut self.scratch()),
        })
    }

    /// ẋ = f(t, x, u, θ) (or `x[k+1]` in discrete time) into `dx`.
    ///
    /// # Panics
    /// If x, u or θ do not have the lengths of [`Self::states`], [`Self::inputs`],
    /// [`Self::parameters`], or `dx` is shorter than x.
    pub fn rhs_with(
        &self,
        s: &mut Scratch,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        dx: &mut [f64],
    ) {
        check_len(dx, self.states.len(), "dx");
        self.eval(s, &self.tapes.f, t, x, u, theta, &mut [dx]);
    }

    /// y = h(x, u, θ) into `y` (outputs do not depend on t).
    ///
    /// # Panics
    /// As [`Self::rhs_with`], with `y` of the length of [`Self::outputs`].
    pub fn output_with(&self, s: &mut Scratch, x: &[f64], u: &[f64], theta: &[f64], y: &mut [f64]) {
        check_len(y, self.outputs.len(), "y");
        if let Some(direct) = &self.direct_output {
            self.check_point(x, u, theta);
            return direct.output(x, u, theta, y);
        }
        self.eval(s, &self.tapes.h, 0.0, x, u, theta, &mut [y]);
    }

    /// f with ∂f/∂x (n×n, row-major: `fx[i*n + j] = ∂fᵢ/∂xⱼ`) and ∂f/∂θ (n×p, row-major),
    /// from one pass over one tape.
    ///
    /// # Panics
    /// As [`Self::rhs_with`], with `fx` of n·n and `ftheta` of n·p entries.
    #[allow(clippy::too_many_arguments)]
    pub fn rhs_jacobians_with(
        &self,
        s: &mut Scratch,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        dx: &mut [f64],
        fx: &mut [f64],
        ftheta: &mut [f64],
    ) {
        let (n, p) = (self.states.len(), self.parameters.len());
        check_len(dx, n, "dx");
        check_len(fx, n * n, "fx");
        check_len(ftheta, n * p, "ftheta");
        self.eval(s, &self.tapes.f_jac, t, x, u, theta, &mut [dx, fx, ftheta]);
    }

    /// The tape computing f, ∂f/∂x and the columns `params` of ∂f/∂θ (see
    /// [`Self::rhs_jacobian_columns_with`]); None if an index is not below the number of
    /// parameters.
    pub fn rhs_jacobian_columns(&self, params: &[usize]) -> Option<ColumnTape> {
        let (n, p) = (self.states.len(), self.parameters.len());
        if params.iter().any(|&c| c >= p) {
            return None;
        }
        // Result layout of the full tape: f, then ∂f/∂x row-major, then ∂f/∂θ row-major.
        let mut keep: Vec<usize> = (0..n + n * n).collect();
        for i in 0..n {
            keep.extend(params.iter().map(|&c| n + n * n + i * p + c));
        }
        Some(ColumnTape {
            params: params.to_vec(),
            tape: self.tapes.f_jac.restrict(&keep),
        })
    }

    /// [`Self::rhs_jacobians_with`] from a [`ColumnTape`]: f, ∂f/∂x (n×n) and ∂f/∂θ for its
    /// columns only (`ftheta` n×k row-major, k = `columns.params().len()`), in one pass; the
    /// values equal the corresponding entries of [`Self::rhs_jacobians_with`].
    ///
    /// # Panics
    /// As [`Self::rhs_jacobians_with`], with `ftheta` of n·k entries.
    #[allow(clippy::too_many_arguments)]
    pub fn rhs_jacobian_columns_with(
        &self,
        s: &mut Scratch,
        columns: &ColumnTape,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        dx: &mut [f64],
        fx: &mut [f64],
        ftheta: &mut [f64],
    ) {
        let n = self.states.len();
        check_len(dx, n, "dx");
        check_len(fx, n * n, "fx");
        check_len(ftheta, n * columns.params.len(), "ftheta");
        self.eval(s, &columns.tape, t, x, u, theta, &mut [dx, fx, ftheta]);
    }

    /// The tape of `columns` with θ bound (partial evaluation on the slots of θ: what θ
    /// alone determines computed once, exact identities such as pow(x, 1) = x applied,
    /// products fused into multiply–add superinstructions), None when θ does not have the
    /// length of [`Self::parameters`] or the bound tape needs more than 256 registers.
    pub fn bind_columns(&self, columns: &ColumnTape, theta: &[f64]) -> Option<BoundColumns> {
        let (n, m) = (self.states.len(), self.inputs.len());
        if theta.len() != self.parameters.len() {
            return None;
        }
        BoundColumns::new(columns.tape.bind(1 + n + m, theta), n, m)
    }

    /// The tape of f with θ bound (see [`Self::bind_columns`]): [`BoundColumns::eval`] then
    /// writes ẋ only (n results). None as for [`Self::bind_columns`].
    pub fn bind_rhs(&self, theta: &[f64]) -> Option<BoundColumns> {
        let (n, m) = (self.states.len(), self.inputs.len());
        if theta.len() != self.parameters.len() {
            return None;
        }
        BoundColumns::new(self.tapes.f.bind(1 + n + m, theta), n, m)
    }

    /// h with ∂h/∂x (ny×n, row-major) and ∂h/∂θ (ny×p, row-major).
    ///
    /// # Panics
    /// As [`Self::rhs_with`], with `hx` of ny·n and `htheta` of ny·p entries.
    #[allow(clippy::too_many_arguments)]
    pub fn output_jacobians_with(
        &self,
        s: &mut Scratch,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        y: &mut [f64],
        hx: &mut [f64],
        htheta: &mut [f64],
    ) {
        let (ny, n, p) = (self.outputs.len(), self.states.len(), self.parameters.len());
        check_len(y, ny, "y");
        check_len(hx, ny * n, "hx");
        check_len(htheta, ny * p, "htheta");
        if let Some(direct) = &self.direct_output {
            self.check_point(x, u, theta);
            direct.output(x, u, theta, y);
            hx.copy_from_slice(&direct.hx);
            htheta.copy_from_slice(&direct.htheta);
            return;
        }
        self.eval(s, &self.tapes.h_jac, 0.0, x, u, theta, &mut [y, hx, htheta]);
    }

    /// f with ∂f/∂u (n×m, row-major).
    #[allow(clippy::too_many_arguments)]
    pub fn rhs_input_jacobian_with(
        &self,
        s: &mut Scratch,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        dx: &mut [f64],
        fu: &mut [f64],
    ) {
        check_len(dx, self.states.len(), "dx");
        check_len(fu, self.states.len() * self.inputs.len(), "fu");
        self.eval(s, &self.tapes.f_u, t, x, u, theta, &mut [dx, fu]);
    }

    /// h with ∂h/∂u (ny×m, row-major).
    pub fn output_input_jacobian_with(
        &self,
        s: &mut Scratch,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        y: &mut [f64],
        hu: &mut [f64],
    ) {
        check_len(y, self.outputs.len(), "y");
        check_len(hu, self.outputs.len() * self.inputs.len(), "hu");
        self.eval(s, &self.tapes.h_u, 0.0, x, u, theta, &mut [y, hu]);
    }

    /// [`Self::rhs_with`] with this thread's scratch.
    pub fn rhs(&self, t: f64, x: &[f64], u: &[f64], theta: &[f64], dx: &mut [f64]) {
        self.with_thread_scratch(|s| self.rhs_with(s, t, x, u, theta, dx));
    }

    /// [`Self::output_with`] with this thread's scratch (none when every output is a state,
    /// an input, a parameter or a constant: they are read, no tape runs).
    pub fn output(&self, x: &[f64], u: &[f64], theta: &[f64], y: &mut [f64]) {
        if let Some(direct) = &self.direct_output {
            check_len(y, self.outputs.len(), "y");
            self.check_point(x, u, theta);
            return direct.output(x, u, theta, y);
        }
        self.with_thread_scratch(|s| self.output_with(s, x, u, theta, y));
    }

    /// The operations that compute f (ẋ, or the next state in discrete time), in the order
    /// [`Self::rhs`] performs them, one result per state: what a code generator prints to
    /// compute f as this model does, to the bit ([`Listing`]).
    pub fn rhs_listing(&self) -> Listing {
        listing::of(&self.tapes.f, self.states.len(), self.inputs.len())
    }

    /// The operations of a [`ColumnTape`] in the order
    /// [`Self::rhs_jacobian_columns_with`] performs them, with its results in that
    /// method's layout: f (n), ∂f/∂x (n×n row-major), then ∂f/∂θ for the tape's columns
    /// (n×k row-major). A printed listing computes what the tape computes, operation for
    /// operation; the caller applies the finite-derivative convention (a derivative that is
    /// not finite is reported as 0, see the crate docs) to every result after the first n.
    pub fn columns_listing(&self, columns: &ColumnTape) -> Listing {
        listing::of(&columns.tape, self.states.len(), self.inputs.len())
    }

    /// The operations that compute h, in the order [`Self::output`] performs them, one
    /// result per output (they never read the time).
    pub fn output_listing(&self) -> Listing {
        listing::of(&self.tapes.h, self.states.len(), self.inputs.len())
    }

    /// [`Self::rhs_jacobians_with`] with this thread's scratch.
    #[allow(clippy::too_many_arguments)]
    pub fn rhs_jacobians(
        &self,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        dx: &mut [f64],
        fx: &mut [f64],
        ftheta: &mut [f64],
    ) {
        self.with_thread_scratch(|s| self.rhs_jacobians_with(s, t, x, u, theta, dx, fx, ftheta));
    }

    /// [`Self::output_jacobians_with`] with this thread's scratch.
    pub fn output_jacobians(
        &self,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        y: &mut [f64],
        hx: &mut [f64],
        htheta: &mut [f64],
    ) {
        if self.direct_output.is_some() {
            // No register file needed.
            return self.output_jacobians_with(&mut Scratch::new(), x, u, theta, y, hx, htheta);
        }
        self.with_thread_scratch(|s| self.output_jacobians_with(s, x, u, theta, y, hx, htheta));
    }

    /// [`Self::rhs_input_jacobian_with`] with this thread's scratch.
    pub fn rhs_input_jacobian(
        &self,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        dx: &mut [f64],
        fu: &mut [f64],
    ) {
        self.with_thread_scratch(|s| self.rhs_input_jacobian_with(s, t, x, u, theta, dx, fu));
    }

    /// [`Self::output_input_jacobian_with`] with this thread's scratch.
    pub fn output_input_jacobian(
        &self,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        y: &mut [f64],
        hu: &mut [f64],
    ) {
        self.with_thread_scratch(|s| self.output_input_jacobian_with(s, x, u, theta, y, hu));
    }
}

fn check_len(v: &[f64], n: usize, what: &str) {
    assert!(
        v.len() == n,
        "{what} must have {n} entries, has {}",
        v.len()
    );
}

/// Parses and lowers one expression of the file.
fn lower_text(
    text: &str,
    g: &mut Graph,
    scope: &Scope,
    e: &ExprText,
) -> Result<crate::lower::Lowered, EquationError> {
    let at = |err: ast::SyntaxError| EquationError::at(text, e.file_offset(err.pos), err.message);
    let tree = ast::parse(&e.text).map_err(at)?;
    lower(g, scope, &tree).map_err(at)
}

/// One expression per name in `names` from `exprs` (none for a name not listed, none
/// missing), in the order of `names`.
fn match_entries<'e>(
    text: &str,
    names: &[Named],
    exprs: &'e [ExprText],
    section: &str,
    section_pos: usize,
    what: &str,
) -> Result<Vec<&'e ExprText>, EquationError> {
    for e in exprs {
        if !names.iter().any(|n| n.name == e.key.name) {
            return Err(EquationError::at(
                text,
                e.key.pos,
                format!(
                    "{section} has an entry for '{}', which is not {what} ({})",
                    e.key.name,
                    file::list(names)
                ),
            ));
        }
    }
    names
        .iter()
        .map(|n| {
            exprs.iter().find(|e| e.key.name == n.name).ok_or_else(|| {
                EquationError::at(
                    text,
                    n.pos,
                    format!(
                        "'{}' has no expression in {section} (line {}); add {} = \"…\"",
                        n.name,
                        line_column(text, section_pos).0,
                        n.name
                    ),
                )
            })
        })
        .collect()
}

fn compile(text: &str, fm: FileModel) -> Result<EquationModel, EquationError> {
    let (n, m, p) = (fm.states.len(), fm.inputs.len(), fm.parameters.len());
    let mut g = Graph::default();
    let mut names = HashMap::new();
    let slots = fm
        .states
        .iter()
        .map(|s| &s.name)
        .chain(fm.inputs.iter().map(|s| &s.name))
        .chain(fm.parameters.iter().map(|(p, _)| &p.name));
    for (k, name) in slots.enumerate() {
        names.insert(name.clone(), Binding::Slot(1 + k as u32));
    }
    let names_of = |v: &[Named]| v.iter().map(|n| n.name.clone()).collect::<Vec<_>>();
    let line_starts: Vec<usize> = std::iter::once(0)
        .chain(text.match_indices('\n').map(|(i, _)| i + 1))
        .collect();
    let line_of = |pos: usize| line_starts.partition_point(|&s| s <= pos);
    let mut scope = Scope {
        names,
        lets: fm
            .lets
            .iter()
            .enumerate()
            .map(|(i, e)| (e.key.name.clone(), (i, line_of(e.key.pos))))
            .collect(),
        time_allowed: true,
        section: "[let]",
        groups: vec![
            ("states", names_of(&fm.states)),
            ("inputs", names_of(&fm.inputs)),
            (
                "parameters",
                fm.parameters.iter().map(|(p, _)| p.name.clone()).collect(),
            ),
        ],
        let_order: fm.lets.iter().map(|e| e.key.name.clone()).collect(),
        ..Scope::default()
    };
    for (i, e) in fm.lets.iter().enumerate() {
        scope.defining = Some(i);
        let l = lower_text(text, &mut g, &scope, e)?;
        scope
            .names
            .insert(e.key.name.clone(), Binding::Let(l.id, l.uses_time));
    }
    scope.defining = None;
    scope.section = "[equations]";
    let eqs = match_entries(
        text,
        &fm.states,
        &fm.equations,
        "[equations]",
        fm.equations_pos,
        "a state",
    )?;
    let mut f = Vec::with_capacity(n);
    for e in eqs {
        f.push(lower_text(text, &mut g, &scope, e)?.id);
    }
    scope.section = "[output]";
    scope.time_allowed = false;
    let outs = match_entries(
        text,
        &fm.outputs,
        &fm.output,
        "[output]",
        fm.output_pos,
        "a listed output",
    )?;
    let mut h = Vec::with_capacity(fm.outputs.len());
    for e in outs {
        h.push(lower_text(text, &mut g, &scope, e)?.id);
    }
    let tapes = differentiate_and_compile(&mut g, n, m, p, &f, &h);
    let registers = [
        &tapes.f,
        &tapes.f_jac,
        &tapes.f_u,
        &tapes.h,
        &tapes.h_jac,
        &tapes.h_u,
    ]
    .iter()
    .map(|t| t.registers())
    .max()
    .unwrap_or(0);
    Ok(EquationModel {
        source: text.to_string(),
        name: fm.name,
        time: fm.time,
        states: fm.states.into_iter().map(|s| s.name).collect(),
        inputs: fm.inputs.into_iter().map(|s| s.name).collect(),
        outputs: fm.outputs.into_iter().map(|s| s.name).collect(),
        units: fm.units,
        parameters: fm.parameters.into_iter().map(|(p, _)| p).collect(),
        initial: fm.initial,
        direct_output: DirectOutput::of(&tapes.h, &tapes.h_jac, n, m, p),
        tapes,
        registers,
    })
}

/// The six tapes: derivatives of f and h with respect to every state, parameter and
/// input (slots 1.., after t in slot 0), laid out row-major after the values.
fn differentiate_and_compile(
    g: &mut Graph,
    n: usize,
    m: usize,
    p: usize,
    f: &[Id],
    h: &[Id],
) -> Tapes {
    let limit = g.nodes.len();
    let slots = 1 + n + m + p;
    // d[k][id]: derivative of node id with respect to slot 1 + k.
    let d: Vec<Vec<Id>> = (1..slots as u32).map(|s| g.derivative(limit, s)).collect();
    let state = |k: usize| k;
    let input = |k: usize| n + k;
    let param = |k: usize| n + m + k;
    let block = |roots: &[Id], cols: &dyn Fn(usize) -> usize, count: usize| -> Vec<Id> {
        roots
            .iter()
            .flat_map(|&r| (0..count).map(move |j| (r, j)))
            .map(|(r, j)| d[cols(j)][r as usize])
            .collect()
    };
    let jac = |roots: &[Id]| -> Vec<Id> {
        let mut v = roots.to_vec();
        v.extend(block(roots, &state, n));
        v.extend(block(roots, &param, p));
        v
    };
    let with_u = |roots: &[Id]| -> Vec<Id> {
        let mut v = roots.to_vec();
        v.extend(block(roots, &input, m));
        v
    };
    Tapes {
        f: Tape::compile(g, slots, f),
        f_jac: Tape::compile(g, slots, &jac(f)),
        f_u: Tape::compile(g, slots, &with_u(f)),
        h: Tape::compile(g, slots, h),
        h_jac: Tape::compile(g, slots, &jac(h)),
        h_u: Tape::compile(g, slots, &with_u(h)),
    }
}
