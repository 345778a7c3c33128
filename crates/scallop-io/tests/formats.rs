//! Every format reads the same tetrahedron into the same mesh; units and 3MF
//! build transforms are applied.

#![allow(clippy::unwrap_used, reason = "tests fail loudly by design")]

mod common;

use common::*;
use scallop_geom::Point3;
use scallop_io::{LoadedMesh, MeshFormat, MeshReadError, Units, read_mesh};

fn all_tetrahedra() -> Vec<(&'static str, MeshFormat, Vec<u8>)> {
    let (v, t) = (&TETRA_VERTICES[..], &TETRA_TRIANGLES[..]);
    vec![
        ("STL ascii", MeshFormat::Stl, stl_ascii(v, t)),
        ("STL binary", MeshFormat::Stl, stl_binary(v, t, b"binary")),
        ("STL binary with 'solid' header", MeshFormat::Stl, stl_binary(v, t, b"solid tetra")),
        ("OBJ", MeshFormat::Obj, obj(v, t)),
        ("PLY ascii", MeshFormat::Ply, ply_ascii(v, t)),
        ("PLY binary little-endian", MeshFormat::Ply, ply_binary(v, t, false)),
        ("PLY binary big-endian", MeshFormat::Ply, ply_binary(v, t, true)),
        ("3MF", MeshFormat::ThreeMf, threemf_tetra(None)),
    ]
}

fn signed_volume(m: &LoadedMesh) -> f64 {
    m.mesh.soup().iter().map(|[a, b, c]| a.coords.dot(&b.coords.cross(&c.coords)) / 6.0).sum()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0)
}

#[test]
fn the_same_tetrahedron_from_every_format() {
    for (name, format, bytes) in all_tetrahedra() {
        let m = read_mesh(&bytes, format, Units::Millimetres).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.format, format);
        assert_eq!(m.mesh.vertices().len(), 4, "{name}");
        assert_eq!(m.mesh.triangles().len(), 4, "{name}");
        assert!(close(m.mesh.area(), tetra_area()), "{name}: area {}", m.mesh.area());
        assert!(close(signed_volume(&m), 1000.0 / 6.0), "{name}: volume {}", signed_volume(&m));
        assert_eq!(m.mesh.bounds().min, Point3::new(1.5, -2.0, 0.25), "{name}");
        assert_eq!(m.mesh.bounds().max, Point3::new(11.5, 8.0, 10.25), "{name}");
        assert_eq!(m.diagnostics.boundary_edges, 0, "{name}");
        assert_eq!(m.diagnostics.degenerate_dropped, 0, "{name}");
        assert!(close(m.scale, 1.0), "{name}");
        let references = if format == MeshFormat::Stl { 12 } else { 4 };
        assert_eq!(m.diagnostics.input_vertices, references, "{name}");
    }
}

#[test]
fn inches_scale_by_25_4() {
    for (name, format, bytes) in all_tetrahedra() {
        let m = read_mesh(&bytes, format, Units::Inches).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(close(m.mesh.area(), tetra_area() * 25.4 * 25.4), "{name}");
        assert!(close(m.mesh.bounds().max.x, 11.5 * 25.4), "{name}");
        assert!(close(m.scale, 25.4), "{name}");
    }
}

#[test]
fn threemf_units_convert_to_mm() {
    for (unit, mm) in [
        ("micron", 0.001),
        ("millimeter", 1.0),
        ("centimeter", 10.0),
        ("inch", 25.4),
        ("foot", 304.8),
        ("meter", 1000.0),
    ] {
        let m = read_mesh(&threemf_tetra(Some(unit)), MeshFormat::ThreeMf, Units::Millimetres).unwrap();
        assert!(close(m.mesh.bounds().max.z, 10.25 * mm), "{unit}: {:?}", m.mesh.bounds());
        assert!(close(m.scale, mm), "{unit}");
        assert!(m.units_note.contains(unit), "{}", m.units_note);
    }
    let err = read_mesh(&threemf_tetra(Some("furlong")), MeshFormat::ThreeMf, Units::Millimetres).unwrap_err();
    assert!(err.to_string().contains("3D/3dmodel.model line 2, <model>: unknown unit 'furlong'"), "{err}");
}

#[test]
fn threemf_build_items_components_and_mirrors() {
    let tetra = threemf_object(1, &TETRA_VERTICES, &TETRA_TRIANGLES);
    let assembly = "  <object id=\"5\">\n   <components>\n    <component objectid=\"1\" />\n    \
                    <component objectid=\"1\" transform=\"1 0 0 0 1 0 0 0 1 0 0 100\" />\n   </components>\n  </object>\n";
    // Item 1: the tetrahedron moved by +1000 in x. Item 2: the assembly mirrored in x.
    let build = "  <item objectid=\"1\" transform=\"1 0 0 0 1 0 0 0 1 1000 0 0\" />\n  \
                 <item objectid=\"5\" transform=\"-1 0 0 0 1 0 0 0 1 0 0 0\" />\n";
    let model = threemf_model(Some("millimeter"), &format!("{tetra}{assembly}"), build);
    let m = read_mesh(&threemf(&model), MeshFormat::ThreeMf, Units::Millimetres).unwrap();
    assert_eq!(m.mesh.triangles().len(), 12);
    assert_eq!(m.mesh.vertices().len(), 12);
    assert_eq!(m.mesh.bounds().min, Point3::new(-11.5, -2.0, 0.25));
    assert_eq!(m.mesh.bounds().max, Point3::new(1011.5, 8.0, 110.25));
    // Mirrored copies keep outward normals: total volume is three tetrahedra.
    assert!(close(signed_volume(&m), 3.0 * 1000.0 / 6.0), "{}", signed_volume(&m));
    assert_eq!(m.diagnostics.boundary_edges, 0);
}

#[test]
fn threemf_stored_entries_other_root_names_and_production_paths() {
    let object = threemf_object(3, &TETRA_VERTICES, &TETRA_TRIANGLES);
    let part = threemf_model(None, &object, "");
    let root = threemf_model(
        Some("centimeter"),
        "  <object id=\"1\">\n   <components>\n    <component p:path=\"/3D/Objects/tetra.model\" objectid=\"3\" />\n   \
         </components>\n  </object>\n",
        "  <item objectid=\"1\" />\n",
    );
    let bytes = zip(
        &[
            ("[Content_Types].xml", CONTENT_TYPES),
            ("_rels/.rels", &rels("/3D/Main.model")),
            ("3D/Main.model", &root),
            ("3D/Objects/tetra.model", &part),
        ],
        false,
    );
    let m = read_mesh(&bytes, MeshFormat::ThreeMf, Units::Millimetres).unwrap();
    assert_eq!(m.mesh.triangles().len(), 4);
    assert!(close(m.mesh.bounds().max.x, 115.0));
}

#[test]
fn threemf_ignores_extension_elements_with_core_names() {
    // A slice stack has <vertex> elements too; they are not mesh vertices.
    let slices = "  <s:slicestack id=\"9\" xmlns:s=\"http://schemas.microsoft.com/3dmanufacturing/slice/2015/07\">\n   \
                  <s:slice ztop=\"1\"><s:vertices><s:vertex x=\"nan\" y=\"0\" /></s:vertices></s:slice>\n  \
                  </s:slicestack>\n";
    let object = threemf_object(1, &TETRA_VERTICES, &TETRA_TRIANGLES);
    let model = threemf_model(None, &format!("{slices}{object}"), "  <item objectid=\"1\" />\n");
    let m = read_mesh(&threemf(&model), MeshFormat::ThreeMf, Units::Millimetres).unwrap();
    assert_eq!(m.mesh.triangles().len(), 4);
}

#[test]
fn threemf_errors_name_entry_line_and_element() {
    let object = threemf_object(1, &TETRA_VERTICES, &[[0, 1, 2], [0, 1, 4]]);
    let model = threemf_model(None, &object, "  <item objectid=\"1\" />\n");
    let err = read_mesh(&threemf(&model), MeshFormat::ThreeMf, Units::Millimetres).unwrap_err();
    assert!(matches!(err, MeshReadError::BadIndex { index: 4, vertex_count: 4, .. }), "{err}");
    assert!(err.to_string().starts_with("3MF 3D/3dmodel.model line 15, <triangle>: vertex index 4"), "{err}");

    let model = threemf_model(None, "", "  <item objectid=\"1\" />\n");
    let err = read_mesh(&threemf(&model), MeshFormat::ThreeMf, Units::Millimetres).unwrap_err();
    assert!(err.to_string().contains("line 7, <item>: objectid 1 names no <object>"), "{err}");

    let cycle = "  <object id=\"1\"><components><component objectid=\"1\"/></components></object>\n";
    let model = threemf_model(None, cycle, "  <item objectid=\"1\" />\n");
    let err = read_mesh(&threemf(&model), MeshFormat::ThreeMf, Units::Millimetres).unwrap_err();
    assert!(err.to_string().contains("deeper than 32 levels"), "{err}");
}

#[test]
fn format_from_extension() {
    assert_eq!(MeshFormat::from_extension("C:\\parts\\a.b.Obj"), Some(MeshFormat::Obj));
    assert_eq!(MeshFormat::from_extension(".stl"), Some(MeshFormat::Stl));
    assert_eq!(MeshFormat::from_extension("stl.txt"), None);
    assert_eq!(MeshFormat::from_extension(""), None);
}

#[test]
fn a_large_binary_stl_loads() {
    // A 200 x 200 grid of 80,000 triangles: a smoke test of the binary path.
    let n = 200usize;
    let mut v = Vec::new();
    let mut t = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            v.push([i as f64, j as f64, ((i * j) % 7) as f64]);
        }
    }
    let at = |i: usize, j: usize| i * (n + 1) + j;
    for i in 0..n {
        for j in 0..n {
            t.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            t.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    let bytes = stl_binary(&v, &t, b"grid");
    let start = std::time::Instant::now();
    let m = read_mesh(&bytes, MeshFormat::Stl, Units::Millimetres).unwrap();
    let elapsed = start.elapsed();
    assert_eq!(m.mesh.triangles().len(), 2 * n * n);
    assert_eq!(m.mesh.vertices().len(), (n + 1) * (n + 1));
    assert_eq!(m.diagnostics.boundary_edges, 4 * n);
    // Generous: the test profile is optimised; this only catches accidental quadratic work.
    assert!(elapsed.as_secs_f64() < 5.0, "{elapsed:?}");
}
