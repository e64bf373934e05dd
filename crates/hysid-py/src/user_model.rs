//! Grey-box models written as Python functions (`hysid.GreyBoxModel`).
//!
//! The model is the continuous-time state-space model of the grey-box estimator,
//!
//! ```text
//! ẋ(t) = f(t, x, u, θ)        y(t) = h(x, u, θ)
//! ```
//!
//! with f = `rhs(t, x, u, p)` and h = `output(t, x, u, p)` Python callables on float64
//! numpy arrays (`output` receives t = nan: the library's output map is time-invariant).
//! The estimator integrates it with classical RK4 (one `rhs` call per stage, four per
//! sub-step) and takes the Jacobian of the output-error criterion by forward finite
//! differences (one extra simulation per free parameter), since a Python function gives
//! no analytic ∂f/∂x, ∂f/∂θ.
//!
//! Cost: every call wraps x, u, p in three new numpy arrays and reads the result back
//! (a few µs of overhead against nanoseconds for a built-in model's whole step); and the
//! finite-difference simulations, which run in parallel for a built-in model, run one
//! after the other here (a Python callback needs the GIL, so parallel threads would only
//! queue for it): the fit runs on a one-thread pool.
//!
//! An exception inside a callback (or a result of the wrong shape) is kept, the
//! simulation is failed with NaN, and the fit's caller raises `hysid.CallbackError` with
//! the original exception as its `__cause__`.

use crate::errors::{named, CallbackError, InternalError};
use crate::recipes::{
    estimation, id_data, parameter_set, quiet, samples, simulation, source, ParamTuple,
};
use hysid::data::Channel;
use hysid::identify::greybox::InitialStates;
use hysid::model::greybox::simulate::{simulate, InputTrack};
use hysid::model::greybox::StateSpaceModel;
use hysid::model::ParameterSet;
use hysid::{Error, Result};
use numpy::{PyArray1, PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::prelude::*;
use serde_json::json;
use std::sync::{Arc, Mutex};

/// Registers this module's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(greybox_fit_user, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_user, m)?)?;
    Ok(())
}

/// A state-space model whose f and h are Python callables.
struct PythonModel {
    rhs: Py<PyAny>,
    output: Py<PyAny>,
    states: Vec<String>,
    n_inputs: usize,
    n_outputs: usize,
    params: ParameterSet,
    /// The first callback failure; once set, every later call returns NaN at once.
    error: Mutex<Option<PyErr>>,
}

impl PythonModel {
    fn failed(&self) -> bool {
        self.error.lock().map(|e| e.is_some()).unwrap_or(true)
    }

    fn keep(&self, err: PyErr) {
        if let Ok(mut slot) = self.error.lock() {
            slot.get_or_insert(err);
        }
    }

    /// Calls `f(t, x, u, p)` and writes its float64 result into `out`.
    #[allow(clippy::too_many_arguments)]
    fn call(
        &self,
        which: &str,
        f: &Py<PyAny>,
        t: f64,
        x: &[f64],
        u: &[f64],
        theta: &[f64],
        out: &mut [f64],
    ) {
        if self.failed() {
            out.fill(f64::NAN);
            return;
        }
        let outcome = Python::attach(|py| -> PyResult<()> {
            let args = (
                t,
                PyArray1::from_slice(py, x),
                PyArray1::from_slice(py, u),
                PyArray1::from_slice(py, theta),
            );
            let result = f.bind(py).call1(args).map_err(|e| {
                let err = CallbackError::new_err(format!(
                    "{which}(t, x, u, p) raised {}",
                    describe(py, &e)
                ));
                err.set_cause(py, Some(e));
                err
            })?;
            let array = match result.extract::<PyReadonlyArray1<'_, f64>>() {
                Ok(a) => a,
                Err(_) => py
                    .import("numpy")?
                    .call_method1("asarray", (result.clone(), "float64"))
                    .and_then(|a| a.extract::<PyReadonlyArray1<'_, f64>>())
                    .map_err(|_| {
                        CallbackError::new_err(format!(
                            "{which}(t, x, u, p) returned {}; return a 1-D float array of {} values",
                            result.repr().map(|r| r.to_string()).unwrap_or_default(),
                            out.len()
                        ))
                    })?,
            };
            if array.len() != out.len() {
                return Err(CallbackError::new_err(format!(
                    "{which}(t, x, u, p) returned {} values; it must return {} (shape ({},))",
                    array.len(),
                    out.len(),
                    out.len()
                )));
            }
            for (o, v) in out.iter_mut().zip(array.as_array().iter()) {
                *o = *v;
            }
            Ok(())
        });
        if let Err(e) = outcome {
            out.fill(f64::NAN);
            self.keep(e);
        }
    }

    /// The kept callback error, if any.
    fn take_error(&self) -> Option<PyErr> {
        self.error.lock().ok().and_then(|mut e| e.take())
    }
}

/// "TypeName: message" of a Python exception.
fn describe(py: Python<'_>, e: &PyErr) -> String {
    let name = e
        .get_type(py)
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "an exception".into());
    format!("{name}: {}", e.value(py))
}

impl StateSpaceModel for PythonModel {
    fn kind(&self) -> &'static str {
        "python"
    }
    fn states(&self) -> Vec<Channel> {
        self.states.iter().map(Channel::new).collect()
    }
    fn inputs(&self) -> Vec<Channel> {
        (0..self.n_inputs)
            .map(|i| Channel::new(format!("u{i}")))
            .collect()
    }
    fn outputs(&self) -> Vec<Channel> {
        (0..self.n_outputs)
            .map(|i| Channel::new(format!("y{i}")))
            .collect()
    }
    fn parameters(&self) -> ParameterSet {
        self.params.clone()
    }
    fn rhs(&self, t: f64, x: &[f64], u: &[f64], theta: &[f64], dx: &mut [f64]) {
        self.call("rhs", &self.rhs, t, x, u, theta, dx);
    }
    fn output(&self, x: &[f64], u: &[f64], theta: &[f64], y: &mut [f64]) {
        self.call("output", &self.output, f64::NAN, x, u, theta, y);
    }
}

/// What Python passes to describe a model: rhs, output, state names, inputs, outputs,
/// parameters, x0.
type ModelSpec = (
    Py<PyAny>,
    Py<PyAny>,
    Vec<String>,
    usize,
    usize,
    Vec<ParamTuple>,
    Vec<f64>,
);

fn build(spec: ModelSpec) -> Result<(Arc<PythonModel>, Vec<f64>)> {
    let (rhs, output, states, n_inputs, n_outputs, params, x0) = spec;
    if x0.len() != states.len() {
        return Err(Error::CountMismatch {
            model: "the model".into(),
            what: "states (values of x0)",
            expected: states.len(),
            given: x0.len(),
        });
    }
    let model = PythonModel {
        rhs,
        output,
        states,
        n_inputs,
        n_outputs,
        params: parameter_set(&params)?,
        error: Mutex::new(None),
    };
    Ok((Arc::new(model), x0))
}

/// Runs `f` on a one-thread pool with the GIL released, then raises the callback's
/// error first (it explains the library's), else the library's.
fn on_one_thread<T: Send>(
    py: Python<'_>,
    model: &Arc<PythonModel>,
    f: impl FnOnce() -> Result<T> + Send,
) -> PyResult<T> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| InternalError::new_err(format!("cannot start a worker thread: {e}")))?;
    // The worker attaches to the interpreter once for the whole fit: every callback then
    // finds the GIL held by its own thread (a counter increment) instead of creating and
    // destroying a thread state per call (~50 µs). Python's eval loop still hands the GIL
    // to other threads at its switch interval while callbacks run.
    let outcome = crate::errors::run(py, || pool.install(|| Python::attach(|_| f())));
    match model.take_error() {
        Some(e) => Err(e),
        None => outcome,
    }
}

/// Output-error fit of a Python-defined grey-box model; returns the report's JSON.
#[pyfunction]
#[pyo3(signature = (spec, u, y, ts, starts, seed, integrator, substeps, interpolation))]
#[allow(clippy::too_many_arguments)]
fn greybox_fit_user(
    py: Python<'_>,
    spec: ModelSpec,
    u: Vec<PyReadonlyArray1<'_, f64>>,
    y: Vec<PyReadonlyArray1<'_, f64>>,
    ts: f64,
    starts: usize,
    seed: u64,
    integrator: &str,
    substeps: usize,
    interpolation: &str,
) -> PyResult<String> {
    let u: Vec<Vec<f64>> = u.iter().map(samples).collect();
    let y: Vec<Vec<f64>> = y.iter().map(samples).collect();
    let sim = crate::errors::guard(py, || simulation(integrator, substeps, interpolation))?;
    let (model, x0) = crate::errors::guard(py, || build(spec))?;
    let m = model.clone();
    on_one_thread(py, &model, move || {
        let data = id_data(ts, u, y)?;
        let n = x0.len();
        let initial = InitialStates {
            values: vec![x0],
            estimated: vec![false; n],
        };
        let fit = estimation(sim, starts, seed, &Default::default()).estimate(
            m.clone(),
            &data,
            &m.params,
            initial,
            &mut quiet(),
        )?;
        let fitted = fit.fitted_model(m.as_ref(), sim);
        let extra = json!({"model": "python callbacks", "residual_analysis": hysid::report::greybox_residuals(&fit, &data)});
        hysid::report::greybox_report(
            "greybox fit",
            &fit,
            &data,
            source(),
            fitted.to_file(),
            extra,
        )?
        .to_json()
    })
}

/// Simulates a Python-defined model with parameter values `theta` from state `x0`.
#[pyfunction]
#[pyo3(signature = (spec, inputs, ts, integrator, substeps, interpolation))]
fn simulate_user<'py>(
    py: Python<'py>,
    spec: ModelSpec,
    inputs: Vec<PyReadonlyArray1<'py, f64>>,
    ts: f64,
    integrator: &str,
    substeps: usize,
    interpolation: &str,
) -> PyResult<Vec<Bound<'py, PyArray1<f64>>>> {
    let inputs: Vec<Vec<f64>> = inputs.iter().map(samples).collect();
    let sim = crate::errors::guard(py, || simulation(integrator, substeps, interpolation))?;
    let (model, x0) = crate::errors::guard(py, || build(spec))?;
    if inputs.len() != model.n_inputs {
        return Err(named(
            py,
            "DataError",
            format!(
                "the model has {} input(s), {} given",
                model.n_inputs,
                inputs.len()
            ),
        ));
    }
    let m = model.clone();
    let outputs = on_one_thread(py, &model, move || {
        check_inputs(&inputs, ts)?;
        let refs: Vec<&[f64]> = inputs.iter().map(Vec::as_slice).collect();
        let track = InputTrack::new(&refs, &sim)?;
        let theta = m.params.values();
        let mut outputs = vec![Vec::with_capacity(track.len()); m.n_outputs];
        let (mut uk, mut yk) = (vec![0.0; m.n_inputs], vec![0.0; m.n_outputs]);
        simulate(
            m.as_ref(),
            &theta,
            &x0,
            &track,
            ts,
            sim.integrator,
            |k, x| {
                track.at(k, 0.0, &mut uk);
                m.output(x, &uk, &theta, &mut yk);
                for (o, v) in outputs.iter_mut().zip(&yk) {
                    o.push(*v);
                }
            },
        )?;
        Ok(outputs)
    })?;
    Ok(outputs
        .into_iter()
        .map(|o| PyArray1::from_vec(py, o))
        .collect())
}

/// Errors when the sample time is not positive or an input sample is not finite.
pub fn check_inputs(inputs: &[Vec<f64>], ts: f64) -> Result<()> {
    if !(ts.is_finite() && ts > 0.0) {
        return Err(Error::invalid_option(
            "ts",
            ts,
            format!("ts = {ts}: give a positive sample time"),
        ));
    }
    for (i, u) in inputs.iter().enumerate() {
        if let Some(k) = u.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                channel: format!("u{i}"),
                index: k,
                value: u[k],
            });
        }
    }
    Ok(())
}
