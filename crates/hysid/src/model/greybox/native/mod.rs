//! Equation-file models as machine code: the tape of f, ∂f/∂x and ∂f/∂θ — for a fit, with
//! the forward-sensitivity rates Ṡ = [f_θ, 0] + f_x·S, ẋ alone and a sample interval's RK4
//! sub-steps of x and S ([`Layout`]) — printed as C (`source.rs`), compiled by the
//! machine's C compiler into a private cache keyed by its content and loaded (`object.rs`;
//! [`Backend::Compiled`]), so that a fit of a model written as equations runs at the speed
//! of a built-in model: about 0.1 s the first time on a machine, a cache load in well under
//! a millisecond afterwards. hysid emits no machine code itself: the compiler does.
//!
//! When a fit (or a simulation) of an equation model starts, the model asks for the native
//! form of the tape it is about to run ([`NativeFunction::build`]). The tape interpreter
//! stays: it is the fallback (no C compiler, a compiler error, a refused cache), it is what
//! [`Evaluator::Tape`] selects, and it is the reference the native code is held to. Every
//! native function is evaluated beside the tape at sample points before it is used, and
//! refused unless every result has the tape's bits ([`NativeFunction::build`]'s `check`);
//! the C performs the tape's operations in its order with its rounding (no fused
//! multiply–add, no reordering), so the two agree to the bit and a fit gives the same
//! estimates either way (`native_code_equals_the_tape_for_every_operation`,
//! `native_code_equals_the_tape_on_the_example_files`,
//! `native_code_equals_the_tape_on_random_expressions` and
//! `bouc_wen_file_fit_from_twice_nominal_is_the_built_in_fit_native_or_taped` in the tests).
//!
//! Which evaluator runs is [`Evaluator`], a setting of the model
//! ([`super::equation_model::EquationStateSpace::with_evaluator`]; the front ends' option
//! `--evaluator`, `evaluator=` in Python): `auto` (compiled, else the tape), `cc` (compiled
//! only: an error when it cannot be built), `tape`; `native` is the best native route
//! available (today the C compiler's, so `cc`). [`Evaluator::from_env`] reads the same
//! names from the environment variable `HYSID_EVALUATOR`, the front ends' default. The
//! compiler is [`crate::toolchain::Compiler`] (`$CC` as make reads it, else `cc`); the cache
//! is `$HYSID_CACHE_DIR`, else `$XDG_CACHE_HOME/hysid`, else `~/.cache/hysid`, private and
//! checked (`object.rs`: a library is loaded only if its MAC matches).
//!
//! The technique — generating code for a model's residual and Jacobian from its expression
//! graph and handing it to the system's C compiler — is that of CasADi's code generation
//! (J. A. E. Andersson et al., "CasADi: a software framework for nonlinear optimization and
//! optimal control", *Mathematical Programming Computation* 11, 2019).

#[cfg(target_os = "linux")]
mod object;
mod source;

use crate::{Error, Result};
use hysid_equations::Listing;
use std::sync::Arc;

/// Which code evaluates an equation model's tapes in a simulation (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Evaluator {
    /// Native code when the C compiler builds it (or the cache has it), else the tape
    /// interpreter.
    #[default]
    Auto,
    /// Native code by the best route available (the C compiler's, as [`Evaluator::Cc`]); a
    /// simulation fails with the reason when it cannot be built.
    Native,
    /// Native code from the C compiler only ([`Backend::Compiled`]); a simulation fails
    /// with the reason when it cannot be built.
    Cc,
    /// The tape interpreter.
    Tape,
}

/// The names [`Evaluator`] parses, for messages.
const EVALUATORS: &str = "auto, native, cc or tape";

impl Evaluator {
    /// The evaluator the environment variable `HYSID_EVALUATOR` names (`auto`, `native`,
    /// `cc` or `tape`; unset or empty: `auto`). The library never reads it by itself: a
    /// front end calls this for its default and passes the result to the model.
    ///
    /// Errors: [`Error::InvalidOption`] for any other value (`jit` names the in-process
    /// encoder, which was removed).
    pub fn from_env() -> Result<Self> {
        match std::env::var("HYSID_EVALUATOR") {
            Err(_) => Ok(Self::Auto),
            Ok(v) => v.parse().map_err(|e: Error| match e {
                Error::InvalidOption { value, reason, .. } => Error::InvalidOption {
                    option: "HYSID_EVALUATOR".into(),
                    value,
                    reason: format!("HYSID_EVALUATOR: {reason}"),
                },
                other => other,
            }),
        }
    }

    /// The name the front ends use (`auto`, `native`, `cc`, `tape`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Native => "native",
            Self::Cc => "cc",
            Self::Tape => "tape",
        }
    }

    /// The routes to native code this evaluator tries, in order (none for the tape).
    pub fn backends(self) -> &'static [Backend] {
        match self {
            Self::Auto | Self::Native | Self::Cc => &[Backend::Compiled],
            Self::Tape => &[],
        }
    }

    /// Whether a simulation fails when native code cannot be built.
    pub fn requires_native(self) -> bool {
        matches!(self, Self::Native | Self::Cc)
    }
}

/// How a listing becomes machine code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// Printed as C (`source.rs`), compiled by the system's C compiler and cached
    /// (`object.rs`; Linux): about 0.1 s the first time on a machine.
    Compiled,
}

impl Backend {
    /// Whether this build on this machine has the route (the C compiler's presence is
    /// found out when it runs).
    pub fn available(self) -> bool {
        match self {
            Backend::Compiled => cfg!(target_os = "linux"),
        }
    }
}

impl std::str::FromStr for Evaluator {
    type Err = Error;
    /// `auto` (or empty), `native`, `cc` or `tape`, surrounding blanks ignored.
    ///
    /// Errors: [`Error::InvalidOption`] (option `evaluator`) for any other name, `jit`
    /// with the note that the in-process encoder was removed.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "" | "auto" => Ok(Self::Auto),
            "native" => Ok(Self::Native),
            "cc" => Ok(Self::Cc),
            "tape" => Ok(Self::Tape),
            "jit" => Err(Error::invalid_option(
                "evaluator",
                "jit",
                format!(
                    "the evaluator 'jit' (the in-process machine-code encoder) was removed; \
                     choose {EVALUATORS}"
                ),
            )),
            other => Err(Error::invalid_option(
                "evaluator",
                other,
                format!("'{other}' is not an equation evaluator; choose {EVALUATORS}"),
            )),
        }
    }
}

/// How a native function was obtained, for a report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Provenance {
    /// Loaded from the cache of compiled models.
    Cached,
    /// Compiled now, in this many seconds, and stored in the cache for later runs.
    Compiled(f64),
    /// Compiled now, in this many seconds, in a private temporary directory: no cache was
    /// usable (refused by its checks, or none), so the next run compiles again.
    CompiledUncached(f64),
}

type PrepareFn = unsafe extern "C" fn(*const f64, *mut f64);
type EvalFn = unsafe extern "C" fn(f64, *const f64, *const f64, *const f64, *mut f64);
type SensFn = unsafe extern "C" fn(
    f64,
    *const f64,
    *const f64,
    *const f64,
    *const f64,
    *const u8,
    *mut f64,
    *mut f64,
);
type SubstepsFn =
    unsafe extern "C" fn(*const f64, *const f64, *const u8, i32, f64, *mut f64, *mut f64);

/// What a native function computes from a listing.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Layout {
    /// The listing's results: the first `values` as computed, the others finite (a
    /// non-finite derivative is 0), result k written at `positions[k]` of the output.
    Results {
        /// How many leading results are values (not derivatives).
        values: usize,
        /// Where each result goes.
        positions: Vec<usize>,
    },
    /// For the listing of a column tape (f, ∂f/∂x, ∂f/∂θ for `k` parameter columns,
    /// [`hysid_equations::EquationModel::columns_listing`]): ẋ = f and the forward
    /// sensitivity rates of `q` ≥ k columns (row-major n × q; the last q − k, initial
    /// states, have no direct term),
    ///
    /// ```text
    /// Ṡᵢ꜀ = [f_θ]ᵢ꜀ + Σⱼ [f_x]ᵢⱼ · Sⱼ꜀
    /// ```
    ///
    /// summed as the RK4 kernel of equation models sums them: the direct term, then the
    /// products in the order of j, a product left out where its Jacobian entry is zero
    /// for the bound θ ([`BoundNative::sensitivities`]'s `coupled`).
    Sensitivities {
        /// Parameter columns of the tape.
        k: usize,
        /// Sensitivity columns.
        q: usize,
    },
}

/// The entry points of a loaded function.
#[derive(Clone, Copy)]
enum Entry {
    Results(EvalFn),
    /// `hysid_sens` (one evaluation) and `hysid_substeps` (one sample interval's RK4).
    Sensitivities(SensFn, SubstepsFn),
}

/// The sizes a native function reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    /// States (x has this many entries).
    pub states: usize,
    /// Inputs (u).
    pub inputs: usize,
    /// Parameters (θ).
    pub parameters: usize,
}

/// A listing compiled to machine code and loaded (see the module docs).
pub struct NativeFunction {
    /// Keeps the code mapped.
    code: Arc<dyn Send + Sync>,
    prepare: PrepareFn,
    entry: Entry,
    /// ẋ alone from the same code and prepared values (`hysid_rates`), for a
    /// [`Layout::Sensitivities`] function.
    rates: Option<EvalFn>,
    layout: Layout,
    /// Doubles of the prepared array.
    prepared: usize,
    /// The length of the output a [`Layout::Results`] function writes (one more than its
    /// largest position).
    out_len: usize,
    shape: Shape,
    provenance: Provenance,
}

/// The entry points of a loaded library, by their C names.
struct Found {
    prepare: PrepareFn,
    entry: Entry,
    rates: Option<EvalFn>,
}

impl Found {
    /// The functions `layout` needs, from `symbol` (a name to its address).
    fn look_up(
        symbol: impl Fn(&std::ffi::CStr) -> std::result::Result<*mut std::ffi::c_void, String>,
        layout: &Layout,
    ) -> std::result::Result<Self, String> {
        type Address = *mut std::ffi::c_void;
        // SAFETY: each name is a function of `source.rs` with the C signature it is
        // transmuted to.
        unsafe {
            let prepare = std::mem::transmute::<Address, PrepareFn>(symbol(c"hysid_prepare")?);
            let (entry, rates) = match layout {
                Layout::Results { .. } => (
                    Entry::Results(std::mem::transmute::<Address, EvalFn>(symbol(
                        c"hysid_eval",
                    )?)),
                    None,
                ),
                Layout::Sensitivities { .. } => (
                    Entry::Sensitivities(
                        std::mem::transmute::<Address, SensFn>(symbol(c"hysid_sens")?),
                        std::mem::transmute::<Address, SubstepsFn>(symbol(c"hysid_substeps")?),
                    ),
                    Some(std::mem::transmute::<Address, EvalFn>(symbol(
                        c"hysid_rates",
                    )?)),
                ),
            };
            Ok(Self {
                prepare,
                entry,
                rates,
            })
        }
    }

    /// The native function of these entry points, `code` kept alive with it.
    fn function(
        self,
        code: Arc<dyn Send + Sync>,
        layout: Layout,
        shape: Shape,
        prepared: usize,
        provenance: Provenance,
    ) -> NativeFunction {
        let out_len = match &layout {
            Layout::Results { positions, .. } => positions.iter().max().map_or(0, |p| p + 1),
            Layout::Sensitivities { .. } => 0,
        };
        NativeFunction {
            code,
            prepare: self.prepare,
            entry: self.entry,
            rates: self.rates,
            layout,
            prepared,
            out_len,
            shape,
            provenance,
        }
    }
}

impl std::fmt::Debug for NativeFunction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NativeFunction")
            .field("shape", &self.shape)
            .field("layout", &self.layout)
            .field("prepared", &self.prepared)
            .field("provenance", &self.provenance)
            .finish()
    }
}

impl NativeFunction {
    /// The native form of `listing` over `shape`, computing what `layout` says, made by
    /// `backend`. Before it is returned, `check` is called with it and must return true
    /// (the caller compares it with the tape at sample points). Errors: one line, why
    /// there is no native code (the route is not available here, no C compiler, a
    /// compiler error, a layout that does not fit the listing, a check that failed).
    pub fn build(
        listing: &Listing,
        layout: Layout,
        shape: Shape,
        backend: Backend,
        check: impl FnOnce(&Arc<NativeFunction>) -> bool,
    ) -> std::result::Result<Arc<Self>, String> {
        let n = shape.states;
        let fits = match &layout {
            Layout::Results { values, positions } => {
                positions.len() == listing.results.len() && *values <= positions.len()
            }
            Layout::Sensitivities { k, q } => listing.results.len() == n + n * n + n * k && q >= k,
        };
        if !fits {
            return Err(match layout {
                Layout::Results { .. } => "one position per result is needed".into(),
                Layout::Sensitivities { .. } => {
                    "the listing is not a column tape of this shape".into()
                }
            });
        }
        if !backend.available() {
            return Err(format!("{backend:?} native code is not available here"));
        }
        let native = Arc::new(match backend {
            Backend::Compiled => {
                let source = match &layout {
                    Layout::Results { values, positions } => {
                        source::results_source(listing, *values, positions)
                    }
                    Layout::Sensitivities { k, q } => {
                        source::sensitivities_source(listing, n, *k, *q, shape.inputs)
                    }
                };
                Self::load(&source, layout, shape)?
            }
        });
        if !check(&native) {
            return Err("the compiled code does not reproduce the tape's numbers".into());
        }
        Ok(native)
    }

    /// The functions of `source` compiled by the C compiler (or loaded from the cache).
    #[cfg(target_os = "linux")]
    fn load(
        source: &source::Source,
        layout: Layout,
        shape: Shape,
    ) -> std::result::Result<Self, String> {
        let (library, provenance) = object::load(&source.text)?;
        let library = Arc::new(library);
        let symbol = |name: &std::ffi::CStr| library.symbol(name);
        let found = Found::look_up(symbol, &layout)?;
        Ok(found.function(library.clone(), layout, shape, source.prepared, provenance))
    }

    #[cfg(not(target_os = "linux"))]
    fn load(_: &source::Source, _: Layout, _: Shape) -> std::result::Result<Self, String> {
        Err("native code is built on Linux only".into())
    }

    /// How the code was obtained.
    pub fn provenance(&self) -> Provenance {
        self.provenance
    }

    /// For a [`Layout::Sensitivities`] function, ẋ alone from the same compiled code: a
    /// [`Layout::Results`] function of the first n results (f) at positions 0 … n − 1,
    /// which a plain simulation runs (no second compilation). None for another layout.
    /// Check it against the tape of f before use, as [`NativeFunction::build`]'s caller
    /// checks the function itself.
    pub fn rates(&self) -> Option<Arc<NativeFunction>> {
        let found = Found {
            prepare: self.prepare,
            entry: Entry::Results(self.rates?),
            rates: None,
        };
        let n = self.shape.states;
        let layout = Layout::Results {
            values: n,
            positions: (0..n).collect(),
        };
        Some(Arc::new(found.function(
            Arc::clone(&self.code),
            layout,
            self.shape,
            self.prepared,
            self.provenance,
        )))
    }

    /// What the function computes.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The function with the parameters θ prepared (what depends on θ alone computed once).
    ///
    /// # Panics
    /// If θ does not have the shape's length.
    pub fn bind(self: &Arc<Self>, theta: &[f64]) -> BoundNative {
        let q = match self.layout {
            Layout::Sensitivities { q, .. } => q,
            Layout::Results { .. } => 0,
        };
        BoundNative {
            prepared: self.prepare(theta),
            entry: self.entry,
            states: self.shape.states,
            inputs: self.shape.inputs,
            q,
            out_len: self.out_len,
            _function: Arc::clone(self),
        }
    }

    fn prepare(&self, theta: &[f64]) -> Vec<f64> {
        assert_eq!(theta.len(), self.shape.parameters, "parameters");
        let mut prepared = vec![0.0; self.prepared];
        // SAFETY: θ has the parameters the code reads; `prepared` the slots it writes.
        unsafe { (self.prepare)(theta.as_ptr(), prepared.as_mut_ptr()) };
        prepared
    }
}

/// A [`NativeFunction`] with its parameters prepared ([`NativeFunction::bind`]).
pub struct BoundNative {
    /// Keeps the code loaded.
    _function: Arc<NativeFunction>,
    prepared: Vec<f64>,
    // The function's entry point and sizes, read at every call.
    entry: Entry,
    states: usize,
    inputs: usize,
    q: usize,
    out_len: usize,
}

impl BoundNative {
    /// The results at (t, x, u) into their positions in `out`, every position written
    /// ([`Layout::Results`]).
    ///
    /// # Panics
    /// If the layout is another, or x, u or `out` are shorter than the function reads or
    /// writes.
    #[inline]
    pub fn eval(&self, t: f64, x: &[f64], u: &[f64], out: &mut [f64]) {
        let Entry::Results(eval) = self.entry else {
            panic!("native evaluation: not a results layout");
        };
        assert!(
            x.len() >= self.states && u.len() >= self.inputs && out.len() >= self.out_len,
            "native evaluation: buffers shorter than the model's"
        );
        // SAFETY: the code reads x[..states], u[..inputs] and the prepared slots, and
        // writes out[..out_len]: all checked above.
        unsafe {
            eval(
                t,
                x.as_ptr(),
                u.as_ptr(),
                self.prepared.as_ptr(),
                out.as_mut_ptr(),
            )
        }
    }

    /// ẋ into `dx` and Ṡ (row-major n × q) into `ds` at (t, x, u) and sensitivities `s`
    /// ([`Layout::Sensitivities`]); `coupled[i·n + j]` false leaves out the products of
    /// an entry ∂fᵢ/∂xⱼ that depends on θ alone and is zero for the bound θ.
    ///
    /// # Panics
    /// If the layout is another, or a buffer is shorter than the shape's.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn sensitivities(
        &self,
        t: f64,
        x: &[f64],
        u: &[f64],
        s: &[f64],
        coupled: &[bool],
        dx: &mut [f64],
        ds: &mut [f64],
    ) {
        let Entry::Sensitivities(sens, _) = self.entry else {
            panic!("native evaluation: not a sensitivities layout");
        };
        let (n, q) = (self.states, self.q);
        assert!(
            x.len() >= n
                && u.len() >= self.inputs
                && s.len() >= n * q
                && coupled.len() >= n * n
                && dx.len() >= n
                && ds.len() >= n * q,
            "native evaluation: buffers shorter than the model's"
        );
        // SAFETY: the code reads x[..n], u[..inputs], s[..n·q], coupled[..n²] (bool is one
        // byte, 0 or 1) and the prepared slots, and writes dx[..n], ds[..n·q]: all
        // checked above.
        unsafe {
            sens(
                t,
                x.as_ptr(),
                u.as_ptr(),
                s.as_ptr(),
                self.prepared.as_ptr(),
                coupled.as_ptr().cast::<u8>(),
                dx.as_mut_ptr(),
                ds.as_mut_ptr(),
            )
        }
    }

    /// Advances x and S (row-major n × q) by one sample interval: `m` classical RK4
    /// sub-steps of size `h`, the input read at the interval's 2m + 1 half-step nodes
    /// (`nodes`, node-major) — the stages and updates of the fixed-size Rust loop
    /// (`fixed_rk4`) with the rates of [`Self::sensitivities`], to the bit, in one call.
    ///
    /// # Panics
    /// If the layout is not [`Layout::Sensitivities`], or a buffer is shorter than the
    /// shape's, or m does not fit a C `int`.
    #[inline]
    pub fn substeps(
        &self,
        nodes: &[f64],
        coupled: &[bool],
        m: usize,
        h: f64,
        x: &mut [f64],
        s: &mut [f64],
    ) {
        let Entry::Sensitivities(_, substeps) = self.entry else {
            panic!("native evaluation: not a sensitivities layout");
        };
        let (n, q) = (self.states, self.q);
        let steps = i32::try_from(m).expect("sub-steps per sample fit an int");
        assert!(
            nodes.len() >= (2 * m + 1) * self.inputs
                && coupled.len() >= n * n
                && x.len() >= n
                && s.len() >= n * q,
            "native evaluation: buffers shorter than the model's"
        );
        // SAFETY: the code reads nodes[..(2m + 1)·inputs], coupled[..n²] (bool is one byte,
        // 0 or 1) and the prepared slots, and reads and writes x[..n], s[..n·q]: all
        // checked above.
        unsafe {
            substeps(
                nodes.as_ptr(),
                self.prepared.as_ptr(),
                coupled.as_ptr().cast::<u8>(),
                steps,
                h,
                x.as_mut_ptr(),
                s.as_mut_ptr(),
            )
        }
    }
}
