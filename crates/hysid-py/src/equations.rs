//! Grey-box models written as equation files (`hysid.GreyBoxModel.from_equations`): the
//! text of a TOML file with `[model]`, `[parameters]`, `[initial]`, `[let]`, `[equations]`
//! (ẋ = f(t, x, u, θ)) and `[output]` (y = h(x, u, θ)), compiled by `hysid-equations` with
//! symbolic ∂f/∂x, ∂f/∂θ, ∂h/∂x, ∂h/∂θ into flat tapes. The fit integrates the forward
//! sensitivity equations Ṡ = (∂f/∂x)S + ∂f/∂θ through RK4 like a built-in model (L. Ljung,
//! *System Identification: Theory for the User*, 2nd ed., 1999, §4.5, §10.2): no Python
//! callback, exact sensitivities, all cores, the GIL released.
//!
//! The fitted model is saved as the `equations` model kind, which embeds the text: the CLI
//! simulates it (`hysid simulate --model`) and `hysid.load_model` reads it back.

use crate::errors::guard;
use crate::pool::run_on;
use crate::recipes::{estimation, id_data, parameter_set, samples, simulation, source, ParamTuple};
use crate::watch::watching;
use hysid::identify::greybox::InitialStates;
use hysid::model::greybox::equation_model::EquationStateSpace;
use hysid::model::greybox::native::Evaluator;
use hysid::model::greybox::StateSpaceModel;
use hysid::model::saved::FittedEquations;
use hysid::model::saved::FittedModel;
use hysid::{Error, Result};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use serde_json::json;
use std::sync::Arc;

/// Registers this module's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(equation_info, m)?)?;
    m.add_function(wrap_pyfunction!(equation_model_file, m)?)?;
    m.add_function(wrap_pyfunction!(greybox_fit_equations, m)?)?;
    Ok(())
}

/// What Python needs to know of an equation file: its name, parameters
/// [(name, value, lower, upper, fixed, unit)], state, input and output names, initial state
/// and which initial states are estimated.
type EquationInfo = (
    String,
    Vec<ParamTuple>,
    Vec<String>,
    Vec<String>,
    Vec<String>,
    Vec<f64>,
    Vec<bool>,
);

/// Parses and compiles `text` (errors name `origin`, the line and the column).
#[pyfunction]
fn equation_info(py: Python<'_>, text: &str, origin: &str) -> PyResult<EquationInfo> {
    guard(py, || {
        let m = EquationStateSpace::parse(text, origin)?;
        let names = |c: Vec<hysid::data::Channel>| c.into_iter().map(|c| c.name).collect();
        let params = m
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
        Ok((
            m.name().to_string(),
            params,
            names(m.states()),
            names(m.inputs()),
            names(m.outputs()),
            m.initial_values(),
            m.initial_estimated(),
        ))
    })
}

/// The model file (`hysid.model/1`, kind `equations`) of the equation model `text` with the
/// parameters `params`, initial state `x0` and the simulation settings; JSON text.
#[pyfunction]
#[pyo3(signature = (text, params, x0, integrator, substeps, interpolation))]
fn equation_model_file(
    py: Python<'_>,
    text: &str,
    params: Vec<ParamTuple>,
    x0: Vec<f64>,
    integrator: &str,
    substeps: usize,
    interpolation: &str,
) -> PyResult<String> {
    guard(py, || {
        let model = EquationStateSpace::parse(text, "equation model")?;
        let parameters = checked_parameters(&model, &params)?;
        if x0.len() != model.states().len() {
            return Err(Error::CountMismatch {
                model: format!("model '{}'", model.name()),
                what: "states (values of x0)",
                expected: model.states().len(),
                given: x0.len(),
            });
        }
        let file = FittedModel::Equations(FittedEquations {
            equations: text.to_string(),
            std: vec![f64::NAN; parameters.len()],
            parameters,
            simulation: simulation(integrator, substeps, interpolation)?,
            initial_state: x0,
            evaluator: hysid::model::greybox::native::Evaluator::Auto,
        })
        .to_file();
        serde_json::to_string(&file).map_err(|e| Error::Serialization(format!("model: {e}")))
    })
}

/// `params` as a parameter set, refused unless it names the model's parameters in order.
fn checked_parameters(
    model: &EquationStateSpace,
    params: &[ParamTuple],
) -> Result<hysid::model::ParameterSet> {
    let set = parameter_set(params)?;
    let expected = model.parameters().names();
    if set.names() != expected {
        return Err(Error::ModelMismatch(format!(
            "model '{}' has the parameters {}, got {}",
            model.name(),
            expected.join(", "),
            set.names().join(", ")
        )));
    }
    Ok(set)
}

/// Output-error fit of the equation model `text` from the parameters `params`; the initial
/// state is `[initial]` of the file (states with `fixed = false` estimated). Returns the
/// report's JSON (the CLI's `greybox fit --model-file`). `evaluator`: auto, native, cc or tape
/// (None: `HYSID_EVALUATOR`, else auto).
#[pyfunction]
#[pyo3(signature = (text, u, y, ts, params, starts, seed, integrator, substeps, interpolation, threads=0, time_limit=None, progress=None, evaluator=None))]
#[allow(clippy::too_many_arguments)]
fn greybox_fit_equations(
    py: Python<'_>,
    text: &str,
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
    evaluator: Option<&str>,
) -> PyResult<String> {
    let evaluator = evaluator.map(str::to_string);
    let u: Vec<Vec<f64>> = u.iter().map(samples).collect();
    let y: Vec<Vec<f64>> = y.iter().map(samples).collect();
    let (text, integrator, interpolation) = (
        text.to_string(),
        integrator.to_string(),
        interpolation.to_string(),
    );
    run_on(
        py,
        threads,
        watching(py, time_limit, progress)?,
        move |watch| {
            // The evaluator given, else HYSID_EVALUATOR, else auto.
            let evaluator = match &evaluator {
                Some(name) => name.parse::<Evaluator>()?,
                None => Evaluator::from_env()?,
            };
            let eq = Arc::new(
                EquationStateSpace::parse(&text, "equation model")?.with_evaluator(evaluator),
            );
            let model: Arc<dyn StateSpaceModel> = eq.clone();
            let sim = simulation(&integrator, substeps, &interpolation)?;
            let data = id_data(ts, u, y)?;
            let params = checked_parameters(&eq, &params)?;
            let initial = InitialStates::of_equations(&eq, data.n_experiments(), &[]);
            let fit = estimation(sim, starts, seed, watch).estimate(
                model.clone(),
                &data,
                &params,
                initial,
                &mut watch.callback(),
            )?;
            let fitted = fit
                .fitted_model(model.as_ref(), sim)
                .with_equations(eq.source());
            let extra = json!({"residual_analysis": hysid::report::greybox_residuals(&fit, &data), "sensitivity": null});
            let report = hysid::report::greybox_report(
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
