//! The floating-point type of an export: `double` (the default: the library's numbers to the
//! bit) or `single` (`float` / `f32`, for cores with a single-precision FPU only, such as the
//! Cortex-M4F, where every `double` operation is a library call).
//!
//! A single-precision export prints the same program ([`super::program::Program`]) with
//! `float` state, tables, locals and API, `f`-suffixed literals (each the `f64` constant
//! rounded to nearest) and the `f`-suffixed math functions (`fabsf`, `sinf`, `powf`, …). It
//! is refused unless it meets [`SINGLE_BAR`]: before writing, the export runs the program in
//! both types ([`super::eval`]) on a test record — the documented test sequence
//! ([`super::sequence`]) over the model file's `input_range`, or the rows given with
//! `--data` ([`ExportOptions::bound_record`](super::ExportOptions::bound_record)); a
//! compensator is fed the forward model's double outputs on it, as references — and takes
//!
//! d = max_k |y_single(k) − y_double(k)| ÷ (max_k y_double − min_k y_double).
//!
//! The header states the measured d and the bound B = max(2·d, [`BOUND_FLOOR`]): the factor 2
//! covers the target's math library (its `sinf`, `expf`, `powf` may differ from the host's by
//! an ulp), and B is what the generated test program (`--test-vectors`) holds the code to. A
//! compensator's command limits are moved inwards to the nearest `float` values
//! ([`single_limits`]), so that every command lies within the limits as given.

use super::eval::{self, Deviation};
use super::program::Program;
use crate::model::limits::Limits;
use crate::{Error, Result};

/// The floating-point type of the exported code.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Precision {
    /// `double` / `f64`: bit-identical to the library.
    #[default]
    Double,
    /// `float` / `f32`: within the bound its header states.
    Single,
}

impl Precision {
    /// Both, in the order the help lists them.
    pub const ALL: [Precision; 2] = [Precision::Double, Precision::Single];

    /// The name on the command line (`double`, `single`).
    pub fn name(self) -> &'static str {
        match self {
            Precision::Double => "double",
            Precision::Single => "single",
        }
    }

    /// The precision named `name`; the error lists both.
    pub fn parse(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|p| p.name() == name)
            .ok_or_else(|| {
                Error::invalid_option(
                    "precision",
                    name,
                    "choose double (the library's numbers to the bit) or single (float)".into(),
                )
            })
    }

    /// The value of the type nearest `v` (in single, `v` rounded to `float`), as an `f64`.
    pub fn nearest(self, v: f64) -> f64 {
        match self {
            Precision::Double => v,
            Precision::Single => v as f32 as f64,
        }
    }

    /// True for [`Precision::Single`].
    pub fn is_single(self) -> bool {
        self == Precision::Single
    }
}

/// The largest deviation d a single-precision export may have: 10⁻⁴ of the output range
/// (a 13-bit converter's step; the bar).
pub const SINGLE_BAR: f64 = 1e-4;

/// The smallest bound a header states: 10⁻⁶ of the output range (eight `float` ulps of a
/// value at the top of its range).
pub const BOUND_FLOOR: f64 = 1e-6;

/// The limits `limits` moved inwards to the nearest `float` values (lo rounded up, hi
/// rounded down; unchanged when they are floats already), so that a `float` command
/// within them lies within the limits as given.
pub fn single_limits(limits: Limits) -> Result<Limits> {
    let inward = |v: f64, up: bool| -> f64 {
        let f = v as f32;
        let f = if (f as f64) < v && up {
            f.next_up()
        } else if (f as f64) > v && !up {
            f.next_down()
        } else {
            f
        };
        f as f64
    };
    let (lo, hi) = (inward(limits.lo(), true), inward(limits.hi(), false));
    if !(lo.is_finite() && hi.is_finite()) || lo > hi {
        return Err(Error::invalid_option(
            "limits",
            format!("{:?}:{:?}", limits.lo(), limits.hi()),
            "the command limits do not hold a float (single precision): export in double, or \
             give --limits within ±3.4e38"
                .into(),
        ));
    }
    Limits::new(lo, hi)
}

/// Refuses a single-precision program with a constant beyond the range of `float` (it would
/// round to infinity).
pub fn check_single(program: &Program) -> Result<()> {
    match program
        .literals()
        .into_iter()
        .find(|v| !(*v as f32).is_finite())
    {
        Some(v) => Err(Error::Unsupported(format!(
            "single precision: a constant of the model, {v:e}, is beyond the range of float \
             (±3.4e38); export in double (--precision double)"
        ))),
        None => Ok(()),
    }
}

/// What a single-precision export measured (see the [module docs](self)).
#[derive(Clone, Debug, PartialEq)]
pub struct SingleBound {
    /// The deviation measured.
    pub deviation: Deviation,
    /// The number of samples of the test record.
    pub samples: usize,
    /// The test record: the test sequence, or the rows given at export.
    pub record: String,
}

impl SingleBound {
    /// The bound the header states: max(2·d, [`BOUND_FLOOR`]).
    pub fn bound(&self) -> f64 {
        (2.0 * self.deviation.relative()).max(BOUND_FLOOR)
    }

    /// The bound in the output's units: [`SingleBound::bound`] × the output's range (the
    /// header's `NAME_BOUND`, Rust's `BOUND`).
    pub fn absolute(&self) -> f64 {
        self.bound() * self.deviation.range
    }

    /// The header's lines on the precision.
    pub fn comment(&self) -> String {
        format!(
            "Precision: single (float). Measured on {}\n\
             ({} samples): the outputs differ from the double code's by at most {:.3e} of\n\
             their range ({:.3e} in the output's units). Stated bound, with a factor 2 for the\n\
             target's math library: {:.3e} of the range, {:.3e} in the output's units\n\
             (NAME_BOUND / BOUND; docs/export.md, \"Single precision\").\n",
            self.record,
            self.samples,
            self.deviation.relative(),
            self.deviation.max_abs,
            self.bound(),
            self.absolute()
        )
    }
}

/// Measures the single-precision program `program` against itself in double on the rows
/// `rows` (described by `record`), and refuses it when the deviation exceeds [`SINGLE_BAR`].
pub fn measure(program: &Program, rows: &[Vec<f64>], record: &str) -> Result<SingleBound> {
    check_single(program)?;
    let deviation = eval::measure(program, rows)?;
    let found = SingleBound {
        deviation,
        samples: rows.len(),
        record: record.into(),
    };
    let d = deviation.relative();
    if d.is_nan() || d > SINGLE_BAR {
        return Err(Error::Unsupported(format!(
            "single precision: on {record} the float code differs from the double code by \
             {d:.2e} of the output's range, above the bound {SINGLE_BAR:e}; export in double \
             (--precision double), or rescale the model's units"
        )));
    }
    Ok(found)
}
