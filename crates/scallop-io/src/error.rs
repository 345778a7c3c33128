//! The one error type of the crate and the places it points at.

use std::fmt;

use scallop_mesh::MeshError;

use crate::MeshFormat;

/// Where in the input a problem is. Lines count from 1; byte offsets,
/// triangle and vertex numbers count from 0.
///
/// ```
/// use scallop_io::Place;
/// assert_eq!(Place::LineByte { line: 3, byte: 41 }.to_string(), "line 3, byte 41");
/// assert_eq!(Place::Triangle { index: 2, vertex: 1, byte: 212 }.to_string(), "triangle 2, vertex 1 (byte 212)");
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Place {
    /// A line of a text file.
    Line {
        /// Line number (from 1).
        line: usize,
    },
    /// A byte inside a line of a text file.
    LineByte {
        /// Line number (from 1).
        line: usize,
        /// Byte offset from the start of the file.
        byte: u64,
    },
    /// A byte offset in a binary file.
    Byte {
        /// Byte offset from the start of the file.
        byte: u64,
    },
    /// A corner of a binary STL triangle.
    Triangle {
        /// Triangle number in file order.
        index: u64,
        /// Corner (0..3).
        vertex: u8,
        /// Byte offset of the offending value.
        byte: u64,
    },
    /// An element of an XML part inside a zip (3MF).
    Xml {
        /// Zip entry name, e.g. `3D/3dmodel.model`.
        entry: String,
        /// Line in that entry (from 1).
        line: usize,
        /// Element name without namespace prefix, e.g. `vertex` (empty when unknown).
        element: String,
    },
    /// A whole zip entry (3MF).
    Entry {
        /// Zip entry name.
        entry: String,
    },
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Place::Line { line } => write!(f, "line {line}"),
            Place::LineByte { line, byte } => write!(f, "line {line}, byte {byte}"),
            Place::Byte { byte } => write!(f, "byte {byte}"),
            Place::Triangle { index, vertex, byte } => write!(f, "triangle {index}, vertex {vertex} (byte {byte})"),
            Place::Xml { entry, line, element } if element.is_empty() => write!(f, "{entry} line {line}"),
            Place::Xml { entry, line, element } => write!(f, "{entry} line {line}, <{element}>"),
            Place::Entry { entry } => write!(f, "zip entry {entry}"),
        }
    }
}

/// Why a mesh file could not be read. The message names the place (line, byte
/// offset, triangle, zip entry or XML element), what is wrong and how to fix it;
/// a caller adds the file name in front.
///
/// ```
/// use scallop_io::{read_mesh, MeshFormat, Units};
/// let err = read_mesh(b"v 0 0 0\nf 1 2 3\n", MeshFormat::Obj, Units::Millimetres).unwrap_err();
/// assert!(err.to_string().starts_with("OBJ line 2:"), "{err}");
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MeshReadError {
    /// The input has no bytes at all. Fix: check that the file was written completely.
    #[error("{format}: the file is empty (0 bytes); check that it was written completely")]
    EmptyInput {
        /// Format that was asked for.
        format: MeshFormat,
    },
    /// The content does not follow the format's grammar; `problem` says what was
    /// expected and what was found. Fix: export the file again, or repair it at `place`.
    #[error("{format} {place}: {problem}")]
    Syntax {
        /// Format being read.
        format: MeshFormat,
        /// Where.
        place: Place,
        /// What is wrong and how to fix it.
        problem: String,
    },
    /// A valid file using a feature this reader does not support (a PLY format
    /// or property type, a 3MF extension). Fix: export with the supported option named.
    #[error("{format} {place}: {problem}")]
    Unsupported {
        /// Format being read.
        format: MeshFormat,
        /// Where.
        place: Place,
        /// What is unsupported and what is.
        problem: String,
    },
    /// Text that is not UTF-8 where keywords or numbers are expected.
    /// Fix: save the file as plain (ASCII or UTF-8) text.
    #[error("{format} {place}: byte 0x{byte:02X} is not UTF-8 text; save the file as plain ASCII or UTF-8 text")]
    NotText {
        /// Format being read.
        format: MeshFormat,
        /// Where; the byte offset points at the bad byte.
        place: Place,
        /// The offending byte.
        byte: u8,
    },
    /// A coordinate is NaN or infinite (after unit conversion).
    /// Fix: repair the export; scallop never guesses a value.
    #[error(
        "{format} {place}: coordinate {value} is not a finite number; repair the export (scallop never guesses a value)"
    )]
    NonFinite {
        /// Format being read.
        format: MeshFormat,
        /// Where.
        place: Place,
        /// The value as read (before unit conversion).
        value: f64,
    },
    /// A face refers to a vertex that does not exist. Fix: repair the face at `place`.
    #[error("{format} {place}: vertex index {index} is out of range: {vertex_count} vertices are available ({rule})")]
    BadIndex {
        /// Format being read.
        format: MeshFormat,
        /// Where.
        place: Place,
        /// The index as written in the file.
        index: i64,
        /// How many vertices the index could name.
        vertex_count: usize,
        /// How the format counts indices.
        rule: &'static str,
    },
    /// A binary STL whose length does not match its triangle count. Fix: the
    /// file is truncated or its count is wrong; export it again.
    #[error(
        "STL byte 80: the binary triangle count is {triangles}, which needs {expected} bytes, but the file has \
         {actual} bytes; the file is truncated or its count is wrong: export it again"
    )]
    StlSize {
        /// The count stored at byte 80.
        triangles: u32,
        /// `84 + 50 * triangles`.
        expected: u64,
        /// The input length.
        actual: u64,
    },
    /// The file parsed but holds no triangle. Fix: check that the export
    /// contains a part, not only a header.
    #[error("{format} {place}: the file holds no triangles; check that the export contains a part, not only a header")]
    NoTriangles {
        /// Format being read.
        format: MeshFormat,
        /// Where the (empty) content ends.
        place: Place,
    },
    /// A 3MF that is not a readable zip archive. Fix: check that the file is a
    /// complete 3MF (a 3MF is a zip archive).
    #[error(
        "3MF: not a readable zip archive ({reason}); a 3MF file is a zip: check that it is complete and really 3MF"
    )]
    NotZip {
        /// The zip reader's complaint.
        reason: String,
    },
    /// A zip entry that cannot be read (unsupported compression, encryption, corrupt data).
    /// Fix: save the 3MF again with standard (deflate) compression.
    #[error("3MF {place}: cannot read it ({reason}); save the 3MF again with standard (deflate) compression")]
    ZipEntry {
        /// Which entry.
        place: Place,
        /// Why.
        reason: String,
    },
    /// A 3MF zip without its model part. Fix: export the 3MF again; the zip must hold `3D/3dmodel.model`.
    #[error(
        "3MF: the zip has no model part '{looked_for}' (it has {entries} entries); export the 3MF again, \
         the zip must hold the 3D model XML"
    )]
    MissingModel {
        /// Entry name that was looked for.
        looked_for: String,
        /// Number of entries in the zip.
        entries: usize,
    },
    /// The triangles were read but do not form a usable mesh (for example all
    /// are degenerate); the mesh error names the triangle (in file order).
    #[error("{format}: {source}")]
    Mesh {
        /// Format being read.
        format: MeshFormat,
        /// The mesh validation error.
        source: MeshError,
    },
}
