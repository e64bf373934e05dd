//! A reader of the numeric arrays of a level-5 MAT-file, with every size checked.
//!
//! The level-5 format (The MathWorks, *MAT-File Format*, versions 5 to 7) is a 128-byte
//! header — 116 bytes of text, an 8-byte subsystem offset, a 2-byte version and the
//! endian indicator `IM` (little endian) or `MI` (big endian) — followed by data elements.
//! Each element has an 8-byte tag (data type, byte count) or, when the upper half of its
//! first word is non-zero, a 4-byte "small element" tag with up to 4 bytes of data. An
//! element `miMATRIX` (14) holds sub-elements: array flags (class, complex bit), dimensions
//! (`miINT32`), the name (`miINT8`), the real part and, for a complex array, the imaginary
//! part, each padded to 8 bytes. An element `miCOMPRESSED` (15) holds a zlib stream (RFC
//! 1950) of further elements.
//!
//! Only dense numeric classes (double, single, 8- to 64-bit integers) are returned; cells,
//! structures, objects, characters and sparse matrices are skipped. Nothing is printed:
//! every problem is an error string. Decompression is capped (see [`decompression_limit`])
//! so that a small file cannot expand into gigabytes.

use std::io::Read;

/// Bytes of the file header before the first data element.
const HEADER_BYTES: usize = 128;
/// The largest ratio of decompressed bytes to the file's size that is accepted.
pub const MAX_EXPANSION: u64 = 64;
/// The most decompressed bytes accepted from one file (1 GiB), whatever its size.
pub const MAX_DECOMPRESSED: u64 = 1 << 30;
/// Decompressed bytes always allowed (16 MiB), so that a small file of nearly constant
/// channels, which compresses far better than 64:1, still reads.
const MIN_BUDGET: u64 = 16 << 20;

/// A dense numeric array of the file, its values converted to `f64`, column-major.
#[derive(Debug, Clone)]
pub struct MatArray {
    name: String,
    dims: Vec<usize>,
    real: Vec<f64>,
    complex: bool,
}

impl MatArray {
    /// The variable's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The dimensions (rows, columns, …).
    pub fn size(&self) -> &[usize] {
        &self.dims
    }

    /// The real part, column-major.
    pub fn real(&self) -> &[f64] {
        &self.real
    }

    /// True when the array has an imaginary part.
    pub fn is_complex(&self) -> bool {
        self.complex
    }
}

/// The most decompressed bytes accepted from a file of `file_bytes` bytes:
/// min(1 GiB, max(64 × file size, 16 MiB)).
pub fn decompression_limit(file_bytes: usize) -> u64 {
    let file_bytes = u64::try_from(file_bytes).unwrap_or(u64::MAX);
    file_bytes
        .saturating_mul(MAX_EXPANSION)
        .clamp(MIN_BUDGET, MAX_DECOMPRESSED)
}

/// The dense numeric arrays of a level-5 MAT-file (header included in `bytes`).
pub fn parse(bytes: &[u8]) -> Result<Vec<MatArray>, String> {
    let header = bytes
        .get(..HEADER_BYTES)
        .ok_or("the file is shorter than the 128-byte MAT-file header")?;
    let big_endian = match &header[126..128] {
        b"IM" => false,
        b"MI" => true,
        _ => return Err("the header has no endian indicator (IM or MI)".into()),
    };
    let mut reader = Reader {
        big_endian,
        budget: decompression_limit(bytes.len()),
        limit: decompression_limit(bytes.len()),
        file_bytes: bytes.len(),
        arrays: Vec::new(),
    };
    reader.elements(&bytes[HEADER_BYTES..], HEADER_BYTES, true)?;
    Ok(reader.arrays)
}

/// The parsing state: byte order, what is left of the decompression budget, the arrays.
struct Reader {
    big_endian: bool,
    budget: u64,
    limit: u64,
    file_bytes: usize,
    arrays: Vec<MatArray>,
}

/// A data element: its type, its data and where it starts (for messages).
struct Element<'a> {
    kind: u32,
    data: &'a [u8],
    offset: usize,
}

/// A cursor over a byte slice that splits off tagged elements.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    base: usize,
    big_endian: bool,
}

impl<'a> Cursor<'a> {
    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    fn word(&self, at: usize) -> Option<u32> {
        let b: [u8; 4] = self.bytes.get(at..at.checked_add(4)?)?.try_into().ok()?;
        Some(if self.big_endian {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        })
    }

    /// The next element; uncompressed elements are padded to 8 bytes (`pad`).
    fn next(&mut self, pad: bool) -> Result<Element<'a>, String> {
        let offset = self.base + self.pos;
        let truncated = || format!("the data element at byte {offset} is truncated");
        let first = self.word(self.pos).ok_or_else(truncated)?;
        if first >> 16 != 0 {
            // Small data element: type in the lower half, size in the upper, 4 data bytes.
            let len = usize::try_from(first >> 16).map_err(|_| truncated())?;
            if len > 4 {
                return Err(format!(
                    "the small data element at byte {offset} claims {len} bytes (at most 4)"
                ));
            }
            let data = self
                .bytes
                .get(self.pos + 4..self.pos + 4 + len)
                .ok_or_else(truncated)?;
            self.pos = (self.pos + 8).min(self.bytes.len());
            return Ok(Element {
                kind: first & 0xffff,
                data,
                offset,
            });
        }
        let len = self.word(self.pos + 4).ok_or_else(truncated)?;
        let len = usize::try_from(len).map_err(|_| truncated())?;
        let start = self.pos + 8;
        let end = start.checked_add(len).ok_or_else(truncated)?;
        let data = self.bytes.get(start..end).ok_or_else(|| {
            format!(
                "the data element at byte {offset} claims {len} bytes but only {} remain",
                self.bytes.len().saturating_sub(start)
            )
        })?;
        let kind = first;
        let padded = if pad && kind != COMPRESSED {
            end.checked_add(7).map_or(end, |e| e / 8 * 8)
        } else {
            end
        };
        self.pos = padded.min(self.bytes.len());
        Ok(Element { kind, data, offset })
    }
}

#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub const INT8: u32 = 1;
const UINT8: u32 = 2;
const INT16: u32 = 3;
const UINT16: u32 = 4;
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub const INT32: u32 = 5;
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub const UINT32: u32 = 6;
const SINGLE: u32 = 7;
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub const DOUBLE: u32 = 9;
const INT64: u32 = 12;
const UINT64: u32 = 13;
#[doc(hidden)] // reached by the white-box tests in crates/hysid-tests/tests/library/unit
pub const MATRIX: u32 = 14;
const COMPRESSED: u32 = 15;

/// Array classes with dense numeric data (double … uint64).
const NUMERIC_CLASSES: std::ops::RangeInclusive<u32> = 6..=15;
/// The array-flags bit of a complex array.
const COMPLEX_FLAG: u32 = 0x0800;

impl Reader {
    /// Reads the elements of `bytes` (which starts at byte `base` of its stream); a
    /// compressed element is allowed only at the top level.
    fn elements(&mut self, bytes: &[u8], base: usize, top: bool) -> Result<(), String> {
        let mut cursor = Cursor {
            bytes,
            pos: 0,
            base,
            big_endian: self.big_endian,
        };
        while cursor.remaining() >= 8 {
            let element = cursor.next(true)?;
            match element.kind {
                MATRIX => self.matrix(&element)?,
                COMPRESSED if top => {
                    let inflated = self.inflate(&element)?;
                    self.elements(&inflated, 0, false)?;
                }
                COMPRESSED => {
                    return Err(format!(
                        "the compressed element at byte {} is nested in another",
                        element.offset
                    ))
                }
                // Other top-level elements carry no variable (MATLAB writes none).
                _ => {}
            }
        }
        Ok(())
    }

    /// The zlib stream of a compressed element, refused past the decompression budget.
    fn inflate(&mut self, element: &Element) -> Result<Vec<u8>, String> {
        // The decoder's own message describes its internals (bit regions, block types):
        // only whether the stream ends early or is malformed is said.
        let corrupt = |e: std::io::Error| {
            let what = match e.kind() {
                std::io::ErrorKind::UnexpectedEof => "ends before its data are complete",
                _ => "is not a valid zlib stream",
            };
            format!(
                "the compressed element at byte {} is corrupt: it {what}",
                element.offset
            )
        };
        let decoder = libflate::zlib::Decoder::new(element.data).map_err(corrupt)?;
        let mut inflated = Vec::new();
        decoder
            .take(self.budget.saturating_add(1))
            .read_to_end(&mut inflated)
            .map_err(corrupt)?;
        let got = u64::try_from(inflated.len()).unwrap_or(u64::MAX);
        if got > self.budget {
            return Err(format!(
                "it decompresses to more than {} bytes, over the limit of {} bytes for a {}-byte file (64 times its size, at least 16 MiB, at most 1 GiB)",
                self.limit, self.limit, self.file_bytes
            ));
        }
        self.budget -= got;
        Ok(inflated)
    }

    /// A `miMATRIX` element: kept when it is a dense numeric array.
    fn matrix(&mut self, element: &Element) -> Result<(), String> {
        if element.data.is_empty() {
            return Ok(());
        }
        let at = element.offset;
        let mut cursor = Cursor {
            bytes: element.data,
            pos: 0,
            base: at + 8,
            big_endian: self.big_endian,
        };
        let flags = cursor.next(true)?;
        if flags.kind != UINT32 || flags.data.len() != 8 {
            return Err(format!("the array at byte {at} has no array flags"));
        }
        let words = self.numbers(UINT32, flags.data, at)?;
        let class = words[0] as u32 & 0xff;
        let complex = words[0] as u32 & COMPLEX_FLAG != 0;
        if !NUMERIC_CLASSES.contains(&class) {
            return Ok(());
        }
        let dims = cursor.next(true)?;
        if dims.kind != INT32 || dims.data.len() < 8 {
            return Err(format!("the array at byte {at} has no valid dimensions"));
        }
        let dims: Vec<usize> = self
            .numbers(INT32, dims.data, at)?
            .into_iter()
            .map(|d| usize::try_from(d as i64).ok())
            .collect::<Option<_>>()
            .ok_or_else(|| format!("the array at byte {at} has a negative dimension"))?;
        let count = dims
            .iter()
            .try_fold(1usize, |n, &d| n.checked_mul(d))
            .ok_or_else(|| format!("the array at byte {at} has dimensions too large"))?;
        let name = cursor.next(true)?;
        if name.kind != INT8 && name.kind != UINT8 {
            return Err(format!("the array at byte {at} has no name"));
        }
        let name = String::from_utf8_lossy(name.data).into_owned();
        let real = self.part(&mut cursor, count, &name)?;
        if complex {
            self.part(&mut cursor, count, &name)?;
        }
        self.arrays.push(MatArray {
            name,
            dims,
            real,
            complex,
        });
        Ok(())
    }

    /// A real or imaginary part of `count` numbers.
    fn part(&self, cursor: &mut Cursor, count: usize, name: &str) -> Result<Vec<f64>, String> {
        if cursor.remaining() == 0 {
            return Err(format!("variable '{name}' has no data"));
        }
        let part = cursor.next(true)?;
        let size = element_size(part.kind).ok_or_else(|| {
            format!(
                "variable '{name}' has data of unknown type {} at byte {}",
                part.kind, part.offset
            )
        })?;
        if count.checked_mul(size) != Some(part.data.len()) {
            return Err(format!(
                "variable '{name}' should hold {count} numbers but its data has {} bytes of {size}",
                part.data.len()
            ));
        }
        self.numbers(part.kind, part.data, part.offset)
    }

    /// The numbers of type `kind` in `data`, as `f64` (64-bit integers are rounded).
    fn numbers(&self, kind: u32, data: &[u8], at: usize) -> Result<Vec<f64>, String> {
        let size =
            element_size(kind).ok_or_else(|| format!("unknown data type {kind} at byte {at}"))?;
        let big = self.big_endian;
        Ok(data
            .chunks_exact(size)
            .map(|c| decode(kind, c, big))
            .collect())
    }
}

/// Bytes per number of a numeric data type.
fn element_size(kind: u32) -> Option<usize> {
    match kind {
        INT8 | UINT8 => Some(1),
        INT16 | UINT16 => Some(2),
        INT32 | UINT32 | SINGLE => Some(4),
        DOUBLE | INT64 | UINT64 => Some(8),
        _ => None,
    }
}

/// One number of type `kind` from its bytes.
fn decode(kind: u32, c: &[u8], big: bool) -> f64 {
    macro_rules! num {
        ($t:ty) => {{
            let mut b = [0u8; std::mem::size_of::<$t>()];
            b.copy_from_slice(c);
            if big {
                <$t>::from_be_bytes(b)
            } else {
                <$t>::from_le_bytes(b)
            }
        }};
    }
    match kind {
        INT8 => f64::from(num!(i8)),
        UINT8 => f64::from(num!(u8)),
        INT16 => f64::from(num!(i16)),
        UINT16 => f64::from(num!(u16)),
        INT32 => f64::from(num!(i32)),
        UINT32 => f64::from(num!(u32)),
        SINGLE => f64::from(num!(f32)),
        DOUBLE => num!(f64),
        // Counts and indices fit; larger integers round to the nearest double.
        INT64 => num!(i64) as f64,
        _ => num!(u64) as f64,
    }
}
