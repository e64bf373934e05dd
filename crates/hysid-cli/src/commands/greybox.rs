//! `hysid greybox fit`: output-error estimation of a built-in grey-box model.

use super::present::{print_fit, print_residuals, print_sensitivity};
use crate::cli::{GreyboxFitArgs, IntegratorArg, InterpolationArg, SimulationArgs};
use crate::commands::identify::load_grouped;
use crate::output::Outputs;
use crate::progress::FitProgress;
use anyhow::{bail, Context, Result};
use hysid::data::{IdData, TimeSteps};
use hysid::identify::greybox::{GreyBoxEstimation, InitialStates};
use hysid::identify::validate::sensitivity_table;
use hysid::model::greybox::equation_model::EquationStateSpace;
use hysid::model::greybox::{models, InputInterpolation, Integrator, Simulation, StateSpaceModel};
use hysid::model::ParameterSet;
use hysid::numerics::LmConfig;
use hysid::report::greybox_report;
use hysid::report::plot::greybox_figures;
use serde_json::json;
use std::sync::Arc;

/// Runs `hysid greybox fit`.
pub fn fit(args: &GreyboxFitArgs) -> Result<()> {
    // A built-in model by name, or an equation file (whose [initial] and text also count).
    if args.model_file.is_none() && args.evaluator.evaluator.is_some() {
        return Err(crate::exit::UsageError(
            "--evaluator chooses how an equation file is evaluated; give it with --model-file, or leave it out".into(),
        )
        .into());
    }
    let equations = match &args.model_file {
        Some(path) => Some(Arc::new(
            EquationStateSpace::load(path)?
                .with_evaluator(crate::options::evaluator(&args.evaluator)?),
        )),
        None => None,
    };
    let model: Arc<dyn StateSpaceModel> = match (&equations, &args.model) {
        (Some(eq), _) => eq.clone(),
        (None, name) => Arc::from(models::by_kind(name.as_deref().unwrap_or_default())?),
    };
    let mut inputs = vec![args.data.data.as_path()];
    inputs.extend(args.model_file.as_deref());
    let mut out = Outputs::new(
        &inputs,
        args.json.as_deref(),
        args.model_out.as_deref(),
        args.plots.as_deref(),
    )?;
    // A model with k inputs and m outputs takes k --input and m --output per experiment.
    let data = load_grouped(
        &args.data,
        model.inputs().len(),
        model.outputs().len(),
        TimeSteps::Uniform,
    )?;
    out.fitted_on(&data);
    let params = configure(
        model.parameters(),
        &args.fix,
        &args.free,
        &args.init,
        &args.bounds,
    )?;
    let mut initial = initial_states(model.as_ref(), &data, &args.estimate_x0)?;
    if let Some(eq) = &equations {
        initial = InitialStates::of_equations(eq, data.n_experiments(), &initial.estimated);
    }
    let default_lm = GreyBoxEstimation::default().lm;
    let estimation = GreyBoxEstimation {
        simulation: simulation(&args.simulation),
        lm: LmConfig {
            // A given --max-iterations is a hard cap.
            max_iterations: args
                .search
                .max_iterations
                .unwrap_or(default_lm.max_iterations),
            extra_iterations: match args.search.max_iterations {
                Some(_) => 0,
                None => default_lm.extra_iterations,
            },
            improvement_tolerance: args.search.tolerance,
            ..default_lm
        },
        starts: args.search.starts.max(1),
        seed: args.search.seed,
        ..GreyBoxEstimation::default()
    };
    let estimated_states = initial.estimated.iter().filter(|e| **e).count();
    let free = params.free_indices().len() + estimated_states * data.n_experiments();
    crate::budget::check(
        "the grey-box fit",
        estimation.work_estimate(
            data.n_samples(),
            model.inputs().len(),
            model.states().len(),
            free,
        ),
    )?;
    let fit = {
        let progress = FitProgress::new("fitting");
        let estimation = GreyBoxEstimation {
            observer: progress.observer(),
            ..estimation
        };
        let mut callback = progress.callback();
        estimation.estimate(model.clone(), &data, &params, initial, &mut callback)?
    };
    print_fit(
        &format!(
            "{} fitted to {} ({} samples)",
            model.kind(),
            args.data.data.display(),
            data.n_samples()
        ),
        &fit,
    );
    let residuals = print_residuals(&fit, &data);
    for warning in fit.warnings() {
        tell!("warning: {warning}");
    }
    let sensitivity = if args.sensitivity {
        let structure = hysid::identify::greybox::GreyBox::new(
            model.clone(),
            &data,
            estimation.simulation,
            fit.initial_states(model.as_ref(), data.n_experiments()),
        )?;
        let rows = sensitivity_table(&structure, &data, &fit.fit.parameters, 0.2)?;
        print_sensitivity(&rows);
        Some(rows)
    } else {
        None
    };
    let mut fitted = fit.fitted_model(model.as_ref(), estimation.simulation);
    if let Some(eq) = &equations {
        fitted = fitted.with_equations(eq.source());
    }
    out.figures(|| greybox_figures(&fit, &data, &residuals))?;
    let extra = json!({"residual_analysis": residuals, "sensitivity": sensitivity});
    let sources = vec![args.data.data.display().to_string()];
    let report = greybox_report("greybox fit", &fit, &data, sources, fitted.to_file(), extra)?;
    out.finish(Some(&report), Some(&fitted))
}

/// `params` with the command line's fixes, frees, initial values and bounds applied.
pub fn configure(
    mut params: ParameterSet,
    fix: &[String],
    free: &[String],
    init: &[String],
    bounds: &[String],
) -> Result<ParameterSet> {
    if let Some(name) = fix.iter().find(|n| free.contains(n)) {
        bail!("--fix {name} and --free {name}: a parameter is either fixed or free; give it to one of them");
    }
    for name in fix {
        params.by_name_mut(name)?.fixed = true;
    }
    for name in free {
        params.by_name_mut(name)?.fixed = false;
    }
    for spec in init {
        let (name, value) = spec
            .split_once('=')
            .with_context(|| format!("--init {spec}: write NAME=VALUE"))?;
        let value = number(value, "--init", spec)?;
        if !value.is_finite() {
            bail!("--init {spec}: the initial value must be finite");
        }
        params.by_name_mut(name.trim())?.value = value;
    }
    for spec in bounds {
        let (name, range) = spec
            .split_once('=')
            .with_context(|| format!("--bounds {spec}: write NAME=LO:HI"))?;
        let (lo, hi) = range
            .split_once(':')
            .with_context(|| format!("--bounds {spec}: write NAME=LO:HI"))?;
        let (lo, hi) = (number(lo, "--bounds", spec)?, number(hi, "--bounds", spec)?);
        let p = params.by_name_mut(name.trim())?;
        // The model's own bounds are its physics (a positive mass): narrow them, never widen.
        if lo < p.min || hi > p.max {
            bail!(
                "--bounds {spec}: the model needs {} within [{}, {}]; give bounds inside that range",
                p.name,
                p.min,
                p.max
            );
        }
        p.min = lo;
        p.max = hi;
    }
    Ok(params)
}

fn number(text: &str, option: &str, spec: &str) -> Result<f64> {
    match text.trim() {
        "inf" | "+inf" => Ok(f64::INFINITY),
        "-inf" => Ok(f64::NEG_INFINITY),
        t => match t.parse::<f64>() {
            Ok(v) if !v.is_nan() => Ok(v),
            _ => bail!("{option} {spec}: '{t}' is not a number"),
        },
    }
}

/// Initial states at rest, with the named ones estimated.
fn initial_states(
    model: &dyn StateSpaceModel,
    data: &IdData,
    estimate: &[String],
) -> Result<InitialStates> {
    let states = model.states();
    let mut initial = InitialStates::at_rest(states.len(), data.n_experiments());
    for name in estimate {
        let Some(i) = states.iter().position(|s| &s.name == name) else {
            let names: Vec<&str> = states.iter().map(|s| s.name.as_str()).collect();
            bail!(
                "--estimate-x0 {name}: the {} model's states are {}",
                model.kind(),
                names.join(", ")
            );
        };
        initial.estimated[i] = true;
    }
    Ok(initial)
}

/// The command line's simulation settings.
pub fn simulation(args: &SimulationArgs) -> Simulation {
    let substeps = args.substeps.max(1);
    Simulation {
        integrator: match args.integrator {
            IntegratorArg::Rk4 => Integrator::Rk4 { substeps },
            IntegratorArg::Newmark => Integrator::Newmark { substeps },
        },
        interpolation: match args.interpolation {
            InterpolationArg::Zoh => InputInterpolation::ZeroOrderHold,
            InterpolationArg::Linear => InputInterpolation::Linear,
            InterpolationArg::BandLimited => InputInterpolation::BandLimited,
        },
    }
}
