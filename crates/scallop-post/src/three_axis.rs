//! The 3-axis writer: a [`FittedPath`] (lines and `G2`/`G3` arcs in the principal
//! planes; [`FittedPath::lines`] for a toolpath without arcs) in an ISO dialect, optionally after an indexed rotary
//! positioning (3+2: `G0 A.. C..` with the rotaries then held).

use std::io::{self, Write};

use scallop_toolpath::{ArcPlane, FittedPath, MoveKind, Segment};

use crate::dialect::{ArcWords, Dialect};

/// Millimetres per inch (exact by definition).
const MM_PER_INCH: f64 = 25.4;
use crate::fmt_number;

/// Job data printed in a 3-axis program (header templates `{program}`, `{tool}`,
/// `{spindle}`, `{dialect}`, `{version}`; the other template names of [`Dialect`]
/// are left as written).
#[derive(Debug, Clone, PartialEq)]
pub struct ProgramInfo {
    /// Program name or number (`O{program}`).
    pub program: String,
    /// Tool number (the dialect's `tool_change` lines; none when 0).
    pub tool: u32,
    /// Spindle speed (1/min); `S.. M3` after the tool change when > 0.
    pub spindle: f64,
    /// 3+2: rotary words (letter, degrees) written in one rapid block before the first
    /// move, with the rotaries held for the whole program; empty for 3-axis work.
    pub indexed_rotaries: Vec<(String, f64)>,
}

impl ProgramInfo {
    /// Program `1`, no tool change, no spindle word, no rotary positioning.
    #[must_use]
    pub fn anonymous() -> ProgramInfo {
        ProgramInfo { program: "1".into(), tool: 0, spindle: 0.0, indexed_rotaries: Vec::new() }
    }

    fn render(&self, dialect: &Dialect, template: &str) -> String {
        template
            .replace("{program}", &self.program)
            .replace("{tool}", &self.tool.to_string())
            .replace("{spindle}", &fmt_number(self.spindle, 0))
            .replace("{dialect}", &dialect.name)
            .replace("{version}", env!("CARGO_PKG_VERSION"))
    }
}

/// The comment written where a section has no spindle speed (no `S.. M3`):
/// the spindle must already turn, or the job gives the speed.
pub const NO_SPINDLE: &str =
    "no spindle start: no speed given (job: output.spindle, the operation's spindle or the tool library's vc)";

/// Writes `path` (lines and arcs) in `dialect`. `comments` go into the header, one
/// line each. Coordinates are absolute (`G90`, set by the dialect's header) in mm;
/// arcs select their plane (`G17`/`G18`/`G19`) when it changes and carry the
/// centre as `I J K` offsets from the start (or `R`, per [`Dialect::arc_words`]).
///
/// ```
/// use scallop_geom::Point3;
/// use scallop_post::{Dialect, ProgramInfo, write_fitted};
/// use scallop_toolpath::{fit_arcs, Move, MoveKind, Toolpath};
/// let mut path = Toolpath::new(1000.0);
/// path.push(Move::new(MoveKind::Rapid, Point3::new(10.0, 0.0, 0.0)));
/// for i in 1..=90 {
///     let a = f64::from(i).to_radians();
///     path.push(Move::new(MoveKind::Feed, Point3::new(10.0 * a.cos(), 0.0, 10.0 * a.sin())));
/// }
/// let mut out = Vec::new();
/// write_fitted(&fit_arcs(&path, 1e-3), &Dialect::builtin("linuxcnc").unwrap(), &ProgramInfo::anonymous(), &[], &mut out).unwrap();
/// let text = String::from_utf8(out).unwrap();
/// // Seen from +Y (the G18 convention), X towards Z is clockwise.
/// assert!(text.contains("G18 G2 X0.0000 Y0.0000 Z10.0000 I-10.0000 K0.0000 F1000.0"), "{text}");
/// ```
///
/// # Errors
/// Any error of `out`.
pub fn write_fitted(
    path: &FittedPath,
    dialect: &Dialect,
    info: &ProgramInfo,
    comments: &[&str],
    out: &mut impl Write,
) -> io::Result<()> {
    write_header(dialect, info, comments, out)?;
    write_section(path, dialect, info, out)?;
    write_footer(dialect, info, out)
}

/// One operation of a program written by [`write_sections`]: its moves, its
/// tool and spindle (`info.program` is not used) and a comment line naming it.
#[derive(Debug, Clone)]
pub struct Section<'a> {
    /// The moves (lines and arcs).
    pub path: &'a FittedPath,
    /// Tool number, spindle speed and indexed rotaries of the operation.
    pub info: ProgramInfo,
    /// A comment written before the operation's tool change.
    pub title: String,
}

/// A program of several operations (one tool change each): the dialect's header
/// once with `comments`, then per section its title, `M5` before every tool
/// change but the first (the spindle stops before the change), the tool change,
/// the length offset, the spindle start and the moves, then the footer. With one
/// section the text is that of [`write_fitted`] plus the title comment.
///
/// ```
/// use scallop_geom::Point3;
/// use scallop_post::{Dialect, ProgramInfo, Section, write_sections};
/// use scallop_toolpath::{FittedPath, Move, MoveKind, Toolpath};
/// let mut tp = Toolpath::new(1000.0);
/// tp.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 5.0)));
/// tp.push(Move::new(MoveKind::Feed, Point3::new(10.0, 0.0, 0.0)));
/// let lines = FittedPath::lines(&tp);
/// let tool = |t: u32| ProgramInfo { tool: t, spindle: 8000.0, ..ProgramInfo::anonymous() };
/// let sections = [
///     Section { path: &lines, info: tool(1), title: "rough".into() },
///     Section { path: &lines, info: tool(2), title: "finish".into() },
/// ];
/// let mut text = Vec::new();
/// write_sections(&sections, &Dialect::builtin("linuxcnc").unwrap(), "1", &[], &mut text).unwrap();
/// let text = String::from_utf8(text).unwrap();
/// assert!(text.contains("T1 M6\nG43 H1\nS8000 M3"));
/// assert!(text.contains("(finish)\nM5\nT2 M6\nG43 H2\nS8000 M3"), "{text}");
/// assert!(text.ends_with("M2\n"));
/// ```
///
/// # Errors
/// Any error of `out`.
pub fn write_sections(
    sections: &[Section<'_>],
    dialect: &Dialect,
    program: &str,
    comments: &[&str],
    out: &mut impl Write,
) -> io::Result<()> {
    let info = ProgramInfo { program: program.to_string(), ..ProgramInfo::anonymous() };
    write_header(dialect, &info, comments, out)?;
    let (open, close) = (&dialect.comment.0, &dialect.comment.1);
    for (k, section) in sections.iter().enumerate() {
        writeln!(out, "{open}{}{close}", clean_comment(&section.title))?;
        if k > 0 && section.info.tool > 0 {
            writeln!(out, "M5")?;
        }
        write_section(section.path, dialect, &section.info, out)?;
    }
    write_footer(dialect, &info, out)
}

fn clean_comment(c: &str) -> String {
    c.chars().map(|ch| if ch == '(' || ch == ')' { '_' } else { ch }).collect()
}

/// The program's first lines: tape start, the scallop comment, `comments`, the
/// dialect's header.
fn write_header(dialect: &Dialect, info: &ProgramInfo, comments: &[&str], out: &mut impl Write) -> io::Result<()> {
    let (open, close) = (&dialect.comment.0, &dialect.comment.1);
    let mut header = dialect.header.iter();
    // A leading `%` (tape start) must stay the first line.
    if dialect.header.first().is_some_and(|h| h == "%") {
        writeln!(out, "%")?;
        header.next();
    }
    writeln!(out, "{open}scallop {}, dialect: {}{close}", env!("CARGO_PKG_VERSION"), clean_comment(&dialect.name))?;
    for c in comments {
        writeln!(out, "{open}{}{close}", clean_comment(c))?;
    }
    for h in header {
        writeln!(out, "{}", info.render(dialect, h))?;
    }
    Ok(())
}

fn write_footer(dialect: &Dialect, info: &ProgramInfo, out: &mut impl Write) -> io::Result<()> {
    for f in &dialect.footer {
        writeln!(out, "{}", info.render(dialect, f))?;
    }
    Ok(())
}

/// One operation: tool change, length offset, spindle, indexed rotaries, moves.
fn write_section(path: &FittedPath, dialect: &Dialect, info: &ProgramInfo, out: &mut impl Write) -> io::Result<()> {
    if info.tool > 0 {
        for t in &dialect.tool_change {
            writeln!(out, "{}", info.render(dialect, t))?;
        }
        for t in &dialect.length_offset {
            writeln!(out, "{}", info.render(dialect, t))?;
        }
    }
    if info.spindle > 0.0 {
        writeln!(out, "S{} M3", fmt_number(info.spindle, 0))?;
    } else {
        // The footer stops the spindle (`M5`): say that this program never started it.
        let (open, close) = (&dialect.comment.0, &dialect.comment.1);
        writeln!(out, "{open}{NO_SPINDLE}{close}")?;
    }
    if !info.indexed_rotaries.is_empty() {
        let words: Vec<String> = info
            .indexed_rotaries
            .iter()
            .map(|(l, v)| format!("{}{}", dialect.axis_word(l), fmt_number(*v, dialect.rotary_decimals)))
            .collect();
        writeln!(out, "G0 {}", words.join(" "))?;
    }
    let d = dialect.decimals;
    // Inch programs: every linear word and feed divided by 25.4 (units inside are mm).
    let k = if dialect.inch { 1.0 / MM_PER_INCH } else { 1.0 };
    let xyz = |p: &scallop_geom::Point3| {
        format!("X{} Y{} Z{}", fmt_number(k * p.x, d), fmt_number(k * p.y, d), fmt_number(k * p.z, d))
    };
    let mut last_feed: Option<f64> = None;
    let mut plane = ArcPlane::Xy; // every ISO header selects G17
    let mut from: Option<scallop_geom::Point3> = None;
    for seg in &path.segments {
        let feed_word = |kind: MoveKind, last: &mut Option<f64>| -> String {
            let feed = if kind == MoveKind::Plunge { path.plunge_feed } else { path.feed };
            if last.is_some_and(|f: f64| f.to_bits() == feed.to_bits()) {
                String::new()
            } else {
                *last = Some(feed);
                format!(" F{}", fmt_number(k * feed, dialect.feed_decimals))
            }
        };
        match seg {
            Segment::Line(m) => match m.kind {
                MoveKind::Rapid | MoveKind::Retract => {
                    writeln!(out, "G0 {}", xyz(&m.to))?;
                    last_feed = None;
                }
                kind => {
                    let f = feed_word(kind, &mut last_feed);
                    writeln!(out, "G1 {}{f}", xyz(&m.to))?;
                }
            },
            Segment::Arc(a) => {
                let select = if a.plane == plane { String::new() } else { format!("{} ", a.plane.code()) };
                plane = a.plane;
                let code = if a.ccw { "G3" } else { "G2" };
                let centre = match dialect.arc_words {
                    ArcWords::Radius => format!("R{}", fmt_number(k * a.radius(), d)),
                    ArcWords::Ijk => {
                        let start = from.unwrap_or(a.to);
                        let (u, v, _) = a.plane.axes();
                        let letter = |i: usize| ["I", "J", "K"][i];
                        let (mut first, mut second) = (u, v);
                        if first > second {
                            std::mem::swap(&mut first, &mut second);
                        }
                        format!(
                            "{}{} {}{}",
                            letter(first),
                            fmt_number(k * (a.center[first] - start[first]), d),
                            letter(second),
                            fmt_number(k * (a.center[second] - start[second]), d)
                        )
                    }
                };
                let f = feed_word(a.kind, &mut last_feed);
                writeln!(out, "{select}{code} {} {centre}{f}", xyz(&a.to))?;
            }
        }
        from = Some(seg.to());
    }
    if plane != ArcPlane::Xy {
        writeln!(out, "G17")?;
    }
    Ok(())
}
