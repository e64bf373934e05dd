//! All-or-nothing outputs: the files and directories of one run appear together, or not at
//! all, and never replace an input.
//!
//! An [`OutputSet`] is a transaction over the outputs of a run, in the spirit of the
//! write-to-temporary-then-rename idiom (a `rename(2)` within one directory replaces the
//! destination atomically, POSIX.1-2008):
//!
//! 1. every output path is registered before any work ([`OutputSet::file`],
//!    [`OutputSet::dir`]); registration refuses, as [`Error::OutputClash`], an output that
//!    is a file the run reads, a directory output that holds one, and an output that is
//!    another output or lies inside it — compared by identity: the same file after symbolic
//!    links and `..` (canonical paths) and, on unix, after hard links (device and inode).
//!    An input directory counts with every file directly inside it (the files a command
//!    reads from it). Registration then refuses a destination directory where a probe file
//!    cannot be created and removed;
//! 2. each output is written to a temporary in its destination directory — a file to
//!    `.NAME.hysid-tmp-PID-N`, a directory output to a sibling directory of that form — whose
//!    path registration returns. A temporary file is created through [`create`] or
//!    [`write()`], under the same lock as a signal handler's removal (below), so that no
//!    interrupt can leave one behind;
//! 3. [`OutputSet::commit`] puts every temporary in place, each by one atomic replacement
//!    (a file renamed over the previous one, a directory swapped with it), and only then
//!    deletes the previous outputs; if a replacement fails the previous outputs are put
//!    back. A run killed at any moment leaves each output path with its previous complete
//!    content or the new one.
//!
//! Dropping the set without committing (an error, a `?`) removes every temporary: the
//! previous outputs stay as they were. Signals belong to the program, not to the library:
//! this module installs no handler. A program that wants the temporaries gone on SIGINT or
//! SIGTERM calls [`remove_live_temporaries`] from its own handler before it exits (the
//! `hysid` command line does, then exits with status 130); a process killed without one
//! (SIGKILL) leaves only hidden `.NAME.hysid-tmp-…` files, never a half-written output.
//!
//! [`ensure_finite`] refuses a report holding NaN or ±∞ before it is written, naming the key
//! path of the first one (JSON has no such numbers; `serde_json` would write `null`).

use std::fs;
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use crate::error::{Clash, ClashKind, Error, Result};

/// The prefix-free middle part of every temporary name.
const TMP_TAG: &str = "hysid-tmp";

/// Distinguishes the temporaries of one process.
static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// Temporaries of every live output set, by set ([`remove_live_temporaries`]).
static LIVE: Mutex<Vec<(usize, PathBuf)>> = Mutex::new(Vec::new());

/// The kind of a registered output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    File,
    Dir,
}

/// Entries read from one input directory, or walked in one existing output directory, at
/// most: a bound on the work of registration, far above what a command reads.
const MAX_ENTRIES: usize = 100_000;

/// Which file a path is: its canonical path and, on unix, its device and inode (the same
/// for every hard link of the file).
#[derive(Clone, Debug)]
struct Identity {
    canonical: PathBuf,
    inode: Option<(u64, u64)>,
}

impl Identity {
    /// The identity of `path`, existing or to be created (then without an inode, and
    /// with the part below its deepest existing ancestor taken as written, `..` removing
    /// the component before it); `None` when no ancestor can be resolved.
    fn of(path: &Path) -> Option<Self> {
        let canonical = match canonical_target(path) {
            Ok(c) => c,
            Err(_) => lexical_target(path)?,
        };
        Some(Self {
            canonical,
            inode: inode(path),
        })
    }

    /// The same file: the same canonical path, or the same inode.
    fn same(&self, other: &Identity) -> bool {
        self.canonical == other.canonical || (self.inode.is_some() && self.inode == other.inode)
    }
}

/// Device and inode of the file `path` resolves to.
#[cfg(unix)]
fn inode(path: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
}

/// Device and inode of the file `path` resolves to (not known off unix).
#[cfg(not(unix))]
fn inode(_path: &Path) -> Option<(u64, u64)> {
    None
}

/// One file or directory the run reads.
#[derive(Debug)]
struct Input {
    /// The path as given (for a file inside an input directory: the directory).
    given: PathBuf,
    /// The file itself.
    file: PathBuf,
    id: Identity,
}

/// One registered output: where it goes and where it is being written.
#[derive(Debug)]
struct Output {
    kind: Kind,
    target: PathBuf,
    id: Identity,
    /// The inodes of the files inside an existing directory output (hard links count).
    held: Vec<(u64, u64)>,
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
/// hysid::io::atomic::write(&report, b"{}")?; // the run writes its temporary…
/// outputs.commit()?; // …and the report appears only now
/// assert!(dir.join("report.json").is_file());
/// # std::fs::remove_dir_all(&dir).unwrap();
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct OutputSet {
    id: usize,
    inputs: Vec<Input>,
    outputs: Vec<Output>,
    /// Parent directories created for directory outputs, removed again on failure.
    created: Vec<PathBuf>,
    committed: bool,
}

impl OutputSet {
    /// A new transaction whose outputs must not be, nor hold, any of `inputs`: the files
    /// the run reads, and the directories it reads files from (with every file directly
    /// inside them). Compared by identity (see the [module documentation](self)), so
    /// `./a.csv`, `d/../a.csv`, a symbolic link to `a.csv` and a hard link of it are all
    /// `a.csv`. An input that does not exist yet counts by its path.
    pub fn new(inputs: &[&Path]) -> Result<Self> {
        let mut found = Vec::new();
        for given in inputs {
            let Some(id) = Identity::of(given) else {
                continue;
            };
            if given.is_dir() {
                let entries = fs::read_dir(given).into_iter().flatten().flatten();
                for entry in entries.take(MAX_ENTRIES) {
                    let file = entry.path();
                    if file.is_file() {
                        if let Some(id) = Identity::of(&file) {
                            found.push(Input {
                                given: given.to_path_buf(),
                                file,
                                id,
                            });
                        }
                    }
                }
            }
            found.push(Input {
                given: given.to_path_buf(),
                file: given.to_path_buf(),
                id,
            });
        }
        Ok(Self {
            id: COUNTER.fetch_add(1, Ordering::Relaxed),
            inputs: found,
            outputs: Vec::new(),
            created: Vec::new(),
            committed: false,
        })
    }

    /// Registers the output file `path` and returns the temporary to write it to (in the
    /// same directory, not yet created). Refused: an input, a path already registered, an
    /// existing directory, a missing or unwritable directory.
    pub fn file(&mut self, path: &Path) -> Result<PathBuf> {
        self.check_clash(path, Kind::File)?;
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
        let id = self.check_new(path, Kind::File)?;
        probe(path, parent)?;
        let staged = temporary_beside(path);
        self.push(&mut lock_live(), Kind::File, path, id, staged.clone());
        Ok(staged)
    }

    /// Registers the output directory `path` and returns the temporary directory to fill
    /// (created, beside `path`; missing parents of `path` are created and removed again if
    /// the run fails). Refused: an input or a directory holding one, a path already
    /// registered, an existing file, an unwritable parent.
    pub fn dir(&mut self, path: &Path) -> Result<PathBuf> {
        self.check_clash(path, Kind::Dir)?;
        if path.exists() && !path.is_dir() {
            return Err(invalid_output(
                path,
                "exists and is not a directory; give a directory",
            ));
        }
        let parent = parent_of(path).to_path_buf();
        self.create_parents(&parent)?;
        let id = self.check_new(path, Kind::Dir)?;
        probe(path, &parent)?;
        let staged = temporary_beside(path);
        // Registered and created under one lock, so that a signal handler's removal runs
        // wholly before (and the process ends before the directory exists) or wholly after.
        let mut live = lock_live();
        self.push(&mut live, Kind::Dir, path, id, staged.clone());
        fs::create_dir(&staged).map_err(|source| io(&staged, source))?;
        drop(live);
        Ok(staged)
    }

    /// Renames every temporary into place, replacing previous outputs. Every registered
    /// file must have been written. On an error the previous outputs are restored and the
    /// temporaries removed.
    ///
    /// Each replacement is atomic, so a run killed at any moment (SIGKILL, a power cut
    /// after the data reached the disk) leaves every output path holding either its
    /// previous complete content or the new one, never nothing and never a part:
    /// a file is replaced by one `rename(2)` over it (its previous content stays reachable
    /// through a hard link for the rollback); a directory is swapped with its temporary by
    /// one `renameat2(RENAME_EXCHANGE)` on Linux (elsewhere, or on a file system without
    /// it, it is moved aside and the temporary renamed in: a kill between the two leaves
    /// the path empty and the previous directory beside it under a temporary name).
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
        // The registry stays locked through the replacements: a signal handler's
        // [`remove_live_temporaries`] then runs wholly before them (and the process ends
        // before they start) or wholly after them (with this set's temporaries no longer
        // registered), never while a temporary directory being removed is swapped into
        // place, which would empty the new output.
        let mut live = lock_live();
        let mut replaced: Vec<Replaced> = Vec::with_capacity(self.outputs.len());
        for output in &self.outputs {
            match replace(output) {
                Ok(done) => replaced.push(done),
                Err(source) => {
                    for (output, done) in self.outputs.iter().zip(&replaced).rev() {
                        undo(output, done);
                    }
                    // Released before the set's drop removes the temporaries.
                    drop(live);
                    return Err(io(&output.target, source));
                }
            }
        }
        self.committed = true;
        // The previous copies take the temporaries' places in the registry until they are
        // removed: an interrupt during their removal removes them too (the new outputs
        // are in place by now), so none is left under a temporary name.
        live.retain(|(set, _)| *set != self.id);
        let previous: Vec<PathBuf> = replaced
            .into_iter()
            .filter_map(|done| match done {
                Replaced::Previous(old) => Some(old),
                Replaced::New => None,
            })
            .collect();
        live.extend(previous.iter().map(|old| (self.id, old.clone())));
        drop(live);
        for old in &previous {
            remove_any(old);
        }
        unregister(self.id);
        Ok(())
    }

    /// The identity of a new output path, refused (as any other error of
    /// [`canonical_target`]) when it does not name a file or directory in an existing one.
    fn check_new(&self, path: &Path, kind: Kind) -> Result<Identity> {
        self.check_clash(path, kind)?;
        Ok(Identity {
            canonical: canonical_target(path)?,
            inode: inode(path),
        })
    }

    /// Refuses an output of `kind` at `path` that is an input, holds one, or clashes with
    /// an output registered before (see the [module documentation](self)). A path whose
    /// directory does not exist clashes with nothing (its registration fails otherwise).
    fn check_clash(&self, path: &Path, kind: Kind) -> Result<()> {
        let Some(id) = Identity::of(path) else {
            return Ok(());
        };
        let clash = |other: &Path, file: &Path, kind: ClashKind| {
            Err(Error::OutputClash(Clash {
                output: path.to_path_buf(),
                other: other.to_path_buf(),
                file: file.to_path_buf(),
                kind,
            }))
        };
        if let Some(input) = self.inputs.iter().find(|i| i.id.same(&id)) {
            let what = if kind == Kind::Dir && input.file.is_dir() {
                ClashKind::HoldsInput
            } else {
                ClashKind::Input
            };
            return clash(&input.given, &input.file, what);
        }
        // A directory output is replaced whole: it must hold no input, by path or as a
        // hard link inside it.
        let held = match kind {
            Kind::Dir => held_inodes(path),
            Kind::File => Vec::new(),
        };
        if kind == Kind::Dir {
            let inside = |i: &&Input| {
                i.id.canonical.starts_with(&id.canonical)
                    || i.id.inode.is_some_and(|n| held.contains(&n))
            };
            if let Some(input) = self.inputs.iter().find(inside) {
                return clash(&input.given, &input.file, ClashKind::HoldsInput);
            }
        }
        // The same path, or one inside the other (a file in a directory output).
        let clashes = |o: &&Output| {
            o.id.same(&id)
                || o.id.canonical.starts_with(&id.canonical)
                || id.canonical.starts_with(&o.id.canonical)
                || id.inode.is_some_and(|n| o.held.contains(&n))
                || o.id.inode.is_some_and(|n| held.contains(&n))
        };
        if let Some(other) = self.outputs.iter().find(clashes) {
            return clash(&other.target, &other.target, ClashKind::Output);
        }
        Ok(())
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

    /// Registers `staged` in the locked registry `live` and the output in the set.
    fn push(
        &mut self,
        live: &mut Vec<(usize, PathBuf)>,
        kind: Kind,
        target: &Path,
        id: Identity,
        staged: PathBuf,
    ) {
        live.push((self.id, staged.clone()));
        let held = match kind {
            Kind::Dir => held_inodes(target),
            Kind::File => Vec::new(),
        };
        self.outputs.push(Output {
            kind,
            target: target.to_path_buf(),
            id,
            held,
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
        // Removed while still registered: an interrupt meanwhile removes them too.
        for output in &self.outputs {
            remove_any(&output.staged);
        }
        unregister(self.id);
        for dir in self.created.iter().rev() {
            // Only if still empty: something else may have been put there meanwhile.
            let _ = fs::remove_dir(dir);
        }
    }
}

/// What replacing one output left behind: nothing (the path was new), or the previous
/// content under a temporary name.
enum Replaced {
    /// The output did not exist before.
    New,
    /// The previous output, kept at this path until the commit succeeds.
    Previous(PathBuf),
}

/// Puts `output`'s temporary in place atomically (see [`OutputSet::commit`]).
fn replace(output: &Output) -> std::io::Result<Replaced> {
    if fs::symlink_metadata(&output.target).is_err() {
        fs::rename(&output.staged, &output.target)?;
        return Ok(Replaced::New);
    }
    let old = temporary_beside(&output.target);
    match output.kind {
        Kind::File => {
            if fs::hard_link(&output.target, &old).is_err() {
                // No hard links here: the previous file is moved aside instead.
                fs::rename(&output.target, &old)?;
            }
            fs::rename(&output.staged, &output.target)?;
        }
        Kind::Dir => {
            if exchange(&output.staged, &output.target).is_ok() {
                // The temporary's path now holds the previous directory.
                return Ok(Replaced::Previous(output.staged.clone()));
            }
            fs::rename(&output.target, &old)?;
            if let Err(e) = fs::rename(&output.staged, &output.target) {
                let _ = fs::rename(&old, &output.target);
                return Err(e);
            }
        }
    }
    Ok(Replaced::Previous(old))
}

/// Undoes [`replace`] of `output` after a later output failed: the previous content goes
/// back in place and the new one back to the temporary (which the set then removes).
fn undo(output: &Output, done: &Replaced) {
    match done {
        Replaced::New => {
            let _ = fs::rename(&output.target, &output.staged);
        }
        Replaced::Previous(old) if *old == output.staged => {
            let _ = exchange(&output.staged, &output.target);
        }
        Replaced::Previous(old) => {
            if output.kind == Kind::Dir {
                let _ = fs::rename(&output.target, &output.staged);
            }
            let _ = fs::rename(old, &output.target);
        }
    }
}

/// Swaps the two existing paths `a` and `b` in one atomic step (Linux `renameat2` with
/// `RENAME_EXCHANGE`, since 3.15); an error where the system or the file system lacks it.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt;
    let c = |p: &Path| {
        CString::new(p.as_os_str().as_bytes())
            .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, e))
    };
    let (a, b) = (c(a)?, c(b)?);
    // SAFETY: both arguments are NUL-terminated strings that outlive the call; the system
    // call reads them and touches no memory of ours.
    let status = unsafe {
        libc::syscall(
            libc::SYS_renameat2,
            libc::AT_FDCWD,
            a.as_ptr(),
            libc::AT_FDCWD,
            b.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if status == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

/// Not available off Linux: directories are replaced in two renames.
#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> std::io::Result<()> {
    Err(std::io::Error::from(std::io::ErrorKind::Unsupported))
}

/// The inodes of the files under the existing directory `dir` (symbolic links not
/// followed: replacing the directory removes a link, not what it points to), at most
/// [`MAX_ENTRIES`] entries; empty when `dir` is not a directory or off unix.
fn held_inodes(dir: &Path) -> Vec<(u64, u64)> {
    let mut held = Vec::new();
    if !dir.is_dir() {
        return held;
    }
    let mut pending = vec![dir.to_path_buf()];
    let mut seen = 0usize;
    while let Some(d) = pending.pop() {
        for entry in fs::read_dir(&d).into_iter().flatten().flatten() {
            seen += 1;
            if seen > MAX_ENTRIES {
                return held;
            }
            let path = entry.path();
            match fs::symlink_metadata(&path) {
                Ok(m) if m.is_dir() => pending.push(path),
                Ok(m) if m.is_file() => held.extend(inode(&path)),
                _ => {}
            }
        }
    }
    held
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
    lock_live().retain(|(set, _)| *set != id);
}

/// The registry of live temporaries, locked. A thread that panicked while holding it
/// leaves it poisoned; the paths in it are still valid.
fn lock_live() -> std::sync::MutexGuard<'static, Vec<(usize, PathBuf)>> {
    match LIVE.lock() {
        Ok(live) => live,
        Err(poisoned) => poisoned.into_inner(),
    }
}

/// Removes the temporaries of every live output set of the process (the previous outputs
/// stay as they were): for a program's own SIGINT/SIGTERM handler, called right before it
/// exits. The process must end after it: the registry's lock stays held, so that no output
/// is registered (and no temporary made) between the removal and the exit; a later
/// registration waits for ever.
///
/// It takes a lock, so call it from a handler that runs on an ordinary thread (as the
/// `ctrlc` crate's does), not from an async-signal context. The run's other threads go on
/// meanwhile: a file written into a temporary directory while it is being removed keeps
/// the directory alive, so the removal is repeated until every temporary is gone (at most
/// a hundred rounds a millisecond apart). No new temporary can appear meanwhile:
/// registering one, creating a directory one ([`OutputSet::dir`]) or a file one ([`create`])
/// takes the same lock, which is held from here on. Nor can a commit put
/// one in place meanwhile: [`OutputSet::commit`] holds the lock through its replacements.
pub fn remove_live_temporaries() {
    let live = lock_live();
    for _ in 0..REMOVAL_ROUNDS {
        for (_, path) in live.iter() {
            remove_any(path);
        }
        if live
            .iter()
            .all(|(_, path)| fs::symlink_metadata(path).is_err())
        {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    // Held until the process ends (see above).
    std::mem::forget(live);
}

/// Creates (or truncates) the registered temporary file `staged` — a path returned by
/// [`OutputSet::file`] — for writing.
///
/// The file is created under the registry's lock, as [`OutputSet::dir`] creates its
/// directory: a signal handler's [`remove_live_temporaries`] then runs wholly before (it
/// keeps the lock until the process ends, so this call waits for the end) or wholly after
/// (and removes the file). Creating the temporary any other way (`fs::write`,
/// `File::create`) could recreate it between the handler's removal and the process's end.
/// Files *inside* a temporary directory need none of this: once the directory is removed
/// they cannot be created. Refused: a path that is not a live temporary of this process.
pub fn create(staged: &Path) -> Result<fs::File> {
    let live = lock_live();
    if !live.iter().any(|(_, path)| path == staged) {
        return Err(Error::InvalidOutput(format!(
            "{} is not a registered temporary; register the output with OutputSet::file first",
            staged.display()
        )));
    }
    let file = fs::File::create(staged).map_err(|source| io(staged, source))?;
    drop(live);
    Ok(file)
}

/// Writes `contents` to the registered temporary file `staged` ([`create`], then the bytes).
pub fn write(staged: &Path, contents: impl AsRef<[u8]>) -> Result<()> {
    use std::io::Write;
    create(staged)?
        .write_all(contents.as_ref())
        .map_err(|source| io(staged, source))
}

/// Rounds of [`remove_live_temporaries`] at most.
const REMOVAL_ROUNDS: usize = 100;

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

/// The path `path` will have once its missing directories are created: its deepest
/// existing ancestor canonicalised, joined with the rest, `.` dropped and `..` removing the
/// component before it.
fn lexical_target(path: &Path) -> Option<PathBuf> {
    let absolute = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir().ok()?.join(path)
    };
    let parts: Vec<Component> = absolute.components().collect();
    let (exists, mut out) = (0..=parts.len()).rev().find_map(|n| {
        Some((
            n,
            fs::canonicalize(parts[..n].iter().collect::<PathBuf>()).ok()?,
        ))
    })?;
    for part in &parts[exists..] {
        match part {
            Component::Normal(name) => out.push(name),
            Component::ParentDir => {
                out.pop();
            }
            _ => {}
        }
    }
    Some(out)
}

/// Creates and removes a probe file in `dir`: the only sure test that it is writable.
fn probe(path: &Path, dir: &Path) -> Result<()> {
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let probe = dir.join(format!(".hysid-probe-{}-{n}", std::process::id()));
    // Under the registry's lock: a signal handler's removal ([`remove_live_temporaries`])
    // holds it until the process ends, so the probe is never left behind by an interrupt.
    let _live = lock_live();
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
