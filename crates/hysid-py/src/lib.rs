//! # hysid-py — the Python extension module `hysid._hysid`
//!
//! A thin PyO3 layer over the hysid library: every function takes float64 numpy arrays,
//! runs one library recipe with the GIL released (`Python::detach`), and returns the
//! library's typed report (`hysid.report/1`) as JSON text, which the pure-Python package
//! (`python/hysid/__init__.py`) wraps in a `Result`. Keeping the boundary at the report's
//! JSON makes pickling exact (serde_json writes the shortest round-tripping decimal of
//! every f64, and Python's `json` reads it back bit for bit).
//!
//! Long calls run on a worker thread while the calling thread checks Python's signals, so
//! Ctrl-C raises `KeyboardInterrupt` within a fraction of a second ([`watch`]); the
//! library installs no signal handler of its own.
//!
//! Errors: every [`hysid::Error`] becomes a subclass of `hysid.HysidError` carrying the
//! library's one-line message ([`errors`]); a panic inside the library is caught with
//! [`std::panic::catch_unwind`] and raised as `hysid.InternalError`, never as a Rust panic.
//!
//! References: J. Vörös, "Modeling and Identification of Discrete-Time Nonlinear Dynamic
//! Cascade Systems with Input Hysteresis", Math. Probl. Eng. 2015, 393572; J. Gunnar,
//! E. Wernholt, G. Hovland, T. Brogårdh, "Nonlinear Grey-Box Identification of Linear
//! Actuators Containing Hysteresis", ICRA 2006; J.-P. Noël, M. Schoukens, "Hysteretic
//! benchmark with a dynamic nonlinearity", 2016.

use pyo3::prelude::*;

pub mod actuator;
pub mod equations;
pub mod errors;
pub mod export;
pub mod pool;
pub mod recipes;
pub mod stream;
pub mod user_model;
pub mod watch;
pub mod zoo;

/// The module `hysid._hysid`.
#[pymodule]
fn _hysid(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    recipes::register(m)?;
    user_model::register(m)?;
    pool::register(m)?;
    actuator::register(m)?;
    equations::register(m)?;
    zoo::register(m)?;
    stream::register(m)?;
    export::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
