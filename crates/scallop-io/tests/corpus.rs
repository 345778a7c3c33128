//! The bad-file corpus (`tests/corpus/`, written by `tests/corpus/generate.py`):
//! each file must give an `Err` whose message names the expected place.

#![allow(clippy::unwrap_used, reason = "tests fail loudly by design")]

use std::path::Path;

use scallop_io::{MeshFormat, Units, read_mesh};

/// File, then texts its error message must contain (the place first).
const CASES: &[(&str, &[&str])] = &[
    // STL
    ("stl_empty.stl", &["STL: the file is empty (0 bytes)"]),
    ("stl_binary_truncated.stl", &["byte 80", "count is 4, which needs 284 bytes, but the file has 201 bytes"]),
    ("stl_binary_count_too_small.stl", &["byte 80", "count is 3, which needs 234 bytes, but the file has 284 bytes"]),
    ("stl_binary_huge_count.stl", &["byte 80", "count is 4294967295, which needs 214748364834 bytes"]),
    ("stl_binary_no_triangles.stl", &["STL byte 80: the file holds no triangles"]),
    ("stl_binary_short_header.stl", &["STL byte 40: the file ends inside the 84-byte binary STL header"]),
    ("stl_binary_nan.stl", &["STL triangle 2, vertex 1 (byte 212): coordinate NaN is not a finite number"]),
    ("stl_ascii_nan.stl", &["STL line 6: coordinate NaN is not a finite number"]),
    ("stl_ascii_inf.stl", &["STL line 5: coordinate -inf is not a finite number"]),
    ("stl_ascii_missing_vertex.stl", &["STL line 6: this facet has only 2 vertices"]),
    ("stl_ascii_two_coordinates.stl", &["STL line 5: 'vertex' has 2 coordinates; each vertex needs x y z"]),
    ("stl_ascii_bad_number.stl", &["STL line 5: the y coordinate '8,0' is not a number"]),
    ("stl_ascii_not_utf8.stl", &["STL line 7, byte 135: byte 0xF6 is not UTF-8 text"]),
    ("stl_ascii_empty_solid.stl", &["STL line 2: the file holds no triangles"]),
    ("stl_ascii_truncated.stl", &["STL line 16: the file ends where", "the file is truncated"]),
    ("stl_ascii_no_solid.stl", &["STL line 1: expected 'solid' at the start of an ASCII STL, found 'facet'"]),
    ("stl_ascii_all_degenerate.stl", &["STL: all 2 triangles are degenerate"]),
    // OBJ
    ("obj_index_zero.obj", &["OBJ line 6: vertex index 0 is out of range: 4 vertices are available"]),
    ("obj_index_out_of_range.obj", &["OBJ line 6: vertex index 5 is out of range"]),
    ("obj_negative_out_of_range.obj", &["OBJ line 6: vertex index -5 is out of range"]),
    ("obj_nan.obj", &["OBJ line 2: coordinate NaN is not a finite number"]),
    ("obj_not_utf8.obj", &["OBJ line 4, byte 50: byte 0xFF is not UTF-8 text"]),
    ("obj_no_faces.obj", &["OBJ line 5: the file holds no triangles"]),
    ("obj_bad_corner.obj", &["OBJ line 6: face corner 'two' is not a vertex index"]),
    ("obj_two_corners.obj", &["OBJ line 5: this face has 2 corners; a face needs at least 3"]),
    ("obj_binary_garbage.obj", &["OBJ line 1, byte 0: byte 0x00 is not UTF-8 text"]),
    // PLY
    ("ply_too_few_vertex_lines.ply", &["PLY line 13: vertex 3 of 4 has more values than its properties take"]),
    ("ply_too_few_face_lines.ply", &["PLY line 16: the file ends before face 3 of 4"]),
    ("ply_unknown_format.ply", &["PLY line 2: unknown format 'binary_pdp_endian'"]),
    ("ply_bad_index.ply", &["PLY line 17: vertex index 4 is out of range: 4 vertices are available"]),
    ("ply_nan.ply", &["PLY line 12: coordinate NaN is not a finite number"]),
    ("ply_not_utf8_header.ply", &["PLY line 5, byte 66: byte 0xF6 is not UTF-8 text"]),
    ("ply_no_face_element.ply", &["PLY line 7: the header declares no 'face' element"]),
    ("ply_unknown_type.ply", &["PLY line 6: unknown property type 'float128'"]),
    ("ply_not_ply.ply", &["PLY line 1: the file does not start with a 'ply' line"]),
    ("ply_binary_truncated.ply", &["PLY byte 264: the file ends inside face 3 of 4"]),
    ("ply_binary_trailing_bytes.ply", &["PLY byte 269: 4 bytes follow the last element"]),
    ("ply_binary_bad_index.ply", &["PLY byte 265: vertex index -7 is out of range"]),
    // 3MF
    ("3mf_not_zip.3mf", &["3MF: not a readable zip archive"]),
    ("3mf_truncated_zip.3mf", &["3MF: not a readable zip archive"]),
    ("3mf_without_model.3mf", &["3MF: the zip has no model part '3D/3dmodel.model' (it has 2 entries)"]),
    ("3mf_bad_index.3mf", &["3MF 3D/3dmodel.model line 16, <triangle>: vertex index 9 is out of range: 4 vertices"]),
    ("3mf_nan_vertex.3mf", &["3MF 3D/3dmodel.model line 9, <vertex>: coordinate NaN is not a finite number"]),
    ("3mf_missing_attribute.3mf", &["3MF 3D/3dmodel.model line 7, <vertex>: the 'z' attribute is missing"]),
    ("3mf_malformed_xml.3mf", &["3MF 3D/3dmodel.model line 18", "malformed XML"]),
    ("3mf_unknown_object.3mf", &["3MF 3D/3dmodel.model line 22, <item>: objectid 7 names no <object>"]),
    (
        "3mf_bad_transform.3mf",
        &["3MF 3D/3dmodel.model line 22, <item>: transform=\"1 0 0 1\" is not 12 finite numbers"],
    ),
    ("3mf_unknown_unit.3mf", &["3MF 3D/3dmodel.model line 2, <model>: unknown unit 'cubit'"]),
    ("3mf_no_build_items.3mf", &["3MF zip entry 3D/3dmodel.model: the <build> has no <item>"]),
    ("3mf_not_utf8.3mf", &["3MF 3D/3dmodel.model line 21: byte 0xF6 is not UTF-8 text"]),
];

fn corpus_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("corpus")
}

#[test]
fn every_bad_file_gives_an_error_naming_its_place() {
    let mut failures = Vec::new();
    for (name, wanted) in CASES {
        let bytes = std::fs::read(corpus_dir().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let format = MeshFormat::from_extension(name).unwrap();
        match read_mesh(&bytes, format, Units::Millimetres) {
            Ok(m) => failures.push(format!("{name}: read {} triangles, expected an error", m.mesh.triangles().len())),
            Err(e) => {
                let message = e.to_string();
                if let Some(missing) = wanted.iter().find(|w| !message.contains(*w)) {
                    failures.push(format!("{name}: {message}\n    (wanted: {missing})"));
                }
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn every_corpus_file_has_a_case() {
    let listed: Vec<&str> = CASES.iter().map(|(name, _)| *name).collect();
    for entry in std::fs::read_dir(corpus_dir()).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if name != "generate.py" {
            assert!(listed.contains(&name.as_str()), "{name} is in the corpus but not in CASES");
        }
    }
}
