//! A fast, exact path for the decimal numbers CSV files mostly hold.
//!
//! A decimal w·10^e with an integer w ≤ 2⁵³ and |e| ≤ 22 is the correctly rounded quotient
//! (or product) of two doubles that are both exact, and IEEE 754 division and multiplication
//! round correctly: one operation gives the same double as a full decimal-to-binary
//! conversion (Clinger, "How to read floating point numbers accurately", PLDI 1990). A wider
//! w (the 17-digit numbers of full-precision output, up to 19 digits) is converted with
//! exact integer arithmetic and one rounding instead (see `wide`). Every other text (more
//! digits, large exponents, `nan`, `inf`, a stray character) is left to the standard
//! library's parser by returning `None`.
//!
//! A double has one correctly rounded value, so every path gives the standard parser's bits.

/// 10⁰ … 10²², all exact in binary64.
const POWERS_OF_TEN: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Largest integer mantissa every value up to which is exact in binary64.
const MAX_EXACT: u64 = 1 << 53;

/// The value of `[+-]digits[.digits][(e|E)[+-]digits]` when Clinger's fast path applies
/// exactly, else None (the caller then parses the text in full).
#[doc(hidden)] // reached by the white-box tests in tests/library/unit
pub fn parse_fast(text: &[u8]) -> Option<f64> {
    let (negative, rest) = match text.first()? {
        b'-' => (true, &text[1..]),
        b'+' => (false, &text[1..]),
        _ => (false, text),
    };
    let (mantissa, int_digits, rest) = digits(rest, 0)?;
    let (mantissa, frac_digits, rest) = match rest.split_first() {
        Some((b'.', frac)) => digits(frac, mantissa)?,
        _ => (mantissa, 0, rest),
    };
    if int_digits + frac_digits == 0 {
        return None;
    }
    let exponent = match rest.split_first() {
        None => 0,
        Some((b'e' | b'E', exp)) => exponent(exp)?,
        Some(_) => return None,
    };
    let e10 = exponent - frac_digits as i64;
    let magnitude = if mantissa <= MAX_EXACT {
        clinger(mantissa, e10)?
    } else {
        wide(mantissa, e10)?
    };
    Some(if negative { -magnitude } else { magnitude })
}

/// w·10^e10 for w ≤ 2⁵³: one correctly rounded operation on exact doubles.
fn clinger(w: u64, e10: i64) -> Option<f64> {
    let w = w as f64;
    match e10 {
        0 => Some(w),
        1..=22 => Some(w * POWERS_OF_TEN[e10 as usize]),
        -22..=-1 => Some(w / POWERS_OF_TEN[(-e10) as usize]),
        _ => None,
    }
}

/// w·10^e10 correctly rounded for w > 2⁵³, where w itself is not exact as a double and one
/// floating-point operation would round twice: the exact value is formed in integers and
/// rounded once, by the conversion of a `u128` to `f64` (to nearest, ties to even).
///
/// For e10 ≥ 0 that is the product w·10^e10, when it fits in 128 bits. For e10 = −k < 0,
/// w/10^k = (w/5^k)·2^−k: the quotient q = ⌊w·2^s / 5^k⌋ is taken with w·2^s ∈ [2¹²⁷, 2¹²⁸),
/// so q ≥ 2¹²⁷/5²² > 2⁷⁵ has at least 22 bits below the 53 kept; a remainder is OR-ed into
/// its last bit (sticky), which then rounds as the exact quotient would (that bit is below
/// the half-unit the rounding compares with, and a nonzero remainder tips an exact tie up
/// just as the true value does). Scaling by 2^−(s+k) is exact: the results lie far inside
/// the normal range.
fn wide(w: u64, e10: i64) -> Option<f64> {
    match e10 {
        0..=22 => {
            let product = u128::from(w).checked_mul(10u128.pow(e10 as u32))?;
            Some(product as f64)
        }
        -22..=-1 => {
            let k = (-e10) as u32;
            let shift = w.leading_zeros() + 64;
            let scaled = u128::from(w) << shift;
            let five_k = u128::from(5u64.pow(k));
            let quotient = scaled / five_k;
            let sticky = u128::from(scaled - quotient * five_k != 0);
            Some((quotient | sticky) as f64 * power_of_two(-((shift + k) as i32)))
        }
        _ => None,
    }
}

/// 2^e as a double, for a normal 2^e (|e| < 1023).
fn power_of_two(e: i32) -> f64 {
    f64::from_bits(((1023 + e) as u64) << 52)
}

/// Reads decimal digits onto `mantissa`: the new mantissa, the digit count and the rest.
/// None past 19 digits (the mantissa could overflow). One pass over the digits: the cells
/// of long files are mostly 16–17-digit numbers, and this loop is most of their cost.
fn digits(text: &[u8], mut mantissa: u64) -> Option<(u64, usize, &[u8])> {
    let mut count = 0;
    // Whole groups of eight digits first, while they fit in the 19 allowed: the same
    // integer as eight single steps (the prefix values only grow, so the checked steps
    // overflow exactly when the single ones would).
    while count + 8 <= MAX_DIGITS {
        let Some(group) = text.get(count..count + 8).and_then(eight_digits) else {
            break;
        };
        mantissa = mantissa.checked_mul(100_000_000)?.checked_add(group)?;
        count += 8;
    }
    while let Some(&b) = text.get(count) {
        let digit = b.wrapping_sub(b'0');
        if digit > 9 {
            break;
        }
        if count == MAX_DIGITS {
            return None;
        }
        mantissa = mantissa.checked_mul(10)?.checked_add(u64::from(digit))?;
        count += 1;
    }
    Some((mantissa, count, &text[count..]))
}

/// Digits a mantissa may have (10¹⁹ − 1 < 2⁶⁴).
const MAX_DIGITS: usize = 19;

/// The value of eight ASCII decimal digits (most significant first), or None when any byte is
/// not a digit. SWAR: the eight bytes as one little-endian word, so the first digit is the
/// lowest byte; adjacent digits are merged into 2-, then 4-, then 8-digit values, each lane
/// holding the higher part times the power of ten plus the lower part.
#[doc(hidden)] // reached by the white-box tests in tests/library/unit
pub fn eight_digits(bytes: &[u8]) -> Option<u64> {
    const LOW_NIBBLES: u64 = 0x0F0F_0F0F_0F0F_0F0F;
    const ZEROS: u64 = 0x3030_3030_3030_3030;
    let word = u64::from_le_bytes(bytes.try_into().ok()?);
    // A digit is 0x30–0x39: high nibble 3, and adding 6 keeps the high nibble at 3.
    let high = !LOW_NIBBLES;
    if word & high != ZEROS || word.wrapping_add(0x0606_0606_0606_0606) & high != ZEROS {
        return None;
    }
    let d = word - ZEROS;
    // Byte 2i: 10·digit(2i) + digit(2i+1).
    let pairs = (d * 10 + (d >> 8)) & 0x00FF_00FF_00FF_00FF;
    // 16-bit lane 2i: 100·pair(2i) + pair(2i+1).
    let quads = (pairs * 100 + (pairs >> 16)) & 0x0000_FFFF_0000_FFFF;
    // 10⁴·(first four) + (last four).
    Some(((quads & 0xFFFF) * 10_000) + (quads >> 32))
}

/// A short signed decimal exponent that is the whole of `text`.
fn exponent(text: &[u8]) -> Option<i64> {
    let (negative, rest) = match text.first()? {
        b'-' => (true, &text[1..]),
        b'+' => (false, &text[1..]),
        _ => (false, text),
    };
    if rest.is_empty() || rest.len() > 4 || !rest.iter().all(u8::is_ascii_digit) {
        return None;
    }
    let value = rest.iter().fold(0i64, |v, &b| 10 * v + i64::from(b - b'0'));
    Some(if negative { -value } else { value })
}
