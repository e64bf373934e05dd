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

use super::float;

/// Data regions shorter than this are read sequentially: that takes two or three
/// milliseconds at most, and an unusual file would be read twice (chunks, then records) for
/// nothing. Longer ones gain already: the Bouc–Wen benchmark's training record (2.4 MB,
/// 40 960 rows of three full-precision numbers) reads in 3.5 ms in chunks on two threads
/// against 10–12 ms record by record.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub const MIN_BYTES: u64 = 512 << 10;

/// Bytes per chunk: large enough that the per-chunk costs (two reads, one lock) vanish next
/// to the parsing, small enough that a chunk read stays in the core's cache until it is
/// parsed, that the threads stay evenly loaded, and that the chunks in flight are a small
/// fraction of the columns' memory.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub const CHUNK_BYTES: usize = 256 << 10;

/// How far past its end a chunk reads first, which is enough to finish its last line unless
/// that line is longer than this.
const TAIL: usize = 4 << 10;

/// How far past its end a chunk reads to finish its last line. A line that does not end by
/// then (a row of more than 64 KiB) sends the file to the sequential path, which has no limit.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
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
    // The length first: a short file, a pipe or a device (length 0) goes no further.
    let len = file.metadata().ok()?.len();
    if len.saturating_sub(after_header) < min_bytes.max(1) {
        return None;
    }
    let start = data_start(file, after_header)?;
    let data_bytes = len.checked_sub(start).filter(|&bytes| bytes > 0)?;
    // Each column once, in field order: a line is then parsed in one pass over its fields.
    let mut wanted = indices.to_vec();
    wanted.sort_unstable();
    wanted.dedup();
    let chunks = Chunks {
        file,
        start,
        len,
        // No chunk longer than the data (nor a buffer for one).
        chunk_bytes: (chunk_bytes as u64).clamp(1, data_bytes),
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
        let assembly = Mutex::new(Assembly::new(self.line.wanted.len(), count));
        let threads = rayon::current_num_threads().clamp(1, count);
        (0..threads).into_par_iter().for_each(|_| {
            let mut buffer = vec![0; self.chunk_bytes as usize + MAX_LINE + 2];
            let mut part = vec![Vec::new(); self.line.wanted.len()];
            while !failed.load(Ordering::Relaxed) {
                let index = next.fetch_add(1, Ordering::Relaxed);
                if index >= count {
                    return;
                }
                if self.parse(index, &mut buffer, &mut part).is_none() {
                    failed.store(true, Ordering::Relaxed);
                    return;
                }
                part = assembly
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .add(index, part);
            }
        });
        if failed.into_inner() {
            return None;
        }
        let assembly = assembly.into_inner().unwrap_or_else(|e| e.into_inner());
        debug_assert_eq!(assembly.next, count);
        Some(assembly.columns)
    }

    /// Pushes the wanted columns of the lines chunk `index` owns onto `columns` (empty), read
    /// through `buffer` (at least `chunk_bytes + MAX_LINE + 2` long); None when the chunk is
    /// not plain.
    fn parse(&self, index: usize, buffer: &mut [u8], columns: &mut [Vec<f64>]) -> Option<()> {
        let Some(window) = self.read(index, buffer)? else {
            return Some(());
        };
        let mut at = window.first;
        while at < window.owned {
            at = self.line.parse(window.text, at, window.at_eof, columns)?;
        }
        Some(())
    }

    /// Reads chunk `index` into `buffer`, from one byte before it (none for the first chunk)
    /// to past the end of its last line: its window, or `Some(None)` when no line starts in
    /// it (it lies inside the file's last line, or inside a long one, which the chunk where
    /// that line starts reads), or None when the read fails, the file has changed length or
    /// the last line runs more than [`MAX_LINE`] bytes past the chunk.
    fn read<'b>(&self, index: usize, buffer: &'b mut [u8]) -> Option<Option<Window<'b>>> {
        let begin = self.start + index as u64 * self.chunk_bytes;
        let end = (begin + self.chunk_bytes).min(self.len);
        // One byte before the chunk tells whether its first byte starts a line.
        let from = if index == 0 { begin } else { begin - 1 };
        let owned = (end - from) as usize;
        // A short reach past the end almost always holds the end of the last line; the rest
        // of MAX_LINE is read only when it does not.
        let mut filled = self.fill(buffer, from, 0, end + TAIL as u64)?;
        let first = match index {
            0 => 0,
            _ => match buffer[..owned].iter().position(|&b| b == b'\n') {
                Some(newline) => newline + 1,
                None => return Some(None),
            },
        };
        // The chunk's last line is complete once a \n follows its last byte (or the file ends).
        let finished = |text: &[u8]| {
            from + text.len() as u64 == self.len || text[owned - 1..].contains(&b'\n')
        };
        if !finished(&buffer[..filled]) {
            filled = self.fill(buffer, from, filled, end + MAX_LINE as u64)?;
            if !finished(&buffer[..filled]) {
                return None;
            }
        }
        Some(Some(Window {
            text: &buffer[..filled],
            first,
            owned,
            at_eof: from + filled as u64 == self.len,
        }))
    }

    /// Reads the file from `from + filled` up to `to` (or its end) into `buffer[filled..]`,
    /// where the bytes from `from` on go: the new number of bytes in `buffer`, or None when
    /// the read fails or the file is not the length it was.
    fn fill(&self, buffer: &mut [u8], from: u64, filled: usize, to: u64) -> Option<usize> {
        let to = to.min(self.len);
        let expected = (to - from) as usize;
        // Reaching the end, ask for one byte more than the file should have: getting it
        // means the file grew, and the sequential path is the one to read it.
        let asked = expected + usize::from(to == self.len);
        let got = read_full(self.file, &mut buffer[filled..asked], from + filled as u64).ok()?;
        (filled + got == expected).then_some(expected)
    }
}

/// The bytes a chunk reads: from the byte before it to past the end of its last line.
struct Window<'b> {
    text: &'b [u8],
    /// Offset in `text` of the first line the chunk owns.
    first: usize,
    /// Offset in `text` of the chunk's end: the chunk owns the lines that start before it.
    owned: usize,
    /// Whether `text` runs to the end of the file, so the last line may end there.
    at_eof: bool,
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
            let wanted = self.wanted.get(next_wanted) == Some(&field);
            // Most wanted cells are a bare number: read in place, it ends where the cell does,
            // and is then what csv_io::number gives for the cell (see float::parse_prefix).
            let in_place = match wanted {
                true => float::parse_prefix(text, cell_start).and_then(|(value, stop)| {
                    let after = cell_end(text, stop, last, at_eof)?;
                    value.is_finite().then_some((value, after))
                }),
                false => None,
            };
            let after = match in_place {
                Some((value, after)) => {
                    columns[next_wanted].push(value);
                    after
                }
                None => {
                    // Find the cell's end, then (if wanted) trim and parse it as csv_io does.
                    let stop = find_special(text, cell_start).unwrap_or(text.len());
                    let after = cell_end(text, stop, last, at_eof)?;
                    if wanted {
                        let cell = text[cell_start..stop].trim_ascii();
                        columns[next_wanted].push(super::number(cell).filter(|v| v.is_finite())?);
                    }
                    // csv skips empty lines, and so rows and line numbers part: not plain.
                    if last && stop == at {
                        return None;
                    }
                    after
                }
            };
            next_wanted += usize::from(wanted);
            if last {
                return Some(after);
            }
            cell_start = after;
        }
        // A header has at least one field.
        None
    }
}

/// Where what follows a cell that stops at `text[stop]` begins, if it ends there as a plain
/// cell does: at a `,` when it is not the line's last, else at a `\n`, a `\r\n` or, when
/// `at_eof`, the end of `text`. None for anything else (a quote, a bare `\r`, a stray byte
/// after a number, too many or too few fields, a line running past the buffer).
fn cell_end(text: &[u8], stop: usize, last: bool, at_eof: bool) -> Option<usize> {
    match (text.get(stop), last) {
        (Some(b','), false) | (Some(b'\n'), true) => Some(stop + 1),
        (Some(b'\r'), true) if text.get(stop + 1) == Some(&b'\n') => Some(stop + 2),
        (None, true) if at_eof => Some(stop),
        _ => None,
    }
}

/// Bytes that end a cell or make a line not plain.
const SPECIAL: [u8; 4] = [b',', b'\n', b'\r', b'"'];

/// Offset of the first [`SPECIAL`] byte of `text` from `from` on. Eight bytes at a time
/// (SWAR): scanning for cell ends is, with the numbers, most of the work, and cells are
/// mostly longer than eight bytes.
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
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
    /// Appended chunks' vectors, emptied, for the next chunks to fill: reused, they keep
    /// their memory, which freed and allocated again would be new pages to fault in.
    spare: Vec<Vec<Vec<f64>>>,
    /// Number of chunks in the file.
    chunks: usize,
}

impl Assembly {
    /// Nothing appended yet, to `width` columns of a file of `chunks` chunks.
    fn new(width: usize, chunks: usize) -> Self {
        Self {
            columns: vec![Vec::new(); width],
            next: 0,
            waiting: BTreeMap::new(),
            spare: Vec::new(),
            chunks,
        }
    }

    /// Takes chunk `index`'s columns; appends them, and any waiting chunks now next in
    /// line. Returns empty vectors for the caller's next chunk.
    fn add(&mut self, index: usize, part: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
        let width = part.len();
        self.waiting.insert(index, part);
        while let Some(mut part) = self.waiting.remove(&self.next) {
            if self.next == 0 {
                // The first chunk's rows times the chunks, and a sixteenth more: the columns
                // are then allocated once instead of growing by doubling (each step a copy
                // and fresh pages). Chunks hold equal bytes, so rows differ only with the
                // lines' lengths; a longer file part just grows the columns as before.
                let rows = part.first().map_or(0, Vec::len);
                let expected = rows.saturating_mul(self.chunks);
                for column in &mut self.columns {
                    column.reserve(expected.saturating_add(expected / 16));
                }
            }
            for (column, values) in self.columns.iter_mut().zip(&mut part) {
                column.extend_from_slice(values);
                values.clear();
            }
            self.spare.push(part);
            self.next += 1;
        }
        self.spare.pop().unwrap_or_else(|| vec![Vec::new(); width])
    }
}
