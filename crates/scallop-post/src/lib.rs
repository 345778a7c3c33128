//! G-code output. A [`Dialect`] is data (decimals, axis words, feed conventions, header
//! and footer templates, line numbering, modal suppression, TCP and tilted-plane codes),
//! loadable from TOML, with built-ins for LinuxCNC, Fanuc, Siemens 840D, Heidenhain
//! (plain language and ISO) and grbl. Two writers:
//! - [`write_gcode`]: a 3-axis [`Toolpath`] (the demo path); [`write_fitted`]: a 3-axis
//!   path with `G2`/`G3` arcs ([`scallop_toolpath::fit_arcs`]) and the job's program,
//!   tool, spindle and 3+2 rotary positioning;
//! - [`write_program`]: a joint-space [`MachineProgram`](scallop_machine::program::MachineProgram)
//!   in joint space with inverse-time feeds, in TCP form, or in tilted work planes
//!   ([`OutputMode`]).
//!
//! [`replay`] reads our own output back into joint motion through the machine's forward
//! kinematics and [`check_replay`] checks it against the input CL path (spec K16).
//! Specification: `kinematics.md` 3.9-3.13; user documentation: `docs/post.md`.
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
//! - Never performs file I/O and never prints: text goes through `io::Write`.
//! - Output is deterministic: fixed decimals, `-0` written as `0`, modal words
//!   suppressed only by rule.
//! - Units in: mm, rad and mm/min; out: mm, deg, mm/min (1/min for G93, s for `FT`).
//!   G93 words are rounded down and `FT` times up, so no axis exceeds its velocity.
//! - Every numeric threshold lives in [`tol`].

use std::io::{self, Write};

use scallop_toolpath::{MoveKind, Toolpath};

pub mod dialect;
pub mod error;
pub mod reader;
pub mod three_axis;
pub mod tol;
pub mod writer;

pub use dialect::{ArcWords, Dialect, FeedByTime, LineNumbers, ModuloWords, Syntax, TcpCodes, TiltedPlane};
pub use error::PostError;
pub use reader::{ReplayedBlock, RoundTrip, check_replay, replay};
pub use three_axis::{ProgramInfo, write_fitted, write_toolpath};
pub use writer::{OutputMode, PostParams, cycle800_angles, program_text, write_program};

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
