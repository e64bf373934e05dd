//! Export: a fitted model leaves hysid as code that runs in a controller.
//!
//! The streaming form of every model (one sample in, one sample out, a fixed-size state; the
//! library's own form is `model::stream`) is written as
//!
//! * **C99** ([`Target::C`]): exactly two files, `NAME.h` and `NAME.c`, no heap, no globals,
//!   only `<math.h>` and `<stddef.h>`. The header defines the state struct completely and
//!   declares
//!   `void NAME_init(NAME_state *s);` and
//!   `void NAME_step(NAME_state *s, const double *u, double *y);`
//!   with the constants `NAME_N_INPUTS`, `NAME_N_OUTPUTS` and `NAME_SAMPLE_TIME`;
//! * **`no_std` Rust** ([`Target::Rust`]): a library crate `NAME/` depending on `libm` only,
//!   with `pub struct Model`, `Model::new()`, `Model::step(&mut self, u: &[f64; N_IN]) ->
//!   [f64; N_OUT]` and the constants `N_IN`, `N_OUT`, `SAMPLE_TIME`;
//! * an **FMI 2.0 Co-Simulation FMU** ([`Target::Fmu`]): `NAME.fmu` with the C sources inside
//!   and, unless asked not to, a binary built by the machine's C compiler.
//!
//! The step semantics are the same everywhere: `step` with input u_k returns y_k — the sample
//! `hysid simulate` reports at k — and then advances the state to k + 1. With
//! [`ExportOptions::inverse`] the same interface computes the compensator: the input is the
//! reference r_k, the output the command u_k that makes the model follow it (references
//! outside the reachable range are clipped, as `hysid compensate` does).
//!
//! The API: [`c_code`] (the two C files and their [`Interface`], which the FMU packager
//! uses), [`rust_crate`] and [`export`] (the files of any target, paths relative to the
//! output directory). The sample time is the model file's, else
//! [`ExportOptions::sample_time`], else 0 for a rate-independent `operator` file; any other
//! kind without one is an error asking for `--ts` ([`interface::SampleTime::of`]). A
//! compensator's command is limited and a non-finite sample skipped and counted (`error`,
//! `NAME_faults`) by the one rule of [`crate::model::limits`]. Every state carries a diverged
//! flag, set once a step cannot be computed where the library's
//! simulation would fail (an integration beyond its sub-step budget, a Preisach memory beyond
//! its capacity, a non-finite output); the outputs then hold their last values until the
//! state is initialised again. The compensator of an operator cascade with delay k takes the
//! reference k samples ahead ([`linear`]). Grey-box and equation-file models export forward
//! with their saved integrator and input interpolation, one interval late as the library's
//! stream ([`greybox`]), Newmark's Newton corrector with a fixed-size LU in nalgebra's order
//! of operations ([`greybox::newmark`]); a `band_limited` model is refused
//! ([`Error::UnsupportedKind`]). See `docs/export.md`.
//!
//! How it is built: a language-neutral program ([`code`], [`mod@program`]) that the renderers
//! ([`render`]) print as C or Rust; each model kind ([`kinds`]) and each operator family,
//! through the family registry ([`families`]), supplies its step once, transliterating the
//! library's computation in its order of operations; the emitters know models, the renderers
//! targets. Generated code is tested against the library sample by sample
//! (`crates/hysid-tests/tests/export`): bit-identical as C, within 2e-13 of the range as
//! Rust (the `libm` crate's `pow` and `sin` differ from the platform's by an ulp).

pub mod code;
pub mod coleman_hodgdon;
pub mod eval;
pub mod families;
pub mod fmu;
pub mod greybox;
pub mod interface;
pub mod kinds;
pub mod linear;
pub mod output;
pub mod precision;
pub mod program;
pub mod render;
pub mod sequence;
pub mod solve;
pub mod stmt;
pub mod vectors;
pub mod zip;

use crate::model::limits::Limits;
use crate::model::saved::{FittedModel, ModelFile};
use crate::{Error, Result};
use interface::SampleTime;
pub use precision::Precision;
use std::path::PathBuf;

/// Where an exported model goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    /// C99: `NAME.h` and `NAME.c`.
    C,
    /// A `no_std` Rust library crate `NAME/`.
    Rust,
    /// An FMI 2.0 Co-Simulation FMU `NAME.fmu`.
    Fmu,
}

impl Target {
    /// Every target, in the order the help lists them.
    pub const ALL: [Target; 3] = [Target::C, Target::Rust, Target::Fmu];

    /// The target's name on the command line (`c`, `rust`, `fmu`).
    pub fn name(self) -> &'static str {
        match self {
            Target::C => "c",
            Target::Rust => "rust",
            Target::Fmu => "fmu",
        }
    }

    /// The target named `name`; the error lists the targets.
    pub fn parse(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|t| t.name() == name)
            .ok_or_else(|| Error::InvalidOption {
                option: "target".into(),
                value: name.into(),
                reason: format!(
                    "unknown export target; choose one of {}",
                    Self::ALL.map(Target::name).join(", ")
                ),
            })
    }
}

/// How a model is exported.
#[derive(Clone, Debug, PartialEq)]
pub struct ExportOptions {
    /// Export the compensator (input: the reference; output: the command) instead of the
    /// model.
    pub inverse: bool,
    /// The sample time in seconds when the model file has none (`--ts`); the model file's
    /// `sample_time` wins when both are given and agree, and a disagreement is an error.
    pub sample_time: Option<f64>,
    /// Build the FMU's binary with the machine's C compiler (`--no-binary` turns it off).
    pub binary: bool,
    /// The measured initial output y(0) (`--y0`) of a Coleman–Hodgdon hysteresis saved with
    /// `initial_output: measured`, which its forward step starts from (as `hysid simulate`
    /// starts from the record's first measured output); ignored by every other model.
    pub initial_output: Option<f64>,
    /// The command limits of a compensator (`--limits LO:HI`,
    /// [`crate::model::limits`]); None takes the model file's `input_range`, and a file
    /// without one exports an unlimited compensator ([`export_limits`] says which).
    pub limits: Option<Limits>,
    /// The floating-point type of the code (`--precision`, [`precision`]): double (the
    /// default) or single; the FMU is double only (FMI 2.0's `Real` is a double).
    pub precision: Precision,
    /// The rows fed to the exported step on which a single-precision export measures its
    /// bound (`--data FILE`: the record's inputs for a model, its outputs as references for
    /// a compensator); None takes the test sequence ([`sequence`]) over the file's
    /// `input_range`.
    pub bound_record: Option<Vec<Vec<f64>>>,
    /// Add reference vectors and a program that checks them (`--test-vectors`,
    /// [`vectors`]): `NAME_test.c` for C, `NAME/tests/vectors.rs` for Rust; refused for the
    /// FMU.
    pub test_vectors: bool,
    /// The input range the test vectors' sequence covers (`--test-range LO:HI`); None takes
    /// the model file's `input_range` ([`vectors`]).
    pub test_range: Option<Limits>,
}

impl Default for ExportOptions {
    fn default() -> Self {
        Self {
            inverse: false,
            sample_time: None,
            binary: true,
            initial_output: None,
            limits: None,
            precision: Precision::Double,
            bound_record: None,
            test_vectors: false,
            test_range: None,
        }
    }
}

/// The limits an export of `file` applies to its compensator's command: `--limits`
/// ([`ExportOptions::limits`]), else the file's `input_range`, else none (the front end
/// warns); None for a forward export. In single precision they are moved inwards to the
/// nearest floats ([`precision::single_limits`]; unchanged when that fails, and
/// [`c_code`] then refuses the export).
pub fn export_limits(file: &ModelFile, options: &ExportOptions) -> Option<Limits> {
    if !options.inverse {
        return None;
    }
    let limits = options.limits.or_else(|| file.limits())?;
    Some(match options.precision {
        Precision::Double => limits,
        Precision::Single => precision::single_limits(limits).unwrap_or(limits),
    })
}

/// One file of an export, its path relative to the output directory.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GeneratedFile {
    /// The path under the output directory (`NAME.h`, `NAME/src/lib.rs`, `NAME.fmu`).
    pub path: PathBuf,
    /// The contents.
    pub contents: Vec<u8>,
}

/// The outside of an exported model: what a host (the FMU's model description, a test driver)
/// needs to know about `NAME_step`.
#[derive(Clone, Debug, PartialEq)]
pub struct Interface {
    /// The export name (a C identifier, [`check_name`]).
    pub name: String,
    /// The number of inputs of `NAME_step` (`NAME_N_INPUTS`).
    pub n_inputs: usize,
    /// The number of outputs of `NAME_step` (`NAME_N_OUTPUTS`).
    pub n_outputs: usize,
    /// The step's period in seconds (`NAME_SAMPLE_TIME`; 0 for a rate-independent operator
    /// without a stored sample time).
    pub sample_time: f64,
    /// The input names: the columns the model was fitted on ([`crate::model::saved::Columns`]),
    /// else `u` (`u1`, `u2`, … when several); the reference for a compensator.
    pub inputs: Vec<String>,
    /// The output names, likewise (`y`, or the command for a compensator).
    pub outputs: Vec<String>,
    /// The model's parameters as named in the model file, with their values.
    pub parameters: Vec<(String, f64)>,
    /// One line: the model's kind or family, forward or inverse, and the hysid version.
    pub description: String,
}

/// The C target's two files and the interface they implement.
#[derive(Clone, Debug, PartialEq)]
pub struct CCode {
    /// `NAME.h`: the state struct, the constants and the two functions.
    pub header: String,
    /// `NAME.c`: includes only `NAME.h`, `<math.h>` and `<stddef.h>`.
    pub source: String,
    /// What the code implements.
    pub interface: Interface,
}

/// Checks an export name: a C identifier (and so a Rust crate name), `[A-Za-z_][A-Za-z0-9_]*`,
/// at most 64 characters, not a C or Rust keyword.
pub fn check_name(name: &str) -> Result<()> {
    let valid = !name.is_empty()
        && name.len() <= 64
        && name
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !KEYWORDS.contains(&name);
    if valid {
        Ok(())
    } else {
        Err(Error::InvalidOption {
            option: "name".into(),
            value: name.into(),
            reason: "the name must be a C identifier: a letter or '_', then letters, digits or \
                     '_', at most 64 characters, not a C or Rust keyword"
                .into(),
        })
    }
}

/// C99 and Rust keywords an export name may not be.
const KEYWORDS: &[&str] = &[
    "auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else",
    "enum", "extern", "float", "for", "goto", "if", "inline", "int", "long", "register",
    "restrict", "return", "short", "signed", "sizeof", "static", "struct", "switch", "typedef",
    "union", "unsigned", "void", "volatile", "while", "as", "crate", "fn", "impl", "let", "loop",
    "match", "mod", "move", "mut", "pub", "ref", "self", "Self", "super", "trait", "type",
    "unsafe", "use", "where", "core", "std", "libm",
];

/// The program, interface and opening comment of the export `name` of `file`.
/// What [`prepare`] makes: the program, its interface, the opening comment and what a
/// single-precision export measured (None in double: bit-identical).
type Prepared = (
    program::Program,
    Interface,
    String,
    Option<precision::SingleBound>,
);

/// The bound `NAME_BOUND` of the code in the output's units: 0 in double (bit-identical).
fn absolute_bound(single: &Option<precision::SingleBound>) -> f64 {
    single
        .as_ref()
        .map_or(0.0, precision::SingleBound::absolute)
}

fn prepare(file: &ModelFile, name: &str, options: &ExportOptions) -> Result<Prepared> {
    check_name(name)?;
    let given = options;
    let options = &ExportOptions {
        limits: export_limits(file, given),
        ..given.clone()
    };
    let (model, sample_time) = model_at(file, options)?;
    let program = kinds::program(&model, options, sample_time.seconds())?;
    program.check()?;
    let sizes = if options.inverse {
        (program.n_outputs, program.n_inputs)
    } else {
        (program.n_inputs, program.n_outputs)
    };
    let interface = interface::interface(file, name, options, sample_time, sizes);
    let mut comment = interface::comment(file, &interface, given, sample_time);
    comment.push('\n');
    comment.push_str(&program.worst_case_comment());
    if let SampleTime::Resampled { fitted, given: ts } = sample_time {
        comment.push('\n');
        comment.push_str(&resampling_estimate(file, options, fitted, ts)?);
    }
    let mut bound = None;
    if options.precision.is_single() {
        if let Some(limits) = given
            .limits
            .or_else(|| file.limits())
            .filter(|_| given.inverse)
        {
            precision::single_limits(limits)?;
        }
        let measured = single_bound(file, &model, &program, options, sample_time.seconds())?;
        comment.push('\n');
        comment.push_str(&measured.comment());
        bound = Some(measured);
    }
    Ok((program, interface, comment, bound))
}

/// The model an export of `file` runs, and its sample time: the file's model, its
/// integration re-stepped for a `--ts` other than the file's ([`FittedModel::resampled`]),
/// which only a continuous-time grey-box or equation model accepts.
fn model_at(file: &ModelFile, options: &ExportOptions) -> Result<(FittedModel, SampleTime)> {
    let sample_time = SampleTime::of(file, options)?;
    let model = FittedModel::from_file(file)?;
    let SampleTime::Resampled { fitted, given } = sample_time else {
        return Ok((model, sample_time));
    };
    match model.resampled(fitted, given) {
        Some(model) => Ok((model, sample_time)),
        None => Err(Error::invalid_option(
            "ts",
            given,
            format!(
                "the model file's sample time is {fitted} s, and the {} model runs at the rate \
                 it was fitted at (only a continuous-time grey-box or equation model is \
                 re-stepped for another); leave the sample time out or give the same value",
                interface::model_name(file)
            ),
        )),
    }
}

/// The opening comment's line on a re-stepped integration ([`SampleTime::Resampled`]): the
/// largest difference, on the test sequence over the file's input range, between the
/// exported step and the same step with sub-steps half as long, an estimate of its
/// integration error (for RK4 the error of the coarser is about 16/15 of it).
fn resampling_estimate(
    file: &ModelFile,
    options: &ExportOptions,
    fitted: f64,
    ts: f64,
) -> Result<String> {
    let rule = "Integration: sub-steps no longer than those the model was fitted with";
    let rule = format!("{rule};\n");
    let Some(ranges) = file.input_range.as_deref() else {
        return Ok(format!(
            "{rule}its error is not estimated (the model file records no input range)."
        ));
    };
    let model = FittedModel::from_file(file)?;
    let forward = ExportOptions {
        inverse: false,
        precision: precision::Precision::Double,
        ..options.clone()
    };
    let outputs = |from: f64| -> Result<Vec<Vec<f64>>> {
        let stepped = model.resampled(from, ts).ok_or_else(|| {
            Error::Unsupported("the model is not re-stepped for another sample time".into())
        })?;
        let program = kinds::program(&stepped, &forward, ts)?;
        eval::run::<f64>(&program, &sequence::inputs(ranges))
    };
    let (steps, halved) = (outputs(fitted)?, outputs(fitted / 2.0)?);
    let difference = steps
        .iter()
        .flatten()
        .zip(halved.iter().flatten())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    Ok(format!(
        "{rule}on the test sequence over the input range the step differs from the same step\n\
         with sub-steps half as long by at most {difference:.3e} (the output's units), an\n\
         estimate of its integration error."
    ))
}

/// Measures the single-precision `program` of `model` (see [`precision`]) on the rows of
/// [`ExportOptions::bound_record`], else on the test sequence over the file's input range
/// (a file without one: [`ExportOptions::test_range`]), fed through the forward model (in
/// double) for a compensator.
fn single_bound(
    file: &ModelFile,
    model: &FittedModel,
    program: &program::Program,
    options: &ExportOptions,
    ts: f64,
) -> Result<precision::SingleBound> {
    if let Some(rows) = &options.bound_record {
        let width = rows.iter().map(Vec::len).find(|n| *n != program.n_inputs);
        if rows.is_empty() || width.is_some() {
            return Err(Error::InvalidOption {
                option: "data".into(),
                value: format!("{} rows", rows.len()),
                reason: format!(
                    "the record for the single-precision bound needs rows of {} values (the \
                     exported step's inputs)",
                    program.n_inputs
                ),
            });
        }
        return precision::measure(program, rows, "the record given at export (--data)");
    }
    let model_inputs = if options.inverse {
        program.n_outputs
    } else {
        program.n_inputs
    };
    let given = options
        .test_range
        .map(|r| vec![[r.lo(), r.hi()]; model_inputs]);
    let ranges = file.input_range.clone().or(given).ok_or_else(|| {
        Error::Unsupported(
            "single precision: the model file records no input_range (a file of an earlier \
             version), over which the bound is measured; give a record with --data FILE (or \
             the range with --test-range LO:HI), or refit the model"
                .into(),
        )
    })?;
    let ranges = ranges.as_slice();
    let mut rows = sequence::inputs(ranges);
    let mut record = format!(
        "the test sequence over the input range {}",
        ranges
            .iter()
            .map(|r| format!("[{:?}, {:?}]", r[0], r[1]))
            .collect::<Vec<_>>()
            .join(", ")
    );
    if options.inverse {
        let forward = ExportOptions {
            inverse: false,
            initial_output: options.initial_output.or(Some(0.0)),
            ..options.clone()
        };
        let plant = kinds::program(model, &forward, ts)?;
        rows = eval::run::<f64>(&plant, &rows)?;
        // Then the test vectors' references beyond reach, which the code must hold to the
        // bound as well (a compensator of a saturating model may not).
        let good: Vec<f64> = rows.iter().map(|r| r[0]).collect();
        rows.extend(vectors::beyond_reach(&good).into_iter().map(|r| vec![r]));
        record.push_str(
            " fed through the model (the references), then the test vectors' references \
             beyond reach",
        );
    }
    precision::measure(program, &rows, &record)
}

/// The language-neutral program an export of `file` prints (in `options.precision`: a
/// single-precision export is measured, and refused, as [`c_code`] does), for running it
/// with [`eval`].
pub fn program(file: &ModelFile, options: &ExportOptions) -> Result<program::Program> {
    Ok(prepare(file, "program", options)?.0)
}

/// The C99 code of the model (or, with [`ExportOptions::inverse`], of its compensator):
/// `NAME.h` and `NAME.c` (see the module docs and `docs/export.md`).
pub fn c_code(file: &ModelFile, name: &str, options: &ExportOptions) -> Result<CCode> {
    let (program, interface, comment, bound) = prepare(file, name, options)?;
    let (header, source) = render::c::render(
        &program,
        name,
        &comment,
        interface.sample_time,
        (options.precision, absolute_bound(&bound)),
    );
    Ok(CCode {
        header,
        source,
        interface,
    })
}

/// The `no_std` Rust crate of the model (or of its compensator): `NAME/Cargo.toml` and
/// `NAME/src/lib.rs`, depending on `libm` only.
pub fn rust_crate(
    file: &ModelFile,
    name: &str,
    options: &ExportOptions,
) -> Result<Vec<GeneratedFile>> {
    let (program, interface, comment, bound) = prepare(file, name, options)?;
    let lib = render::rust::lib_rs(
        &program,
        &comment,
        interface.sample_time,
        (options.precision, absolute_bound(&bound)),
    );
    let cargo = render::rust::cargo_toml(name, &interface.description);
    Ok(vec![
        GeneratedFile {
            path: PathBuf::from(name).join("Cargo.toml"),
            contents: cargo.into_bytes(),
        },
        GeneratedFile {
            path: PathBuf::from(name).join("src").join("lib.rs"),
            contents: lib.into_bytes(),
        },
    ])
}

/// The reference vectors of the export `name` of `file` ([`vectors`]): the test sequence (or
/// the forward model's outputs on it, then hostile samples, for a compensator) and the
/// library's outputs for it; in single precision the check's bound is the one the header
/// states (measured as [`c_code`] does).
pub fn test_vectors(
    file: &ModelFile,
    name: &str,
    options: &ExportOptions,
) -> Result<vectors::Vectors> {
    check_name(name)?;
    let bound = match options.precision {
        Precision::Double => vectors::DOUBLE_BOUND,
        Precision::Single => prepare(file, name, options)?
            .3
            .map_or(vectors::DOUBLE_BOUND, |single| single.bound()),
    };
    let (model, sample_time) = model_at(file, options)?;
    vectors::vectors(file, &model, options, sample_time.seconds(), bound)
}

/// The files of the export of `file` to `target` under the name `name`, paths relative to
/// the output directory; with [`ExportOptions::test_vectors`] also the test program
/// (`NAME_test.c`, `NAME/tests/vectors.rs`).
pub fn export(
    file: &ModelFile,
    target: Target,
    name: &str,
    options: &ExportOptions,
) -> Result<Vec<GeneratedFile>> {
    if options.test_vectors && target == Target::Fmu {
        return Err(Error::invalid_option(
            "test-vectors",
            "fmu",
            "test vectors come with the C and Rust targets; export the C or the Rust".into(),
        ));
    }
    let mut files = match target {
        Target::C => {
            let code = c_code(file, name, options)?;
            vec![
                GeneratedFile {
                    path: PathBuf::from(format!("{name}.h")),
                    contents: code.header.into_bytes(),
                },
                GeneratedFile {
                    path: PathBuf::from(format!("{name}.c")),
                    contents: code.source.into_bytes(),
                },
            ]
        }
        Target::Rust => rust_crate(file, name, options)?,
        Target::Fmu if options.precision.is_single() => {
            return Err(Error::invalid_option(
                "precision",
                "single",
                "an FMU computes in double (FMI 2.0's Real is a double); export --target c or \
                 rust for single precision"
                    .into(),
            ))
        }
        Target::Fmu => fmu::fmu_files(&c_code(file, name, options)?, options)?,
    };
    if options.test_vectors {
        let v = test_vectors(file, name, options)?;
        files.push(match target {
            Target::Rust => GeneratedFile {
                path: PathBuf::from(name).join("tests").join("vectors.rs"),
                contents: vectors::rust_test(name, &v).into_bytes(),
            },
            _ => GeneratedFile {
                path: PathBuf::from(format!("{name}_test.c")),
                contents: vectors::c_test(name, &v).into_bytes(),
            },
        });
    }
    Ok(files)
}
