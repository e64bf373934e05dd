//! Tests of `hysid::data::csv_io::chunks`: the chunked path gives the sequential path's bits
//! on plain files, and falls back to it (same values, same error) on everything else.

use std::fmt::Write as _;
use std::path::Path;

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

use hysid::data::csv_io::chunks::{find_special, MAX_LINE, MIN_BYTES};
use hysid::data::csv_io::{read_columns_by, Rows};

use super::{fixture_bytes, Fixture};

/// The columns a test reads: every numeric one, one twice, out of order.
const NAMES: [&str; 4] = ["y", "t", "x", "y"];

/// What a read gave, comparable bit for bit: the header and the columns' bits, or the
/// error's message.
type Outcome = Result<(Vec<String>, Vec<Vec<u64>>), String>;

/// Reads `path` the given way: the outcome, and whether the chunks read it.
fn read_by(path: &Path, rows: Rows) -> (Outcome, bool) {
    match read_columns_by(path, &NAMES, rows) {
        Ok((header, columns, chunked)) => {
            let bits = columns
                .iter()
                .map(|column| column.iter().map(|v| v.to_bits()).collect())
                .collect();
            (Ok((header, bits)), chunked)
        }
        Err(error) => (Err(error.to_string()), false),
    }
}

/// The cell text of `value` in one of the forms files hold, picked by `rng`.
fn cell(rng: &mut Xoshiro256PlusPlus) -> String {
    let v: f64 = (rng.random::<f64>() - 0.5) * 10f64.powi(rng.random_range(-6..7));
    let text = match rng.random_range(0..8) {
        0 => format!("{}", rng.random_range(-100_000i64..100_000)),
        1 => format!("{v:e}"),
        2 => format!("{v:.3E}"),
        // 17 significant digits: wider than the fast path's 2⁵³ mantissas.
        3 => format!("{v:.16e}"),
        // More digits than any u64 mantissa.
        4 => format!("{v:.25}"),
        5 => format!("+{}", v.abs()),
        _ => format!("{v}"),
    };
    // Spaces and tabs around a cell are trimmed.
    match rng.random_range(0..10) {
        0 => format!("  {text}"),
        1 => format!("{text}\t "),
        _ => text,
    }
}

/// A plain file of `rows` rows under the header `t, x ,y,label` (`label,t, x ,y` unless
/// `label_last`, so that a number ends each line): mixed number forms, a text column, some
/// lines ending in `\r\n`; `end` is written after the last row instead of its line end (so
/// "" leaves the final newline out).
fn plain_file(seed: u64, rows: usize, end: &str, label_last: bool) -> String {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut text = String::from(match label_last {
        true => "t, x ,y,label\n",
        false => "label,t, x ,y\n",
    });
    for k in 0..rows {
        let (x, y) = (cell(&mut rng), cell(&mut rng));
        let label = ["a", "", "text with spaces", "é"][rng.random_range(0..4)];
        match label_last {
            true => write!(text, "{k},{x},{y},{label}"),
            false => write!(text, "{label},{k},{x},{y}"),
        }
        .unwrap();
        let line_end = if k + 1 == rows {
            end
        } else if rng.random_range(0..4) == 0 {
            "\r\n"
        } else {
            "\n"
        };
        text.push_str(line_end);
    }
    text
}

/// The sequential path's outcome, after checking that the chunks (with `chunk_bytes`) gave
/// the same and whether they read the file themselves.
fn agree(f: &Fixture, chunk_bytes: usize, expect_chunked: bool) -> Outcome {
    let (sequential, chunked_there) = read_by(&f.path, Rows::Sequential);
    assert!(!chunked_there);
    let (chunked, chunked_here) = read_by(&f.path, Rows::Chunked(chunk_bytes));
    assert_eq!(chunked_here, expect_chunked, "chunk bytes {chunk_bytes}");
    assert_eq!(chunked, sequential, "chunk bytes {chunk_bytes}");
    sequential
}

/// Plain multi-megabyte files: the chunks read them, to the same bits as csv records, for
/// every way the header and the file may end.
#[test]
fn plain_files_give_the_same_bits() {
    for (seed, prefix, header_end, end, label_last) in [
        (1, "", "\n", "\n", true),
        (2, "\u{feff}", "\r\n", "", false),
        (3, "", "\r\n", "\r\n", false),
        (4, "\u{feff}", "\n", "", true),
    ] {
        let body = plain_file(seed, 80_000, end, label_last);
        let text = format!("{prefix}{}", body.replacen('\n', header_end, 1));
        let f = fixture_bytes(text.as_bytes());
        let outcome = agree(&f, 64 << 10, true);
        let (header, columns) = outcome.expect("a plain file reads");
        assert_eq!(header.len(), 4);
        assert_eq!(columns[0].len(), 80_000);
        assert_eq!(columns[0], columns[3]);
    }
}

/// `Rows::Auto` takes the chunks for a file of at least `MIN_BYTES` of rows when rayon has two
/// threads, and not for a shorter one.
#[test]
fn auto_takes_the_chunks_for_long_files_only() {
    let long = plain_file(5, (MIN_BYTES / 20) as usize, "\n", false);
    assert!(long.len() as u64 > MIN_BYTES + 1000);
    let f = fixture_bytes(long.as_bytes());
    let (auto, chunked) = read_by(&f.path, Rows::Auto);
    assert_eq!(chunked, rayon::current_num_threads() >= 2);
    assert_eq!(auto, read_by(&f.path, Rows::Sequential).0);

    let f = fixture_bytes(plain_file(6, 1000, "\n", false).as_bytes());
    assert!(!read_by(&f.path, Rows::Auto).1);
}

/// Chunk boundaries on every kind of byte — a line start, the `\n` of a `\r\n`, inside a
/// cell, in the last line — and chunks with no line start of their own.
#[test]
fn every_chunk_boundary_gives_the_same_bits() {
    for label_last in [true, false] {
        let text = plain_file(7, 60, "\r\n", label_last);
        let f = fixture_bytes(text.as_bytes());
        let bytes = text.as_bytes();
        let start = text.find('\n').unwrap() + 1;
        let (mut on_line_start, mut inside_crlf) = (false, false);
        for chunk_bytes in 1..=3 * 64 {
            for boundary in (start + chunk_bytes..bytes.len()).step_by(chunk_bytes) {
                on_line_start |= bytes[boundary - 1] == b'\n';
                inside_crlf |= bytes[boundary - 1] == b'\r';
            }
            agree(&f, chunk_bytes, true).expect("a plain file reads");
        }
        assert!(on_line_start && inside_crlf);
    }
}

/// A small file with `line` in place of data line `row` (0-based) of a plain file.
fn with_line(rows: usize, row: usize, line: &str) -> Fixture {
    let mut lines: Vec<String> = plain_file(8, rows, "\n", true)
        .lines()
        .map(str::to_owned)
        .collect();
    lines[row + 1] = line.to_owned();
    fixture_bytes((lines.join("\n") + "\n").as_bytes())
}

/// Lines the chunks do not read, valid for csv or not: each makes them give up, and the
/// sequential path then gives its values or its error, wherever the line is.
#[test]
fn unusual_lines_fall_back_to_the_same_outcome() {
    // Longer than a chunk's reach past its end, wherever in the chunk the line starts.
    let long_label = "w".repeat(MAX_LINE + 2048);
    let unusual = [
        // Valid for csv: quotes, a quoted delimiter, a quoted line break, a blank line.
        "1,\"2.5\",3,a",
        "1,2.5,3,\"a,b\"",
        "1,2.5,3,\"two\nlines\"",
        "1,2.5,3,a\"b",
        "",
        "\r",
        "1,2.5,3,a\r\r",
        "1,2.5,3,a\r22,2.5,3,a",
        &format!("1,2.5,3,{long_label}"),
        // Invalid: the sequential path's errors, with their line numbers.
        "1,2.5,3",
        "1,2.5,3,a,b",
        "1,2.5\r,3,a",
        "1,abc,3,a",
        "1,,3,a",
        "1,  ,3,a",
        "1,nan,3,a",
        "1,-inf,3,a",
        "1,1e999,3,a",
        "1,0x10,3,a",
        "1,\u{b5},3,a",
    ];
    let rows = 300;
    for line in unusual {
        for row in [0, rows / 2, rows - 1] {
            let f = with_line(rows, row, line);
            // 1 KiB chunks: the line lands in the first, a middle or the last one.
            let (sequential, _) = read_by(&f.path, Rows::Sequential);
            let (chunked, chunked_here) = read_by(&f.path, Rows::Chunked(1024));
            assert!(!chunked_here, "{line:?} in row {row}");
            assert_eq!(chunked, sequential, "{line:?} in row {row}");
        }
    }
}

/// A line running further past its chunk than the first read reaches (but less than
/// `MAX_LINE`) is finished by a second read, not given up.
#[test]
fn long_lines_are_finished() {
    let label = "w".repeat(10_000);
    for row in [0, 150, 299] {
        let f = with_line(300, row, &format!("1,2.5,3,{label}"));
        agree(&f, 1024, true).expect("a plain file reads");
    }
}

/// Text in the columns nobody asked for does not matter.
#[test]
fn other_columns_may_hold_anything_but_quotes() {
    let f = with_line(300, 150, "1,2.5,3,abc ; \t nan é");
    agree(&f, 1024, true).expect("a plain file reads");
}

/// Files with no plain data region: none at all, a header without a line end, a header
/// ending in a bare `\r`, blank lines only.
#[test]
fn files_without_plain_rows_fall_back() {
    for text in [
        "t,x,y",
        "t,x,y\n",
        "t,x,y\r\n",
        "t,x,y\r1,2,3\n",
        "t,x,y\n\n\n",
        "t,x,y\r\n\r\n",
        "t,x,y\n1,2,3",
    ] {
        let f = fixture_bytes(text.as_bytes());
        let outcome = agree(&f, 1, text.ends_with("1,2,3"));
        assert_eq!(outcome.is_ok(), text.contains("1,2,3"), "{text:?}");
    }
}

/// A file of blank lines has no rows, even when no column is asked for (nothing to parse).
#[test]
fn blank_lines_are_no_rows() {
    let f = fixture_bytes(b"t\n\n\r\n\n");
    let error = read_columns_by(&f.path, &[], Rows::Chunked(1)).unwrap_err();
    assert!(error.to_string().contains("no data rows"), "{error}");
    let f = fixture_bytes(b"t\n\n1\n");
    let (_, columns, chunked) = read_columns_by(&f.path, &[], Rows::Chunked(1)).unwrap();
    assert!(columns.is_empty() && !chunked);
}

/// The SWAR scan finds the first special byte, as a byte-by-byte one does.
#[test]
fn find_special_finds_the_first_special_byte() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
    let alphabet = b"0123456789.-e ,\n\r\"\x80\xff";
    for _ in 0..20_000 {
        let len = rng.random_range(0..40);
        let text: Vec<u8> = (0..len)
            .map(|_| {
                // Mostly digits, so that words without a special byte occur.
                if rng.random_range(0..4) == 0 {
                    alphabet[rng.random_range(0..alphabet.len())]
                } else {
                    b'0' + rng.random_range(0..10u8)
                }
            })
            .collect();
        let from = rng.random_range(0..=len);
        let naive = text[from..]
            .iter()
            .position(|b| b",\n\r\"".contains(b))
            .map(|offset| from + offset);
        assert_eq!(find_special(&text, from), naive, "{text:?} from {from}");
    }
}
