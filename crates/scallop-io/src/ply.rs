//! Stanford PLY: `ascii`, `binary_little_endian` and `binary_big_endian` 1.0.
//!
//! The header declares elements in file order, each with a count and typed
//! properties (scalars or lists). The mesh comes from the `vertex` element's
//! `x`, `y`, `z` (any numeric type) and the `face` element's `vertex_indices`
//! (or `vertex_index`) list, with any count and index types; polygons are
//! fan-triangulated. Every other element and property is read past by its
//! declared type. ASCII data is one element per line, and lines are checked
//! against the properties, so a header count that disagrees with the data is
//! caught at the first line where they part.
//!
//! Counts in the header are untrusted: nothing is reserved beyond what the
//! remaining input could hold.

use scallop_geom::Point3;

use crate::text::{Line, Lines, Token, Tokens};
use crate::{Geometry, MeshFormat, MeshReadError, Place};

const FORMAT: MeshFormat = MeshFormat::Ply;
const RULE: &str = "PLY indices count from 0";
/// Largest integer every f64 below it represents exactly (2^53).
const MAX_EXACT_INT: f64 = 9_007_199_254_740_992.0;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Ascii,
    LittleEndian,
    BigEndian,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn from_name(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }

    fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "int8",
            Scalar::U8 => "uint8",
            Scalar::I16 => "int16",
            Scalar::U16 => "uint16",
            Scalar::I32 => "int32",
            Scalar::U32 => "uint32",
            Scalar::F32 => "float32",
            Scalar::F64 => "float64",
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
    /// Header line declaring it.
    line: usize,
}

impl Element {
    /// The fewest bytes one instance can take, to bound reservations.
    fn min_bytes(&self, encoding: Encoding) -> usize {
        let sum = match encoding {
            // A value and a separator each, except that the last may end the file.
            Encoding::Ascii => (2 * self.properties.len()).saturating_sub(1),
            _ => self
                .properties
                .iter()
                .map(|p| match p.kind {
                    Kind::Scalar(s) => s.size(),
                    Kind::List { count, .. } => count.size(),
                })
                .sum(),
        };
        sum.max(1)
    }

    fn property_names(&self) -> String {
        self.properties.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(" ")
    }
}

#[derive(Debug)]
struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Offset of the first data byte.
    data_start: usize,
    /// Line of `end_header`.
    end_line: usize,
}

/// A value as read, exact for every PLY type.
#[derive(Clone, Copy, Debug)]
enum Num {
    Int(i64),
    Float(f64),
}

impl Num {
    #[allow(clippy::cast_precision_loss, reason = "PLY int32 coordinates convert to f64 exactly")]
    fn to_f64(self) -> f64 {
        match self {
            Num::Int(i) => i as f64,
            Num::Float(f) => f,
        }
    }

    /// The value as an integer, when it is one (float-typed indices are accepted if integral).
    #[allow(clippy::cast_possible_truncation, reason = "checked integral and in range first")]
    fn to_int(self) -> Option<i64> {
        match self {
            Num::Int(i) => Some(i),
            Num::Float(f) if f.fract() == 0.0 && f.abs() <= MAX_EXACT_INT => Some(f as i64),
            Num::Float(_) => None,
        }
    }
}

pub(crate) fn read(bytes: &[u8], scale: f64) -> Result<Geometry, MeshReadError> {
    let header = read_header(bytes)?;
    let layout = Layout::find(&header)?;
    match header.encoding {
        Encoding::Ascii => {
            let lines = Lines::new(bytes, header.data_start, header.end_line + 1);
            let tokens = Line { text: &[], offset: 0, number: 0 }.tokens();
            let mut src = AsciiSource { lines, tokens, line: header.end_line };
            read_body(&mut src, &header, &layout, scale)
        }
        encoding => {
            let mut src = BinarySource { bytes, pos: header.data_start, big: encoding == Encoding::BigEndian };
            read_body(&mut src, &header, &layout, scale)
        }
    }
}

fn read_header(bytes: &[u8]) -> Result<Header, MeshReadError> {
    let mut lines = Lines::new(bytes, 0, 1);
    let magic = lines.next().map(|l| l.text.trim_ascii_end());
    if magic != Some(b"ply") {
        if let Some(t) = Lines::new(bytes, 0, 1).next().and_then(|l| l.tokens().next()) {
            t.as_str(FORMAT)?;
        }
        return Err(syntax(1, "the file does not start with a 'ply' line (is it a PLY file?)".to_string()));
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    for line in lines.by_ref() {
        let mut tokens = line.tokens();
        let Some(keyword) = tokens.next() else { continue };
        match keyword.text {
            b"comment" | b"obj_info" => {}
            b"format" => {
                let (Some(name), Some(version)) = (tokens.next(), tokens.next()) else {
                    return Err(syntax(line.number, "'format' needs an encoding and a version".to_string()));
                };
                encoding = Some(match name.text {
                    b"ascii" => Encoding::Ascii,
                    b"binary_little_endian" => Encoding::LittleEndian,
                    b"binary_big_endian" => Encoding::BigEndian,
                    _ => {
                        name.as_str(FORMAT)?;
                        return Err(unsupported(
                            line.number,
                            format!(
                                "unknown format {}; expected ascii, binary_little_endian or binary_big_endian",
                                name.shown()
                            ),
                        ));
                    }
                });
                if !matches!(version.text, b"1.0" | b"1") {
                    return Err(unsupported(line.number, format!("version {} is not PLY 1.0", version.shown())));
                }
            }
            b"element" => {
                let (Some(name), Some(count)) = (tokens.next(), tokens.next()) else {
                    return Err(syntax(line.number, "'element' needs a name and a count".to_string()));
                };
                let name = name.as_str(FORMAT)?.to_string();
                let Ok(count) = count.as_str(FORMAT)?.parse::<u64>() else {
                    return Err(syntax(line.number, format!("element count {} is not a whole number", count.shown())));
                };
                elements.push(Element { name, count, properties: Vec::new(), line: line.number });
            }
            b"property" => {
                let Some(element) = elements.last_mut() else {
                    return Err(syntax(line.number, "'property' comes before any 'element' line".to_string()));
                };
                element.properties.push(read_property(&line, tokens)?);
            }
            b"end_header" => {
                let Some(encoding) = encoding else {
                    return Err(syntax(line.number, "the header has no 'format' line".to_string()));
                };
                return Ok(Header { encoding, elements, data_start: lines.offset(), end_line: line.number });
            }
            _ => {
                keyword.as_str(FORMAT)?;
                return Err(syntax(
                    line.number,
                    format!(
                        "unknown header line {}; expected format, element, property, comment or end_header",
                        keyword.shown()
                    ),
                ));
            }
        }
    }
    Err(syntax(
        lines.last_number(),
        "the file ends inside the header (no 'end_header' line); the file is truncated".to_string(),
    ))
}

fn read_property(line: &Line<'_>, mut tokens: Tokens<'_>) -> Result<Property, MeshReadError> {
    let scalar = |t: Option<Token<'_>>| -> Result<Scalar, MeshReadError> {
        let Some(t) = t else {
            return Err(syntax(line.number, "'property' needs a type and a name".to_string()));
        };
        t.as_str(FORMAT)?;
        Scalar::from_name(t.text).ok_or_else(|| {
            unsupported(
                line.number,
                format!(
                    "unknown property type {}; expected char, uchar, short, ushort, int, uint, float, double \
                     (or int8 ... float64)",
                    t.shown()
                ),
            )
        })
    };
    let first = tokens.next();
    let kind = if first.is_some_and(|t| t.text == b"list") {
        let count = scalar(tokens.next())?;
        let item = scalar(tokens.next())?;
        if count.is_float() {
            return Err(unsupported(
                line.number,
                format!("a list count of type {} is not a whole number", count.name()),
            ));
        }
        Kind::List { count, item }
    } else {
        Kind::Scalar(scalar(first)?)
    };
    let Some(name) = tokens.next() else {
        return Err(syntax(line.number, "'property' needs a name after its type".to_string()));
    };
    Ok(Property { name: name.as_str(FORMAT)?.to_string(), kind })
}

/// Which element and properties hold the mesh.
struct Layout {
    vertex: usize,
    xyz: [usize; 3],
    face: usize,
    indices: usize,
}

impl Layout {
    fn find(header: &Header) -> Result<Layout, MeshReadError> {
        let Some(vertex) = header.elements.iter().position(|e| e.name == "vertex") else {
            return Err(syntax(header.end_line, "the header declares no 'vertex' element".to_string()));
        };
        let el = &header.elements[vertex];
        let mut xyz = [0; 3];
        for (slot, axis) in xyz.iter_mut().zip(["x", "y", "z"]) {
            match el.properties.iter().position(|p| p.name == axis) {
                Some(i) if matches!(el.properties[i].kind, Kind::Scalar(_)) => *slot = i,
                Some(_) => return Err(syntax(el.line, format!("vertex property '{axis}' is a list, not a number"))),
                None => {
                    return Err(syntax(
                        el.line,
                        format!("the 'vertex' element has no '{axis}' property (it has: {})", el.property_names()),
                    ));
                }
            }
        }
        let Some(face) = header.elements.iter().position(|e| e.name == "face") else {
            return Err(syntax(
                header.end_line,
                "the header declares no 'face' element: a point cloud is not a mesh".to_string(),
            ));
        };
        let el = &header.elements[face];
        let is_list = |p: &Property| matches!(p.kind, Kind::List { .. });
        let lists: Vec<usize> = (0..el.properties.len()).filter(|&i| is_list(&el.properties[i])).collect();
        let named = lists
            .iter()
            .copied()
            .find(|&i| matches!(el.properties[i].name.as_str(), "vertex_indices" | "vertex_index"));
        let indices = match (named, lists.as_slice()) {
            (Some(i), _) | (None, &[i]) => i,
            _ => {
                return Err(syntax(
                    el.line,
                    format!("the 'face' element has no 'vertex_indices' list (it has: {})", el.property_names()),
                ));
            }
        };
        Ok(Layout { vertex, xyz, face, indices })
    }
}

/// Element and instance being read, for messages.
struct Ctx<'h> {
    element: &'h Element,
    index: u64,
}

impl Ctx<'_> {
    fn describe(&self) -> String {
        format!("{} {} of {}", self.element.name, self.index, self.element.count)
    }
}

/// Where values come from: ASCII lines or binary bytes.
trait Source {
    /// Starts an instance (ASCII: takes the next non-blank line).
    fn begin(&mut self, ctx: &Ctx<'_>) -> Result<(), MeshReadError>;
    /// Reads one value and its place.
    fn value(&mut self, ty: Scalar, ctx: &Ctx<'_>) -> Result<(Num, Place), MeshReadError>;
    /// Ends an instance (ASCII: nothing may be left on the line).
    fn end(&mut self, ctx: &Ctx<'_>) -> Result<(), MeshReadError>;
    /// After the last element: nothing may follow.
    fn finish(&mut self) -> Result<(), MeshReadError>;
    /// Bytes not yet read.
    fn remaining(&self) -> usize;
}

struct AsciiSource<'a> {
    lines: Lines<'a>,
    /// Tokens left on the current instance's line, and its number.
    tokens: Tokens<'a>,
    line: usize,
}

impl Source for AsciiSource<'_> {
    fn begin(&mut self, ctx: &Ctx<'_>) -> Result<(), MeshReadError> {
        for line in self.lines.by_ref() {
            if line.tokens().next().is_some() {
                self.tokens = line.tokens();
                self.line = line.number;
                return Ok(());
            }
        }
        Err(syntax(
            self.lines.last_number(),
            format!(
                "the file ends before {}: the file is truncated or the header's count ({}) is too large",
                ctx.describe(),
                ctx.element.count
            ),
        ))
    }

    fn value(&mut self, ty: Scalar, ctx: &Ctx<'_>) -> Result<(Num, Place), MeshReadError> {
        let Some(t) = self.tokens.next() else {
            return Err(syntax(
                self.line,
                format!(
                    "{} has too few values for its properties ({}); each {} is one line",
                    ctx.describe(),
                    ctx.element.property_names(),
                    ctx.element.name
                ),
            ));
        };
        let num = if ty.is_float() {
            t.as_f64(FORMAT)?.map(Num::Float)
        } else {
            t.as_i64(FORMAT)?.filter(|&i| fits(i, ty)).map(Num::Int)
        };
        let Some(num) = num else {
            return Err(syntax(t.line, format!("{} in {} is not a valid {}", t.shown(), ctx.describe(), ty.name())));
        };
        Ok((num, t.place()))
    }

    fn end(&mut self, ctx: &Ctx<'_>) -> Result<(), MeshReadError> {
        if self.tokens.next().is_some() {
            return Err(syntax(
                self.line,
                format!(
                    "{} has more values than its properties take ({}); does the file have fewer {} lines than \
                     the header declares?",
                    ctx.describe(),
                    ctx.element.property_names(),
                    ctx.element.name
                ),
            ));
        }
        Ok(())
    }

    fn finish(&mut self) -> Result<(), MeshReadError> {
        match self.lines.by_ref().find(|l| l.tokens().next().is_some()) {
            Some(line) => Err(syntax(
                line.number,
                "data continues after the last element the header declares; the header's counts are too small"
                    .to_string(),
            )),
            None => Ok(()),
        }
    }

    fn remaining(&self) -> usize {
        self.lines.remaining()
    }
}

fn fits(i: i64, ty: Scalar) -> bool {
    let range = match ty {
        Scalar::I8 => i64::from(i8::MIN)..=i64::from(i8::MAX),
        Scalar::U8 => 0..=i64::from(u8::MAX),
        Scalar::I16 => i64::from(i16::MIN)..=i64::from(i16::MAX),
        Scalar::U16 => 0..=i64::from(u16::MAX),
        Scalar::I32 => i64::from(i32::MIN)..=i64::from(i32::MAX),
        Scalar::U32 => 0..=i64::from(u32::MAX),
        Scalar::F32 | Scalar::F64 => return true,
    };
    range.contains(&i)
}

struct BinarySource<'a> {
    bytes: &'a [u8],
    pos: usize,
    big: bool,
}

impl BinarySource<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let raw: [u8; N] = self.bytes.get(self.pos..self.pos + N)?.try_into().ok()?;
        self.pos += N;
        Some(if self.big { reversed(raw) } else { raw })
    }
}

fn reversed<const N: usize>(mut raw: [u8; N]) -> [u8; N] {
    raw.reverse();
    raw
}

impl Source for BinarySource<'_> {
    fn begin(&mut self, _ctx: &Ctx<'_>) -> Result<(), MeshReadError> {
        Ok(())
    }

    fn value(&mut self, ty: Scalar, ctx: &Ctx<'_>) -> Result<(Num, Place), MeshReadError> {
        let place = Place::Byte { byte: self.pos as u64 };
        let num = match ty {
            Scalar::I8 => self.take::<1>().map(|b| Num::Int(i64::from(i8::from_le_bytes(b)))),
            Scalar::U8 => self.take::<1>().map(|b| Num::Int(i64::from(b[0]))),
            Scalar::I16 => self.take::<2>().map(|b| Num::Int(i64::from(i16::from_le_bytes(b)))),
            Scalar::U16 => self.take::<2>().map(|b| Num::Int(i64::from(u16::from_le_bytes(b)))),
            Scalar::I32 => self.take::<4>().map(|b| Num::Int(i64::from(i32::from_le_bytes(b)))),
            Scalar::U32 => self.take::<4>().map(|b| Num::Int(i64::from(u32::from_le_bytes(b)))),
            Scalar::F32 => self.take::<4>().map(|b| Num::Float(f64::from(f32::from_le_bytes(b)))),
            Scalar::F64 => self.take::<8>().map(|b| Num::Float(f64::from_le_bytes(b))),
        };
        let Some(num) = num else {
            return Err(MeshReadError::Syntax {
                format: FORMAT,
                place: Place::Byte { byte: self.bytes.len() as u64 },
                problem: format!(
                    "the file ends inside {}: the file is truncated or the header's count ({}) is too large",
                    ctx.describe(),
                    ctx.element.count
                ),
            });
        };
        Ok((num, place))
    }

    fn end(&mut self, _ctx: &Ctx<'_>) -> Result<(), MeshReadError> {
        Ok(())
    }

    fn finish(&mut self) -> Result<(), MeshReadError> {
        if self.pos == self.bytes.len() {
            return Ok(());
        }
        Err(MeshReadError::Syntax {
            format: FORMAT,
            place: Place::Byte { byte: self.pos as u64 },
            problem: format!(
                "{} bytes follow the last element the header declares; the header's counts are too small",
                self.bytes.len() - self.pos
            ),
        })
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }
}

fn read_body<S: Source>(src: &mut S, header: &Header, layout: &Layout, scale: f64) -> Result<Geometry, MeshReadError> {
    let mut geometry = Geometry::default();
    let vertex_count = usize::try_from(header.elements[layout.vertex].count).unwrap_or(usize::MAX);
    let mut corners: Vec<usize> = Vec::new();
    for (e, element) in header.elements.iter().enumerate() {
        if element.properties.is_empty() {
            continue; // no data at all, however large the count
        }
        // Bounded by the input: each instance takes at least min_bytes.
        let fit = src.remaining() / element.min_bytes(header.encoding);
        let capacity = usize::try_from(element.count).unwrap_or(usize::MAX).min(fit);
        if e == layout.vertex {
            geometry.vertices.reserve(capacity);
        } else if e == layout.face {
            geometry.triangles.reserve(capacity);
        }
        for index in 0..element.count {
            let ctx = Ctx { element, index };
            src.begin(&ctx)?;
            let mut p = [0.0; 3];
            for (k, property) in element.properties.iter().enumerate() {
                match property.kind {
                    Kind::Scalar(ty) => {
                        let (num, place) = src.value(ty, &ctx)?;
                        if e == layout.vertex
                            && let Some(axis) = layout.xyz.iter().position(|&i| i == k)
                        {
                            let v = num.to_f64();
                            p[axis] = v * scale;
                            if !p[axis].is_finite() {
                                return Err(MeshReadError::NonFinite { format: FORMAT, place, value: v });
                            }
                        }
                    }
                    Kind::List { count, item } => {
                        let (n, place) = src.value(count, &ctx)?;
                        let n =
                            n.to_int().and_then(|n| u64::try_from(n).ok()).ok_or_else(|| MeshReadError::Syntax {
                                format: FORMAT,
                                place: place.clone(),
                                problem: format!("a list length in {} is negative", ctx.describe()),
                            })?;
                        let is_face = e == layout.face && k == layout.indices;
                        if is_face && n < 3 {
                            return Err(MeshReadError::Syntax {
                                format: FORMAT,
                                place,
                                problem: format!("{} has {n} corners; a face needs at least 3", ctx.describe()),
                            });
                        }
                        corners.clear();
                        for _ in 0..n {
                            let (v, place) = src.value(item, &ctx)?;
                            if is_face {
                                corners.push(vertex_index(v, vertex_count, place)?);
                            }
                        }
                        for k in 1..corners.len().saturating_sub(1) {
                            geometry.triangles.push([corners[0], corners[k], corners[k + 1]]);
                        }
                    }
                }
            }
            src.end(&ctx)?;
            if e == layout.vertex {
                geometry.vertices.push(Point3::new(p[0], p[1], p[2]));
            }
        }
    }
    src.finish()?;
    if geometry.triangles.is_empty() {
        let line = header.elements[layout.face].line;
        return Err(MeshReadError::NoTriangles { format: FORMAT, place: Place::Line { line } });
    }
    Ok(geometry)
}

fn vertex_index(v: Num, vertex_count: usize, place: Place) -> Result<usize, MeshReadError> {
    let Some(index) = v.to_int() else {
        return Err(MeshReadError::Syntax {
            format: FORMAT,
            place,
            problem: format!("vertex index {} is not a whole number", v.to_f64()),
        });
    };
    match usize::try_from(index) {
        Ok(i) if i < vertex_count => Ok(i),
        _ => Err(MeshReadError::BadIndex { format: FORMAT, place, index, vertex_count, rule: RULE }),
    }
}

fn syntax(line: usize, problem: String) -> MeshReadError {
    MeshReadError::Syntax { format: FORMAT, place: Place::Line { line }, problem }
}

fn unsupported(line: usize, problem: String) -> MeshReadError {
    MeshReadError::Unsupported { format: FORMAT, place: Place::Line { line }, problem }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII_HEADER: &str = "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 4\nproperty float x\n\
                                property float y\nproperty float z\nelement face 1\n\
                                property list uchar int vertex_indices\nend_header\n";

    fn ascii(body: &str) -> Result<Geometry, MeshReadError> {
        read(format!("{ASCII_HEADER}{body}").as_bytes(), 1.0)
    }

    #[test]
    fn ascii_quad_is_fanned() {
        let g = ascii("0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n").unwrap();
        assert_eq!(g.vertices.len(), 4);
        assert_eq!(g.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn other_elements_and_properties_are_skipped() {
        let text = "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty uchar red\r\nproperty double z\r\n\
                    property list uchar float extra\r\nproperty short y\r\nproperty int x\r\n\
                    element material 1\r\nproperty list int int stuff\r\n\
                    element face 1\r\nproperty int flags\r\nproperty list ushort uint vertex_index\r\nend_header\r\n\
                    255 0.5 2 9 9 0 0\r\n1 0.5 0 0 1\r\n1 0.5 1 7.5 0 0\r\n3 1 2 3\r\n0 3 2 1 0\r\n";
        let g = read(text.as_bytes(), 2.0).unwrap();
        assert_eq!(g.vertices[1], Point3::new(2.0, 0.0, 1.0));
        assert_eq!(g.triangles, vec![[2, 1, 0]]);
    }

    #[test]
    fn binary_both_endiannesses() {
        for (name, big) in [("binary_little_endian", false), ("binary_big_endian", true)] {
            let header = format!(
                "ply\nformat {name} 1.0\nelement vertex 3\nproperty double x\nproperty float y\nproperty short z\n\
                 element face 1\nproperty list uchar uint vertex_indices\nend_header\n"
            );
            let mut b = header.into_bytes();
            let put = |bytes: &mut Vec<u8>, le: &[u8]| {
                let mut v = le.to_vec();
                if big {
                    v.reverse();
                }
                bytes.extend_from_slice(&v);
            };
            for (x, y, z) in [(0.0f64, 0.0f32, 0i16), (1.0, 0.0, 0), (0.0, 1.0, -2)] {
                put(&mut b, &x.to_le_bytes());
                put(&mut b, &y.to_le_bytes());
                put(&mut b, &z.to_le_bytes());
            }
            b.push(3);
            for i in [0u32, 1, 2] {
                put(&mut b, &i.to_le_bytes());
            }
            let g = read(&b, 1.0).unwrap();
            assert_eq!(g.vertices[2], Point3::new(0.0, 1.0, -2.0), "{name}");
            assert_eq!(g.triangles, vec![[0, 1, 2]], "{name}");
            // Truncated: names the byte where the file ends and the element.
            let err = read(&b[..b.len() - 2], 1.0).unwrap_err().to_string();
            assert!(err.contains(&format!("byte {}", b.len() - 2)) && err.contains("face 0 of 1"), "{err}");
            // Trailing bytes: the header's counts are wrong.
            b.push(0);
            let err = read(&b, 1.0).unwrap_err().to_string();
            assert!(err.contains(&format!("byte {}: 1 bytes follow", b.len() - 1)), "{err}");
        }
    }

    #[test]
    fn data_errors_name_lines() {
        for (body, want) in [
            ("0 0 0\n1 0 0\n1 1 0\n3 0 1 2\n", "line 14: vertex 3 of 4 has more values"),
            ("0 0 0\n1 0 0\n1 1 0\n0 1\n3 0 1 2\n", "line 14: vertex 3 of 4 has too few values"),
            ("0 0 0\n1 0 0\n1 1 0\n0 1 0\n", "line 14: the file ends before face 0 of 1"),
            ("0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 4\n", "line 15: vertex index 4 is out of range: 4 vertices"),
            ("0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 -1\n", "line 15: vertex index -1"),
            ("0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 1\n", "line 15: face 0 of 1 has 2 corners"),
            ("0 0 0\n1 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", "line 13: coordinate NaN"),
            ("0 0 0\n1 0 0\n1 one 0\n0 1 0\n3 0 1 2\n", "line 13: 'one' in vertex 2 of 4 is not a valid float32"),
            ("0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n\n1 1 1\n", "line 17: data continues"),
            ("0 0 0\n1 0 0\n1 1 0\n0 1 0\n300 0 1 2\n", "line 15: '300' in face 0 of 1 is not a valid uint8"),
        ] {
            let err = ascii(body).unwrap_err().to_string();
            assert!(err.contains(want), "{err} (wanted {want})");
        }
    }

    #[test]
    fn header_errors_name_lines() {
        for (from, to, want) in [
            ("ply\n", "plx\n", "line 1: the file does not start with a 'ply' line"),
            ("format ascii 1.0", "format binary_middle_endian 1.0", "line 2: unknown format 'binary_middle_endian'"),
            ("format ascii 1.0", "format ascii 2.0", "line 2: version '2.0'"),
            ("property float y", "property quad y", "line 6: unknown property type 'quad'"),
            ("property float z", "property float w", "line 4: the 'vertex' element has no 'z' property"),
            ("element face 1", "element face many", "line 8: element count 'many'"),
            ("element face 1", "element edge 1", "line 10: the header declares no 'face' element"),
            ("comment made by hand", "commentary", "line 3: unknown header line 'commentary'"),
            ("comment made by hand", "comment caf\u{e9}", ""),
        ] {
            let text = format!("{ASCII_HEADER}0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n").replacen(from, to, 1);
            match read(text.as_bytes(), 1.0) {
                Err(e) => assert!(!want.is_empty() && e.to_string().contains(want), "{e} (wanted {want})"),
                Ok(_) => assert!(want.is_empty(), "no error (wanted {want})"),
            }
        }
        let err = read(ASCII_HEADER.replace("end_header\n", "").as_bytes(), 1.0).unwrap_err().to_string();
        assert!(err.contains("line 9: the file ends inside the header"), "{err}");
        let mut bytes = ASCII_HEADER.as_bytes().to_vec();
        bytes[ASCII_HEADER.find("vertex 4").unwrap()] = 0xFF;
        let err = read(&bytes, 1.0).unwrap_err().to_string();
        assert!(err.contains("line 4, byte 50: byte 0xFF is not UTF-8"), "{err}");
    }

    #[test]
    fn absurd_counts_do_not_allocate() {
        let text = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000000\nproperty float x\n\
                    property float y\nproperty float z\nelement face 4000000000000\n\
                    property list uchar int vertex_indices\nend_header\n\x01\x02";
        let err = read(text.as_bytes(), 1.0).unwrap_err().to_string();
        assert!(err.contains("the file ends inside vertex 0 of 4000000000000"), "{err}");
    }
}
