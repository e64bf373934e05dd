//! The linear actuator of J. Gunnar, E. Wernholt, G. Hovland, T. Brogårdh, "Nonlinear
//! Grey-Box Identification of Linear Actuators Containing Hysteresis", ICRA 2006: its
//! three-step identification (`hysid.actuator_three_steps`, the CLI's `actuator identify`)
//! and its virtual test rig (`hysid.actuator_rig`, the CLI's `actuator rig`).
//!
//! Step 1: rigid-body least squares Jt θ̈ + Fv θ̇ + Fc sgn(θ̇) = τ on data set 1; step 2: the
//! steady-state loops τn = k1 x1 + k2 x1³ + Cu/d(x1) of data sets 2–5; step 3: output error
//! of the saddle-fixed model on data set 6 with 7 (m67) and with 8 (m68), all seven
//! parameters free or J, Fv, Fc fixed (m67f, m68f). The report is the library's
//! `hysid::report::actuator::three_steps_report`, the one the CLI writes.

use crate::errors::run;
use crate::pool::run_on;
use crate::recipes::{id_data, samples};
use crate::watch::watching;
use hysid::experiments::actuator_rig::Rig;
use hysid::identify::actuator::{read_data_sets, Record, ThreeSteps, PARAMETERS};
use hysid::numerics::LmConfig;
use hysid::report::actuator::three_steps_report;
use hysid::{Error, Result};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use serde_json::json;
use std::collections::BTreeMap;

/// Registers this module's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(actuator_three_steps, m)?)?;
    m.add_function(wrap_pyfunction!(actuator_rig, m)?)?;
    m.add_function(wrap_pyfunction!(actuator_parameter_names, m)?)?;
    m.add_function(wrap_pyfunction!(actuator_read_data_sets, m)?)?;
    m.add_function(wrap_pyfunction!(actuator_rig_truth, m)?)?;
    Ok(())
}

/// A data set as Python passes it: (torque τ \[N·m\], motor angle θ \[rad\], sample time \[s\]).
type RecordArrays<'py> = (PyReadonlyArray1<'py, f64>, PyReadonlyArray1<'py, f64>, f64);

/// The settings of the three steps (the CLI's flags, same defaults in the Python wrapper).
#[derive(Clone, Copy)]
struct Settings {
    gear_ratio: f64,
    saddle_mass: f64,
    cutoff_hz: f64,
    remove_mean: bool,
    reversal_margin: f64,
    unfiltered_step3: bool,
    max_iterations: usize,
    tolerance: f64,
}

impl Settings {
    fn three_steps(self) -> ThreeSteps {
        let defaults = ThreeSteps::default();
        ThreeSteps {
            r: self.gear_ratio,
            m: self.saddle_mass,
            cutoff_hz: self.cutoff_hz,
            remove_mean: self.remove_mean,
            reversal_margin: self.reversal_margin,
            prefilter_step3: !self.unfiltered_step3,
            lm: LmConfig {
                max_iterations: self.max_iterations,
                improvement_tolerance: self.tolerance,
                ..defaults.lm.clone()
            },
            ..defaults
        }
    }
}

/// The parameter names of the actuator model, in its order: J, Fv, Fc, k1, k2, alpha, A.
#[pyfunction]
fn actuator_parameter_names() -> Vec<&'static str> {
    PARAMETERS.to_vec()
}

/// The rig's default true parameters (Table I's m67), in [`PARAMETERS`] order.
#[pyfunction]
fn actuator_rig_truth() -> Vec<f64> {
    Rig::default().truth
}

/// Data sets 1–8 of a directory (`dataset1.csv` … `dataset8.csv`, columns t_s, tau_Nm,
/// theta_rad, as `hysid actuator rig` writes them): [(torque, angle, ts)].
#[pyfunction]
#[allow(clippy::type_complexity)]
fn actuator_read_data_sets<'py>(
    py: Python<'py>,
    dir: std::path::PathBuf,
) -> PyResult<Vec<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, f64)>> {
    let sets = run(py, move || read_data_sets(&dir))?;
    Ok(sets
        .into_values()
        .map(|r| {
            (
                PyArray1::from_vec(py, r.torque),
                PyArray1::from_vec(py, r.angle),
                r.ts,
            )
        })
        .collect())
}

/// Data sets 1–8 from Python's arrays, each checked (finite, equal lengths, positive ts).
fn records(sets: Vec<(Vec<f64>, Vec<f64>, f64)>) -> Result<BTreeMap<usize, Record>> {
    if sets.len() != 8 {
        return Err(Error::InvalidData(format!(
            "{} data sets given; the procedure needs data sets 1 to 8 in order",
            sets.len()
        )));
    }
    sets.into_iter()
        .enumerate()
        .map(|(i, (torque, angle, ts))| {
            id_data(ts, vec![torque.clone()], vec![angle.clone()])
                .map_err(|e| Error::InvalidData(format!("data set {}: {e}", i + 1)))?;
            Ok((i + 1, Record { ts, torque, angle }))
        })
        .collect()
}

/// The three steps on data sets 1–8; returns the report's JSON (`details.steps`: one report
/// per step; `details.elapsed_s`: wall time; `model`: m67, the CLI's `--model-out`).
#[pyfunction]
#[pyo3(signature = (sets, source, truth, gear_ratio, saddle_mass, cutoff_hz, remove_mean, reversal_margin, unfiltered_step3, max_iterations, tolerance, threads=0, time_limit=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn actuator_three_steps(
    py: Python<'_>,
    sets: Vec<RecordArrays<'_>>,
    source: String,
    truth: Option<Vec<f64>>,
    gear_ratio: f64,
    saddle_mass: f64,
    cutoff_hz: f64,
    remove_mean: bool,
    reversal_margin: f64,
    unfiltered_step3: bool,
    max_iterations: usize,
    tolerance: f64,
    threads: usize,
    time_limit: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let sets: Vec<(Vec<f64>, Vec<f64>, f64)> = sets
        .iter()
        .map(|(tau, theta, ts)| (samples(tau), samples(theta), *ts))
        .collect();
    let settings = Settings {
        gear_ratio,
        saddle_mass,
        cutoff_hz,
        remove_mean,
        reversal_margin,
        unfiltered_step3,
        max_iterations,
        tolerance,
    };
    run_on(
        py,
        threads,
        watching(py, time_limit, progress)?,
        move |watch| {
            if let Some(t) = &truth {
                if t.len() != PARAMETERS.len() || t.iter().any(|v| !v.is_finite()) {
                    return Err(Error::invalid_option(
                        "truth",
                        format!("{t:?}"),
                        format!(
                            "truth: give {} finite values ({})",
                            PARAMETERS.len(),
                            PARAMETERS.join(", ")
                        ),
                    ));
                }
            }
            let clock = std::time::Instant::now();
            let records = records(sets)?;
            let steps = ThreeSteps {
                observer: watch.observer(),
                ..settings.three_steps()
            };
            let id = steps.run(&records)?;
            let mut report =
                three_steps_report(&id, truth.as_deref(), vec![source], steps.simulation)?;
            if let Some(obj) = report.details.as_object_mut() {
                obj.insert("elapsed_s".into(), json!(clock.elapsed().as_secs_f64()));
            }
            watch.finish(report).to_json()
        },
    )
}

/// The eight data sets of the virtual rig: [(set, saddle_free, ts, torque, angle)].
#[pyfunction]
#[pyo3(signature = (truth, backlash, noise, seed, gear_ratio, saddle_mass))]
#[allow(clippy::type_complexity)]
fn actuator_rig<'py>(
    py: Python<'py>,
    truth: Option<Vec<f64>>,
    backlash: f64,
    noise: f64,
    seed: u64,
    gear_ratio: f64,
    saddle_mass: f64,
) -> PyResult<
    Vec<(
        usize,
        bool,
        f64,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
    )>,
> {
    let records = run(py, move || {
        if !(noise.is_finite() && noise >= 0.0) {
            return Err(Error::invalid_option(
                "noise",
                noise,
                format!(
                    "noise = {noise}: give a non-negative multiple of the documented noise levels"
                ),
            ));
        }
        if !(backlash.is_finite() && backlash >= 0.0) {
            return Err(Error::invalid_option(
                "backlash",
                backlash,
                format!("backlash = {backlash}: give a non-negative play width in rad"),
            ));
        }
        let defaults = Rig::default();
        let truth = truth.unwrap_or_else(|| defaults.truth.clone());
        if truth.len() != PARAMETERS.len() {
            return Err(Error::invalid_option(
                "truth",
                format!("{truth:?}"),
                format!(
                    "truth: give {} values ({})",
                    PARAMETERS.len(),
                    PARAMETERS.join(", ")
                ),
            ));
        }
        let rig = Rig {
            truth,
            backlash,
            angle_noise: defaults.angle_noise * noise,
            torque_noise: defaults.torque_noise * noise,
            seed,
            r: gear_ratio,
            m: saddle_mass,
            ..defaults
        };
        rig.records()
    })?;
    Ok(records
        .into_iter()
        .map(|r| {
            (
                r.set,
                r.saddle_free,
                r.ts,
                PyArray1::from_vec(py, r.torque),
                PyArray1::from_vec(py, r.angle),
            )
        })
        .collect())
}
