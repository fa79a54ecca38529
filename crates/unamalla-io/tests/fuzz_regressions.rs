//! Regression tests for inputs found by the fuzz targets of `fuzz/` (figures and commands
//! in `docs/reliability.md`).

use unamalla_io::{parse_shapefile_parts, IoError};

/// `shapefile` target: a 320-byte file whose polygon record (2 parts, 10 points) has a first
/// part index of 0x9a00_0000 (negative as `i32`); the `shapefile` crate derived a ring of
/// ~1.7·10⁹ points from the part indices and reserved ~27 GB before reading (an out-of-memory
/// abort under the fuzzer). Record sizes, counts and part indices are now checked against the
/// file first: the error is `MalformedBinary` at the byte offset of the bad part index
/// (record at byte 100, content at 108, part indices from 108 + 44 = 152).
#[test]
fn shapefile_with_impossible_point_count_is_an_error_not_an_allocation() {
    let bytes = include_bytes!("data/fuzz/shapefile-huge-point-count.shp");
    match parse_shapefile_parts(bytes) {
        Err(IoError::MalformedBinary {
            offset, message, ..
        }) => {
            assert_eq!(offset, 152, "{message}");
            assert!(message.contains("part 0"), "{message}");
        }
        other => panic!("expected MalformedBinary, got {other:?}"),
    }
}

/// Record sizes are checked too: a polygon record that declares more content than the file
/// has is rejected before any allocation. A minimal file: the 100-byte header (file code 9994,
/// file length in 16-bit words, version 1000, shape type 5) and one record header that claims
/// 2³⁰ words of content.
#[test]
fn shapefile_record_longer_than_the_file_is_an_error() {
    let mut b = vec![0u8; 108];
    b[0..4].copy_from_slice(&9994i32.to_be_bytes());
    b[24..28].copy_from_slice(&54i32.to_be_bytes()); // 108 bytes = 54 words
    b[28..32].copy_from_slice(&1000i32.to_le_bytes());
    b[32..36].copy_from_slice(&5i32.to_le_bytes());
    b[100..104].copy_from_slice(&1i32.to_be_bytes()); // record number 1
    b[104..108].copy_from_slice(&(1i32 << 30).to_be_bytes()); // content length in words
    match parse_shapefile_parts(&b) {
        Err(IoError::MalformedBinary { offset, .. }) => assert_eq!(offset, 104),
        other => panic!("expected MalformedBinary, got {other:?}"),
    }
}

/// `shapefile` target, 10-minute run: the record at byte 100 declares 0 bytes of content, but
/// the `shapefile` crate reads the shape type and the polygon's fixed fields regardless and
/// reserved 4 GB for a garbage part count. A record too short for its shape type's fixed fields
/// (44 bytes for a polygon) is now `MalformedBinary` at the record's length field (byte 104).
#[test]
fn shapefile_record_too_short_for_its_shape_is_an_error() {
    let bytes = include_bytes!("data/fuzz/shapefile-zero-length-record.shp");
    match parse_shapefile_parts(bytes) {
        Err(IoError::MalformedBinary {
            offset, message, ..
        }) => {
            assert_eq!(offset, 104, "{message}");
            assert!(message.contains("too short"), "{message}");
        }
        other => panic!("expected MalformedBinary, got {other:?}"),
    }
}

/// `shapefile` target, second 10-minute run: the header declares 324 bytes; the first record
/// ends at byte 320, and the `shapefile` crate reads a second record starting there (its start
/// is below the declared length) whose header extends beyond it. The pre-check stopped where
/// a whole record header no longer fitted in the declared length, so it never saw that
/// record, whose garbage part count made the crate reserve 4 GB. The pre-check now walks
/// exactly the records the crate reads; the second record's content length (bytes 324..328)
/// runs past the end of the 512-byte file.
#[test]
fn shapefile_record_starting_below_the_declared_length_is_checked() {
    let bytes = include_bytes!("data/fuzz/shapefile-record-across-declared-length.shp");
    match parse_shapefile_parts(bytes) {
        Err(IoError::MalformedBinary {
            offset, message, ..
        }) => {
            assert!(offset >= 320, "offset {offset}: {message}");
        }
        other => panic!("expected MalformedBinary, got {other:?}"),
    }
}

/// `shapefile` target, third 10-minute run: a null-shape record (type 0) declaring 128 bytes
/// of content. The `shapefile` crate reads records sequentially without skipping to the
/// declared end, so it took the padding for the next record and reserved 4 GB for a garbage
/// multipoint count. A null shape must now have exactly its 4-byte type as content
/// (`MalformedBinary` at the record's length field, byte 104).
#[test]
fn shapefile_padded_null_shape_is_an_error() {
    let bytes = include_bytes!("data/fuzz/shapefile-padded-null-shape.shp");
    match parse_shapefile_parts(bytes) {
        Err(IoError::MalformedBinary {
            offset, message, ..
        }) => assert_eq!(offset, 104, "{message}"),
        other => panic!("expected MalformedBinary, got {other:?}"),
    }
}

/// `shapefile` target, fourth 10-minute run (out of memory inside the `shapefile` crate, input
/// `fuzz/artifacts/shapefile/oom-8bb556…`, 324 bytes): the header declares 0x0500_0000 words;
/// the polygon record at byte 100 declares 212 bytes of content but has 0 parts and 10 points,
/// i.e. 44 + 16·10 = 204 bytes of data and 8 bytes of padding. The crate read on from the end
/// of the data (not from the declared end of the record), took the padding and the next bytes
/// for a record header and reserved gigabytes. Our own parser (the `shapefile` crate is no
/// longer used) moves by the declared length to byte 100 + 8 + 212 = 320, where
/// the next record header (8 bytes) does not fit in the 324-byte file.
#[test]
fn shapefile_record_padding_is_skipped_by_declared_length() {
    let bytes = include_bytes!("data/fuzz/shapefile-oom-fourth-run.shp");
    match parse_shapefile_parts(bytes) {
        Err(IoError::MalformedBinary {
            offset, message, ..
        }) => {
            assert_eq!(offset, 320, "{message}");
            assert!(message.contains("end of the file"), "{message}");
        }
        other => panic!("expected MalformedBinary, got {other:?}"),
    }
}
