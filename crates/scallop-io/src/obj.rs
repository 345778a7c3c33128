//! Wavefront OBJ: `v x y z [w]` and `f` statements; everything else
//! (`vt`, `vn`, `g`, `o`, `usemtl`, `mtllib`, `s`, `l`, ...) is skipped unread.
//!
//! A face is `f a b c ...` with each corner `v`, `v/vt`, `v//vn` or `v/vt/vn`;
//! `v` counts from 1, or back from the last vertex when negative (-1 is the
//! vertex just above). Only vertices defined above the face count. Polygons
//! are fan-triangulated from their first corner.

use scallop_geom::Point3;

use crate::text::{Lines, Token};
use crate::{Geometry, MeshFormat, MeshReadError, Place};

const FORMAT: MeshFormat = MeshFormat::Obj;
const RULE: &str = "OBJ indices count from 1, negative ones back from the last vertex, and only vertices above the face \
                    line count";

pub(crate) fn read(bytes: &[u8], scale: f64) -> Result<Geometry, MeshReadError> {
    let mut geometry = Geometry::default();
    let mut corners: Vec<usize> = Vec::new();
    let mut lines = Lines::new(bytes, 0, 1);
    for line in lines.by_ref() {
        let text = match line.text.iter().position(|&b| b == b'#') {
            Some(n) => &line.text[..n],
            None => line.text,
        };
        let line = crate::text::Line { text, ..line };
        let mut tokens = line.tokens();
        let Some(keyword) = tokens.next() else { continue };
        match keyword.text {
            b"v" => {
                let mut p = [0.0; 3];
                for (axis, (value, name)) in p.iter_mut().zip(["x", "y", "z"]).enumerate() {
                    let Some(t) = tokens.next() else {
                        return Err(syntax(
                            line.number,
                            format!("'v' has {axis} coordinates; each vertex needs x y z"),
                        ));
                    };
                    let Some(v) = t.as_f64(FORMAT)? else {
                        return Err(syntax(
                            line.number,
                            format!("the {name} coordinate {} is not a number", t.shown()),
                        ));
                    };
                    *value = v * scale;
                    if !value.is_finite() {
                        return Err(MeshReadError::NonFinite { format: FORMAT, place: t.place(), value: v });
                    }
                }
                geometry.vertices.push(Point3::new(p[0], p[1], p[2]));
            }
            b"f" | b"fo" => {
                corners.clear();
                for t in tokens {
                    corners.push(vertex_index(&t, geometry.vertices.len())?);
                }
                if corners.len() < 3 {
                    return Err(syntax(
                        line.number,
                        format!("this face has {} corners; a face needs at least 3", corners.len()),
                    ));
                }
                for k in 1..corners.len() - 1 {
                    geometry.triangles.push([corners[0], corners[k], corners[k + 1]]);
                }
            }
            _ => {
                // Skipped statement; its keyword must still be text, so that a
                // binary file given as OBJ is not silently read as empty.
                keyword.as_str(FORMAT)?;
                if keyword.text.contains(&0) {
                    return Err(MeshReadError::NotText {
                        format: FORMAT,
                        place: Place::LineByte { line: line.number, byte: keyword.offset as u64 },
                        byte: 0,
                    });
                }
            }
        }
    }
    if geometry.triangles.is_empty() {
        return Err(MeshReadError::NoTriangles { format: FORMAT, place: Place::Line { line: lines.last_number() } });
    }
    Ok(geometry)
}

/// The 0-based vertex of a face corner `v[/vt[/vn]]`, given `defined` vertices so far.
fn vertex_index(t: &Token<'_>, defined: usize) -> Result<usize, MeshReadError> {
    let text = t.as_str(FORMAT)?;
    let head = text.split('/').next().unwrap_or(text);
    let Ok(index) = head.parse::<i64>() else {
        return Err(syntax(
            t.line,
            format!("face corner {} is not a vertex index (expected v, v/vt, v//vn or v/vt/vn)", t.shown()),
        ));
    };
    let resolved = if index > 0 {
        usize::try_from(index - 1).ok().filter(|&i| i < defined)
    } else if index < 0 {
        usize::try_from(index.unsigned_abs()).ok().and_then(|back| defined.checked_sub(back))
    } else {
        None
    };
    resolved.ok_or(MeshReadError::BadIndex {
        format: FORMAT,
        place: t.place(),
        index,
        vertex_count: defined,
        rule: RULE,
    })
}

fn syntax(line: usize, problem: String) -> MeshReadError {
    MeshReadError::Syntax { format: FORMAT, place: Place::Line { line }, problem }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_forms_and_fans() {
        let text = "# cube corner\nv 0 0 0\nv 1 0 0 1.0\nv 1 1 0\nv 0 1 0 0.5 0.5 0.5\nvt 0 0\nvn 0 0 1\n\
                    g quad\nusemtl steel\nf 1/1/1 2//1 3/1 -1 # quad\nf -4 -3 -2\n";
        let g = read(text.as_bytes(), 1.0).unwrap();
        assert_eq!(g.vertices.len(), 4);
        assert_eq!(g.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 2]]);
    }

    #[test]
    fn bad_indices_name_the_line() {
        for (face, want) in [
            ("f 1 2 0", "line 4: vertex index 0 is out of range"),
            ("f 1 2 4", "line 4: vertex index 4 is out of range: 3 vertices"),
            ("f 1 2 -4", "line 4: vertex index -4"),
            ("f 1 2 x", "line 4: face corner 'x' is not a vertex index"),
            ("f 1 2", "line 4: this face has 2 corners"),
        ] {
            let text = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{face}\n");
            let err = read(text.as_bytes(), 1.0).unwrap_err().to_string();
            assert!(err.contains(want), "{err} (wanted {want})");
        }
    }

    #[test]
    fn forward_reference_is_an_error() {
        let err = read(b"f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", 1.0).unwrap_err().to_string();
        assert!(err.contains("line 1: vertex index 1"), "{err}");
    }

    #[test]
    fn vertex_errors() {
        let err = read(b"v 0 0\n", 1.0).unwrap_err().to_string();
        assert!(err.contains("line 1: 'v' has 2 coordinates"), "{err}");
        let err = read(b"\nv 0 inf 0\n", 1.0).unwrap_err().to_string();
        assert!(err.contains("line 2: coordinate inf"), "{err}");
        let err = read(b"o caf\xe9\nv 0 0 \xff\n", 1.0).unwrap_err().to_string();
        assert!(err.contains("line 2, byte 13"), "{err}");
        let err = read(b"\0\0\0\0", 1.0).unwrap_err().to_string();
        assert!(err.contains("line 1, byte 0"), "{err}");
        let err = read(b"v 0 0 0\n\n", 1.0).unwrap_err().to_string();
        assert!(err.contains("line 2: the file holds no triangles"), "{err}");
    }
}
