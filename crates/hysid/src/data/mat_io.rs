//! Reading identification data from MATLAB MAT-files.
//!
//! Level-5 MAT-files are read: what MATLAB's `save` writes by default up to `-v7`
//! (compressed or not) and what SciPy's `savemat` writes. Version 7.3 files are HDF5
//! containers and are refused with a message saying how to re-save them.
//!
//! Channels are picked by variable name (exact match first, then case-insensitive), in one
//! of two forms:
//!
//! * `name`: a vector variable, N×1 or 1×N;
//! * `name(:,k)`: column k (one-based, as in MATLAB) of an N×M matrix variable.
//!
//! Every numeric class (double, single, integers) is converted to `f64`; complex, sparse,
//! cell, structure and character variables are not channels. The sample time comes from
//! the spec, else from a time variable (`spec.time`, else one called `t`, `time`, `t_s` or
//! `time_s`), else it is 1 (time in samples), exactly as for CSV files
//! ([`IdData::from_csv`]). Every error is one line and names the file.

use std::fs;
use std::path::Path;

use super::csv_io::{TimeSteps, TIME_COLUMN_NAMES};
use super::mat5::{self, MatArray as Array};
use super::{one_line, Channel, CsvSpec, Experiment, IdData};
use crate::error::{Error, Result};

/// Bytes of descriptive text at the start of a MAT-file header.
const HEADER_TEXT: usize = 116;

impl IdData {
    /// Reads one experiment from a MAT-file, named after the file's stem; `spec` names
    /// variables (or matrix columns, `name(:,k)`) instead of CSV columns. See the
    /// [module documentation](self).
    ///
    /// ```no_run
    /// use hysid::data::{CsvSpec, IdData};
    /// // MATLAB: t = (0:999)'/1e3; u = sin(2*pi*5*t); y = ...; save run.mat t u y
    /// let spec = CsvSpec {
    ///     inputs: vec!["u".into()],
    ///     outputs: vec!["y".into()],
    ///     ..CsvSpec::default()
    /// };
    /// let data = IdData::from_mat(std::path::Path::new("run.mat"), &spec)?;
    /// # Ok::<(), hysid::Error>(())
    /// ```
    pub fn from_mat(path: &Path, spec: &CsvSpec) -> Result<IdData> {
        if spec.inputs.is_empty() && spec.outputs.is_empty() {
            return Err(invalid(path, "no input or output variables were asked for"));
        }
        let bytes = fs::read(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_mat_bytes(path, &bytes, spec)
    }

    /// [`from_mat`](Self::from_mat) on the contents of a MAT-file already in memory;
    /// `path` names it in messages and gives the experiment its name.
    pub fn from_mat_bytes(path: &Path, bytes: &[u8], spec: &CsvSpec) -> Result<IdData> {
        if spec.inputs.is_empty() && spec.outputs.is_empty() {
            return Err(invalid(path, "no input or output variables were asked for"));
        }
        let file = MatVariables::parse(path, bytes)?;
        let mut columns = spec
            .inputs
            .iter()
            .chain(&spec.outputs)
            .map(|name| file.column(name))
            .collect::<Result<Vec<_>>>()?;
        let ts = match (spec.ts, &spec.time) {
            (Some(ts), _) => ts,
            (None, Some(name)) => file.sample_time(name, spec.time_steps)?,
            (None, None) => match file.detect_time(spec) {
                Some(name) => file.sample_time(&name, spec.time_steps)?,
                None => 1.0,
            },
        };
        let outputs = columns.split_off(spec.inputs.len());
        let name = path.file_stem().unwrap_or_default().to_string_lossy();
        let channel = |name: &String| Channel::new(name.trim());
        let experiment =
            Experiment::new(name, columns, outputs).map_err(|error| in_file(path, error))?;
        IdData::new(
            ts,
            spec.inputs.iter().map(channel).collect(),
            spec.outputs.iter().map(channel).collect(),
            vec![experiment],
        )
        .map_err(|error| in_file(path, error))
    }

    /// Reads one experiment from a MAT-file (extension `.mat`, any case) or else a CSV file:
    /// [`from_mat`](Self::from_mat) or [`from_csv`](Self::from_csv).
    pub fn from_file(path: &Path, spec: &CsvSpec) -> Result<IdData> {
        if is_mat(path) {
            Self::from_mat(path, spec)
        } else {
            Self::from_csv(path, spec)
        }
    }
}

/// True when `path` has the extension `.mat` (any case).
pub fn is_mat(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.to_string_lossy().eq_ignore_ascii_case("mat"))
}

/// The numeric variables of a parsed MAT-file.
struct MatVariables<'p> {
    path: &'p Path,
    arrays: Vec<Array>,
}

impl<'p> MatVariables<'p> {
    fn parse(path: &'p Path, bytes: &[u8]) -> Result<Self> {
        check_header(path, bytes)?;
        let arrays = mat5::parse(bytes).map_err(|e| {
            invalid(
                path,
                &format!(
                    "cannot read the MAT-file: {e}; save it again with save(..., '-v7') or export CSV"
                ),
            )
        })?;
        Ok(Self { path, arrays })
    }

    /// The variable called `name`: the exact match, else the only case-insensitive one.
    fn variable(&self, name: &str) -> Result<&Array> {
        let arrays = &self.arrays;
        if let Some(array) = arrays.iter().find(|a| a.name() == name) {
            return Ok(array);
        }
        let lower = name.to_lowercase();
        let matches: Vec<&Array> = arrays
            .iter()
            .filter(|a| a.name().to_lowercase() == lower)
            .collect();
        match matches.as_slice() {
            [array] => Ok(array),
            [] => Err(invalid(
                self.path,
                &format!(
                    "no numeric variable named '{}' (the file has: {}); pick one of those",
                    one_line(name),
                    self.listing()
                ),
            )),
            _ => Err(invalid(
                self.path,
                &format!(
                    "variable name '{}' is ambiguous: several variables match when case is ignored; give it exactly",
                    one_line(name)
                ),
            )),
        }
    }

    /// The channel `spec`: a vector variable, or `name(:,k)`, a column of a matrix.
    fn column(&self, spec: &str) -> Result<Vec<f64>> {
        let spec = spec.trim();
        let (name, column) = parse_selector(spec).map_err(|m| invalid(self.path, &m))?;
        let array = self.variable(name)?;
        let values = real_values(array).map_err(|m| invalid(self.path, &m))?;
        let size = array.size();
        if size.len() != 2 {
            return Err(invalid(
                self.path,
                &format!(
                    "variable '{name}' has {} dimensions; give a vector or a matrix",
                    size.len()
                ),
            ));
        }
        let (rows, cols) = (size[0], size[1]);
        let selected = match column {
            None if rows == 1 || cols == 1 => values,
            None => {
                return Err(invalid(
                    self.path,
                    &format!(
                        "variable '{name}' is a {rows}×{cols} matrix; pick a column as {name}(:,k)"
                    ),
                ))
            }
            Some(k) if k >= 1 && k <= cols => values[(k - 1) * rows..k * rows].to_vec(),
            Some(k) => {
                return Err(invalid(
                    self.path,
                    &format!("'{spec}': variable '{name}' has {cols} column(s), not {k}"),
                ))
            }
        };
        if selected.is_empty() {
            return Err(invalid(self.path, &format!("variable '{name}' is empty")));
        }
        if let Some(index) = selected.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                channel: one_line(spec).into_owned(),
                index,
                value: selected[index],
            });
        }
        Ok(selected)
    }

    /// The sample time of the time variable `name` under `steps` ([`TimeSteps`]).
    fn sample_time(&self, name: &str, steps: TimeSteps) -> Result<f64> {
        let time = self.column(name)?;
        steps.sample_time(&time).map_err(|(index, problem)| {
            invalid(
                self.path,
                &format!(
                    "time variable '{}' {problem} at sample {}; {}",
                    one_line(name),
                    index + 1,
                    steps.hint("variable")
                ),
            )
        })
    }

    /// A vector variable with a conventional time name that is not a channel.
    fn detect_time(&self, spec: &CsvSpec) -> Option<String> {
        let taken: Vec<String> = spec
            .inputs
            .iter()
            .chain(&spec.outputs)
            .map(|n| n.trim().to_lowercase())
            .collect();
        self.arrays
            .iter()
            .map(|a| a.name().to_string())
            .find(|name| {
                let lower = name.to_lowercase();
                TIME_COLUMN_NAMES.contains(&lower.as_str()) && !taken.contains(&lower)
            })
    }

    /// "name [rows×cols], …" of every numeric variable.
    fn listing(&self) -> String {
        let names: Vec<String> = self
            .arrays
            .iter()
            .map(|a| {
                let dims: Vec<String> = a.size().iter().map(|d| d.to_string()).collect();
                format!("{} [{}]", a.name(), dims.join("×"))
            })
            .collect();
        if names.is_empty() {
            "no numeric variables".into()
        } else {
            one_line(&names.join(", ")).into_owned()
        }
    }
}

/// Refuses what is not a level-5 MAT-file, with the reason: a version 7.3 (HDF5) file, or
/// a file without the MATLAB header.
fn check_header(path: &Path, bytes: &[u8]) -> Result<()> {
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(HEADER_TEXT)]);
    if text.starts_with("MATLAB 7.3") {
        return Err(invalid(
            path,
            "is a version 7.3 MAT-file (HDF5), which hysid does not read; save it with save(..., '-v7') or export CSV",
        ));
    }
    if bytes.len() < 128 || !text.starts_with("MATLAB") {
        return Err(invalid(
            path,
            "is not a MAT-file (no MATLAB 5.0 header); give a .mat file saved by MATLAB (-v7 or older) or a CSV file",
        ));
    }
    Ok(())
}

/// `name` or `name(:,k)` → (name, Some(k)).
fn parse_selector(spec: &str) -> std::result::Result<(&str, Option<usize>), String> {
    let Some(open) = spec.find('(') else {
        return Ok((spec, None));
    };
    let name = spec[..open].trim();
    let inside = spec[open + 1..]
        .strip_suffix(')')
        .and_then(|s| s.trim().strip_prefix(':'))
        .and_then(|s| s.trim().strip_prefix(','));
    match inside.map(|k| k.trim().parse::<usize>()) {
        Some(Ok(k)) if !name.is_empty() => Ok((name, Some(k))),
        _ => Err(format!(
            "'{}' is not a variable name or name(:,k) with a column number k",
            one_line(spec)
        )),
    }
}

/// The values of a real numeric array, column-major.
fn real_values(array: &Array) -> std::result::Result<Vec<f64>, String> {
    if array.is_complex() {
        return Err(format!(
            "variable '{}' is complex; give a real variable",
            one_line(array.name())
        ));
    }
    Ok(array.real().to_vec())
}

fn invalid(path: &Path, message: &str) -> Error {
    Error::InvalidData(format!("{}: {message}", path.display()))
}

/// An error about this file's contents, prefixed with the file when it does not say it.
fn in_file(path: &Path, error: Error) -> Error {
    match error {
        Error::InvalidData(message) => Error::InvalidData(format!("{}: {message}", path.display())),
        other => other,
    }
}
