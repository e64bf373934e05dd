//! Writing an export into its output directory, as every hysid output is written: all or
//! nothing, never over other files, never over an input.
//!
//! The directory is registered in an [`OutputSet`] before anything is read (refused when it
//! is an input of the run, holds one, or is a file), then refused when it exists and holds
//! anything at all — an export never overwrites and never mixes its files with others. The
//! files are written into a temporary directory beside it, which is renamed into place when
//! complete; on any error the temporary goes and the directory stays as it was (on SIGINT
//! too, in a program whose handler calls [`crate::io::atomic::remove_live_temporaries`], as the
//! `hysid` command line does).

use super::GeneratedFile;
use crate::io::atomic::OutputSet;
use crate::{Error, Result};
use std::path::{Component, Path, PathBuf};

/// The output directory of one export, registered and checked, not yet written.
#[derive(Debug)]
pub struct ExportDir {
    set: OutputSet,
    staged: PathBuf,
    target: PathBuf,
}

impl ExportDir {
    /// Registers `out` (created if missing, with its parents) as the directory of an export
    /// that reads `inputs`. Refused: an input or a directory holding one
    /// ([`Error::OutputClash`]), an existing file, an existing directory that is not empty.
    pub fn new(out: &Path, inputs: &[&Path]) -> Result<Self> {
        let mut set = OutputSet::new(inputs)?;
        let staged = set.dir(out)?;
        if let Ok(mut entries) = std::fs::read_dir(out) {
            if let Some(entry) = entries.next() {
                let held =
                    entry.map_or_else(|_| "a file".into(), |e| e.path().display().to_string());
                return Err(Error::InvalidOutput(format!(
                    "the output directory {} is not empty (it holds {held}); an export never \
                     overwrites or mixes with other files: give a new or empty directory",
                    out.display()
                )));
            }
        }
        Ok(Self {
            set,
            staged,
            target: out.to_path_buf(),
        })
    }

    /// The directory the export appears in.
    pub fn path(&self) -> &Path {
        &self.target
    }

    /// Writes `files` (paths relative to the directory) and renames the directory into
    /// place.
    pub fn write(self, files: &[GeneratedFile]) -> Result<()> {
        for file in files {
            let relative = file
                .path
                .components()
                .all(|c| matches!(c, Component::Normal(_)));
            if !relative || file.path.as_os_str().is_empty() {
                return Err(Error::InvalidOutput(format!(
                    "the exported file {} is not a path inside the output directory",
                    file.path.display()
                )));
            }
            // The directories below the staged one, one by one: the staged directory itself
            // is never recreated, so that an interrupt's removal of it is final.
            let path = self.staged.join(&file.path);
            let mut parent = self.staged.clone();
            for part in file.path.parent().into_iter().flat_map(Path::components) {
                parent.push(part);
                match std::fs::create_dir(&parent) {
                    Err(e) if e.kind() != std::io::ErrorKind::AlreadyExists => {
                        return Err(io(&parent, e));
                    }
                    _ => {}
                }
            }
            std::fs::write(&path, &file.contents).map_err(|source| io(&path, source))?;
        }
        self.set.commit()
    }
}

fn io(path: &Path, source: std::io::Error) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        source,
    }
}
