//! `toolchain::Compiler`: `$CC` read as make reads it (a program and its arguments, split at
//! whitespace), and its printed form.

use hysid::toolchain::Compiler;
use std::ffi::{OsStr, OsString};

fn words(compiler: &Compiler) -> Vec<String> {
    std::iter::once(&compiler.program)
        .chain(&compiler.args)
        .map(|w| w.to_string_lossy().into_owned())
        .collect()
}

#[test]
fn cc_is_a_program_and_its_arguments() {
    assert_eq!(
        words(&Compiler::parse(OsStr::new("ccache cc"))),
        ["ccache", "cc"]
    );
    assert_eq!(
        words(&Compiler::parse(OsStr::new("  gcc\t-m64  -O1 "))),
        ["gcc", "-m64", "-O1"]
    );
    assert_eq!(
        words(&Compiler::parse(OsStr::new("/usr/bin/clang"))),
        ["/usr/bin/clang"]
    );
    assert_eq!(Compiler::parse(OsStr::new("")), Compiler::new("cc"));
    assert_eq!(Compiler::parse(OsStr::new(" \t")), Compiler::new("cc"));
    assert_eq!(Compiler::parse(OsStr::new("env cc")).to_string(), "env cc");
}

#[cfg(unix)]
#[test]
fn a_value_that_is_not_utf8_is_one_program() {
    use std::os::unix::ffi::OsStringExt;
    let cc = OsString::from_vec(b"/opt/c\xffc -m64".to_vec());
    let compiler = Compiler::parse(&cc);
    assert_eq!(compiler.program, cc);
    assert!(compiler.args.is_empty());
}

/// The command runs the program with the leading arguments first: `env cc --version`
/// prints what `cc --version` prints.
#[test]
fn the_command_puts_the_arguments_first() {
    let run = |compiler: &Compiler| {
        let out = compiler.command().arg("--version").output().unwrap();
        assert!(out.status.success(), "{compiler}");
        out.stdout
    };
    assert_eq!(
        run(&Compiler::parse(OsStr::new("env cc"))),
        run(&Compiler::new("cc"))
    );
}
