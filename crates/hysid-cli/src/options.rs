//! The admissible range of every numeric option, checked when the command line is parsed.
//!
//! Each option names its parser in `cli.rs` (`value_parser = options::count::<1, 1000>`), and
//! its doc comment states the same range, so `--help` shows it. A value out of range is a
//! usage error (exit 2, one line naming the option, the value and the range) before any file
//! is read. Sizes that depend on the data too (a delay shorter than the record, a filter
//! cut-off below Nyquist) are the library's to check; the memory and work a run needs are
//! checked by [`crate::budget`] once the data are known.

/// A count in `LO..=HI`: a whole number, no sign, no exponent.
pub fn count<const LO: usize, const HI: usize>(text: &str) -> Result<usize, String> {
    let n: usize = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a whole number in {LO}..={HI}"))?;
    if (LO..=HI).contains(&n) {
        Ok(n)
    } else {
        Err(format!("{n} is outside {LO}..={HI}"))
    }
}

/// `v` as written by a person: plain in [1e-4, 1e6), else in exponent form.
fn show(v: f64) -> String {
    if v == 0.0 || (1e-4..1e6).contains(&v.abs()) || !v.is_finite() {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A finite number.
fn number(text: &str) -> Result<f64, String> {
    let v: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{} is not finite; give a finite number", show(v)))
    }
}

/// A finite number in the closed interval [lo, hi].
fn within(text: &str, lo: f64, hi: f64) -> Result<f64, String> {
    let v = number(text)?;
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "{} is outside [{}, {}]",
            show(v),
            show(lo),
            show(hi)
        ))
    }
}

/// A finite number in (0, 1e12]: a physical constant, a sample time, a cut-off frequency.
pub fn positive(text: &str) -> Result<f64, String> {
    let v = number(text)?;
    if v > 0.0 && v <= 1e12 && v.is_normal() {
        Ok(v)
    } else {
        Err(format!("{} is outside (0, 1e12]", show(v)))
    }
}

/// Command limits `LO:HI`, two finite numbers with LO <= HI (`--limits`).
pub fn limits(text: &str) -> Result<hysid::model::limits::Limits, String> {
    hysid::model::limits::Limits::parse(text).map_err(|_| {
        format!("'{text}' is not LO:HI, two finite numbers with LO <= HI (e.g. -10:150)")
    })
}

/// A finite number in [-1e300, 1e300]: a measured value of a signal.
pub fn finite(text: &str) -> Result<f64, String> {
    within(text, -1e300, 1e300)
}

/// A finite number in [0, 1e6]: a noise level or a play width.
pub fn nonnegative(text: &str) -> Result<f64, String> {
    within(text, 0.0, 1e6)
}

/// A relative tolerance in [1e-15, 1): below 1e-15 it is beneath the working precision.
pub fn tolerance(text: &str) -> Result<f64, String> {
    let v = number(text)?;
    if (1e-15..1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{} is outside [1e-15, 1)", show(v)))
    }
}

/// A fraction in [0, 0.5).
pub fn margin(text: &str) -> Result<f64, String> {
    let v = number(text)?;
    if (0.0..0.5).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{} is outside [0, 0.5)", show(v)))
    }
}

/// A scale factor in [1e-6, 1e6].
pub fn factor(text: &str) -> Result<f64, String> {
    within(text, 1e-6, 1e6)
}

/// A drive gain: finite, |g| in [1e-9, 1e9] (beyond, g·u under- or overflows for
/// ordinary drive signals).
pub fn gain(text: &str) -> Result<f64, String> {
    let v = number(text)?;
    if (1e-9..=1e9).contains(&v.abs()) {
        Ok(v)
    } else {
        Err(format!("{} is outside ±[1e-9, 1e9]", show(v)))
    }
}

/// Seconds of wall-clock time in (0, 1e7].
pub fn seconds(text: &str) -> Result<f64, String> {
    let v = number(text)?;
    if v > 0.0 && v <= 1e7 {
        Ok(v)
    } else {
        Err(format!("{} is outside (0, 1e7] seconds", show(v)))
    }
}

/// The evaluator of equation models: `--evaluator` when given, else `$HYSID_EVALUATOR`
/// (`auto`, `native`, `cc` or `tape`), else auto. An unknown `$HYSID_EVALUATOR` (`jit`
/// among them: the in-process encoder was removed) is a usage error (exit 2).
pub fn evaluator(
    args: &crate::cli::EvaluatorArgs,
) -> Result<hysid::model::greybox::native::Evaluator, crate::exit::UsageError> {
    use crate::cli::EvaluatorArg;
    use hysid::model::greybox::native::Evaluator;
    match args.evaluator {
        Some(EvaluatorArg::Auto) => Ok(Evaluator::Auto),
        Some(EvaluatorArg::Cc) => Ok(Evaluator::Cc),
        Some(EvaluatorArg::Tape) => Ok(Evaluator::Tape),
        None => Evaluator::from_env().map_err(|e| {
            crate::exit::UsageError(format!("{e}; or give --evaluator auto, cc or tape"))
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_keep_their_range() {
        assert_eq!(count::<1, 10>("1"), Ok(1));
        assert_eq!(count::<1, 10>(" 10"), Ok(10));
        for bad in ["0", "11", "-1", "1e3", "nan", "", "18446744073709551616"] {
            assert!(count::<1, 10>(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn numbers_are_finite_and_in_range() {
        assert_eq!(positive("2.5"), Ok(2.5));
        for bad in ["0", "-1", "nan", "inf", "1e308", "1e-320", "abc"] {
            assert!(positive(bad).is_err(), "{bad}");
        }
        assert_eq!(nonnegative("0"), Ok(0.0));
        assert!(nonnegative("NaN").is_err());
        assert!(nonnegative("-1e-9").is_err());
        assert_eq!(tolerance("1e-4"), Ok(1e-4));
        assert!(tolerance("0").is_err() && tolerance("1").is_err());
        assert_eq!(margin("0.05"), Ok(0.05));
        assert!(margin("0.5").is_err());
        assert_eq!(gain("-35.15"), Ok(-35.15));
        for bad in ["nan", "inf", "1e308", "1e-320", "0"] {
            assert!(gain(bad).is_err(), "{bad}");
        }
        assert!(seconds("0").is_err() && seconds("1.5").is_ok());
        assert!(factor("0").is_err() && factor("1").is_ok());
    }
}
