//! Mesh readers for scallop: STL (ASCII and binary), OBJ, PLY (ASCII and
//! binary) and 3MF, parsed from bytes into a validated [`TriMesh`] in
//! millimetres.
//!
//! ```
//! use scallop_io::{read_mesh, MeshFormat, Units};
//! let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
//! let loaded = read_mesh(obj, MeshFormat::Obj, Units::Inches).unwrap();
//! assert_eq!(loaded.mesh.triangles().len(), 2); // the quad is fan-triangulated
//! assert!((loaded.mesh.area() - 25.4 * 25.4).abs() < 1e-9);
//! ```
//!
//! # Invariants
//! - Never performs I/O and never prints: input is a byte slice, problems are
//!   [`MeshReadError`] values whose message names the place (line, byte
//!   offset, triangle, zip entry or XML element) and the fix.
//! - Never panics on any input, and never allocates from an untrusted count
//!   before checking it against the input length.
//! - Coordinates are converted to millimetres here and nowhere else.
//! - Non-finite coordinates and out-of-range indices are errors, never repaired;
//!   welding and degenerate-triangle removal are [`TriMesh::from_indexed`]'s,
//!   reported in [`MeshDiagnostics`].

#![cfg_attr(test, allow(clippy::unwrap_used, reason = "tests fail loudly by design"))]

mod error;
mod obj;
mod ply;
mod stl;
mod text;
mod threemf;

use std::fmt;

use scallop_geom::Point3;
use scallop_mesh::FastMap;
pub use scallop_mesh::{MeshDiagnostics, MeshError, TriMesh};

pub mod cl;
pub mod gcode;
pub mod job;
pub mod tools;

pub use error::{MeshReadError, Place};

/// A mesh file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum MeshFormat {
    /// STL, ASCII or binary (told apart by the content).
    Stl,
    /// Wavefront OBJ (`v` and `f` statements).
    Obj,
    /// Stanford PLY (ASCII, binary little- or big-endian).
    Ply,
    /// 3D Manufacturing Format (a zip holding an XML model).
    ThreeMf,
}

impl MeshFormat {
    /// The format named by a file extension (case-insensitive). Takes a path,
    /// a file name or the bare extension.
    ///
    /// ```
    /// use scallop_io::MeshFormat;
    /// assert_eq!(MeshFormat::from_extension("parts/Bracket.STL"), Some(MeshFormat::Stl));
    /// assert_eq!(MeshFormat::from_extension("a.3mf"), Some(MeshFormat::ThreeMf));
    /// assert_eq!(MeshFormat::from_extension("ply"), Some(MeshFormat::Ply));
    /// assert_eq!(MeshFormat::from_extension("notes.txt"), None);
    /// ```
    #[must_use]
    pub fn from_extension(path_or_name: &str) -> Option<MeshFormat> {
        let name = path_or_name.rsplit(['/', '\\']).next().unwrap_or(path_or_name);
        let ext = name.rsplit('.').next().unwrap_or(name);
        [("stl", MeshFormat::Stl), ("obj", MeshFormat::Obj), ("ply", MeshFormat::Ply), ("3mf", MeshFormat::ThreeMf)]
            .into_iter()
            .find(|(e, _)| ext.eq_ignore_ascii_case(e))
            .map(|(_, f)| f)
    }
}

impl fmt::Display for MeshFormat {
    /// The usual name: `STL`, `OBJ`, `PLY`, `3MF`.
    ///
    /// ```
    /// assert_eq!(scallop_io::MeshFormat::ThreeMf.to_string(), "3MF");
    /// ```
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            MeshFormat::Stl => "STL",
            MeshFormat::Obj => "OBJ",
            MeshFormat::Ply => "PLY",
            MeshFormat::ThreeMf => "3MF",
        })
    }
}

/// The length unit of the file's coordinates. STL, OBJ and PLY carry no unit,
/// so the caller says it; a 3MF's own `unit` is converted to millimetres
/// first and this factor is then applied on top (leave it at millimetres for 3MF).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Units {
    /// Coordinates are millimetres (factor 1).
    #[default]
    Millimetres,
    /// Coordinates are inches (factor 25.4).
    Inches,
    /// Coordinates are metres (factor 1000; some exporters write metres).
    Metres,
    /// Coordinates are centimetres (factor 10).
    Centimetres,
}

impl Units {
    /// Millimetres per file unit.
    ///
    /// ```
    /// assert_eq!(scallop_io::Units::Inches.mm_per_unit(), 25.4);
    /// ```
    #[must_use]
    pub fn mm_per_unit(self) -> f64 {
        match self {
            Units::Millimetres => 1.0,
            Units::Inches => MM_PER_INCH,
            Units::Metres => 1000.0,
            Units::Centimetres => 10.0,
        }
    }
}

/// Millimetres per inch (exact by definition).
pub(crate) const MM_PER_INCH: f64 = 25.4;

/// A mesh read from a file, in millimetres.
///
/// ```
/// use scallop_io::{read_mesh, MeshFormat, Units};
/// let ply = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
///             property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
///             0 0 0\n2 0 0\n0 2 0\n3 0 1 2\n";
/// let loaded = read_mesh(ply, MeshFormat::Ply, Units::Millimetres).unwrap();
/// assert_eq!(loaded.format, MeshFormat::Ply);
/// assert_eq!(loaded.scale, 1.0);
/// assert_eq!(loaded.diagnostics.input_vertices, 3);
/// assert_eq!(loaded.mesh.area(), 2.0);
/// ```
#[derive(Debug, Clone)]
pub struct LoadedMesh {
    /// The validated mesh.
    pub mesh: TriMesh,
    /// What welding and cleaning did (degenerate triangles dropped, open edges...).
    pub diagnostics: MeshDiagnostics,
    /// The format read.
    pub format: MeshFormat,
    /// Millimetres per file coordinate unit that was applied (3MF unit times [`Units`]).
    pub scale: f64,
    /// How the units were decided, for the report, e.g. `3MF model unit 'inch' (x25.4)`.
    pub units_note: String,
}

/// Reads a triangle mesh of `format` from `bytes`, converting coordinates to
/// millimetres with `units` (see [`Units`] for 3MF).
///
/// Polygons (OBJ, PLY) are fan-triangulated; vertices are welded and
/// degenerate triangles dropped by [`TriMesh::from_indexed`].
///
/// # Errors
/// A [`MeshReadError`] naming the place of the first problem: bad syntax,
/// non-UTF-8 text, a non-finite coordinate, an out-of-range index, a binary
/// STL whose length does not match its count, no triangles, a broken 3MF zip,
/// or a mesh with only degenerate triangles.
///
/// ```
/// use scallop_io::{read_mesh, MeshFormat, Units};
/// let stl = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n\
///             endloop\nendfacet\nendsolid t\n";
/// let loaded = read_mesh(stl, MeshFormat::Stl, Units::Millimetres).unwrap();
/// assert_eq!(loaded.mesh.triangles().len(), 1);
/// assert_eq!(loaded.diagnostics.boundary_edges, 3);
///
/// let err = read_mesh(&stl[..60], MeshFormat::Stl, Units::Millimetres).unwrap_err();
/// assert!(err.to_string().contains("line 5"), "{err}");
/// ```
pub fn read_mesh(bytes: &[u8], format: MeshFormat, units: Units) -> Result<LoadedMesh, MeshReadError> {
    if bytes.is_empty() {
        return Err(MeshReadError::EmptyInput { format });
    }
    let user_scale = units.mm_per_unit();
    let unit_name = match units {
        Units::Millimetres => "millimetres",
        Units::Inches => "inches",
        Units::Metres => "metres",
        Units::Centimetres => "centimetres",
    };
    let (geometry, scale, units_note) = match format {
        MeshFormat::Stl => (stl::read(bytes, user_scale)?, user_scale, format!("coordinates taken as {unit_name}")),
        MeshFormat::Obj => (obj::read(bytes, user_scale)?, user_scale, format!("coordinates taken as {unit_name}")),
        MeshFormat::Ply => (ply::read(bytes, user_scale)?, user_scale, format!("coordinates taken as {unit_name}")),
        MeshFormat::ThreeMf => {
            let (geometry, file_unit, scale) = threemf::read(bytes, user_scale)?;
            let mut note = format!("3MF model unit '{}' (x{})", file_unit.name, file_unit.mm);
            if units != Units::Millimetres {
                note.push_str(&format!(", then {unit_name} asked for (x{user_scale})"));
            }
            (geometry, scale, note)
        }
    };
    let input_vertices = geometry.vertices.len();
    let geometry = merge_identical(geometry);
    let (mesh, mut diagnostics) = TriMesh::from_indexed(&geometry.vertices, &geometry.triangles)
        .map_err(|source| MeshReadError::Mesh { format, source })?;
    diagnostics.input_vertices = input_vertices;
    Ok(LoadedMesh { mesh, diagnostics, format, scale, units_note })
}

/// Merges bit-identical vertices (`-0` counts as `0`), keeping first-appearance
/// order. Welding would merge them anyway, to the same representative; doing it
/// here with one hash lookup per vertex spares the weld most of its work on
/// triangle soups (STL, where each vertex appears about six times).
fn merge_identical(geometry: Geometry) -> Geometry {
    let Geometry { vertices, mut triangles } = geometry;
    let mut first: FastMap<[u64; 3], usize> = FastMap::with_capacity_and_hasher(vertices.len() / 4, Default::default());
    let mut unique = Vec::with_capacity(vertices.len() / 4);
    let remap: Vec<usize> = vertices
        .iter()
        .map(|p| {
            let key = [(p.x + 0.0).to_bits(), (p.y + 0.0).to_bits(), (p.z + 0.0).to_bits()];
            *first.entry(key).or_insert_with(|| {
                unique.push(*p);
                unique.len() - 1
            })
        })
        .collect();
    for corner in triangles.iter_mut().flatten() {
        *corner = remap[*corner];
    }
    Geometry { vertices: unique, triangles }
}

/// Text that is not UTF-8, with its place: the line (from 1) and the byte offset (from 0)
/// of the first bad byte.
///
/// ```
/// let e = scallop_io::utf8_text(b"kind,x,y,z\nfeed,1,\xff,3\n").unwrap_err();
/// assert_eq!((e.line, e.byte, e.value), (2, 18, 0xff));
/// assert!(e.to_string().starts_with("line 2, byte 18: 0xFF"), "{e}");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("line {line}, byte {byte}: 0x{value:02X} is not UTF-8 text; save the file as plain (ASCII or UTF-8) text")]
pub struct NotUtf8 {
    /// Line of the bad byte (from 1).
    pub line: usize,
    /// Offset of the bad byte from the start of the file (from 0).
    pub byte: usize,
    /// The bad byte.
    pub value: u8,
}

/// The bytes as text, or the place of the first byte that is not UTF-8.
///
/// # Errors
/// [`NotUtf8`] with the line and byte offset.
pub fn utf8_text(bytes: &[u8]) -> Result<&str, NotUtf8> {
    std::str::from_utf8(bytes).map_err(|e| {
        let byte = e.valid_up_to();
        let line = 1 + bytes[..byte].iter().filter(|&&b| b == b'\n').count();
        NotUtf8 { line, byte, value: bytes.get(byte).copied().unwrap_or(0) }
    })
}

/// Vertices (mm, finite) and index triples (in range) as a parser produces them.
#[derive(Debug, Default)]
pub(crate) struct Geometry {
    pub vertices: Vec<Point3>,
    pub triangles: Vec<[usize; 3]>,
}
