//! Grey-box models written as equations in a text file (`hysid-equations`), usable wherever
//! a built-in model is.
//!
//! The file gives
//!
//! ```text
//! ẋ = f(t, x, u, θ)        y = h(x, u, θ)
//! ```
//!
//! with named states, inputs, outputs and parameters (value, unit, bounds, fixed flag) and
//! optional initial states; `hysid-equations` differentiates f and h symbolically and
//! compiles them, with ∂f/∂x, ∂f/∂θ, ∂h/∂x, ∂h/∂θ, into flat instruction tapes. So an
//! equation model has analytic Jacobians, and the estimator integrates the forward
//! sensitivity equations Ṡ = (∂f/∂x)S + ∂f/∂θ through RK4 exactly as for a built-in model
//! (L. Ljung, *System Identification: Theory for the User*, 2nd ed., 1999, §4.5 and §10.2
//! on output-error estimation of physically parameterised state-space models).
//!
//! Differences from the built-in models:
//!
//! * no stick–slip handling: a Coulomb friction written `Fc*sign(v)` is integrated as the
//!   plain discontinuous law (the built-in `actuator_fixed` also holds the body at rest
//!   while the applied force is below Fc);
//! * no second-order layout ([`StateSpaceModel::mechanical_dofs`] is None), so Newmark
//!   integration is refused: use RK4 (or the adaptive integrator);
//!
//! A discrete-time file (`[model] time = "discrete"`) gives next states instead,
//!
//! ```text
//! x[k+1] = f(t_k, x[k], u[k], θ)        y[k] = h(x[k], u[k], θ)
//! ```
//!
//! and is simulated by this recursion, with the sensitivities of its chain rule
//! S\[k+1\] = f_x·S\[k\] + f_θ ([`super::discrete`]); the integrator and the input
//! interpolation do not apply to it.

use super::fixed_rk4::{Rk4Sensitivities, SampleSink};
use super::native::{Backend, Evaluator, Layout, NativeFunction, Provenance, Shape};
use super::{equation_kernel, sensitivity, JacobianScratch, StateSpaceModel};
use crate::data::Channel;
use crate::error::EquationFileError;
use crate::model::{Parameter, ParameterSet};
use crate::{Error, Result};
use hysid_equations::{ColumnTape, EquationError, EquationModel, Scratch, TimeDomain};
use std::cell::RefCell;
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};

/// The model kind of equation-file models in saved models and reports.
pub const EQUATIONS_KIND: &str = "equations";

/// A grey-box model read from an equation file (see the module docs): ẋ = f(t, x, u, θ)
/// (or x\[k+1\] = f(t_k, x\[k\], u\[k\], θ) in discrete time), y = h(x, u, θ), with
/// analytic Jacobians from the compiled tape.
///
/// ```
/// use hysid::model::greybox::equation_model::EquationStateSpace;
/// use hysid::model::greybox::StateSpaceModel;
/// let text = "[model]\nstates = [\"x\"]\ninputs = [\"u\"]\noutputs = [\"y\"]\n\
///             [parameters]\na = 2.0\n[equations]\nx = \"-a*x + u\"\n[output]\ny = \"x\"\n";
/// let m = EquationStateSpace::parse(text, "example").unwrap();
/// let mut dx = [0.0];
/// m.rhs(0.0, &[1.0], &[0.5], &[2.0], &mut dx);
/// assert_eq!(dx[0], -1.5);
/// assert_eq!(m.kind(), "equations");
/// ```
#[derive(Clone, Debug)]
pub struct EquationStateSpace {
    model: EquationModel,
    states: Vec<Channel>,
    inputs: Vec<Channel>,
    outputs: Vec<Channel>,
    parameters: ParameterSet,
    /// The Jacobian tape restricted to the free parameters' ∂f/∂θ columns (what a fit
    /// asks sensitivities for).
    free_columns: Option<ColumnTape>,
    /// Which code runs the tapes of a simulation.
    evaluator: Evaluator,
    /// The native functions built so far, shared by the clones of this model (a fit's
    /// threads): one compilation (or cache load) per tape and layout, different ones
    /// built side by side (the two halves of split sensitivity columns).
    native: Arc<Mutex<NativeCells>>,
}

/// One native function, or why there is none, built once.
type NativeCell = OnceLock<std::result::Result<Arc<NativeFunction>, String>>;

/// The cells of the native functions asked for so far, by tape and layout.
type NativeCells = Vec<(NativeKey, Arc<NativeCell>)>;

/// Which tape and layout a native function computes: f alone, or the columns of the
/// parameters `params` padded to `q` sensitivity columns.
#[derive(Clone, Debug, PartialEq, Eq)]
enum NativeKey {
    Rates,
    Columns { params: Vec<usize>, q: usize },
}

impl NativeKey {
    /// The column code without columns: a plain simulation's sub-steps of x alone.
    fn plain_substeps() -> Self {
        Self::Columns {
            params: Vec::new(),
            q: 0,
        }
    }
}

/// Per-thread registers and value buffers, so that the trait's Jacobian methods (which do
/// not return f or h) never allocate after their first call on a thread.
#[derive(Default)]
struct Work {
    scratch: Scratch,
    values: Vec<f64>,
}

thread_local! {
    static WORK: RefCell<Work> = RefCell::new(Work::default());
}

/// Runs `f` with this thread's work buffers, `values` sized to `n`.
fn with_work<R>(n: usize, f: impl FnOnce(&mut Scratch, &mut [f64]) -> R) -> R {
    WORK.with(|cell| match cell.try_borrow_mut() {
        Ok(mut w) => {
            let w = &mut *w;
            if w.values.len() < n {
                w.values.resize(n, 0.0);
            }
            f(&mut w.scratch, &mut w.values[..n])
        }
        // Re-entered on one thread (not done by hysid): stay correct with fresh buffers.
        Err(_) => f(&mut Scratch::new(), &mut vec![0.0; n]),
    })
}

/// Ṡ = f_x·S + [f_θ, 0] row by row: `fx` n × n, `direct` n × k (the parameter columns),
/// `s` and `ds` n × q with q ≥ k (the last q − k columns, initial states, have no direct
/// term). Summed in the order of the default sensitivity right-hand side, so the values
/// are the same to the bit.
fn sensitivity_rates(n: usize, fx: &[f64], direct: &[f64], s: &[f64], ds: &mut [f64]) {
    let (q, k) = (s.len() / n, direct.len() / n);
    if q == 0 {
        return;
    }
    for (r, (ds_row, fx_row)) in ds.chunks_exact_mut(q).zip(fx.chunks_exact(n)).enumerate() {
        let mut terms = fx_row.iter().zip(s.chunks_exact(q));
        // The first product initialises the row (no separate copy of the direct term:
        // per-row memcpy calls of a few entries cost more than the products).
        if let Some((&a, s0)) = terms.next() {
            let (d_head, d_tail) = ds_row.split_at_mut(k);
            let (s_head, s_tail) = s0.split_at(k);
            let f_row = &direct[r * k..(r + 1) * k];
            for ((d, &f), &sj) in d_head.iter_mut().zip(f_row).zip(s_head) {
                *d = f + a * sj;
            }
            for (d, &sj) in d_tail.iter_mut().zip(s_tail) {
                *d = 0.0 + a * sj;
            }
        }
        for (&a, s_row) in terms {
            for (d, &sj) in ds_row.iter_mut().zip(s_row) {
                *d += a * sj;
            }
        }
    }
}

/// The language's error as hysid's, with where the text came from.
fn located(origin: &str, e: EquationError) -> Error {
    Error::Equations(EquationFileError {
        origin: origin.to_string(),
        line: e.line,
        column: e.column,
        message: e.message,
    })
}

impl EquationStateSpace {
    /// Parses, checks and compiles the equation-file text `text`; `origin` names where it
    /// came from in error messages (a path, or "saved model").
    ///
    /// Errors: any language error (with line and column), or a parameter whose bounds are
    /// empty (lower = upper).
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        let model = EquationModel::parse(text).map_err(|e| located(origin, e))?;
        Self::new(model, origin)
    }

    /// Reads and compiles the equation file at `path`.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Wraps a compiled model (see [`Self::parse`] for what is refused).
    pub fn new(model: EquationModel, origin: &str) -> Result<Self> {
        let channel = |name: &String| {
            Channel::new(name.clone()).with_unit(model.unit(name).unwrap_or_default())
        };
        let parameters = ParameterSet::new(
            model
                .parameters()
                .iter()
                .map(|p| {
                    Parameter::new(p.name.clone(), p.value)
                        .unit(p.unit.clone())
                        .bounds(p.lower, p.upper)
                        .fixed(p.fixed)
                })
                .collect(),
        )?;
        parameters
            .validate()
            .map_err(|e| Error::InvalidModel(format!("{origin}: {e}")))?;
        Ok(Self {
            free_columns: model.rhs_jacobian_columns(&parameters.free_indices()),
            evaluator: Evaluator::Auto,
            native: Arc::default(),
            states: model.states().iter().map(channel).collect(),
            inputs: model.inputs().iter().map(channel).collect(),
            outputs: model.outputs().iter().map(channel).collect(),
            parameters,
            model,
        })
    }

    /// The compiled equations.
    pub fn equations(&self) -> &EquationModel {
        &self.model
    }

    /// The file text (saved models embed it).
    pub fn source(&self) -> &str {
        self.model.source()
    }

    /// `[model] name` of the file.
    pub fn name(&self) -> &str {
        self.model.name()
    }

    /// x(t₀) as `[initial]` declares it (0 for a state not listed).
    pub fn initial_values(&self) -> Vec<f64> {
        self.model.initial().iter().map(|s| s.value).collect()
    }

    /// Per state, whether `[initial]` asks for it to be estimated (`fixed = false`).
    pub fn initial_estimated(&self) -> Vec<bool> {
        self.model.initial().iter().map(|s| !s.fixed).collect()
    }

    /// The same model run by `evaluator` (the default is [`Evaluator::Auto`]; a front end
    /// passes the user's choice, or [`Evaluator::from_env`]).
    pub fn with_evaluator(mut self, evaluator: Evaluator) -> Self {
        self.evaluator = evaluator;
        self.native = Arc::default();
        self
    }

    /// Which code runs this model's simulations (see [`super::native`]).
    pub fn evaluator(&self) -> Evaluator {
        self.evaluator
    }

    /// The native code of the tape `key` names, built on first use (once for this model
    /// and its clones); None when the evaluator is the tape, or `auto` and native code
    /// cannot be built. With [`Evaluator::Native`] that is an error.
    fn native(&self, key: NativeKey) -> Result<Option<Arc<NativeFunction>>> {
        if self.evaluator == Evaluator::Tape {
            return Ok(None);
        }
        let found = self
            .native_cell(&key)
            .get_or_init(|| self.build_native(&key))
            .clone();
        match found {
            Ok(f) => Ok(Some(f)),
            Err(why) if self.evaluator.requires_native() => Err(Error::Unsupported(format!(
                "equation model '{}': no native code for the evaluator '{}' ({why}); choose \
                 the evaluator auto or tape to run the tape interpreter",
                self.name(),
                self.evaluator.name()
            ))),
            Err(_) => Ok(None),
        }
    }

    /// The cell of `key`'s native function (made empty on first use).
    fn native_cell(&self, key: &NativeKey) -> Arc<NativeCell> {
        let mut cells = self.native.lock().unwrap_or_else(|e| e.into_inner());
        match cells.iter().find(|(k, _)| k == key) {
            Some((_, cell)) => Arc::clone(cell),
            None => {
                let cell = Arc::new(NativeCell::new());
                cells.push((key.clone(), Arc::clone(&cell)));
                cell
            }
        }
    }

    /// Whether the native ẋ `native` equals the tape of f at the check points.
    fn rates_match(&self, native: &Arc<NativeFunction>) -> bool {
        let (n, m) = (self.states.len(), self.inputs.len());
        let theta = self.parameters.values();
        let native = native.bind(&theta);
        check_points(n, m, 0, |x, u, _| {
            let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
            native.eval(0.0, x, u, &mut a);
            self.model.rhs(0.0, x, u, &theta, &mut b);
            same_bits(&a, &b)
        })
    }

    /// The native code of `key` by the first of the evaluator's routes that builds it
    /// ([`Evaluator::backends`]: the C compiler), or why none did.
    fn build_native(&self, key: &NativeKey) -> std::result::Result<Arc<NativeFunction>, String> {
        let mut why = Vec::new();
        for &backend in self.evaluator.backends() {
            match self.build_with(key, backend) {
                Ok(native) => return Ok(native),
                Err(e) => why.push(e),
            }
        }
        Err(if why.is_empty() {
            "no route to native code on this machine".into()
        } else {
            why.join("; ")
        })
    }

    /// Builds the native code of `key` by `backend` and checks it against the tape at
    /// sample points. The code of a column tape carries ẋ alone as well: it becomes the
    /// plain simulations' native function (checked likewise) unless they have one already.
    fn build_with(
        &self,
        key: &NativeKey,
        backend: Backend,
    ) -> std::result::Result<Arc<NativeFunction>, String> {
        let (n, m) = (self.states.len(), self.inputs.len());
        let shape = Shape {
            states: n,
            inputs: m,
            parameters: self.parameters.len(),
        };
        let theta = self.parameters.values();
        match key {
            NativeKey::Rates => {
                let layout = Layout::Results {
                    values: n,
                    positions: (0..n).collect(),
                };
                NativeFunction::build(
                    &self.model.rhs_listing(),
                    layout,
                    shape,
                    backend,
                    |native| self.rates_match(native),
                )
            }
            NativeKey::Columns { params, q } => {
                let columns = self
                    .model
                    .rhs_jacobian_columns(params)
                    .ok_or("a parameter column out of range")?;
                let listing = self.model.columns_listing(&columns);
                let (k, q) = (params.len(), *q);
                let layout = Layout::Sensitivities { k, q };
                let built = NativeFunction::build(&listing, layout, shape, backend, |native| {
                    let Some(bound) = self.model.bind_columns(&columns, &theta) else {
                        return false;
                    };
                    let coupled = equation_kernel::coupling(&bound, n);
                    let native = native.bind(&theta);
                    check_points(n, m, n * q, |x, u, s| {
                        let (mut dx, mut ds) = (vec![0.0; n], vec![0.0; n * q]);
                        native.sensitivities(0.0, x, u, s, &coupled, &mut dx, &mut ds);
                        let mut scratch = self.model.scratch();
                        let (mut f, mut fx, mut ft) =
                            (vec![0.0; n], vec![0.0; n * n], vec![0.0; n * k]);
                        self.model.rhs_jacobian_columns_with(
                            &mut scratch,
                            &columns,
                            0.0,
                            x,
                            u,
                            &theta,
                            &mut f,
                            &mut fx,
                            &mut ft,
                        );
                        // The generic path's sums: they add the products the kernels
                        // leave out (an entry zero for this θ), which changes at most the
                        // sign of a zero.
                        let mut want = vec![0.0; n * q];
                        sensitivity_rates(n, &fx, &ft, s, &mut want);
                        same_bits(&dx, &f)
                            && ds
                                .iter()
                                .zip(&want)
                                .all(|(a, b)| a == b || same_bits(&[*a], &[*b]))
                    })
                });
                let rates = built.as_ref().ok().and_then(|f| f.rates());
                let matched = rates.filter(|rates| self.rates_match(rates));
                if let Some(rates) = &matched {
                    // Already set when the plain simulations built their own: kept.
                    let _ = self
                        .native_cell(&NativeKey::Rates)
                        .set(Ok(Arc::clone(rates)));
                }
                // A plain simulation's sub-steps must give its ẋ: the tape of f's.
                if *key == NativeKey::plain_substeps() && matched.is_none() {
                    return Err("the column code's ẋ is not the tape of f's".into());
                }
                built
            }
        }
    }
}

/// Whether `agrees(x, u, s)` holds at a few seeded points: n states, m inputs and `len`
/// sensitivity entries, mixing signs, magnitudes and a negative zero.
fn check_points(
    n: usize,
    m: usize,
    len: usize,
    mut agrees: impl FnMut(&[f64], &[f64], &[f64]) -> bool,
) -> bool {
    let points = [0.37, -1.9, 2.6e-3, 41.0, -0.0, 7.5e-7];
    (0..points.len()).all(|p| {
        let pick = |i: usize| points[(p + 3 * i) % points.len()] * (1.0 + i as f64);
        let x: Vec<f64> = (0..n).map(pick).collect();
        let u: Vec<f64> = (0..m).map(|i| pick(n + i)).collect();
        let s: Vec<f64> = (0..len).map(|i| pick(n + m + i)).collect();
        agrees(&x, &u, &s)
    })
}

/// The same bits entry by entry (NaN matching NaN).
fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(a, b)| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()))
}

impl StateSpaceModel for EquationStateSpace {
    /// Always `equations` (the file's own name is [`EquationStateSpace::name`]).
    fn kind(&self) -> &'static str {
        EQUATIONS_KIND
    }

    fn states(&self) -> Vec<Channel> {
        self.states.clone()
    }

    fn inputs(&self) -> Vec<Channel> {
        self.inputs.clone()
    }

    fn outputs(&self) -> Vec<Channel> {
        self.outputs.clone()
    }

    fn parameters(&self) -> ParameterSet {
        self.parameters.clone()
    }

    /// True for a `time = "discrete"` file.
    fn discrete_time(&self) -> bool {
        self.model.time_domain() == TimeDomain::Discrete
    }

    #[inline]
    fn rhs(&self, t: f64, x: &[f64], u: &[f64], theta: &[f64], dx: &mut [f64]) {
        self.model.rhs(t, x, u, theta, dx);
    }

    #[inline]
    fn output(&self, x: &[f64], u: &[f64], theta: &[f64], y: &mut [f64]) {
        self.model.output(x, u, theta, y);
    }

    /// From the tape that computes f, ∂f/∂x and ∂f/∂θ in one pass (f is discarded).
    fn rhs_jacobians(
        &self,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        fx: &mut [f64],
        ftheta: &mut [f64],
    ) -> bool {
        with_work(x.len(), |s, dx| {
            self.model
                .rhs_jacobians_with(s, t, x, u, theta, dx, fx, ftheta)
        });
        true
    }

    /// ẋ and Ṡ = (∂f/∂x)·S + ∂f/∂θ\[params\] from ONE pass over the Jacobian tape —
    /// restricted to the free parameters' columns when `params` are exactly those — with
    /// the registers and Jacobian buffers from `scratch`; the values equal the default's.
    /// `held` is ignored: equation files have no stick–slip handling (their `rhs_sliding`
    /// is `rhs`).
    #[allow(clippy::too_many_arguments)]
    fn rhs_sensitivities(
        &self,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        held: Option<f64>,
        params: &[usize],
        s: &[f64],
        scratch: &mut JacobianScratch,
        dx: &mut [f64],
        ds: &mut [f64],
    ) -> bool {
        let (n, p, k) = (x.len(), theta.len(), params.len());
        let q = s.len() / n.max(1);
        if n == 0 || k > q || ds.len() != s.len() || params.iter().any(|&c| c >= p) {
            return sensitivity::default_rhs_sensitivities(
                self, t, x, u, theta, held, params, s, scratch, dx, ds,
            );
        }
        let (fx, ft, regs) = scratch.split(n, p + k);
        let (full, direct) = ft.split_at_mut(n * p);
        match &self.free_columns {
            Some(columns) if columns.params() == params => self
                .model
                .rhs_jacobian_columns_with(regs, columns, t, x, u, theta, dx, fx, direct),
            _ => {
                self.model
                    .rhs_jacobians_with(regs, t, x, u, theta, dx, fx, full);
                for (row, out) in full.chunks_exact(p).zip(direct.chunks_exact_mut(k.max(1))) {
                    for (o, &c) in out.iter_mut().zip(params) {
                        *o = row[c];
                    }
                }
            }
        }
        sensitivity_rates(n, fx, direct, s, ds);
        true
    }

    /// The fixed-size path of the private `equation_kernel` module: the Jacobian tape of the
    /// run's columns (the tape of f for a run without columns, a plain simulation) bound to
    /// its θ — run as native code unless the evaluator is the tape ([`super::native`]) —
    /// for up to 4 states and 10 columns of a continuous-time file that does not read t
    /// (otherwise None: the generic path runs).
    fn fixed_rk4_sensitivities(
        &self,
        run: &Rk4Sensitivities<'_>,
        on_sample: &mut SampleSink<'_>,
    ) -> Option<Result<()>> {
        if self.discrete_time()
            || run.x0.len() != self.states.len()
            || run.input.n_channels() != self.inputs.len()
        {
            return None;
        }
        if !equation_kernel::has_fixed_path(run.x0.len(), run.columns()) {
            return None;
        }
        if run.columns() == 0 {
            let tape = self.model.bind_rhs(run.theta)?;
            if tape.uses_time() {
                return None;
            }
            // Native code: the sub-steps of x alone, one call per sample (a stage's values
            // stay in registers; built only when its ẋ is the tape of f's to the bit), else
            // the native ẋ called per stage, else the tape.
            if let Ok(Some(code)) = self.native(NativeKey::plain_substeps()) {
                let columns = self.model.rhs_jacobian_columns(&[])?;
                let bound = self.model.bind_columns(&columns, run.theta)?;
                let native = Some(code.bind(run.theta));
                return equation_kernel::simulate(bound, native, run, on_sample);
            }
            let native = match self.native(NativeKey::Rates) {
                Ok(native) => native.map(|f| f.bind(run.theta)),
                Err(e) => return Some(Err(e)),
            };
            return equation_kernel::simulate_rates(tape, native, run, on_sample);
        }
        let fresh;
        let columns = match &self.free_columns {
            Some(c) if c.params() == run.params => c,
            _ => {
                fresh = self.model.rhs_jacobian_columns(run.params)?;
                &fresh
            }
        };
        let tape = self.model.bind_columns(columns, run.theta)?;
        if tape.uses_time() {
            return None;
        }
        let key = NativeKey::Columns {
            params: run.params.to_vec(),
            q: run.columns(),
        };
        let native = match self.native(key) {
            Ok(native) => native.map(|f| f.bind(run.theta)),
            Err(e) => return Some(Err(e)),
        };
        equation_kernel::simulate(tape, native, run, on_sample)
    }

    /// "native code (…)" when every simulation that asked for native code got it (how:
    /// compiled now with the compiler's time, or loaded from the cache), "tape interpreter (…)" with the reason otherwise; None before any
    /// simulation.
    fn evaluation(&self) -> Option<String> {
        if self.evaluator == Evaluator::Tape {
            return Some("tape interpreter (evaluator tape chosen)".into());
        }
        let cells = self.native.lock().unwrap_or_else(|e| e.into_inner());
        let built: Vec<_> = cells.iter().filter_map(|(_, cell)| cell.get()).collect();
        if built.is_empty() {
            return (!cells.is_empty()).then(|| "native code (being built)".into());
        }
        if let Some(Err(why)) = built.iter().find(|b| b.is_err()) {
            return Some(format!("tape interpreter (no native code: {why})"));
        }
        let (mut compiled, mut cached) = (None::<f64>, false);
        let mut uncached = false;
        for b in built.iter().filter_map(|b| b.as_ref().ok()) {
            match b.provenance() {
                Provenance::Compiled(s) => *compiled.get_or_insert(0.0) += s,
                Provenance::CompiledUncached(s) => {
                    *compiled.get_or_insert(0.0) += s;
                    uncached = true;
                }
                Provenance::Cached => cached = true,
            }
        }
        let mut how = Vec::new();
        if let Some(s) = compiled {
            how.push(if uncached {
                format!("compiled now: {s:.2} s of compiler time; not cached (no usable cache)")
            } else {
                format!("compiled now: {s:.2} s of compiler time; cached for the next runs")
            });
        }
        if cached {
            how.push("loaded from the cache".into());
        }
        Some(format!("native code ({})", how.join("; ")))
    }

    /// Constant when every output is a state, an input, a parameter or a constant.
    fn output_jacobians_are_constant(&self) -> bool {
        self.model.constant_output_jacobians().is_some()
    }

    /// Read unless every output is a state, a parameter or a constant.
    fn output_reads_input(&self) -> bool {
        self.model.output_reads_inputs()
    }

    /// From the tape that computes h, ∂h/∂x and ∂h/∂θ in one pass (h is discarded), or
    /// copied when they are constants (outputs that are states, inputs or parameters).
    fn output_jacobians(
        &self,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        hx: &mut [f64],
        htheta: &mut [f64],
    ) -> bool {
        if let Some((hx0, htheta0)) = self.model.constant_output_jacobians() {
            hx.copy_from_slice(hx0);
            htheta.copy_from_slice(htheta0);
            return true;
        }
        with_work(self.outputs.len(), |s, y| {
            self.model
                .output_jacobians_with(s, x, u, theta, y, hx, htheta)
        });
        true
    }
}
