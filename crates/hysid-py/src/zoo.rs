//! The hysteresis model zoo behind `hysid.identify_operator`, `hysid.compare`,
//! `hysid.compensate`, the operator cascades of `hysid.identify_cascade` and
//! `hysid.FAMILIES`: the families are the library's registry
//! (`hysid::model::operators::Family`), the reports the ones `hysid identify operator`,
//! `hysid compare`, `hysid compensate` and `hysid identify cascade --hysteresis FAMILY` write.

use crate::errors::guard;
use crate::pool::run_on;
use crate::recipes::{id_data, parse_model, samples, source};
use crate::watch::watching;
use hysid::data::IdData;
use hysid::identify::operator_cascade::OperatorCascadeIdentification;
use hysid::identify::operators::{
    compare as compare_families, fit_operator, CompareOptions, EnvelopeChoice, Family,
    FamilyOptions, FamilySetting, Split,
};
use hysid::model::compensate::compensate_within;
use hysid::model::operators::{InitialState, LoopOrientation};
use hysid::model::saved::FittedModel;
use hysid::report;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use serde_json::json;

/// Registers this module's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(families, m)?)?;
    m.add_function(wrap_pyfunction!(identify_operator, m)?)?;
    m.add_function(wrap_pyfunction!(identify_operator_cascade, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(compensate, m)?)?;
    Ok(())
}

/// Every family of the registry: [(name, model and reference)], in the registry's order.
#[pyfunction]
fn families() -> Vec<(&'static str, &'static str)> {
    Family::ALL.iter().map(|f| (f.name(), f.title())).collect()
}

/// The recipes' options as Python passes them: `threshold_grid` empty means the uniform
/// grid of `thresholds` thresholds; `None` sizes are chosen from the data, as the command
/// line does without `--thresholds`/`--grid` (a given size fixes the model as given).
fn family_options(
    thresholds: Option<usize>,
    threshold_grid: Vec<f64>,
    grid: Option<usize>,
    lambda: f64,
    dead_zones: Option<usize>,
) -> FamilyOptions {
    let defaults = FamilyOptions::default();
    let choose_thresholds = thresholds.is_none() && threshold_grid.is_empty();
    FamilyOptions {
        thresholds: if threshold_grid.is_empty() {
            thresholds.unwrap_or(defaults.thresholds)
        } else {
            threshold_grid.len()
        },
        threshold_grid: (!threshold_grid.is_empty()).then_some(threshold_grid),
        grid: grid.unwrap_or(defaults.grid),
        lambda,
        dead_zones: dead_zones.unwrap_or(defaults.dead_zones),
        choose_dead_zones: dead_zones.is_none(),
        choose_thresholds,
        choose_grid: grid.is_none(),
        ..defaults
    }
}

/// The turning sense Python gives (`"ccw"`, `"cw"`), None to detect it.
fn loop_orientation(text: Option<&str>) -> hysid::Result<Option<LoopOrientation>> {
    text.map(LoopOrientation::parse).transpose()
}

/// The initial state Python asks for (`"demagnetised"`, `"descending"`, `"ascending"`,
/// `"estimate"`), None for the default `estimate`.
fn requested_state(text: Option<&str>) -> hysid::Result<InitialState> {
    text.map_or(Ok(InitialState::Estimate), InitialState::parse)
}

/// The PI's static envelope Python asks for (`"auto"`, `"none"`, `"cubic"`), None for the
/// default `auto`.
fn requested_envelope(text: Option<&str>) -> hysid::Result<EnvelopeChoice> {
    text.map_or(Ok(EnvelopeChoice::Auto), EnvelopeChoice::parse)
}

/// Fits the hysteresis family `family` to input `u` and output `y`: the report of `hysid
/// identify operator` as JSON text. `threshold_grid` empty: the uniform grid of
/// `thresholds`.
#[pyfunction]
#[pyo3(signature = (u, y, family, ts, thresholds, threshold_grid, grid, lambda_, dead_zones, threads=0, orientation=None, time_limit=None, progress=None, initial_state=None, envelope=None))]
#[allow(clippy::too_many_arguments)] // the Python keyword arguments, one each
fn identify_operator(
    py: Python<'_>,
    u: PyReadonlyArray1<'_, f64>,
    y: PyReadonlyArray1<'_, f64>,
    family: &str,
    ts: f64,
    thresholds: Option<usize>,
    threshold_grid: Vec<f64>,
    grid: Option<usize>,
    lambda_: f64,
    dead_zones: Option<usize>,
    threads: usize,
    orientation: Option<&str>,
    time_limit: Option<f64>,
    progress: Option<Py<PyAny>>,
    initial_state: Option<&str>,
    envelope: Option<&str>,
) -> PyResult<String> {
    let (u, y) = (samples(&u), samples(&y));
    let family = guard(py, || Family::parse(family))?;
    let mut options = family_options(thresholds, threshold_grid, grid, lambda_, dead_zones);
    options.loop_orientation = guard(py, || loop_orientation(orientation))?;
    options.initial_state = guard(py, || requested_state(initial_state))?;
    options.envelope = guard(py, || requested_envelope(envelope))?;
    if options.envelope != EnvelopeChoice::Auto
        && !family.settings().contains(&FamilySetting::Envelope)
    {
        return guard(py, || {
            Err(hysid::Error::invalid_option(
                "envelope",
                options.envelope.name(),
                format!("the static envelope is a pi option, not {family}'s; leave it out"),
            ))
        });
    }
    run_on(
        py,
        threads,
        watching(py, time_limit, progress)?,
        move |watch| {
            let data = id_data(ts, vec![u], vec![y])?;
            let options = FamilyOptions {
                observer: watch.observer(),
                ..options
            };
            watch
                .finish(operator_report(family, &data, &options)?)
                .to_json()
        },
    )
}

/// `family` fitted to the first experiment of `data`, and its `identify operator` report.
fn operator_report(
    family: Family,
    data: &IdData,
    options: &FamilyOptions,
) -> hysid::Result<report::Report> {
    let exp = data.experiment(0);
    let fitted = fit_operator(family, exp.input(0), exp.output(0), options)?;
    let simulated = report::operator_simulation(&fitted, data)?;
    report::operator_report(&fitted, data, &simulated, source())
}

/// Identifies an operator of `family` (not ch4/ch6) followed by a linear block with `na`,
/// `nb` coefficients and delay `delay`: the report of `hysid identify cascade --hysteresis
/// FAMILY` as JSON text.
#[pyfunction]
#[pyo3(signature = (x, y, family, na, nb, delay, ts, thresholds, grid, threads=0, orientation=None, time_limit=None, progress=None))]
#[allow(clippy::too_many_arguments)] // the Python keyword arguments, one each
fn identify_operator_cascade(
    py: Python<'_>,
    x: PyReadonlyArray1<'_, f64>,
    y: PyReadonlyArray1<'_, f64>,
    family: &str,
    na: usize,
    nb: usize,
    delay: usize,
    ts: f64,
    thresholds: usize,
    grid: usize,
    threads: usize,
    orientation: Option<&str>,
    time_limit: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let (x, y) = (samples(&x), samples(&y));
    let family = guard(py, || Family::parse_operator(family))?;
    let loop_orientation = guard(py, || loop_orientation(orientation))?;
    run_on(
        py,
        threads,
        watching(py, time_limit, progress)?,
        move |watch| {
            let data = id_data(ts, vec![x], vec![y])?;
            let mut id = OperatorCascadeIdentification::new(family, na, nb, delay);
            id.options = FamilyOptions {
                thresholds,
                grid,
                loop_orientation,
                observer: watch.observer(),
                choose_thresholds: false,
                choose_grid: false,
                ..FamilyOptions::default()
            };
            let fit = id.estimate(&data, &mut watch.callback())?;
            let extra = json!({"input": ["x"], "output": ["y"]});
            let report =
                report::operator_cascade_report(family.name(), &fit, &data, source(), extra)?;
            watch.finish(report).to_json()
        },
    )
}

/// What `compare` returns: the `hysid compare` report; per family in the ranked order,
/// (name, its `identify operator` report on the training samples, or None when it failed);
/// the validation samples' input and output; each family's simulated validation output.
type Compared<'py> = (
    String,
    Vec<(String, Option<String>)>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Vec<Bound<'py, PyArray1<f64>>>,
);

/// Fits `families` to (u, y) and ranks them by validation fit % on (u_val, y_val), or on
/// the last 40 % of (u, y) when those are None (`hysid compare`).
#[pyfunction]
#[pyo3(signature = (u, y, u_val, y_val, families, ts, thresholds, threshold_grid, grid, lambda_, dead_zones, threads=0, orientation=None, time_limit=None, progress=None, initial_state=None, envelope=None))]
#[allow(clippy::too_many_arguments)] // the Python keyword arguments, one each
fn compare<'py>(
    py: Python<'py>,
    u: PyReadonlyArray1<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    u_val: Option<PyReadonlyArray1<'py, f64>>,
    y_val: Option<PyReadonlyArray1<'py, f64>>,
    families: Vec<String>,
    ts: f64,
    thresholds: Option<usize>,
    threshold_grid: Vec<f64>,
    grid: Option<usize>,
    lambda_: f64,
    dead_zones: Option<usize>,
    threads: usize,
    orientation: Option<&str>,
    time_limit: Option<f64>,
    progress: Option<Py<PyAny>>,
    initial_state: Option<&str>,
    envelope: Option<&str>,
) -> PyResult<Compared<'py>> {
    let (u, y) = (samples(&u), samples(&y));
    let validation = u_val.zip(y_val).map(|(a, b)| (samples(&a), samples(&b)));
    let families = guard(py, || families.iter().map(|f| Family::parse(f)).collect())?;
    let loop_orientation = guard(py, || loop_orientation(orientation))?;
    let initial_state = guard(py, || requested_state(initial_state))?;
    let envelope = guard(py, || requested_envelope(envelope))?;
    let options = CompareOptions {
        families,
        family: FamilyOptions {
            loop_orientation,
            initial_state,
            envelope,
            ..family_options(thresholds, threshold_grid, grid, lambda_, dead_zones)
        },
        ..CompareOptions::default()
    };
    let (text, results, comparison) = run_on(
        py,
        threads,
        watching(py, time_limit, progress)?,
        move |watch| {
            let data = id_data(ts, vec![u.clone()], vec![y.clone()])?;
            let held_out = validation
                .as_ref()
                .map(|(a, b)| (a.as_slice(), b.as_slice()));
            let mut options = options;
            options.family.observer = watch.observer();
            let comparison = compare_families(&u, &y, held_out, &options)?;
            let what = if held_out.is_some() {
                "validation record"
            } else {
                "validation samples"
            };
            let text = watch
                .finish(report::compare_report(&data, &comparison, source(), what)?)
                .to_json()?;
            let train = match comparison.split {
                Split::Fraction { train, .. } => train,
                Split::Record { train, .. } => train,
            };
            let train_data = id_data(ts, vec![u[..train].to_vec()], vec![y[..train].to_vec()])?;
            let results = comparison
                .rows
                .iter()
                .map(|row| {
                    let text = match &row.fitted {
                        Some(fitted) => {
                            let simulated = report::operator_simulation(fitted, &train_data)?;
                            let r =
                                report::operator_report(fitted, &train_data, &simulated, source())?;
                            Some(r.to_json()?)
                        }
                        None => None,
                    };
                    Ok((row.family.to_string(), text))
                })
                .collect::<hysid::Result<Vec<_>>>()?;
            Ok((text, results, comparison))
        },
    )?;
    let simulated = comparison
        .rows
        .iter()
        .map(|r| PyArray1::from_slice(py, &r.validation_simulated))
        .collect();
    Ok((
        text,
        results,
        PyArray1::from_slice(py, &comparison.validation_input),
        PyArray1::from_slice(py, &comparison.validation_output),
        simulated,
    ))
}

/// What `compensate` returns: the `hysid compensate` report (the clipped samples in its
/// details), the compensating input u, the model's output for it.
type Compensated<'py> = (String, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// The command limits of a compensator of `file`: `given` (lo, hi), else the file's
/// `input_range`, else none.
pub(crate) fn limits_of(
    file: &hysid::model::saved::ModelFile,
    given: Option<(f64, f64)>,
) -> hysid::Result<Option<hysid::model::limits::Limits>> {
    match given {
        Some((lo, hi)) => hysid::model::limits::Limits::new(lo, hi).map(Some),
        None => Ok(file.limits()),
    }
}

/// The input that makes the model `model_json` follow `reference` (`hysid compensate`), the
/// command limited to `limits` (lo, hi), else to the file's `input_range`, else not at all.
#[pyfunction]
#[pyo3(signature = (model_json, reference, ts, model_source, limits=None))]
fn compensate<'py>(
    py: Python<'py>,
    model_json: &str,
    reference: PyReadonlyArray1<'py, f64>,
    ts: f64,
    model_source: &str,
    limits: Option<(f64, f64)>,
) -> PyResult<Compensated<'py>> {
    let reference = samples(&reference);
    let (model_json, model_source) = (model_json.to_string(), model_source.to_string());
    let (text, c) = crate::errors::run(py, move || {
        let file = parse_model(&model_json)?;
        let limits = limits_of(&file, limits)?;
        let model = FittedModel::from_file(&file)?;
        let data = id_data(ts, vec![reference], Vec::new())?;
        let c = compensate_within(&model, data.experiment(0).input(0), limits)?;
        let r =
            report::compensation_report(&model, &data, &c, source(), "reference", &model_source);
        Ok((r.to_json()?, c))
    })?;
    Ok((
        text,
        PyArray1::from_vec(py, c.u),
        PyArray1::from_vec(py, c.predicted),
    ))
}
