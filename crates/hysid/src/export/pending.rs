// Replaced by the codegen branch at merge.
//! The entry points of the export until the C emitter lands: the sample time is resolved
//! as [`ExportOptions::sample_time`] documents, then every model kind is refused; the FMU
//! target is already wired to [`fmu_files`].

use super::fmu::fmu_files;
use super::{check_name, CCode, ExportOptions, GeneratedFile, Target};
use crate::model::saved::ModelFile;
use crate::{Error, Result};

/// The C code of the model in `file` under the export name `name`.
pub fn c_code(file: &ModelFile, name: &str, options: &ExportOptions) -> Result<CCode> {
    check_name(name)?;
    sample_time(file, options)?;
    Err(Error::UnsupportedKind {
        kind: file.kind().to_string(),
        operation: "export (no code generator for it yet)".into(),
    })
}

/// The files of the export of the model in `file` to `target`.
pub fn export(
    file: &ModelFile,
    target: Target,
    name: &str,
    options: &ExportOptions,
) -> Result<Vec<GeneratedFile>> {
    let code = c_code(file, name, options)?;
    match target {
        Target::Fmu => fmu_files(&code, options),
        Target::C | Target::Rust => Err(Error::UnsupportedKind {
            kind: file.kind().to_string(),
            operation: format!("export to {}", target.name()),
        }),
    }
}

/// The step's period: the file's `sample_time`, else the one given; both must agree.
fn sample_time(file: &ModelFile, options: &ExportOptions) -> Result<f64> {
    match (file.sample_time, options.sample_time) {
        (Some(saved), Some(given)) if saved != given => Err(Error::invalid_option(
            "ts",
            given,
            format!(
                "the sample time {given} s differs from the model file's {saved} s (the data it \
                 was fitted on); leave --ts out"
            ),
        )),
        (Some(ts), _) | (None, Some(ts)) => Ok(ts),
        (None, None) => Err(Error::invalid_option(
            "ts",
            "none",
            "the model file has no sample_time (written by an earlier version, or fitted \
             without one): give the sample time of the data it was fitted on with --ts"
                .into(),
        )),
    }
}
