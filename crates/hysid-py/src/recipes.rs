//! The library recipes behind `hysid.identify_cascade`, `identify_hysteresis`,
//! `greybox_fit` (built-in models), `benchmark_bouc_wen`, `rigid_body_ls`, and model
//! simulation, loading and saving. Each returns JSON text (`hysid.report/1` for a fit,
//! `hysid.model/1` for a model) and runs with the GIL released, its parallel work on
//! `threads` workers ([`crate::pool`]).
//!
//! The reports are the library's (`hysid::report::cascade_report`, `greybox_report`, …),
//! the ones the CLI writes.

use crate::errors::{guard, run};
use crate::pool::run_on;
use crate::watch::{watching, Watch};
use hysid::data::{Channel, Experiment, IdData};
use hysid::identify::bouc_wen_benchmark::BoucWenBenchmark;
use hysid::identify::cascade::CascadeIdentification;
use hysid::identify::greybox::{GreyBoxEstimation, InitialStates};
use hysid::identify::hysteresis::{HysteresisIdentification, InitialOutput};
use hysid::identify::rigid_body::RigidBodyLs;
use hysid::identify::Uncertainty;
use hysid::model::greybox::{models, InputInterpolation, Integrator, Simulation, StateSpaceModel};
use hysid::model::saved::{FittedModel, ModelFile};
use hysid::model::{ChForm, Parameter, ParameterSet};
use hysid::numerics::{metrics, Control, IterationRecord};
use hysid::report::{self, ValidationEntry};
use hysid::{Error, Result};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use serde_json::json;
use std::sync::Arc;

/// A parameter as Python passes it: (name, value, lower, upper, fixed, unit).
pub type ParamTuple = (String, f64, f64, f64, bool, String);

/// A test record: (input, output, sample time, source name).
type TestRecord<'py> = (
    PyReadonlyArray1<'py, f64>,
    PyReadonlyArray1<'py, f64>,
    f64,
    String,
);

/// Registers this module's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(identify_cascade, m)?)?;
    m.add_function(wrap_pyfunction!(identify_hysteresis, m)?)?;
    m.add_function(wrap_pyfunction!(model_parameters, m)?)?;
    m.add_function(wrap_pyfunction!(greybox_fit, m)?)?;
    m.add_function(wrap_pyfunction!(benchmark_bouc_wen, m)?)?;
    m.add_function(wrap_pyfunction!(rigid_body_ls, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_model, m)?)?;
    m.add_function(wrap_pyfunction!(load_model, m)?)?;
    m.add_function(wrap_pyfunction!(check_model, m)?)?;
    m.add_function(wrap_pyfunction!(residual_analysis, m)?)?;
    Ok(())
}

/// The samples of a 1-D float64 array.
pub fn samples(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

/// A progress callback that never stops the fit.
pub fn quiet() -> impl FnMut(&IterationRecord) -> Control {
    |_: &IterationRecord| Control::Continue
}

/// One experiment with input channels `u` and output channels `y`.
pub fn id_data(ts: f64, u: Vec<Vec<f64>>, y: Vec<Vec<f64>>) -> Result<IdData> {
    let inputs = (0..u.len())
        .map(|i| Channel::new(format!("u{i}")))
        .collect();
    let outputs = (0..y.len())
        .map(|i| Channel::new(format!("y{i}")))
        .collect();
    let experiment = Experiment::new("experiment 1", u, y)?;
    IdData::new(ts, inputs, outputs, vec![experiment])
}

/// The `data.source` of a report on numpy arrays.
pub fn source() -> Vec<String> {
    vec!["python (numpy arrays)".into()]
}

/// Identifies a Coleman–Hodgdon hysteresis + linear-block cascade (Vörös 2015).
#[pyfunction]
#[pyo3(signature = (x, y, hysteresis, na, nb, delay, ts, uncertainty, replicates, seed, threads=0, time_limit=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn identify_cascade(
    py: Python<'_>,
    x: PyReadonlyArray1<'_, f64>,
    y: PyReadonlyArray1<'_, f64>,
    hysteresis: &str,
    na: usize,
    nb: usize,
    delay: usize,
    ts: f64,
    uncertainty: &str,
    replicates: usize,
    seed: u64,
    threads: usize,
    time_limit: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let (x, y) = (samples(&x), samples(&y));
    let hysteresis = hysteresis.to_string();
    let uncertainty = match uncertainty {
        "asymptotic" => Uncertainty::Asymptotic,
        "bootstrap" => Uncertainty::Bootstrap(replicates),
        other => {
            return Err(crate::errors::named(
                py,
                "ConfigError",
                format!("uncertainty='{other}': use 'asymptotic' or 'bootstrap'"),
            ))
        }
    };
    run_on(
        py,
        threads,
        watching(py, time_limit, progress)?,
        move |watch| {
            let form = ChForm::parse(&hysteresis)?;
            let data = id_data(ts, vec![x], vec![y])?;
            let mut id = CascadeIdentification::new(form, na, nb, delay);
            id.uncertainty = uncertainty;
            id.bootstrap_seed = seed;
            id.observer = watch.observer();
            let fit = id.estimate(&data, &mut watch.callback())?;
            let extra = json!({"input": ["x"], "output": ["y"]});
            watch
                .finish(report::cascade_report(
                    "identify cascade",
                    &fit,
                    &data,
                    source(),
                    extra,
                )?)
                .to_json()
        },
    )
}

/// Identifies a Coleman–Hodgdon hysteresis alone (separated regression, then output error).
#[pyfunction]
#[pyo3(signature = (x, y, hysteresis, ts, initial_output, threads=0, time_limit=None, progress=None))]
#[allow(clippy::too_many_arguments)] // the Python keyword arguments, one each
fn identify_hysteresis(
    py: Python<'_>,
    x: PyReadonlyArray1<'_, f64>,
    y: PyReadonlyArray1<'_, f64>,
    hysteresis: &str,
    ts: f64,
    initial_output: &str,
    threads: usize,
    time_limit: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let (x, y) = (samples(&x), samples(&y));
    let hysteresis = hysteresis.to_string();
    let initial = match initial_output {
        "measured" => InitialOutput::Measured,
        "zero" => InitialOutput::Zero,
        other => {
            return Err(crate::errors::named(
                py,
                "ConfigError",
                format!("initial_output='{other}': use 'measured' or 'zero'"),
            ))
        }
    };
    run_on(
        py,
        threads,
        watching(py, time_limit, progress)?,
        move |watch| {
            let form = ChForm::parse(&hysteresis)?;
            let data = id_data(ts, vec![x], vec![y])?;
            let mut id = HysteresisIdentification::new(form);
            id.initial = initial;
            let fit = id.estimate(&data, &mut watch.callback())?;
            watch
                .finish(report::hysteresis_report(&fit, &data, source(), initial)?)
                .to_json()
        },
    )
}

/// The default parameters of a built-in grey-box model:
/// [(name, value, lower, upper, fixed, unit)], the state names and the input count.
#[pyfunction]
fn model_parameters(py: Python<'_>, kind: &str) -> PyResult<(Vec<ParamTuple>, Vec<String>, usize)> {
    guard(py, || {
        let model = models::by_kind(kind)?;
        let params = model
            .parameters()
            .iter()
            .map(|p| {
                (
                    p.name.clone(),
                    p.value,
                    p.min,
                    p.max,
                    p.fixed,
                    p.unit.clone(),
                )
            })
            .collect();
        let states = model.states().into_iter().map(|c| c.name).collect();
        Ok((params, states, model.inputs().len()))
    })
}

/// A parameter set from Python's tuples.
pub fn parameter_set(params: &[ParamTuple]) -> Result<ParameterSet> {
    ParameterSet::new(
        params
            .iter()
            .map(|(name, value, lo, hi, fixed, unit)| {
                Parameter::new(name.clone(), *value)
                    .bounds(*lo, *hi)
                    .fixed(*fixed)
                    .unit(unit.clone())
            })
            .collect(),
    )
}

/// The simulation settings named by Python: integrator `rk4` or `newmark` with sub-steps,
/// interpolation `zoh`, `linear` or `band-limited`.
pub fn simulation(integrator: &str, substeps: usize, interpolation: &str) -> Result<Simulation> {
    let substeps = substeps.max(1);
    let integrator = match integrator {
        "rk4" => Integrator::Rk4 { substeps },
        "newmark" => Integrator::Newmark { substeps },
        other => {
            return Err(Error::invalid_option(
                "integrator",
                other,
                format!("integrator='{other}': use 'rk4' or 'newmark'"),
            ))
        }
    };
    let interpolation = match interpolation {
        "zoh" => InputInterpolation::ZeroOrderHold,
        "linear" => InputInterpolation::Linear,
        "band-limited" | "band_limited" => InputInterpolation::BandLimited,
        other => {
            return Err(Error::invalid_option(
                "interpolation",
                other,
                format!("interpolation='{other}': use 'zoh', 'linear' or 'band-limited'"),
            ))
        }
    };
    Ok(Simulation {
        integrator,
        interpolation,
    })
}

/// The grey-box estimation settings.
pub fn estimation(sim: Simulation, starts: usize, seed: u64, watch: &Watch) -> GreyBoxEstimation {
    GreyBoxEstimation {
        simulation: sim,
        starts: starts.max(1),
        seed,
        observer: watch.observer(),
        ..GreyBoxEstimation::default()
    }
}

/// Output-error fit of a built-in grey-box model (`bouc-wen`, `rigid-body`, …).
#[pyfunction]
#[pyo3(signature = (kind, u, y, ts, params, starts, seed, integrator, substeps, interpolation, threads=0, time_limit=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn greybox_fit(
    py: Python<'_>,
    kind: &str,
    u: Vec<PyReadonlyArray1<'_, f64>>,
    y: Vec<PyReadonlyArray1<'_, f64>>,
    ts: f64,
    params: Vec<ParamTuple>,
    starts: usize,
    seed: u64,
    integrator: &str,
    substeps: usize,
    interpolation: &str,
    threads: usize,
    time_limit: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let u: Vec<Vec<f64>> = u.iter().map(samples).collect();
    let y: Vec<Vec<f64>> = y.iter().map(samples).collect();
    let (kind, integrator, interpolation) = (
        kind.to_string(),
        integrator.to_string(),
        interpolation.to_string(),
    );
    run_on(
        py,
        threads,
        watching(py, time_limit, progress)?,
        move |watch| {
            let model: Arc<dyn StateSpaceModel> = Arc::from(models::by_kind(&kind)?);
            let sim = simulation(&integrator, substeps, &interpolation)?;
            let data = id_data(ts, u, y)?;
            let params = parameter_set(&params)?;
            let n_states = model.states().len();
            let fit = estimation(sim, starts, seed, watch).estimate(
                model.clone(),
                &data,
                &params,
                InitialStates::at_rest(n_states, 1),
                &mut watch.callback(),
            )?;
            let fitted = fit.fitted_model(model.as_ref(), sim);
            let extra = json!({"residual_analysis": report::greybox_residuals(&fit, &data), "sensitivity": null});
            let report = report::greybox_report(
                "greybox fit",
                &fit,
                &data,
                source(),
                fitted.to_file(),
                extra,
            )?;
            watch.finish(report).to_json()
        },
    )
}

/// The Bouc–Wen benchmark of Noël & Schoukens (2016): fit on the training record, e_RMS
/// (the RMS simulation error) on each test record.
#[pyfunction]
#[pyo3(signature = (u, y, ts, params, tests, steady_state, starts, seed, substeps, threads=0, time_limit=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn benchmark_bouc_wen(
    py: Python<'_>,
    u: PyReadonlyArray1<'_, f64>,
    y: PyReadonlyArray1<'_, f64>,
    ts: f64,
    params: Vec<ParamTuple>,
    tests: Vec<TestRecord<'_>>,
    steady_state: bool,
    starts: usize,
    seed: u64,
    substeps: usize,
    threads: usize,
    time_limit: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let (u, y) = (samples(&u), samples(&y));
    let tests: Vec<(Vec<f64>, Vec<f64>, f64, String)> = tests
        .iter()
        .map(|(u, y, ts, name)| (samples(u), samples(y), *ts, name.clone()))
        .collect();
    run_on(
        py,
        threads,
        watching(py, time_limit, progress)?,
        move |watch| {
            // The library's benchmark settings (integrator, the LM's stopping rule), so that
            // the fit is the CLI's `benchmark bouc-wen` to the bit.
            let benchmark = BoucWenBenchmark {
                substeps,
                starts,
                seed,
                steady_state,
                observer: watch.observer(),
            };
            let sim = benchmark.simulation();
            let data = id_data(ts, vec![u], vec![y])?;
            let params = parameter_set(&params)?;
            let model = models::BoucWen;
            let fit = benchmark.estimation().estimate(
                Arc::new(model),
                &data,
                &params,
                InitialStates::at_rest(3, 1),
                &mut watch.callback(),
            )?;
            let fitted = fit.fitted_model(&model, sim);
            let validation = tests
                .iter()
                .map(|(u, y, ts, name)| score(&fitted, u, y, *ts, name, steady_state))
                .collect::<Result<Vec<_>>>()?;
            let report = report::bouc_wen_benchmark_report(
                &fit,
                &data,
                source(),
                fitted.to_file(),
                validation,
                steady_state,
            )?;
            watch.finish(report).to_json()
        },
    )
}

/// e_RMS of `model` on one test record, from rest or in the periodic steady state (the
/// input applied twice, the second period scored).
fn score(
    model: &FittedModel,
    u: &[f64],
    y: &[f64],
    ts: f64,
    name: &str,
    steady_state: bool,
) -> Result<ValidationEntry> {
    if u.len() != y.len() || u.is_empty() {
        return Err(Error::InvalidData(format!(
            "test record {name}: u has {} samples and y {}; give equal, non-zero lengths",
            u.len(),
            y.len()
        )));
    }
    id_data(ts, vec![u.to_vec()], vec![y.to_vec()])?;
    let yhat = if steady_state {
        let twice: Vec<f64> = u.iter().chain(u).copied().collect();
        model.simulate(&[&twice], ts, None)?.remove(0)[u.len()..].to_vec()
    } else {
        model.simulate(&[u], ts, None)?.remove(0)
    };
    ValidationEntry::of(name.to_string(), y, &yhat, Some(metrics::rmse(y, &yhat)))
}

/// Rigid-body least squares (the paper's step 1): filtered position, velocity and
/// acceleration, force = g·u regressed on inertia, viscous and Coulomb friction.
#[pyfunction]
#[pyo3(signature = (q, u, ts, gain, offset, cutoff_hz, order, decimation, border, inertia_name, threads=0, time_limit=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn rigid_body_ls(
    py: Python<'_>,
    q: PyReadonlyArray1<'_, f64>,
    u: PyReadonlyArray1<'_, f64>,
    ts: f64,
    gain: f64,
    offset: bool,
    cutoff_hz: f64,
    order: usize,
    decimation: usize,
    border: usize,
    inertia_name: String,
    threads: usize,
    time_limit: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let (q, u) = (samples(&q), samples(&u));
    run_on(
        py,
        threads,
        watching(py, time_limit, progress)?,
        move |_| {
            let clock = std::time::Instant::now();
            // Checks the record (finite, equal lengths, enough samples) as for every recipe.
            id_data(ts, vec![u.clone()], vec![q.clone()])?;
            let ls = RigidBodyLs {
                inertia_name,
                gain,
                offset,
                cutoff_hz,
                filter_order: order,
                decimation,
                border,
            };
            let e = ls.estimate(&q, &u, ts)?;
            let settings = json!({"position": "q", "input": "u"});
            let elapsed = clock.elapsed().as_secs_f64();
            let source = source().remove(0);
            let record = report::RigidBodyRecord {
                source: &source,
                q: &q,
                u: &u,
                ts,
            };
            report::rigid_body_report(&e, &ls, record, &[], elapsed, settings)?.to_json()
        },
    )
}

/// Simulates a saved model (`hysid.model/1` JSON) for the input channels `inputs`; an
/// equation model's tapes run by `evaluator` (auto, native, cc or tape; None:
/// `HYSID_EVALUATOR`, else auto).
#[pyfunction]
#[pyo3(signature = (model_json, inputs, ts, y0=None, evaluator=None))]
fn simulate_model<'py>(
    py: Python<'py>,
    model_json: &str,
    inputs: Vec<PyReadonlyArray1<'py, f64>>,
    ts: f64,
    y0: Option<f64>,
    evaluator: Option<&str>,
) -> PyResult<Vec<Bound<'py, PyArray1<f64>>>> {
    let inputs: Vec<Vec<f64>> = inputs.iter().map(samples).collect();
    let model_json = model_json.to_string();
    let evaluator = evaluator.map(str::to_string);
    let outputs = run(py, move || {
        let evaluator = match &evaluator {
            Some(name) => name.parse::<hysid::model::greybox::native::Evaluator>()?,
            None => hysid::model::greybox::native::Evaluator::from_env()?,
        };
        let model = FittedModel::from_file(&parse_model(&model_json)?)?.with_evaluator(evaluator);
        crate::user_model::check_inputs(&inputs, ts)?;
        let refs: Vec<&[f64]> = inputs.iter().map(Vec::as_slice).collect();
        model.simulate(&refs, ts, y0)
    })?;
    Ok(outputs
        .into_iter()
        .map(|o| PyArray1::from_vec(py, o))
        .collect())
}

/// A model file's JSON, parsed.
pub fn parse_model(text: &str) -> Result<ModelFile> {
    serde_json::from_str(text)
        .map_err(|e| Error::InvalidModel(format!("not a hysid.model/1 model file: {e}")))
}

/// Reads a model file the CLI wrote; returns its JSON (checked by rebuilding the model).
#[pyfunction]
fn load_model(py: Python<'_>, path: std::path::PathBuf) -> PyResult<String> {
    guard(py, || {
        // The file as written, checked: its sample time and columns included.
        let file = ModelFile::load(&path)?;
        serde_json::to_string(&file).map_err(|e| Error::Serialization(format!("model: {e}")))
    })
}

/// Checks a model file's JSON (rebuilds the model) and returns it normalised.
#[pyfunction]
fn check_model(py: Python<'_>, model_json: &str) -> PyResult<String> {
    guard(py, || {
        let file = parse_model(model_json)?;
        let model = FittedModel::from_file(&file)?;
        let saved = ModelFile {
            input_range: file.input_range.clone(),
            ..model.to_file()
        };
        let saved = match (file.sample_time, file.columns) {
            (Some(ts), Some(columns)) => saved.with_data(ts, columns),
            (ts, columns) => ModelFile {
                sample_time: ts,
                columns,
                ..saved
            },
        };
        serde_json::to_string_pretty(&saved)
            .map_err(|e| Error::Serialization(format!("model: {e}")))
    })
}

/// The residual analysis of the simulated output `yhat` against the measured `y` for input
/// `u` (auto-correlation of the residual, its cross-correlation with the input, the 99 %
/// band; `max_lag` lags) as JSON text: what the grey-box reports hold in
/// `details.residual_analysis`.
#[pyfunction]
fn residual_analysis(
    py: Python<'_>,
    u: PyReadonlyArray1<'_, f64>,
    y: PyReadonlyArray1<'_, f64>,
    yhat: PyReadonlyArray1<'_, f64>,
    ts: f64,
    max_lag: usize,
) -> PyResult<String> {
    let (u, y, yhat) = (samples(&u), samples(&y), samples(&yhat));
    guard(py, || {
        if yhat.len() != y.len() {
            return Err(Error::InvalidData(format!(
                "the simulated output has {} samples and the measured {}; give equal lengths",
                yhat.len(),
                y.len()
            )));
        }
        let data = id_data(ts, vec![u], vec![y])?;
        let analysis = hysid::identify::validate::residual_analysis(&data, 0, 0, &yhat, max_lag);
        serde_json::to_string(&analysis)
            .map_err(|e| Error::Serialization(format!("residual analysis: {e}")))
    })
}
