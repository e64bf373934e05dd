//! `hysid identify cascade` and `hysid identify hysteresis`.

use super::cascade::{fitted, print_summary, rows, uncertainty};
use crate::cli::{CascadeArgs, DataArgs, HysteresisArgs, InitialArg, OutputArgs};
use crate::output::Outputs;
use crate::progress::FitProgress;
use crate::report::{figures, print_table, Row};
use anyhow::Result;
use hysid::data::{Channel, CsvSpec, Experiment, IdData, TimeSteps};
use hysid::identify::cascade::CascadeIdentification;
use hysid::identify::hysteresis::{HysteresisIdentification, InitialOutput};
use hysid::model::saved::FittedHysteresis;
use hysid::model::saved::FittedModel;
use hysid::model::ChForm;
use hysid::report::plot::{cascade_figures, hysteresis_figures};
use hysid::report::{cascade_report, hysteresis_report};
use hysid::Error;
use serde_json::json;

/// Reads the input and output columns of a CSV file: one experiment per --input/--output
/// pair, the time column under the rule `steps` (only increasing for a rate-independent
/// model).
pub fn load(args: &DataArgs, steps: TimeSteps) -> Result<IdData> {
    load_grouped(args, 1, 1, steps)
}

/// Reads the input and output columns of a CSV file for a model with `n_inputs` inputs and
/// `n_outputs` outputs: the --input columns are taken `n_inputs` at a time and the --output
/// columns `n_outputs` at a time, in the order given, each group one experiment (for a
/// single-input, single-output model: one experiment per --input/--output pair).
pub fn load_grouped(
    args: &DataArgs,
    n_inputs: usize,
    n_outputs: usize,
    steps: TimeSteps,
) -> Result<IdData> {
    let (ni, no) = (n_inputs.max(1), n_outputs.max(1));
    if (ni, no) == (1, 1) {
        anyhow::ensure!(
            args.input.len() == args.output.len(),
            "give one --output per --input ({} inputs, {} outputs)",
            args.input.len(),
            args.output.len()
        );
    } else {
        let whole = args.input.len().is_multiple_of(ni) && args.output.len().is_multiple_of(no);
        anyhow::ensure!(
            whole && args.input.len() / ni == args.output.len() / no,
            "the model has {ni} input(s) and {no} output(s): give {ni} --input and {no} --output \
             per experiment, in the model's order ({} --input and {} --output given)",
            args.input.len(),
            args.output.len()
        );
    }
    let groups = args.input.chunks(ni).zip(args.output.chunks(no));
    let mut data: Option<IdData> = None;
    for (k, (inputs, outputs)) in groups.enumerate() {
        let spec = CsvSpec {
            inputs: inputs.to_vec(),
            outputs: outputs.to_vec(),
            time: args.time.clone(),
            ts: args.ts,
            time_steps: steps,
        };
        let experiment = IdData::from_file(&args.data, &spec).map_err(|e| match e {
            // The data layer names channels, not files: say which file.
            Error::NonFinite { .. } => anyhow::anyhow!("{}: {e}", args.data.display()),
            other => other.into(),
        })?;
        data = Some(match data {
            None => experiment,
            // Later groups become further experiments under the first group's channel names.
            Some(d) => {
                let renamed = rename(experiment, d.input_channels(), d.output_channels(), k)?;
                d.merge(renamed)?
            }
        });
    }
    data.ok_or_else(|| anyhow::anyhow!("give at least one --input/--output pair"))
}

/// The experiment of `data` under the given channel names, named "experiment k+1".
fn rename(data: IdData, inputs: &[Channel], outputs: &[Channel], k: usize) -> Result<IdData> {
    let exp = data.experiment(0);
    let experiment = Experiment::new(
        format!("experiment {}", k + 1),
        (0..inputs.len()).map(|i| exp.input(i).to_vec()).collect(),
        (0..outputs.len()).map(|o| exp.output(o).to_vec()).collect(),
    )?;
    Ok(IdData::new(
        data.ts(),
        inputs.to_vec(),
        outputs.to_vec(),
        vec![experiment],
    )?)
}

/// `hysid identify cascade`.
pub fn cascade(args: &CascadeArgs) -> Result<()> {
    if !super::cascade::is_coleman_hodgdon(&args.hysteresis) {
        return super::operator_cascade::identify(args);
    }
    let form = ChForm::parse(&args.hysteresis)?;
    anyhow::ensure!(
        args.orientation.is_none(),
        "--orientation applies to the operator families, not {} (the Coleman–Hodgdon \
         hysteresis has no orientation setting)",
        form.short_name()
    );
    let mut out = register(&args.data, &args.output)?;
    let data = load(&args.data, TimeSteps::Uniform)?;
    out.fitted_on(&data);
    let mut id = CascadeIdentification::new(form, args.na, args.nb, args.delay);
    id.uncertainty = uncertainty(args.uncertainty, args.replicates);
    id.bootstrap_seed = args.seed;
    crate::budget::check(
        "the cascade identification",
        id.work_estimate(data.n_samples()),
    )?;
    let fit = {
        let progress = FitProgress::new("identifying cascade");
        id.observer = progress.observer();
        let mut callback = progress.callback();
        id.estimate(&data, &mut callback)?
    };
    let (x, y) = (data.experiment(0).input(0), data.experiment(0).output(0));
    say!(
        "Cascade {} + linear block (na = {}, nb = {}, k = {}) from {} ({} samples)",
        form.short_name(),
        args.na,
        args.nb,
        args.delay,
        args.data.data.display(),
        x.len()
    );
    print_table(&rows(&fit, None, None));
    let extra = json!({"input": args.data.input, "output": args.data.output});
    let report = cascade_report(
        "identify cascade",
        &fit,
        &data,
        vec![args.data.data.display().to_string()],
        extra,
    )?;
    print_summary(&fit, &report);
    out.figures(|| cascade_figures(&fit, x, y, None))?;
    out.finish(Some(&report), Some(&fitted(&fit)))
}

/// `hysid identify hysteresis`.
pub fn hysteresis(args: &HysteresisArgs) -> Result<()> {
    let form = ChForm::parse(&args.hysteresis)?;
    let mut out = register(&args.data, &args.output)?;
    let data = load(&args.data, TimeSteps::Ordered)?;
    out.fitted_on(&data);
    let mut id = HysteresisIdentification::new(form);
    id.initial = match args.initial_output {
        InitialArg::Measured => InitialOutput::Measured,
        InitialArg::Zero => InitialOutput::Zero,
    };
    let fit = {
        let progress = FitProgress::new("identifying hysteresis");
        let mut callback = progress.callback();
        id.estimate(&data, &mut callback)?
    };
    say!(
        "Coleman–Hodgdon hysteresis {} from {} ({} samples)",
        form.short_name(),
        args.data.data.display(),
        data.n_samples()
    );
    let std = fit.std();
    let rows: Vec<Row> = form
        .parameter_names()
        .iter()
        .zip(fit.model.params())
        .zip(&std)
        .map(|((name, estimate), std)| Row {
            name: name.to_string(),
            truth: None,
            initial: None,
            estimate,
            std: *std,
        })
        .collect();
    print_table(&rows);
    let sources = vec![args.data.data.display().to_string()];
    let report = hysteresis_report(&fit, &data, sources, id.initial)?;
    say!(
        "  separated regression: d re-estimated {} times ({}); output-error fit: {} iterations, {}",
        fit.separated.d_history.len().saturating_sub(1),
        fit.separated.termination,
        fit.output_error.report.iterations,
        fit.output_error.report.termination
    );
    let (fit_percent, rmse, _) = figures(&report);
    say!(
        "  fit {fit_percent:.2} %   RMSE {rmse:.4e}   time {:.2} s",
        fit.elapsed_s
    );
    let adm = fit.model.admissibility();
    if !adm.holds {
        say!(
            "  warning: the identified hysteresis is not admissible: {}",
            adm.violations.join("; ")
        );
    }
    out.figures(|| hysteresis_figures(&fit, &data))?;
    let fitted = FittedModel::Hysteresis(FittedHysteresis {
        model: fit.model.clone(),
        initial: id.initial,
        std,
    });
    out.finish(Some(&report), Some(&fitted))
}

/// Registers the report, model and plot destinations before the fit (refused when one is
/// the data file or cannot be written).
pub(super) fn register(data: &DataArgs, output: &OutputArgs) -> Result<Outputs> {
    Outputs::new(
        &[data.data.as_path()],
        output.json.as_deref(),
        output.model_out.as_deref(),
        output.plots.as_deref(),
    )
}
