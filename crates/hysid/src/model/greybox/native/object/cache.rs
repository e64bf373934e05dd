//! The cache of compiled models: its directory, its key, its entries and their bound. The
//! method and the threat model are `object.rs`'s module docs; this file holds the checks.
//!
//! Layout, under the base directory `$HYSID_CACHE_DIR` (else `$XDG_CACHE_HOME/hysid`, else
//! `~/.cache/hysid`):
//!
//! ```text
//! key                 32 random bytes, mode 0600: the MAC key
//! native/             mode 0700
//!   NAME.so           a compiled model, NAME = 64 hex digits (object.rs: entry_name)
//!   NAME.mac          keyed BLAKE3 of NAME and NAME.so's bytes, 64 hex digits
//!   .build-XXXXXX/    a compilation in progress (tempfile, mode 0700)
//! ```

use std::fs::{self, File, Metadata, OpenOptions, Permissions};
use std::io::{ErrorKind, Read, Write};
use std::os::unix::fs::{DirBuilderExt, MetadataExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

use tempfile::TempDir;

/// Entries kept at most (a fit of one file makes two to four).
const MAX_ENTRIES: usize = 256;
/// Bytes of compiled models kept at most (an entry is 15–60 kB).
const MAX_BYTES: u64 = 64 << 20;
/// Age after which what a process left behind when it died (a build directory, a stray
/// file) is removed.
const STALE: Duration = Duration::from_secs(3600);
/// The prefix of build directories.
const BUILD: &str = ".build-";
/// Mode bits no directory or file of the cache may have: writable by group or others.
const OTHERS_WRITE: u32 = 0o022;
/// Mode bits the key may not have: any access by group or others.
const OTHERS_ANY: u32 = 0o077;

/// A cache directory that passed its checks, with its key.
pub(super) struct Cache {
    /// `native/` of the base directory.
    dir: PathBuf,
    key: [u8; blake3::KEY_LEN],
}

/// What a look-up found.
pub(super) enum Lookup {
    /// The library's bytes, read once, their MAC checked.
    Verified(Vec<u8>),
    /// No entry (or no MAC beside it yet: a writer between its two renames).
    Missing,
    /// A library whose MAC does not match (replaced or damaged), at this path.
    Mismatch(PathBuf),
}

impl Cache {
    /// The cache of this user, created when missing (mode 0700 for each level created),
    /// with its key (created on first use). None when no location is set (no `HOME`);
    /// an error, one line, when the directory or the key is not this user's alone.
    pub(super) fn open() -> Result<Option<Self>, String> {
        let Some(base) = location() else {
            return Ok(None);
        };
        let dir = base.join("native");
        fs::DirBuilder::new()
            .recursive(true)
            .mode(0o700)
            .create(&dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        for d in [&base, &dir] {
            let meta = fs::metadata(d).map_err(|e| format!("cannot read {}: {e}", d.display()))?;
            if !meta.is_dir() {
                return Err(format!("{} is not a directory", d.display()));
            }
            owned(d, &meta, OTHERS_WRITE)?;
        }
        let key = key(&base.join("key"))?;
        Ok(Some(Self { dir, key }))
    }

    /// The entry `name`: its library opened and read once, and the keyed hash of `name` and
    /// those bytes compared in constant time with the MAC written beside it; the bytes when
    /// they match. An error when a
    /// file of the entry is not this user's alone (or not a regular file, or a symlink).
    pub(super) fn find(&self, name: &str) -> Result<Lookup, String> {
        let so = self.dir.join(format!("{name}.so"));
        let Some(mut library) = open_owned(&so, OTHERS_WRITE)? else {
            return Ok(Lookup::Missing);
        };
        let mac = self.dir.join(format!("{name}.mac"));
        let Some(mut mac_file) = open_owned(&mac, OTHERS_WRITE)? else {
            return Ok(Lookup::Missing);
        };
        let mut stored = String::new();
        (&mut mac_file)
            .take(2 * blake3::OUT_LEN as u64 + 1)
            .read_to_string(&mut stored)
            .map_err(|e| format!("cannot read {}: {e}", mac.display()))?;
        let mut bytes = Vec::new();
        library
            .read_to_end(&mut bytes)
            .map_err(|e| format!("cannot read {}: {e}", so.display()))?;
        // `blake3::Hash`'s equality is constant-time.
        match blake3::Hash::from_hex(stored.trim()) {
            Ok(stored) if stored == self.mac(name, &bytes) => {
                // The mtime is the least-recently-used order of `trim`.
                let _ = library.set_modified(SystemTime::now());
                Ok(Lookup::Verified(bytes))
            }
            _ => Ok(Lookup::Mismatch(so)),
        }
    }

    /// A private directory to compile in, inside the cache (so that its files are renamed
    /// into place on the same filesystem), removed when dropped; what dead processes left
    /// behind is removed first.
    pub(super) fn build_dir(&self) -> Result<TempDir, String> {
        self.remove_stale();
        self.private_dir()
    }

    /// A private directory inside the cache (`tempfile`, mode 0700, a name of its own),
    /// removed when dropped.
    pub(super) fn private_dir(&self) -> Result<TempDir, String> {
        tempfile::Builder::new()
            .prefix(BUILD)
            .tempdir_in(&self.dir)
            .map_err(|e| {
                format!(
                    "cannot create a build directory in {}: {e}",
                    self.dir.display()
                )
            })
    }

    /// Stores the library `so` (in a [`Cache::build_dir`]) as the entry `name`: made 0700,
    /// its MAC written beside it (0600), both renamed into place, the library first (a
    /// reader meanwhile finds no MAC: a miss). Then the cache is trimmed to its bound.
    pub(super) fn store(&self, name: &str, so: &Path) -> std::io::Result<()> {
        fs::set_permissions(so, Permissions::from_mode(0o700))?;
        let mac = self.mac(name, &fs::read(so)?);
        let mac_path = so.with_extension("mac");
        OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o600)
            .open(&mac_path)?
            .write_all(mac.to_hex().as_bytes())?;
        fs::rename(so, self.dir.join(format!("{name}.so")))?;
        fs::rename(&mac_path, self.dir.join(format!("{name}.mac")))?;
        self.trim();
        Ok(())
    }

    /// The directory of the entries, for messages.
    pub(super) fn dir(&self) -> &Path {
        &self.dir
    }

    /// The MAC of the entry `name` with these library bytes: keyed BLAKE3 of both (NAME
    /// has a fixed length, so the two cannot run into each other).
    fn mac(&self, name: &str, bytes: &[u8]) -> blake3::Hash {
        let mut hasher = blake3::Hasher::new_keyed(&self.key);
        hasher.update(name.as_bytes());
        hasher.update(bytes);
        hasher.finalize()
    }

    /// The entries (`NAME.so`), with their last use (mtime) and size.
    fn entries(&self) -> Vec<(SystemTime, u64, String)> {
        let Ok(listing) = fs::read_dir(&self.dir) else {
            return Vec::new();
        };
        listing
            .flatten()
            .filter_map(|entry| {
                let name = entry.file_name().into_string().ok()?;
                let stem = name.strip_suffix(".so").filter(|s| is_name(s))?;
                let meta = entry.metadata().ok()?;
                Some((meta.modified().ok()?, meta.len(), stem.to_string()))
            })
            .collect()
    }

    /// Removes the least recently used entries until at most [`MAX_ENTRIES`] entries of at
    /// most [`MAX_BYTES`] in all remain.
    fn trim(&self) {
        let mut entries = self.entries();
        entries.sort_by_key(|e| std::cmp::Reverse(e.0));
        let (mut count, mut bytes) = (0, 0);
        for (_, size, name) in entries {
            if count < MAX_ENTRIES && bytes + size <= MAX_BYTES {
                count += 1;
                bytes += size;
            } else {
                let _ = fs::remove_file(self.dir.join(format!("{name}.so")));
                let _ = fs::remove_file(self.dir.join(format!("{name}.mac")));
            }
        }
    }

    /// Removes, once they are [`STALE`], the build directories of processes that died while
    /// compiling, MACs without their library, and files of no entry (earlier hysid versions'
    /// `KEY.c`, `KEY.so` and temporaries).
    fn remove_stale(&self) {
        let Ok(listing) = fs::read_dir(&self.dir) else {
            return;
        };
        for entry in listing.flatten() {
            let stale = entry
                .metadata()
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|age| age > STALE);
            if !stale {
                continue;
            }
            let file = entry.file_name();
            let file = file.to_string_lossy();
            let path = entry.path();
            if file.starts_with(BUILD) {
                let _ = fs::remove_dir_all(&path);
            } else if let Some(name) = file.strip_suffix(".mac").filter(|s| is_name(s)) {
                if !self.dir.join(format!("{name}.so")).exists() {
                    let _ = fs::remove_file(&path);
                }
            } else if !file.strip_suffix(".so").is_some_and(is_name) {
                let _ = fs::remove_file(&path);
            }
        }
    }
}

/// The base directory (see the module docs); None without `HOME` and the variables.
fn location() -> Option<PathBuf> {
    let var = |name: &str| {
        std::env::var_os(name)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("HYSID_CACHE_DIR")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("hysid")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("hysid")))
}

/// Whether `stem` is an entry's NAME: 64 lower-case hex digits.
fn is_name(stem: &str) -> bool {
    stem.len() == 2 * blake3::OUT_LEN
        && stem.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f'))
}

/// The key at `path`: read, or made when missing — 32 bytes of the system's random source
/// written to a new file (`O_EXCL`, mode 0600) beside it and linked into place only if no
/// other process made one first (`persist_noclobber`), in which case that one is used.
fn key(path: &Path) -> Result<[u8; blake3::KEY_LEN], String> {
    if let Some(file) = open_owned(path, OTHERS_ANY)? {
        return read_key(file, path);
    }
    let mut key = [0u8; blake3::KEY_LEN];
    getrandom::fill(&mut key)
        .map_err(|e| format!("no random bytes for the key {}: {e}", path.display()))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let cannot = |e: std::io::Error| format!("cannot write the key {}: {e}", path.display());
    let mut file = tempfile::Builder::new()
        .prefix(".key-")
        .tempfile_in(dir)
        .map_err(cannot)?;
    file.write_all(&key).map_err(cannot)?;
    file.as_file().sync_all().map_err(cannot)?;
    match file.persist_noclobber(path) {
        Ok(_) => Ok(key),
        Err(e) if e.error.kind() == ErrorKind::AlreadyExists => match open_owned(path, OTHERS_ANY)?
        {
            Some(file) => read_key(file, path),
            None => Err(format!(
                "the key {} vanished while it was made",
                path.display()
            )),
        },
        Err(e) => Err(cannot(e.error)),
    }
}

/// The 32 bytes of the key file `file`.
fn read_key(file: File, path: &Path) -> Result<[u8; blake3::KEY_LEN], String> {
    let mut bytes = Vec::new();
    file.take(blake3::KEY_LEN as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read the key {}: {e}", path.display()))?;
    bytes.try_into().map_err(|_| {
        format!(
            "{} is not a key of {} bytes (delete it: a new one is made)",
            path.display(),
            blake3::KEY_LEN
        )
    })
}

/// The regular file at `path`, opened without following a symlink and checked on the open
/// file: this user's, without the mode bits `forbidden`. None when there is no such file.
fn open_owned(path: &Path, forbidden: u32) -> Result<Option<File>, String> {
    // O_NONBLOCK: a FIFO put in the file's place fails the regular-file test below
    // instead of blocking the open.
    let file = match OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path)
    {
        Ok(file) => file,
        Err(e) if e.kind() == ErrorKind::NotFound => return Ok(None),
        Err(e) if e.raw_os_error() == Some(libc::ELOOP) => {
            return Err(format!("{} is a symbolic link", path.display()))
        }
        Err(e) => return Err(format!("cannot open {}: {e}", path.display())),
    };
    let meta = file
        .metadata()
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if !meta.is_file() {
        return Err(format!("{} is not a regular file", path.display()));
    }
    owned(path, &meta, forbidden)?;
    Ok(Some(file))
}

/// Whether `meta` (of `path`) is owned by the effective user and has none of the mode
/// bits `forbidden`; the error names which and how.
fn owned(path: &Path, meta: &Metadata, forbidden: u32) -> Result<(), String> {
    // SAFETY: geteuid has no preconditions and cannot fail.
    let user = unsafe { libc::geteuid() };
    if meta.uid() != user {
        return Err(format!(
            "{} belongs to uid {}, not to this user (uid {user})",
            path.display(),
            meta.uid()
        ));
    }
    let mode = meta.mode() & 0o777;
    if mode & forbidden != 0 {
        return Err(format!(
            "{} has mode {mode:03o}, open to others",
            path.display()
        ));
    }
    Ok(())
}
