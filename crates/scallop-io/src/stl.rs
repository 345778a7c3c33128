//! STL, binary and ASCII.
//!
//! Binary: an 80-byte header, a little-endian `u32` triangle count at byte 80,
//! then 50 bytes per triangle (normal, three corners as `f32`, 2 attribute
//! bytes). A file is binary when `84 + 50 * count == length`, even if its
//! header starts with `solid`. Otherwise it is ASCII when its first 512 bytes
//! hold no NUL and either start with `solid` or are UTF-8 text; anything
//! else is reported as a binary STL whose length does not match its count
//! (a binary header and float data almost never pass as text).
//!
//! Normals are ignored (the winding gives the orientation); `NaN` normals,
//! which some exporters write for slivers, are therefore accepted.

use scallop_geom::Point3;

use crate::text::{Lexer, Token};
use crate::{Geometry, MeshFormat, MeshReadError, Place};

const FORMAT: MeshFormat = MeshFormat::Stl;
const HEADER: usize = 84;
const RECORD: usize = 50;
/// How far to look for a NUL byte when telling text from binary.
const SNIFF: usize = 512;

pub(crate) fn read(bytes: &[u8], scale: f64) -> Result<Geometry, MeshReadError> {
    if let Some(count) = binary_count(bytes) {
        let expected = HEADER as u64 + RECORD as u64 * u64::from(count);
        if expected == bytes.len() as u64 {
            return read_binary(bytes, count, scale);
        }
    }
    if looks_like_text(bytes) {
        return read_ascii(bytes, scale);
    }
    match binary_count(bytes) {
        Some(triangles) => Err(MeshReadError::StlSize {
            triangles,
            expected: HEADER as u64 + RECORD as u64 * u64::from(triangles),
            actual: bytes.len() as u64,
        }),
        None => Err(MeshReadError::Syntax {
            format: FORMAT,
            place: Place::Byte { byte: bytes.len() as u64 },
            problem: format!(
                "the file ends inside the 84-byte binary STL header ({} bytes); the file is truncated",
                bytes.len()
            ),
        }),
    }
}

/// Whether a file whose length is not a binary STL's should be read as ASCII:
/// no NUL byte at its start, and either it starts with `solid` or its start
/// is UTF-8 text.
fn looks_like_text(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(SNIFF)];
    if head.contains(&0) {
        return false;
    }
    let trimmed = head.trim_ascii_start();
    let solid = trimmed.len() >= 5 && trimmed[..5].eq_ignore_ascii_case(b"solid");
    // A UTF-8 sequence cut by the sniff window still counts as text.
    solid || std::str::from_utf8(head).map_or_else(|e| e.error_len().is_none(), |_| true)
}

fn binary_count(bytes: &[u8]) -> Option<u32> {
    let raw: [u8; 4] = bytes.get(80..HEADER)?.try_into().ok()?;
    Some(u32::from_le_bytes(raw))
}

fn read_binary(bytes: &[u8], count: u32, scale: f64) -> Result<Geometry, MeshReadError> {
    if count == 0 {
        return Err(MeshReadError::NoTriangles { format: FORMAT, place: Place::Byte { byte: 80 } });
    }
    // The length was checked against the count, so this allocation is bounded by the input.
    let n = count as usize;
    let mut vertices = Vec::with_capacity(3 * n);
    for (t, record) in bytes[HEADER..].chunks_exact(RECORD).enumerate() {
        for corner in 0..3 {
            let mut p = [0.0; 3];
            for (axis, value) in p.iter_mut().enumerate() {
                let at = 12 + 12 * corner + 4 * axis;
                let raw = [record[at], record[at + 1], record[at + 2], record[at + 3]];
                let v = f64::from(f32::from_le_bytes(raw));
                *value = v * scale;
                if !value.is_finite() {
                    return Err(MeshReadError::NonFinite {
                        format: FORMAT,
                        place: Place::Triangle {
                            index: t as u64,
                            vertex: corner as u8,
                            byte: (HEADER + RECORD * t + at) as u64,
                        },
                        value: v,
                    });
                }
            }
            vertices.push(Point3::new(p[0], p[1], p[2]));
        }
    }
    let triangles = (0..n).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    Ok(Geometry { vertices, triangles })
}

/// The ASCII grammar, keywords case-insensitive, free-form whitespace:
/// `solid [name]` { `facet normal` n n n `outer loop` (`vertex` x y z){3}
/// `endloop` `endfacet` } `endsolid [name]`, repeated for several solids.
/// Names are skipped unread (they may be in any encoding).
fn read_ascii(bytes: &[u8], scale: f64) -> Result<Geometry, MeshReadError> {
    let mut lx = Lexer::new(bytes);
    let mut geometry = Geometry::default();
    let mut solids = 0usize;
    let mut last_end = 1;
    loop {
        let Some(tok) = lx.next_token() else {
            if solids == 0 {
                return Err(syntax(lx.line(), "the file has no 'solid' line (is it an STL file?)".to_string()));
            }
            break;
        };
        if !tok.is("solid") {
            let problem = if solids == 0 {
                format!("expected 'solid' at the start of an ASCII STL, found {} (is it an STL file?)", tok.shown())
            } else {
                format!("expected 'solid' or the end of the file after 'endsolid', found {}", tok.shown())
            };
            // Report text that is not UTF-8 as such: it is the likelier cause.
            tok.as_str(FORMAT)?;
            return Err(syntax(tok.line, problem));
        }
        solids += 1;
        lx.skip_line();
        last_end = read_solid(&mut lx, &mut geometry, scale)?;
    }
    if geometry.triangles.is_empty() {
        return Err(MeshReadError::NoTriangles { format: FORMAT, place: Place::Line { line: last_end } });
    }
    Ok(geometry)
}

/// Reads facets up to and including `endsolid [name]`; returns the line of `endsolid`.
fn read_solid(lx: &mut Lexer<'_>, geometry: &mut Geometry, scale: f64) -> Result<usize, MeshReadError> {
    loop {
        let tok = expect_any(lx, "'facet' or 'endsolid'")?;
        if tok.is("endsolid") {
            lx.skip_line();
            return Ok(tok.line);
        }
        if !tok.is("facet") {
            return Err(unexpected(&tok, "'facet' or 'endsolid'"));
        }
        expect(lx, "normal")?;
        for axis in ["x", "y", "z"] {
            let t = expect_any(lx, "a normal component")?;
            if t.line != tok.line || t.as_f64(FORMAT)?.is_none() {
                return Err(syntax(
                    tok.line,
                    format!("'facet normal' needs 3 numbers; its {axis} component is {}", t.shown()),
                ));
            }
        }
        expect(lx, "outer")?;
        expect(lx, "loop")?;
        let first = geometry.vertices.len();
        for corner in 0..3 {
            let t = expect_any(lx, "'vertex'")?;
            if t.is("endloop") {
                return Err(syntax(
                    t.line,
                    format!("this facet has only {corner} vertices; an STL facet needs exactly 3 'vertex' lines"),
                ));
            }
            if !t.is("vertex") {
                return Err(unexpected(&t, "'vertex'"));
            }
            geometry.vertices.push(read_point(lx, &t, scale)?);
        }
        let t = expect_any(lx, "'endloop'")?;
        if t.is("vertex") {
            return Err(syntax(
                t.line,
                "this facet has more than 3 vertices; STL facets are triangles (export with triangulation on)"
                    .to_string(),
            ));
        }
        if !t.is("endloop") {
            return Err(unexpected(&t, "'endloop'"));
        }
        expect(lx, "endfacet")?;
        geometry.triangles.push([first, first + 1, first + 2]);
    }
}

/// Reads `x y z` after a `vertex` keyword; all three must be on its line.
fn read_point(lx: &mut Lexer<'_>, keyword: &Token<'_>, scale: f64) -> Result<Point3, MeshReadError> {
    let mut p = [0.0; 3];
    for (axis, (value, name)) in p.iter_mut().zip(["x", "y", "z"]).enumerate() {
        let missing = || syntax(keyword.line, format!("'vertex' has {axis} coordinates; each vertex needs x y z"));
        let Some(t) = lx.next_token() else { return Err(missing()) };
        if t.line != keyword.line {
            return Err(missing());
        }
        let Some(v) = t.as_f64(FORMAT)? else {
            return Err(syntax(t.line, format!("the {name} coordinate {} is not a number", t.shown())));
        };
        *value = v * scale;
        if !value.is_finite() {
            return Err(MeshReadError::NonFinite { format: FORMAT, place: t.place(), value: v });
        }
    }
    Ok(Point3::new(p[0], p[1], p[2]))
}

fn expect_any<'a>(lx: &mut Lexer<'a>, what: &str) -> Result<Token<'a>, MeshReadError> {
    lx.next_token().ok_or_else(|| {
        syntax(lx.line(), format!("the file ends where {what} was expected; the file is truncated (no 'endsolid')"))
    })
}

fn expect(lx: &mut Lexer<'_>, word: &str) -> Result<(), MeshReadError> {
    let what = format!("'{word}'");
    let tok = expect_any(lx, &what)?;
    if tok.is(word) { Ok(()) } else { Err(unexpected(&tok, &what)) }
}

/// `expected X, found Y`, or the not-UTF-8 error when Y is not text.
fn unexpected(tok: &Token<'_>, what: &str) -> MeshReadError {
    if let Err(e) = tok.as_str(FORMAT) {
        return e;
    }
    syntax(tok.line, format!("expected {what}, found {}", tok.shown()))
}

fn syntax(line: usize, problem: String) -> MeshReadError {
    MeshReadError::Syntax { format: FORMAT, place: Place::Line { line }, problem }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ascii_tetra() -> String {
        let tris = [
            [[0, 0, 0], [0, 1, 0], [1, 0, 0]],
            [[0, 0, 0], [1, 0, 0], [0, 0, 1]],
            [[0, 0, 0], [0, 0, 1], [0, 1, 0]],
            [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
        ];
        let mut s = String::from("solid tetra\n");
        for t in tris {
            s.push_str("  facet normal 0 0 0\n    outer loop\n");
            for v in t {
                s.push_str(&format!("      vertex {} {} {}\n", v[0], v[1], v[2]));
            }
            s.push_str("    endloop\n  endfacet\n");
        }
        s.push_str("endsolid tetra\n");
        s
    }

    fn binary(tris: &[[[f32; 3]; 3]], header: &[u8]) -> Vec<u8> {
        let mut b = vec![b' '; 80];
        b[..header.len()].copy_from_slice(header);
        b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
        for t in tris {
            b.extend_from_slice(&[0; 12]);
            for v in t {
                for c in v {
                    b.extend_from_slice(&c.to_le_bytes());
                }
            }
            b.extend_from_slice(&[0; 2]);
        }
        b
    }

    #[test]
    fn ascii_tetrahedron() {
        let g = read(ascii_tetra().as_bytes(), 1.0).unwrap();
        assert_eq!(g.triangles.len(), 4);
        assert_eq!(g.vertices.len(), 12);
        assert_eq!(g.vertices[1], Point3::new(0.0, 1.0, 0.0));
    }

    #[test]
    fn ascii_keywords_ignore_case_and_crlf_and_names_in_any_encoding() {
        let text = ascii_tetra().replace("vertex", "VERTEX").replace('\n', "\r\n");
        let mut bytes = text.into_bytes();
        bytes.splice(6..6, b"caf\xe9 ".iter().copied()); // Latin-1 name
        assert_eq!(read(&bytes, 1.0).unwrap().triangles.len(), 4);
    }

    #[test]
    fn binary_with_solid_header_is_binary() {
        let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let b = binary(&[tri, tri], b"solid but binary");
        let g = read(&b, 2.0).unwrap();
        assert_eq!(g.triangles, vec![[0, 1, 2], [3, 4, 5]]);
        assert_eq!(g.vertices[1], Point3::new(2.0, 0.0, 0.0));
    }

    #[test]
    fn binary_nan_names_triangle_and_byte() {
        let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let mut bad = tri;
        bad[1][2] = f32::NAN;
        let err = read(&binary(&[tri, bad], b""), 1.0).unwrap_err();
        // Triangle 1 starts at 134; corner 1 z is at 134 + 12 + 12 + 8.
        assert!(err.to_string().contains("triangle 1, vertex 1 (byte 166)"), "{err}");
    }

    #[test]
    fn huge_count_fails_fast() {
        let mut b = binary(&[], b"");
        b[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        let err = read(&b, 1.0).unwrap_err();
        assert!(matches!(err, MeshReadError::StlSize { triangles: u32::MAX, actual: 84, .. }), "{err}");
    }

    #[test]
    fn ascii_errors_name_lines() {
        let cases: [(&str, &str, &str); 5] = [
            ("vertex 0 1 0\n", "vertex 0 1\n", "line 5: 'vertex' has 2 coordinates"),
            ("vertex 0 1 0\n", "vertex 0 1 nan\n", "line 5: coordinate NaN"),
            ("vertex 0 1 0\n", "vertex 0 1 zero\n", "line 5: the z coordinate 'zero'"),
            ("endsolid tetra\n", "", "the file is truncated"),
            ("outer loop", "outer lop", "line 3: expected 'loop', found 'lop'"),
        ];
        for (from, to, want) in cases {
            let text = ascii_tetra().replacen(from, to, 1);
            let err = read(text.as_bytes(), 1.0).unwrap_err().to_string();
            assert!(err.contains(want), "{err} (wanted {want})");
        }
    }

    #[test]
    fn missing_and_extra_vertex() {
        let text = ascii_tetra();
        let lines: Vec<&str> = text.lines().collect();
        let mut missing = lines.clone();
        missing.remove(4);
        let err = read(missing.join("\n").as_bytes(), 1.0).unwrap_err().to_string();
        assert!(err.contains("line 6: this facet has only 2 vertices"), "{err}");
        let mut extra = lines;
        extra.insert(4, "vertex 5 5 5");
        let err = read(extra.join("\n").as_bytes(), 1.0).unwrap_err().to_string();
        assert!(err.contains("line 7: this facet has more than 3 vertices"), "{err}");
    }

    #[test]
    fn empty_solid_and_nul_bytes() {
        let err = read(b"solid empty\nendsolid empty\n", 1.0).unwrap_err();
        assert!(matches!(err, MeshReadError::NoTriangles { place: Place::Line { line: 2 }, .. }), "{err}");
        let err = read(b"solid \0 short", 1.0).unwrap_err().to_string();
        assert!(err.contains("byte 13"), "{err}");
    }
}
