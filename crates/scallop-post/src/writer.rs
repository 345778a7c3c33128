//! Writers from a joint-space [`MachineProgram`] (spec 3.9, 3.11-3.13): simultaneous
//! 5-axis joint-space output with inverse-time feeds, TCP output (tip and rotary
//! positions, the controller does the kinematics) and 3+2 output through tilted work
//! planes.

use std::io::Write;

use scallop_geom::nalgebra::Rotation3;
use scallop_geom::{Point3, Vec3};
use scallop_machine::feed::pow10i;
use scallop_machine::frame::SetupFrame;
use scallop_machine::program::{MachineProgram, Motion, ProgramBlock, ProgramOptions};
use scallop_machine::{AxisKind, Kinematics, ToolLengthMode, Wrap};

use crate::dialect::{Dialect, FeedByTime, Syntax, TcpCodes, TiltedPlane};
use crate::error::PostError;
use crate::{fmt_number, tol};

/// Output mode (spec 3.11, 3.13).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputMode {
    /// Joint-space words (the machine's NC words), inverse-time feeds where the dialect has them.
    Joint,
    /// TCP, rotary form: X/Y/Z are the tool tip in the part frame, A/B/C the rotary words;
    /// the controller computes the linear joints. Tip feed in G94.
    Tcp,
    /// 3+2: every run of blocks with one tool axis is written in a tilted work plane
    /// (`z_f` = tool axis, [`scallop_machine::frame::tilted_plane`], origin at the part
    /// origin) with X/Y/Z in that plane; the axis may change only on a rapid (the plane is
    /// switched before it). Dialects without tilted-plane codes get joint-space output with
    /// the rotaries held (spec 3.13 (a)).
    TiltedPlane,
}

impl OutputMode {
    /// Name printed in the header.
    ///
    /// ```
    /// assert_eq!(scallop_post::OutputMode::Tcp.name(), "tcp");
    /// ```
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            OutputMode::Joint => "joint",
            OutputMode::Tcp => "tcp",
            OutputMode::TiltedPlane => "tilted_plane",
        }
    }
}

/// The job decisions a program is written with (no `Default`: they are user decisions).
#[derive(Debug, Clone, PartialEq)]
pub struct PostParams {
    /// Program name or number (`O{program}`, `BEGIN PGM {program} MM`).
    pub program: String,
    /// Output mode.
    pub mode: OutputMode,
    /// Tool number.
    pub tool: u32,
    /// Tool length used by the kinematics (mm; 0 when the controller applies it).
    pub tool_length: f64,
    /// Spindle speed (1/min).
    pub spindle: f64,
    /// Path tolerance of joint-space interpolation (mm), printed in the header.
    pub tol_pos: f64,
    /// Tool-axis tolerance (rad), printed in the header; also the tolerance that groups
    /// blocks of one tool axis in [`OutputMode::TiltedPlane`].
    pub tol_ang: f64,
    /// Predicted machining time (s), printed in the header.
    pub predicted_time: Option<f64>,
}

impl PostParams {
    /// The parameters of a program whose header prints the interpolation tolerances of
    /// `options` (the ones it was planned with), without a predicted time.
    ///
    /// ```
    /// use scallop_machine::program::ProgramOptions;
    /// use scallop_post::{OutputMode, PostParams};
    /// let options = ProgramOptions::default();
    /// let p = PostParams::new("1", OutputMode::Joint, 1, 0.0, 12000.0, &options);
    /// assert_eq!((p.tol_pos, p.tol_ang, p.predicted_time), (options.tol_pos, options.tol_ang, None));
    /// ```
    #[must_use]
    pub fn new(
        program: &str,
        mode: OutputMode,
        tool: u32,
        tool_length: f64,
        spindle: f64,
        options: &ProgramOptions,
    ) -> PostParams {
        PostParams {
            program: program.to_string(),
            mode,
            tool,
            tool_length,
            spindle,
            tol_pos: options.tol_pos,
            tol_ang: options.tol_ang,
            predicted_time: None,
        }
    }
}

/// Rounds `v` down to `decimals` (an exactly representable value is kept).
pub(crate) fn round_down(v: f64, decimals: usize) -> f64 {
    let s = pow10i(i32::try_from(decimals).unwrap_or(9));
    let r = crate::round_fast(v * s);
    if ((v * s) - r).abs() <= tol::ROUNDING_SLACK * r.abs().max(1.0) { r / s } else { crate::floor_fast(v * s) / s }
}

/// Rounds `v` up to `decimals` (an exactly representable value is kept).
pub(crate) fn round_up(v: f64, decimals: usize) -> f64 {
    -round_down(-v, decimals)
}

/// Writes `program` in `dialect` and `params.mode` through `out`.
///
/// ```
/// use scallop_geom::{Point3, Vec3};
/// use scallop_machine::{Kinematics, Machine, Pose};
/// use scallop_machine::program::{to_program, ClRecord, Motion, ProgramOptions};
/// use scallop_post::{Dialect, OutputMode, PostParams, write_program};
/// let k = Kinematics::new(&Machine::builtin("linuxcnc-xyzac-trt").unwrap(), 0.0);
/// let rec = |x: f64, m| ClRecord { pose: Pose::new(Point3::new(x, 0.0, 20.0), Vec3::new(0.0, -0.3, 1.0)), motion: m, feed: 1000.0 };
/// let prog = to_program(&k, &[rec(0.0, Motion::Rapid), rec(10.0, Motion::Feed)], None, &ProgramOptions::default()).unwrap();
/// let params = PostParams { program: "1".into(), mode: OutputMode::Joint, tool: 1, tool_length: 0.0, spindle: 10000.0,
///                           tol_pos: 0.005, tol_ang: 0.001, predicted_time: None };
/// let mut out = Vec::new();
/// write_program(&prog, &k, &Dialect::builtin("linuxcnc").unwrap(), &params, &mut out).unwrap();
/// assert!(String::from_utf8(out).unwrap().contains("G93 G1"));
/// ```
///
/// # Errors
/// [`PostError::Unsupported`] when the dialect or the machine cannot express the mode
/// (no TCP, more axes than the controller drives); [`PostError::Io`] from `out`.
pub fn write_program(
    program: &MachineProgram,
    kin: &Kinematics,
    dialect: &Dialect,
    params: &PostParams,
    out: &mut impl Write,
) -> Result<(), PostError> {
    let text = program_text(program, kin, dialect, params)?;
    out.write_all(text.as_bytes())?;
    Ok(())
}

/// [`write_program`] into a `String`.
///
/// # Errors
/// As [`write_program`].
pub fn program_text(
    program: &MachineProgram,
    kin: &Kinematics,
    dialect: &Dialect,
    params: &PostParams,
) -> Result<String, PostError> {
    if dialect.inch {
        return Err(PostError::Unsupported {
            dialect: dialect.name.clone(),
            what: "a 5-axis or 3+2 program in inches".into(),
            fix: "write it in millimetres (inch output is 3-axis only)".into(),
        });
    }
    program_text_with(program, kin, dialect, params, true)
}

/// [`program_text`]; `fast: false` writes every block through the general path with
/// modal words compared as formatted text (the reference the fast paths are tested
/// against).
fn program_text_with(
    program: &MachineProgram,
    kin: &Kinematics,
    dialect: &Dialect,
    params: &PostParams,
    fast: bool,
) -> Result<String, PostError> {
    let machine = kin.machine();
    check_axis_count(program, machine, dialect)?;
    let tcp = tcp_codes(machine, dialect, params.mode)?;
    let planes = params.mode == OutputMode::TiltedPlane && dialect.tilted_plane != TiltedPlane::None;
    let vars = header_vars(machine, dialect, params, planes);
    let mut e = Emitter::new(dialect);
    e.fast = fast;
    write_preamble(&mut e, machine, dialect, &vars, tcp)?;
    let layout = AxisLayout::new(machine, dialect, params.mode, fast);
    if planes {
        write_plane_blocks(&mut e, program, kin, params, &layout)?;
    } else {
        write_joint_blocks(&mut e, program, kin, params.mode, &layout)?;
    }
    if let Some(codes) = tcp {
        for l in &codes.off {
            e.line(&vars.render(l));
        }
    }
    for f in &dialect.footer {
        e.line(&vars.render(f));
    }
    // INVARIANT: the text is built from `str` pieces and ASCII numbers only.
    Ok(String::from_utf8(e.text).unwrap_or_else(|err| String::from_utf8_lossy(err.as_bytes()).into_owned()))
}

/// [`PostError::Unsupported`] in `dialect`.
fn unsupported(dialect: &Dialect, what: String, fix: &str) -> PostError {
    PostError::Unsupported { dialect: dialect.name.clone(), what, fix: fix.to_string() }
}

/// A machine with more axes than the controller drives is accepted only when its extra
/// (rotary) words never leave zero in the dialect's rotary decimals.
fn check_axis_count(
    program: &MachineProgram,
    machine: &scallop_machine::Machine,
    dialect: &Dialect,
) -> Result<(), PostError> {
    if machine.axes().len() <= dialect.max_axes {
        return Ok(());
    }
    let rotary: Vec<usize> =
        (0..machine.axes().len()).filter(|&i| machine.axes()[i].kind == AxisKind::Rotary).collect();
    let half = 0.5 * 10f64.powi(-i32::try_from(dialect.rotary_decimals).unwrap_or(4));
    match program.blocks.iter().find(|b| rotary.iter().any(|&i| b.words[i].abs() >= half)) {
        Some(b) => Err(unsupported(
            dialect,
            format!("a rotary move (block of CL {}) on a {}-axis controller", b.cl_index, dialect.max_axes),
            "use a 5-axis dialect, or a 3-axis toolpath with the tool along the machine Z",
        )),
        None => Ok(()),
    }
}

/// The dialect's TCP codes in TCP output (`None` in the other modes); an error when the
/// dialect or the machine has no TCP.
fn tcp_codes<'d>(
    machine: &scallop_machine::Machine,
    dialect: &'d Dialect,
    mode: OutputMode,
) -> Result<Option<&'d TcpCodes>, PostError> {
    if mode != OutputMode::Tcp {
        return Ok(None);
    }
    let codes = dialect.tcp.as_ref().ok_or_else(|| unsupported(dialect, "TCP output".into(), "use joint output"))?;
    if !machine.tcp().supported {
        return Err(unsupported(
            dialect,
            format!("TCP on machine `{}` (its [tcp] says unsupported)", machine.name()),
            "use joint output",
        ));
    }
    Ok(Some(codes))
}

/// The template variables of the header, tool change and footer lines; `planes`: the
/// tilted-plane mode writes tilted planes (else joint space with the rotaries held).
fn header_vars(machine: &scallop_machine::Machine, dialect: &Dialect, params: &PostParams, planes: bool) -> Vars {
    let mode = params.mode;
    let mode_name = match mode {
        OutputMode::TiltedPlane if !planes => "tilted_plane (joint space, rotaries held)",
        m => m.name(),
    };
    let tool_length = if mode == OutputMode::Tcp || machine.tool_length_mode() == ToolLengthMode::Controller {
        format!("length applied by the controller, kinematics length {} mm", fmt_number(params.tool_length, 4))
    } else {
        format!("baked length {} mm: this program runs only with this tool length", fmt_number(params.tool_length, 4))
    };
    Vars {
        pairs: vec![
            ("program", params.program.clone()),
            ("dialect", dialect.name.clone()),
            ("machine", machine.name().to_string()),
            ("mode", mode_name.to_string()),
            ("tool", params.tool.to_string()),
            ("tool_length", tool_length),
            ("tol_pos", fmt_number(params.tol_pos, 4)),
            ("tol_ang", fmt_number(params.tol_ang.to_degrees(), 4)),
            ("time", params.predicted_time.map_or_else(|| "not computed".to_string(), |t| format!("{t:.1} s"))),
            ("spindle", fmt_number(params.spindle, 0)),
            ("version", env!("CARGO_PKG_VERSION").to_string()),
            ("machine_tcp_on", machine.tcp().on.clone().unwrap_or_default()),
            ("machine_tcp_off", machine.tcp().off.clone().unwrap_or_default()),
        ],
    }
}

/// Header comments, header lines, the tool change, then TCP on (`tcp`) or the joint
/// kinematics and tool length offset lines.
fn write_preamble(
    e: &mut Emitter,
    machine: &scallop_machine::Machine,
    dialect: &Dialect,
    vars: &Vars,
    tcp: Option<&TcpCodes>,
) -> Result<(), PostError> {
    for c in &dialect.header_comments {
        e.comment(&vars.render(c));
    }
    for h in dialect.header.iter().chain(&dialect.tool_change) {
        e.line(&vars.render(h));
    }
    if let Some(codes) = tcp {
        for l in &codes.on {
            let text = vars.render(l);
            if text.trim().is_empty() {
                return Err(unsupported(
                    dialect,
                    format!("TCP on machine `{}` without `tcp.on`/`tcp.off` codes", machine.name()),
                    "declare the configuration's TCP codes in the machine description's [tcp]",
                ));
            }
            e.line(&text);
        }
        return Ok(());
    }
    for l in &dialect.joint_kinematics {
        let text = vars.render(l);
        if !text.trim().is_empty() {
            e.line(&text);
        }
    }
    if machine.tool_length_mode() == ToolLengthMode::Controller {
        for l in &dialect.length_offset {
            e.line(&vars.render(l));
        }
    }
    Ok(())
}

/// The component (0, 1, 2) of the tip that the linear axis `i` writes in TCP and
/// tilted-plane output; an error for a linear axis not named X, Y or Z.
fn linear_component(machine: &scallop_machine::Machine, dialect: &Dialect, i: usize) -> Result<usize, PostError> {
    match machine.axes()[i].name.as_str() {
        "X" => Ok(0),
        "Y" => Ok(1),
        "Z" => Ok(2),
        other => Err(PostError::Unsupported {
            dialect: dialect.name.clone(),
            what: format!("TCP or tilted-plane output with a linear axis named `{other}`"),
            fix: "name the linear axes X, Y, Z, or use joint output".into(),
        }),
    }
}

/// How the machine's axes are written in one program, decided once.
struct AxisLayout {
    /// The word letter of each machine axis.
    letters: Vec<String>,
    /// The machine axes that are written (all of them, or the linear ones when the
    /// controller drives fewer axes than the machine has).
    written: Vec<usize>,
    /// The modulo-360 rotaries (their joint indices).
    modulo: Vec<usize>,
    /// Joint-space output whose words are all joint words with one-letter names: the
    /// letters and decimals of the steady-state G93 blocks of `Emitter::joint_block`.
    fast_joint: Option<(Vec<u8>, Vec<usize>)>,
    /// Per written word: the decimals when it is the joint word itself (joint-space output
    /// of a linear or absolute rotary axis), the common case decided once.
    joint_decimals: Vec<Option<usize>>,
}

impl AxisLayout {
    fn new(machine: &scallop_machine::Machine, dialect: &Dialect, mode: OutputMode, fast: bool) -> AxisLayout {
        let axes = machine.axes();
        let letters: Vec<String> = axes.iter().map(|a| dialect.axis_word(&a.name).to_string()).collect();
        let written: Vec<usize> =
            (0..axes.len()).filter(|&i| axes[i].kind == AxisKind::Linear || axes.len() <= dialect.max_axes).collect();
        let modulo: Vec<usize> =
            (0..axes.len()).filter(|&i| axes[i].kind == AxisKind::Rotary && axes[i].wrap != Wrap::Absolute).collect();
        let fast_joint: Option<(Vec<u8>, Vec<usize>)> = (fast && mode == OutputMode::Joint && written.len() <= 5)
            .then(|| {
                written
                    .iter()
                    .map(|&i| {
                        let axis = &axes[i];
                        let dec = match axis.kind {
                            AxisKind::Linear => dialect.decimals,
                            AxisKind::Rotary if axis.wrap == Wrap::Absolute => dialect.rotary_decimals,
                            AxisKind::Rotary => return None,
                        };
                        match letters[i].as_bytes() {
                            &[l] => Some((l, dec)),
                            _ => None,
                        }
                    })
                    .collect::<Option<Vec<(u8, usize)>>>()
            })
            .flatten()
            .map(|v| v.into_iter().unzip());
        let joint_decimals: Vec<Option<usize>> = written
            .iter()
            .map(|&i| {
                let axis = &axes[i];
                match axis.kind {
                    AxisKind::Linear if mode != OutputMode::Tcp => Some(dialect.decimals),
                    AxisKind::Rotary if axis.wrap == Wrap::Absolute => Some(dialect.rotary_decimals),
                    _ => None,
                }
            })
            .collect();
        AxisLayout { letters, written, modulo, fast_joint, joint_decimals }
    }
}

/// 3+2 output ([`OutputMode::TiltedPlane`] in a dialect with tilted planes): a tilted
/// plane per run of blocks with one tool axis (within `params.tol_ang`), switched on
/// rapids only, X/Y/Z of the tip in that plane; the plane is reset at the end.
fn write_plane_blocks(
    e: &mut Emitter,
    program: &MachineProgram,
    kin: &Kinematics,
    params: &PostParams,
    layout: &AxisLayout,
) -> Result<(), PostError> {
    let (machine, dialect) = (kin.machine(), e.d);
    let mut previous: Option<&ProgramBlock> = None;
    // The tool axis of the plane in force (as its first block has it) and its frame.
    let mut plane: Option<(Vec3, SetupFrame)> = None;
    for b in &program.blocks {
        let needs_new = plane.as_ref().is_none_or(|(axis, _)| angle(axis, &b.pose.axis) > params.tol_ang);
        if needs_new {
            if previous.is_some() && b.motion != Motion::Rapid {
                return Err(unsupported(
                    dialect,
                    format!("a tool-axis change on a cutting move (CL {}) in tilted-plane output", b.cl_index),
                    "reorient on rapids only (3+2 work), or use joint or TCP output for simultaneous 5-axis moves",
                ));
            }
            if plane.is_some() {
                e.plane_off();
            }
            let frame = SetupFrame::tilted_plane(&b.pose.axis);
            let dir = if b.words[kin.tilt_axis()] >= 0.0 { 1 } else { -1 };
            e.plane_on(&frame.plane(), dir);
            plane = Some((b.pose.axis, frame));
        }
        let local = plane.as_ref().map_or(b.pose.tip, |(_, frame)| frame.to_setup(&b.pose.tip));
        let mut words = Vec::new();
        for i in 0..machine.axes().len() {
            if machine.axes()[i].kind == AxisKind::Linear {
                let component = linear_component(machine, dialect, i)?;
                words.push((layout.letters[i].as_str(), e.num(local[component], dialect.decimals)));
            }
        }
        let feed = if b.motion == Motion::Rapid { FeedWord::Rapid } else { FeedWord::PerMinute(b.feed) };
        e.motion(&words, feed);
        previous = Some(b);
    }
    if plane.is_some() {
        e.plane_off();
    }
    Ok(())
}

/// Joint-space and TCP output: every block, cut into [`pieces`] so that no modulo rotary
/// turns half a turn in one block, with its feed word ([`block_feed`]) and its words
/// ([`fill_words`]); steady-state G93 blocks through `Emitter::joint_block`.
fn write_joint_blocks(
    e: &mut Emitter,
    program: &MachineProgram,
    kin: &Kinematics,
    mode: OutputMode,
    layout: &AxisLayout,
) -> Result<(), PostError> {
    let caps = RateCaps::new(kin.machine(), e.d);
    // One word per written axis, reused block after block: numbers are compared with the
    // modal words as scaled integers and formatted only when written.
    let mut words: Vec<Word> = layout.written.iter().map(|&i| Word::new(layout.letters[i].as_str())).collect();
    let mut previous: Option<&ProgramBlock> = None;
    for b in &program.blocks {
        let pieces = previous.map_or(1, |p| pieces(&layout.modulo, p, b));
        for piece in 1..=pieces {
            let at = Piece { from: previous.unwrap_or(b), to: b, piece, pieces };
            let feed = block_feed(kin, e.d, mode, &caps, previous, b, pieces);
            if let (Some((letters, decimals)), FeedWord::InverseTime(f_inv)) = (&layout.fast_joint, feed) {
                let mut values = [0.0; 5];
                for (v, &i) in values.iter_mut().zip(&layout.written) {
                    *v = at.word(i);
                }
                if e.joint_block(letters, decimals, &values[..layout.written.len()], f_inv) {
                    continue;
                }
            }
            fill_words(e, &mut words, kin.machine(), mode, layout, &at)?;
            e.motion_words(&mut words, feed);
        }
        previous = Some(b);
    }
    Ok(())
}

/// Piece `piece` of `pieces` of the block `from -> to` (linear in the words).
struct Piece<'b> {
    from: &'b ProgramBlock,
    to: &'b ProgramBlock,
    piece: u32,
    pieces: u32,
}

impl Piece<'_> {
    /// Word `i` at the end of this piece.
    fn word(&self, i: usize) -> f64 {
        let s = f64::from(self.piece) / f64::from(self.pieces);
        self.from.words[i] + (self.to.words[i] - self.from.words[i]) * s
    }

    /// Word `i` at the start of this piece.
    fn word_before(&self, i: usize) -> f64 {
        word_at_prev(&self.from.words, &self.to.words, i, self.piece, self.pieces)
    }

    /// The tool tip at the end of this piece (part frame).
    fn tip(&self) -> Point3 {
        let s = f64::from(self.piece) / f64::from(self.pieces);
        self.from.pose.tip + (self.to.pose.tip - self.from.pose.tip) * s
    }
}

/// The feed word of a piece of the block `b` (one of `pieces`): rapid, the tip feed
/// (first block, TCP output), or the inverse-time feed capped by the axis velocities, in
/// the dialect's form of feed by time.
fn block_feed(
    kin: &Kinematics,
    dialect: &Dialect,
    mode: OutputMode,
    caps: &RateCaps,
    previous: Option<&ProgramBlock>,
    b: &ProgramBlock,
    pieces: u32,
) -> FeedWord {
    match (b.motion, previous) {
        (Motion::Rapid, _) => FeedWord::Rapid,
        (_, None) => FeedWord::PerMinute(b.feed),
        (_, Some(_)) if mode == OutputMode::Tcp => FeedWord::PerMinute(b.feed),
        (_, Some(p)) => {
            let f_inv = b.inverse_time.unwrap_or_else(|| {
                scallop_machine::feed::inverse_time_feed(kin, &p.pose, &b.pose, &p.joints, &b.joints, b.feed)
            }) * f64::from(pieces);
            let f_inv = caps.cap(&p.words, &b.words, pieces, f_inv);
            match dialect.feed_by_time {
                FeedByTime::G93 => FeedWord::InverseTime(f_inv),
                FeedByTime::BlockSeconds => FeedWord::Seconds(60.0 / f_inv),
                FeedByTime::None => {
                    let delta: Vec<f64> = (0..5).map(|i| (b.words[i] - p.words[i]) / f64::from(pieces)).collect();
                    FeedWord::PerMinute(controller_length(kin.machine(), &delta) * f_inv)
                }
            }
        }
    }
}

/// The words of a piece: joint words, the tip in TCP output, absolute or modulo rotary
/// words (the latter as tokens with the dialect's direction templates).
fn fill_words(
    e: &Emitter,
    words: &mut [Word],
    machine: &scallop_machine::Machine,
    mode: OutputMode,
    layout: &AxisLayout,
    at: &Piece,
) -> Result<(), PostError> {
    let dialect = e.d;
    for ((word, &i), &joint_dec) in words.iter_mut().zip(&layout.written).zip(&layout.joint_decimals) {
        if let Some(dec) = joint_dec {
            word.set_number(at.word(i), dec);
            continue;
        }
        let axis = &machine.axes()[i];
        match axis.kind {
            AxisKind::Linear if mode == OutputMode::Tcp => {
                word.set_number(at.tip()[linear_component(machine, dialect, i)?], dialect.decimals);
            }
            AxisKind::Linear => word.set_number(at.word(i), dialect.decimals),
            AxisKind::Rotary if axis.wrap == Wrap::Absolute => {
                word.set_number(at.word(i), dialect.rotary_decimals);
            }
            AxisKind::Rotary => {
                let w = at.word(i);
                let token = e.rotary(word.letter, w, w - at.word_before(i), axis.wrap);
                word.set_token(token.as_bytes());
            }
        }
    }
    Ok(())
}

/// Per-axis data of [`RateCaps::cap`], computed once per program.
struct RateCaps {
    /// `(rounding unit of the word, vmax in word units per second)` per axis.
    axes: Vec<(f64, f64)>,
}

impl RateCaps {
    fn new(machine: &scallop_machine::Machine, dialect: &Dialect) -> RateCaps {
        let axes = machine
            .axes()
            .iter()
            .map(|axis| {
                let (decimals, vmax) = match axis.kind {
                    AxisKind::Linear => (dialect.decimals, axis.dynamics.vmax),
                    AxisKind::Rotary => (dialect.rotary_decimals, axis.dynamics.vmax.to_degrees()),
                };
                (pow10i(-i32::try_from(decimals).unwrap_or(4)), vmax)
            })
            .collect();
        RateCaps { axes }
    }

    /// Caps an inverse-time word so that no axis exceeds its velocity even when its
    /// rounded words move it by one rounding unit more than the exact delta.
    fn cap(&self, a: &[f64; 5], b: &[f64; 5], pieces: u32, f_inv: f64) -> f64 {
        let mut cap = f_inv;
        for (i, &(unit, vmax)) in self.axes.iter().enumerate() {
            let delta = (b[i] - a[i]).abs() / f64::from(pieces);
            if delta == 0.0 {
                continue;
            }
            cap = cap.min(60.0 * vmax / (delta + unit));
        }
        cap
    }
}

fn word_at_prev(a: &[f64; 5], b: &[f64; 5], i: usize, piece: u32, pieces: u32) -> f64 {
    a[i] + (b[i] - a[i]) * f64::from(piece - 1) / f64::from(pieces)
}

/// Angle between two unit vectors (rad).
pub(crate) fn angle(a: &Vec3, b: &Vec3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// Number of equal pieces so that no modulo-360 rotary (`modulo`: their joint indices)
/// turns 180 deg or more in one block (spec 3.7: the control takes the shortest path).
fn pieces(modulo: &[usize], a: &ProgramBlock, b: &ProgramBlock) -> u32 {
    let mut n = 1.0f64;
    for &i in modulo {
        n = n.max(((b.words[i] - a.words[i]).abs() / tol::MODULO_HALF_TURN).floor() + 1.0);
    }
    // INVARIANT: n is a small positive integer (a block turns a few revolutions at most).
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "small positive integer")]
    let n = n as u32;
    n
}

/// The controller's length of a block from its word deltas (spec 3.9, `nc.g94_feed_norm`).
fn controller_length(machine: &scallop_machine::Machine, delta: &[f64]) -> f64 {
    let (mut lin, mut rot) = (0.0, 0.0);
    for (axis, d) in machine.axes().iter().zip(delta) {
        match axis.kind {
            AxisKind::Linear => lin += d * d,
            AxisKind::Rotary => rot += d * d,
        }
    }
    match machine.nc().g94_feed_norm {
        scallop_machine::FeedNorm::XyzThenAbc if lin > 0.0 => lin.sqrt(),
        scallop_machine::FeedNorm::XyzThenAbc => rot.sqrt(),
        _ => (lin + rot).sqrt(),
    }
}

struct Vars {
    pairs: Vec<(&'static str, String)>,
}

impl Vars {
    fn render(&self, template: &str) -> String {
        let mut s = template.to_string();
        for (k, v) in &self.pairs {
            s = s.replace(&format!("{{{k}}}"), v);
        }
        s
    }
}

#[derive(Clone, Copy)]
enum FeedWord {
    Rapid,
    PerMinute(f64),
    InverseTime(f64),
    Seconds(f64),
}

/// One word of a motion block: a number, compared with the modal word as a scaled
/// integer ([`crate::scaled_key`]) and formatted only when it is written, or a ready
/// token (modulo rotary words, tilted-plane words).
struct Word<'l> {
    letter: &'l str,
    /// `(value, decimals)`; `None`: the word is `token`.
    number: Option<(f64, usize)>,
    /// The full token when `number` is `None`; scratch otherwise.
    token: Vec<u8>,
}

impl<'l> Word<'l> {
    fn new(letter: &'l str) -> Word<'l> {
        Word { letter, number: None, token: Vec::with_capacity(24) }
    }

    fn set_number(&mut self, v: f64, decimals: usize) {
        self.number = Some((v, decimals));
    }

    fn set_token(&mut self, token: &[u8]) {
        self.number = None;
        self.token.clear();
        self.token.extend_from_slice(token);
    }
}

/// Most words of a block the fast modal comparison handles.
const FAST_WORDS: usize = 8;

/// The last written value of a word letter (or of the feed word).
#[derive(Clone, Debug, PartialEq)]
enum Modal {
    /// A number written by the integer fast path: `(scaled key, decimals)`.
    Key(i64, usize),
    /// Any other token, as written.
    Token(Vec<u8>),
}

/// Line writer with numbering and modal state.
struct Emitter<'a> {
    d: &'a Dialect,
    /// The program text, UTF-8 built as bytes (numbers are written as ASCII bytes).
    text: Vec<u8>,
    number: u64,
    /// Last written value per word letter, `(letter, value)`, in first-use order: a few
    /// entries searched linearly (cheaper than a map for five axes).
    last_words: Vec<(String, Modal)>,
    last_motion: Option<&'static str>,
    /// Last written feed number (without its letter).
    last_feed: Option<Modal>,
    g93: bool,
    /// Reused per-word state of `motion_words`: `(index in last_words, scaled key,
    /// differs from the modal word)`.
    state: Vec<(Option<usize>, Option<i64>, bool)>,
    /// Scratch token buffers for the slow comparisons.
    scratch: (Vec<u8>, Vec<u8>),
    /// The modal state was checked to be the steady state of [`Emitter::joint_block`]
    /// (reset by every other motion or plane output).
    joint_steady: bool,
    /// The fast paths are enabled (`false` only in tests: text comparison throughout).
    fast: bool,
}

impl<'a> Emitter<'a> {
    fn new(d: &'a Dialect) -> Emitter<'a> {
        Emitter {
            d,
            text: Vec::new(),
            number: d.line_numbers.as_ref().map_or(0, |n| n.start),
            last_words: Vec::new(),
            last_motion: None,
            last_feed: None,
            g93: false,
            state: Vec::new(),
            scratch: (Vec::new(), Vec::new()),
            joint_steady: false,
            fast: true,
        }
    }

    /// The index in `last_words` of `letter`, tried first at `hint` (blocks list their
    /// words in one order, so the hint is almost always right).
    fn last_index(&self, hint: usize, letter: &str) -> Option<usize> {
        if self.last_words.get(hint).is_some_and(|(l, _)| short_eq(l.as_bytes(), letter.as_bytes())) {
            return Some(hint);
        }
        self.last_words.iter().position(|(l, _)| short_eq(l.as_bytes(), letter.as_bytes()))
    }

    fn line(&mut self, s: &str) {
        self.line_bytes(s.as_bytes());
    }

    /// Starts a line: the line number when the dialect numbers lines.
    fn line_start(&mut self) {
        if let Some(n) = &self.d.line_numbers {
            self.text.extend_from_slice(n.prefix.as_bytes());
            let mut bytes = [0u8; 32];
            // INVARIANT: line numbers stay far below i64::MAX.
            let at = crate::write_key(&mut bytes, i64::try_from(self.number).unwrap_or(i64::MAX), 0);
            self.text.extend_from_slice(&bytes[at..]);
            self.text.push(b' ');
            self.number += n.step;
        }
    }

    fn line_bytes(&mut self, s: &[u8]) {
        if s != b"%" {
            self.line_start();
        }
        self.text.extend_from_slice(s);
        self.text.push(b'\n');
    }

    fn comment(&mut self, s: &str) {
        let (open, close) = (&self.d.comment.0, &self.d.comment.1);
        let clean: String = if close.is_empty() {
            s.chars().map(|c| if c == '\n' { ' ' } else { c }).collect()
        } else {
            s.chars().map(|c| if c == '(' || c == ')' || c == '\n' { '_' } else { c }).collect()
        };
        let line = format!("{open}{clean}{close}");
        self.line(&line);
    }

    /// `letter` followed by `v` as [`Emitter::num`] writes it, in one allocation.
    fn token(&self, letter: &str, v: f64, decimals: usize) -> String {
        let mut s = String::with_capacity(letter.len() + 16);
        s.push_str(letter);
        crate::push_number(&mut s, v, decimals);
        if self.d.explicit_plus && !s[letter.len()..].starts_with('-') {
            s.insert(letter.len(), '+');
        }
        s
    }

    /// Appends `letter` and the number `v` (its scaled key when known) as
    /// [`Emitter::token`] writes them.
    fn push_number_token(out: &mut Vec<u8>, explicit_plus: bool, letter: &str, v: f64, key: Option<i64>, dec: usize) {
        match letter.as_bytes() {
            &[l] => out.push(l),
            l => out.extend_from_slice(l),
        }
        match key {
            Some(key) => {
                if explicit_plus && key >= 0 {
                    out.push(b'+');
                }
                crate::push_key(out, key, dec);
            }
            None => {
                if explicit_plus {
                    out.push(b'+');
                }
                let at = out.len();
                crate::push_number_bytes(out, v, dec);
                if explicit_plus && out.get(at) == Some(&b'-') {
                    out.remove(at - 1);
                }
            }
        }
    }

    /// Appends the modal value `m` of `letter` as it was written.
    fn push_modal_token(out: &mut Vec<u8>, explicit_plus: bool, letter: &str, m: &Modal) {
        match m {
            Modal::Key(key, dec) => Self::push_number_token(out, explicit_plus, letter, 0.0, Some(*key), *dec),
            Modal::Token(t) => out.extend_from_slice(t),
        }
    }

    fn num(&self, v: f64, decimals: usize) -> String {
        let s = fmt_number(v, decimals);
        if self.d.explicit_plus && !s.starts_with('-') { format!("+{s}") } else { s }
    }

    /// A rotary word: absolute, or modulo 360 with the dialect's templates.
    fn rotary(&self, letter: &str, word: f64, delta: f64, wrap: Wrap) -> String {
        let dec = self.d.rotary_decimals;
        let token = |value: String, template: Option<&String>| match template {
            Some(t) => t.replace("{axis}", letter).replace("{value}", &value),
            None => format!("{letter}{value}"),
        };
        match wrap {
            Wrap::Absolute => self.token(letter, word, dec),
            _ => {
                let mut m = word.rem_euclid(360.0);
                if fmt_number(m, dec) == fmt_number(360.0, dec) {
                    m = 0.0;
                }
                let value = self.num(m, dec);
                let t = self.d.modulo_words.as_ref().map(|w| match wrap {
                    Wrap::Modulo360Signed if delta >= 0.0 => &w.positive,
                    Wrap::Modulo360Signed => &w.negative,
                    _ => &w.shortest,
                });
                token(value, t)
            }
        }
    }

    /// A motion block from `(letter, number)` pairs.
    fn motion(&mut self, words: &[(&str, String)], feed: FeedWord) {
        let mut tokens: Vec<Word> = words
            .iter()
            .map(|(l, v)| {
                let mut w = Word::new(l);
                w.set_token(format!("{l}{v}").as_bytes());
                w
            })
            .collect();
        self.motion_words(&mut tokens, feed);
    }

    /// Whether `word` (with its scaled key) writes the same token as the modal value `last`.
    fn same_as(
        scratch: &mut (Vec<u8>, Vec<u8>),
        plus: bool,
        last: &Modal,
        word: &Word,
        key: Option<i64>,
        by_key: bool,
    ) -> bool {
        match (last, word.number, key) {
            (Modal::Key(k, d), Some((_, dw)), Some(kw)) if by_key && *d == dw => *k == kw,
            _ => {
                let (a, b) = scratch;
                a.clear();
                b.clear();
                Self::push_modal_token(a, plus, word.letter, last);
                match word.number {
                    Some((v, dec)) => Self::push_number_token(b, plus, word.letter, v, key, dec),
                    None => b.extend_from_slice(&word.token),
                }
                short_eq(a, b)
            }
        }
    }

    /// Whether two modal feed values write the same number.
    fn same_feed(scratch: &mut (Vec<u8>, Vec<u8>), last: &Modal, new: &Modal) -> bool {
        match (last, new) {
            (Modal::Key(k, d), Modal::Key(kn, dn)) if d == dn => k == kn,
            _ => {
                let (a, b) = scratch;
                a.clear();
                b.clear();
                Self::push_modal_token(a, false, "", last);
                Self::push_modal_token(b, false, "", new);
                short_eq(a, b)
            }
        }
    }

    /// Appends a space (unless the line is still empty after `start`), then `word`.
    fn push_word(&mut self, start: usize, word: &Word, key: Option<i64>) {
        let space = self.text.len() > start;
        if let (true, Some((_, dec)), Some(key), &[letter]) = (self.fast, word.number, key, word.letter.as_bytes()) {
            // One letter and a scaled key: the token in one piece.
            // The prefix right-aligned in four bytes: [space] letter [+].
            let (prefix, len) = if self.d.explicit_plus && key >= 0 {
                ([0, b' ', letter, b'+'], 2 + usize::from(space))
            } else {
                ([0, 0, b' ', letter], 1 + usize::from(space))
            };
            crate::push_token_key(&mut self.text, prefix, len, key, dec);
            return;
        }
        if space {
            self.text.push(b' ');
        }
        match word.number {
            Some((v, dec)) => Self::push_number_token(&mut self.text, self.d.explicit_plus, word.letter, v, key, dec),
            None => self.text.extend_from_slice(&word.token),
        }
    }

    /// Appends a space (unless the line is still empty after `start`), then `t`.
    fn push_piece(&mut self, start: usize, t: &[u8]) {
        if self.text.len() > start {
            self.text.push(b' ');
        }
        self.text.extend_from_slice(t);
    }

    /// The feed number `f` (rounded down to `dec`) after `letter`, unless it equals the
    /// modal feed and `always` is false. Updates the modal feed.
    fn feed_word(&mut self, start: usize, letter: &[u8], f: f64, dec: usize, always: bool) {
        let f = round_down(f, dec);
        let key = crate::scaled_key(f, dec);
        if let (true, true, Some(k), &[l]) = (self.fast, always, key, letter) {
            // Written on every block (G93): no comparison, one token.
            let len = 1 + usize::from(self.text.len() > start);
            crate::push_token_key(&mut self.text, [0, 0, b' ', l], len, k, dec);
            match &mut self.last_feed {
                Some(Modal::Key(last, last_dec)) => (*last, *last_dec) = (k, dec),
                last => *last = Some(Modal::Key(k, dec)),
            }
            return;
        }
        let value = match key {
            Some(k) => Modal::Key(k, dec),
            None => Modal::Token(fmt_number(f, dec).into_bytes()),
        };
        if always
            || !self.d.modal
            || !self.last_feed.as_ref().is_some_and(|last| Self::same_feed(&mut self.scratch, last, &value))
        {
            match &value {
                Modal::Key(k, dec) if self.fast && letter.len() <= 3 => {
                    let mut prefix = [b' '; 4];
                    prefix[4 - letter.len()..].copy_from_slice(letter);
                    let len = letter.len() + usize::from(self.text.len() > start);
                    crate::push_token_key(&mut self.text, prefix, len, *k, *dec);
                }
                Modal::Key(k, dec) => {
                    self.push_piece(start, letter);
                    crate::push_key(&mut self.text, *k, *dec);
                }
                Modal::Token(t) => {
                    self.push_piece(start, letter);
                    self.text.extend_from_slice(t);
                }
            }
            self.last_feed = Some(value);
        }
    }

    /// The codes of a motion block before its words: G93/G94 and the motion code (ISO),
    /// `L` (Heidenhain).
    fn motion_codes(&mut self, start: usize, feed: FeedWord) {
        match self.d.syntax {
            Syntax::Iso => {
                let want_g93 = matches!(feed, FeedWord::InverseTime(_));
                if want_g93 != self.g93 {
                    self.push_piece(start, if want_g93 { b"G93" } else { b"G94" });
                    self.g93 = want_g93;
                    self.last_feed = None;
                }
                let code = if matches!(feed, FeedWord::Rapid) { "G0" } else { "G1" };
                if !self.d.modal || self.last_motion != Some(code) {
                    self.push_piece(start, code.as_bytes());
                    self.last_motion = Some(code);
                }
            }
            Syntax::Heidenhain => self.push_piece(start, b"L"),
        }
    }

    /// The feed word of a motion block, after its words.
    fn feed_codes(&mut self, start: usize, feed: FeedWord) {
        match self.d.syntax {
            // G93 needs F on every block (`always`).
            Syntax::Iso => match feed {
                FeedWord::Rapid | FeedWord::Seconds(_) => {}
                FeedWord::PerMinute(f) => self.feed_word(start, b"F", f, self.d.feed_decimals, false),
                FeedWord::InverseTime(f) => self.feed_word(start, b"F", f, self.d.inverse_time_decimals, true),
            },
            Syntax::Heidenhain => match feed {
                FeedWord::Rapid => {
                    self.push_piece(start, b"FMAX");
                    self.last_feed = None;
                }
                FeedWord::Seconds(t) => {
                    let dec = self.d.inverse_time_decimals;
                    let ft = format!("FT{}", fmt_number(round_up(t, dec), dec));
                    self.push_piece(start, ft.as_bytes());
                    self.last_feed = None;
                }
                FeedWord::PerMinute(f) | FeedWord::InverseTime(f) => {
                    self.feed_word(start, b"F", f, self.d.feed_decimals, false);
                }
            },
        }
    }

    /// A joint-space G93 block in the steady state of modal ISO output (G93 and G1 in
    /// force, the words `letters` with `decimals` modal in this order, no explicit plus):
    /// exactly the text [`Emitter::motion_words`] writes for it, without its general
    /// machinery. Returns `false`, having written nothing, when the state or a number is
    /// not of that form (the caller then uses [`Emitter::motion_words`]).
    fn joint_block(&mut self, letters: &[u8], decimals: &[usize], values: &[f64], f_inv: f64) -> bool {
        let n = values.len();
        if !self.joint_steady {
            let steady = self.d.modal
                && self.d.syntax == Syntax::Iso
                && !self.d.explicit_plus
                && self.g93
                && self.last_motion == Some("G1")
                && self.last_words.len() >= n
                && letters.len() == n
                && decimals.len() == n
                && self.last_words.iter().zip(letters.iter().zip(decimals)).all(|((l, m), (letter, dec))| {
                    short_eq(l.as_bytes(), &[*letter]) && matches!(m, Modal::Key(_, d) if d == dec)
                });
            if !steady {
                return false;
            }
            self.joint_steady = true;
        }
        let mut keys = [0i64; 5];
        let mut mask = 0u32;
        for k in 0..n {
            let Some(key) = crate::scaled_key(values[k], decimals[k]) else { return false };
            keys[k] = key;
            if matches!(self.last_words[k].1, Modal::Key(last, _) if last != key) {
                mask |= 1 << k;
            }
        }
        if mask == 0 {
            return true;
        }
        let dec = self.d.inverse_time_decimals;
        let Some(feed_key) = crate::scaled_key(round_down(f_inv, dec), dec) else { return false };
        self.line_start();
        let start = self.text.len();
        for k in 0..n {
            if mask & (1 << k) != 0 {
                let len = 1 + usize::from(self.text.len() > start);
                crate::push_token_key(&mut self.text, [0, 0, b' ', letters[k]], len, keys[k], decimals[k]);
                if let Modal::Key(last, _) = &mut self.last_words[k].1 {
                    *last = keys[k];
                }
            }
        }
        crate::push_token_key(&mut self.text, [0, 0, b' ', b'F'], 2, feed_key, dec);
        self.text.push(b'\n');
        self.last_feed = Some(Modal::Key(feed_key, dec));
        true
    }

    /// The fast form of the modal comparison of [`Emitter::motion_words`]: every word is a
    /// number with a scaled key, and the modal word at its position has its letter and a
    /// key with its decimals (the steady state of joint-space output). Returns the keys and
    /// the bit mask of the words that change; `None` sends the block to the general path.
    fn fast_changes(&self, words: &[Word]) -> Option<([i64; FAST_WORDS], u32)> {
        if !self.fast || words.len() > FAST_WORDS || !self.d.modal || words.len() > self.last_words.len() {
            return None;
        }
        let mut keys = [0i64; FAST_WORDS];
        let mut mask = 0u32;
        for (k, (word, (letter, last))) in words.iter().zip(&self.last_words).enumerate() {
            let (v, dec) = word.number?;
            let key = crate::scaled_key(v, dec)?;
            match last {
                Modal::Key(last_key, last_dec)
                    if *last_dec == dec && short_eq(letter.as_bytes(), word.letter.as_bytes()) =>
                {
                    if *last_key != key {
                        mask |= 1 << k;
                    }
                }
                _ => return None,
            }
            keys[k] = key;
        }
        Some((keys, mask))
    }

    /// A motion block. Hot path of every program: the modal comparison is done on scaled
    /// integers, and only the words that change are formatted, straight into the text.
    fn motion_words(&mut self, words: &mut [Word], feed: FeedWord) {
        self.joint_steady = false;
        if let Some((keys, mask)) = self.fast_changes(words) {
            if mask == 0 {
                return;
            }
            self.line_start();
            let start = self.text.len();
            self.motion_codes(start, feed);
            for (k, word) in words.iter().enumerate() {
                if mask & (1 << k) != 0 {
                    self.push_word(start, word, Some(keys[k]));
                    if let Modal::Key(last_key, _) = &mut self.last_words[k].1 {
                        *last_key = keys[k];
                    }
                }
            }
            self.feed_codes(start, feed);
            self.text.push(b'\n');
            return;
        }
        let mut state = std::mem::take(&mut self.state);
        state.clear();
        let mut any = false;
        for (k, word) in words.iter().enumerate() {
            let slot = self.last_index(k, word.letter);
            let key = word.number.and_then(|(v, dec)| crate::scaled_key(v, dec));
            let changed = !self.d.modal
                || match slot {
                    None => true,
                    Some(j) => !Self::same_as(
                        &mut self.scratch,
                        self.d.explicit_plus,
                        &self.last_words[j].1,
                        word,
                        key,
                        self.fast,
                    ),
                };
            any |= changed;
            state.push((slot, key, changed));
        }
        if !any {
            self.state = state;
            return;
        }
        self.line_start();
        let start = self.text.len();
        self.motion_codes(start, feed);
        for (word, &(_, key, c)) in words.iter().zip(&state) {
            if c {
                self.push_word(start, word, key);
            }
        }
        self.feed_codes(start, feed);
        self.text.push(b'\n');
        for (word, &(slot, key, _)) in words.iter().zip(&state) {
            let value = match (word.number, key) {
                (Some((_, dec)), Some(k)) => Modal::Key(k, dec),
                (Some((v, dec)), None) => {
                    let mut t = Vec::new();
                    Self::push_number_token(&mut t, self.d.explicit_plus, word.letter, v, None, dec);
                    Modal::Token(t)
                }
                (None, _) => Modal::Token(word.token.clone()),
            };
            match slot {
                Some(j) => self.last_words[j].1 = value,
                // A letter twice in one block: the later token is the modal one.
                None => match self.last_words.iter_mut().find(|(l, _)| l == word.letter) {
                    Some((_, t)) => *t = value,
                    None => self.last_words.push((word.letter.to_string(), value)),
                },
            }
        }
        self.state = state;
    }

    /// Activates a tilted plane `r` (columns x_f, y_f, z_f in the part frame) at the
    /// part origin; `dir` selects the rotary solution (sign of the tilt word).
    fn plane_on(&mut self, r: &Rotation3<f64>, dir: i32) {
        self.joint_steady = false;
        let dec = self.d.rotary_decimals;
        let deg = |v: f64| self.num(v.to_degrees(), dec);
        let lines: Vec<String> = match self.d.tilted_plane {
            TiltedPlane::None => Vec::new(),
            TiltedPlane::G68_2 => {
                let (i, j, k) = scallop_machine::frame::fanuc_g68_2(r);
                vec![format!("G68.2 X0 Y0 Z0 I{} J{} K{}", deg(i), deg(j), deg(k)), "G53.1".into()]
            }
            TiltedPlane::Cycle800 => {
                let (a, b, c) = cycle800_angles(r);
                vec![format!("CYCLE800(0,\"TC1\",200000,57,0,0,0,{},{},{},0,0,0,{dir},100,1)", deg(a), deg(b), deg(c))]
            }
            TiltedPlane::PlaneSpatial => {
                let (a, b, c) = scallop_machine::frame::plane_spatial(r);
                let seq = if dir >= 0 { "SEQ+" } else { "SEQ-" };
                vec![format!("PLANE SPATIAL SPA{} SPB{} SPC{} TURN FMAX {seq}", deg(a), deg(b), deg(c))]
            }
        };
        for l in lines {
            self.line(&l);
        }
        self.last_words.clear();
        self.last_motion = None;
    }

    fn plane_off(&mut self) {
        self.joint_steady = false;
        let l = match self.d.tilted_plane {
            TiltedPlane::None => return,
            TiltedPlane::G68_2 => "G69",
            TiltedPlane::Cycle800 => "CYCLE800()",
            TiltedPlane::PlaneSpatial => "PLANE RESET STAY",
        };
        self.line(l);
        self.last_words.clear();
        self.last_motion = None;
    }
}

/// Byte equality of short strings (word letters, tokens) without a `memcmp` call.
fn short_eq(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x == y)
}

/// `CYCLE800` axis-by-axis angles (X, then the rotated Y, then the rotated Z):
/// `R_f = Rx(a) Ry(b) Rz(c)`, so `b = atan2(R13, sqrt(R11^2 + R12^2))`,
/// `a = atan2(-R23, R33)`, `c = atan2(-R12, R11)`.
///
/// ```
/// use scallop_geom::Vec3;
/// let r = scallop_machine::frame::tilted_plane(&Vec3::new(1.0, 0.0, 1.0));
/// let (a, b, c) = scallop_post::cycle800_angles(&r);
/// assert!(a.abs() < 1e-12 && (b - std::f64::consts::FRAC_PI_4).abs() < 1e-12 && c.abs() < 1e-12);
/// ```
#[must_use]
pub fn cycle800_angles(r: &Rotation3<f64>) -> (f64, f64, f64) {
    let m = r.matrix();
    let b = m[(0, 2)].atan2(m[(0, 0)].hypot(m[(0, 1)]));
    ((-m[(1, 2)]).atan2(m[(2, 2)]), b, (-m[(0, 1)]).atan2(m[(0, 0)]))
}

#[cfg(test)]
mod tests {
    use scallop_geom::{Point3, Vec3};
    use scallop_machine::program::{ClRecord, Motion, ProgramOptions, to_program};
    use scallop_machine::{Kinematics, Machine, Pose};

    use super::{OutputMode, PostParams, program_text_with};
    use crate::Dialect;

    /// The fast paths (scaled-integer modal comparison, steady-state joint blocks) write
    /// exactly what the general path with text comparison writes, on every shipped
    /// machine and dialect, in joint and TCP output.
    #[test]
    fn fast_paths_write_the_same_text_as_the_general_path() {
        let tilt = 25f64.to_radians();
        let mut records = vec![ClRecord {
            pose: Pose::new(Point3::new(0.0, 0.0, 60.0), Vec3::new(0.1, 0.0, 1.0)),
            motion: Motion::Rapid,
            feed: 2000.0,
        }];
        for i in 0..400 {
            let t = f64::from(i) * 0.01;
            // Values that hit rounding ties now and then (multiples of 0.00005) and a
            // slow precession with pauses (unchanged words).
            let x = (20.0 * (t * 1.3).cos() * 2e4).round() / 2e4;
            let precess = 0.9 * (t * 0.7).sin() + if i % 50 < 5 { 0.0 } else { 0.01 * t };
            let axis = Vec3::new(tilt.sin() * precess.cos(), tilt.sin() * precess.sin(), tilt.cos());
            let motion = if i % 97 == 0 { Motion::Rapid } else { Motion::Feed };
            records.push(ClRecord {
                pose: Pose::new(Point3::new(x, 15.0 * (t * 0.9).sin(), 30.0 + (i % 7) as f64 * 0.5), axis),
                motion,
                feed: if i % 40 < 20 { 1500.0 } else { 2500.0 },
            });
        }
        let options = ProgramOptions::default();
        let mut compared = 0;
        for name in Machine::builtin_names() {
            let machine = Machine::builtin(name).expect("shipped machine");
            let kin = Kinematics::new(&machine, 0.0);
            let Ok(program) = to_program(&kin, &records, None, &options) else { continue };
            for dialect_name in Dialect::builtin_names() {
                let dialect = Dialect::builtin(dialect_name).expect("shipped dialect");
                for mode in [OutputMode::Joint, OutputMode::Tcp] {
                    let params = PostParams::new("7", mode, 3, 0.0, 9000.0, &options);
                    let fast = program_text_with(&program, &kin, &dialect, &params, true);
                    let general = program_text_with(&program, &kin, &dialect, &params, false);
                    match (fast, general) {
                        (Ok(a), Ok(b)) => {
                            assert_eq!(a, b, "{name} {dialect_name} {mode:?}");
                            compared += 1;
                        }
                        (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
                        (a, b) => panic!("{name} {dialect_name} {mode:?}: {a:?} vs {b:?}"),
                    }
                }
            }
        }
        assert!(compared >= 20, "only {compared} programs compared");
    }
}
