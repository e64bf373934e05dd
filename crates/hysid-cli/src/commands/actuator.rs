//! `hysid actuator rig|identify` and `hysid demo actuator`: the linear actuator of Gunnar et
//! al. (2006), its virtual test rig and the three-step identification with the paper's tables
//! and figures.

use crate::cli::{
    ActuatorConstants, ActuatorIdentifyArgs, DemoActuatorArgs, RigArgs, RigSettings, ThreeStepArgs,
};
use crate::output::{
    ensure_dir, preflight, write_atomic, write_figures, write_json, write_model, write_report,
};
use anyhow::{bail, Context, Result};
use hysid::experiments::actuator_rig::Rig;
use hysid::identify::actuator::{
    read_data_sets, ActuatorIdentification, Record, ThreeSteps, PARAMETERS,
};
use hysid::model::greybox::models::ActuatorFixed;
use hysid::model::greybox::Simulation;
use hysid::numerics::LmConfig;
use hysid::report::actuator::three_steps_report;
use hysid::report::plot::actuator_figures;
use serde_json::json;
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Writes the eight data sets of the virtual rig.
pub fn rig(args: &RigArgs) -> Result<()> {
    let rig = rig_from(&args.rig, &args.constants)?;
    preflight(&[], &[Some(&args.data_out)])?;
    let files = write_rig(&rig, &args.data_out)?;
    println!(
        "virtual actuator rig (Gunnar et al. 2006): {} data sets in {} (backlash {} rad, angle noise {:.3e} rad, torque noise {:.3e} N·m, seed {})",
        files.len(),
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
    preflight(
        &[args.json.as_deref(), args.model_out.as_deref()],
        &[args.plots.as_deref()],
    )?;
    let records = read_data_sets(&args.data)?;
    let truth = rig_truth(&args.data)?;
    let clock = Instant::now();
    let steps = three_steps(&args.steps, &args.constants);
    let id = run(&steps, &records)?;
    let outputs = Outputs {
        plots: args.plots.as_deref(),
        json: args.json.as_deref(),
        model_out: args.model_out.as_deref(),
        sources: vec![args.data.display().to_string()],
        simulation: steps.simulation,
    };
    publish(
        &id,
        truth.as_deref(),
        &records,
        &outputs,
        json!({ "elapsed_s": clock.elapsed().as_secs_f64() }),
    )
}

/// Where the results of the three steps go.
struct Outputs<'a> {
    plots: Option<&'a Path>,
    json: Option<&'a Path>,
    model_out: Option<&'a Path>,
    sources: Vec<String>,
    simulation: Simulation,
}

/// The rig and the three steps on the default settings.
pub fn demo(args: &DemoActuatorArgs) -> Result<()> {
    let clock = Instant::now();
    let rig = rig_from(&args.rig, &args.constants)?;
    preflight(&[args.json.as_deref()], &[Some(&args.plots)])?;
    let data_dir = args.plots.join("actuator-data");
    write_rig(&rig, &data_dir)?;
    let records = read_data_sets(&data_dir)?;
    println!(
        "Virtual actuator rig (Gunnar et al. 2006): backlash {} rad, angle noise {:.3e} rad, torque noise {:.3e} N·m, seed {}; data in {}",
        rig.backlash,
        rig.angle_noise,
        rig.torque_noise,
        rig.seed,
        data_dir.display()
    );
    let steps = three_steps(&args.steps, &args.constants);
    let id = run(&steps, &records)?;
    let plots = args.plots.join("actuator");
    let outputs = Outputs {
        plots: Some(&plots),
        json: args.json.as_deref(),
        model_out: None,
        sources: vec![data_dir.display().to_string()],
        simulation: steps.simulation,
    };
    publish(
        &id,
        Some(&rig.truth),
        &records,
        &outputs,
        json!({ "rig": rig_json(&rig) }),
    )?;
    println!("  total time {:.1} s", clock.elapsed().as_secs_f64());
    Ok(())
}

/// The three steps, naming each stage on stderr when it is a terminal (so that an error
/// stays the only line there otherwise).
fn run(steps: &ThreeSteps, records: &BTreeMap<usize, Record>) -> Result<ActuatorIdentification> {
    let terminal = std::io::stderr().is_terminal();
    let id = steps.run_reporting(records, &mut |stage| {
        if terminal {
            eprintln!("  {stage}");
        }
    })?;
    Ok(id)
}

/// Prints the tables; writes Markdown, plots and JSON.
fn publish(
    id: &ActuatorIdentification,
    truth: Option<&[f64]>,
    records: &BTreeMap<usize, Record>,
    outputs: &Outputs,
    details: serde_json::Value,
) -> Result<()> {
    let simulation = outputs.simulation;
    let markdown = id.markdown(truth);
    println!("\n{markdown}");
    for (name, fit) in &id.step3 {
        println!(
            "  {name}: {} iterations, stopped: {}, {:.2} s",
            fit.fit.report.iterations, fit.fit.report.termination, fit.elapsed_s
        );
    }
    if let Some(dir) = outputs.plots {
        ensure_dir(dir)?;
        write_atomic(&dir.join("tables.md"), markdown.as_bytes())?;
        let files = write_figures(dir, &actuator_figures(id, truth, records[&6].ts)?)?;
        println!("  tables and {} plots in {}", files.len(), dir.display());
    }
    if let Some(path) = outputs.json {
        let mut report = three_steps_report(id, truth, outputs.sources.clone(), simulation)?;
        if let (Some(obj), serde_json::Value::Object(more)) =
            (report.details.as_object_mut(), details)
        {
            obj.extend(more);
        }
        write_report(path, &report)?;
        println!("  report: {}", path.display());
    }
    if let Some(path) = outputs.model_out {
        write_model(
            path,
            &id.step3["m67"].fitted_model(&ActuatorFixed, simulation),
        )?;
        println!("  model (m67): {}", path.display());
    }
    Ok(())
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

/// Simulates and writes the data sets and rig.json; returns the data-set files.
fn write_rig(rig: &Rig, dir: &Path) -> Result<Vec<PathBuf>> {
    ensure_dir(dir)?;
    let records = rig.records()?;
    let files = records
        .iter()
        .map(|r| r.write(dir))
        .collect::<hysid::Result<Vec<_>>>()?;
    write_json(&dir.join("rig.json"), &rig_json(rig))?;
    Ok(files)
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
        .map(Some)
}
