//! The hysteresis model zoo behind `hysid.identify_operator` and `hysid.FAMILIES`: the
//! families are the library's registry (`hysid::model::operators::Family`), the report the
//! one `hysid identify operator` writes (`hysid::report::operator_report`).

use crate::errors::guard;
use crate::pool::run_on;
use crate::recipes::{id_data, samples, source};
use hysid::identify::operators::{fit_operator, Family, FamilyOptions};
use hysid::report;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;

/// Registers this module's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(families, m)?)?;
    m.add_function(wrap_pyfunction!(identify_operator, m)?)?;
    Ok(())
}

/// Every family of the registry: [(name, model and reference)], in the registry's order.
#[pyfunction]
fn families() -> Vec<(&'static str, &'static str)> {
    Family::ALL.iter().map(|f| (f.name(), f.title())).collect()
}

/// Fits the hysteresis family `family` to input `u` and output `y`: the report of `hysid
/// identify operator` as JSON text. `threshold_grid` empty: the uniform grid of
/// `thresholds`.
#[pyfunction]
#[pyo3(signature = (u, y, family, ts, thresholds, threshold_grid, grid, lambda_, dead_zones, threads=0))]
#[allow(clippy::too_many_arguments)] // the Python keyword arguments, one each
fn identify_operator(
    py: Python<'_>,
    u: PyReadonlyArray1<'_, f64>,
    y: PyReadonlyArray1<'_, f64>,
    family: &str,
    ts: f64,
    thresholds: usize,
    threshold_grid: Vec<f64>,
    grid: usize,
    lambda_: f64,
    dead_zones: usize,
    threads: usize,
) -> PyResult<String> {
    let (u, y) = (samples(&u), samples(&y));
    let family = guard(py, || Family::parse(family))?;
    let options = FamilyOptions {
        thresholds: if threshold_grid.is_empty() {
            thresholds
        } else {
            threshold_grid.len()
        },
        threshold_grid: (!threshold_grid.is_empty()).then_some(threshold_grid),
        grid,
        lambda: lambda_,
        dead_zones,
        ..FamilyOptions::default()
    };
    run_on(py, threads, move || {
        let data = id_data(ts, vec![u], vec![y])?;
        let exp = data.experiment(0);
        let fitted = fit_operator(family, exp.input(0), exp.output(0), &options)?;
        let simulated = report::operator_simulation(&fitted, &data)?;
        report::operator_report(&fitted, &data, &simulated, source())?.to_json()
    })
}
