//! All-or-nothing outputs: the files and directories of one run appear together, or not at
//! all, and never replace an input.
//!
//! An [`OutputSet`] is a transaction over the outputs of a run, in the spirit of the
//! write-to-temporary-then-rename idiom (a `rename(2)` within one directory replaces the
//! destination atomically, POSIX.1-2008):
//!
//! 1. every output path is registered before any work ([`OutputSet::file`],
//!    [`OutputSet::dir`]); registration refuses a path equal to an input (compared
//!    canonicalised), a path given twice, a directory output that contains an input, and a
//!    destination directory where a probe file cannot be created and removed;
//! 2. each output is written to a temporary in its destination directory — a file to
//!    `.NAME.hysid-tmp-PID-N`, a directory output to a sibling directory of that form — whose
//!    path registration returns;
//! 3. [`OutputSet::commit`] moves every previous output aside, renames every temporary into
//!    place and only then deletes what was set aside; if a rename fails the previous outputs
//!    are put back.
//!
//! Dropping the set without committing (an error, a `?`) removes every temporary, and so
//! does SIGINT or SIGTERM (a handler is installed with the first set; the process then exits
//! with status 130): the previous outputs stay as they were.
//!
//! [`ensure_finite`] refuses a report holding NaN or ±∞ before it is written, naming the key
//! path of the first one (JSON has no such numbers; `serde_json` would write `null`).

use std::fs;
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, Once};

use crate::error::{Error, Result};

/// The prefix-free middle part of every temporary name.
const TMP_TAG: &str = "hysid-tmp";

/// Distinguishes the temporaries of one process.
static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// Temporaries of every live output set, by set, removed by the signal handler.
static LIVE: Mutex<Vec<(usize, PathBuf)>> = Mutex::new(Vec::new());

/// Installs the SIGINT/SIGTERM handler once.
static HANDLER: Once = Once::new();

/// The kind of a registered output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    File,
    Dir,
}

/// One registered output: where it goes and where it is being written.
#[derive(Debug)]
struct Output {
    kind: Kind,
    target: PathBuf,
    canonical: PathBuf,
    staged: PathBuf,
}

/// The outputs of one run, written to temporaries and renamed into place together by
/// [`commit`](Self::commit). See the [module documentation](self).
///
/// ```
/// # fn main() -> hysid::Result<()> {
/// use hysid::io::atomic::OutputSet;
/// let dir = std::env::temp_dir().join(format!("hysid-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let mut outputs = OutputSet::new(&[])?;
/// let report = outputs.file(&dir.join("report.json"))?;
/// std::fs::write(&report, b"{}").unwrap(); // the run writes its temporary…
/// outputs.commit()?; // …and the report appears only now
/// assert!(dir.join("report.json").is_file());
/// # std::fs::remove_dir_all(&dir).unwrap();
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct OutputSet {
    id: usize,
    inputs: Vec<PathBuf>,
    outputs: Vec<Output>,
    /// Parent directories created for directory outputs, removed again on failure.
    created: Vec<PathBuf>,
    committed: bool,
}

impl OutputSet {
    /// A new transaction whose outputs must differ from every path of `inputs` (those that
    /// exist; compared canonicalised, so `./a.csv` and `a.csv` are the same).
    pub fn new(inputs: &[&Path]) -> Result<Self> {
        install_signal_cleanup();
        let inputs = inputs
            .iter()
            .filter_map(|p| fs::canonicalize(p).ok())
            .collect();
        Ok(Self {
            id: COUNTER.fetch_add(1, Ordering::Relaxed),
            inputs,
            outputs: Vec::new(),
            created: Vec::new(),
            committed: false,
        })
    }

    /// Registers the output file `path` and returns the temporary to write it to (in the
    /// same directory, not yet created). Refused: an input, a path already registered, an
    /// existing directory, a missing or unwritable directory.
    pub fn file(&mut self, path: &Path) -> Result<PathBuf> {
        if path.is_dir() {
            return Err(invalid_output(path, "is a directory; give a file name"));
        }
        let parent = parent_of(path);
        if !parent.is_dir() {
            return Err(invalid_output(
                path,
                &format!(
                    "directory {} does not exist; create it or choose another path",
                    parent.display()
                ),
            ));
        }
        let canonical = self.check_new(path)?;
        probe(path, parent)?;
        let staged = temporary_beside(path);
        self.push(Kind::File, path, canonical, staged.clone());
        Ok(staged)
    }

    /// Registers the output directory `path` and returns the temporary directory to fill
    /// (created, beside `path`; missing parents of `path` are created and removed again if
    /// the run fails). Refused: an input or a directory holding one, a path already
    /// registered, an existing file, an unwritable parent.
    pub fn dir(&mut self, path: &Path) -> Result<PathBuf> {
        if path.exists() && !path.is_dir() {
            return Err(invalid_output(
                path,
                "exists and is not a directory; give a directory",
            ));
        }
        let parent = parent_of(path).to_path_buf();
        self.create_parents(&parent)?;
        let canonical = self.check_new(path)?;
        if let Some(input) = self.inputs.iter().find(|i| i.starts_with(&canonical)) {
            return Err(invalid_output(
                path,
                &format!(
                    "holds the input {}, which replacing the directory would delete; choose another directory",
                    input.display()
                ),
            ));
        }
        probe(path, &parent)?;
        let staged = temporary_beside(path);
        fs::create_dir(&staged).map_err(|source| io(&staged, source))?;
        self.push(Kind::Dir, path, canonical, staged.clone());
        Ok(staged)
    }

    /// Renames every temporary into place, replacing previous outputs. Every registered
    /// file must have been written. On an error the previous outputs are restored and the
    /// temporaries removed.
    pub fn commit(mut self) -> Result<()> {
        if let Some(missing) = self
            .outputs
            .iter()
            .find(|o| o.kind == Kind::File && !o.staged.is_file())
        {
            return Err(Error::InvalidData(format!(
                "output {} was registered but never written; nothing was replaced",
                missing.target.display()
            )));
        }
        let mut aside: Vec<(usize, PathBuf)> = Vec::new();
        for (k, output) in self.outputs.iter().enumerate() {
            if fs::symlink_metadata(&output.target).is_ok() {
                let old = temporary_beside(&output.target);
                if let Err(source) = fs::rename(&output.target, &old) {
                    restore(&self.outputs, &aside, 0);
                    return Err(io(&output.target, source));
                }
                aside.push((k, old));
            }
        }
        for (k, output) in self.outputs.iter().enumerate() {
            if let Err(source) = fs::rename(&output.staged, &output.target) {
                restore(&self.outputs, &aside, k);
                return Err(io(&output.target, source));
            }
        }
        self.committed = true;
        unregister(self.id);
        for (k, old) in aside {
            // The new outputs are in place; a leftover old copy is only untidy.
            let _ = match self.outputs[k].kind {
                Kind::File => fs::remove_file(&old),
                Kind::Dir => fs::remove_dir_all(&old),
            };
        }
        Ok(())
    }

    /// The canonical form of a new output path, refused if it is an input or registered.
    fn check_new(&self, path: &Path) -> Result<PathBuf> {
        let canonical = canonical_target(path)?;
        if self.inputs.contains(&canonical) {
            return Err(invalid_output(
                path,
                "is also an input of this run; writing it would destroy the input: choose another output path",
            ));
        }
        // The same path, or one inside the other (a file in a directory output).
        let clash = self
            .outputs
            .iter()
            .find(|o| o.canonical.starts_with(&canonical) || canonical.starts_with(&o.canonical));
        if let Some(other) = clash {
            return Err(invalid_output(
                path,
                &format!(
                    "clashes with the output {} of the same run; give each output its own path",
                    other.target.display()
                ),
            ));
        }
        Ok(canonical)
    }

    /// Creates the missing ancestors of `dir`, remembering them for a rollback.
    fn create_parents(&mut self, dir: &Path) -> Result<()> {
        let missing: Vec<PathBuf> = dir
            .ancestors()
            .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
            .map(Path::to_path_buf)
            .collect();
        for d in missing.iter().rev() {
            fs::create_dir(d).map_err(|source| io(d, source))?;
            self.created.push(d.clone());
        }
        Ok(())
    }

    fn push(&mut self, kind: Kind, target: &Path, canonical: PathBuf, staged: PathBuf) {
        if let Ok(mut live) = LIVE.lock() {
            live.push((self.id, staged.clone()));
        }
        self.outputs.push(Output {
            kind,
            target: target.to_path_buf(),
            canonical,
            staged,
        });
    }
}

impl Drop for OutputSet {
    /// Without a commit: removes every temporary and every parent directory created.
    fn drop(&mut self) {
        if self.committed {
            return;
        }
        unregister(self.id);
        for output in &self.outputs {
            remove_any(&output.staged);
        }
        for dir in self.created.iter().rev() {
            // Only if still empty: something else may have been put there meanwhile.
            let _ = fs::remove_dir(dir);
        }
    }
}

/// Undoes a failed commit: the first `moved` outputs go back to their temporaries, and
/// what was set aside goes back in place.
fn restore(outputs: &[Output], aside: &[(usize, PathBuf)], moved: usize) {
    for output in &outputs[..moved] {
        let _ = fs::rename(&output.target, &output.staged);
    }
    for (k, old) in aside {
        let _ = fs::rename(old, &outputs[*k].target);
    }
}

/// Removes a file or a directory tree, ignoring what is already gone.
fn remove_any(path: &Path) {
    match fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => {
            let _ = fs::remove_dir_all(path);
        }
        Ok(_) => {
            let _ = fs::remove_file(path);
        }
        Err(_) => {}
    }
}

fn unregister(id: usize) {
    if let Ok(mut live) = LIVE.lock() {
        live.retain(|(set, _)| *set != id);
    }
}

/// On SIGINT or SIGTERM, removes the temporaries of every live set and exits with 130.
/// Does nothing when the program has installed its own handler already.
fn install_signal_cleanup() {
    HANDLER.call_once(|| {
        let _ = ctrlc::set_handler(|| {
            // A panicking thread may have poisoned the lock; the paths are still valid.
            let live = match LIVE.lock() {
                Ok(live) => live,
                Err(poisoned) => poisoned.into_inner(),
            };
            for (_, path) in live.iter() {
                remove_any(path);
            }
            std::process::exit(130);
        });
    });
}

/// The directory `path` is written into ("." for a bare name).
fn parent_of(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// `DIR/.NAME.hysid-tmp-PID-N` for `DIR/NAME`.
fn temporary_beside(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    parent_of(path).join(format!(".{name}.{TMP_TAG}-{}-{n}", std::process::id()))
}

/// The canonical path `path` has or will have: its existing parent canonicalised, joined
/// with its name.
fn canonical_target(path: &Path) -> Result<PathBuf> {
    if let Ok(c) = fs::canonicalize(path) {
        return Ok(c);
    }
    let name = match path.components().next_back() {
        Some(Component::Normal(name)) => name.to_owned(),
        _ => return Err(invalid_output(path, "does not name a file or directory")),
    };
    let parent = fs::canonicalize(parent_of(path)).map_err(|source| io(path, source))?;
    Ok(parent.join(name))
}

/// Creates and removes a probe file in `dir`: the only sure test that it is writable.
fn probe(path: &Path, dir: &Path) -> Result<()> {
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let probe = dir.join(format!(".hysid-probe-{}-{n}", std::process::id()));
    let created = fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe);
    match created {
        Ok(_) => fs::remove_file(&probe).map_err(|source| io(&probe, source)),
        Err(e) => Err(invalid_output(
            path,
            &format!(
                "cannot be written: directory {} is not writable ({e}); choose another path",
                dir.display()
            ),
        )),
    }
}

fn invalid_output(path: &Path, message: &str) -> Error {
    Error::InvalidOutput(format!("output {}: {message}", path.display()))
}

fn io(path: &Path, source: std::io::Error) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Refuses a JSON value holding a non-finite number, naming its key path (`a.b[2]`).
///
/// A [`serde_json::Value`] cannot hold NaN or ±∞ — `json!` and `to_value` turn them into
/// `null` — so check typed reports with [`ensure_finite`] *before* converting them.
pub fn ensure_finite_json(value: &serde_json::Value) -> Result<()> {
    ensure_finite(value)
}

/// Refuses a serialisable value holding a non-finite `f32` or `f64`, naming the key path of
/// the first one (`model.parameters.alpha.value`, `history[3]`), as the numerical failure
/// [`Error::NonFiniteResult`] — JSON has no such numbers and `serde_json` would write `null`.
pub fn ensure_finite<T: serde::Serialize + ?Sized>(value: &T) -> Result<()> {
    let mut walker = finite::Walker::default();
    match value.serialize(&mut walker) {
        Ok(()) => Ok(()),
        Err(found) => Err(Error::NonFiniteResult {
            key: if found.path.is_empty() {
                "(top level)".into()
            } else {
                found.path
            },
            value: found.value,
        }),
    }
}

mod finite;
