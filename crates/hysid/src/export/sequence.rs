//! The export's test sequence: the input record on which an export measures its
//! single-precision error bound and computes its reference vectors (`--test-vectors`), unless
//! the user gives a record (`--data FILE`).
//!
//! For an input range \[lo, hi\] (the model file's `input_range`, or `--test-range`) the
//! sequence visits the turning points
//!
//! lo + w·f, f ∈ (½, 1, 0, 1, 0.2, 0.8, 0.35, 0.65, 0.45, 0.55, 0, 0.6, 0.3, 0.9, 0.1, 0.7, ½),
//! w = hi − lo,
//!
//! joined by straight legs of at most w/[`LEG_STEPS`] per sample: from the middle, a major
//! loop, then a descending series of nested minor loops (each inside the last, as in a
//! demagnetisation), then loops that cross earlier ones, and back to the middle. Every
//! branch of a rate-independent memory (wiped-out reversals, nested ones, a return to the
//! major loop) is exercised, and both ends of the range are reached exactly. Then come
//! [`SET_POINTS`] set points drawn (a fixed linear congruential generator, so the sequence is
//! the same on every machine) uniformly in \[lo, hi\], as an arbitrary set-point sequence.
//!
//! A model of several inputs gets the same sequence on each, input j shifted by j/(n + 1)
//! of its length, so that the inputs do not move together.

/// The samples of a full traverse lo → hi.
pub const LEG_STEPS: usize = 64;

/// The number of arbitrary set points after the loops.
pub const SET_POINTS: usize = 64;

/// The turning points as fractions of the range.
const TURNS: [f64; 17] = [
    0.5, 1.0, 0.0, 1.0, 0.2, 0.8, 0.35, 0.65, 0.45, 0.55, 0.0, 0.6, 0.3, 0.9, 0.1, 0.7, 0.5,
];

/// The sequence for one input with range \[lo, hi\] (see the [module docs](self)).
pub fn sequence(lo: f64, hi: f64) -> Vec<f64> {
    let w = hi - lo;
    let at = |f: f64| {
        if f == 0.0 {
            lo
        } else if f == 1.0 {
            hi
        } else {
            lo + w * f
        }
    };
    let mut out = vec![at(TURNS[0])];
    for pair in TURNS.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let steps = (((b - a).abs() * LEG_STEPS as f64).ceil() as usize).max(1);
        for k in 1..=steps {
            let f = if k == steps {
                b
            } else {
                a + (b - a) * k as f64 / steps as f64
            };
            out.push(at(f));
        }
    }
    // Knuth's MMIX multiplier and increment; the top 53 bits give a fraction in [0, 1).
    let mut x: u64 = 0x2545_f491_4f6c_dd1d;
    for _ in 0..SET_POINTS {
        x = x
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let f = (x >> 11) as f64 / (1u64 << 53) as f64;
        out.push(lo + w * f);
    }
    out
}

/// The samples (one row of inputs each) for inputs with ranges `ranges` (see the
/// [module docs](self)).
pub fn inputs(ranges: &[[f64; 2]]) -> Vec<Vec<f64>> {
    let columns: Vec<Vec<f64>> = ranges.iter().map(|r| sequence(r[0], r[1])).collect();
    let n = columns.first().map_or(0, Vec::len);
    let shift = |j: usize| j * n / (ranges.len() + 1);
    (0..n)
        .map(|k| {
            columns
                .iter()
                .enumerate()
                .map(|(j, c)| c[(k + shift(j)) % n])
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sequence_reaches_both_ends_and_stays_inside() {
        let s = sequence(-3.0, 7.0);
        assert!(s.contains(&-3.0) && s.contains(&7.0));
        assert!(s.iter().all(|&v| (-3.0..=7.0).contains(&v)));
        let step = s
            .windows(2)
            .take(s.len() - SET_POINTS - 1)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f64::max);
        assert!(step <= 10.0 / LEG_STEPS as f64 + 1e-12, "{step}");
    }

    #[test]
    fn the_turning_points_are_the_documented_ones() {
        let s = sequence(0.0, 1.0);
        let loops = &s[..s.len() - SET_POINTS];
        let mut turns = vec![loops[0]];
        for w in loops.windows(3) {
            if (w[1] - w[0]) * (w[2] - w[1]) < 0.0 {
                turns.push(w[1]);
            }
        }
        turns.push(*loops.last().unwrap());
        let expected: Vec<f64> = TURNS.to_vec();
        assert_eq!(turns.len(), expected.len());
        for (a, b) in turns.iter().zip(&expected) {
            assert!((a - b).abs() < 1e-12, "{turns:?}");
        }
    }

    #[test]
    fn several_inputs_are_shifted_copies() {
        let rows = inputs(&[[0.0, 1.0], [0.0, 1.0]]);
        let n = rows.len();
        assert_eq!(rows[0][1], rows[n / 3][0]);
        assert_ne!(rows[0][0], rows[0][1]);
    }
}
