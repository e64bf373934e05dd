//! The library recipes behind `hysid.identify_cascade`, `identify_hysteresis`,
//! `greybox_fit` (built-in models), `benchmark_bouc_wen`, `rigid_body_ls`, and model
//! simulation, loading and saving. Each returns JSON text (`hysid.report/1` for a fit,
//! `hysid.model/1` for a model) and runs with the GIL released.
//!
//! The `details` of each report are assembled here as the CLI assembles them (the same
//! keys), until the library offers them itself.

use crate::errors::{guard, run};
use hysid::data::{Channel, Experiment, IdData};
use hysid::identify::cascade::{CascadeFit, CascadeIdentification};
use hysid::identify::greybox::{GreyBoxEstimation, GreyBoxFit, InitialStates};
use hysid::identify::hysteresis::{HysteresisIdentification, InitialOutput};
use hysid::identify::rigid_body::RigidBodyLs;
use hysid::identify::Uncertainty;
use hysid::model::greybox::{models, InputInterpolation, Integrator, Simulation, StateSpaceModel};
use hysid::model::saved::{FittedModel, ModelFile};
use hysid::model::{ChForm, Parameter, ParameterSet};
use hysid::numerics::{metrics, Control, IterationRecord};
use hysid::report::{Report, SearchSummary, UncertaintySummary, ValidationEntry};
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

fn source() -> Vec<String> {
    vec!["python (numpy arrays)".into()]
}

/// Identifies a Coleman–Hodgdon hysteresis + linear-block cascade (Vörös 2015).
#[pyfunction]
#[pyo3(signature = (x, y, hysteresis, na, nb, delay, ts, uncertainty, replicates, seed))]
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
    run(py, move || {
        let form = ChForm::parse(&hysteresis)?;
        let data = id_data(ts, vec![x], vec![y])?;
        let mut id = CascadeIdentification::new(form, na, nb, delay);
        id.uncertainty = uncertainty;
        id.bootstrap_seed = seed;
        let fit = id.estimate(&data, &mut quiet())?;
        cascade_report(&fit, &data, uncertainty)?.to_json()
    })
}

/// The report of a cascade fit (the CLI's `identify cascade` details).
fn cascade_report(fit: &CascadeFit, data: &IdData, uncertainty: Uncertainty) -> Result<Report> {
    let oe = &fit.output_error;
    let fitted = FittedModel::Cascade {
        model: fit.model.clone(),
        std: fit.std(),
    };
    let key_term = fit.key_term.as_ref().map(|k| {
        json!({
            "termination": k.termination.to_string(),
            "iterations": k.history.len().saturating_sub(1),
            "history": k.history,
            "equation_error": k.costs,
        })
    });
    let details = json!({
        "admissibility": fit.model.hysteresis.admissibility(),
        "linear_block_spectral_radius": fit.model.linear.spectral_radius(),
        "threshold": fit.threshold,
        "switching_consistent": fit.switching_consistent,
        "fit_percent_per_experiment": oe.fit_percent,
        "key_term_iteration": key_term,
        "output_error_history": oe.report.history,
        "candidates": fit.candidates.iter().map(|c| json!({"origin": c.origin, "cost": c.cost, "start": c.start, "refined": c.refined})).collect::<Vec<_>>(),
        "asymptotic_std": oe.std(),
        "bootstrap": fit.bootstrap.as_ref().map(|b| json!({"replicates": b.replicates.len(), "failed": b.failed, "std": b.std})),
    });
    let summary = match (uncertainty, &fit.bootstrap) {
        (Uncertainty::Bootstrap(n), Some(b)) => UncertaintySummary::bootstrap(n, b.failed),
        _ => UncertaintySummary::asymptotic(),
    };
    Ok(Report::of_output_error(
        "identify cascade",
        data,
        source(),
        fitted.to_file(),
        oe,
        fit.elapsed_s,
        summary,
    )?
    .with_details(details))
}

/// Identifies a Coleman–Hodgdon hysteresis alone (separated regression, then output error).
#[pyfunction]
#[pyo3(signature = (x, y, hysteresis, ts, initial_output))]
fn identify_hysteresis(
    py: Python<'_>,
    x: PyReadonlyArray1<'_, f64>,
    y: PyReadonlyArray1<'_, f64>,
    hysteresis: &str,
    ts: f64,
    initial_output: &str,
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
    run(py, move || {
        let form = ChForm::parse(&hysteresis)?;
        let data = id_data(ts, vec![x], vec![y])?;
        let mut id = HysteresisIdentification::new(form);
        id.initial = initial;
        let fit = id.estimate(&data, &mut quiet())?;
        let oe = &fit.output_error;
        let fitted = FittedModel::Hysteresis {
            model: fit.model.clone(),
            initial,
            std: fit.std(),
        };
        let details = json!({
            "fit_percent_per_experiment": oe.fit_percent,
            "admissibility": fit.model.admissibility(),
            "threshold": fit.threshold,
            "separated_regression": {
                "d_history": fit.separated.d_history,
                "termination": fit.separated.termination.to_string(),
            },
            "output_error_history": oe.report.history,
        });
        Report::of_output_error(
            "identify hysteresis",
            &data,
            source(),
            fitted.to_file(),
            oe,
            fit.elapsed_s,
            UncertaintySummary::asymptotic(),
        )?
        .with_details(details)
        .to_json()
    })
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
            return Err(Error::Config(format!(
                "integrator='{other}': use 'rk4' or 'newmark'"
            )))
        }
    };
    let interpolation = match interpolation {
        "zoh" => InputInterpolation::ZeroOrderHold,
        "linear" => InputInterpolation::Linear,
        "band-limited" | "band_limited" => InputInterpolation::BandLimited,
        other => {
            return Err(Error::Config(format!(
                "interpolation='{other}': use 'zoh', 'linear' or 'band-limited'"
            )))
        }
    };
    Ok(Simulation {
        integrator,
        interpolation,
    })
}

/// The grey-box estimation settings.
pub fn estimation(sim: Simulation, starts: usize, seed: u64) -> GreyBoxEstimation {
    GreyBoxEstimation {
        simulation: sim,
        starts: starts.max(1),
        seed,
        ..GreyBoxEstimation::default()
    }
}

/// The model file of a fitted grey-box model: its own parameters, their std, the first
/// experiment's initial state.
pub fn fitted_greybox(
    kind: &str,
    n_params: usize,
    n_states: usize,
    fit: &GreyBoxFit,
    sim: Simulation,
) -> Result<FittedModel> {
    let all = &fit.fit.parameters;
    let parameters = ParameterSet::new(all.iter().take(n_params).cloned().collect())?;
    let values = all.values();
    Ok(FittedModel::GreyBox {
        kind: kind.to_string(),
        parameters,
        std: fit.fit.std()[..n_params].to_vec(),
        simulation: sim,
        initial_state: values[n_params..n_params + n_states].to_vec(),
    })
}

/// The report of a grey-box fit (the CLI's `greybox fit` details, without the residual
/// analysis and sensitivity table).
pub fn greybox_report(
    command: &str,
    fit: &GreyBoxFit,
    data: &IdData,
    model: ModelFile,
    extra: serde_json::Value,
) -> Result<Report> {
    let oe = &fit.fit;
    let n = oe.parameters.len();
    let correlation: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| oe.covariance.correlation[(i, j)]).collect())
        .collect();
    let mut details = json!({
        "fit_percent_per_experiment": oe.fit_percent,
        "mse_per_experiment": oe.mse,
        "function_evaluations": oe.report.function_evaluations,
        "rejected_trials": oe.report.rejected_trials,
        "correlation": correlation,
        "history": oe.report.history,
        "starts": fit.starts,
    });
    if let (Some(obj), serde_json::Value::Object(more)) = (details.as_object_mut(), extra) {
        obj.extend(more);
    }
    Ok(Report::of_output_error(
        command,
        data,
        source(),
        model,
        oe,
        fit.elapsed_s,
        UncertaintySummary::asymptotic(),
    )?
    .with_details(details))
}

/// Output-error fit of a built-in grey-box model (`bouc-wen`, `rigid-body`, …).
#[pyfunction]
#[pyo3(signature = (kind, u, y, ts, params, starts, seed, integrator, substeps, interpolation))]
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
) -> PyResult<String> {
    let u: Vec<Vec<f64>> = u.iter().map(samples).collect();
    let y: Vec<Vec<f64>> = y.iter().map(samples).collect();
    let (kind, integrator, interpolation) = (
        kind.to_string(),
        integrator.to_string(),
        interpolation.to_string(),
    );
    run(py, move || {
        let model: Arc<dyn StateSpaceModel> = Arc::from(models::by_kind(&kind)?);
        let sim = simulation(&integrator, substeps, &interpolation)?;
        let data = id_data(ts, u, y)?;
        let params = parameter_set(&params)?;
        let n_states = model.states().len();
        let fit = estimation(sim, starts, seed).estimate(
            model.clone(),
            &data,
            &params,
            InitialStates::at_rest(n_states, 1),
            &mut quiet(),
        )?;
        let fitted = fitted_greybox(model.kind(), params.len(), n_states, &fit, sim)?;
        greybox_report("greybox fit", &fit, &data, fitted.to_file(), json!({}))?.to_json()
    })
}

/// The Bouc–Wen benchmark of Noël & Schoukens (2016): fit on the training record, e_RMS
/// (the RMS simulation error) on each test record.
#[pyfunction]
#[pyo3(signature = (u, y, ts, params, tests, steady_state, starts, seed, substeps))]
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
) -> PyResult<String> {
    let (u, y) = (samples(&u), samples(&y));
    let tests: Vec<(Vec<f64>, Vec<f64>, f64, String)> = tests
        .iter()
        .map(|(u, y, ts, name)| (samples(u), samples(y), *ts, name.clone()))
        .collect();
    run(py, move || {
        let sim = Simulation {
            integrator: Integrator::Rk4 {
                substeps: substeps.max(1),
            },
            interpolation: InputInterpolation::BandLimited,
        };
        let data = id_data(ts, vec![u], vec![y])?;
        let params = parameter_set(&params)?;
        let model = models::BoucWen;
        let fit = estimation(sim, starts, seed).estimate(
            Arc::new(model),
            &data,
            &params,
            InitialStates::at_rest(3, 1),
            &mut quiet(),
        )?;
        let fitted = fitted_greybox(model.kind(), params.len(), 3, &fit, sim)?;
        let validation = tests
            .iter()
            .map(|(u, y, ts, name)| score(&fitted, u, y, *ts, name, steady_state))
            .collect::<Result<Vec<_>>>()?;
        let extra = json!({
            "training_e_rms": fit.fit.mse[0][0].sqrt(),
            "tests": validation.iter().map(|t| json!({"file": t.source, "e_rms": t.e_rms, "fit_percent": t.fit_percent, "samples": t.samples})).collect::<Vec<_>>(),
        });
        let mut report =
            greybox_report("benchmark bouc-wen", &fit, &data, fitted.to_file(), extra)?;
        report.validation = validation;
        report.to_json()
    })
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
#[pyo3(signature = (q, u, ts, gain, offset, cutoff_hz, order, decimation, border, inertia_name))]
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
) -> PyResult<String> {
    let (q, u) = (samples(&q), samples(&u));
    run(py, move || {
        let clock = std::time::Instant::now();
        let data = id_data(ts, vec![u.clone()], vec![q.clone()])?;
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
        let records = (0..e.names.len())
            .map(|i| json!({"name": e.names[i], "value": e.values[i], "std": e.std[i], "unit": "", "fixed": false, "lower": null, "upper": null}))
            .collect::<Vec<_>>();
        let model: ModelFile = serde_json::from_value(json!({
            "schema": "hysid.model/1", "kind": "rigid_body_ls", "parameters": records,
            "hysteresis": null, "delay": null, "initial_output": null, "simulation": null, "initial_state": null,
        }))
        .map_err(|err| Error::Config(format!("rigid-body model record: {err}")))?;
        let mut report = Report::new("rigid-body ls");
        report.data = Some(hysid::report::DataSummary::of(&data, source()));
        report.model = Some(model);
        report.search = Some(SearchSummary::direct(clock.elapsed().as_secs_f64()));
        report.uncertainty = Some(UncertaintySummary::least_squares());
        report.details = json!({
            "relative_error_percent": e.relative_error_percent,
            "relative_std_percent": e.relative_std_percent,
            "condition_number": e.condition_number_unscaled,
            "condition_number_scaled": e.condition_number,
            "equations": e.equations,
        });
        report.to_json()
    })
}

/// Simulates a saved model (`hysid.model/1` JSON) for the input channels `inputs`.
#[pyfunction]
#[pyo3(signature = (model_json, inputs, ts, y0=None))]
fn simulate_model<'py>(
    py: Python<'py>,
    model_json: &str,
    inputs: Vec<PyReadonlyArray1<'py, f64>>,
    ts: f64,
    y0: Option<f64>,
) -> PyResult<Vec<Bound<'py, PyArray1<f64>>>> {
    let inputs: Vec<Vec<f64>> = inputs.iter().map(samples).collect();
    let model_json = model_json.to_string();
    let outputs = run(py, move || {
        let model = FittedModel::from_file(&parse_model(&model_json)?)?;
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
fn parse_model(text: &str) -> Result<ModelFile> {
    serde_json::from_str(text)
        .map_err(|e| Error::Config(format!("not a hysid.model/1 model file: {e}")))
}

/// Reads a model file the CLI wrote; returns its JSON (checked by rebuilding the model).
#[pyfunction]
fn load_model(py: Python<'_>, path: std::path::PathBuf) -> PyResult<String> {
    guard(py, || {
        let model = FittedModel::load(&path)?;
        serde_json::to_string(&model.to_file()).map_err(|e| Error::Config(format!("model: {e}")))
    })
}

/// Checks a model file's JSON (rebuilds the model) and returns it normalised.
#[pyfunction]
fn check_model(py: Python<'_>, model_json: &str) -> PyResult<String> {
    guard(py, || {
        let model = FittedModel::from_file(&parse_model(model_json)?)?;
        serde_json::to_string_pretty(&model.to_file())
            .map_err(|e| Error::Config(format!("model: {e}")))
    })
}
