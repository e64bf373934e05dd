//! `export::zip`: the archive read back by an independent reader (the central directory
//! parsed here, the data inflated by libflate), the CRC-32 against its check value.

use hysid::export::zip::{archive, crc32, Entry};

/// The entries of a ZIP archive: name, stored CRC, uncompressed contents. Panics on a
/// malformed archive (a test failure).
pub fn read_zip(bytes: &[u8]) -> Vec<(String, u32, Vec<u8>)> {
    let u16_at = |i: usize| u16::from_le_bytes([bytes[i], bytes[i + 1]]) as usize;
    let u32_at = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().unwrap());
    let end = bytes.len() - 22;
    assert_eq!(u32_at(end), 0x0605_4b50, "end of central directory");
    let count = u16_at(end + 10);
    let mut at = u32_at(end + 16) as usize;
    let mut entries = Vec::new();
    for _ in 0..count {
        assert_eq!(u32_at(at), 0x0201_4b50, "central header");
        assert_eq!(u16_at(at + 10), 8, "deflate");
        let crc = u32_at(at + 16);
        let (compressed, size) = (u32_at(at + 20) as usize, u32_at(at + 24) as usize);
        let name_len = u16_at(at + 28);
        let extra = u16_at(at + 30) + u16_at(at + 32);
        let local = u32_at(at + 42) as usize;
        let name = String::from_utf8(bytes[at + 46..at + 46 + name_len].to_vec()).unwrap();
        assert_eq!(u32_at(local), 0x0403_4b50, "local header of {name}");
        assert_eq!(
            u32_at(local + 14),
            crc,
            "the local and central CRC of {name}"
        );
        let data_at = local + 30 + u16_at(local + 26) + u16_at(local + 28);
        let mut data = Vec::new();
        std::io::Read::read_to_end(
            &mut libflate::deflate::Decoder::new(&bytes[data_at..data_at + compressed]),
            &mut data,
        )
        .unwrap();
        assert_eq!(data.len(), size, "size of {name}");
        entries.push((name, crc, data));
        at += 46 + name_len + extra;
    }
    entries
}

#[test]
fn crc32_has_its_check_value() {
    // The check value of CRC-32/ISO-HDLC (the ZIP CRC) over the nine ASCII digits.
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    assert_eq!(crc32(b""), 0);
}

#[test]
fn entries_read_back_with_their_crc() {
    let big: Vec<u8> = (0..100_000u32).map(|k| (k * 7919 % 251) as u8).collect();
    let entries = [
        Entry::new("a.txt", "hello\n"),
        Entry::new("dir/empty", Vec::new()),
        Entry::new("dir/sub/big.bin", big.clone()),
    ];
    let bytes = archive(&entries).unwrap();
    let read = read_zip(&bytes);
    assert_eq!(read.len(), 3);
    for (entry, (name, crc, data)) in entries.iter().zip(&read) {
        assert_eq!(&entry.name, name);
        assert_eq!(&entry.data, data);
        assert_eq!(*crc, crc32(data));
    }
    // Deflated: the repetitive entry shrinks.
    assert!(bytes.len() < big.len() / 2, "{} bytes", bytes.len());
    // The same entries, the same bytes.
    assert_eq!(archive(&entries).unwrap(), bytes);
}

#[test]
fn unsafe_or_repeated_names_are_refused() {
    for name in ["", "/abs", "a/../b", "a//b", "a\\b", "dir/"] {
        let err = archive(&[Entry::new(name, "x")]).unwrap_err().to_string();
        assert!(err.contains("not a relative path"), "{name}: {err}");
    }
    let twice = [Entry::new("a", "1"), Entry::new("a", "2")];
    assert!(archive(&twice).unwrap_err().to_string().contains("twice"));
}
