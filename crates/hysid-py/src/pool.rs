//! Where a call's parallel work runs: the process-wide rayon pool (all cores), or a pool of
//! `threads` workers of its own.
//!
//! A built-in fit spreads its simulations (one per finite-difference or sensitivity column,
//! one per multi-start candidate) over rayon's pool. One call alone is fastest on all cores;
//! but two Python threads (or a Dask worker's threads) fitting at once then share one pool
//! and gain nothing. With `threads = 1` each call runs on a pool of its own with one worker:
//! n such calls from n Python threads use n cores, the throughput that concurrent fits want.
//! Pools are kept per calling thread and thread count (building one starts OS threads; a
//! pool shared between calling threads would queue their calls one behind the other).
//!
//! `threads = 0` means the process default, set by `hysid.set_num_threads(n)` (0 at start:
//! rayon's global pool, one worker per core).

use crate::errors::{convert, InternalError};
use crate::watch::{run_watched, Watch, Watching};
use pyo3::prelude::*;
use rayon::{ThreadPool, ThreadPoolBuilder};
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// The process default of `threads` (0: the global pool).
static DEFAULT_THREADS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    /// The pools this calling thread has built, by worker count.
    static POOLS: RefCell<HashMap<usize, Arc<ThreadPool>>> = RefCell::new(HashMap::new());
}

/// Registers `set_num_threads` and `get_num_threads`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(set_num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(get_num_threads, m)?)?;
    Ok(())
}

/// Sets the worker threads of every later call that does not give `threads` (0: all cores,
/// rayon's global pool).
#[pyfunction]
fn set_num_threads(n: usize) {
    DEFAULT_THREADS.store(n, Ordering::Relaxed);
}

/// The worker threads of a call that does not give `threads` (0: all cores).
#[pyfunction]
fn get_num_threads() -> usize {
    DEFAULT_THREADS.load(Ordering::Relaxed)
}

/// The pool of `n` workers (built on first use), or None for the global pool (n = 0).
pub fn pool(n: usize) -> PyResult<Option<Arc<ThreadPool>>> {
    let n = if n == 0 {
        DEFAULT_THREADS.load(Ordering::Relaxed)
    } else {
        n
    };
    if n == 0 {
        return Ok(None);
    }
    if let Some(p) = POOLS.with(|m| m.borrow().get(&n).cloned()) {
        return Ok(Some(p));
    }
    let p = ThreadPoolBuilder::new()
        .num_threads(n)
        .thread_name(move |i| format!("hysid-{n}-{i}"))
        .build()
        .map_err(|e| InternalError::new_err(format!("cannot start {n} worker thread(s): {e}")))?;
    let p = Arc::new(p);
    POOLS.with(|m| m.borrow_mut().insert(n, p.clone()));
    Ok(Some(p))
}

/// A long call: `f` watched from the calling thread, so that Ctrl-C stops it, with the time
/// limit and progress callable of `watching` ([`crate::watch`]), its parallel work on
/// `threads` workers, its errors mapped.
pub fn run_on<T: Send + 'static>(
    py: Python<'_>,
    threads: usize,
    watching: Watching,
    f: impl FnOnce(&Watch) -> hysid::Result<T> + Send + 'static,
) -> PyResult<T> {
    let pool = pool(threads)?;
    let outcome = run_watched(py, watching, move |watch| match pool {
        None => f(watch),
        Some(p) => p.install(|| f(watch)),
    })?;
    convert(py, outcome)
}
