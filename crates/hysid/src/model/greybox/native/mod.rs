//! Equation-file models as machine code: the tape of f, ∂f/∂x and ∂f/∂θ printed as C
//! (`source.rs`), compiled by the machine's C compiler into a cache keyed by its content and
//! loaded (`object`), so that a fit of a model written as equations runs its right-hand
//! side at the speed of a built-in model.
//!
//! When a fit (or a simulation) of an equation model starts, the model asks for the native
//! form of the tape it is about to run ([`NativeFunction::build`]). The first time on a
//! machine that costs one run of the C compiler (about 0.05–0.1 s for the Bouc–Wen file);
//! afterwards the cached object is loaded in well under a millisecond. The tape interpreter
//! stays: it is the fallback (no compiler, a compiler error, another operating system than
//! Linux), it is what [`Evaluator::Tape`] selects, and it is the reference the native code
//! is held to. Every native function is evaluated beside the tape at sample points before
//! it is used, and refused unless every result has the tape's bits
//! ([`NativeFunction::build`]'s `check`); the printed code performs the tape's operations in
//! its order with its rounding (see `source.rs`), so the two agree to the bit and a fit gives
//! the same estimates either way (`native_code_equals_the_tape` in the tests).
//!
//! Which evaluator runs is [`Evaluator`]: `auto` (native when it can be built, else the
//! tape), `native` (an error when it cannot be built), `tape`; the default is read from the
//! environment variable `HYSID_EVALUATOR`. The compiler is `$CC`, else `cc`; the cache is
//! `$HYSID_CACHE_DIR`, else `$XDG_CACHE_HOME/hysid`, else `~/.cache/hysid`.
//!
//! The technique — generating C for a model's residual and Jacobian and compiling it with
//! the system compiler — is that of CasADi's code generation (J. A. E. Andersson et al.,
//! "CasADi: a software framework for nonlinear optimization and optimal control",
//! *Mathematical Programming Computation* 11, 2019, §5).

#[cfg(target_os = "linux")]
mod object;
mod source;

use crate::{Error, Result};
use hysid_equations::Listing;
use std::sync::Arc;

/// Which code evaluates an equation model's tapes in a simulation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Evaluator {
    /// Native code when it can be built (a C compiler, Linux), else the tape interpreter.
    #[default]
    Auto,
    /// Native code; a simulation fails with the reason when it cannot be built.
    Native,
    /// The tape interpreter.
    Tape,
}

impl Evaluator {
    /// The evaluator the environment variable `HYSID_EVALUATOR` names (`auto`, `native` or
    /// `tape`; unset or empty: `auto`).
    pub fn from_env() -> Result<Self> {
        match std::env::var("HYSID_EVALUATOR") {
            Err(_) => Ok(Self::Auto),
            Ok(v) => v.parse(),
        }
    }
}

impl std::str::FromStr for Evaluator {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "" | "auto" => Ok(Self::Auto),
            "native" => Ok(Self::Native),
            "tape" => Ok(Self::Tape),
            other => Err(Error::invalid_option(
                "HYSID_EVALUATOR",
                other,
                format!(
                    "HYSID_EVALUATOR is '{other}'; the equation evaluator is auto, native or tape"
                ),
            )),
        }
    }
}

/// How a native function was obtained, for a report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Provenance {
    /// Loaded from the cache of compiled models.
    Cached,
    /// Compiled now, in this many seconds.
    Compiled(f64),
}

type PrepareFn = unsafe extern "C" fn(*const f64, *mut f64);
type EvalFn = unsafe extern "C" fn(f64, *const f64, *const f64, *const f64, *mut f64);

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
    #[cfg(target_os = "linux")]
    _library: object::Library,
    prepare: PrepareFn,
    eval: EvalFn,
    /// Doubles of the prepared array.
    prepared: usize,
    /// One more than the largest output position.
    out_len: usize,
    shape: Shape,
    provenance: Provenance,
}

impl std::fmt::Debug for NativeFunction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NativeFunction")
            .field("shape", &self.shape)
            .field("prepared", &self.prepared)
            .field("out_len", &self.out_len)
            .field("provenance", &self.provenance)
            .finish()
    }
}

impl NativeFunction {
    /// The native form of `listing` over `shape`: its first `values` results as computed,
    /// the others finite (a non-finite derivative is 0), result k written at
    /// `positions[k]`. Before it is returned, `check` is called with it and must return
    /// true (the caller compares it with the tape at sample points). Errors: one line,
    /// why there is no native code (no C compiler, a compiler error, not Linux, a check
    /// that failed).
    pub fn build(
        listing: &Listing,
        values: usize,
        positions: &[usize],
        shape: Shape,
        check: impl FnOnce(&NativeFunction) -> bool,
    ) -> std::result::Result<Arc<Self>, String> {
        if positions.len() != listing.results.len() {
            return Err("one position per result is needed".into());
        }
        let source = source::c_source(listing, values, positions);
        let native = Self::load(&source, shape, positions)?;
        if !check(&native) {
            return Err("the compiled code does not reproduce the tape's numbers".into());
        }
        Ok(Arc::new(native))
    }

    #[cfg(target_os = "linux")]
    fn load(
        source: &source::Source,
        shape: Shape,
        positions: &[usize],
    ) -> std::result::Result<Self, String> {
        let (library, provenance) = object::load(&source.text)?;
        let prepare = library.symbol(c"hysid_prepare")?;
        let eval = library.symbol(c"hysid_eval")?;
        // SAFETY: the symbols are the functions `source::c_source` defines, with these
        // C signatures.
        let (prepare, eval) = unsafe {
            (
                std::mem::transmute::<*mut std::ffi::c_void, PrepareFn>(prepare),
                std::mem::transmute::<*mut std::ffi::c_void, EvalFn>(eval),
            )
        };
        Ok(Self {
            _library: library,
            prepare,
            eval,
            prepared: source.prepared,
            out_len: positions.iter().max().map_or(0, |p| p + 1),
            shape,
            provenance,
        })
    }

    #[cfg(not(target_os = "linux"))]
    fn load(_: &source::Source, _: Shape, _: &[usize]) -> std::result::Result<Self, String> {
        Err("native code is built on Linux only".into())
    }

    /// How the code was obtained.
    pub fn provenance(&self) -> Provenance {
        self.provenance
    }

    /// The function with the parameters θ prepared (what depends on θ alone computed once).
    ///
    /// # Panics
    /// If θ does not have the shape's length.
    pub fn bind(self: &Arc<Self>, theta: &[f64]) -> BoundNative {
        assert_eq!(theta.len(), self.shape.parameters, "parameters");
        let mut prepared = vec![0.0; self.prepared];
        // SAFETY: θ has the parameters the code reads; `prepared` the slots it writes.
        unsafe { (self.prepare)(theta.as_ptr(), prepared.as_mut_ptr()) };
        BoundNative {
            function: Arc::clone(self),
            prepared,
        }
    }
}

impl NativeFunction {
    /// One evaluation at θ and (t, x, u), θ prepared for it alone (a check; a simulation
    /// prepares θ once, [`NativeFunction::bind`]).
    ///
    /// # Panics
    /// As [`NativeFunction::bind`] and [`BoundNative::eval`].
    pub fn eval_once(&self, theta: &[f64], t: f64, x: &[f64], u: &[f64], out: &mut [f64]) {
        assert_eq!(theta.len(), self.shape.parameters, "parameters");
        let mut prepared = vec![0.0; self.prepared];
        // SAFETY: as in `bind`.
        unsafe { (self.prepare)(theta.as_ptr(), prepared.as_mut_ptr()) };
        self.eval_prepared(&prepared, t, x, u, out);
    }

    /// The results at (t, x, u) with the prepared slots `prepared`.
    #[inline]
    fn eval_prepared(&self, prepared: &[f64], t: f64, x: &[f64], u: &[f64], out: &mut [f64]) {
        assert!(
            x.len() >= self.shape.states
                && u.len() >= self.shape.inputs
                && out.len() >= self.out_len
                && prepared.len() == self.prepared,
            "native evaluation: buffers shorter than the model's"
        );
        // SAFETY: the code reads x[..states], u[..inputs] and the prepared slots, and
        // writes out[..out_len]: all checked above.
        unsafe {
            (self.eval)(
                t,
                x.as_ptr(),
                u.as_ptr(),
                prepared.as_ptr(),
                out.as_mut_ptr(),
            )
        }
    }
}

/// A [`NativeFunction`] with its parameters prepared ([`NativeFunction::bind`]).
pub struct BoundNative {
    function: Arc<NativeFunction>,
    prepared: Vec<f64>,
}

impl BoundNative {
    /// The results at (t, x, u) into their positions in `out` (every position written each
    /// call).
    ///
    /// # Panics
    /// If x, u or `out` are shorter than the function reads or writes.
    #[inline]
    pub fn eval(&self, t: f64, x: &[f64], u: &[f64], out: &mut [f64]) {
        self.function.eval_prepared(&self.prepared, t, x, u, out);
    }
}
