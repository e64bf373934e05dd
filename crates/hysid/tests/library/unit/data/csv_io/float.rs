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

/// Every group of eight digits, and groups with one non-digit anywhere, against the
/// digit-by-digit value.
#[test]
fn eight_digit_groups() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    for _ in 0..100_000 {
        let n: u64 = rng.random_range(0..100_000_000);
        let text = format!("{n:08}");
        assert_eq!(eight_digits(text.as_bytes()), Some(n), "{text}");
        let mut bad = text.into_bytes();
        let at = rng.random_range(0..8);
        bad[at] = *[b'/', b':', b'.', b'e', b' ', 0xB5]
            .get(rng.random_range(0..6))
            .unwrap();
        assert_eq!(eight_digits(&bad), None, "{bad:?}");
    }
    assert_eq!(eight_digits(b"99999999"), Some(99_999_999));
    assert_eq!(eight_digits(b"00000000"), Some(0));
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
        "9007199254740993",
        "12345678901234567890",
        "1e-23",
    ] {
        assert_eq!(parse_fast(text.as_bytes()), None, "{text}");
    }
}
