//! A minimal ZIP writer for FMUs: deflated entries, one fixed timestamp, no extra fields.
//!
//! An FMU is a ZIP archive (FMI 2.0, §2.3: compression method "deflate"). The archive written
//! here is the plainest the ZIP format (PKWARE APPNOTE 6.3.x) allows, so that the same
//! entries always give the same bytes:
//!
//! * each entry is a local file header, the deflated data (method 8, raw deflate by
//!   `libflate`), and is listed again in the central directory, which the end-of-central-
//!   directory record points to;
//! * every entry carries the same timestamp, 1980-01-01 00:00 (the earliest MS-DOS date, the
//!   format's zero), no extra fields, no comment, no data descriptor (sizes and CRC-32 are
//!   known before the header is written), and external attributes of a regular file with
//!   mode 0644 made on unix;
//! * names are UTF-8 with `/` as separator (general-purpose flag bit 11 set).
//!
//! No ZIP64: more than 65 535 entries, an entry or an archive beyond 4 GiB is refused.

use crate::{Error, Result};
use std::io::Write;

/// One file of an archive: its path inside the archive (`/`-separated) and its bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    /// The path inside the archive, `/`-separated, relative (`sources/model.c`).
    pub name: String,
    /// The file's contents.
    pub data: Vec<u8>,
}

impl Entry {
    /// The entry `name` holding `data`.
    pub fn new(name: impl Into<String>, data: impl Into<Vec<u8>>) -> Self {
        Self {
            name: name.into(),
            data: data.into(),
        }
    }
}

/// The ZIP archive of `entries`, in their order. Refused: an empty, absolute or `..` name,
/// a name given twice, and sizes beyond the format without ZIP64.
pub fn archive(entries: &[Entry]) -> Result<Vec<u8>> {
    if entries.len() > usize::from(u16::MAX) {
        return Err(too_large(&format!("{} entries", entries.len())));
    }
    let mut out = Vec::new();
    let mut central = Vec::new();
    for (k, entry) in entries.iter().enumerate() {
        check_name(&entry.name)?;
        if entries[..k].iter().any(|e| e.name == entry.name) {
            return Err(Error::InvalidData(format!(
                "zip archive: the entry {} is given twice",
                entry.name
            )));
        }
        let offset = u32_of(out.len(), "the archive")?;
        let compressed = deflate(&entry.data)?;
        let record = Record {
            name: entry.name.as_bytes(),
            crc: crc32(&entry.data),
            compressed: u32_of(compressed.len(), &entry.name)?,
            size: u32_of(entry.data.len(), &entry.name)?,
        };
        record.local_header(&mut out);
        out.extend_from_slice(&compressed);
        record.central_header(offset, &mut central);
    }
    let directory_offset = u32_of(out.len(), "the archive")?;
    let directory_size = u32_of(central.len(), "the central directory")?;
    out.extend_from_slice(&central);
    // End of central directory record.
    let count = entries.len() as u16; // checked above
    put32(&mut out, 0x0605_4b50);
    put16(&mut out, 0); // number of this disk
    put16(&mut out, 0); // disk where the central directory starts
    put16(&mut out, count);
    put16(&mut out, count);
    put32(&mut out, directory_size);
    put32(&mut out, directory_offset);
    put16(&mut out, 0); // comment length
    u32_of(out.len(), "the archive")?;
    Ok(out)
}

/// Version needed to extract: 2.0 (deflate).
const VERSION_NEEDED: u16 = 20;
/// Version made by: unix (3) in the high byte, ZIP specification 2.0 in the low byte.
const VERSION_MADE_BY: u16 = (3 << 8) | 20;
/// General-purpose flags: bit 11, names are UTF-8.
const FLAGS: u16 = 1 << 11;
/// Compression method 8: deflate.
const DEFLATE: u16 = 8;
/// MS-DOS time 00:00:00.
const DOS_TIME: u16 = 0;
/// MS-DOS date 1980-01-01: (year − 1980) << 9 | month << 5 | day.
const DOS_DATE: u16 = (1 << 5) | 1;
/// External attributes: a regular file, mode 0644, in the high 16 bits (unix).
const EXTERNAL_ATTRIBUTES: u32 = 0o100_644 << 16;

/// What the local and the central header of one entry share.
struct Record<'a> {
    name: &'a [u8],
    crc: u32,
    compressed: u32,
    size: u32,
}

impl Record<'_> {
    /// The fields from the version needed to the file-name length, common to both headers.
    fn common(&self, out: &mut Vec<u8>) {
        put16(out, VERSION_NEEDED);
        put16(out, FLAGS);
        put16(out, DEFLATE);
        put16(out, DOS_TIME);
        put16(out, DOS_DATE);
        put32(out, self.crc);
        put32(out, self.compressed);
        put32(out, self.size);
        put16(out, self.name.len() as u16); // at most 255 bytes: check_name
    }

    fn local_header(&self, out: &mut Vec<u8>) {
        put32(out, 0x0403_4b50);
        self.common(out);
        put16(out, 0); // extra field length
        out.extend_from_slice(self.name);
    }

    fn central_header(&self, offset: u32, out: &mut Vec<u8>) {
        put32(out, 0x0201_4b50);
        put16(out, VERSION_MADE_BY);
        self.common(out);
        put16(out, 0); // extra field length
        put16(out, 0); // comment length
        put16(out, 0); // disk number start
        put16(out, 0); // internal attributes
        put32(out, EXTERNAL_ATTRIBUTES);
        put32(out, offset);
        out.extend_from_slice(self.name);
    }
}

/// Refuses a name an unzip tool would put outside its target, or cannot store.
fn check_name(name: &str) -> Result<()> {
    let bad = name.is_empty()
        || name.len() > 255
        || name.starts_with('/')
        || name.contains('\\')
        || name.split('/').any(|part| part.is_empty() || part == "..");
    if bad {
        return Err(Error::InvalidData(format!(
            "zip archive: the entry name '{name}' is not a relative path of at most 255 bytes \
             without '..'"
        )));
    }
    Ok(())
}

/// `data`, raw-deflated (RFC 1951).
fn deflate(data: &[u8]) -> Result<Vec<u8>> {
    let failed = |e: std::io::Error| Error::Serialization(format!("zip archive: deflate: {e}"));
    let mut encoder = libflate::deflate::Encoder::new(Vec::new());
    encoder.write_all(data).map_err(failed)?;
    encoder.finish().into_result().map_err(failed)
}

/// `n` as the format's 32-bit size, refused beyond 4 GiB (no ZIP64).
fn u32_of(n: usize, what: &str) -> Result<u32> {
    u32::try_from(n).map_err(|_| too_large(&format!("{what} ({n} bytes)")))
}

fn too_large(what: &str) -> Error {
    Error::InvalidData(format!(
        "zip archive: {what} exceeds what a ZIP file without ZIP64 holds (65 535 entries, \
         4 GiB); export a smaller model"
    ))
}

fn put16(out: &mut Vec<u8>, v: u16) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

/// The CRC-32 of `data` (ISO 3309 / ITU-T V.42, the ZIP and gzip checksum: reflected
/// polynomial 0xEDB88320, initial value and final XOR 0xFFFFFFFF), by `crc32fast`.
pub fn crc32(data: &[u8]) -> u32 {
    crc32fast::hash(data)
}
