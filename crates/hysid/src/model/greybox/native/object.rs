//! C source to a loaded shared object: compiled by the machine's C compiler
//! ([`Compiler`]: `$CC` split at whitespace as make splits it, else `cc`) in a private
//! temporary directory, kept in a cache that only its user can put code in, and loaded with
//! `dlopen`.
//!
//! # Method
//!
//! * **Naming.** An object is named by the BLAKE3 hash of the compiler (program and
//!   arguments), its flags and the source: NAME, 64 hex digits (the collision resistance of
//!   a cryptographic hash makes the name stand for its inputs; no copy of the source is
//!   kept to compare).
//! * **The cache** (`object/cache.rs`) is `$HYSID_CACHE_DIR`, else `$XDG_CACHE_HOME/hysid`,
//!   else `~/.cache/hysid` (the base), subdirectory `native/`; each level hysid creates is
//!   made mode 0700. Before any use, the base and `native/` must belong to the effective
//!   user (`geteuid`) and not be writable by group or others, and so must each file read
//!   from them — opened without following a symbolic link and checked on the open file.
//!   Otherwise the cache is refused for that load: one warning line on stderr, and the object
//!   is compiled in a private temporary directory of the system's (`tempfile`, mode 0700),
//!   loaded and removed — correct, only not cached. The same happens, without a warning,
//!   when there is no location (no `HOME`).
//! * **The key**: 32 bytes of the system's random source (`getrandom`) in the file `key` of
//!   the base, mode 0600 — made as a new file (`O_EXCL`, 0600 from the start) and linked
//!   into place only if no other process made one first; refused unless the user's and
//!   0600 (or stricter).
//! * **A load** opens `native/NAME.so`, reads its bytes once, and compares their keyed
//!   BLAKE3 hash (with NAME: a MAC under the key) in constant time with `native/NAME.mac`,
//!   written when hysid built the library. Only a match loads it: the checked bytes are
//!   written to a new file in a private directory made inside `native/` (`tempfile`, 0700;
//!   removed once loaded, the library staying mapped) and `dlopen` maps that file, so the
//!   bytes that run are the bytes that were checked (and each load has a path of its own:
//!   `dlopen` returns the library it already holds under a path). The entry's mtime is then
//!   set to now (its last use). A library that does not
//!   match is never opened by `dlopen` (its constructors never run): it is reported in one
//!   warning line and compiled again, which replaces it.
//! * **A miss** compiles in a build directory made inside `native/` (`tempfile`, mode 0700,
//!   `.build-XXXXXX`: the same filesystem, so the result is renamed, not copied), loads the
//!   library from there, and stores it: made 0700, its MAC computed from the bytes the
//!   compiler wrote and written (0600) beside it, the library renamed into place first and
//!   the MAC second. Two processes compiling the same source at once each rename a complete
//!   file; a reader between the two renames finds no MAC, a miss. Build directories of a
//!   process that died while compiling, and files of no entry, are removed an hour later.
//! * **Bound.** After each store, the least recently used entries (oldest mtime) are removed
//!   until at most 256 entries of at most 64 MiB remain (an entry is 15–60 kB; a fit of one
//!   file makes two to four).
//!
//! # Threat model
//!
//! The cache holds code that hysid runs in the user's process. The adversary is anyone else
//! on the machine — another user, or a program that can write where the cache is (a shared
//! `HYSID_CACHE_DIR`, a cache copied from elsewhere, a file left by an earlier tool) — who
//! puts a library in the cache, or in the place of one, for hysid to load. What is checked,
//! and why it is enough:
//!
//! * Nobody else can write into the cache: its directories are the user's and closed to
//!   writes by others, so others can neither create, replace, rename nor remove entries;
//!   files in it are the user's and not writable by others, so their contents cannot be
//!   changed either. A cache that is not so is not used at all.
//! * Nothing reaches `dlopen` without the MAC of its own bytes under the user's key, and
//!   only the user (and root) can read the key: a library planted or replaced by anyone who
//!   lacks the key — also a file that got there by the user's own mistake (a copied cache, a
//!   backup restored) — fails the check and is not loaded. The MAC is of the library file,
//!   not of the source: the source of a model is public (anyone can regenerate it from the
//!   model file), so a check against it proves nothing about the library.
//! * Check, then load, without a gap: the MAC is computed on bytes read once from the
//!   entry, and those bytes, not the entry, are what `dlopen` maps, from a file hysid wrote
//!   in a directory only this user can write. Nobody else can change or swap that file
//!   between the check and the load: the directories that name it are 0700 and the user's,
//!   which is what makes the check-then-load sound (and would make it sound for a load of
//!   the entry's own path too; the copy is a second line of defence, and costs a write of
//!   15–60 kB).
//!
//! Out of scope: the user's own processes and root (they can read the key and write the
//! cache; they can also run code as the user directly), the compiler (`$CC` is trusted as
//! make trusts it), and the directories above the base (the user's home).

use std::collections::BTreeSet;
use std::ffi::{c_void, CStr, CString};
use std::io::Write;
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use super::Provenance;
use crate::toolchain::Compiler;

mod cache;

use cache::{Cache, Lookup};

/// The compiler's flags: C99, optimised (`-O2`: `-O1` compiles in a quarter less time but
/// its code ran 14 % more instructions on the Bouc–Wen file), no contraction of a·b + c into a
/// fused multiply–add (each statement must round as the tape's operation does), linked
/// without the C library (`pow`, `sin`, … are resolved when loaded, from the process's own
/// libm: the same functions the tape calls).
const FLAGS: [&str; 7] = [
    "-std=c99",
    "-O2",
    "-pipe",
    "-fPIC",
    "-shared",
    "-nostdlib",
    "-ffp-contract=off",
];

/// A loaded shared object (closed when dropped).
pub(super) struct Library {
    handle: *mut c_void,
}

// SAFETY: a dlopen handle may be used and closed from any thread.
unsafe impl Send for Library {}
// SAFETY: `symbol` only reads through the handle (dlsym is thread-safe).
unsafe impl Sync for Library {}

impl Drop for Library {
    fn drop(&mut self) {
        // SAFETY: the handle came from dlopen and is closed once.
        unsafe {
            libc::dlclose(self.handle);
        }
    }
}

impl Library {
    fn open(path: &Path) -> Result<Self, String> {
        let c_path = CString::new(path.as_os_str().as_encoded_bytes())
            .map_err(|_| format!("{}: a path with a NUL byte", path.display()))?;
        // SAFETY: a valid C string; the flags are dlopen's.
        let handle = unsafe { libc::dlopen(c_path.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL) };
        if handle.is_null() {
            return Err(format!("cannot load {}: {}", path.display(), dl_error()));
        }
        Ok(Self { handle })
    }

    /// The library of `bytes` (checked by the caller), written to a new file of the private
    /// directory `dir` and loaded from there: the bytes that run are the bytes that were
    /// checked, whatever the cache's files hold meanwhile, and each load has a path of its
    /// own (the dynamic loader would return the library it already holds under a path).
    fn open_bytes(bytes: &[u8], dir: &Path) -> Result<Self, String> {
        let path = dir.join("model.so");
        std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o700)
            .open(&path)
            .and_then(|mut file| file.write_all(bytes))
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        Self::open(&path)
    }

    /// The address of the symbol `name`.
    pub(super) fn symbol(&self, name: &CStr) -> Result<*mut c_void, String> {
        // SAFETY: the handle is open; dlsym reads the C string.
        let address = unsafe { libc::dlsym(self.handle, name.as_ptr()) };
        if address.is_null() {
            return Err(format!("no symbol {name:?}: {}", dl_error()));
        }
        Ok(address)
    }
}

/// dlerror's message (or a placeholder when it has none).
fn dl_error() -> String {
    // SAFETY: dlerror returns NULL or a NUL-terminated string valid until the next call.
    let message = unsafe { libc::dlerror() };
    if message.is_null() {
        "unknown dlopen error".into()
    } else {
        // SAFETY: non-null, NUL-terminated (above).
        unsafe { CStr::from_ptr(message) }
            .to_string_lossy()
            .into_owned()
    }
}

/// [`FLAGS`], and `-mavx` where the processor has AVX (`numerics::cpu::has_avx`): wider
/// registers for the same element-wise operations — no fused multiply–add, so the same
/// numbers; the flags are part of the cache key, so a cache shared with a machine without
/// AVX keeps an object of each kind.
fn flags() -> Vec<&'static str> {
    let mut flags = FLAGS.to_vec();
    if crate::numerics::cpu::has_avx() {
        flags.push("-mavx");
    }
    flags
}

/// The name of the object of `source` compiled by `compiler` with `flags` (see the module
/// docs): BLAKE3 of each part preceded by its length, in hex.
fn entry_name(compiler: &Compiler, flags: &[&str], source: &str) -> String {
    let parts = std::iter::once(compiler.program.as_encoded_bytes())
        .chain(compiler.args.iter().map(|a| a.as_encoded_bytes()))
        .chain(flags.iter().map(|f| f.as_bytes()))
        .chain(std::iter::once(source.as_bytes()));
    let mut hasher = blake3::Hasher::new();
    for part in parts {
        hasher.update(&(part.len() as u64).to_le_bytes());
        hasher.update(part);
    }
    hasher.finalize().to_hex().to_string()
}

/// Prints `message` as one warning line on stderr, once per process (the library's one
/// print: a refused cache or a library that does not match its MAC must not pass silently,
/// and the report of the fit says only which code ran).
fn warn(message: String) {
    static SEEN: Mutex<BTreeSet<String>> = Mutex::new(BTreeSet::new());
    let mut seen = SEEN.lock().unwrap_or_else(|e| e.into_inner());
    if seen.insert(message.clone()) {
        eprintln!("hysid: warning: {message}");
    }
}

/// The warning of a refused cache, `why` being what is wrong with it.
fn refuse(why: &str) {
    warn(format!(
        "native-code cache not used: {why}; compiling in a private temporary directory \
         instead (make the cache yours and mode 0700, delete it, or set HYSID_CACHE_DIR)"
    ));
}

/// The loaded object of `source`: from the cache, else compiled now (see the module docs).
/// Errors are one line: no compiler, a compiler error, no loadable object.
pub(super) fn load(source: &str) -> Result<(Library, Provenance), String> {
    let compiler = Compiler::from_env();
    let flags = flags();
    let name = entry_name(&compiler, &flags, source);
    let cache = Cache::open().unwrap_or_else(|why| {
        refuse(&why);
        None
    });
    let cache = match cache.map(|c| (c.find(&name), c)) {
        Some((Ok(Lookup::Verified(bytes)), cache)) => {
            let dir = cache.private_dir()?;
            if let Ok(library) = Library::open_bytes(&bytes, dir.path()) {
                return Ok((library, Provenance::Cached));
            }
            Some(cache)
        }
        Some((Ok(Lookup::Missing), cache)) => Some(cache),
        Some((Ok(Lookup::Mismatch(path)), cache)) => {
            warn(format!(
                "{} does not match its MAC (replaced or damaged): not loaded; compiled \
                 again, which replaces it",
                path.display()
            ));
            Some(cache)
        }
        Some((Err(why), _)) => {
            refuse(&why);
            None
        }
        None => None,
    };
    let build = match &cache {
        Some(cache) => cache.build_dir(),
        None => tempfile::Builder::new()
            .prefix("hysid-native-")
            .tempdir()
            .map_err(|e| format!("cannot create a temporary directory: {e}")),
    }?;
    let started = Instant::now();
    let so = compile(&compiler, &flags, source, build.path())?;
    let seconds = started.elapsed().as_secs_f64();
    let library = Library::open(&so)?;
    let stored = match &cache {
        Some(cache) => match cache.store(&name, &so) {
            Ok(()) => true,
            Err(e) => {
                warn(format!(
                    "cannot store the compiled model in {}: {e}; it is compiled again next time",
                    cache.dir().display()
                ));
                false
            }
        },
        None => false,
    };
    // `build` is removed here; the loaded object stays mapped.
    Ok((
        library,
        if stored {
            Provenance::Compiled(seconds)
        } else {
            Provenance::CompiledUncached(seconds)
        },
    ))
}

/// Writes `source` to `dir` and compiles it there; the path of the shared object.
fn compile(
    compiler: &Compiler,
    flags: &[&str],
    source: &str,
    dir: &Path,
) -> Result<PathBuf, String> {
    let (c, so) = (dir.join("model.c"), dir.join("model.so"));
    std::fs::write(&c, source).map_err(|e| format!("cannot write {}: {e}", c.display()))?;
    let output = compiler
        .command()
        .args(flags)
        .arg("-o")
        .arg(&so)
        .arg(&c)
        .output()
        .map_err(|e| format!("no C compiler '{compiler}' ({e}); set CC to one"))?;
    if output.status.success() {
        Ok(so)
    } else {
        let stderr = String::from_utf8_lossy(&output.stderr);
        let first = stderr.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
        Err(format!("'{compiler}' failed ({}): {first}", output.status))
    }
}
