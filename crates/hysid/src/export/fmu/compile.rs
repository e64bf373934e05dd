//! Building the FMU's binary with the machine's C compiler.
//!
//! The compiler is [`Compiler::from_env`] (`$CC` split at whitespace as make splits it:
//! `CC="ccache cc"` runs `ccache` with `cc` first; else `cc`; `crate::toolchain`). The
//! sources are written to a private temporary directory (`tempfile`, mode 0700), compiled
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

use crate::toolchain::Compiler;
use crate::{Error, Result};

/// Compiles `files` (name and contents; the `.c` files among `sources` are compiled) with
/// `compiler` into the shared library `name` of this machine's FMI platform, and returns
/// its path in the FMU (`binaries/linux64/NAME.so`) and its bytes.
pub(super) fn shared_library(
    compiler: &Compiler,
    name: &str,
    files: &[(String, Vec<u8>)],
    sources: &[String],
) -> Result<(String, Vec<u8>)> {
    let (platform, extension) = platform()?;
    let dir = tempfile::Builder::new()
        .prefix("hysid-fmu-")
        .tempdir()
        .map_err(|source| Error::Io {
            path: std::env::temp_dir(),
            source,
        })?;
    for (file, contents) in files {
        let path = dir.path().join(file);
        std::fs::write(&path, contents).map_err(|source| Error::Io { path, source })?;
    }
    let library = format!("{name}.{extension}");
    let output = compiler
        .command()
        .args(["-std=c99", "-O2", "-shared", "-fPIC", "-o", &library])
        .args(sources)
        .arg("-lm")
        .current_dir(dir.path())
        .output()
        .map_err(|e| {
            Error::Unsupported(format!(
                "no C compiler to build the FMU's binary: cannot run '{compiler}' ({e}); \
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
            "the C compiler '{compiler}' failed to build the FMU's binary ({}): {}; export \
             without the binary (--no-binary) for a source-only FMU",
            output.status,
            first.trim()
        )));
    }
    let path = dir.path().join(&library);
    let bytes = std::fs::read(&path).map_err(|source| Error::Io { path, source })?;
    Ok((format!("binaries/{platform}/{library}"), bytes))
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
