//! Cutter-location files: the one CL format of scallop, the CSV that `scallop run`,
//! `demo` and `optimize` write as `toolpath.csv` ([`write_cl`]) and that `scallop post`
//! and `scallop simulate --toolpath` read ([`read_cl`]), with an optional tool axis and
//! feed per row.
//!
//! Format: a header line naming the columns, then one move per line. Required columns:
//! `kind` (`rapid`, `plunge`, `feed`, `link`, `retract`), `x`, `y`, `z` (mm, part frame,
//! tool tip). Optional: `i`, `j`, `k` (tool axis from the tip towards the spindle, any
//! length > 0, normalised on reading; all three or none; default +Z) and `feed` (mm/min).
//! Columns may come in any order; blank lines and lines starting with `#` are skipped.
//!
//! ```
//! use scallop_io::cl::read_cl_csv;
//! let rows = read_cl_csv("kind,x,y,z,i,j,k\nrapid,0,0,10,0,0,1\nfeed,5,0,0,0,0.6,0.8\n").unwrap();
//! assert_eq!(rows.len(), 2);
//! assert!((rows[1].axis.y - 0.6).abs() < 1e-15);
//! ```

use scallop_geom::{Point3, Vec3};
use scallop_toolpath::{Move, MoveKind, Toolpath};

/// The CSV word of a move kind.
#[must_use]
pub fn kind_name(kind: MoveKind) -> &'static str {
    match kind {
        MoveKind::Rapid => "rapid",
        MoveKind::Plunge => "plunge",
        MoveKind::Feed => "feed",
        MoveKind::Link => "link",
        MoveKind::Retract => "retract",
    }
}

/// Writes `path` as a CL file: `kind,x,y,z`, plus `i,j,k` when the path carries
/// tool axes other than +Z and `feed` when some moves carry a feed of their own
/// (empty where they do not). Numbers in the shortest form that reads back to the
/// same `f64`, so [`read_cl`] returns the same path.
///
/// ```
/// use scallop_geom::{Point3, Vec3};
/// use scallop_io::cl::{read_cl, write_cl};
/// use scallop_toolpath::{Move, MoveKind, Toolpath};
/// let mut path = Toolpath::new(1200.0);
/// path.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 10.0)));
/// path.push_with_axis(Move::new(MoveKind::Feed, Point3::new(5.0, 0.0, 0.0)), Vec3::new(0.0, 0.6, 0.8));
/// let text = write_cl(&path);
/// assert_eq!(text, "kind,x,y,z,i,j,k\nrapid,0,0,10,0,0,1\nfeed,5,0,0,0,0.6,0.8\n");
/// assert_eq!(read_cl(&text, 1200.0).unwrap().moves(), path.moves());
/// ```
#[must_use]
pub fn write_cl(path: &Toolpath) -> String {
    use std::fmt::Write as _;
    let (axes, feeds) = (path.has_tool_axes(), path.has_feeds());
    let mut out = String::from("kind,x,y,z");
    if axes {
        out.push_str(",i,j,k");
    }
    if feeds {
        out.push_str(",feed");
    }
    out.push('\n');
    for (i, m) in path.moves().iter().enumerate() {
        // Writing into a String cannot fail.
        let _ = write!(out, "{},{},{},{}", kind_name(m.kind), m.to.x, m.to.y, m.to.z);
        if axes {
            let a = path.axis(i);
            let _ = write!(out, ",{},{},{}", a.x, a.y, a.z);
        }
        if feeds {
            out.push(',');
            if let Some(f) = path.feed_override(i) {
                let _ = write!(out, "{f}");
            }
        }
        out.push('\n');
    }
    out
}

/// Reads a CL file (see the module documentation) into a toolpath whose cutting
/// feed is `default_feed` (mm/min; plunges at half of it) where a row gives none.
///
/// # Errors
/// [`ClError`] naming the line and column of the first problem.
pub fn read_cl(text: &str, default_feed: f64) -> Result<Toolpath, ClError> {
    let rows = read_cl_csv(text)?;
    let mut path = Toolpath::new(default_feed);
    for r in &rows {
        path.set_feed_from(r.feed);
        path.push_with_axis(Move::new(r.kind, r.tip), r.axis);
    }
    path.set_feed_from(None);
    Ok(path)
}

/// One cutter-location row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClRow {
    /// Kind of move into this location.
    pub kind: MoveKind,
    /// Tool tip (mm).
    pub tip: Point3,
    /// Unit tool axis.
    pub axis: Vec3,
    /// Programmed feed (mm/min), when the file gives one.
    pub feed: Option<f64>,
}

/// What is wrong with a CL file, and where.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ClError {
    /// The header misses a column or repeats one.
    #[error("line {line}: {problem}; the header must name kind,x,y,z and optionally i,j,k and feed")]
    Header {
        /// 1-based line of the header (after blank and `#` lines).
        line: usize,
        /// What is wrong.
        problem: String,
    },
    /// A value cannot be read.
    #[error("line {line}, column `{column}`: {problem}")]
    Value {
        /// 1-based line.
        line: usize,
        /// Column name.
        column: String,
        /// What is wrong and the fix.
        problem: String,
    },
    /// No move at all.
    #[error("the file holds no move; give at least one line after the header")]
    Empty,
}

/// Reads a CL CSV (see the module documentation).
///
/// # Errors
/// [`ClError`] naming the line and column of the first problem.
pub fn read_cl_csv(text: &str) -> Result<Vec<ClRow>, ClError> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((header_index, header)) = lines.next() else { return Err(ClError::Empty) };
    let header_line = header_index + 1;
    let names: Vec<String> = header.split(',').map(|c| c.trim().to_ascii_lowercase()).collect();
    let find = |name: &str| -> Result<Option<usize>, ClError> {
        let hits: Vec<usize> = names.iter().enumerate().filter(|(_, n)| *n == name).map(|(i, _)| i).collect();
        match hits.len() {
            0 => Ok(None),
            1 => Ok(Some(hits[0])),
            _ => Err(ClError::Header {
                line: header_line,
                problem: format!("column `{name}` appears {} times", hits.len()),
            }),
        }
    };
    let required = |name: &str| -> Result<usize, ClError> {
        find(name)?.ok_or_else(|| ClError::Header { line: header_line, problem: format!("no `{name}` column") })
    };
    let (ck, cx, cy, cz) = (required("kind")?, required("x")?, required("y")?, required("z")?);
    let axis_cols = [find("i")?, find("j")?, find("k")?];
    let axis_cols = match axis_cols {
        [Some(i), Some(j), Some(k)] => Some([i, j, k]),
        [None, None, None] => None,
        _ => {
            return Err(ClError::Header {
                line: header_line,
                problem: "the tool axis needs all of i, j, k (or none)".into(),
            });
        }
    };
    let cf = find("feed")?;
    let mut rows = Vec::new();
    for (index, line) in lines {
        let line_no = index + 1;
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != names.len() {
            return Err(ClError::Value {
                line: line_no,
                column: "*".into(),
                problem: format!(
                    "{} fields where the header names {}; give one value per column",
                    fields.len(),
                    names.len()
                ),
            });
        }
        let number = |c: usize| -> Result<f64, ClError> {
            let v: f64 = fields[c].parse().map_err(|_| ClError::Value {
                line: line_no,
                column: names[c].clone(),
                problem: format!("`{}` is not a number", fields[c]),
            })?;
            if v.is_finite() && v.abs() <= crate::gcode::MAX_COORDINATE {
                Ok(v)
            } else {
                Err(ClError::Value {
                    line: line_no,
                    column: names[c].clone(),
                    problem: format!(
                        "{v:e} is not a finite number within +-{:e} (mm, mm/min or a unit axis); fix the value",
                        crate::gcode::MAX_COORDINATE
                    ),
                })
            }
        };
        let word = fields[ck].to_ascii_lowercase();
        let kinds = [MoveKind::Rapid, MoveKind::Plunge, MoveKind::Feed, MoveKind::Link, MoveKind::Retract];
        let kind = match kinds.into_iter().find(|&k| kind_name(k) == word) {
            Some(kind) => kind,
            None => {
                let other = word.as_str();
                return Err(ClError::Value {
                    line: line_no,
                    column: "kind".into(),
                    problem: format!("`{other}` is not a move kind; use rapid, plunge, feed, link or retract"),
                });
            }
        };
        let tip = Point3::new(number(cx)?, number(cy)?, number(cz)?);
        let axis = match axis_cols {
            None => Vec3::z(),
            Some([i, j, k]) => {
                let a = Vec3::new(number(i)?, number(j)?, number(k)?);
                let n = a.norm();
                if !(n > 0.0 && n.is_finite()) {
                    return Err(ClError::Value {
                        line: line_no,
                        column: "i,j,k".into(),
                        problem: "the tool axis is zero; give a non-zero vector".into(),
                    });
                }
                a / n
            }
        };
        let feed = match cf {
            None => None,
            Some(c) if fields[c].is_empty() => None,
            Some(c) => {
                let f = number(c)?;
                if f <= 0.0 {
                    return Err(ClError::Value {
                        line: line_no,
                        column: "feed".into(),
                        problem: format!("{f} mm/min; a feed must be > 0 (leave it empty to use the default)"),
                    });
                }
                Some(f)
            }
        };
        rows.push(ClRow { kind, tip, axis, feed });
    }
    if rows.is_empty() {
        return Err(ClError::Empty);
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// write then read gives the same moves, axes and feeds, bit for bit, for
    /// random paths with and without axes and feeds.
    #[test]
    fn write_then_read_is_the_identity() {
        use proptest::prelude::*;
        let kinds = [MoveKind::Rapid, MoveKind::Plunge, MoveKind::Feed, MoveKind::Link, MoveKind::Retract];
        let coordinate = -1e4f64..1e4;
        let row = (
            0..5usize,
            [coordinate.clone(), coordinate.clone(), coordinate],
            prop::option::of(0usize..3),
            prop::option::of(1.0f64..1e4),
        );
        proptest!(|(rows in prop::collection::vec(row, 1..40), tilted in any::<bool>())| {
            let mut path = Toolpath::new(1500.0);
            for (k, [x, y, z], axis, feed) in rows {
                path.set_feed_from(feed);
                let m = Move::new(kinds[k], Point3::new(x, y, z));
                match axis {
                    Some(a) if tilted => path.push_with_axis(m, [Vec3::z(), Vec3::new(0.3, -0.2, 0.9), Vec3::x()][a]),
                    _ => path.push(m),
                }
            }
            path.set_feed_from(None);
            let back = read_cl(&write_cl(&path), 1500.0).unwrap();
            prop_assert_eq!(back.moves(), path.moves());
            for i in 0..path.moves().len() {
                prop_assert!((back.axis(i) - path.axis(i)).norm() <= 1e-15);
                prop_assert_eq!(back.feed_of(i).to_bits(), path.feed_of(i).to_bits());
            }
        });
    }

    #[test]
    fn reads_the_finishing_csv_and_defaults_the_axis() {
        let rows = read_cl_csv("kind,x,y,z\nrapid,0,0,10\nplunge,0,0,0\nfeed,1.5,-2,0.25\n").unwrap();
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[2].kind, MoveKind::Feed);
        assert_eq!(rows[2].tip, Point3::new(1.5, -2.0, 0.25));
        assert_eq!(rows[2].axis, Vec3::z());
        assert_eq!(rows[2].feed, None);
    }

    #[test]
    fn columns_in_any_order_with_feed_and_a_normalised_axis() {
        let rows = read_cl_csv("feed,k,j,i,z,y,x,kind\n1200,2,0,0,3,2,1,feed\n").unwrap();
        assert_eq!(rows[0].tip, Point3::new(1.0, 2.0, 3.0));
        assert_eq!(rows[0].axis, Vec3::z());
        assert_eq!(rows[0].feed, Some(1200.0));
    }

    #[test]
    fn errors_name_the_line_and_column() {
        // (file, what the message starts with or contains)
        let cases = [
            ("kind,x,y,z\nfeed,1,2,3\nfeed,1,nan,3\n", "line 3, column `y`"),
            ("kind,x,y,z\ndrill,1,2,3\n", "not a move kind"),
            ("kind,x,y\n", "no `z` column"),
            ("kind,x,y,z,i,j\n", "i, j, k"),
            ("kind,x,y,z,i,j,k\nfeed,0,0,0,0,0,0\n", "zero"),
            ("kind,x,y,z\nfeed,1,2\n", "3 fields where the header names 4"),
            // The header's own line, after comments and blank lines.
            ("# exported\n\n# by hand\nkind,x,y\nfeed,1,2\n", "line 4: no `z` column"),
            ("kind,x,y,z\nfeed,1e300,2,3\n", "line 2, column `x`"),
        ];
        for (text, expected) in cases {
            let e = read_cl_csv(text).unwrap_err().to_string();
            let placed = if expected.starts_with("line ") { e.starts_with(expected) } else { e.contains(expected) };
            assert!(placed, "{text:?}: {e}");
        }
        assert_eq!(read_cl_csv("kind,x,y,z\n"), Err(ClError::Empty));
        assert_eq!(read_cl_csv(""), Err(ClError::Empty));
    }
}
