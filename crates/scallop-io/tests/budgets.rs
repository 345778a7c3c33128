//! Issue 21: 3MF files that would exhaust memory are refused before the work, with the
//! estimate and the cap, and zip damage is described in words.

#![allow(clippy::unwrap_used, reason = "tests fail loudly by design")]

mod common;

use common::*;
use scallop_io::{MeshFormat, MeshReadError, Units, read_mesh};

/// `levels` objects each placing the one below `copies` times, over the tetrahedron.
fn instancing(levels: u32, copies: u32) -> Vec<u8> {
    scallop_fuzz::threemf_instancing_of(&TETRA_VERTICES, &TETRA_TRIANGLES, levels, copies)
}

#[test]
fn instancing_is_counted_before_it_is_placed() {
    // 4 * 4^11 = 16.8 million triangles from a file of a few kB: refused with the count.
    let e = read_mesh(&instancing(11, 4), MeshFormat::ThreeMf, Units::Millimetres).unwrap_err();
    assert!(e.to_string().contains("16777216 triangles"), "{e}");
    assert!(e.to_string().contains("8388608"), "{e}");
    // 4 * 4^4 = 1024 triangles: placed.
    let m = read_mesh(&instancing(4, 4), MeshFormat::ThreeMf, Units::Millimetres).unwrap();
    assert_eq!(m.diagnostics.input_triangles, 1024);
}

/// Sets the uncompressed size that the zip declares for `entry` (central directory and
/// local header) to `size`, as a zip bomb or a damaged archive would.
fn declare_size(zip: &mut [u8], entry: &str, size: u32) {
    let name = entry.as_bytes();
    for at in 0..zip.len().saturating_sub(46 + name.len()) {
        let central = zip[at..at + 4] == *b"PK\x01\x02" && zip[at + 46..at + 46 + name.len()] == *name;
        let local = zip[at..at + 4] == *b"PK\x03\x04" && zip[at + 30..at + 30 + name.len()] == *name;
        if central {
            zip[at + 24..at + 28].copy_from_slice(&size.to_le_bytes());
        }
        if local {
            zip[at + 22..at + 26].copy_from_slice(&size.to_le_bytes());
        }
    }
}

#[test]
fn a_part_declaring_more_than_the_cap_is_not_read() {
    let mut zip = threemf_tetra(None);
    declare_size(&mut zip, "3D/3dmodel.model", 0xFFFF_FFF0);
    let e = read_mesh(&zip, MeshFormat::ThreeMf, Units::Millimetres).unwrap_err();
    assert!(matches!(e, MeshReadError::ZipEntry { .. }), "{e}");
    assert!(e.to_string().contains("4294967280 bytes"), "{e}");
}

#[test]
fn zip_damage_is_described_in_words() {
    let whole = threemf_tetra(None);
    for cut in [10, whole.len() / 2, whole.len() - 5] {
        let e = read_mesh(&whole[..cut], MeshFormat::ThreeMf, Units::Millimetres).unwrap_err();
        let text = e.to_string();
        assert!(!text.contains("::"), "internal names in: {text}");
        assert!(text.contains("zip"), "{text}");
    }
}
