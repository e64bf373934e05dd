//! Writing result files through the library's one atomic writer,
//! [`hysid::io::atomic::OutputSet`]: every output of a run is registered before any work
//! (refused when it equals an input, is given twice or cannot be written), written to a
//! temporary, and renamed into place together with the others at the end — or not at all.

use anyhow::{Context, Result};
use hysid::data::IdData;
use hysid::io::atomic::OutputSet;
use hysid::model::saved::{Columns, FittedModel, ModelFile};
use hysid::report::plot::Svg;
use hysid::report::Report;
use std::path::{Path, PathBuf};

/// One registered output: where it will appear and the temporary to write now.
#[derive(Clone, Debug)]
pub struct Staged {
    /// The path the user asked for.
    pub target: PathBuf,
    /// The temporary file or directory to write (renamed to `target` by the commit).
    pub tmp: PathBuf,
}

/// The outputs of one command: the report (`--json`), the saved model (`--model-out`), the
/// plot directory (`--plots`) and any further file or directory, as one transaction.
pub struct Outputs {
    set: OutputSet,
    /// The report, when asked for.
    pub json: Option<Staged>,
    /// The saved-model file, when asked for.
    pub model_out: Option<Staged>,
    /// The plot directory, when asked for.
    pub plots: Option<Staged>,
    /// The sample time and column names of the data the model was fitted on, saved with it
    /// in the model file and the report's `model` ([`Outputs::fitted_on`]).
    data: Option<(f64, Columns)>,
    /// The input range of the data the model was fitted on (`input_range`).
    input_range: Option<Vec<[f64; 2]>>,
}

impl Outputs {
    /// Registers the usual outputs of a command, refusing any that equals one of `inputs`.
    pub fn new(
        inputs: &[&Path],
        json: Option<&Path>,
        model_out: Option<&Path>,
        plots: Option<&Path>,
    ) -> Result<Self> {
        let mut out = Self {
            set: OutputSet::new(inputs)?,
            json: None,
            model_out: None,
            plots: None,
            data: None,
            input_range: None,
        };
        // The directory first: a file inside it is then refused as a clash, even before
        // the directory exists.
        out.plots = out.dir(plots)?;
        out.json = out.file(json)?;
        out.model_out = out.file(model_out)?;
        Ok(out)
    }

    /// Registers a further output file, when one was asked for.
    pub fn file(&mut self, path: Option<&Path>) -> Result<Option<Staged>> {
        path.map(|p| self.file_at(p)).transpose()
    }

    /// Registers the output file `path`.
    pub fn file_at(&mut self, path: &Path) -> Result<Staged> {
        Ok(Staged {
            target: path.to_path_buf(),
            tmp: self.set.file(path)?,
        })
    }

    /// Registers a further output directory, when one was asked for.
    pub fn dir(&mut self, path: Option<&Path>) -> Result<Option<Staged>> {
        path.map(|p| self.dir_at(p)).transpose()
    }

    /// Registers the output directory `path`.
    pub fn dir_at(&mut self, path: &Path) -> Result<Staged> {
        Ok(Staged {
            target: path.to_path_buf(),
            tmp: self.set.dir(path)?,
        })
    }

    /// Saves the sample time and the channel names of `data`, the data the model is fitted
    /// on, with the model (`sample_time`, `columns`: `hysid export` takes the step's period
    /// and the FMU's variable names from them).
    pub fn fitted_on(&mut self, data: &IdData) {
        let names =
            |channels: &[hysid::data::Channel]| channels.iter().map(|c| c.name.clone()).collect();
        let columns = Columns {
            inputs: names(data.input_channels()),
            outputs: names(data.output_channels()),
        };
        self.fitted_on_columns(data.ts(), columns);
        self.input_range = Some(hysid::model::limits::input_range_of(data));
    }

    /// [`Outputs::fitted_on`] for a model whose columns are not those of an [`IdData`].
    pub fn fitted_on_columns(&mut self, ts: f64, columns: Columns) {
        self.data = Some((ts, columns));
    }

    /// Writes the plots into the plot directory, when one was asked for.
    pub fn figures(&self, figures: impl FnOnce() -> hysid::Result<Vec<Svg>>) -> Result<()> {
        if let Some(dir) = &self.plots {
            write_figures(&dir.tmp, &figures()?)?;
        }
        Ok(())
    }

    /// Writes the report and the model file when asked for, renames every output into
    /// place and says where they are.
    pub fn finish(self, report: Option<&Report>, model: Option<&FittedModel>) -> Result<()> {
        let with_data = |file: ModelFile| {
            let mut file = match &self.data {
                Some((ts, columns)) => file.with_data(*ts, columns.clone()),
                None => file,
            };
            if self.input_range.is_some() {
                file.input_range.clone_from(&self.input_range);
            }
            file
        };
        if let (Some(out), Some(report)) = (&self.json, report) {
            let mut report = report.clone();
            report.model = report.model.map(with_data);
            write_report(out, &report)?;
        }
        if let (Some(out), Some(model)) = (&self.model_out, model) {
            write_model(out, &with_data(model.to_file()))?;
        }
        let (json, model_out, plots) = (
            self.json.clone(),
            self.model_out.clone(),
            self.plots.clone(),
        );
        self.set.commit()?;
        if let Some(dir) = plots {
            say!("  plots: {}", dir.target.display());
        }
        if let Some(out) = json.filter(|_| report.is_some()) {
            say!("  report: {}", out.target.display());
        }
        if let Some(out) = model_out.filter(|_| model.is_some()) {
            say!("  model: {}", out.target.display());
        }
        Ok(())
    }
}

/// Writes the report as pretty JSON, refused when a number in it is not finite.
pub fn write_report(out: &Staged, report: &Report) -> Result<()> {
    // A search stopped by --time-limit says so in the report.
    let text = crate::progress::mark_report(report).to_json()?;
    write_text(out, &text).context("writing the JSON report")
}

/// Writes the saved-model file `file`, refused when a parameter is not finite.
pub fn write_model(out: &Staged, file: &ModelFile) -> Result<()> {
    if let Some(p) = file.parameters().iter().find(|p| !p.value.is_finite()) {
        anyhow::bail!(
            "the estimate of {} is not finite; no model file written",
            p.name
        );
    }
    let text = serde_json::to_string_pretty(file).context("serialising the model file")?;
    write_text(out, &text).context("writing the model file")
}

/// Writes the plots into `dir`, a staged directory (which exists: registering it created
/// it, and it is never recreated here, so that an interrupt's removal is final).
pub fn write_figures(dir: &Path, figures: &[Svg]) -> Result<()> {
    for f in figures {
        let path = dir.join(&f.name);
        std::fs::write(&path, &f.svg)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

/// Writes `text` to the temporary of `out` (created through the library, so that an
/// interrupt never leaves it behind: [`hysid::io::atomic::create`]).
pub fn write_text(out: &Staged, text: &str) -> Result<()> {
    hysid::io::atomic::write(&out.tmp, text)
        .with_context(|| format!("cannot write {}", out.target.display()))
}
