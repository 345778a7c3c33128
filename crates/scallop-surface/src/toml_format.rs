//! The TOML description of a [`SurfaceSet`] (the format is documented in the
//! crate docs, section "TOML format"): [`parse_surfaces`] and [`to_toml`].
//!
//! Parsing is a pure function of the text (no file access): the caller reads the file.

use std::fmt::Write as _;

use scallop_geom::Point3;
use serde::Deserialize;

use crate::error::{Direction, PatchLabel, SurfaceError};
use crate::patch::Patch;
use crate::set::SurfaceSet;

/// Millimetres per inch (`units = "in"`).
pub const MM_PER_INCH: f64 = 25.4;

/// Why a TOML surface description was rejected. Every variant about a patch names
/// it ([`PatchLabel`]: index from 0 and name) and the line where its `[[patch]]`
/// table starts; TOML syntax errors keep the parser's line and column.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SurfaceFormatError {
    /// Not valid TOML, or a wrong top-level key (the message has the line and
    /// column). Fix: correct the text at that place.
    #[error("invalid surface file: {message}")]
    Syntax {
        /// The TOML parser's message, with line and column.
        message: String,
    },
    /// Unknown `units`. Fix: `units = "mm"` or `units = "in"`.
    #[error("units = {found:?} is not supported; write units = \"mm\" or units = \"in\"")]
    Units {
        /// The value found.
        found: String,
    },
    /// No `[[patch]]` table. Fix: add at least one.
    #[error("the file has no [[patch]] tables; add at least one")]
    NoPatches,
    /// A patch table with a missing, unknown or mistyped key (the message names it).
    /// Fix: see the format in the crate docs.
    #[error("{patch} (table at line {line}): {message}")]
    Field {
        /// The patch (the name is empty if the table has none).
        patch: PatchLabel,
        /// Line of the `[[patch]]` header, from 1.
        line: usize,
        /// What is wrong, from the TOML deserializer (e.g. "missing field `degree`").
        message: String,
    },
    /// A control point that is not `[x, y, z]`. Fix: write three coordinates.
    #[error(
        "{patch} (table at line {line}): control point (i = {i}, j = {j}) has {found} coordinates; write [x, y, z]"
    )]
    PointArity {
        /// The patch.
        patch: PatchLabel,
        /// Line of the `[[patch]]` header, from 1.
        line: usize,
        /// Index along u (row of `control`).
        i: usize,
        /// Index along v (position in the row).
        j: usize,
        /// Coordinates given.
        found: usize,
    },
    /// Knot vectors on a Bezier patch. Fix: remove them, or use `kind = "nurbs"`.
    #[error(
        "{patch} (table at line {line}): kind = \"bezier\" takes no knots_{direction}; remove it or use kind = \"nurbs\""
    )]
    KnotsOnBezier {
        /// The patch.
        patch: PatchLabel,
        /// Line of the `[[patch]]` header, from 1.
        line: usize,
        /// The knot vector found.
        direction: Direction,
    },
    /// A NURBS patch without a knot vector. Fix: add `knots_u` / `knots_v`.
    #[error("{patch} (table at line {line}): kind = \"nurbs\" needs knots_{direction}")]
    MissingKnots {
        /// The patch.
        patch: PatchLabel,
        /// Line of the `[[patch]]` header, from 1.
        line: usize,
        /// The missing knot vector.
        direction: Direction,
    },
    /// The patch is well-formed TOML but not a valid surface (the inner error names
    /// the patch, the place and the fix).
    #[error("{source} (table at line {line})")]
    Invalid {
        /// Line of the `[[patch]]` header, from 1 (0 for errors about the whole set).
        line: usize,
        /// The validation error.
        source: SurfaceError,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileDoc {
    units: String,
    #[serde(default)]
    patch: Vec<toml::Spanned<toml::Table>>,
}

#[derive(Deserialize)]
#[serde(rename_all = "lowercase")]
enum KindDoc {
    Bezier,
    Nurbs,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PatchDoc {
    name: String,
    kind: KindDoc,
    degree: [usize; 2],
    control: Vec<Vec<Vec<f64>>>,
    #[serde(default)]
    weights: Option<Vec<Vec<f64>>>,
    #[serde(default)]
    knots_u: Option<Vec<f64>>,
    #[serde(default)]
    knots_v: Option<Vec<f64>>,
}

/// Parses a TOML surface description (format in the crate docs). Lengths in
/// inches are converted to mm; knots and weights are unit-free.
///
/// ```
/// let text = r#"
/// units = "mm"
/// [[patch]]
/// name = "flat"
/// kind = "bezier"
/// degree = [1, 1]
/// control = [[[0, 0, 0], [0, 10, 0]],
///            [[10, 0, 0], [10, 10, 0]]]
/// "#;
/// let set = scallop_surface::toml_format::parse_surfaces(text).unwrap();
/// assert_eq!(set.patches()[0].point(1.0, 1.0), scallop_geom::Point3::new(10.0, 10.0, 0.0));
/// ```
///
/// # Errors
/// A [`SurfaceFormatError`] naming the patch (index and name) and the place.
pub fn parse_surfaces(text: &str) -> Result<SurfaceSet, SurfaceFormatError> {
    let doc: FileDoc = toml::from_str(text).map_err(|e| SurfaceFormatError::Syntax { message: e.to_string() })?;
    let scale = match doc.units.as_str() {
        "mm" => 1.0,
        "in" => MM_PER_INCH,
        _ => return Err(SurfaceFormatError::Units { found: doc.units }),
    };
    if doc.patch.is_empty() {
        return Err(SurfaceFormatError::NoPatches);
    }
    let mut patches = Vec::with_capacity(doc.patch.len());
    let mut lines = Vec::with_capacity(doc.patch.len());
    for (index, spanned) in doc.patch.into_iter().enumerate() {
        let line = line_of(text, spanned.span().start);
        let table = spanned.into_inner();
        let name = table.get("name").and_then(toml::Value::as_str).unwrap_or_default().to_owned();
        let label = PatchLabel { index: Some(index), name };
        patches.push(parse_patch(table, &label, line, scale)?);
        lines.push(line);
    }
    SurfaceSet::new(patches).map_err(|source| {
        let line = source.patch().and_then(|p| p.index).map_or(0, |i| lines[i]);
        SurfaceFormatError::Invalid { line, source }
    })
}

fn parse_patch(table: toml::Table, label: &PatchLabel, line: usize, scale: f64) -> Result<Patch, SurfaceFormatError> {
    let doc: PatchDoc = toml::Value::Table(table).try_into().map_err(|e: toml::de::Error| {
        SurfaceFormatError::Field { patch: label.clone(), line, message: e.message().trim().to_owned() }
    })?;
    let mut control = Vec::with_capacity(doc.control.len());
    for (i, row) in doc.control.iter().enumerate() {
        let mut points = Vec::with_capacity(row.len());
        for (j, xyz) in row.iter().enumerate() {
            let &[x, y, z] = xyz.as_slice() else {
                return Err(SurfaceFormatError::PointArity { patch: label.clone(), line, i, j, found: xyz.len() });
            };
            points.push(Point3::new(x * scale, y * scale, z * scale));
        }
        control.push(points);
    }
    let invalid = |source: SurfaceError| SurfaceFormatError::Invalid {
        line,
        source: source.with_patch_index(label.index.unwrap_or(0)),
    };
    match doc.kind {
        KindDoc::Bezier => {
            for (direction, knots) in [(Direction::U, &doc.knots_u), (Direction::V, &doc.knots_v)] {
                if knots.is_some() {
                    return Err(SurfaceFormatError::KnotsOnBezier { patch: label.clone(), line, direction });
                }
            }
            Patch::bezier(&doc.name, doc.degree, &control, doc.weights.as_deref()).map_err(invalid)
        }
        KindDoc::Nurbs => {
            let Some(knots_u) = doc.knots_u else {
                return Err(SurfaceFormatError::MissingKnots { patch: label.clone(), line, direction: Direction::U });
            };
            let Some(knots_v) = doc.knots_v else {
                return Err(SurfaceFormatError::MissingKnots { patch: label.clone(), line, direction: Direction::V });
            };
            Patch::nurbs(&doc.name, doc.degree, [knots_u, knots_v], &control, doc.weights.as_deref()).map_err(invalid)
        }
    }
}

/// The 1-based line of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1
}

/// Writes `set` in the TOML format (units mm, control rows one per line). The
/// output parses back with [`parse_surfaces`] to an equal set: floats are written
/// in Rust's shortest round-trip form.
///
/// ```
/// use scallop_surface::{builtin, toml_format::{parse_surfaces, to_toml}};
/// let choi = builtin("choi").unwrap();
/// assert_eq!(parse_surfaces(&to_toml(&choi)).unwrap(), choi);
/// ```
#[must_use]
pub fn to_toml(set: &SurfaceSet) -> String {
    let mut out = String::new();
    // Writing to a String cannot fail; the results are ignored below for that reason.
    let _ = writeln!(out, "# scallop surface set: {} patch(es); format in the scallop-surface crate docs", set.len());
    let _ = writeln!(out, "units = \"mm\"");
    for patch in set.patches() {
        let [p, q] = patch.degree();
        let [rows, columns] = patch.control_shape();
        let _ = writeln!(out);
        let _ = writeln!(out, "[[patch]]");
        let _ = writeln!(out, "name = {}", quote(patch.name()));
        let _ = writeln!(out, "kind = \"{}\"", if patch.is_bezier() { "bezier" } else { "nurbs" });
        let _ = writeln!(out, "degree = [{p}, {q}]");
        for direction in Direction::BOTH {
            if let Some(knots) = patch.knots(direction) {
                let _ = writeln!(out, "knots_{direction} = {}", list(knots.iter().map(|k| number(*k))));
            }
        }
        let _ = writeln!(out, "# control[i][j] = [x, y, z] (mm), i along u, j along v");
        let _ = writeln!(out, "control = [");
        for i in 0..rows {
            let row = (0..columns).map(|j| {
                let c = patch.control_point(i, j);
                list([c.x, c.y, c.z].into_iter().map(number))
            });
            let _ = writeln!(out, "    {},", list(row));
        }
        let _ = writeln!(out, "]");
        if let Some(weights) = patch.weights() {
            let _ = writeln!(out, "weights = [");
            for row in weights.chunks(columns) {
                let _ = writeln!(out, "    {},", list(row.iter().map(|w| number(*w))));
            }
            let _ = writeln!(out, "]");
        }
    }
    out
}

fn list(items: impl IntoIterator<Item = String>) -> String {
    format!("[{}]", items.into_iter().collect::<Vec<_>>().join(", "))
}

/// A finite float as a TOML float in shortest round-trip form (`7.92`, `0.0`, `1e-7`).
fn number(x: f64) -> String {
    format!("{x:?}")
}

/// A TOML basic string.
fn quote(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => {
                let _ = write!(out, "\\u{:04X}", u32::from(c));
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}
