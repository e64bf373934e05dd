//! Writing result files: never a half-written file (temporary file, then rename).

use anyhow::{Context, Result};
use serde::Serialize;
use std::fs;
use std::path::Path;

/// Writes `value` as pretty JSON to `path` atomically.
pub fn write_json(path: &Path, value: &impl Serialize) -> Result<()> {
    let text = serde_json::to_string_pretty(value).context("serialising the report")?;
    write_atomic(path, text.as_bytes())
}

/// Writes the report as pretty JSON to `path` atomically, refused when a number in it is
/// not finite.
pub fn write_report(path: &Path, report: &hysid::report::Report) -> Result<()> {
    let text = report.to_json()?;
    write_atomic(path, text.as_bytes()).context("writing the JSON report")
}

/// Writes the saved-model file of `model` to `path` atomically, refused when a parameter is
/// not finite.
pub fn write_model(path: &Path, model: &hysid::model::saved::FittedModel) -> Result<()> {
    let file = model.to_file();
    if let Some(p) = file.parameters.iter().find(|p| !p.value.is_finite()) {
        anyhow::bail!(
            "the estimate of {} is not finite; no model file written",
            p.name
        );
    }
    write_json(path, &file).context("writing the model file")
}

/// Writes `bytes` to `path` through a temporary file in the same directory.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = writable_file(path)?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    fs::write(&tmp, bytes).with_context(|| format!("cannot write {}", tmp.display()))?;
    fs::rename(&tmp, path).map_err(|e| {
        let _ = fs::remove_file(&tmp);
        anyhow::anyhow!("cannot write {}: {e}", path.display())
    })
}

/// Creates the plot directory (and its parents).
pub fn ensure_dir(dir: &Path) -> Result<()> {
    fs::create_dir_all(dir).with_context(|| format!("cannot create directory {}", dir.display()))
}

/// Checks, before any work, that every result file can be written where asked (its
/// directory exists and the path is not a directory) and creates the plot directories, so
/// that a long fit never ends in "cannot write".
pub fn preflight(files: &[Option<&Path>], dirs: &[Option<&Path>]) -> Result<()> {
    for path in files.iter().flatten() {
        writable_file(path)?;
    }
    for dir in dirs.iter().flatten() {
        ensure_dir(dir)?;
    }
    Ok(())
}

/// The directory `path` would be written into, when it exists and `path` is not itself a
/// directory.
fn writable_file(path: &Path) -> Result<&Path> {
    if path.is_dir() {
        anyhow::bail!(
            "cannot write {}: it is a directory; give a file name",
            path.display()
        );
    }
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !dir.is_dir() {
        anyhow::bail!(
            "cannot write {}: directory {} does not exist; create it or choose another path",
            path.display(),
            dir.display()
        );
    }
    Ok(dir)
}

/// Writes the plots into `dir` (created when missing); returns the files written.
pub fn write_figures(
    dir: &Path,
    figures: &[hysid::report::plot::Svg],
) -> Result<Vec<std::path::PathBuf>> {
    ensure_dir(dir)?;
    figures
        .iter()
        .map(|f| {
            let path = dir.join(&f.name);
            write_atomic(&path, f.svg.as_bytes())?;
            Ok(path)
        })
        .collect()
}
