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

/// 5⁰ … 5²²: w/10^k = (w/5^k)·2^−k.
const POWERS_OF_FIVE: [u64; 23] = {
    let mut powers = [1; 23];
    let mut k = 1;
    while k < 23 {
        powers[k] = 5 * powers[k - 1];
        k += 1;
    }
    powers
};

/// Largest integer mantissa every value up to which is exact in binary64.
const MAX_EXACT: u64 = 1 << 53;

/// The value of `[+-]digits[.digits][(e|E)[+-]digits]` when it has at most 19 digits and
/// an exponent this module converts exactly, else None (the caller then parses the text in
/// full).
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn parse_fast(text: &[u8]) -> Option<f64> {
    match parse_prefix(text, 0)? {
        (value, end) if end == text.len() => Some(value),
        _ => None,
    }
}

/// The number that starts at `text[at]`, as [`parse_fast`] reads it, and the offset of the
/// first byte after it: for reading a cell in place, without finding its end first.
///
/// The number ends at the first byte that cannot continue it; bytes after that one never
/// change the answer (digits are read eight at a time, but a word's digits count only up to
/// its first non-digit). So when the byte at the returned offset ends the cell, the value is
/// exactly [`parse_fast`] of the cell, and [`parse_fast`] is this function on a cell that
/// must be read to its end.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
#[inline(always)]
pub fn parse_prefix(text: &[u8], at: usize) -> Option<(f64, usize)> {
    let (negative, at) = match text.get(at)? {
        b'-' => (true, at + 1),
        b'+' => (false, at + 1),
        _ => (false, at),
    };
    // Most numbers have one digit before the point: no need for a word of eight.
    let (mantissa, int_digits, at) = match (text.get(at), text.get(at + 1)) {
        (Some(&digit @ b'0'..=b'9'), Some(b'.')) => (u64::from(digit - b'0'), 1, at + 1),
        _ => digits(text, at, 0, 0)?,
    };
    let (mantissa, all_digits, at) = match text.get(at) {
        Some(b'.') => digits(text, at + 1, mantissa, int_digits)?,
        _ => (mantissa, int_digits, at),
    };
    if all_digits == 0 {
        return None;
    }
    let frac_digits = all_digits - int_digits;
    let (exponent, at) = match text.get(at) {
        Some(b'e' | b'E') => exponent(text, at + 1)?,
        _ => (0, at),
    };
    let e10 = exponent - frac_digits as i64;
    let magnitude = if mantissa <= MAX_EXACT {
        clinger(mantissa, e10)?
    } else {
        wide(mantissa, e10)?
    };
    Some((if negative { -magnitude } else { magnitude }, at))
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
/// rounded once, by the conversion of a 64-bit integer to `f64` (to nearest, ties to even).
///
/// For e10 ≥ 0 that integer is the product w·10^e10 (when it fits in 128 bits), cut to its
/// leading 64 bits. For e10 = −k < 0, w/10^k = (w/5^k)·2^−k, and the integer is the quotient
/// q = ⌊w·2^s / 5^k⌋ with s chosen so that 2⁶² < q < 2⁶⁴ (one hardware division). Either way
/// at least 10 bits lie below the 53 kept, and whatever was cut off (low bits, a remainder)
/// is OR-ed into the last bit (sticky): that bit is below the half-unit the rounding compares
/// with, so the integer rounds as the exact value does, a nonzero remainder tipping an exact
/// tie up just as the true value does. Scaling by a power of two is exact: the results lie
/// far inside the normal range.
fn wide(w: u64, e10: i64) -> Option<f64> {
    match e10 {
        0..=22 => {
            let product = u128::from(w).checked_mul(10u128.pow(e10 as u32))?;
            let cut = 64u32.saturating_sub(product.leading_zeros());
            let lost = product & ((1 << cut) - 1) != 0;
            let top = (product >> cut) as u64 | u64::from(lost);
            Some(top as f64 * power_of_two(cut as i32))
        }
        -22..=-1 => {
            let k = (-e10) as u32;
            let five_k = POWERS_OF_FIVE[k as usize];
            // With w in [2^(bw−1), 2^bw) and 5^k in [2^(bd−1), 2^bd), q lies in (2^62, 2^64).
            let (bw, bd) = (64 - w.leading_zeros(), 64 - five_k.leading_zeros());
            let shift = 63 + bd - bw;
            let scaled = u128::from(w) << shift;
            let quotient = (scaled / u128::from(five_k)) as u64;
            let remainder = scaled - u128::from(quotient) * u128::from(five_k);
            let sticky = u64::from(remainder != 0);
            Some((quotient | sticky) as f64 * power_of_two(-((shift + k) as i32)))
        }
        _ => None,
    }
}

/// 2^e as a double, for a normal 2^e (|e| < 1023).
fn power_of_two(e: i32) -> f64 {
    f64::from_bits(((1023 + e) as u64) << 52)
}

/// Reads the decimal digits from `text[at]` on onto `mantissa`, after `count` digits read
/// before: the new mantissa, the new count and the offset after the digits. None past
/// [`MAX_DIGITS`] in all, so the mantissa cannot overflow. The cells of long files are mostly
/// 16–17-digit numbers, and this loop is most of their cost: it takes eight bytes at a time
/// while the text has eight more, whatever their mix of digits and other bytes.
#[inline]
fn digits(
    text: &[u8],
    mut at: usize,
    mut mantissa: u64,
    mut count: usize,
) -> Option<(u64, usize, usize)> {
    while let Some(bytes) = text.get(at..at + 8) {
        let (value, n) = digit_prefix(u64::from_le_bytes(bytes.try_into().expect("eight")));
        if count + n > MAX_DIGITS {
            return None;
        }
        mantissa = mantissa * DIGIT_SCALES[n] + value;
        count += n;
        at += n;
        // A run often ends right after a whole word (16-digit fractions): one byte says so.
        if n < 8 || !text.get(at).is_some_and(u8::is_ascii_digit) {
            return Some((mantissa, count, at));
        }
    }
    while let Some(&b) = text.get(at) {
        let digit = b.wrapping_sub(b'0');
        if digit > 9 {
            break;
        }
        if count == MAX_DIGITS {
            return None;
        }
        mantissa = mantissa * 10 + u64::from(digit);
        count += 1;
        at += 1;
    }
    Some((mantissa, count, at))
}

/// Digits a mantissa may have (10¹⁹ − 1 < 2⁶⁴).
const MAX_DIGITS: usize = 19;

/// 10ⁿ for the n ≤ 8 digits [`digit_prefix`] takes at a time.
const DIGIT_SCALES: [u64; 9] = [
    1,
    10,
    100,
    1_000,
    10_000,
    100_000,
    1_000_000,
    10_000_000,
    100_000_000,
];

/// The number of ASCII decimal digits that eight bytes (a little-endian word: the first byte
/// lowest) start with, 0 to 8, and their value (most significant first). SWAR: one word
/// operation per step for all eight bytes instead of one step per byte.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub fn digit_prefix(word: u64) -> (u64, usize) {
    const HIGH_NIBBLES: u64 = 0xF0F0_F0F0_F0F0_F0F0;
    const ZEROS: u64 = 0x3030_3030_3030_3030;
    const LOW_SEVEN: u64 = 0x7F7F_7F7F_7F7F_7F7F;
    // A digit is 0x30–0x39: high nibble 3, and adding 6 keeps it at 3. Other bytes are
    // nonzero in `off`. (Adding 6 to a byte ≥ 0xFA carries into the next byte, but that byte
    // already lies past a non-digit, and only the first non-digit counts.)
    let off = ((word & HIGH_NIBBLES) ^ ZEROS)
        | ((word.wrapping_add(0x0606_0606_0606_0606) & HIGH_NIBBLES) ^ ZEROS);
    // The high bit of every nonzero byte of `off`: (b & 0x7F) + 0x7F ≤ 0xFE never carries.
    let non_digits = (((off & LOW_SEVEN) + LOW_SEVEN) | off) & !LOW_SEVEN;
    let n = (non_digits.trailing_zeros() / 8) as usize;
    if n == 0 {
        return (0, 0);
    }
    // Digit values, the n digits moved to the top bytes with zeros below: leading zeros of
    // an eight-digit number. (Bytes below 0x30 borrow from the bytes above them, which lie
    // past the digits and are shifted out.)
    let d = word.wrapping_sub(ZEROS) << (8 * (8 - n));
    // Byte 2i: 10·digit(2i) + digit(2i+1).
    let pairs = (d * 10 + (d >> 8)) & 0x00FF_00FF_00FF_00FF;
    // 16-bit lane 2i: 100·pair(2i) + pair(2i+1).
    let quads = (pairs * 100 + (pairs >> 16)) & 0x0000_FFFF_0000_FFFF;
    // 10⁴·(first four) + (last four).
    ((quads & 0xFFFF) * 10_000 + (quads >> 32), n)
}

/// The signed decimal exponent of one to four digits at `text[at]`, and the offset after
/// it; None for no digit or more than four (longer ones go to the full parser).
fn exponent(text: &[u8], at: usize) -> Option<(i64, usize)> {
    let (negative, start) = match text.get(at) {
        Some(b'-') => (true, at + 1),
        Some(b'+') => (false, at + 1),
        _ => (false, at),
    };
    let count = text
        .get(start..)?
        .iter()
        .take(5)
        .take_while(|b| b.is_ascii_digit())
        .count();
    if count == 0 || count > 4 {
        return None;
    }
    let end = start + count;
    let value = text[start..end]
        .iter()
        .fold(0i64, |v, &b| 10 * v + i64::from(b - b'0'));
    Some((if negative { -value } else { value }, end))
}
