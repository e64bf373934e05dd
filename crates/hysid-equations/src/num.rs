//! The scalar semantics of every operation, shared by constant folding and the tape so
//! that both compute bit-identical values.

/// sign x with sign 0 = 0 (and sign NaN = 0).
#[inline]
pub fn sign0(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// xⁿ for an integer n by repeated multiplication (x² = x·x, x³ = x·x·x, …; x⁻ⁿ = 1/xⁿ).
#[inline]
pub fn powi(x: f64, n: i32) -> f64 {
    match n {
        0 => 1.0,
        1 => x,
        2 => x * x,
        3 => x * x * x,
        4 => {
            let s = x * x;
            s * s
        }
        _ => {
            let mut e = n.unsigned_abs();
            let (mut base, mut acc) = (x, 1.0);
            while e > 0 {
                if e & 1 == 1 {
                    acc *= base;
                }
                base *= base;
                e >>= 1;
            }
            if n < 0 {
                1.0 / acc
            } else {
                acc
            }
        }
    }
}

/// aᵇ (IEEE 754 pow), answering the exponents 1 and 0 without the library call: pow(a, 1)
/// = a and pow(a, 0) = 1 exactly for every a (also NaN and ±∞; IEEE 754-2008 §9.2.1), so
/// the value is the same to the bit. A model with a parameter exponent held at 1 (the
/// Bouc–Wen ν) evaluates |z|^ν and its derivative |z|^(ν−1) at every stage.
#[inline]
pub fn pow(a: f64, b: f64) -> f64 {
    if b == 1.0 {
        a
    } else if b == 0.0 {
        1.0
    } else {
        a.powf(b)
    }
}

/// min taking the first argument when a ≤ b (ties: the first).
#[inline]
pub fn min(a: f64, b: f64) -> f64 {
    if a <= b {
        a
    } else {
        b
    }
}

/// max taking the first argument when a ≥ b.
#[inline]
pub fn max(a: f64, b: f64) -> f64 {
    if a >= b {
        a
    } else {
        b
    }
}

/// A truth value as a number.
#[inline]
pub fn truth(b: bool) -> f64 {
    if b {
        1.0
    } else {
        0.0
    }
}

/// x where finite, 0 where infinite or NaN: the convention for derivative factors that do
/// not exist (see the crate docs).
#[inline]
pub fn finite_or_zero(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

/// The one-argument functions of the tape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Fn1 {
    /// sin
    Sin,
    /// cos
    Cos,
    /// tan
    Tan,
    /// exp
    Exp,
    /// ln
    Ln,
    /// sqrt
    Sqrt,
    /// |x|
    Abs,
    /// sign with sign 0 = 0
    Sign,
    /// tanh
    Tanh,
    /// atan
    Atan,
    /// x if finite, else 0 (derivative conventions)
    FiniteOr0,
}

/// f(x).
#[inline]
pub fn apply1(f: Fn1, x: f64) -> f64 {
    match f {
        Fn1::Sin => x.sin(),
        Fn1::Cos => x.cos(),
        Fn1::Tan => x.tan(),
        Fn1::Exp => x.exp(),
        Fn1::Ln => x.ln(),
        Fn1::Sqrt => x.sqrt(),
        Fn1::Abs => x.abs(),
        Fn1::Sign => sign0(x),
        Fn1::Tanh => x.tanh(),
        Fn1::Atan => x.atan(),
        Fn1::FiniteOr0 => finite_or_zero(x),
    }
}

/// The two-argument operations of the tape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Fn2 {
    /// a + b
    Add,
    /// a − b
    Sub,
    /// a · b
    Mul,
    /// a / b
    Div,
    /// a^b (powf)
    Pow,
    /// min(a, b)
    Min,
    /// max(a, b)
    Max,
    /// a < b
    Lt,
    /// a ≤ b
    Le,
    /// a = b
    Eq,
    /// a ≠ b
    Ne,
    /// a and b (non-zero is true)
    And,
    /// a or b
    Or,
}

/// a op b.
#[inline]
pub fn apply2(f: Fn2, a: f64, b: f64) -> f64 {
    match f {
        Fn2::Add => a + b,
        Fn2::Sub => a - b,
        Fn2::Mul => a * b,
        Fn2::Div => a / b,
        Fn2::Pow => pow(a, b),
        Fn2::Min => min(a, b),
        Fn2::Max => max(a, b),
        Fn2::Lt => truth(a < b),
        Fn2::Le => truth(a <= b),
        Fn2::Eq => truth(a == b),
        Fn2::Ne => truth(a != b),
        Fn2::And => truth(a != 0.0 && b != 0.0),
        Fn2::Or => truth(a != 0.0 || b != 0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_powers_match_powf() {
        for &x in &[-2.5, -1.0, 0.0, 0.3, 1.7, 3.0] {
            for n in -7..=9 {
                let want = f64::powi(x, n);
                let got = powi(x, n);
                assert!(
                    (got - want).abs() <= 1e-12 * want.abs().max(1.0) || got == want,
                    "{x}^{n}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn pow_shortcuts_equal_powf_to_the_bit() {
        let xs = [
            -2.5,
            -0.0,
            0.0,
            1e-300,
            0.3,
            1.7,
            7.1e12,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for x in xs {
            for y in [1.0, 0.0, -0.0, 0.5, 2.0] {
                assert_eq!(pow(x, y).to_bits(), x.powf(y).to_bits(), "{x}^{y}");
            }
        }
        assert!(pow(f64::NAN, 1.0).is_nan());
        assert_eq!(pow(f64::NAN, 0.0), 1.0);
    }

    #[test]
    fn ties_and_signs() {
        assert_eq!(sign0(0.0), 0.0);
        assert_eq!(sign0(-0.0), 0.0);
        assert_eq!(sign0(-3.0), -1.0);
        assert_eq!(min(1.0, 1.0), 1.0);
        assert_eq!(max(2.0, 1.0), 2.0);
        assert_eq!(finite_or_zero(f64::INFINITY), 0.0);
        assert_eq!(finite_or_zero(f64::NAN), 0.0);
        assert_eq!(finite_or_zero(-2.0), -2.0);
    }
}
