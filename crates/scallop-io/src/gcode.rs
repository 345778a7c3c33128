//! A reader of plain 3-axis G-code (RS-274 subset) into a [`Toolpath`], so
//! that programs from other systems can be simulated and verified.
//!
//! Understood: `G0 G1 G2 G3` (circular or helical arcs in the plane `G17` XY,
//! `G18` ZX or `G19` YZ, with `I J K` centre offsets or `R`), `G20 G21` (inches, millimetres), `G90 G91` (absolute,
//! incremental), `F`, `X Y Z`, line numbers `N`, comments `( ... )` and `;`,
//! block delete `/`, and `%`. Spindle, coolant, tool and program words (`S T M
//! O`) and `G40 G43 G49 G54..G59 G80 G94 G64 G61` are accepted and have no
//! effect on the path. Anything else that moves the tool (canned cycles, `G28`, `G53`, `G92`, rotary words `A B C`, ...) is an error naming
//! the line: a simulation must never silently skip motion.
//!
//! `T` selects a tool and `M6` loads it; the simulation uses one cutter, so a change to
//! another tool after the first feed move is an error naming its line.
//!
//! Until the tool's position is known, rapids may give it one axis at a time (`G0 Z50`
//! then `G0 X0 Y0`, as programs for real controllers start); the tool is placed when X, Y
//! and Z are all known, and a feed move before that is an error. Coordinates are bounded by
//! [`MAX_COORDINATE`] after inch scaling and incremental accumulation.
//!
//! Arcs are replaced by chords within `arc_tolerance` (sagitta), so every move
//! of the result is straight.

use scallop_geom::{Point2, Point3};
use scallop_toolpath::{ArcXY, Move, MoveKind, Toolpath};

/// Why a G-code program cannot be read. Lines count from 1.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GcodeError {
    /// A word that is not a letter followed by a number.
    #[error("G-code line {line}: '{word}' is not a word (a letter and a number)")]
    Syntax {
        /// Line number.
        line: usize,
        /// The text.
        word: String,
    },
    /// A code that moves the tool in a way this reader does not follow.
    #[error(
        "G-code line {line}: {code} is not supported ({why}); the simulation would be wrong, so the program is refused"
    )]
    Unsupported {
        /// Line number.
        line: usize,
        /// The code.
        code: String,
        /// Why it matters.
        why: &'static str,
    },
    /// An arc whose end is not on its circle, or with no centre.
    #[error("G-code line {line}: arc is inconsistent ({why})")]
    BadArc {
        /// Line number.
        line: usize,
        /// What is wrong.
        why: String,
    },
    /// A feed move before any position is known, or without a feed rate.
    #[error("G-code line {line}: {why}")]
    State {
        /// Line number.
        line: usize,
        /// What is missing.
        why: &'static str,
    },
    /// The program has no motion at all.
    #[error("the program has no motion (no G0/G1/G2/G3 move with coordinates)")]
    Empty,
    /// A coordinate, centre offset or radius outside the machinable range
    /// ([`MAX_COORDINATE`]) once inch scaling and incremental accumulation are applied.
    #[error(
        "G-code line {line}: {what} = {value:e} mm is outside +-{max:e} mm (after G20 inch scaling and G91 accumulation); fix the number on this line"
    )]
    OutOfRange {
        /// Line number.
        line: usize,
        /// Which value (`X`, `arc centre`, `R`, ...).
        what: String,
        /// The value in mm (possibly infinite).
        value: f64,
        /// The bound, [`MAX_COORDINATE`].
        max: f64,
    },
}

/// Largest absolute coordinate (mm) a program may reach, and largest arc radius: 100 m,
/// far beyond any machine's stroke; beyond it a number is a typo, and near `f64::MAX`
/// arithmetic overflows to infinity.
pub const MAX_COORDINATE: f64 = 1e5;

fn in_range(line: usize, what: &str, value: f64) -> Result<f64, GcodeError> {
    if value.is_finite() && value.abs() <= MAX_COORDINATE {
        Ok(value)
    } else {
        Err(GcodeError::OutOfRange { line, what: what.to_string(), value, max: MAX_COORDINATE })
    }
}

/// Options of [`read_gcode`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GcodeOptions {
    /// Largest distance between an arc and its chords (mm).
    pub arc_tolerance: f64,
    /// Where the tool is before the first move; `None` = unknown (the first
    /// move then only places the tool).
    pub start: Option<Point3>,
}

impl Default for GcodeOptions {
    fn default() -> Self {
        GcodeOptions { arc_tolerance: 0.001, start: None }
    }
}

/// Largest number of chords one arc is cut into.
const MAX_ARC_CHORDS: usize = 100_000;
/// Millimetres per inch.
const MM_PER_INCH: f64 = 25.4;

/// Reads a program.
///
/// # Errors
/// [`GcodeError`] naming the line of the first problem.
///
/// ```
/// use scallop_io::gcode::{read_gcode, GcodeOptions};
/// let path = read_gcode("G21 G90\nG0 X0 Y0 Z5\nG1 Z0 F300\nG1 X10\nG2 X20 Y0 I5 J0\n", &GcodeOptions::default()).unwrap();
/// assert!(path.moves().len() > 4);
/// let last = path.moves().last().unwrap().to;
/// assert!((last.x - 20.0).abs() < 1e-12 && last.y.abs() < 1e-12);
/// assert!(read_gcode("G0 X0 Y0 Z0\nG28\n", &GcodeOptions::default()).unwrap_err().to_string().contains("line 2"));
/// ```
pub fn read_gcode(text: &str, options: &GcodeOptions) -> Result<Toolpath, GcodeError> {
    read(text, options, false).map(|(path, _)| path)
}

/// Reads a program like [`read_gcode`], but keeps every `G2`/`G3` in the XY plane (G17) as one move
/// to its end point carrying its circle and signed sweep
/// ([`Toolpath::arc`]); `arc_tolerance` is unused.
///
/// # Errors
/// As [`read_gcode`].
///
/// ```
/// use scallop_io::gcode::{read_gcode_arcs, GcodeOptions};
/// // A full clockwise circle of radius 5 about (5, 0), then a half circle.
/// let text = "G21 G90\nG0 X0 Y0 Z5\nG1 Z0 F300\nG2 X0 Y0 I5 J0\nG3 X10 Y0 R5\n";
/// let path = read_gcode_arcs(text, &GcodeOptions::default()).unwrap();
/// assert_eq!(path.moves().len(), 4);
/// let full = path.arc(2).unwrap();
/// assert_eq!((full.center.x, full.center.y), (5.0, 0.0));
/// assert!((full.sweep + std::f64::consts::TAU).abs() < 1e-12);
/// assert!((path.arc(3).unwrap().sweep - std::f64::consts::PI).abs() < 1e-12);
/// ```
pub fn read_gcode_arcs(text: &str, options: &GcodeOptions) -> Result<Toolpath, GcodeError> {
    read(text, options, true).map(|(path, _)| path)
}

/// Reads a program like [`read_gcode_arcs`] and also returns, for every move of the
/// toolpath, the line (from 1) of the block it comes from, so that a simulation fault on
/// a move can name the G-code line.
///
/// # Errors
/// As [`read_gcode`].
///
/// ```
/// use scallop_io::gcode::{read_gcode_lines, GcodeOptions};
/// let (path, lines) = read_gcode_lines("G21\nG0 Z5\nG0 X0 Y0\nG1 Z0 F100\n(c)\nG1 X4\n", &GcodeOptions::default()).unwrap();
/// assert_eq!(path.moves().len(), 3);
/// assert_eq!(lines, [3, 4, 6]);
/// ```
pub fn read_gcode_lines(text: &str, options: &GcodeOptions) -> Result<(Toolpath, Vec<usize>), GcodeError> {
    read(text, options, true)
}

fn read(text: &str, options: &GcodeOptions, keep_arcs: bool) -> Result<(Toolpath, Vec<usize>), GcodeError> {
    let mut state = State {
        pos: options.start,
        partial: [None; 3],
        partial_line: 0,
        scale: 1.0,
        absolute: true,
        motion: None,
        feed: None,
        plane: (0, 1, 2),
    };
    let mut path = Toolpath::new(0.0);
    let mut feeds: Vec<f64> = Vec::new();
    let mut tool = Tools::default();
    let mut lines: Vec<usize> = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let block = state.block(&mut tool, raw, line)?;
        let target = block.target;
        if target.iter().all(Option::is_none) {
            continue;
        }
        let Some(motion) = state.motion else {
            return Err(GcodeError::State { line, why: "coordinates without a motion mode (G0/G1/G2/G3)" });
        };
        let placed = if state.pos.is_none() && target.iter().any(Option::is_none) {
            state.place_partial(target, motion, line)?
        } else {
            let to = state.resolve(target, line)?;
            match state.pos {
                Some(from) => {
                    if motion != 0 {
                        let feed =
                            state.feed.ok_or(GcodeError::State { line, why: "a feed move before any F word" })?;
                        tool.cut = true;
                        feeds.push(feed * state.scale);
                    }
                    match motion {
                        0 => path.push(Move::new(MoveKind::Rapid, to)),
                        1 => {
                            let plunge = (to.x - from.x).abs() + (to.y - from.y).abs() == 0.0 && to.z < from.z;
                            path.push(Move::new(if plunge { MoveKind::Plunge } else { MoveKind::Feed }, to));
                        }
                        2 | 3 => {
                            let arc = ArcMove { from, to, clockwise: motion == 2, keep: keep_arcs };
                            push_arc(&mut path, &state, &block, &arc, options.arc_tolerance, line)?;
                        }
                        _ => unreachable!("motion modes are 0..=3"),
                    }
                    state.pos = Some(to);
                    lines.resize(path.moves().len(), line);
                    None
                }
                // Unknown start: place the tool.
                None => Some(to),
            }
        };
        if let Some(to) = placed {
            path.push(Move::new(MoveKind::Rapid, to));
            state.pos = Some(to);
            lines.push(line);
        }
    }
    if path.moves().is_empty() {
        if state.partial.iter().any(Option::is_some) {
            return Err(GcodeError::State {
                line: state.partial_line,
                why: "X, Y and Z are never all given, so the tool's position is never known",
            });
        }
        return Err(GcodeError::Empty);
    }
    // One feed for the path: the most common programmed feed (mm/min), for time estimates.
    feeds.sort_by(f64::total_cmp);
    path.feed = feeds.get(feeds.len() / 2).copied().unwrap_or(0.0);
    path.plunge_feed = path.feed;
    debug_assert_eq!(lines.len(), path.moves().len());
    Ok((path, lines))
}

/// One block's coordinate words: the axes it gives (X, Y, Z), the arc
/// centre offsets (I, J, K) and the arc radius (R), as written.
struct Block {
    target: [Option<f64>; 3],
    offsets: [Option<f64>; 3],
    radius: Option<f64>,
}

/// The ends and sense of one G2/G3 move; `keep` keeps XY arcs as arcs.
struct ArcMove {
    from: Point3,
    to: Point3,
    clockwise: bool,
    keep: bool,
}

/// Pushes a G2/G3 move onto `path`: one arc move (G17 with `keep`), else
/// chords within `tolerance` of the circle.
fn push_arc(
    path: &mut Toolpath,
    state: &State,
    block: &Block,
    arc: &ArcMove,
    tolerance: f64,
    line: usize,
) -> Result<(), GcodeError> {
    let (from, to) = (arc.from, arc.to);
    let (u, v, _) = state.plane;
    let offsets = block.offsets.map(|o| o.map(|x| x * state.scale));
    for (o, name) in offsets.iter().zip(["I", "J", "K"]) {
        if let Some(o) = o {
            in_range(line, name, *o)?;
        }
    }
    if let Some(r) = block.radius {
        in_range(line, "R", r * state.scale)?;
    }
    let centre = arc_centre(
        (from[u], from[v]),
        (to[u], to[v]),
        (offsets[u], offsets[v]),
        block.radius.map(|x| x * state.scale),
        arc.clockwise,
        line,
    )?;
    // The whole circle stays in range (an arc may sweep most of it).
    let radius = (from[u] - centre.0).hypot(from[v] - centre.1);
    in_range(line, "arc extent (|centre| + radius)", centre.0.abs() + radius)?;
    in_range(line, "arc extent (|centre| + radius)", centre.1.abs() + radius)?;
    if arc.keep && state.plane == (0, 1, 2) {
        let (_, sweep) = arc_sweep(from, to, centre, (0, 1), arc.clockwise);
        let xy = ArcXY { center: Point2::new(centre.0, centre.1), sweep };
        path.push_arc(Move::new(MoveKind::Feed, to), xy);
    } else {
        for p in arc_points(from, to, centre, state.plane, arc.clockwise, tolerance) {
            path.push(Move::new(MoveKind::Feed, p));
        }
    }
    Ok(())
}

/// Tool words: the program is simulated with one cutter, so a tool change (`M6`) to
/// another tool after cutting has begun is refused with its line.
#[derive(Default)]
struct Tools {
    /// The last `T` word.
    selected: Option<f64>,
    /// The tool in the spindle (set by `M6`).
    current: Option<f64>,
    /// A feed move has been read.
    cut: bool,
}

impl Tools {
    fn change(&mut self, line: usize) -> Result<(), GcodeError> {
        if self.cut && self.selected != self.current {
            return Err(GcodeError::Unsupported {
                line,
                code: "M6".into(),
                why: "a change to another tool after cutting began: the simulation uses one cutter; \
                      split the program at this line and simulate each tool with its own --cutter",
            });
        }
        self.current = self.selected;
        Ok(())
    }
}

struct State {
    pos: Option<Point3>,
    /// The axes known so far while `pos` is unknown (rapids giving one axis at a time).
    partial: [Option<f64>; 3],
    /// The last line that gave one of them.
    partial_line: usize,
    scale: f64,
    absolute: bool,
    motion: Option<u8>,
    feed: Option<f64>,
    /// Arc plane `(u, v, n)`, right-handed: G17 (X, Y, Z), G18 (Z, X, Y), G19 (Y, Z, X).
    plane: (usize, usize, usize),
}

impl State {
    fn g_code(&mut self, value: f64, line: usize) -> Result<(), GcodeError> {
        // G codes are integers or one decimal (G64.1 and the like).
        let tenth = (value * 10.0).round();
        #[allow(clippy::cast_possible_truncation)]
        let code = tenth as i64;
        match code {
            0 | 10 | 20 | 30 => self.motion = Some(u8::try_from(code / 10).unwrap_or(0)),
            400 | 430 | 490 | 800 | 940 | 610 | 640 | 641 | 540 | 550 | 560 | 570 | 580 | 590 => {}
            170 => self.plane = (0, 1, 2),
            180 => self.plane = (2, 0, 1),
            190 => self.plane = (1, 2, 0),
            200 => self.scale = MM_PER_INCH,
            210 => self.scale = 1.0,
            900 => self.absolute = true,
            910 => self.absolute = false,
            _ => {
                return Err(GcodeError::Unsupported {
                    line,
                    code: format!("G{value}"),
                    why: "a code that may move the tool or change the frame",
                });
            }
        }
        Ok(())
    }

    /// Reads one block: modal codes and the feed into the state, tool words
    /// into `tool` (an `M6` after the block's `T` word, whatever their order,
    /// as controllers do), coordinates and arc words into the result.
    fn block(&mut self, tool: &mut Tools, raw: &str, line: usize) -> Result<Block, GcodeError> {
        let mut block = Block { target: [None; 3], offsets: [None; 3], radius: None };
        let mut m6 = false;
        for (letter, value) in words(raw, line)? {
            match letter {
                'G' => self.g_code(value, line)?,
                'X' => block.target[0] = Some(value),
                'Y' => block.target[1] = Some(value),
                'Z' => block.target[2] = Some(value),
                'I' => block.offsets[0] = Some(value),
                'J' => block.offsets[1] = Some(value),
                'K' => block.offsets[2] = Some(value),
                'R' => block.radius = Some(value),
                'F' => {
                    if !(value.is_finite() && value > 0.0) {
                        return Err(GcodeError::Syntax { line, word: format!("F{value}") });
                    }
                    self.feed = Some(value);
                }
                'T' => tool.selected = Some(value),
                'M' if (value - 6.0).abs() < 1e-9 => m6 = true,
                'N' | 'S' | 'M' | 'O' | 'P' | 'H' | 'D' => {}
                'A' | 'B' | 'C' | 'U' | 'V' | 'W' => {
                    return Err(GcodeError::Unsupported {
                        line,
                        code: letter.to_string(),
                        why: "rotary or extra axes: this reader is 3-axis",
                    });
                }
                other => return Err(GcodeError::Syntax { line, word: other.to_string() }),
            }
        }
        if m6 {
            tool.change(line)?;
        }
        Ok(block)
    }

    /// Takes the axes a block gives while the start is unknown, as on a
    /// controller after homing: rapids may give the axes one at a time
    /// (`G0 Z50` then `G0 X0 Y0`). Returns where to place the tool once all
    /// three are known.
    fn place_partial(
        &mut self,
        target: [Option<f64>; 3],
        motion: u8,
        line: usize,
    ) -> Result<Option<Point3>, GcodeError> {
        if motion != 0 {
            return Err(GcodeError::State {
                line,
                why: "a feed move before X, Y and Z are all known; start with G0 moves that give every axis",
            });
        }
        if !self.absolute {
            return Err(GcodeError::State {
                line,
                why: "an incremental (G91) move from an unknown position; give absolute X, Y and Z first",
            });
        }
        for (axis, name) in ["X", "Y", "Z"].into_iter().enumerate() {
            if let Some(v) = target[axis] {
                self.partial[axis] = Some(in_range(line, name, v * self.scale)?);
            }
            self.partial_line = line;
        }
        Ok(match self.partial {
            [Some(x), Some(y), Some(z)] => Some(Point3::new(x, y, z)),
            _ => None,
        })
    }

    fn resolve(&self, target: [Option<f64>; 3], line: usize) -> Result<Point3, GcodeError> {
        let mut p = [0.0; 3];
        for axis in 0..3 {
            let current = self.pos.map(|q| q[axis]);
            p[axis] = match (target[axis], current) {
                (Some(v), Some(c)) if !self.absolute => c + v * self.scale,
                (Some(v), _) => v * self.scale,
                (None, Some(c)) => c,
                (None, None) => {
                    return Err(GcodeError::State {
                        line,
                        why: "the first move must give X, Y and Z (the start is unknown)",
                    });
                }
            };
        }
        for (v, name) in p.iter().zip(["X", "Y", "Z"]) {
            in_range(line, name, *v)?;
        }
        Ok(Point3::new(p[0], p[1], p[2]))
    }
}

fn words(raw: &str, line: usize) -> Result<Vec<(char, f64)>, GcodeError> {
    let mut text = String::with_capacity(raw.len());
    let mut depth = 0usize;
    for ch in raw.chars() {
        match ch {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            ';' if depth == 0 => break,
            c if depth == 0 => text.push(c),
            _ => {}
        }
    }
    let text = text.trim();
    if text.starts_with('/') || text.starts_with('%') || text.is_empty() {
        return Ok(Vec::new());
    }
    let mut out = Vec::new();
    let bytes: Vec<char> = text.chars().filter(|c| !c.is_whitespace()).collect();
    let mut k = 0;
    while k < bytes.len() {
        let letter = bytes[k].to_ascii_uppercase();
        if !letter.is_ascii_alphabetic() {
            return Err(GcodeError::Syntax { line, word: bytes[k..].iter().collect() });
        }
        let start = k + 1;
        let mut end = start;
        while end < bytes.len() && (bytes[end].is_ascii_digit() || matches!(bytes[end], '.' | '-' | '+')) {
            end += 1;
        }
        let number: String = bytes[start..end].iter().collect();
        let value: f64 = number
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| GcodeError::Syntax { line, word: format!("{letter}{number}") })?;
        out.push((letter, value));
        k = end;
    }
    Ok(out)
}

/// Centre `(u, v)` of an arc in its plane from `(u, v)` start and end.
fn arc_centre(
    from: (f64, f64),
    to: (f64, f64),
    offsets: (Option<f64>, Option<f64>),
    r: Option<f64>,
    clockwise: bool,
    line: usize,
) -> Result<(f64, f64), GcodeError> {
    if offsets.0.is_some() || offsets.1.is_some() {
        let c = (from.0 + offsets.0.unwrap_or(0.0), from.1 + offsets.1.unwrap_or(0.0));
        let (r0, r1) = ((from.0 - c.0).hypot(from.1 - c.1), (to.0 - c.0).hypot(to.1 - c.1));
        if (r0 - r1).abs() > ARC_RADIUS_MISMATCH * r0.max(1.0) {
            return Err(GcodeError::BadArc { line, why: format!("start radius {r0:.4} mm, end radius {r1:.4} mm") });
        }
        return Ok(c);
    }
    let Some(r) = r else { return Err(GcodeError::BadArc { line, why: "neither I/J/K nor R given".into() }) };
    let (dx, dy) = (to.0 - from.0, to.1 - from.1);
    let d = dx.hypot(dy);
    if d == 0.0 || d > 2.0 * r.abs() * (1.0 + ARC_RADIUS_MISMATCH) {
        return Err(GcodeError::BadArc { line, why: format!("R {r} cannot join points {d:.4} mm apart") });
    }
    let h = (r * r - d * d / 4.0).max(0.0).sqrt();
    // Centre to the left of the chord for CCW with R > 0 (the short arc), mirrored otherwise.
    let side = if clockwise == (r > 0.0) { -1.0 } else { 1.0 };
    let (mx, my) = (from.0 + dx / 2.0, from.1 + dy / 2.0);
    Ok((mx - side * h * dy / d, my + side * h * dx / d))
}

/// Relative mismatch of start and end radii accepted in an arc.
const ARC_RADIUS_MISMATCH: f64 = 1e-3;

/// Start angle and signed sweep of an arc about `c` in the plane of axes
/// `(u, v)` (rad; the sweep negative clockwise), a full turn when the ends coincide.
fn arc_sweep(from: Point3, to: Point3, c: (f64, f64), (u, v): (usize, usize), clockwise: bool) -> (f64, f64) {
    let a0 = (from[v] - c.1).atan2(from[u] - c.0);
    let a1 = (to[v] - c.1).atan2(to[u] - c.0);
    let mut sweep = a1 - a0;
    if clockwise {
        while sweep >= 0.0 {
            sweep -= std::f64::consts::TAU;
        }
    } else {
        while sweep <= 0.0 {
            sweep += std::f64::consts::TAU;
        }
    }
    (a0, sweep)
}

fn arc_points(
    from: Point3,
    to: Point3,
    c: (f64, f64),
    (u, v, n): (usize, usize, usize),
    clockwise: bool,
    tolerance: f64,
) -> Vec<Point3> {
    let radius = (from[u] - c.0).hypot(from[v] - c.1);
    let (a0, sweep) = arc_sweep(from, to, c, (u, v), clockwise);
    // Chord sagitta r (1 - cos(theta / 2)) <= tolerance.
    let max_step = if radius > tolerance { 2.0 * (1.0 - tolerance / radius).acos() } else { std::f64::consts::PI };
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let steps = ((sweep.abs() / max_step.max(f64::EPSILON)).ceil() as usize).clamp(1, MAX_ARC_CHORDS);
    #[allow(clippy::cast_precision_loss)]
    let mut pts: Vec<Point3> = (1..steps)
        .map(|k| {
            let t = k as f64 / steps as f64;
            let a = a0 + sweep * t;
            let mut p = from;
            p[u] = c.0 + radius * a.cos();
            p[v] = c.1 + radius * a.sin();
            p[n] = from[n] + (to[n] - from[n]) * t;
            p
        })
        .collect();
    pts.push(to);
    pts
}

#[cfg(test)]
// `unwrap` is allowed in tests by clippy.toml.
#[allow(clippy::float_cmp, reason = "tests: exact values are intended")]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Toolpath, GcodeError> {
        read_gcode(text, &GcodeOptions::default())
    }

    #[test]
    fn modal_incremental_and_inches() {
        let p = read("G20 G91\nG0 X1 Y1 Z1\nG1 X1 F10\nX1\n").unwrap();
        let m = p.moves();
        assert_eq!(m.len(), 3);
        assert_eq!(m[0].to, Point3::new(25.4, 25.4, 25.4));
        assert!((m[2].to - Point3::new(76.2, 25.4, 25.4)).norm() < 1e-12);
        assert_eq!(p.feed, 254.0);
    }

    #[test]
    fn arcs_stay_on_their_circle_within_tolerance() {
        for (code, centre) in
            [("G2 X10 Y0 I5 J0", (5.0, 0.0)), ("G3 X10 Y0 R5", (5.0, 0.0)), ("G2 X10 Y0 R5", (5.0, 0.0))]
        {
            let p = read(&format!("G0 X0 Y0 Z0\nG1 F100\n{code}\n")).unwrap();
            let pts: Vec<Point3> = p.moves().iter().map(|m| m.to).collect();
            assert!(pts.len() > 10, "{code}");
            for w in pts.windows(2) {
                let mid = ((w[0].x + w[1].x) / 2.0, (w[0].y + w[1].y) / 2.0);
                let r_mid = (mid.0 - centre.0).hypot(mid.1 - centre.1);
                assert!(5.0 - r_mid <= 0.001 + 1e-9, "{code}: sagitta {}", 5.0 - r_mid);
            }
            // CW from (0,0) to (10,0) around (5,0) goes through y > 0; CCW through y < 0.
            let y_mid = pts[pts.len() / 2].y;
            assert!(if code.starts_with("G2") { y_mid > 0.0 } else { y_mid < 0.0 }, "{code}: {y_mid}");
        }
    }

    #[test]
    fn arcs_in_the_zx_and_yz_planes_follow_the_g18_g19_conventions() {
        // G18: clockwise seen from +Y. From (10, 0, 0) to (0, 0, 10) about the origin,
        // the short way through x, z > 0 is clockwise (G2).
        let p = read("G0 X10 Y3 Z0\nG1 F100\nG18 G2 X0 Z10 I-10 K0\n").unwrap();
        for m in p.moves() {
            assert!((m.to.x.hypot(m.to.z) - 10.0).abs() <= 0.001 + 1e-9 && m.to.y == 3.0, "{}", m.to);
            assert!(m.to.x >= -1e-9 && m.to.z >= -1e-9, "{}", m.to);
        }
        // G19: counter-clockwise seen from +X, from (0, 10, 0) to (0, 0, 10), helical in X.
        let p = read("G0 X0 Y10 Z0\nG1 F100\nG19 G3 X4 Y0 Z10 R10\n").unwrap();
        let mid = p.moves()[p.moves().len() / 2].to;
        assert!(mid.y > 0.0 && mid.z > 0.0 && (mid.x - 2.0).abs() < 0.3, "{mid}");
    }

    #[test]
    fn refuses_what_it_cannot_follow() {
        let e = read("G0 X0 Y0 Z0\nG1 X1 F100\nG18 G2 X2 Z1 I5\n").unwrap_err();
        assert!(matches!(e, GcodeError::BadArc { line: 3, .. }), "{e}");
        assert!(matches!(read("G0 X0 Y0 Z0\nG1 X1 A90 F100\n").unwrap_err(), GcodeError::Unsupported { line: 2, .. }));
        assert!(matches!(read("G0 X0 Y0 Z0\nG1 X1\n").unwrap_err(), GcodeError::State { line: 2, .. }));
        assert!(matches!(read("G0 X0 Y0 Z0\nG1 X1Q F100\n").unwrap_err(), GcodeError::Syntax { line: 2, .. }));
        assert!(matches!(read("G0 X0 Y0 Z0\nG2 X1 Y1 I3 F100\n").unwrap_err(), GcodeError::BadArc { line: 2, .. }));
        assert!(matches!(read("G0 X1\n").unwrap_err(), GcodeError::State { line: 1, .. }));
        assert!(matches!(read("G0 Z50\nG1 X1 F100\n").unwrap_err(), GcodeError::State { line: 2, .. }));
        assert_eq!(read("(only a comment)\nM30\n").unwrap_err(), GcodeError::Empty);
        assert!(matches!(read("G0 X0 Y0 Z0\nG28\n").unwrap_err(), GcodeError::Unsupported { line: 2, .. }));
    }

    #[test]
    fn a_tool_change_after_cutting_is_refused_with_its_line() {
        // Before cutting, T1 M6 (and re-selecting the same tool) is the program's own tool.
        let ok = "T1 M6\nG0 X0 Y0 Z5\nG1 Z0 F100\nG1 X5\nT1\nM6\nG1 X6\n";
        assert_eq!(read(ok).unwrap().moves().len(), 4);
        let e = read("T1 M6\nG0 X0 Y0 Z5\nG1 Z0 F100\nG1 X5\nG0 Z5\nT2\nM06\nG1 Z0\n").unwrap_err();
        assert!(matches!(e, GcodeError::Unsupported { line: 7, .. }), "{e}");
        let e = read("T1 M6\nG0 X0 Y0 Z5\nG1 Z0 F100\nG1 X5\nM6 T3\n").unwrap_err();
        assert!(matches!(e, GcodeError::Unsupported { line: 5, .. }), "{e}");
        assert!(e.to_string().contains("one cutter"), "{e}");
    }

    #[test]
    fn a_program_may_give_the_start_one_axis_at_a_time() {
        // As controllers read it: a safe Z first, then X and Y; the tool is placed then.
        let p = read("G21 G90\nG0 Z50\nG0 X10 Y-5\nG1 Z0 F300\nG1 X20\n").unwrap();
        let to: Vec<Point3> = p.moves().iter().map(|m| m.to).collect();
        assert_eq!(to, vec![Point3::new(10.0, -5.0, 50.0), Point3::new(10.0, -5.0, 0.0), Point3::new(20.0, -5.0, 0.0)]);
        assert_eq!(p.moves()[0].kind, MoveKind::Rapid);
        // Inches apply to the partial axes too.
        let p = read("G20\nG0 Z2\nG0 X1 Y1\n").unwrap();
        assert_eq!(p.moves()[0].to, Point3::new(25.4, 25.4, 50.8));
    }

    #[test]
    fn coordinates_are_bounded_after_scaling_and_accumulation() {
        // The issue's cases: a finite number that G20 turns into infinity, G91 steps that
        // sum to infinity, an arc centre offset near f64::MAX.
        let big = "9".repeat(308);
        let g20 = format!("G21 G90\nG0 X10 Y10 Z50\nG1 Z38 F100\nG20\nG1 X{big}\n");
        assert!(matches!(read(&g20).unwrap_err(), GcodeError::OutOfRange { line: 5, .. }));
        let g91 = format!("G21 G90\nG0 X10 Y10 Z50\nG1 Z38 F100\nG91\nG1 X{big}\nG1 X{big}\n");
        assert!(matches!(read(&g91).unwrap_err(), GcodeError::OutOfRange { line: 5, .. }));
        let arc = format!("G21 G90\nG0 X10 Y10 Z50\nG1 Z45 F100\nG2 X10 Y10 I17{}\n", "0".repeat(307));
        let e = read(&arc).unwrap_err();
        assert!(matches!(e, GcodeError::OutOfRange { line: 4, .. }), "{e}");
        // An arc whose circle leaves the range (found by the fuzzer: centre 92243 mm, radius
        // 92233 mm, a clockwise sweep of almost a full turn).
        let e = read("G21 G90\nG0 X10 Y10 Z50\nG1 Z45 F100\nG2 X90 Y10 I92233\n").unwrap_err();
        assert!(matches!(e, GcodeError::OutOfRange { line: 4, .. }), "{e}");
        // Accumulation: 2000 steps of 60 mm pass +-1e5 on step 1667.
        let steps = "G1 X60\n".repeat(2000);
        let e = read(&format!("G0 X0 Y0 Z0\nF100 G91\n{steps}")).unwrap_err();
        assert!(matches!(e, GcodeError::OutOfRange { line: 1669, .. }), "{e}");
        // The bound itself is accepted.
        assert!(read(&format!("G0 X0 Y0 Z0\nG1 X{MAX_COORDINATE} F100\n")).is_ok());
    }

    #[test]
    fn reads_scallops_own_output_back() {
        let text = "(scallop)\nG21 G90 G17 G94\nG40 G49 G80\nG0 X1.000 Y2.000 Z9.000\nG1 X1.000 Y2.000 Z0.500 F1000\nG1 X3.000 Y2.000 Z0.250 F2000\nG1 X4.000 Y2.500 Z0.250\nG0 X4.000 Y2.500 Z9.000\nM5\nM30\n";
        let p = read(text).unwrap();
        let kinds: Vec<MoveKind> = p.moves().iter().map(|m| m.kind).collect();
        assert_eq!(kinds, vec![MoveKind::Rapid, MoveKind::Plunge, MoveKind::Feed, MoveKind::Feed, MoveKind::Rapid]);
        assert_eq!(p.moves()[3].to, Point3::new(4.0, 2.5, 0.25));
    }
}
