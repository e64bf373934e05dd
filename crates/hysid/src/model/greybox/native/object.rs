//! C source to a loaded shared object: compiled by the machine's C compiler (`$CC`, else
//! `cc`) into a cache directory keyed by the source's content, and loaded with `dlopen`.
//!
//! The cache: `$HYSID_CACHE_DIR`, else `$XDG_CACHE_HOME/hysid`, else `$HOME/.cache/hysid`,
//! subdirectory `native/`; entry `KEY.so` beside the source it was compiled from,
//! `KEY.c`, where KEY is a 64-bit FNV-1a hash of the compiler, its flags and the source.
//! An entry is used only when its `.c` file holds exactly the source asked for (so a hash
//! collision compiles again rather than loading the wrong code). A new entry is compiled
//! under a name of its own and renamed into place, `.so` first: a process that finds an
//! entry finds it whole, and two processes compiling the same source at once each rename a
//! complete file; the temporaries of a compilation that never finished (its process
//! exited first) are removed an hour later. Without a usable cache directory the object is
//! compiled into the system's temporary directory and removed once loaded.

use std::ffi::{c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use super::Provenance;

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

/// The C compiler to run: `$CC`, else `cc`.
fn compiler() -> String {
    std::env::var("CC")
        .ok()
        .filter(|c| !c.trim().is_empty())
        .unwrap_or_else(|| "cc".into())
}

/// The cache directory (see the module docs), created; None when there is none usable.
fn cache_dir() -> Option<PathBuf> {
    let var = |name: &str| {
        std::env::var_os(name)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    let base = var("HYSID_CACHE_DIR")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("hysid")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("hysid")))?;
    let dir = base.join("native");
    std::fs::create_dir_all(&dir).ok()?;
    Some(dir)
}

/// 64-bit FNV-1a over the parts, each followed by a zero byte.
fn fnv1a(parts: &[&str]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for &b in part.as_bytes().iter().chain(&[0u8]) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// A name no other process or thread uses at the same time.
fn unique() -> String {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    format!(
        "{}-{}-{nanos}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    )
}

/// The loaded object of `source`: from the cache, else compiled now (see the module docs).
/// Errors are one line: no compiler, a compiler error, no loadable object.
pub(super) fn load(source: &str) -> Result<(Library, Provenance), String> {
    let cc = compiler();
    let flags = flags();
    let key = format!("{:016x}", fnv1a(&[&cc, &flags.join(" "), source]));
    let cache = cache_dir();
    if let Some(dir) = &cache {
        let (so, c) = (dir.join(format!("{key}.so")), dir.join(format!("{key}.c")));
        if std::fs::read_to_string(&c).is_ok_and(|cached| cached == source) && so.is_file() {
            if let Ok(library) = Library::open(&so) {
                return Ok((library, Provenance::Cached));
            }
        }
    }
    if let Some(dir) = &cache {
        remove_stale_temporaries(dir);
    }
    let dir = cache.clone().unwrap_or_else(std::env::temp_dir);
    let stem = dir.join(format!("{key}-{}", unique()));
    let (tmp_c, tmp_so) = (stem.with_extension("c"), stem.with_extension("so"));
    let started = Instant::now();
    let result = compile(&cc, &flags, source, &tmp_c, &tmp_so);
    let seconds = started.elapsed().as_secs_f64();
    let loaded = result.and_then(|()| match &cache {
        Some(dir) => {
            let (so, c) = (dir.join(format!("{key}.so")), dir.join(format!("{key}.c")));
            std::fs::rename(&tmp_so, &so)
                .and_then(|()| std::fs::rename(&tmp_c, &c))
                .map_err(|e| {
                    format!("cannot store the compiled model in {}: {e}", dir.display())
                })?;
            Library::open(&so)
        }
        None => Library::open(&tmp_so),
    });
    // Left over only on failure, or always without a cache (the loaded object stays mapped).
    let _ = std::fs::remove_file(&tmp_c);
    let _ = std::fs::remove_file(&tmp_so);
    loaded.map(|library| (library, Provenance::Compiled(seconds)))
}

/// Removes the temporaries (`KEY-…`) of compilations that never finished — a process
/// that exited while its compiler ran — once they are an hour old.
fn remove_stale_temporaries(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let hour = std::time::Duration::from_secs(3600);
    for entry in entries.flatten() {
        let name = entry.file_name();
        let temporary = name.to_str().is_some_and(|n| {
            n.len() > 17
                && n.as_bytes()[16] == b'-'
                && n[..16].bytes().all(|b| b.is_ascii_hexdigit())
        });
        let old = entry
            .metadata()
            .and_then(|m| m.modified())
            .ok()
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age > hour);
        if temporary && old {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Writes `source` to `c` and compiles it into the shared object `so`.
fn compile(cc: &str, flags: &[&str], source: &str, c: &Path, so: &Path) -> Result<(), String> {
    std::fs::write(c, source).map_err(|e| format!("cannot write {}: {e}", c.display()))?;
    let output = Command::new(cc)
        .args(flags)
        .arg("-o")
        .arg(so)
        .arg(c)
        .output()
        .map_err(|e| format!("no C compiler '{cc}' ({e}); set CC to one"))?;
    if output.status.success() {
        Ok(())
    } else {
        let stderr = String::from_utf8_lossy(&output.stderr);
        let first = stderr.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
        Err(format!("'{cc}' failed ({}): {first}", output.status))
    }
}
