//! Reading our own output back (spec 3.12, K16): a small reader of exactly the words the
//! writers emit, turned into joint motion through the machine's kinematics (the
//! controller's job for TCP and tilted planes), and a check that the replayed tool tip
//! of every block stays on the input CL path within the path tolerance.

use std::collections::BTreeMap;

use scallop_geom::nalgebra::{Matrix3, Rotation3};
use scallop_geom::{Point3, Vec3};
use scallop_machine::program::{ClRecord, Motion};
use scallop_machine::{AxisKind, Joints, Kinematics, Pose, Wrap};

use crate::dialect::{Dialect, Syntax, TiltedPlane};
use crate::error::PostError;
use crate::tol;
use crate::writer::angle;

/// One motion block read back and replayed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReplayedBlock {
    /// 1-based line of the program.
    pub line: usize,
    /// Rapid (`G0`, `FMAX`): interpolation not checked.
    pub rapid: bool,
    /// Written under TCP: the controller keeps the tip on the part-frame segment.
    pub tcp: bool,
    /// First block after a tilted-plane activation (the rotaries turned before it).
    pub reoriented: bool,
    /// Joint values at the block end (mm, rad).
    pub joints: Joints,
    /// Forward kinematics of `joints` (part frame).
    pub pose: Pose,
    /// G93 word (1/min), if any.
    pub inverse_time: Option<f64>,
    /// Heidenhain `FT` block time (s), if any.
    pub seconds: Option<f64>,
}

#[derive(Clone, Copy)]
enum RotaryRule {
    Shortest,
    Positive,
    Negative,
    Absolute,
}

struct Plane {
    r: Rotation3<f64>,
    dir: Option<i32>,
}

/// Line texts that switch TCP on or off: the template text before its first `{`, with
/// the machine's codes substituted.
fn tcp_keys(dialect: &Dialect, kin: &Kinematics) -> (Vec<String>, Vec<String>) {
    let tcp = kin.machine().tcp();
    let key = |t: &String| {
        let s = t
            .replace("{machine_tcp_on}", tcp.on.as_deref().unwrap_or(""))
            .replace("{machine_tcp_off}", tcp.off.as_deref().unwrap_or(""));
        s.split('{').next().unwrap_or("").trim().to_string()
    };
    // The tool length offset written with TCP on (LinuxCNC: `G43 H{tool}` before M428) is
    // also written in joint output: it does not switch TCP on.
    let length: Vec<String> = dialect.length_offset.iter().map(key).collect();
    let (on, mut off) = dialect.tcp.as_ref().map_or((Vec::new(), Vec::new()), |c| {
        (
            c.on.iter().map(key).filter(|k| !k.is_empty() && !length.contains(k)).collect::<Vec<_>>(),
            c.off.iter().map(key).filter(|k| !k.is_empty()).collect::<Vec<_>>(),
        )
    });
    off.extend(dialect.joint_kinematics.iter().map(key).filter(|k| !k.is_empty()));
    (on, off)
}

fn number(line: usize, text: &str) -> Result<f64, PostError> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| PostError::Parse { line, problem: format!("`{text}` is not a number") })
}

/// Strips the line number and the comment of a line.
fn strip<'a>(dialect: &Dialect, raw: &'a str) -> &'a str {
    let mut s = raw.trim();
    if let Some(n) = &dialect.line_numbers
        && let Some(rest) = s.strip_prefix(n.prefix.as_str())
    {
        let digits = rest.len() - rest.trim_start_matches(|c: char| c.is_ascii_digit()).len();
        if digits > 0 {
            s = rest[digits..].trim_start();
        }
    }
    let open = dialect.comment.0.trim();
    if dialect.comment.1.is_empty() {
        if let Some(i) = s.find(open) {
            s = &s[..i];
        }
    } else if let Some(i) = s.find(open) {
        s = &s[..i];
    }
    s.trim()
}

/// Reads `text` (written in `dialect` for the machine of `kin`) back into joint motion:
/// axis words become joints (modulo-360 words unwrapped as the control does), TCP blocks
/// (tip + rotaries) get their linear joints from the kinematics, tilted-plane blocks get
/// their rotaries from the plane's tool axis (solution chosen by the plane's direction
/// word, else the one nearest the current joints). Every block is checked against the
/// strokes. The machine starts at all joints zero.
///
/// ```
/// use scallop_machine::{Kinematics, Machine};
/// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
/// let d = scallop_post::Dialect::builtin("fanuc").unwrap();
/// let blocks = scallop_post::replay("G0 X1 Y2 Z50 A10 C20\nG93 G1 X2 F100.5\n", &d, &k).unwrap();
/// assert_eq!(blocks.len(), 2);
/// assert_eq!(blocks[1].inverse_time, Some(100.5));
/// assert!((blocks[1].joints[0] - 2.0).abs() < 1e-12);
/// ```
///
/// # Errors
/// [`PostError::Parse`] for a word that is not understood; [`PostError::Machine`] for an
/// unreachable pose or a word outside its stroke, with the line.
pub fn replay(text: &str, dialect: &Dialect, kin: &Kinematics) -> Result<Vec<ReplayedBlock>, PostError> {
    let mut controller = Controller::new(dialect, kin);
    let mut out = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let s = strip(dialect, raw);
        if s.is_empty() || s == "%" || controller.mode_line(line, s)? {
            continue;
        }
        let words = match dialect.syntax {
            Syntax::Heidenhain => controller.heidenhain_words(line, s)?,
            Syntax::Iso => Some(controller.iso_words(line, s)?),
        };
        match words {
            Some(words) if !words.words.is_empty() => out.push(controller.block(line, &words)?),
            _ => {}
        }
    }
    Ok(out)
}

/// The axis words of one motion line, `(address, rule, value)`, with its feed word and
/// its Heidenhain block time.
#[derive(Default)]
struct LineWords {
    words: Vec<(String, RotaryRule, f64)>,
    feed: Option<f64>,
    seconds: Option<f64>,
}

/// The controller's state while a program is replayed: joints, the tip coordinates of
/// TCP and tilted-plane blocks, and the modal modes.
struct Controller<'a> {
    dialect: &'a Dialect,
    kin: &'a Kinematics,
    /// Joint index of each axis word.
    letters: BTreeMap<String, usize>,
    tcp_on: Vec<String>,
    tcp_off: Vec<String>,
    q: Joints,
    coords: [f64; 3],
    tcp: bool,
    plane: Option<Plane>,
    reoriented: bool,
    rapid: bool,
    g93: bool,
}

impl<'a> Controller<'a> {
    /// The machine at all joints zero, rapid, G94, no TCP and no plane.
    fn new(dialect: &'a Dialect, kin: &'a Kinematics) -> Controller<'a> {
        let letters: BTreeMap<String, usize> =
            kin.machine().axes().iter().enumerate().map(|(i, a)| (dialect.axis_word(&a.name).to_string(), i)).collect();
        let (tcp_on, tcp_off) = tcp_keys(dialect, kin);
        Controller {
            dialect,
            kin,
            letters,
            tcp_on,
            tcp_off,
            q: Joints::zeros(),
            coords: [0.0; 3],
            tcp: false,
            plane: None,
            reoriented: false,
            rapid: true,
            g93: false,
        }
    }

    /// Reads a line that switches TCP or a tilted plane on or off (`true`: consumed).
    fn mode_line(&mut self, line: usize, s: &str) -> Result<bool, PostError> {
        if self.tcp_on.iter().any(|k| s.starts_with(k.as_str())) {
            self.tcp = true;
            return Ok(true);
        }
        if self.tcp_off.iter().any(|k| s.starts_with(k.as_str())) {
            self.tcp = false;
            return Ok(true);
        }
        if let Some(p) = read_plane(self.dialect, line, s)? {
            self.plane = p;
            self.reoriented = true;
            return Ok(true);
        }
        Ok(false)
    }

    /// The words of a Heidenhain `L` line (`None` for any other line): `FMAX` is a
    /// rapid, `FT` a block time, `F` a feed.
    fn heidenhain_words(&mut self, line: usize, s: &str) -> Result<Option<LineWords>, PostError> {
        let tokens: Vec<&str> = s.split_whitespace().collect();
        if tokens.first() != Some(&"L") {
            return Ok(None);
        }
        self.rapid = false;
        let mut w = LineWords::default();
        for t in &tokens[1..] {
            if *t == "FMAX" {
                self.rapid = true;
            } else if let Some(v) = t.strip_prefix("FT") {
                w.seconds = Some(number(line, v)?);
            } else if let Some(v) = t.strip_prefix('F') {
                w.feed = Some(number(line, v)?);
            } else {
                let (address, value) = split_word(t);
                if self.letters.contains_key(address) {
                    w.words.push((address.to_string(), RotaryRule::Shortest, number(line, value)?));
                }
            }
        }
        Ok(Some(w))
    }

    /// The words of an ISO line: motion and feed-mode G codes, `F`, axis words and the
    /// Siemens `NAME=DC(..)`/`ACP(..)`/`ACN(..)` rotary words.
    fn iso_words(&mut self, line: usize, s: &str) -> Result<LineWords, PostError> {
        let mut w = LineWords::default();
        for t in s.split_whitespace() {
            if let Some((name, rhs)) = t.split_once('=') {
                if self.letters.contains_key(name) {
                    let (rule, inner) = siemens_rotary(rhs);
                    w.words.push((name.to_string(), rule, number(line, inner)?));
                }
                continue;
            }
            let (address, value) = split_word(t);
            if value.is_empty() {
                continue; // SOFT, FFWON, ORIWKS, ...
            }
            match address {
                "G" => match value {
                    "0" | "00" => self.rapid = true,
                    "1" | "01" => self.rapid = false,
                    "93" => self.g93 = true,
                    "94" => self.g93 = false,
                    _ => {}
                },
                "F" => w.feed = Some(number(line, value)?),
                a if self.letters.contains_key(a) => {
                    w.words.push((a.to_string(), RotaryRule::Shortest, number(line, value)?));
                }
                _ => {}
            }
        }
        Ok(w)
    }

    /// Moves the machine by the words of a motion line: joints from the axis words, the
    /// linear joints from the kinematics under TCP, all joints from the plane in a tilted
    /// plane; checked against the strokes.
    fn block(&mut self, line: usize, w: &LineWords) -> Result<ReplayedBlock, PostError> {
        let previous = self.q;
        for (address, rule, value) in &w.words {
            self.set_word(line, self.letters[address], *rule, *value)?;
        }
        let kin = self.kin;
        let at = |e: scallop_machine::MachineError| PostError::Machine { line, source: e };
        let tip = Point3::new(self.coords[0], self.coords[1], self.coords[2]);
        if let Some(p) = &self.plane {
            let pose = Pose::new(p.r * tip, p.r * Vec3::z());
            self.q = plane_joints(kin, &pose, &previous, p.dir).map_err(at)?;
        } else if self.tcp {
            solve_linear(kin, &mut self.q, &tip);
        }
        scallop_machine::plan::check_limits(kin.machine(), &self.q, None).map_err(at)?;
        let block = ReplayedBlock {
            line,
            rapid: self.rapid,
            tcp: self.tcp,
            reoriented: self.reoriented,
            joints: self.q,
            pose: kin.fk(&self.q),
            inverse_time: if self.g93 && !self.rapid { w.feed } else { None },
            seconds: w.seconds,
        };
        self.reoriented = false;
        Ok(block)
    }

    /// Axis word `value` of joint `i`: a tip coordinate under TCP or in a plane, else the
    /// joint (rotaries by `rule` from the current value, modulo words unwrapped as the
    /// control does).
    fn set_word(&mut self, line: usize, i: usize, rule: RotaryRule, value: f64) -> Result<(), PostError> {
        let kin = self.kin;
        let axis = &kin.machine().axes()[i];
        match axis.kind {
            AxisKind::Linear => {
                if self.tcp || self.plane.is_some() {
                    self.coords[component(self.dialect, line, &axis.name)?] = value;
                } else {
                    self.q[i] = axis.from_nc_word(value);
                }
            }
            AxisKind::Rotary => {
                let current = axis.to_nc_word(self.q[i]);
                let rule = if axis.wrap == Wrap::Absolute && matches!(rule, RotaryRule::Shortest) {
                    RotaryRule::Absolute
                } else {
                    rule
                };
                let word = match rule {
                    RotaryRule::Absolute => value,
                    RotaryRule::Shortest => current + ((value - current + 180.0).rem_euclid(360.0) - 180.0),
                    RotaryRule::Positive => current + (value - current).rem_euclid(360.0),
                    RotaryRule::Negative => current - (current - value).rem_euclid(360.0),
                };
                self.q[i] = axis.from_nc_word(word);
            }
        }
        Ok(())
    }
}

/// The rule and the number of a Siemens rotary value: `DC(v)`, `ACP(v)`, `ACN(v)` or `v`.
fn siemens_rotary(rhs: &str) -> (RotaryRule, &str) {
    if let Some(v) = rhs.strip_prefix("DC(") {
        (RotaryRule::Shortest, v.trim_end_matches(')'))
    } else if let Some(v) = rhs.strip_prefix("ACP(") {
        (RotaryRule::Positive, v.trim_end_matches(')'))
    } else if let Some(v) = rhs.strip_prefix("ACN(") {
        (RotaryRule::Negative, v.trim_end_matches(')'))
    } else {
        (RotaryRule::Absolute, rhs)
    }
}

/// Splits `X-1.5` into (`X`, `-1.5`).
fn split_word(t: &str) -> (&str, &str) {
    let n = t.find(|c: char| !c.is_ascii_alphabetic()).unwrap_or(t.len());
    (&t[..n], &t[n..])
}

fn component(dialect: &Dialect, line: usize, name: &str) -> Result<usize, PostError> {
    match name {
        "X" => Ok(0),
        "Y" => Ok(1),
        "Z" => Ok(2),
        other => Err(PostError::Parse {
            line,
            problem: format!("dialect `{}`: linear axis `{other}` in TCP or tilted-plane output", dialect.name),
        }),
    }
}

/// Parses a tilted-plane line: `Some(Some(plane))` on, `Some(None)` off, `None` not a plane line.
fn read_plane(dialect: &Dialect, line: usize, s: &str) -> Result<Option<Option<Plane>>, PostError> {
    let deg = |v: &str| number(line, v).map(f64::to_radians);
    match dialect.tilted_plane {
        TiltedPlane::None => Ok(None),
        TiltedPlane::G68_2 => {
            if s.starts_with("G69") {
                return Ok(Some(None));
            }
            // G53.1 turns the rotaries for the active G68.2: read as an ordinary (empty) line.
            if !s.starts_with("G68.2") {
                return Ok(None);
            }
            let (mut i, mut j, mut k) = (0.0, 0.0, 0.0);
            for t in s.split_whitespace().skip(1) {
                let (a, v) = split_word(t);
                match a {
                    "I" => i = deg(v)?,
                    "J" => j = deg(v)?,
                    "K" => k = deg(v)?,
                    _ => {}
                }
            }
            let r = Rotation3::from_axis_angle(&Vec3::z_axis(), i)
                * Rotation3::from_axis_angle(&Vec3::x_axis(), j)
                * Rotation3::from_axis_angle(&Vec3::z_axis(), k);
            Ok(Some(Some(Plane { r, dir: None })))
        }
        TiltedPlane::Cycle800 => {
            let Some(args) = s.strip_prefix("CYCLE800(") else { return Ok(None) };
            let args: Vec<&str> = args.trim_end_matches(')').split(',').collect();
            if args.len() < 14 {
                return Ok(Some(None));
            }
            let (a, b, c) = (deg(args[7])?, deg(args[8])?, deg(args[9])?);
            let r = Rotation3::from_axis_angle(&Vec3::x_axis(), a)
                * Rotation3::from_axis_angle(&Vec3::y_axis(), b)
                * Rotation3::from_axis_angle(&Vec3::z_axis(), c);
            let dir = number(line, args[13])?;
            Ok(Some(Some(Plane { r, dir: Some(if dir < 0.0 { -1 } else { 1 }) })))
        }
        TiltedPlane::PlaneSpatial => {
            if s.starts_with("PLANE RESET") {
                return Ok(Some(None));
            }
            if !s.starts_with("PLANE SPATIAL") {
                return Ok(None);
            }
            let (mut a, mut b, mut c, mut dir) = (0.0, 0.0, 0.0, None);
            for t in s.split_whitespace().skip(2) {
                if let Some(v) = t.strip_prefix("SPA") {
                    a = deg(v)?;
                } else if let Some(v) = t.strip_prefix("SPB") {
                    b = deg(v)?;
                } else if let Some(v) = t.strip_prefix("SPC") {
                    c = deg(v)?;
                } else if t == "SEQ+" {
                    dir = Some(1);
                } else if t == "SEQ-" {
                    dir = Some(-1);
                }
            }
            let r = Rotation3::from_axis_angle(&Vec3::z_axis(), c)
                * Rotation3::from_axis_angle(&Vec3::y_axis(), b)
                * Rotation3::from_axis_angle(&Vec3::x_axis(), a);
            Ok(Some(Some(Plane { r, dir })))
        }
    }
}

/// The controller's choice of rotaries for a tilted plane: an inverse solution inside
/// the strokes, whose tilt word has the sign `dir`, nearest `current` (in that order of
/// priority), rotaries unwrapped to the nearest winding.
fn plane_joints(
    kin: &Kinematics,
    pose: &Pose,
    current: &Joints,
    dir: Option<i32>,
) -> Result<Joints, scallop_machine::MachineError> {
    let machine = kin.machine();
    let tilt = kin.tilt_axis();
    let sols = kin.ik(pose, current)?;
    let mut best: Option<(f64, Joints)> = None;
    for s in sols.as_slice() {
        let mut q = s.joints;
        for (i, axis) in machine.axes().iter().enumerate() {
            if axis.kind == AxisKind::Rotary {
                let turn = std::f64::consts::TAU;
                q[i] += turn * ((current[i] - q[i]) / turn).round();
            }
        }
        let word = machine.axes()[tilt].to_nc_word(q[tilt]);
        let sign_ok = dir.is_none_or(|d| (word >= 0.0) == (d >= 0) || word.abs() <= tol::ZERO_TILT_DEG);
        let inside = scallop_machine::plan::check_limits(machine, &q, None).is_ok();
        let rotary_jump = machine
            .axes()
            .iter()
            .enumerate()
            .filter(|(_, a)| a.kind == AxisKind::Rotary)
            .map(|(i, _)| (q[i] - current[i]).abs())
            .fold(0.0, f64::max);
        let distance = rotary_jump
            + if sign_ok { 0.0 } else { tol::WRONG_SOLUTION_PENALTY }
            + if inside { 0.0 } else { 2.0 * tol::WRONG_SOLUTION_PENALTY };
        if best.is_none_or(|(d, _)| distance < d) {
            best = Some((distance, q));
        }
    }
    // INVARIANT: `ik` returns at least one solution when it returns Ok.
    Ok(best.map_or(*current, |b| b.1))
}

/// Sets the linear joints of `q` so that the tip is at `tip` with the rotaries of `q`:
/// with the rotaries fixed the tip is affine in the linear joints.
fn solve_linear(kin: &Kinematics, q: &mut Joints, tip: &Point3) {
    let machine = kin.machine();
    let linear: Vec<usize> =
        (0..machine.axes().len()).filter(|&i| machine.axes()[i].kind == AxisKind::Linear).collect();
    let mut q0 = *q;
    for &i in &linear {
        q0[i] = 0.0;
    }
    let p0 = kin.fk(&q0).tip;
    let mut m = Matrix3::zeros();
    for (c, &i) in linear.iter().enumerate() {
        let mut qi = q0;
        qi[i] = 1.0;
        m.set_column(c, &(kin.fk(&qi).tip - p0));
    }
    // INVARIANT: a validated machine has three independent linear axes.
    let x = m.try_inverse().unwrap_or_else(Matrix3::identity) * (tip - p0);
    for (c, &i) in linear.iter().enumerate() {
        q[i] = x[c];
    }
}

/// What [`check_replay`] measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoundTrip {
    /// Motion blocks read back.
    pub blocks: usize,
    /// Largest tip distance from the input CL path (block ends and, for joint-space
    /// blocks, 16 samples of the joint-linear interpolation), mm.
    pub max_tip_deviation: f64,
    /// Largest tool-axis angle from the input at the CL records (rad).
    pub max_axis_deviation: f64,
    /// Largest `|dq_j| / (vmax_j T)` over blocks with a time word (G93 or `FT`); <= 1.
    pub max_rate_ratio: f64,
}

/// Distance from `p` to the ray from `a` along the unit vector `d`.
fn distance_to_ray(p: &Point3, a: &Point3, d: &Vec3) -> f64 {
    let t = (p - a).dot(d).max(0.0);
    (p - (a + d * t)).norm()
}

fn distance_to_segment(p: &Point3, a: &Point3, b: &Point3) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 { ((p - a).dot(&ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + ab * t)).norm()
}

/// Checks replayed blocks against the input CL records (spec K16): every block end and
/// every sample of a joint-space block lies within `tol_pos` plus the word rounding of the
/// CL segment it belongs to (off the material, rapids and links, also of the tool-axis
/// rays at its ends: a retract and an approach), every CL record is reached in order by a
/// block at its tip with its tool axis within `tol_ang` plus rounding (blocks and records
/// are paired by order: records sharing a tip are reached one after the other), and no
/// time-word block asks an axis for more than its velocity.
///
/// ```
/// use scallop_geom::{Point3, Vec3};
/// use scallop_machine::{Kinematics, Machine, Pose};
/// use scallop_machine::program::{to_program, ClRecord, Motion, ProgramOptions};
/// use scallop_post::{check_replay, program_text, replay, Dialect, OutputMode, PostParams};
/// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
/// let rec = |x: f64, m| ClRecord { pose: Pose::new(Point3::new(x, 0.0, 50.0), Vec3::new(x / 300.0, 0.3, 1.0)), motion: m, feed: 1000.0 };
/// let records = [rec(0.0, Motion::Rapid), rec(30.0, Motion::Feed)];
/// let opts = ProgramOptions::default();
/// let prog = to_program(&k, &records, None, &opts).unwrap();
/// let d = Dialect::builtin("siemens840d").unwrap();
/// let params = PostParams { program: "P1".into(), mode: OutputMode::Joint, tool: 1, tool_length: 0.0, spindle: 8000.0,
///                           tol_pos: opts.tol_pos, tol_ang: opts.tol_ang, predicted_time: None };
/// let text = program_text(&prog, &k, &d, &params).unwrap();
/// let r = check_replay(&replay(&text, &d, &k).unwrap(), &records, &k, &d, opts.tol_pos, opts.tol_ang).unwrap();
/// assert!(r.max_tip_deviation <= opts.tol_pos + 1e-3);
/// ```
///
/// # Errors
/// [`PostError::Deviation`] naming the line and what deviates.
pub fn check_replay(
    blocks: &[ReplayedBlock],
    records: &[ClRecord],
    kin: &Kinematics,
    dialect: &Dialect,
    tol_pos: f64,
    tol_ang: f64,
) -> Result<RoundTrip, PostError> {
    let machine = kin.machine();
    let half_linear = 0.5 * 10f64.powi(-i32::try_from(dialect.decimals).unwrap_or(4));
    let half_rotary = (0.5 * 10f64.powi(-i32::try_from(dialect.rotary_decimals).unwrap_or(4))).to_radians();
    let allow_pos = 3f64.sqrt() * half_linear + tol::REACH * tol::ROUNDED_ANGLES * half_rotary;
    let allow_ang = tol::ROUNDED_ANGLES * half_rotary;
    let mut result =
        RoundTrip { blocks: blocks.len(), max_tip_deviation: 0.0, max_axis_deviation: 0.0, max_rate_ratio: 0.0 };
    let mut next = 0usize;
    let mut previous: Option<&ReplayedBlock> = None;
    let fail = |line: usize, what: &str, deviation: f64, allowed: f64| PostError::Deviation {
        line,
        what: what.to_string(),
        deviation,
        allowed,
    };
    // A CL record whose tip a block reached with another tool axis: an in-place
    // reorientation pending, or the error to report if the record is never reached.
    let mut axis_miss: Option<(usize, f64)> = None;
    for b in blocks {
        if next >= records.len() {
            return Err(fail(b.line, "motion after the last CL record: tip (mm)", f64::INFINITY, 0.0));
        }
        let a_rec = &records[next.saturating_sub(1)];
        let b_rec = &records[next];
        let (a_pt, b_pt) = (a_rec.pose.tip, b_rec.pose.tip);
        let allowed = tol_pos * (1.0 + tol::CHECK_SLACK) + allow_pos;
        // Off the material (rapids, links) the tool may leave the segment along the tool
        // axes of its ends (a link that changes branch retracts, reorients and comes back).
        let off_material = !b_rec.motion.is_cutting();
        let distance = |tip: &Point3| {
            let d = distance_to_segment(tip, &a_pt, &b_pt);
            if off_material {
                d.min(distance_to_ray(tip, &a_pt, &a_rec.pose.axis)).min(distance_to_ray(tip, &b_pt, &b_rec.pose.axis))
            } else {
                d
            }
        };
        let mut worst = distance(&b.pose.tip);
        let cutting = !b.rapid && b_rec.motion != Motion::Rapid;
        if let Some(p) = previous
            && cutting
            && !b.tcp
            && !b.reoriented
        {
            for k in 1..tol::CHECK_SAMPLES {
                let s = f64::from(k) / f64::from(tol::CHECK_SAMPLES);
                let tip = kin.fk(&(p.joints + (b.joints - p.joints) * s)).tip;
                worst = worst.max(distance(&tip));
            }
        }
        if worst > allowed {
            // A record left at its tip with the wrong tool axis is the cause.
            if let Some((line, ang)) = axis_miss {
                return Err(fail(line, "tool axis (rad)", ang, tol_ang + allow_ang));
            }
            return Err(fail(b.line, "tip (mm)", worst, allowed));
        }
        result.max_tip_deviation = result.max_tip_deviation.max(worst);
        if let Some(p) = previous {
            let t = scallop_machine::plan::move_time(machine, &p.joints, &b.joints);
            let block_time = b.inverse_time.map(|f| 60.0 / f).or(b.seconds);
            if let Some(bt) = block_time.filter(|_| !b.rapid) {
                let ratio = t / bt;
                if ratio > 1.0 + tol::CHECK_SLACK {
                    return Err(fail(b.line, "axis rate (ratio)", ratio, 1.0));
                }
                result.max_rate_ratio = result.max_rate_ratio.max(ratio);
            }
        }
        // Records are paired with blocks in order: a block reaches the next record when
        // both its tip and its tool axis are there (consecutive records may share a tip:
        // a reorientation in place). A block at the tip with another axis leaves the
        // record pending for a later block.
        while next < records.len() && (b.pose.tip - records[next].pose.tip).norm() <= allowed {
            let ang = angle(&b.pose.axis, &records[next].pose.axis);
            if ang > tol_ang + allow_ang {
                axis_miss = Some((b.line, ang));
                break;
            }
            axis_miss = None;
            result.max_axis_deviation = result.max_axis_deviation.max(ang);
            next += 1;
        }
        previous = Some(b);
    }
    if let (true, Some((line, ang))) = (next < records.len(), axis_miss) {
        return Err(fail(line, "tool axis (rad)", ang, tol_ang + allow_ang));
    }
    if next < records.len() {
        return Err(fail(
            blocks.last().map_or(0, |b| b.line),
            "missing pose: CL record never reached, tip (mm)",
            f64::INFINITY,
            0.0,
        ));
    }
    Ok(result)
}
