//! Building the FMU's binary with the machine's C compiler.
//!
//! The compiler is `$CC` when set (split at whitespace: `CC="gcc -m64"` runs `gcc` with
//! `-m64` first), else `cc`. The sources are written to a fresh temporary directory, compiled
//! there with relative paths (so that no path of this machine ends up in the binary) by
//!
//! ```text
//! CC -std=c99 -O2 -shared -fPIC -o NAME.EXT NAME.c fmu_NAME.c -lm
//! ```
//!
//! and the directory is removed again, whatever happens. The binary goes to
//! `binaries/PLATFORM/NAME.EXT` of the FMU, with FMI 2.0's platform names: `linux64` (.so)
//! on x86-64 Linux, `linux32` on x86 Linux, `darwin64` (.dylib) on macOS; on other machines
//! the binary is refused (FMI 2.0 names no platform for them) and a source-only FMU is the
//! way out.

use crate::{Error, Result};
use std::ffi::OsString;
use std::path::PathBuf;
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The C compiler to build with, and its leading arguments.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Compiler {
    /// The program (`cc`, `gcc`, `/usr/bin/clang`).
    pub program: OsString,
    /// Arguments put before the build's own.
    pub args: Vec<OsString>,
}

impl Compiler {
    /// `$CC` when set and not blank (split at whitespace), else `cc`.
    pub fn from_env() -> Self {
        let cc = std::env::var_os("CC").unwrap_or_default();
        let text = cc.to_string_lossy();
        let mut words = text.split_whitespace().map(OsString::from);
        match words.next() {
            // A path that is not valid UTF-8 is kept whole.
            Some(_) if cc.to_str().is_none() => Self::new(cc),
            Some(program) => Self {
                program,
                args: words.collect(),
            },
            None => Self::new("cc"),
        }
    }

    /// The compiler `program`, without leading arguments.
    pub fn new(program: impl Into<OsString>) -> Self {
        Self {
            program: program.into(),
            args: Vec::new(),
        }
    }

    /// Compiles `files` (name and contents; the `.c` files among `sources` are compiled)
    /// into the shared library `name` of this machine's FMI platform, and returns its path in
    /// the FMU (`binaries/linux64/NAME.so`) and its bytes.
    pub fn shared_library(
        &self,
        name: &str,
        files: &[(String, Vec<u8>)],
        sources: &[String],
    ) -> Result<(String, Vec<u8>)> {
        let (platform, extension) = platform()?;
        let dir = TempDir::new()?;
        for (file, contents) in files {
            let path = dir.0.join(file);
            std::fs::write(&path, contents).map_err(|source| Error::Io { path, source })?;
        }
        let library = format!("{name}.{extension}");
        let program = self.program.to_string_lossy().into_owned();
        let output = Command::new(&self.program)
            .args(&self.args)
            .args(["-std=c99", "-O2", "-shared", "-fPIC", "-o", &library])
            .args(sources)
            .arg("-lm")
            .current_dir(&dir.0)
            .output()
            .map_err(|e| {
                Error::Unsupported(format!(
                    "no C compiler to build the FMU's binary: cannot run '{program}' ({e}); \
                     install one or set CC to one, or export without the binary (--no-binary; \
                     binary=False in Python) for a source-only FMU"
                ))
            })?;
        if !output.status.success() {
            let stderr = String::from_utf8_lossy(&output.stderr);
            let first = stderr
                .lines()
                .find(|l| l.contains("error"))
                .or_else(|| stderr.lines().next())
                .unwrap_or("no message");
            return Err(Error::Unsupported(format!(
                "the C compiler '{program}' failed to build the FMU's binary ({}): {}; export \
                 without the binary (--no-binary) for a source-only FMU",
                output.status,
                first.trim()
            )));
        }
        let path = dir.0.join(&library);
        let bytes = std::fs::read(&path).map_err(|source| Error::Io { path, source })?;
        Ok((format!("binaries/{platform}/{library}"), bytes))
    }
}

/// FMI 2.0's name of this machine's platform and its shared-library extension.
fn platform() -> Result<(&'static str, &'static str)> {
    if cfg!(all(target_os = "linux", target_arch = "x86_64")) {
        Ok(("linux64", "so"))
    } else if cfg!(all(target_os = "linux", target_arch = "x86")) {
        Ok(("linux32", "so"))
    } else if cfg!(target_os = "macos") {
        Ok(("darwin64", "dylib"))
    } else {
        Err(Error::Unsupported(format!(
            "FMI 2.0 names no binary platform for {} {}; export without the binary \
             (--no-binary) for a source-only FMU",
            std::env::consts::OS,
            std::env::consts::ARCH
        )))
    }
}

/// A fresh directory under the system's temporary directory, removed when dropped.
struct TempDir(PathBuf);

/// Distinguishes the temporary directories of one process.
static COUNTER: AtomicUsize = AtomicUsize::new(0);

impl TempDir {
    fn new() -> Result<Self> {
        let base = std::env::temp_dir();
        loop {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let path = base.join(format!("hysid-fmu-{}-{n}", std::process::id()));
            match std::fs::create_dir(&path) {
                Ok(()) => return Ok(Self(path)),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(source) => return Err(Error::Io { path, source }),
            }
        }
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        // Only untidy when it fails: the directory is the system's temporary one.
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
