//! GLB structure: header, chunk lengths, 4-byte alignment, JSON, accessors.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use scallop_geom::{Aabb3, Point3};
use scallop_mesh::TriMesh;
use scallop_report::{ReportData, glb::scene_glb};
use scallop_toolpath::{Move, MoveKind, Toolpath};
use serde_json::Value;

fn u32_at(b: &[u8], at: usize) -> usize {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap()) as usize
}

fn scene() -> ReportData {
    let p = |x, y, z| Point3::new(x, y, z);
    let (mesh, _) = TriMesh::from_soup(&[
        [p(0., 0., 0.), p(10., 0., 1.), p(0., 8., 2.)],
        [p(10., 0., 1.), p(10., 8., 3.), p(0., 8., 2.)],
    ])
    .unwrap();
    let mut path = Toolpath::new(1000.0);
    for (k, (x, y, z)) in [(0., 0., 10.), (0., 0., 3.), (10., 0., 3.), (10., 1., 3.5), (0., 1., 3.), (0., 1., 10.)]
        .into_iter()
        .enumerate()
    {
        let kind =
            [MoveKind::Rapid, MoveKind::Plunge, MoveKind::Feed, MoveKind::Link, MoveKind::Feed, MoveKind::Retract][k];
        path.push(Move::new(kind, p(x, y, z)));
    }
    let mut data = ReportData::new("glb test");
    data.part = Some(mesh);
    data.stock = Some(Aabb3 { min: p(-1., -1., -1.), max: p(11., 9., 4.) });
    data.toolpath = Some(path);
    data
}

/// Parses the GLB and returns the JSON and the binary chunk.
fn parse(glb: &[u8]) -> (Value, Vec<u8>) {
    assert_eq!(&glb[..4], b"glTF");
    assert_eq!(u32_at(glb, 4), 2, "version");
    assert_eq!(u32_at(glb, 8), glb.len(), "total length");
    let json_len = u32_at(glb, 12);
    assert_eq!(&glb[16..20], b"JSON");
    assert_eq!(json_len % 4, 0, "JSON chunk padded to 4 bytes");
    let json: Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    let at = 20 + json_len;
    if at == glb.len() {
        return (json, Vec::new());
    }
    let bin_len = u32_at(glb, at);
    assert_eq!(&glb[at + 4..at + 8], b"BIN\0");
    assert_eq!(bin_len % 4, 0, "BIN chunk padded to 4 bytes");
    assert_eq!(at + 8 + bin_len, glb.len(), "chunks fill the file");
    (json, glb[at + 8..].to_vec())
}

#[test]
fn structure_accessors_and_bounds_are_valid() {
    let data = scene();
    let glb = scene_glb(&data).unwrap();
    let (json, bin) = parse(&glb);
    assert_eq!(json["asset"]["version"], "2.0");
    assert_eq!(json["buffers"][0]["byteLength"].as_u64().unwrap() as usize, bin.len());
    let views = json["bufferViews"].as_array().unwrap();
    for v in views {
        let (off, len) = (v["byteOffset"].as_u64().unwrap() as usize, v["byteLength"].as_u64().unwrap() as usize);
        assert_eq!(off % 4, 0, "view offsets aligned");
        assert!(off + len <= bin.len());
    }
    let accessors = json["accessors"].as_array().unwrap();
    for a in accessors {
        let view = &views[a["bufferView"].as_u64().unwrap() as usize];
        let comps = match a["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC3" => 3,
            "VEC4" => 4,
            t => panic!("type {t}"),
        };
        let count = a["count"].as_u64().unwrap() as usize;
        assert_eq!(view["byteLength"].as_u64().unwrap() as usize, 4 * comps * count, "{a}");
    }
    let meshes = json["meshes"].as_array().unwrap();
    let names: Vec<&str> = meshes.iter().map(|m| m["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["part", "stock", "toolpath"]);
    // POSITION accessors carry min/max equal to the data they describe.
    for m in meshes {
        let prim = &m["primitives"][0];
        let a = &accessors[prim["attributes"]["POSITION"].as_u64().unwrap() as usize];
        let view = &views[a["bufferView"].as_u64().unwrap() as usize];
        let off = view["byteOffset"].as_u64().unwrap() as usize;
        let floats: Vec<f32> = bin[off..off + view["byteLength"].as_u64().unwrap() as usize]
            .chunks(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        for c in 0..3 {
            let lo = floats.iter().skip(c).step_by(3).copied().fold(f32::INFINITY, f32::min);
            let hi = floats.iter().skip(c).step_by(3).copied().fold(f32::NEG_INFINITY, f32::max);
            assert_eq!((a["min"][c].as_f64().unwrap() as f32).to_bits(), lo.to_bits());
            assert_eq!((a["max"][c].as_f64().unwrap() as f32).to_bits(), hi.to_bits());
        }
        // Indices in range of the vertices.
        if let Some(ix) = prim["indices"].as_u64() {
            let ia = &accessors[ix as usize];
            let iv = &views[ia["bufferView"].as_u64().unwrap() as usize];
            let io = iv["byteOffset"].as_u64().unwrap() as usize;
            let n = a["count"].as_u64().unwrap() as u32;
            for c in bin[io..io + iv["byteLength"].as_u64().unwrap() as usize].chunks(4) {
                assert!(u32::from_le_bytes(c.try_into().unwrap()) < n);
            }
        }
    }
    // The toolpath is one line strip with a colour per vertex.
    let tp = &meshes[2]["primitives"][0];
    assert_eq!(tp["mode"], 3);
    let colours = &accessors[tp["attributes"]["COLOR_0"].as_u64().unwrap() as usize];
    assert_eq!(colours["count"].as_u64().unwrap() as usize, data.toolpath.as_ref().unwrap().moves().len());
    // Normals are unit vectors.
    let na = &accessors[meshes[0]["primitives"][0]["attributes"]["NORMAL"].as_u64().unwrap() as usize];
    let nv = &views[na["bufferView"].as_u64().unwrap() as usize];
    let no = nv["byteOffset"].as_u64().unwrap() as usize;
    for n in bin[no..no + nv["byteLength"].as_u64().unwrap() as usize].chunks(12) {
        let v: Vec<f32> = n.chunks(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-5, "{v:?}");
    }
    // Deterministic.
    assert_eq!(glb, scene_glb(&data).unwrap());
}

#[test]
fn an_empty_scene_is_a_valid_glb_without_buffers() {
    let glb = scene_glb(&ReportData::new("empty")).unwrap();
    let (json, bin) = parse(&glb);
    assert!(bin.is_empty());
    assert!(json.get("buffers").is_none());
    assert_eq!(json["scenes"][0]["nodes"][0], 0);
}
