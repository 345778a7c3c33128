//! glTF 2.0 binary (GLB) export of the part (triangles with smooth normals),
//! the stock (a translucent box) and the toolpath (a line strip, coloured per
//! vertex by move kind), for Blender or any glTF viewer.
//!
//! glTF is Y-up in metres, scallop Z-up in millimetres: the root node scales
//! by [`tol::GLB_SCALE`] and turns Z up into Y up; the accessors keep the
//! part-frame millimetres (as f32, relative to nothing: bounds stay readable).
//!
//! Layout: 12-byte header, a JSON chunk (padded with spaces), a BIN chunk
//! (padded with zeros); every buffer view starts on a 4-byte boundary.

use scallop_geom::{Point3, Vec3};
use serde_json::{Value, json};

use crate::{KIND_COLOURS, ReportData, ReportError, kind_index, tol};

/// glTF component type of f32.
const FLOAT: u32 = 5126;
/// glTF component type of u32.
const UNSIGNED_INT: u32 = 5125;
/// Buffer view target of vertex attributes.
const ARRAY_BUFFER: u32 = 34962;
/// Buffer view target of indices.
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    /// Appends a buffer view of f32 vectors (`width` components) and its accessor; returns the accessor index.
    fn floats(&mut self, values: &[f32], width: usize, with_bounds: bool) -> usize {
        let count = values.len() / width;
        let kind = match width {
            1 => "SCALAR",
            2 => "VEC2",
            3 => "VEC3",
            _ => "VEC4",
        };
        let mut accessor = json!({
            "bufferView": self.view(values.iter().flat_map(|v| v.to_le_bytes()).collect(), ARRAY_BUFFER),
            "componentType": FLOAT, "count": count, "type": kind,
        });
        if with_bounds && count > 0 {
            let mut lo = vec![f32::INFINITY; width];
            let mut hi = vec![f32::NEG_INFINITY; width];
            for v in values.chunks(width) {
                for c in 0..width {
                    lo[c] = lo[c].min(v[c]);
                    hi[c] = hi[c].max(v[c]);
                }
            }
            accessor["min"] = json!(lo);
            accessor["max"] = json!(hi);
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn indices(&mut self, values: &[u32]) -> usize {
        let view = self.view(values.iter().flat_map(|v| v.to_le_bytes()).collect(), ELEMENT_ARRAY_BUFFER);
        self.accessors.push(json!({
            "bufferView": view, "componentType": UNSIGNED_INT, "count": values.len(), "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }

    fn view(&mut self, bytes: Vec<u8>, target: u32) -> usize {
        let offset = self.bin.len();
        self.bin.extend_from_slice(&bytes);
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len(), "target": target}));
        self.views.len() - 1
    }
}

#[allow(clippy::cast_possible_truncation, reason = "f32 is the precision of glTF vertices")]
fn f32s(p: &Point3) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

/// The scene as a GLB file.
///
/// # Errors
/// [`ReportError::TooLarge`] when the binary chunk would exceed 4 GiB.
pub fn scene_glb(data: &ReportData) -> Result<Vec<u8>, ReportError> {
    let mut b = Builder { bin: Vec::new(), views: Vec::new(), accessors: Vec::new() };
    let mut meshes = Vec::new();
    let scale = [tol::GLB_SCALE; 3];
    let mut nodes = vec![json!({
        "name": "scallop (mm, Z up)",
        "scale": scale,
        // -90 degrees about X: Z up becomes Y up.
        "rotation": [-std::f64::consts::FRAC_1_SQRT_2, 0.0, 0.0, std::f64::consts::FRAC_1_SQRT_2],
        "children": [],
    })];
    let materials = json!([
        {"name": "part", "pbrMetallicRoughness": {"baseColorFactor": [0.67, 0.73, 0.8, 1.0], "metallicFactor": 0.3, "roughnessFactor": 0.6}, "doubleSided": true},
        {"name": "stock", "pbrMetallicRoughness": {"baseColorFactor": [0.85, 0.6, 0.3, 0.2], "metallicFactor": 0.0, "roughnessFactor": 0.9}, "alphaMode": "BLEND", "doubleSided": true},
        {"name": "toolpath", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}},
    ]);
    if let Some(mesh) = &data.part {
        let positions: Vec<f32> = mesh.vertices().iter().flat_map(f32s).collect();
        let mut normals = vec![Vec3::zeros(); mesh.vertices().len()];
        for tri in mesh.triangles() {
            let v = tri.map(|i| mesh.vertices()[i as usize]);
            // Area-weighted: the cross product's length is twice the area.
            let n = (v[1] - v[0]).cross(&(v[2] - v[0]));
            for &i in tri {
                normals[i as usize] += n;
            }
        }
        #[allow(clippy::cast_possible_truncation, reason = "f32 normals")]
        let normals: Vec<f32> = normals
            .iter()
            .flat_map(|n| {
                let u = n.try_normalize(0.0).unwrap_or_else(Vec3::z);
                [u.x as f32, u.y as f32, u.z as f32]
            })
            .collect();
        let indices: Vec<u32> = mesh.triangles().iter().flatten().copied().collect();
        let (p, n, i) = (b.floats(&positions, 3, true), b.floats(&normals, 3, false), b.indices(&indices));
        meshes.push(json!({"name": "part", "primitives": [{"attributes": {"POSITION": p, "NORMAL": n}, "indices": i, "material": 0, "mode": 4}]}));
    }
    if let Some(s) = &data.stock {
        let (lo, hi) = (s.min, s.max);
        let mut positions = Vec::new();
        let mut normals = Vec::new();
        let mut indices = Vec::new();
        // Six faces, four corners each, flat normals; counter-clockwise seen from outside.
        for (axis, sign) in [(0usize, -1.0f64), (0, 1.0), (1, -1.0), (1, 1.0), (2, -1.0), (2, 1.0)] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = u32::try_from(positions.len() / 3).unwrap_or(0);
            let corners = if sign > 0.0 { [(0, 0), (1, 0), (1, 1), (0, 1)] } else { [(0, 0), (0, 1), (1, 1), (1, 0)] };
            for (cu, cv) in corners {
                let mut p = [0.0f64; 3];
                p[axis] = if sign > 0.0 { hi[axis] } else { lo[axis] };
                p[u] = if cu == 0 { lo[u] } else { hi[u] };
                p[v] = if cv == 0 { lo[v] } else { hi[v] };
                positions.extend(f32s(&Point3::new(p[0], p[1], p[2])));
                let mut n = [0.0f32; 3];
                n[axis] = if sign > 0.0 { 1.0 } else { -1.0 };
                normals.extend(n);
            }
            indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        }
        let (p, n, i) = (b.floats(&positions, 3, true), b.floats(&normals, 3, false), b.indices(&indices));
        meshes.push(json!({"name": "stock", "primitives": [{"attributes": {"POSITION": p, "NORMAL": n}, "indices": i, "material": 1, "mode": 4}]}));
    }
    if let Some(path) = data.toolpath.as_ref().filter(|t| t.moves().len() >= 2) {
        let positions: Vec<f32> = path.moves().iter().flat_map(|m| f32s(&m.to)).collect();
        let colours: Vec<f32> = path
            .moves()
            .iter()
            .flat_map(|m| {
                let c = KIND_COLOURS[usize::from(kind_index(m.kind))];
                [srgb_to_linear(c[0]), srgb_to_linear(c[1]), srgb_to_linear(c[2]), 1.0]
            })
            .collect();
        let (p, c) = (b.floats(&positions, 3, true), b.floats(&colours, 4, false));
        meshes.push(json!({"name": "toolpath", "primitives": [{"attributes": {"POSITION": p, "COLOR_0": c}, "material": 2, "mode": 3}]}));
    }
    for (k, m) in meshes.iter().enumerate() {
        nodes.push(json!({"name": m["name"], "mesh": k}));
        if let Some(children) = nodes[0]["children"].as_array_mut() {
            children.push(json!(k + 1));
        }
    }
    let bin_len = b.bin.len();
    let mut gltf = json!({
        "asset": {"version": "2.0", "generator": "scallop-report"},
        "scene": 0,
        "scenes": [{"name": data.title, "nodes": [0]}],
        "nodes": nodes,
        "materials": materials,
        "meshes": meshes,
        "accessors": b.accessors,
        "bufferViews": b.views,
    });
    if bin_len > 0 {
        gltf["buffers"] = json!([{"byteLength": bin_len}]);
    } else {
        // No geometry: no buffer, no views.
        for key in ["bufferViews", "accessors", "meshes"] {
            if let Some(o) = gltf.as_object_mut() {
                o.remove(key);
            }
        }
    }
    let mut text = gltf.to_string().into_bytes();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let total = 12 + 8 + text.len() + if bin_len > 0 { 8 + b.bin.len() } else { 0 };
    let total32 = u32::try_from(total).map_err(|_| ReportError::TooLarge { bytes: total as u64 })?;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&total32.to_le_bytes());
    out.extend_from_slice(&u32::try_from(text.len()).unwrap_or(u32::MAX).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    if bin_len > 0 {
        out.extend_from_slice(&u32::try_from(b.bin.len()).unwrap_or(u32::MAX).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&b.bin);
    }
    Ok(out)
}

/// glTF vertex colours are linear; our palette is sRGB.
#[allow(clippy::cast_possible_truncation, reason = "f32 colours")]
fn srgb_to_linear(c: u8) -> f32 {
    let s = f64::from(c) / 255.0;
    (if s <= 0.04045 { s / 12.92 } else { ((s + 0.055) / 1.055).powf(2.4) }) as f32
}
