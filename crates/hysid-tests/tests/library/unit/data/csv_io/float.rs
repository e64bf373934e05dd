//! Tests of `hysid::data::csv_io::float`.

use hysid::data::csv_io::float::*;
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

/// Wherever the fast path answers, it answers exactly what the standard parser does.
#[test]
fn agrees_with_the_standard_parser() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let mut answered = 0;
    for _ in 0..200_000 {
        let v: f64 = rng.random::<f64>() * 10f64.powi(rng.random_range(-8..8));
        let v = if rng.random::<bool>() { -v } else { v };
        for text in [
            format!("{v}"),
            format!("{v:e}"),
            format!("{v:.6}"),
            format!("{v:.3E}"),
        ] {
            if let Some(fast) = parse_fast(text.as_bytes()) {
                answered += 1;
                assert_eq!(
                    fast.to_bits(),
                    text.parse::<f64>().unwrap().to_bits(),
                    "{text}"
                );
            }
        }
    }
    assert!(
        answered > 400_000,
        "the fast path answered only {answered} times"
    );
}

/// Eight bytes starting with 0 to 8 digits, then anything, against the byte-by-byte count and
/// value.
#[test]
fn digit_prefixes() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    let others = [b'/', b':', b'.', b'e', b' ', b',', 0x00, 0xB5, 0xFA, 0xFF];
    for _ in 0..200_000 {
        let n = rng.random_range(0..=8);
        let bytes: [u8; 8] = std::array::from_fn(|i| {
            if i < n || (i > n && rng.random::<bool>()) {
                b'0' + rng.random_range(0..10u8)
            } else {
                others[rng.random_range(0..others.len())]
            }
        });
        let value = bytes[..n]
            .iter()
            .fold(0, |v, &b| 10 * v + u64::from(b - b'0'));
        let word = u64::from_le_bytes(bytes);
        assert_eq!(digit_prefix(word), (value, n), "{bytes:?}");
    }
    assert_eq!(
        digit_prefix(u64::from_le_bytes(*b"99999999")),
        (99_999_999, 8)
    );
    assert_eq!(digit_prefix(u64::from_le_bytes(*b"00000000")), (0, 8));
}

#[test]
fn known_values_and_refusals() {
    let cases = [
        ("0.124644863552754", Some(0.124644863552754)),
        ("-0", Some(-0.0)),
        ("+12.5e-1", Some(1.25)),
        ("7.", Some(7.0)),
        (".5", Some(0.5)),
        ("1E22", Some(1e22)),
        // 2⁵³ + 1, a tie between 2⁵³ and 2⁵³ + 2: to even.
        ("9007199254740993", Some(9007199254740992.0)),
        ("-9999999999999999999", Some(-9999999999999999999.0)),
        ("4503599627370497.5", Some(4503599627370498.0)),
    ];
    for (text, expected) in cases {
        assert_eq!(
            parse_fast(text.as_bytes()).map(f64::to_bits),
            expected.map(f64::to_bits)
        );
    }
    for text in [
        "",
        "-",
        ".",
        "e5",
        "1e",
        "1e400",
        "nan",
        "inf",
        "1,5",
        "1.5x",
        "12345678901234567890",
        "1.2345678901234567e-23",
        "1e-23",
    ] {
        assert_eq!(parse_fast(text.as_bytes()), None, "{text}");
    }
}

/// Mantissas above 2⁵³ (up to 19 digits), where one floating-point operation would round
/// twice, against the standard parser: random ones with the decimal point anywhere and an
/// exponent, and exact ties between two doubles with their neighbours one digit off.
#[test]
fn wide_mantissas_agree_with_the_standard_parser() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(13);
    let mut texts = Vec::new();
    for _ in 0..200_000 {
        let digits = format!("{}", rng.random_range((1u64 << 53) + 1..=u64::MAX));
        let point = rng.random_range(0..=digits.len());
        let exponent = match rng.random_range(0..4) {
            0 => String::new(),
            _ => format!("e{}", rng.random_range(-30..30)),
        };
        texts.push(format!(
            "{}.{}{exponent}",
            &digits[..point],
            &digits[point..]
        ));
    }
    for binade in 50..64 {
        for _ in 0..2_000 {
            let v = f64::from_bits(rng.random_range(0..1u64 << 52) | ((1075 + binade - 52) << 52));
            let (tie, scale) = midpoint(v);
            for w in [tie - 1, tie, tie + 1] {
                let digits = format!("{w:0>width$}", width = scale + 1);
                let (int, frac) = digits.split_at(digits.len() - scale);
                texts.push(format!("{int}.{frac}"));
            }
        }
    }
    let mut answered = 0;
    for text in &texts {
        if let Some(fast) = parse_fast(text.as_bytes()) {
            answered += 1;
            let standard: f64 = text.parse().unwrap();
            assert_eq!(fast.to_bits(), standard.to_bits(), "{text}");
        }
    }
    assert!(
        answered > texts.len() / 2,
        "the fast path answered only {answered} of {}",
        texts.len()
    );
}

/// The point halfway between `v` (positive, normal) and the next double up, as an integer
/// and the number of decimal places it is to be read with.
fn midpoint(v: f64) -> (u128, usize) {
    let bits = v.to_bits();
    let mantissa = u128::from((bits & ((1 << 52) - 1)) | (1 << 52));
    // v = mantissa·2^e, the midpoint (2·mantissa + 1)·2^(e−1).
    let e = ((bits >> 52) & 0x7ff) as i32 - 1075 - 1;
    let odd = 2 * mantissa + 1;
    if e >= 0 {
        (odd << e, 0)
    } else {
        // n·2^−k = n·5^k / 10^k.
        let k = (-e) as u32;
        (odd * 5u128.pow(k), k as usize)
    }
}

/// Decimals w·10⁻²² just above a tie between two doubles, by less than 2⁻²² of the gap
/// between them: truncated to 64 bits (or to anything short of 75), their quotient lands
/// exactly on the tie, and only the sticky bit rounds them up, as the exact value demands.
///
/// They are found through q = ⌊w·2⁶⁴/5²²⌋ for w ≥ 2⁶³ (76 or 77 bits, t of them below the
/// 53 kept): q ends in a one and t − 1 zeros while the remainder r ≠ 0 exactly when
/// r ≡ 2^(t−1) (mod 2^t), as w·2⁶⁴ ≡ 0 there and 5²² is odd; and r = w·2⁶⁴ mod 5²², so
/// w ≡ r·(2⁶⁴)⁻¹ (mod 5²²).
#[test]
fn near_ties_take_the_sticky_bit() {
    let five_k = 5u128.pow(22);
    let inverse = inverse_mod((1u128 << 64) % five_k, five_k);
    let mut found = 0;
    for j in 0..1_000u128 {
        for t in [23, 24] {
            let r = (1 << (t - 1)) + j * (1 << t);
            let residue = r * inverse % five_k;
            let w = residue + ((1u128 << 63) - residue).div_ceil(five_k) * five_k;
            let quotient = (w << 64) / five_k;
            let kept_below = 128 - quotient.leading_zeros() - 53;
            if w >= 10u128.pow(19) || kept_below != t || (w << 64) % five_k != r {
                continue;
            }
            let text = format!("{w}e-22");
            let standard: f64 = text.parse().unwrap();
            let fast = parse_fast(text.as_bytes()).expect("19 digits, exponent -22");
            assert_eq!(fast.to_bits(), standard.to_bits(), "{text}");
            found += 1;
        }
    }
    assert!(found >= 100, "only {found} near ties");
}

/// The inverse of `a` modulo `m` (coprime), by the extended Euclidean algorithm.
fn inverse_mod(a: u128, m: u128) -> u128 {
    let (mut r0, mut r1) = (a as i128, m as i128);
    let (mut s0, mut s1) = (1i128, 0i128);
    while r1 != 0 {
        let q = r0 / r1;
        (r0, r1) = (r1, r0 - q * r1);
        (s0, s1) = (s1, s0 - q * s1);
    }
    assert_eq!(r0, 1);
    s0.rem_euclid(m as i128) as u128
}

/// Read in place, a number followed by a byte that cannot continue it (and anything after
/// that) is what `parse_fast` makes of it alone; a number that runs on is not taken for the
/// cell.
#[test]
fn prefixes_read_as_the_whole_cell() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(17);
    let cells = [
        "0.4528957186046694",
        "-0.05937734741544166",
        "123456",
        "9007199254740993",
        "1.5e-7",
        "+2E+22",
        "7.",
        ".5",
        "1e",
        "1e12345",
        "12345678901234567890",
        "1x",
        "--1",
        "",
    ];
    let enders = [",", "\n", "\r\n", " ", "\t", "\"", ";", "x"];
    for _ in 0..20_000 {
        let cell = if rng.random::<bool>() {
            cells[rng.random_range(0..cells.len())].to_owned()
        } else {
            let v: f64 = (rng.random::<f64>() - 0.5) * 10f64.powi(rng.random_range(-9..9));
            [format!("{v}"), format!("{v:e}"), format!("{v:.3}")][rng.random_range(0..3)].clone()
        };
        let ender = enders[rng.random_range(0..enders.len())];
        // Digits after the ender fill the eight-byte words read past the cell.
        let text = format!("{cell}{ender}{}", rng.random_range(0..u64::MAX));
        let whole = parse_fast(cell.as_bytes());
        let in_place = parse_prefix(text.as_bytes(), 0);
        if let Some(v) = whole {
            assert_eq!(
                in_place.map(|(v, end)| (v.to_bits(), end)),
                Some((v.to_bits(), cell.len())),
                "{text:?}"
            );
        }
        if let Some((v, end)) = in_place {
            if end == cell.len() {
                assert_eq!(whole.map(f64::to_bits), Some(v.to_bits()), "{text:?}");
            }
        }
    }
}
