//! What `identify operator`, `compare` and `compensate` share: the family options from the
//! flags, reading a record, and the loop plots (through the plotting module's figure API only).

use crate::cli::DataArgs;
use crate::cli_zoo::FamilyArgs;
use crate::exit::UsageError;
use anyhow::{Context, Result};
use hysid::data::{CsvSpec, IdData, TimeSteps};
use hysid::identify::operators::FamilyOptions;
use hysid::model::saved::FittedModel;
use hysid::report::plot::{render, Figure, Series, Style};
use std::path::Path;

/// The recipes' options from the flags, ranges checked.
pub fn family_options(args: &FamilyArgs) -> Result<FamilyOptions> {
    let mut options = FamilyOptions {
        grid: args.grid.map_or(20, |g| g as usize),
        choose_grid: args.grid.is_none(),
        choose_thresholds: args.thresholds.is_none(),
        lambda: args.lambda,
        dead_zones: args.dead_zones.map_or(4, |m| m as usize),
        choose_dead_zones: args.dead_zones.is_none(),
        loop_orientation: args.orientation.map(Into::into),
        initial_state: args.initial_state.into(),
        envelope: args.envelope.into(),
        ..FamilyOptions::default()
    };
    let text = args.thresholds.as_deref().unwrap_or("10").trim();
    match text.parse::<usize>() {
        Ok(n) => options.thresholds = n,
        Err(_) => {
            let grid = text
                .split(',')
                .map(|s| s.trim().parse::<f64>())
                .collect::<Result<Vec<f64>, _>>()
                .map_err(|_| {
                    anyhow::anyhow!(
                        "--thresholds '{text}' is neither a count nor a comma-separated list of numbers"
                    )
                })?;
            options.thresholds = grid.len();
            options.threshold_grid = Some(grid);
        }
    }
    options.validate().with_context(|| {
        format!(
            "--thresholds {text} --grid {} --lambda {} --dead-zones {}",
            args.grid.map_or("chosen".to_string(), |g| g.to_string()),
            args.lambda,
            args.dead_zones
                .map_or("chosen".to_string(), |m| m.to_string())
        )
    })?;
    Ok(options)
}

/// The one input and output column of a zoo command (its families are single-input,
/// single-output operators).
pub fn columns(args: &DataArgs) -> Result<(&str, &str)> {
    match (args.input.as_slice(), args.output.as_slice()) {
        ([input], [output]) => Ok((input, output)),
        _ => Err(UsageError(format!(
            "this command fits one hysteresis loop: give one --input and one --output (got {} and {})",
            args.input.len(),
            args.output.len()
        ))
        .into()),
    }
}

/// Reads the input and output columns of `path` (one experiment). The hysteresis families
/// are rate-independent: a time column need only increase (set points at irregular moments,
/// runs with gaps between them; [`TimeSteps::Ordered`]).
pub fn load(args: &DataArgs, path: &Path) -> Result<IdData> {
    let (input, output) = columns(args)?;
    let spec = CsvSpec {
        inputs: vec![input.to_string()],
        outputs: vec![output.to_string()],
        time: args.time.clone(),
        ts: args.ts,
        time_steps: TimeSteps::Ordered,
    };
    IdData::from_file(path, &spec).with_context(|| format!("reading {}", path.display()))
}

/// The rule for the time column of the records `model` runs on: only increasing for a
/// rate-independent model (a hysteresis operator), uniform otherwise.
pub fn time_steps(model: &FittedModel) -> TimeSteps {
    if model.rate_independent() {
        TimeSteps::Ordered
    } else {
        TimeSteps::Uniform
    }
}

/// The measured loop (points) with model loops (dashed) over it, as `dir/name`.
pub fn loops(
    path: &Path,
    title: &str,
    labels: (&str, &str),
    measured: (&[f64], &[f64]),
    models: &[(String, &[f64])],
) -> Result<()> {
    let mut figure = Figure::new(title, labels.0, labels.1)
        .with(Series::points("measured", measured.0, measured.1));
    for (name, y) in models {
        figure = figure.with(Series::dashed(name, measured.0, y));
    }
    plot(path, &figure)
}

/// Signals against their sample index, as `path`.
pub fn signals(path: &Path, title: &str, y_label: &str, series: &[(&str, &[f64])]) -> Result<()> {
    let mut figure = Figure::new(title, "sample", y_label);
    for (k, (name, y)) in series.iter().enumerate() {
        let style = if k == 0 {
            Style::Line
        } else {
            Style::DashedLine
        };
        figure = figure.with(Series::indexed(name, y, style));
    }
    plot(path, &figure)
}

/// Renders `figure` as SVG into `path`, a file inside a staged plot directory.
fn plot(path: &Path, figure: &Figure) -> Result<()> {
    std::fs::write(path, render(figure)?)
        .with_context(|| format!("cannot write {}", path.display()))
}
