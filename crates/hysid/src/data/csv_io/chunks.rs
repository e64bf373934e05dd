//! Reading long, plain numeric CSV files in chunks, in parallel.
//!
//! The sequential reader ([`super::pipeline`]) splits records on one thread and parses
//! numbers on another, so two cores are the most it can use and the splitting (quotes, line
//! ends) runs at the speed of one. Most long files are plain: one record per line, no quotes.
//! For those, the data region (the bytes after the header) is cut into fixed chunks that the
//! rayon threads read with positioned reads ([`FileExt::read_at`], so the file is never held
//! in memory whole) and parse independently; their columns are appended in file order.
//!
//! **Ownership.** A line begins at the start of the data region or just after a `\n`. A chunk
//! owns the lines that *begin* inside it: it skips to its first line start (it reads one byte
//! before its range to see whether its first byte is one) and finishes its last line past its
//! end (it reads up to [`MAX_LINE`] bytes further). Every line therefore belongs to exactly
//! one chunk, whichever byte the chunk boundary falls on, the `\n` of a `\r\n` included; a
//! chunk that lies wholly inside a line owns none.
//!
//! **Falling back.** The chunks accept only what the csv crate would read the same way and
//! the sequential path would accept: lines ending in `\n` or `\r\n` (or at the end of the
//! file), none empty, holding no `"` and no other `\r` (csv ends a record at a bare `\r`),
//! each with exactly the header's number of `,`-separated fields, every wanted cell, once
//! trimmed, parsed by `csv_io::number`, the function the sequential path uses, to a
//! finite value. Anything else — a quote, a blank line, a ragged row, a bad or non-finite
//! number, a line running more than [`MAX_LINE`] bytes past the chunk it starts in, an I/O
//! error, a file that is no longer the length it was — makes `read` return `None`, and the
//! caller reads the data region from its start on the sequential path (the csv reader has
//! not moved from the end of the header). So valid but unusual files get the sequential
//! path's values, invalid ones its exact error (message and line number), and a plain file
//! the same bits as it would there: the same cell bytes go through the same parser.

use std::collections::BTreeMap;
use std::fs::File;
use std::io;
use std::os::unix::fs::FileExt;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

use rayon::prelude::*;

/// Data regions shorter than this are read sequentially: that takes a few milliseconds at
/// most, and an unusual file would be read twice (chunks, then records) for nothing.
#[doc(hidden)] // reached by the white-box tests in tests/library/unit
pub const MIN_BYTES: u64 = 4 << 20;

/// Bytes per chunk: large enough that the per-chunk costs (one read, one lock, a few small
/// vectors) vanish next to the parsing, small enough to keep two threads evenly loaded and
/// the chunks in flight a small fraction of the columns' memory.
#[doc(hidden)] // reached by the white-box tests in tests/library/unit
pub const CHUNK_BYTES: usize = 1 << 20;

/// How far past its end a chunk reads to finish its last line. A line that does not end by
/// then (a row of more than 64 KiB) sends the file to the sequential path, which has no limit.
#[doc(hidden)] // reached by the white-box tests in tests/library/unit
pub const MAX_LINE: usize = 64 << 10;

/// The values of columns `indices` (in that order) of every data row, or `None` when the file
/// is not for this path (see the [module documentation](self)); `min_bytes` is the shortest
/// data region worth splitting.
///
/// `after_header` is the csv reader's byte offset after the header record; `fields` the
/// header's number of fields.
pub(super) fn read(
    file: &File,
    after_header: u64,
    fields: usize,
    indices: &[usize],
    chunk_bytes: usize,
    min_bytes: u64,
) -> Option<Vec<Vec<f64>>> {
    let len = file.metadata().ok()?.len();
    let start = data_start(file, after_header)?;
    if len.checked_sub(start)? < min_bytes.max(1) {
        return None;
    }
    // Each column once, in field order: a line is then parsed in one pass over its fields.
    let mut wanted = indices.to_vec();
    wanted.sort_unstable();
    wanted.dedup();
    let chunks = Chunks {
        file,
        start,
        len,
        chunk_bytes: chunk_bytes.max(1) as u64,
        line: Line {
            fields,
            wanted: &wanted,
        },
    };
    let parsed = chunks.read_all()?;
    Some(in_order(parsed, &wanted, indices))
}

/// The columns of fields `wanted` (increasing) put in the order of `indices`; a column asked
/// for twice is copied.
fn in_order(mut parsed: Vec<Vec<f64>>, wanted: &[usize], indices: &[usize]) -> Vec<Vec<f64>> {
    let mut columns = Vec::with_capacity(indices.len());
    for (k, col) in indices.iter().enumerate() {
        let at = wanted.binary_search(col).expect("every index is wanted");
        let repeated = indices[k + 1..].contains(col);
        columns.push(if repeated {
            parsed[at].clone()
        } else {
            std::mem::take(&mut parsed[at])
        });
    }
    columns
}

/// Offset of the first data line. csv leaves its position after the header's terminator,
/// which for `\r\n` is between the two bytes (it would skip the `\n` as an empty line). None
/// when the header does not end in `\n` or `\r\n` (a bare `\r`, or no data at all).
fn data_start(file: &File, after_header: u64) -> Option<u64> {
    let mut around = [0; 2];
    let got = read_full(file, &mut around, after_header.checked_sub(1)?).ok()?;
    match &around[..got] {
        [b'\n', ..] => Some(after_header),
        [b'\r', b'\n'] => Some(after_header + 1),
        _ => None,
    }
}

/// Fills `buffer` from `offset` onwards until it is full or the file ends: how many bytes
/// were read. (`read_at` may return fewer bytes than asked for before the end.)
fn read_full(file: &File, buffer: &mut [u8], offset: u64) -> io::Result<usize> {
    let mut filled = 0;
    while filled < buffer.len() {
        match file.read_at(&mut buffer[filled..], offset + filled as u64) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

/// The data region of one file, cut into chunks.
struct Chunks<'a> {
    file: &'a File,
    /// Offset of the first data line.
    start: u64,
    /// The file's length when the read began.
    len: u64,
    /// Bytes per chunk (the last one may be shorter).
    chunk_bytes: u64,
    /// What each line holds.
    line: Line<'a>,
}

impl Chunks<'_> {
    /// Number of chunks: the data region is not empty, so at least one.
    fn count(&self) -> usize {
        (self.len - self.start).div_ceil(self.chunk_bytes) as usize
    }

    /// Every chunk, parsed by the rayon threads and appended in order; None as soon as one
    /// chunk fails (the others then stop at their next chunk).
    fn read_all(&self) -> Option<Vec<Vec<f64>>> {
        let count = self.count();
        // Each thread takes the next chunk in file order, so finished chunks rarely wait long
        // for an earlier one, and few are held besides the growing columns.
        let next = AtomicUsize::new(0);
        let failed = AtomicBool::new(false);
        let assembly = Mutex::new(Assembly::new(self.line.wanted.len()));
        let threads = rayon::current_num_threads().clamp(1, count);
        (0..threads).into_par_iter().for_each(|_| {
            let mut buffer = vec![0; self.chunk_bytes as usize + MAX_LINE + 2];
            // Chunks hold about as many rows as the one before: reserving that many (and a
            // little more) saves growing the vectors row by row.
            let mut rows_hint = 0;
            while !failed.load(Ordering::Relaxed) {
                let index = next.fetch_add(1, Ordering::Relaxed);
                if index >= count {
                    return;
                }
                match self.parse(index, &mut buffer, rows_hint) {
                    Some(part) => {
                        rows_hint = part.first().map_or(0, |c| c.len() + c.len() / 16);
                        assembly
                            .lock()
                            .unwrap_or_else(|e| e.into_inner())
                            .add(index, part);
                    }
                    None => failed.store(true, Ordering::Relaxed),
                }
            }
        });
        if failed.into_inner() {
            return None;
        }
        let assembly = assembly.into_inner().unwrap_or_else(|e| e.into_inner());
        debug_assert_eq!(assembly.next, count);
        Some(assembly.columns)
    }

    /// The wanted columns of the lines chunk `index` owns, read through `buffer` (at least
    /// `chunk_bytes + MAX_LINE + 2` long); `rows_hint` rows are reserved.
    fn parse(&self, index: usize, buffer: &mut [u8], rows_hint: usize) -> Option<Vec<Vec<f64>>> {
        let begin = self.start + index as u64 * self.chunk_bytes;
        let end = (begin + self.chunk_bytes).min(self.len);
        // One byte before the chunk tells whether its first byte starts a line.
        let from = if index == 0 { begin } else { begin - 1 };
        let to = (end + MAX_LINE as u64).min(self.len);
        let at_eof = to == self.len;
        // Reaching the end, ask for one byte more than the file should have: getting it
        // means the file grew, and the sequential path is the one to read it.
        let expected = (to - from) as usize;
        let asked = expected + usize::from(at_eof);
        let got = read_full(self.file, &mut buffer[..asked], from).ok()?;
        if got != expected {
            return None;
        }
        let text = &buffer[..expected];
        let owned = (end - from) as usize;
        // (Not vec![…; n]: a clone of a vector does not keep its capacity.)
        let mut columns: Vec<Vec<f64>> = (0..self.line.wanted.len())
            .map(|_| Vec::with_capacity(rows_hint))
            .collect();
        // A chunk in which no line starts (it lies inside the file's last line, or inside a
        // long one) owns nothing: the chunk where that line starts reads it.
        let mut at = match index {
            0 => 0,
            _ => match text.iter().position(|&b| b == b'\n') {
                Some(newline) => newline + 1,
                None => return Some(columns),
            },
        };
        while at < owned {
            at = self.line.parse(text, at, at_eof, &mut columns)?;
        }
        Some(columns)
    }
}

/// What a plain data line holds: its number of fields and the ones to parse.
struct Line<'a> {
    /// The header's number of fields, which csv demands of every row.
    fields: usize,
    /// Wanted field indices, increasing, each once.
    wanted: &'a [usize],
}

impl Line<'_> {
    /// Parses the line starting at `text[at]`, pushing its wanted cells onto `columns`: the
    /// offset of the next line, or None when the line is not plain or a cell not a finite
    /// number. The line ends at `\n` (a `\r` just before it is dropped) or, when `at_eof`,
    /// at the end of `text`.
    fn parse(
        &self,
        text: &[u8],
        at: usize,
        at_eof: bool,
        columns: &mut [Vec<f64>],
    ) -> Option<usize> {
        let mut cell_start = at;
        let mut next_wanted = 0;
        for field in 0..self.fields {
            let last = field + 1 == self.fields;
            // Where the cell ends, and where what follows it begins.
            let (cell_end, after) = match find_special(text, cell_start) {
                Some(stop) => {
                    match (text[stop], last) {
                        (b',', false) | (b'\n', true) => (stop, stop + 1),
                        (b'\r', true) if text.get(stop + 1) == Some(&b'\n') => (stop, stop + 2),
                        // A quote, a bare \r, too many or too few fields.
                        _ => return None,
                    }
                }
                None if at_eof && last => (text.len(), text.len()),
                // A line too long for the chunk, or too few fields in the file's last line.
                None => return None,
            };
            if self.wanted.get(next_wanted) == Some(&field) {
                let cell = text[cell_start..cell_end].trim_ascii();
                let value = super::number(cell).filter(|v| v.is_finite())?;
                columns[next_wanted].push(value);
                next_wanted += 1;
            }
            if last {
                // csv skips empty lines, and so rows and line numbers part: not plain.
                return (cell_end > at).then_some(after);
            }
            cell_start = after;
        }
        // A header has at least one field.
        None
    }
}

/// Bytes that end a cell or make a line not plain.
const SPECIAL: [u8; 4] = [b',', b'\n', b'\r', b'"'];

/// Offset of the first [`SPECIAL`] byte of `text` from `from` on. Eight bytes at a time
/// (SWAR): scanning for cell ends is, with the numbers, most of the work, and cells are
/// mostly longer than eight bytes.
#[doc(hidden)] // reached by the white-box tests in tests/library/unit
pub fn find_special(text: &[u8], from: usize) -> Option<usize> {
    let mut at = from;
    while let Some(word) = text.get(at..at + 8) {
        let word = u64::from_le_bytes(word.try_into().expect("eight bytes"));
        let found = SPECIAL
            .iter()
            .fold(0, |found, &byte| found | equal_bytes(word, byte));
        if found != 0 {
            // The lowest flag is exact (see equal_bytes): the first special byte.
            return Some(at + found.trailing_zeros() as usize / 8);
        }
        at += 8;
    }
    let tail = text.get(at..)?;
    tail.iter()
        .position(|b| SPECIAL.contains(b))
        .map(|offset| at + offset)
}

/// The high bit of every byte of `word` that equals `byte`, read little-endian. The classic
/// zero-byte test on `word ^ byte…byte`: a borrow can flag a byte *above* a matching one
/// falsely, never one below, so the lowest flag always marks the first match.
fn equal_bytes(word: u64, byte: u8) -> u64 {
    const ONES: u64 = 0x0101_0101_0101_0101;
    const HIGHS: u64 = 0x8080_8080_8080_8080;
    let zero_where_equal = word ^ (ONES * u64::from(byte));
    zero_where_equal.wrapping_sub(ONES) & !zero_where_equal & HIGHS
}

/// Chunks' columns put together in file order as the chunks finish.
struct Assembly {
    /// The columns of chunks `0..next`.
    columns: Vec<Vec<f64>>,
    /// The chunk to append next.
    next: usize,
    /// Finished chunks after `next`, waiting for it.
    waiting: BTreeMap<usize, Vec<Vec<f64>>>,
}

impl Assembly {
    /// Nothing appended yet, to `width` columns.
    fn new(width: usize) -> Self {
        Self {
            columns: vec![Vec::new(); width],
            next: 0,
            waiting: BTreeMap::new(),
        }
    }

    /// Takes chunk `index`'s columns; appends them, and any waiting chunks now next in
    /// line, freeing each as it goes.
    fn add(&mut self, index: usize, part: Vec<Vec<f64>>) {
        self.waiting.insert(index, part);
        while let Some(part) = self.waiting.remove(&self.next) {
            for (column, values) in self.columns.iter_mut().zip(part) {
                column.extend_from_slice(&values);
            }
            self.next += 1;
        }
    }
}
