//! The Python exceptions and the mapping of library errors onto them.
//!
//! `HysidError` is the base of every error the library raises. Bad input data and bad
//! settings also derive from `ValueError` (`DataError`, `ConfigError`), so that
//! `except ValueError` catches them as Python users expect; numerical failures
//! (`NumericalError`), model-file problems (`ModelFileError`), a Python callback that
//! failed (`CallbackError`) and a caught library panic (`InternalError`) derive from
//! `HysidError` only.

use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

pyo3::create_exception!(
    _hysid,
    HysidError,
    PyException,
    "Base class of hysid's errors."
);
pyo3::create_exception!(
    _hysid,
    NumericalError,
    HysidError,
    "A numerical failure: singular regression, diverged simulation, no admissible start."
);
pyo3::create_exception!(
    _hysid,
    ModelFileError,
    HysidError,
    "A model file that cannot be read, or a model that cannot be saved."
);
pyo3::create_exception!(
    _hysid,
    CallbackError,
    HysidError,
    "A user model's Python callback raised or returned the wrong shape."
);
pyo3::create_exception!(
    _hysid,
    InternalError,
    HysidError,
    "A bug in hysid (a caught panic); please report it with the input that caused it."
);

/// Registers the exception classes; `DataError` and `ConfigError` are made in Python
/// (`class DataError(HysidError, ValueError)`) since they have two bases.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("HysidError", py.get_type::<HysidError>())?;
    m.add("NumericalError", py.get_type::<NumericalError>())?;
    m.add("ModelFileError", py.get_type::<ModelFileError>())?;
    m.add("CallbackError", py.get_type::<CallbackError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    let ns = pyo3::types::PyDict::new(py);
    ns.set_item("HysidError", py.get_type::<HysidError>())?;
    ns.set_item("ValueError", py.get_type::<PyValueError>())?;
    py.run(
        c"class DataError(HysidError, ValueError):\n    'Input data that cannot be used: wrong shape, empty, not finite, too short.'\n\nclass ConfigError(HysidError, ValueError):\n    'A setting that is out of range or unknown.'\n",
        Some(&ns),
        None,
    )?;
    for name in ["DataError", "ConfigError"] {
        let class = ns.get_item(name)?.ok_or_else(|| {
            InternalError::new_err(format!("exception class {name} was not created"))
        })?;
        class.setattr("__module__", "hysid")?;
        m.add(name, class)?;
    }
    Ok(())
}

/// The Python exception for a library error, with the library's one-line message.
pub fn to_py(py: Python<'_>, e: hysid::Error) -> PyErr {
    use hysid::error::Category;
    let message = e.to_string();
    let class = match e.category() {
        Category::Data => "DataError",
        Category::Config => "ConfigError",
        Category::ModelFile | Category::Io | Category::Usage => "ModelFileError",
        Category::Numerical | Category::Cancelled => "NumericalError",
        Category::Internal => "InternalError",
    };
    named(py, class, message)
}

/// An exception of the class `name` of `hysid._hysid`.
pub fn named(py: Python<'_>, name: &str, message: String) -> PyErr {
    let class = py
        .import("hysid._hysid")
        .and_then(|m| m.getattr(name))
        .ok()
        .filter(|c| c.is_instance_of::<pyo3::types::PyType>());
    match class.and_then(|c| c.call1((message.clone(),)).ok()) {
        Some(instance) => PyErr::from_value(instance),
        None => HysidError::new_err(message),
    }
}

/// Runs `f`, turning a library error into its Python exception and a panic into
/// `InternalError` (a last resort: the library validates its input and should not panic).
pub fn guard<T>(py: Python<'_>, f: impl FnOnce() -> hysid::Result<T>) -> PyResult<T> {
    convert(py, catch_unwind(AssertUnwindSafe(f)))
}

/// [`guard`] with the GIL released while `f` runs (long fits: other Python threads go on).
pub fn run<T: Send>(py: Python<'_>, f: impl FnOnce() -> hysid::Result<T> + Send) -> PyResult<T> {
    let outcome = py.detach(|| catch_unwind(AssertUnwindSafe(f)));
    convert(py, outcome)
}

/// A recipe's outcome: its result or error, or the panic caught.
pub type Caught<T> = std::thread::Result<hysid::Result<T>>;

/// The Python form of a recipe's outcome: the value, the library error's exception, or
/// `InternalError` for a caught panic.
pub fn convert<T>(py: Python<'_>, outcome: Caught<T>) -> PyResult<T> {
    match outcome {
        Ok(Ok(value)) => Ok(value),
        Ok(Err(e)) => Err(to_py(py, e)),
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown".into());
            Err(InternalError::new_err(format!(
                "internal error in hysid ({what}); please report it with the input that caused it"
            )))
        }
    }
}
