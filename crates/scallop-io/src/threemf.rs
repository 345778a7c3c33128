//! 3MF: a zip whose root relationship (`_rels/.rels`) names the model part,
//! usually `3D/3dmodel.model`, an XML document:
//!
//! ```text
//! <model unit="millimeter"> <resources>
//!   <object id="1"> <mesh> <vertices> <vertex x= y= z=/>... </vertices>
//!                          <triangles> <triangle v1= v2= v3=/>... </triangles> </mesh> </object>
//!   <object id="2"> <components> <component objectid="1" transform="..."/> </components> </object>
//! </resources> <build> <item objectid="2" transform="..."/> </build> </model>
//! ```
//!
//! The part is what the build items place: each item's object, with nested
//! components, under the product of the transforms (3MF's row-vector 3x4
//! matrices `m00 m01 m02 m10 m11 m12 m20 m21 m22 m30 m31 m32`, so
//! `x' = m00 x + m10 y + m20 z + m30`). A mirroring transform (negative
//! determinant) reverses the winding so normals stay outward. Components that
//! point into other model parts (production extension `path`) are read from
//! those parts. Elements are matched by local name and parent, so extension
//! elements (slices, beams) are not mistaken for mesh data. Coordinates are
//! converted from the model `unit` to millimetres.

use std::borrow::Cow;
use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::io::{Cursor, Read};

use quick_xml::events::{BytesStart, Event};
use quick_xml::reader::Reader;
use scallop_geom::Point3;
use zip::ZipArchive;

use crate::{Geometry, MM_PER_INCH, MeshFormat, MeshReadError, Place};

const FORMAT: MeshFormat = MeshFormat::ThreeMf;
const DEFAULT_MODEL: &str = "3D/3dmodel.model";
const RELS: &str = "_rels/.rels";
const RULE: &str = "3MF indices count from 0 within the object's <vertices>";
/// Deepest component nesting accepted (deeper means a cycle or an abuse).
const MAX_DEPTH: usize = 32;
/// Most triangles that instancing may produce (protects memory from tiny files that repeat a
/// mesh): about 8.4 million, 1 to 2 GB once placed, welded and indexed. Counted before
/// anything is placed.
pub const MAX_TRIANGLES: usize = 1 << 23;
/// Most objects that build items and components may place (protects time the same way).
const MAX_PLACEMENTS: usize = 1 << 20;
/// Largest XML part read (decompressed), to stop zip bombs: 1 GiB, about 8 million triangles
/// of 3MF XML. The size the zip declares is checked before reading, the bytes read after.
pub const MAX_PART_BYTES: u64 = 1 << 30;

/// The unit a 3MF model declares.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FileUnit {
    pub name: &'static str,
    pub mm: f64,
}

const UNITS: [FileUnit; 6] = [
    FileUnit { name: "millimeter", mm: 1.0 },
    FileUnit { name: "micron", mm: 0.001 },
    FileUnit { name: "centimeter", mm: 10.0 },
    FileUnit { name: "inch", mm: MM_PER_INCH },
    FileUnit { name: "foot", mm: 12.0 * MM_PER_INCH },
    FileUnit { name: "meter", mm: 1000.0 },
];

/// A 3MF affine transform, rows `m0*`..`m3*` (the last row is the translation).
type Transform = [[f64; 3]; 4];

const IDENTITY: Transform = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]];

fn apply(m: &Transform, p: &Point3) -> Point3 {
    let c = |j: usize| p.x * m[0][j] + p.y * m[1][j] + p.z * m[2][j] + m[3][j];
    Point3::new(c(0), c(1), c(2))
}

/// `first` then `second` (row vectors: `p * first * second`).
fn then(first: &Transform, second: &Transform) -> Transform {
    let mut out = [[0.0; 3]; 4];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, value) in row.iter_mut().enumerate() {
            *value = (0..3).map(|k| first[i][k] * second[k][j]).sum::<f64>() + if i == 3 { second[3][j] } else { 0.0 };
        }
    }
    out
}

fn determinant(m: &Transform) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// An object: a mesh, or components placing other objects.
#[derive(Debug, Default)]
struct Object {
    vertices: Vec<Point3>,
    triangles: Vec<[usize; 3]>,
    components: Vec<Reference>,
}

/// A build item or component: an object (in a part), placed by a transform.
#[derive(Debug)]
struct Reference {
    part: String,
    id: String,
    transform: Transform,
    place: Place,
}

/// What one model part holds.
#[derive(Debug, Default)]
struct Part {
    unit: Option<FileUnit>,
    objects: HashMap<String, Object>,
    items: Vec<Reference>,
}

pub(crate) fn read(bytes: &[u8], user_scale: f64) -> Result<(Geometry, FileUnit, f64), MeshReadError> {
    let mut zip = ZipArchive::new(Cursor::new(bytes)).map_err(|e| MeshReadError::NotZip { reason: zip_words(&e) })?;
    let root = root_part_name(&mut zip);
    let root_xml = read_entry(&mut zip, &root)?;
    let mut parts: HashMap<String, Part> = HashMap::new();
    let part = parse_part(&root_xml, &root, true)?;
    let unit = part.unit.unwrap_or(UNITS[0]);
    if part.items.is_empty() {
        return Err(MeshReadError::Syntax {
            format: FORMAT,
            place: Place::Entry { entry: root.clone() },
            problem: "the <build> has no <item>: nothing to make; export the 3MF with the part placed on the plate"
                .to_string(),
        });
    }
    // Parts named by `path` references, read once each (they may not reference further parts).
    let mut wanted: Vec<String> = part.items.iter().map(|r| r.part.clone()).collect();
    wanted.extend(part.objects.values().flat_map(|o| o.components.iter().map(|c| c.part.clone())));
    parts.insert(root.clone(), part);
    for name in wanted {
        if let Entry::Vacant(slot) = parts.entry(name) {
            let xml = read_entry(&mut zip, slot.key())?;
            let part = parse_part(&xml, slot.key(), false)?;
            slot.insert(part);
        }
    }

    // What the build would place, counted before anything is placed.
    let mut memo = HashMap::new();
    let mut total: u128 = 0;
    for item in &parts[&root].items {
        total = total.saturating_add(count_triangles(&parts, item, 0, &mut memo));
    }
    if total > MAX_TRIANGLES as u128 {
        return Err(MeshReadError::Syntax {
            format: FORMAT,
            place: Place::Entry { entry: root },
            problem: format!(
                "the build places {total} triangles by instancing (objects repeated by <component> and <item>), \
                 over the cap of {MAX_TRIANGLES}; place fewer copies, or merge the part into one mesh"
            ),
        });
    }
    let scale = unit.mm * user_scale;
    let mut out = Geometry::default();
    let mut placements = 0;
    for item in &parts[&root].items {
        place_object(&parts, item, &IDENTITY, 0, &mut placements, &mut out)?;
    }
    if out.triangles.is_empty() {
        return Err(MeshReadError::NoTriangles { format: FORMAT, place: Place::Entry { entry: root } });
    }
    for p in &mut out.vertices {
        let original = *p;
        *p = Point3::from(p.coords * scale);
        if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
            let value = [original.x, original.y, original.z].into_iter().find(|v| !(v * scale).is_finite());
            return Err(MeshReadError::NonFinite {
                format: FORMAT,
                place: Place::Entry { entry: root },
                value: value.unwrap_or(f64::INFINITY),
            });
        }
    }
    Ok((out, unit, scale))
}

/// Appends `reference`'s object (and its components, recursively) under `outer`.
fn place_object(
    parts: &HashMap<String, Part>,
    reference: &Reference,
    outer: &Transform,
    depth: usize,
    placements: &mut usize,
    out: &mut Geometry,
) -> Result<(), MeshReadError> {
    let error = |problem: String| MeshReadError::Syntax { format: FORMAT, place: reference.place.clone(), problem };
    if depth > MAX_DEPTH {
        return Err(error(format!("components nest deeper than {MAX_DEPTH} levels (a cycle of objects?)")));
    }
    *placements += 1;
    if *placements > MAX_PLACEMENTS {
        return Err(error(format!("the build places more than {MAX_PLACEMENTS} objects; this reader stops there")));
    }
    let Some(object) = parts.get(&reference.part).and_then(|p| p.objects.get(&reference.id)) else {
        return Err(error(format!(
            "objectid {} names no <object> in {}; the file is inconsistent, export it again",
            reference.id, reference.part
        )));
    };
    let transform = then(&reference.transform, outer);
    if !object.triangles.is_empty() {
        if out.triangles.len() + object.triangles.len() > MAX_TRIANGLES {
            return Err(error(format!(
                "the build places more than {MAX_TRIANGLES} triangles; this reader stops there"
            )));
        }
        let base = out.vertices.len();
        out.vertices.extend(object.vertices.iter().map(|p| apply(&transform, p)));
        let mirrored = determinant(&transform) < 0.0;
        out.triangles.extend(
            object.triangles.iter().map(|&[a, b, c]| {
                if mirrored { [base + a, base + c, base + b] } else { [base + a, base + b, base + c] }
            }),
        );
    }
    for component in &object.components {
        place_object(parts, component, &transform, depth + 1, placements, out)?;
    }
    Ok(())
}

/// Triangles `reference` places (saturating), memoised per object; a missing object or a
/// nesting deeper than [`MAX_DEPTH`] counts 0 here and is reported by [`place_object`].
fn count_triangles(
    parts: &HashMap<String, Part>,
    reference: &Reference,
    depth: usize,
    memo: &mut HashMap<(String, String), u128>,
) -> u128 {
    if depth > MAX_DEPTH {
        return 0;
    }
    let key = (reference.part.clone(), reference.id.clone());
    if let Some(&n) = memo.get(&key) {
        return n;
    }
    let Some(object) = parts.get(&reference.part).and_then(|p| p.objects.get(&reference.id)) else { return 0 };
    let mut n = object.triangles.len() as u128;
    for c in &object.components {
        n = n.saturating_add(count_triangles(parts, c, depth + 1, memo));
    }
    memo.insert(key, n);
    n
}

/// A zip reader's complaint in words (its messages may name internal types).
fn zip_words(e: &zip::result::ZipError) -> String {
    use zip::result::ZipError;
    match e {
        ZipError::Io(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            "the archive ends early: it is truncated (an incomplete download or copy)".to_string()
        }
        ZipError::Io(io) => format!("the archive cannot be read: {io}"),
        ZipError::InvalidArchive(msg) => {
            let what = if msg.contains("EOCD") {
                "the zip's end record (end of central directory) is missing: the file is cut short or is not a zip"
            } else if msg.contains("CentralEntry") {
                "an entry of the zip's table of contents (central directory) is cut short or damaged"
            } else if msg.contains("LocalEntry") {
                "the header of a file inside the zip is cut short or damaged"
            } else if msg.contains("CentralDirectoryEnd") || msg.to_lowercase().contains("central directory") {
                "the zip's table of contents (central directory) is missing or damaged"
            } else {
                "the zip structure is damaged"
            };
            let detail: Vec<&str> = msg.split_whitespace().map(|w| w.rsplit("::").next().unwrap_or(w)).collect();
            format!("{what}; the file is not a complete zip archive ({})", detail.join(" "))
        }
        ZipError::UnsupportedArchive(what) => {
            format!("the archive uses a zip feature this reader does not support ({what})")
        }
        ZipError::FileNotFound => "a file the archive lists is missing from it".to_string(),
        ZipError::InvalidPassword => "the archive is encrypted".to_string(),
        ZipError::CompressionMethodNotSupported(m) => {
            format!("a file is compressed with method {m}, which this reader does not support (use deflate or store)")
        }
        other => other.to_string(),
    }
}

/// The model part named by the root relationship, else the usual name.
fn root_part_name(zip: &mut ZipArchive<Cursor<&[u8]>>) -> String {
    let Ok(rels) = read_entry(zip, RELS) else { return DEFAULT_MODEL.to_string() };
    let Ok(rels) = std::str::from_utf8(&rels) else { return DEFAULT_MODEL.to_string() };
    let mut reader = Reader::from_str(rels);
    loop {
        match reader.read_event() {
            Ok(Event::Start(e) | Event::Empty(e)) if e.local_name().as_ref() == "Relationship" => {
                let (mut kind, mut target) = (None, None);
                for attr in e.attributes().flatten() {
                    match attr.key.local_name().as_ref() {
                        "Type" => kind = Some(attr.value.to_string()),
                        "Target" => target = Some(attr.value.to_string()),
                        _ => {}
                    }
                }
                if let (Some(kind), Some(target)) = (kind, target)
                    && kind.ends_with("/3dmodel")
                {
                    return target.trim_start_matches('/').to_string();
                }
            }
            Ok(Event::Eof) | Err(_) => return DEFAULT_MODEL.to_string(),
            Ok(_) => {}
        }
    }
}

/// The bytes of entry `name` (leading `/` and ASCII case ignored).
fn read_entry(zip: &mut ZipArchive<Cursor<&[u8]>>, name: &str) -> Result<Vec<u8>, MeshReadError> {
    let wanted = name.trim_start_matches('/');
    let found = (0..zip.len()).find(|&i| {
        zip.name_for_index(i)
            .and_then(Result::ok)
            .is_some_and(|n| n.trim_start_matches('/').eq_ignore_ascii_case(wanted))
    });
    let Some(index) = found else {
        return Err(MeshReadError::MissingModel { looked_for: wanted.to_string(), entries: zip.len() });
    };
    let place = || Place::Entry { entry: wanted.to_string() };
    let entry = zip.by_index(index).map_err(|e| MeshReadError::ZipEntry { place: place(), reason: zip_words(&e) })?;
    let declared = entry.size();
    if declared > MAX_PART_BYTES {
        return Err(MeshReadError::ZipEntry {
            place: place(),
            reason: format!(
                "it declares {declared} bytes once decompressed, over the cap of {MAX_PART_BYTES} bytes (1 GiB); \
                 a 3MF part that large is a zip bomb or a part to split"
            ),
        });
    }
    let mut data = Vec::with_capacity(usize::try_from(declared.min(1 << 24)).unwrap_or(0));
    entry
        .take(MAX_PART_BYTES + 1)
        .read_to_end(&mut data)
        .map_err(|e| MeshReadError::ZipEntry { place: place(), reason: format!("its data is damaged: {e}") })?;
    if data.len() as u64 > MAX_PART_BYTES {
        return Err(MeshReadError::ZipEntry {
            place: place(),
            reason: format!(
                "it decompresses to more than {MAX_PART_BYTES} bytes (1 GiB) although it declares {declared}; \
                 the archive is damaged or a zip bomb"
            ),
        });
    }
    Ok(data)
}

/// Parse state: the element stack, and the line reached (counted as the
/// reader advances, so finding an element's line costs nothing extra).
struct Parser<'x> {
    xml: &'x str,
    stack: Vec<String>,
    line: usize,
    counted: usize,
}

impl Parser<'_> {
    /// Moves the line count up to byte `pos`.
    fn advance(&mut self, pos: u64) {
        let end = usize::try_from(pos).unwrap_or(usize::MAX).min(self.xml.len()).max(self.counted);
        self.line += self.xml.as_bytes()[self.counted..end].iter().filter(|&&b| b == b'\n').count();
        self.counted = end;
    }

    fn parent_is(&self, path: &[&str]) -> bool {
        self.stack.len() >= path.len()
            && self.stack[self.stack.len() - path.len()..].iter().zip(path).all(|(a, b)| a == b)
    }
}

/// One element's attributes, by local name, borrowed from the element.
struct Attrs<'e> {
    pairs: Vec<(&'e str, Cow<'e, str>)>,
}

impl Attrs<'_> {
    fn get(&self, name: &str) -> Option<&str> {
        self.pairs.iter().find(|(k, _)| *k == name).map(|(_, v)| v.as_ref())
    }
}

fn parse_part(bytes: &[u8], entry: &str, is_root: bool) -> Result<Part, MeshReadError> {
    let xml = std::str::from_utf8(bytes).map_err(|e| {
        let bad = e.valid_up_to();
        let line = 1 + bytes[..bad].iter().filter(|&&b| b == b'\n').count();
        MeshReadError::NotText {
            format: FORMAT,
            place: Place::Xml { entry: entry.to_string(), line, element: String::new() },
            byte: bytes[bad],
        }
    })?;
    let mut p = Parser { xml, stack: Vec::new(), line: 1, counted: 0 };
    let mut reader = Reader::from_str(xml);
    let mut part = Part::default();
    let mut seen_model = false;
    let mut current: Option<(String, Object)> = None;
    loop {
        p.advance(reader.buffer_position());
        let event = match reader.read_event() {
            Ok(event) => event,
            Err(e) => {
                p.advance(reader.error_position());
                let element = p.stack.last().cloned().unwrap_or_default();
                return Err(MeshReadError::Syntax {
                    format: FORMAT,
                    place: Place::Xml { entry: entry.to_string(), line: p.line, element },
                    problem: format!("malformed XML ({e}); the file is damaged, export it again"),
                });
            }
        };
        let (element, is_empty) = match event {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(_) => {
                if p.stack.pop().as_deref() == Some("object")
                    && let Some((id, object)) = current.take()
                {
                    part.objects.insert(id, object);
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        let name = element.local_name().as_ref().to_string();
        let line = p.line;
        let place = || Place::Xml { entry: entry.to_string(), line, element: name.clone() };
        let attrs = attributes(&element, &place)?;
        let syntax = |problem: String| MeshReadError::Syntax { format: FORMAT, place: place(), problem };
        match name.as_str() {
            "model" if p.stack.is_empty() => {
                seen_model = true;
                if let Some(unit) = attrs.get("unit") {
                    let Some(u) = UNITS.iter().find(|u| u.name == unit.trim()) else {
                        return Err(syntax(format!(
                            "unknown unit '{unit}'; expected micron, millimeter, centimeter, inch, foot or meter"
                        )));
                    };
                    part.unit = Some(*u);
                }
            }
            "object" if p.parent_is(&["resources"]) => {
                let id = required(&attrs, "id", &syntax)?.trim().to_string();
                current = Some((id, Object::default()));
            }
            "vertex" if p.parent_is(&["object", "mesh", "vertices"]) => {
                if let Some((_, object)) = current.as_mut() {
                    let mut xyz = [0.0; 3];
                    for (value, axis) in xyz.iter_mut().zip(["x", "y", "z"]) {
                        *value = number(&attrs, axis, &syntax)?;
                        if !value.is_finite() {
                            return Err(MeshReadError::NonFinite { format: FORMAT, place: place(), value: *value });
                        }
                    }
                    object.vertices.push(Point3::new(xyz[0], xyz[1], xyz[2]));
                }
            }
            "triangle" if p.parent_is(&["object", "mesh", "triangles"]) => {
                if let Some((_, object)) = current.as_mut() {
                    let mut t = [0usize; 3];
                    for (slot, key) in t.iter_mut().zip(["v1", "v2", "v3"]) {
                        let text = required(&attrs, key, &syntax)?;
                        let Ok(index) = text.trim().parse::<i64>() else {
                            return Err(syntax(format!("{key}=\"{text}\" is not a vertex index")));
                        };
                        *slot =
                            usize::try_from(index).ok().filter(|&i| i < object.vertices.len()).ok_or_else(|| {
                                MeshReadError::BadIndex {
                                    format: FORMAT,
                                    place: place(),
                                    index,
                                    vertex_count: object.vertices.len(),
                                    rule: RULE,
                                }
                            })?;
                    }
                    object.triangles.push(t);
                }
            }
            "component" if p.parent_is(&["object", "components"]) => {
                let reference = reference(&attrs, entry, place(), &syntax)?;
                if !is_root && reference.part != entry {
                    return Err(syntax("a non-root model part refers to another part; not allowed by 3MF".to_string()));
                }
                if let Some((_, object)) = current.as_mut() {
                    object.components.push(reference);
                }
            }
            "item" if p.parent_is(&["build"]) && is_root => {
                part.items.push(reference(&attrs, entry, place(), &syntax)?);
            }
            _ => {}
        }
        if !is_empty {
            p.stack.push(name);
        } else if name == "object"
            && let Some((id, object)) = current.take()
        {
            part.objects.insert(id, object);
        }
    }
    if !seen_model {
        return Err(MeshReadError::Syntax {
            format: FORMAT,
            place: Place::Entry { entry: entry.to_string() },
            problem: "no <model> root element; this is not a 3MF model part".to_string(),
        });
    }
    Ok(part)
}

fn attributes<'e>(element: &'e BytesStart<'_>, place: &impl Fn() -> Place) -> Result<Attrs<'e>, MeshReadError> {
    let mut pairs = Vec::new();
    for attr in element.attributes() {
        let attr = attr.map_err(|e| MeshReadError::Syntax {
            format: FORMAT,
            place: place(),
            problem: format!("malformed attribute ({e}); the file is damaged, export it again"),
        })?;
        pairs.push((attr.key.local_name().into_inner(), attr.value));
    }
    Ok(Attrs { pairs })
}

fn required<'a>(
    attrs: &'a Attrs<'_>,
    key: &str,
    syntax: &impl Fn(String) -> MeshReadError,
) -> Result<&'a str, MeshReadError> {
    attrs.get(key).ok_or_else(|| syntax(format!("the '{key}' attribute is missing")))
}

fn number(attrs: &Attrs<'_>, key: &str, syntax: &impl Fn(String) -> MeshReadError) -> Result<f64, MeshReadError> {
    let text = required(attrs, key, syntax)?;
    text.trim().parse::<f64>().map_err(|_| syntax(format!("{key}=\"{text}\" is not a number")))
}

/// A build item or component: `objectid`, optional `transform` and production `path`.
fn reference(
    attrs: &Attrs<'_>,
    entry: &str,
    place: Place,
    syntax: &impl Fn(String) -> MeshReadError,
) -> Result<Reference, MeshReadError> {
    let id = required(attrs, "objectid", syntax)?.trim().to_string();
    let part = attrs.get("path").map_or_else(|| entry.to_string(), |p| p.trim().trim_start_matches('/').to_string());
    let mut transform = IDENTITY;
    if let Some(text) = attrs.get("transform") {
        let values: Vec<&str> = text.split_ascii_whitespace().collect();
        let numbers: Vec<f64> = values.iter().filter_map(|v| v.parse::<f64>().ok()).collect();
        if values.len() != 12 || numbers.len() != 12 || numbers.iter().any(|v| !v.is_finite()) {
            return Err(syntax(format!(
                "transform=\"{text}\" is not 12 finite numbers (m00 m01 m02 m10 m11 m12 m20 m21 m22 m30 m31 m32)"
            )));
        }
        for (k, v) in numbers.into_iter().enumerate() {
            transform[k / 3][k % 3] = v;
        }
    }
    Ok(Reference { part, id, transform, place })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_compose_in_row_vector_order() {
        // Scale by 2, then translate by (1, 0, 0).
        let scale: Transform = [[2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0], [0.0, 0.0, 0.0]];
        let shift: Transform = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]];
        let p = apply(&then(&scale, &shift), &Point3::new(1.0, 1.0, 1.0));
        assert_eq!(p, Point3::new(3.0, 2.0, 2.0));
        let q = apply(&then(&shift, &scale), &Point3::new(1.0, 1.0, 1.0));
        assert_eq!(q, Point3::new(4.0, 2.0, 2.0));
        assert!(determinant(&scale) > 0.0);
    }
}
