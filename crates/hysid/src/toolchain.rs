//! The machine's C compiler: one type for the two places that run it, the native code of
//! equation-file models (`model/greybox/native/object.rs`) and the FMU's binary
//! (`export/fmu/compile.rs`).
//!
//! `$CC` is read as make reads it: the value split at whitespace is a program and the
//! arguments put before every build's own, so `CC="ccache cc"` runs `ccache cc …`,
//! `CC="env cc"` runs `env cc …` and `CC="gcc -m64"` runs `gcc -m64 …`; unset or blank, the
//! compiler is `cc`. Quotes are not interpreted (make leaves them to the shell): a program
//! whose path holds a space cannot be named through `CC`. A value that is not valid UTF-8
//! is kept whole, as one program name. The compiler's [`Display`](std::fmt::Display) form
//! (`ccache cc`) is what errors and reports name.

use std::ffi::{OsStr, OsString};
use std::process::Command;

/// A C compiler: a program and the arguments put before each build's own.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Compiler {
    /// The program (`cc`, `ccache`, `/usr/bin/clang`).
    pub program: OsString,
    /// Arguments put before the build's own (`cc` of `CC="ccache cc"`).
    pub args: Vec<OsString>,
}

impl Compiler {
    /// The compiler `$CC` names (see the module docs), else `cc`.
    pub fn from_env() -> Self {
        Self::parse(&std::env::var_os("CC").unwrap_or_default())
    }

    /// The compiler a value of `CC` names: split at whitespace into the program and its
    /// leading arguments; `cc` when blank; kept whole when not valid UTF-8.
    pub fn parse(cc: &OsStr) -> Self {
        let Some(text) = cc.to_str() else {
            return Self::new(cc);
        };
        let mut words = text.split_whitespace().map(OsString::from);
        match words.next() {
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

    /// A command that runs the compiler with its leading arguments; the caller adds the
    /// build's own.
    pub fn command(&self) -> Command {
        let mut command = Command::new(&self.program);
        command.args(&self.args);
        command
    }
}

impl std::fmt::Display for Compiler {
    /// The program and its arguments separated by spaces, as `CC` would hold them.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.program.to_string_lossy())?;
        for arg in &self.args {
            write!(f, " {}", arg.to_string_lossy())?;
        }
        Ok(())
    }
}
