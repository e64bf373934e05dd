//! Streaming models in Python: `Model.stepper()` and `Model.compensator()` (`hysid.stream`)
//! wrap these classes, which hold the library's [`hysid::model::stream::Stepper`] and
//! [`hysid::model::stream::Compensator`] of a saved model. Each step runs the library's
//! step; `run` feeds a whole array from the current state (the GIL released).

use crate::errors::{guard, run};
use crate::recipes::{parse_model, samples};
use hysid::model::saved::FittedModel;
use hysid::model::stream;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use std::sync::Mutex;

/// Registers the classes and their constructors.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Stepper>()?;
    m.add_class::<Compensator>()?;
    m.add_function(wrap_pyfunction!(model_stepper, m)?)?;
    m.add_function(wrap_pyfunction!(model_compensator, m)?)?;
    Ok(())
}

/// A lock that a panic inside the library left poisoned is still the stepper's: the next
/// call's error, or a reset, decides what it holds.
fn lock<T: ?Sized>(m: &Mutex<Box<T>>) -> std::sync::MutexGuard<'_, Box<T>> {
    m.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A saved model one sample at a time (`hysid::model::stream::Stepper`).
#[pyclass(module = "hysid._hysid")]
pub struct Stepper {
    inner: Mutex<Box<dyn stream::Stepper>>,
}

#[pymethods]
impl Stepper {
    /// The number of inputs a step takes.
    #[getter]
    fn n_inputs(&self) -> usize {
        lock(&self.inner).n_inputs()
    }

    /// The number of outputs a step gives.
    #[getter]
    fn n_outputs(&self) -> usize {
        lock(&self.inner).n_outputs()
    }

    /// Back to the model's initial state.
    fn reset(&self) {
        lock(&self.inner).reset();
    }

    /// How many bad (non-finite) input samples since the last reset.
    #[getter]
    fn faults(&self) -> usize {
        lock(&self.inner).faults()
    }

    /// True when the last input sample was bad (non-finite).
    #[getter]
    fn error(&self) -> bool {
        lock(&self.inner).error()
    }

    /// y_k for the inputs u_k (one value per input); the state moves on.
    fn step(&self, py: Python<'_>, u: Vec<f64>) -> PyResult<Vec<f64>> {
        let mut stepper = lock(&self.inner);
        let mut y = vec![0.0; stepper.n_outputs()];
        guard(py, || stepper.step(&u, &mut y))?;
        Ok(y)
    }

    /// The outputs for the input channels `inputs`, from the current state.
    fn run<'py>(
        &self,
        py: Python<'py>,
        inputs: Vec<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<Vec<Bound<'py, PyArray1<f64>>>> {
        let inputs: Vec<Vec<f64>> = inputs.iter().map(samples).collect();
        let outputs = run(py, || {
            let refs: Vec<&[f64]> = inputs.iter().map(Vec::as_slice).collect();
            stream::run(lock(&self.inner).as_mut(), &refs)
        })?;
        Ok(outputs
            .into_iter()
            .map(|o| PyArray1::from_vec(py, o))
            .collect())
    }
}

/// A numpy array of float64.
type Array<'py> = Bound<'py, PyArray1<f64>>;

/// A saved model's compensator one sample at a time (`hysid::model::stream::Compensator`).
#[pyclass(module = "hysid._hysid")]
pub struct Compensator {
    inner: Mutex<Box<dyn stream::Compensator>>,
}

#[pymethods]
impl Compensator {
    /// How many samples ahead the reference is given (a cascade's delay; 0 otherwise).
    #[getter]
    fn preview(&self) -> usize {
        lock(&self.inner).preview()
    }

    /// How many references were clipped since the last reset.
    #[getter]
    fn clipped(&self) -> usize {
        lock(&self.inner).clipped()
    }

    /// Back to the model's initial state (and the clipped and fault counts to 0).
    fn reset(&self) {
        lock(&self.inner).reset();
    }

    /// How many bad (non-finite) references since the last reset.
    #[getter]
    fn faults(&self) -> usize {
        lock(&self.inner).faults()
    }

    /// True when the last reference was bad (non-finite).
    #[getter]
    fn error(&self) -> bool {
        lock(&self.inner).error()
    }

    /// The command limits (lo, hi), or None when the command is not limited.
    #[getter]
    fn limits(&self) -> Option<(f64, f64)> {
        lock(&self.inner).limits().map(|l| (l.lo(), l.hi()))
    }

    /// (command, predicted output, clipped) for the reference `r`; the state moves on.
    fn step(&self, py: Python<'_>, r: f64) -> PyResult<(f64, f64, bool)> {
        let step = guard(py, || lock(&self.inner).step(r))?;
        Ok((step.u, step.predicted, step.clipped))
    }

    /// The commands and predicted outputs for the references `r`, from the current state.
    fn run<'py>(
        &self,
        py: Python<'py>,
        r: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(Array<'py>, Array<'py>)> {
        let r = samples(&r);
        let (u, predicted) = run(py, || {
            let mut compensator = lock(&self.inner);
            let (mut u, mut predicted) = (Vec::with_capacity(r.len()), Vec::with_capacity(r.len()));
            for &rk in &r {
                let step = compensator.step(rk)?;
                u.push(step.u);
                predicted.push(step.predicted);
            }
            Ok((u, predicted))
        })?;
        Ok((PyArray1::from_vec(py, u), PyArray1::from_vec(py, predicted)))
    }
}

/// The stepper of a saved model (`hysid.model/1` JSON) for the sample time `ts` and the
/// measured initial output `y0`.
#[pyfunction]
#[pyo3(signature = (model_json, ts, y0=None))]
fn model_stepper(py: Python<'_>, model_json: &str, ts: f64, y0: Option<f64>) -> PyResult<Stepper> {
    let inner = guard(py, || {
        FittedModel::from_file(&parse_model(model_json)?)?.stepper(ts, y0)
    })?;
    Ok(Stepper {
        inner: Mutex::new(inner),
    })
}

/// The compensator of a saved model (`hysid.model/1` JSON), its command limited to `limits`
/// (lo, hi), else to the file's `input_range`, else not at all.
#[pyfunction]
#[pyo3(signature = (model_json, ts, limits=None))]
fn model_compensator(
    py: Python<'_>,
    model_json: &str,
    ts: f64,
    limits: Option<(f64, f64)>,
) -> PyResult<Compensator> {
    let inner = guard(py, || {
        let file = parse_model(model_json)?;
        let limits = crate::zoo::limits_of(&file, limits)?;
        let mut c = FittedModel::from_file(&file)?.compensator(ts)?;
        c.set_limits(limits);
        Ok(c)
    })?;
    Ok(Compensator {
        inner: Mutex::new(inner),
    })
}
