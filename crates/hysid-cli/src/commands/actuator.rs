//! `hysid actuator rig|identify` and `hysid demo actuator`: the linear actuator of Gunnar et
//! al. (2006), its virtual test rig and the three-step identification with the paper's tables
//! and figures.

use crate::cli::{
    ActuatorConstants, ActuatorIdentifyArgs, DemoActuatorArgs, RigArgs, RigSettings, ThreeStepArgs,
};
use crate::output::{write_figures, Outputs};
use crate::progress::FitProgress;
use anyhow::{bail, Context, Result};
use hysid::experiments::actuator_rig::Rig;
use hysid::identify::actuator::{
    read_data_sets, ActuatorIdentification, Record, ThreeSteps, PARAMETERS,
};
use hysid::model::greybox::Simulation;
use hysid::numerics::LmConfig;
use hysid::report::actuator::three_steps_report;
use hysid::report::plot::actuator_figures;
use serde_json::json;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

/// Writes the eight data sets of the virtual rig (all or nothing: an existing directory is
/// replaced only once every file of the new one is written).
pub fn rig(args: &RigArgs) -> Result<()> {
    let rig = rig_from(&args.rig, &args.constants)?;
    let mut out = Outputs::new(&[], None, None, None)?;
    let dir = out.dir_at(&args.data_out)?;
    let files = write_rig(&rig, &dir.tmp)?;
    out.finish(None, None)?;
    say!(
        "virtual actuator rig (Gunnar et al. 2006): {files} data sets in {} (backlash {} rad, angle noise {:.3e} rad, torque noise {:.3e} N·m, seed {})",
        args.data_out.display(),
        rig.backlash,
        rig.angle_noise,
        rig.torque_noise,
        rig.seed
    );
    Ok(())
}

/// The three steps on a data directory.
pub fn identify(args: &ActuatorIdentifyArgs) -> Result<()> {
    let out = Outputs::new(
        &[args.data.as_path()],
        args.json.as_deref(),
        args.model_out.as_deref(),
        args.plots.as_deref(),
    )?;
    let records = read_data_sets(&args.data)?;
    let truth = rig_truth(&args.data)?;
    let clock = Instant::now();
    let steps = three_steps(&args.steps, &args.constants);
    let id = run(&steps, &records)?;
    let sources = vec![args.data.display().to_string()];
    publish(
        "actuator identify",
        &id,
        truth.as_deref(),
        &records,
        out,
        (sources, steps.simulation),
        json!({ "elapsed_s": clock.elapsed().as_secs_f64() }),
    )
}

/// The rig and the three steps on the default settings.
pub fn demo(args: &DemoActuatorArgs) -> Result<()> {
    let clock = Instant::now();
    let rig = rig_from(&args.rig, &args.constants)?;
    let plots = args.plots.join("actuator");
    let mut out = Outputs::new(&[], args.json.as_deref(), None, Some(&plots))?;
    let data_dir = args.plots.join("actuator-data");
    let staged = out.dir_at(&data_dir)?;
    write_rig(&rig, &staged.tmp)?;
    let records = read_data_sets(&staged.tmp)?;
    say!(
        "Virtual actuator rig (Gunnar et al. 2006): backlash {} rad, angle noise {:.3e} rad, torque noise {:.3e} N·m, seed {}; data in {}",
        rig.backlash,
        rig.angle_noise,
        rig.torque_noise,
        rig.seed,
        data_dir.display()
    );
    let steps = three_steps(&args.steps, &args.constants);
    let id = run(&steps, &records)?;
    let sources = vec![data_dir.display().to_string()];
    publish(
        "demo actuator",
        &id,
        Some(&rig.truth),
        &records,
        out,
        (sources, steps.simulation),
        json!({ "rig": rig_json(&rig) }),
    )?;
    say!("  total time {:.1} s", clock.elapsed().as_secs_f64());
    Ok(())
}

/// The three steps, showing the step each is at on stderr (a live line on a terminal, a plain
/// line at most every few seconds otherwise, nothing with `--quiet`; a run that fails within
/// the first seconds prints only its error).
fn run(steps: &ThreeSteps, records: &BTreeMap<usize, Record>) -> Result<ActuatorIdentification> {
    let progress = FitProgress::new("identifying actuator");
    let steps = ThreeSteps {
        observer: progress.observer(),
        ..steps.clone()
    };
    Ok(steps.run_reporting(records, &mut |stage| progress.show(stage))?)
}

/// Prints the tables; writes Markdown and plots, the report (of the command `command`) and
/// the m67 model (read from `sources`, simulated with `simulation`), all in one transaction.
fn publish(
    command: &str,
    id: &ActuatorIdentification,
    truth: Option<&[f64]>,
    records: &BTreeMap<usize, Record>,
    out: Outputs,
    (sources, simulation): (Vec<String>, Simulation),
    details: serde_json::Value,
) -> Result<()> {
    let markdown = id.markdown(truth);
    say!("\n{markdown}");
    for (name, fit) in &id.step3 {
        say!(
            "  {name}: {} iterations, stopped: {}, {:.2} s",
            fit.fit.report.iterations,
            fit.fit.report.termination,
            fit.elapsed_s
        );
    }
    if let Some(dir) = &out.plots {
        std::fs::write(dir.tmp.join("tables.md"), &markdown)
            .with_context(|| format!("cannot write {}", dir.target.join("tables.md").display()))?;
        write_figures(&dir.tmp, &actuator_figures(id, truth, records[&6].ts)?)?;
    }
    let report = if out.json.is_some() {
        let mut report = three_steps_report(id, truth, sources, simulation)?;
        report.command = command.into();
        if let (Some(obj), serde_json::Value::Object(more)) =
            (report.details.as_object_mut(), details)
        {
            obj.extend(more);
        }
        Some(report)
    } else {
        None
    };
    let m67 = id.fitted("m67", simulation);
    out.finish(report.as_ref(), m67.as_ref())
}

fn three_steps(args: &ThreeStepArgs, constants: &ActuatorConstants) -> ThreeSteps {
    let defaults = ThreeSteps::default();
    ThreeSteps {
        r: constants.gear_ratio,
        m: constants.saddle_mass,
        cutoff_hz: args.cutoff,
        remove_mean: args.remove_mean,
        reversal_margin: args.reversal_margin,
        prefilter_step3: !args.unfiltered_step3,
        lm: LmConfig {
            max_iterations: args.max_iterations,
            improvement_tolerance: args.tolerance,
            ..defaults.lm.clone()
        },
        ..defaults
    }
}

fn rig_from(settings: &RigSettings, constants: &ActuatorConstants) -> Result<Rig> {
    if !(settings.noise.is_finite() && settings.noise >= 0.0) {
        bail!(
            "--noise {}: give a non-negative multiple of the documented noise levels",
            settings.noise
        );
    }
    if !(settings.backlash.is_finite() && settings.backlash >= 0.0) {
        bail!(
            "--backlash {}: give a non-negative play width in rad",
            settings.backlash
        );
    }
    let defaults = Rig::default();
    let mut truth = defaults.truth.clone();
    for spec in &settings.truth {
        let (name, value) = spec
            .split_once('=')
            .with_context(|| format!("--truth {spec}: write NAME=VALUE"))?;
        let i = PARAMETERS
            .iter()
            .position(|p| *p == name.trim())
            .with_context(|| {
                format!(
                    "--truth {spec}: the parameters are {}",
                    PARAMETERS.join(", ")
                )
            })?;
        truth[i] = value
            .trim()
            .parse()
            .with_context(|| format!("--truth {spec}: '{value}' is not a number"))?;
    }
    Ok(Rig {
        truth,
        backlash: settings.backlash,
        angle_noise: defaults.angle_noise * settings.noise,
        torque_noise: defaults.torque_noise * settings.noise,
        seed: settings.seed,
        r: constants.gear_ratio,
        m: constants.saddle_mass,
        ..defaults
    })
}

/// Simulates and writes the data sets and rig.json into `dir` (a staged directory);
/// returns the number of data sets.
fn write_rig(rig: &Rig, dir: &Path) -> Result<usize> {
    let records = rig.records()?;
    for r in &records {
        r.write(dir)?;
    }
    let path = dir.join("rig.json");
    let json = rig_json(rig);
    hysid::io::atomic::ensure_finite(&json)?;
    let text = serde_json::to_string_pretty(&json)?;
    std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(records.len())
}

fn rig_json(rig: &Rig) -> serde_json::Value {
    let truth: BTreeMap<&str, f64> = PARAMETERS
        .iter()
        .copied()
        .zip(rig.truth.iter().copied())
        .collect();
    json!({
        "truth": truth,
        "r": rig.r,
        "m": rig.m,
        "fs_hz": rig.fs,
        "backlash_rad": rig.backlash,
        "angle_noise_rad": rig.angle_noise,
        "torque_noise_Nm": rig.torque_noise,
        "multisine_rms_Nm": rig.multisine_rms,
        "seed": rig.seed,
    })
}

/// The true parameters from DIR/rig.json, when the data came from the rig.
fn rig_truth(dir: &Path) -> Result<Option<Vec<f64>>> {
    let path = dir.join("rig.json");
    if !path.is_file() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{} is not valid JSON", path.display()))?;
    PARAMETERS
        .iter()
        .map(|p| {
            value["truth"][p].as_f64().with_context(|| {
                format!("{}: truth.{p} is missing (remove the file or rewrite it with `hysid actuator rig`)", path.display())
            })
        })
        .collect::<Result<Vec<f64>>>()
        .and_then(|truth| {
            Rig::check_truth(&truth).with_context(|| {
                format!("{}: truth (remove the file or rewrite it with `hysid actuator rig`)", path.display())
            })?;
            Ok(Some(truth))
        })
}
