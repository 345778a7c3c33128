//! Writers for small test meshes in every format (test-only; the crate reads, never writes);
//! the ASCII STL and 3MF object writers are the fuzzer's seed writers.

#![allow(dead_code, unused_imports, reason = "each test file uses a different subset")]

use std::io::{Cursor, Write};

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

/// Corners exact in f32 and in short decimals, so every format stores them exactly.
pub const TETRA_VERTICES: [[f64; 3]; 4] = [[1.5, -2.0, 0.25], [11.5, -2.0, 0.25], [1.5, 8.0, 0.25], [1.5, -2.0, 10.25]];
/// Outward winding (positive signed volume).
pub const TETRA_TRIANGLES: [[usize; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];

/// Surface area of the tetrahedron: three right triangles with legs 10 and the slanted face.
pub fn tetra_area() -> f64 {
    3.0 * 50.0 + 3.0_f64.sqrt() / 4.0 * 200.0
}

pub use scallop_fuzz::{stl_ascii, threemf_object};

pub fn stl_binary(v: &[[f64; 3]], t: &[[usize; 3]], header: &[u8]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b[..header.len()].copy_from_slice(header);
    b.extend_from_slice(&u32::try_from(t.len()).unwrap_or(u32::MAX).to_le_bytes());
    for tri in t {
        b.extend_from_slice(&[0; 12]);
        for &i in tri {
            for c in v[i] {
                #[allow(clippy::cast_possible_truncation, reason = "test coordinates are exact in f32")]
                b.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0; 2]);
    }
    b
}

/// OBJ with a mix of index forms: positive, `v/vt/vn`, `v//vn` and negative.
pub fn obj(v: &[[f64; 3]], t: &[[usize; 3]]) -> Vec<u8> {
    let mut s = String::from("# test\nmtllib none.mtl\no tetra\n");
    for p in v {
        s.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    }
    s.push_str("vt 0 0\nvn 0 0 1\ns off\n");
    let n = v.len() as i64;
    for (k, tri) in t.iter().enumerate() {
        let corner = |i: usize| -> String {
            let one = i as i64 + 1;
            match k % 4 {
                0 => format!("{one}"),
                1 => format!("{one}/1/1"),
                2 => format!("{one}//1"),
                _ => format!("{}", one - n - 1),
            }
        };
        s.push_str(&format!("f {} {} {}\n", corner(tri[0]), corner(tri[1]), corner(tri[2])));
    }
    s.into_bytes()
}

pub fn ply_ascii(v: &[[f64; 3]], t: &[[usize; 3]]) -> Vec<u8> {
    let mut s = format!(
        "ply\nformat ascii 1.0\ncomment test\nelement vertex {}\nproperty float x\nproperty float y\n\
         property float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        v.len(),
        t.len()
    );
    for p in v {
        s.push_str(&format!("{} {} {}\n", p[0], p[1], p[2]));
    }
    for tri in t {
        s.push_str(&format!("3 {} {} {}\n", tri[0], tri[1], tri[2]));
    }
    s.into_bytes()
}

/// Binary PLY with doubles for x, a float y, an extra uchar, float z, and
/// `ushort`-counted `uint` indices, then an extra element to skip.
pub fn ply_binary(v: &[[f64; 3]], t: &[[usize; 3]], big_endian: bool) -> Vec<u8> {
    let name = if big_endian { "binary_big_endian" } else { "binary_little_endian" };
    let mut b = format!(
        "ply\nformat {name} 1.0\nelement vertex {}\nproperty double x\nproperty float y\nproperty uchar flag\n\
         property float z\nelement face {}\nproperty list ushort uint vertex_indices\nelement extra 1\n\
         property list uchar short values\nend_header\n",
        v.len(),
        t.len()
    )
    .into_bytes();
    let put = |b: &mut Vec<u8>, mut le: Vec<u8>| {
        if big_endian {
            le.reverse();
        }
        b.extend_from_slice(&le);
    };
    for p in v {
        put(&mut b, p[0].to_le_bytes().to_vec());
        #[allow(clippy::cast_possible_truncation, reason = "test coordinates are exact in f32")]
        put(&mut b, (p[1] as f32).to_le_bytes().to_vec());
        b.push(7);
        #[allow(clippy::cast_possible_truncation, reason = "test coordinates are exact in f32")]
        put(&mut b, (p[2] as f32).to_le_bytes().to_vec());
    }
    for tri in t {
        put(&mut b, 3u16.to_le_bytes().to_vec());
        for &i in tri {
            put(&mut b, u32::try_from(i).unwrap_or(u32::MAX).to_le_bytes().to_vec());
        }
    }
    b.push(2);
    put(&mut b, (-1i16).to_le_bytes().to_vec());
    put(&mut b, 5i16.to_le_bytes().to_vec());
    b
}

/// A 3MF model document: `unit` attribute (or none), resources, and build items.
pub fn threemf_model(unit: Option<&str>, resources: &str, build: &str) -> String {
    let unit = unit.map_or(String::new(), |u| format!(" unit=\"{u}\""));
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model{unit} xml:lang=\"en-US\" \
         xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n <metadata name=\"Title\">t &amp; \
         t</metadata>\n <resources>\n{resources} </resources>\n <build>\n{build} </build>\n</model>\n"
    )
}

pub const CONTENT_TYPES: &str = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Types \
     xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\"><Default Extension=\"rels\" \
     ContentType=\"application/vnd.openxmlformats-package.relationships+xml\"/><Default Extension=\"model\" \
     ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\"/></Types>\n";

pub fn rels(target: &str) -> String {
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Relationships \
         xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\"><Relationship Target=\"{target}\" \
         Id=\"rel0\" Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/></Relationships>\n"
    )
}

/// A zip of `(name, content)` entries, deflated or stored.
pub fn zip(entries: &[(&str, &str)], deflate: bool) -> Vec<u8> {
    let method = if deflate { CompressionMethod::Deflated } else { CompressionMethod::Stored };
    let options = SimpleFileOptions::default().compression_method(method);
    let mut writer = ZipWriter::new(Cursor::new(Vec::new()));
    for (name, content) in entries {
        writer.start_file(*name, options).expect("zip entry");
        writer.write_all(content.as_bytes()).expect("zip write");
    }
    writer.finish().expect("zip finish").into_inner()
}

/// A standard 3MF package holding `model` at `3D/3dmodel.model`.
pub fn threemf(model: &str) -> Vec<u8> {
    zip(
        &[
            ("[Content_Types].xml", CONTENT_TYPES),
            ("_rels/.rels", &rels("/3D/3dmodel.model")),
            ("3D/3dmodel.model", model),
        ],
        true,
    )
}

/// The tetrahedron as a one-object 3MF.
pub fn threemf_tetra(unit: Option<&str>) -> Vec<u8> {
    let object = threemf_object(1, &TETRA_VERTICES, &TETRA_TRIANGLES);
    threemf(&threemf_model(unit, &object, "  <item objectid=\"1\" />\n"))
}
