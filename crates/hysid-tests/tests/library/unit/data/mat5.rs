//! Tests of `hysid::data::mat5`.

use hysid::data::mat5::*;

/// A little-endian MAT-file of one uncompressed double column vector `name`.
fn file_with(name: &str, values: &[f64]) -> Vec<u8> {
    let mut bytes = vec![b' '; 116];
    bytes[..10].copy_from_slice(b"MATLAB 5.0");
    bytes.extend_from_slice(&[0; 8]);
    bytes.extend_from_slice(&[0x00, 0x01, b'I', b'M']);
    let mut m = Vec::new();
    let push = |m: &mut Vec<u8>, kind: u32, data: &[u8]| {
        m.extend_from_slice(&kind.to_le_bytes());
        m.extend_from_slice(&(data.len() as u32).to_le_bytes());
        m.extend_from_slice(data);
        while !m.len().is_multiple_of(8) {
            m.push(0);
        }
    };
    push(&mut m, UINT32, &[6, 0, 0, 0, 0, 0, 0, 0]);
    let dims: Vec<u8> = [values.len() as i32, 1]
        .iter()
        .flat_map(|d| d.to_le_bytes())
        .collect();
    push(&mut m, INT32, &dims);
    push(&mut m, INT8, name.as_bytes());
    let data: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    push(&mut m, DOUBLE, &data);
    push(&mut bytes, MATRIX, &m);
    bytes
}

#[test]
fn an_uncompressed_vector_reads_back() {
    let arrays = parse(&file_with("u", &[1.5, -2.0, 3.25])).unwrap();
    assert_eq!(arrays.len(), 1);
    assert_eq!(arrays[0].name(), "u");
    assert_eq!(arrays[0].size(), &[3, 1]);
    assert_eq!(arrays[0].real(), &[1.5, -2.0, 3.25]);
    assert!(!arrays[0].is_complex());
}

#[test]
fn a_short_data_part_is_refused() {
    let mut bytes = file_with("u", &[1.0, 2.0]);
    // Rows claimed: 5 instead of 2.
    let dims_at = 128 + 8 + 16 + 8;
    bytes[dims_at] = 5;
    let e = parse(&bytes).unwrap_err();
    assert!(e.contains("should hold 5 numbers"), "{e}");
}

#[test]
fn the_limit_is_64_times_the_file_between_16_mib_and_1_gib() {
    assert_eq!(decompression_limit(1000), 16 << 20);
    assert_eq!(decompression_limit(1 << 20), 64 << 20);
    assert_eq!(decompression_limit(1 << 30), 1 << 30);
}
