//! `Model.export`: a model file's model as C, no_std Rust or an FMU, written into a
//! directory of its own with the command line's rules (`hysid export`: the library's
//! [`hysid::export::export`] and [`ExportDir`]).

use crate::errors::guard;
use hysid::export::fmu::{fmu, Compiler};
use hysid::export::output::ExportDir;
use hysid::export::{export, CCode, ExportOptions, Interface, Precision, Target};
use hysid::model::limits::Limits;
use hysid::model::saved::{FittedModel, ModelFile};
use hysid::Error;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::path::PathBuf;

/// Registers the functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(export_model, m)?)?;
    m.add_function(wrap_pyfunction!(fmu_of_c_code, m)?)?;
    Ok(())
}

/// Exports the model file `model_json` to `target` (`c`, `rust`, `fmu`) under `name` into
/// the directory `out` (created; refused when it holds any file); returns the paths written.
/// `limits` are a compensator's command limits (None: the file's input range), `precision`
/// `double` or `single`.
#[pyfunction]
#[pyo3(signature = (model_json, target, name, out, inverse, ts, binary, y0=None, limits=None, precision="double"))]
#[allow(clippy::too_many_arguments)] // the Python keyword arguments, one each
fn export_model(
    py: Python<'_>,
    model_json: &str,
    target: &str,
    name: &str,
    out: PathBuf,
    inverse: bool,
    ts: Option<f64>,
    binary: bool,
    y0: Option<f64>,
    limits: Option<(f64, f64)>,
    precision: &str,
) -> PyResult<Vec<PathBuf>> {
    let model_json = model_json.to_string();
    let name = name.to_string();
    let target = target.to_string();
    let precision = precision.to_string();
    crate::errors::run(py, move || {
        let target = Target::parse(&target)?;
        let precision = Precision::parse(&precision)?;
        let limits = limits.map(|(lo, hi)| Limits::new(lo, hi)).transpose()?;
        if limits.is_some() && !inverse {
            return Err(Error::invalid_option(
                "limits",
                format!("{limits:?}"),
                "limits= applies to inverse=True only (a compensator's command); leave it out"
                    .into(),
            ));
        }
        if let Some(ts) = ts {
            if !(ts.is_finite() && ts > 0.0) {
                return Err(Error::invalid_option(
                    "ts",
                    ts,
                    format!("ts = {ts} is not a positive finite sample time in seconds"),
                ));
            }
        }
        if !binary && target != Target::Fmu {
            return Err(Error::invalid_option(
                "binary",
                binary,
                "binary=False applies to target='fmu' only; leave it out".into(),
            ));
        }
        let dir = ExportDir::new(&out, &[])?;
        let file: ModelFile = serde_json::from_str(&model_json)
            .map_err(|e| Error::InvalidModel(format!("not a hysid.model/1 model file: {e}")))?;
        FittedModel::from_file(&file)?;
        let options = ExportOptions {
            inverse,
            sample_time: ts,
            binary,
            initial_output: y0,
            limits,
            precision,
            bound_record: None,
            ..ExportOptions::default()
        };
        let files = export(&file, target, &name, &options)?;
        let paths = files.iter().map(|f| dir.path().join(&f.path)).collect();
        dir.write(&files)?;
        Ok(paths)
    })
}

/// The FMU of C code written by hand to the C target's contract (`NAME.h`, `NAME.c`) and its
/// interface (a JSON object with the fields of `hysid::export::Interface`): the bytes of
/// `NAME.fmu`, its binary built by `$CC` or `cc` when `binary`. For packaging one's own C
/// code, and for testing the FMU target apart from the code generator.
#[pyfunction]
#[pyo3(signature = (header, source, interface_json, binary))]
fn fmu_of_c_code<'py>(
    py: Python<'py>,
    header: &str,
    source: &str,
    interface_json: &str,
    binary: bool,
) -> PyResult<Bound<'py, PyBytes>> {
    let bytes = guard(py, || {
        let v: serde_json::Value = serde_json::from_str(interface_json)
            .map_err(|e| Error::InvalidModel(format!("the interface is not JSON: {e}")))?;
        let text = |key: &str| -> hysid::Result<Vec<String>> {
            serde_json::from_value(v[key].clone())
                .map_err(|e| Error::InvalidModel(format!("interface key '{key}': {e}")))
        };
        let parameters: Vec<(String, f64)> = serde_json::from_value(v["parameters"].clone())
            .map_err(|e| Error::InvalidModel(format!("interface key 'parameters': {e}")))?;
        let inputs = text("inputs")?;
        let outputs = text("outputs")?;
        let code = CCode {
            header: header.into(),
            source: source.into(),
            interface: Interface {
                name: v["name"].as_str().unwrap_or_default().into(),
                n_inputs: inputs.len(),
                n_outputs: outputs.len(),
                sample_time: v["sample_time"].as_f64().unwrap_or(f64::NAN),
                inputs,
                outputs,
                parameters,
                description: v["description"].as_str().unwrap_or_default().into(),
            },
        };
        fmu(&code, binary.then(Compiler::from_env).as_ref())
    })?;
    Ok(PyBytes::new(py, &bytes))
}
