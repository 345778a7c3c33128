//! G-code output. A [`Dialect`] is data (decimals, header and footer lines);
//! [`write_gcode`] turns a 3-axis [`Toolpath`] into text through `io::Write`.
//!
//! ```
//! use scallop_geom::Point3;
//! use scallop_post::{Dialect, write_gcode};
//! use scallop_toolpath::{Move, MoveKind, Toolpath};
//! let mut path = Toolpath::new(1200.0);
//! path.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 5.0)));
//! path.push(Move::new(MoveKind::Feed, Point3::new(10.0, 0.0, -0.0)));
//! let mut out = Vec::new();
//! write_gcode(&path, &Dialect::plain(), &["demo"], &mut out).unwrap();
//! let text = String::from_utf8(out).unwrap();
//! assert!(text.contains("G1 X10.000 Y0.000 Z0.000 F1200"));
//! ```
//!
//! # Invariants
//! - Output is deterministic: fixed decimals, `-0` written as `0`, modal words
//!   suppressed only by rule.
//! - Units in: mm and mm/min; the only place where numbers become text.

use std::io::{self, Write};

use scallop_toolpath::{MoveKind, Toolpath};

/// A controller dialect as data.
#[derive(Debug, Clone, PartialEq)]
pub struct Dialect {
    /// Name, printed in the header.
    pub name: String,
    /// Decimals of coordinates.
    pub decimals: usize,
    /// Lines before the first move.
    pub header: Vec<String>,
    /// Lines after the last move.
    pub footer: Vec<String>,
    /// Comment delimiters.
    pub comment: (String, String),
}

impl Dialect {
    /// Plain RS-274 (LinuxCNC / Fanuc-compatible subset) in millimetres.
    #[must_use]
    pub fn plain() -> Dialect {
        Dialect {
            name: "plain RS-274, mm".into(),
            decimals: 3,
            header: vec!["G21 G90 G17 G94".into(), "G40 G49 G80".into()],
            footer: vec!["M5".into(), "M30".into()],
            comment: ("(".into(), ")".into()),
        }
    }
}

/// Formats `v` with `decimals` digits, writing negative zero as zero.
///
/// ```
/// assert_eq!(scallop_post::fmt_number(-0.0004, 3), "0.000");
/// assert_eq!(scallop_post::fmt_number(-1.25, 1), "-1.2");
/// ```
#[must_use]
pub fn fmt_number(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') { s[1..].to_string() } else { s }
}

/// Writes `path` as G-code. `comments` go into the header (one line each).
///
/// # Errors
/// Any error of `out`.
pub fn write_gcode(path: &Toolpath, dialect: &Dialect, comments: &[&str], out: &mut impl Write) -> io::Result<()> {
    let (open, close) = (&dialect.comment.0, &dialect.comment.1);
    writeln!(out, "{open}scallop, dialect: {}{close}", dialect.name)?;
    for c in comments {
        let clean: String = c.chars().map(|ch| if ch == '(' || ch == ')' { '_' } else { ch }).collect();
        writeln!(out, "{open}{clean}{close}")?;
    }
    for h in &dialect.header {
        writeln!(out, "{h}")?;
    }
    let d = dialect.decimals;
    let mut last_feed: Option<f64> = None;
    for m in path.moves() {
        let (x, y, z) = (fmt_number(m.to.x, d), fmt_number(m.to.y, d), fmt_number(m.to.z, d));
        match m.kind {
            MoveKind::Rapid | MoveKind::Retract => {
                writeln!(out, "G0 X{x} Y{y} Z{z}")?;
            }
            kind => {
                let feed = if kind == MoveKind::Plunge { path.plunge_feed } else { path.feed };
                if last_feed.is_some_and(|f| f.to_bits() == feed.to_bits()) {
                    writeln!(out, "G1 X{x} Y{y} Z{z}")?;
                } else {
                    writeln!(out, "G1 X{x} Y{y} Z{z} F{}", fmt_number(feed, 0))?;
                    last_feed = Some(feed);
                }
                continue;
            }
        }
        last_feed = None;
    }
    for f in &dialect.footer {
        writeln!(out, "{f}")?;
    }
    Ok(())
}
