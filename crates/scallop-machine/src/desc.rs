//! Machine descriptions: the `scallop.machine/1` TOML schema (spec 2.3), parsed with serde
//! and validated once; a [`Machine`] is valid by construction.
//!
//! Units in files: mm and degrees (velocities mm/s and deg/s, accelerations mm/s^2 and
//! deg/s^2, jerks mm/s^3 and deg/s^3). Inside a [`Machine`]: mm and radians.

use std::collections::BTreeMap;

use scallop_geom::nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion};
use scallop_geom::{Point3, Vec3};
use serde::Deserialize;

use crate::error::MachineError;
use crate::tol;

/// The schema id every description must declare.
pub const SCHEMA: &str = "scallop.machine/1";

/// Joint type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AxisKind {
    /// Translation along `direction` (mm).
    Linear,
    /// Right-handed rotation about `direction` through `point` (rad inside, deg in files).
    Rotary,
}

/// Which chain carries an axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChainSide {
    /// Bed to part (a table axis): moves the part, `sigma = -1` in the Jacobian.
    Part,
    /// Bed to spindle (a head axis): moves the tool, `sigma = +1`.
    Tool,
}

/// How rotary words are written (spec 3.7).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Wrap {
    /// The unwrapped value is written.
    #[default]
    Absolute,
    /// `theta mod 360` in `[0, 360)`; the control takes the shortest way.
    #[serde(rename = "modulo360_shortest")]
    Modulo360Shortest,
    /// `theta mod 360` with an explicit direction (840D `ACP`/`ACN`).
    #[serde(rename = "modulo360_signed")]
    Modulo360Signed,
}

/// The point the CL data controls.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ControlledPoint {
    /// The tool tip.
    #[default]
    Tip,
    /// The centre of the ball end (Bettine 2019's tool frame).
    BallCentre,
}

/// Who applies the tool length (spec 3.11).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ToolLengthMode {
    /// The controller applies it (G43): kinematics run with the length the caller gives, usually 0.
    #[default]
    Controller,
    /// The length is built into the axis words.
    Baked,
}

/// Closed-form family (spec 3.3) or the generic solvers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum FamilyChoice {
    /// Detect the family from the axis directions; generic when none fits.
    #[default]
    #[serde(rename = "auto")]
    Auto,
    /// Force the generic two-rotary solver (or the numeric one when it does not apply).
    #[serde(rename = "generic")]
    Generic,
    /// Table-table, C carried by A.
    #[serde(rename = "TT-AC")]
    TtAc,
    /// Table-table, C carried by B.
    #[serde(rename = "TT-BC")]
    TtBc,
    /// Head-head, A carried by C.
    #[serde(rename = "HH-CA")]
    HhCa,
    /// Head-head, B carried by C.
    #[serde(rename = "HH-CB")]
    HhCb,
    /// B head, C table.
    #[serde(rename = "HT-BC")]
    HtBc,
    /// A head, C table.
    #[serde(rename = "HT-AC")]
    HtAc,
}

/// The NC dialect a machine's programs are written in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Dialect {
    /// Plain ISO 6983 words.
    #[default]
    Iso,
    /// LinuxCNC RS274/NGC.
    Linuxcnc,
    /// Fanuc.
    Fanuc,
    /// Siemens Sinumerik 840D.
    #[serde(rename = "siemens840d")]
    Siemens840d,
    /// Heidenhain (ISO mode or conversational).
    Heidenhain,
    /// grbl 1.1 (3-axis hobby controllers).
    Grbl,
}

/// How a controller measures F in G94 (spec 3.9).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FeedNorm {
    /// XYZ length if any of X, Y, Z moves, else the rotary length (LinuxCNC).
    #[default]
    XyzThenAbc,
    /// Euclidean norm over all words.
    AllAxes,
}

/// Output precision (decimals).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Decimals {
    /// Linear words.
    pub linear: u8,
    /// Rotary words.
    pub rotary: u8,
    /// Feed words.
    pub feed: u8,
}

impl Default for Decimals {
    fn default() -> Self {
        Decimals { linear: 4, rotary: 4, feed: 3 }
    }
}

/// Controller conventions (`[nc]`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Nc {
    /// Post-processor dialect.
    pub dialect: Dialect,
    /// G93 inverse-time feed available.
    pub inverse_time: bool,
    /// Tilted-work-plane codes available (spec 3.13).
    pub tilted_plane: bool,
    /// How F is measured in G94.
    pub g94_feed_norm: FeedNorm,
    /// Block processing floor (s).
    pub min_block_time: f64,
    /// Output precision.
    pub decimals: Decimals,
    /// Contour tolerance of the controller's blending (mm); 0 = exact stop.
    pub corner_tolerance: f64,
    /// Reference radius for pure reorientation feeds (mm).
    pub r_ref: f64,
    /// The machine changes tools by program (`T.. M6`); `false`: by hand (the program
    /// names the tool in a comment and pauses with `M0`).
    pub tool_changer: bool,
}

impl Default for Nc {
    fn default() -> Self {
        Nc {
            dialect: Dialect::Iso,
            inverse_time: false,
            tilted_plane: false,
            g94_feed_norm: FeedNorm::XyzThenAbc,
            min_block_time: 0.0,
            decimals: Decimals::default(),
            corner_tolerance: 0.0,
            r_ref: 50.0,
            tool_changer: true,
        }
    }
}

/// TCP (tool-centre-point) capability (`[tcp]`).
#[derive(Clone, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Tcp {
    /// The controller does TCP.
    pub supported: bool,
    /// Accepted forms: `rotary` (positions) and/or `vector` (tool vector).
    pub forms: Vec<String>,
    /// Code that switches TCP on (e.g. `G43.4`, `TRAORI`, `M428`).
    pub on: Option<String>,
    /// Code that switches it off.
    pub off: Option<String>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawFrame {
    origin: [f64; 3],
    rotation: [[f64; 3]; 3],
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSpindle {
    gauge_point: Option<[f64; 3]>,
    tool_axis: Option<[f64; 3]>,
    max_speed: Option<f64>,
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawChains {
    part: Vec<String>,
    tool: Vec<String>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawAxis {
    pub(crate) kind: AxisKind,
    direction: [f64; 3],
    point: Option<[f64; 3]>,
    nc_sign: Option<i32>,
    limits: Option<[f64; 2]>,
    #[serde(default)]
    continuous: bool,
    #[serde(default)]
    wrap: Wrap,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawPreferred {
    axis: String,
    sign: i32,
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(crate) struct RawKinematics {
    family: FamilyChoice,
    preferred_branch: Option<RawPreferred>,
    pole_eps: Option<f64>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawMachine {
    pub(crate) schema: String,
    pub(crate) name: String,
    #[serde(default)]
    pub(crate) source: String,
    #[serde(default)]
    controlled_point: ControlledPoint,
    #[serde(default)]
    tool_length_mode: ToolLengthMode,
    pub(crate) part_frame: Option<RawFrame>,
    #[serde(default)]
    pub(crate) spindle: RawSpindle,
    /// Absent: every axis on the tool side (3-axis machines only).
    pub(crate) chains: Option<RawChains>,
    pub(crate) axes: BTreeMap<String, RawAxis>,
    #[serde(default)]
    pub(crate) dynamics: BTreeMap<String, [f64; 3]>,
    #[serde(default)]
    pub(crate) rapid: BTreeMap<String, f64>,
    #[serde(default)]
    pub(crate) kinematics: RawKinematics,
    #[serde(default)]
    pub(crate) tcp: Tcp,
    #[serde(default)]
    pub(crate) nc: Nc,
}

impl RawMachine {
    pub(crate) fn spindle_tool_axis(&self) -> Option<[f64; 3]> {
        self.spindle.tool_axis
    }

    pub(crate) fn spindle_gauge_point(&self) -> Option<[f64; 3]> {
        self.spindle.gauge_point
    }
}

/// Feed-motion limits of one axis, internal units (mm or rad per s, s^2, s^3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dynamics {
    /// Maximum velocity.
    pub vmax: f64,
    /// Maximum acceleration.
    pub amax: f64,
    /// Maximum jerk.
    pub jmax: f64,
    /// Rapid velocity.
    pub rapid: f64,
}

/// One validated axis. Internal units: mm and rad.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    /// Name as declared (`X`, `A`, ...).
    pub name: String,
    /// Joint type.
    pub kind: AxisKind,
    /// Unit direction in the machine frame at q = 0.
    pub direction: Vec3,
    /// Rotary: a point of the axis in the machine frame at q = 0 (origin for linear axes).
    pub point: Point3,
    /// NC word = `nc_sign * q`.
    pub nc_sign: f64,
    /// Stroke in NC words, internal units (mm or rad); `None` for a continuous rotary without stops.
    pub limits: Option<(f64, f64)>,
    /// Rotary without stops.
    pub continuous: bool,
    /// How rotary words are written.
    pub wrap: Wrap,
    /// Which chain carries the axis.
    pub side: ChainSide,
    /// Feed and rapid limits.
    pub dynamics: Dynamics,
}

impl Axis {
    /// The stroke as an interval of the joint value q (mm or rad), i.e. the NC-word
    /// limits divided by `nc_sign`.
    ///
    /// ```
    /// # let m = scallop_machine::Machine::builtin("mx330").unwrap();
    /// let a = m.axis_by_name("A").unwrap();
    /// let (lo, hi) = m.axes()[a].joint_limits().unwrap();
    /// assert!(lo < hi && hi > 0.17 && hi < 0.18); // 10 degrees
    /// ```
    #[must_use]
    pub fn joint_limits(&self) -> Option<(f64, f64)> {
        self.limits.map(|(lo, hi)| if self.nc_sign > 0.0 { (lo, hi) } else { (-hi, -lo) })
    }

    /// NC-word unit of the axis in files and messages: `mm` or `deg`.
    #[must_use]
    pub fn unit(&self) -> &'static str {
        match self.kind {
            AxisKind::Linear => "mm",
            AxisKind::Rotary => "deg",
        }
    }

    /// Converts a joint value (mm or rad) to its NC word in file units (mm or deg).
    ///
    /// ```
    /// # let m = scallop_machine::Machine::builtin("mx330").unwrap();
    /// let c = &m.axes()[m.axis_by_name("C").unwrap()];
    /// assert!((c.to_nc_word(std::f64::consts::PI) - 180.0).abs() < 1e-12);
    /// ```
    #[must_use]
    pub fn to_nc_word(&self, q: f64) -> f64 {
        match self.kind {
            AxisKind::Linear => self.nc_sign * q,
            AxisKind::Rotary => (self.nc_sign * q).to_degrees(),
        }
    }

    /// The inverse of [`Axis::to_nc_word`].
    ///
    /// ```
    /// # let m = scallop_machine::Machine::builtin("mx330").unwrap();
    /// let a = &m.axes()[m.axis_by_name("A").unwrap()];
    /// assert!((a.from_nc_word(a.to_nc_word(0.3)) - 0.3).abs() < 1e-15);
    /// ```
    #[must_use]
    pub fn from_nc_word(&self, word: f64) -> f64 {
        match self.kind {
            AxisKind::Linear => self.nc_sign * word,
            AxisKind::Rotary => self.nc_sign * word.to_radians(),
        }
    }
}

/// Which way an axis moves the tool relative to the part for a positive NC word (spec 2.2, test K7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Iso841 {
    /// As ISO 841 requires (+e_x for X and A, +e_y for Y and B, +e_z for Z and C).
    Iso,
    /// The opposite: the sense of the table's own motion.
    TableMotionSense,
    /// The axis is not along its letter's base direction (or its letter is not X, Y, Z, A, B, C).
    NotAxisAligned,
}

/// Which branch of a configuration to prefer when continuity does not decide (spec 3.5).
#[derive(Clone, Debug, PartialEq)]
pub struct PreferredBranch {
    /// Index of the axis whose NC-word sign decides.
    pub axis: usize,
    /// Preferred sign (+1 or -1) of that NC word.
    pub sign: f64,
}

/// A validated machine description. Build it with [`Machine::from_toml_str`] or
/// [`Machine::builtin`]; afterwards every invariant below holds.
///
/// # Invariants
/// - Exactly 3 linear axes with independent unit directions and 2 rotary axes with
///   non-parallel unit directions (5-axis machines; 3- and 4-axis descriptions are
///   rejected as `Unsupported` in this version).
/// - Axes are stored linear first, then rotary, each group sorted by name: joint
///   vectors ([`crate::Joints`]) use this order.
/// - Every axis is in exactly one chain; every stroke has `min < max`; every dynamic
///   limit is positive and finite.
#[derive(Clone, Debug, PartialEq)]
pub struct Machine {
    pub(crate) name: String,
    pub(crate) source: String,
    pub(crate) controlled_point: ControlledPoint,
    pub(crate) tool_length_mode: ToolLengthMode,
    pub(crate) part_frame: Isometry3<f64>,
    pub(crate) gauge_point: Point3,
    pub(crate) tool_axis: Vec3,
    pub(crate) axes: Vec<Axis>,
    pub(crate) part_chain: Vec<usize>,
    pub(crate) tool_chain: Vec<usize>,
    pub(crate) family: FamilyChoice,
    pub(crate) preferred_branch: Option<PreferredBranch>,
    pub(crate) pole_eps: f64,
    pub(crate) tcp: Tcp,
    pub(crate) nc: Nc,
    pub(crate) max_spindle_speed: Option<f64>,
}

/// The machine descriptions shipped in `machines/`, by short name.
pub(crate) const BUILTIN: &[(&str, &str)] = &[
    ("mx330", include_str!("../../../machines/matsuura-mx330.toml")),
    ("ucp710", include_str!("../../../machines/mikron-ucp710.toml")),
    ("generic-tt-bc", include_str!("../../../machines/generic-table-table-bc.toml")),
    ("generic-hh-ca", include_str!("../../../machines/generic-head-head-ca.toml")),
    ("generic-ht-bc", include_str!("../../../machines/generic-head-table-bc.toml")),
    ("linuxcnc-xyzac-trt", include_str!("../../../machines/linuxcnc-xyzac-trt.toml")),
    ("linuxcnc-xyzbc-trt", include_str!("../../../machines/linuxcnc-xyzbc-trt.toml")),
];

fn vec3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// One axis of a machine file, checked: its direction, NC sign, pivot, stroke
/// (NC words in mm or degrees, stored in mm or radians), dynamics, rapid rate
/// and chain side.
/// The part frame of a machine file (identity when absent), checked: a proper
/// rotation and an origin in range.
pub(crate) fn part_frame_of(frame: Option<&RawFrame>) -> Result<Isometry3<f64>, MachineError> {
    Ok(match frame {
        None => Isometry3::identity(),
        Some(f) => {
            let m = Matrix3::from_fn(|r, c| f.rotation[r][c]);
            let err = (m.transpose() * m - Matrix3::identity()).norm();
            // `!(err <= ..)`: a NaN or infinite entry makes `err` NaN and is refused.
            if !(err <= tol::DIRECTION_NORM && m.determinant() > 0.0) {
                return Err(MachineError::invalid(
                    "part_frame.rotation",
                    "not a proper rotation matrix (orthonormal, det +1)",
                    "give the rows of a rotation matrix, e.g. [[1,0,0],[0,1,0],[0,0,1]]",
                ));
            }
            let rot = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
            let origin = point_in_range(f.origin, "part_frame.origin")?;
            Isometry3::from_parts(Translation3::from(origin.coords), rot)
        }
    })
}

/// The controller settings of a machine file: block time and corner tolerance
/// >= 0, a positive reference radius, known TCP forms.
pub(crate) fn check_controller(nc: &Nc, tcp: &Tcp) -> Result<(), MachineError> {
    for (place, v) in [("nc.min_block_time", nc.min_block_time), ("nc.corner_tolerance", nc.corner_tolerance)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(MachineError::invalid(place, format!("{v} must be >= 0"), "give a non-negative value"));
        }
    }
    if !(nc.r_ref.is_finite() && nc.r_ref > 0.0) {
        return Err(MachineError::invalid(
            "nc.r_ref",
            format!("{} must be positive", nc.r_ref),
            "give a positive radius (mm), default 50",
        ));
    }
    for form in &tcp.forms {
        if form != "rotary" && form != "vector" {
            return Err(MachineError::invalid(
                "tcp.forms",
                format!("unknown form `{form}`"),
                "use \"rotary\" and/or \"vector\"",
            ));
        }
    }
    Ok(())
}

pub(crate) fn axis_of(raw: &RawMachine, name: &String) -> Result<Axis, MachineError> {
    let a = &raw.axes[name];
    let place = format!("axes.{name}");
    let direction = unit_direction(a.direction, &format!("{place}.direction"))?;
    let nc_sign = match a.nc_sign.unwrap_or(1) {
        1 => 1.0,
        -1 => -1.0,
        s => {
            return Err(MachineError::invalid(
                format!("{place}.nc_sign"),
                format!("{s} is not +1 or -1"),
                "write nc_sign = 1 or nc_sign = -1",
            ));
        }
    };
    let point = match (a.kind, a.point) {
        (AxisKind::Rotary, Some(p)) => point_in_range(p, &format!("{place}.point"))?,
        (AxisKind::Rotary, None) => {
            return Err(MachineError::invalid(
                format!("{place}.point"),
                "a rotary axis needs a pivot point",
                "add point = [x, y, z] (mm, machine frame at q = 0)",
            ));
        }
        (AxisKind::Linear, Some(_)) => {
            return Err(MachineError::invalid(
                format!("{place}.point"),
                "a linear axis has no pivot point",
                "remove `point` from this axis",
            ));
        }
        (AxisKind::Linear, None) => Point3::origin(),
    };
    if a.kind == AxisKind::Linear && (a.continuous || a.wrap != Wrap::Absolute) {
        return Err(MachineError::invalid(
            place,
            "`continuous` and `wrap` apply to rotary axes only",
            "remove them from this linear axis",
        ));
    }
    let scale = if a.kind == AxisKind::Rotary { std::f64::consts::PI / 180.0 } else { 1.0 };
    let limits = match a.limits {
        Some([lo, hi]) => {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(MachineError::invalid(
                    format!("{place}.limits"),
                    format!("stroke [{lo}, {hi}] needs finite min < max"),
                    "write limits = [min, max] with min < max (NC words, mm or deg)",
                ));
            }
            Some((lo * scale, hi * scale))
        }
        None if a.kind == AxisKind::Rotary && a.continuous => None,
        None => {
            return Err(MachineError::invalid(
                format!("{place}.limits"),
                "missing stroke",
                "add limits = [min, max] (or continuous = true for a rotary without stops)",
            ));
        }
    };
    let dyn_place = format!("dynamics.{name}");
    let d = raw.dynamics.get(name).ok_or_else(|| {
        MachineError::invalid(
            &dyn_place,
            "missing feed-motion limits",
            "add [dynamics] NAME = [vmax, amax, jmax] (mm/s, mm/s^2, mm/s^3 or deg/s, ...)",
        )
    })?;
    if d.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return Err(MachineError::invalid(
            dyn_place,
            format!("limits {d:?} must be positive and finite"),
            "give positive [vmax, amax, jmax]",
        ));
    }
    let rapid = match raw.rapid.get(name) {
        Some(r) if !(r.is_finite() && *r > 0.0) => {
            return Err(MachineError::invalid(
                format!("rapid.{name}"),
                format!("rapid velocity {r} must be positive"),
                "give a positive rapid velocity or remove it (default: vmax)",
            ));
        }
        Some(r) => *r,
        None => d[0],
    };
    let side = match raw.chains.as_ref().map(|c| (c.part.contains(name), c.tool.contains(name))) {
        None | Some((false, true)) => ChainSide::Tool,
        Some((true, false)) => ChainSide::Part,
        Some(_) => {
            return Err(MachineError::invalid(
                "chains",
                format!("axis {name} must be in exactly one of chains.part and chains.tool"),
                format!("list {name} once, in the chain that carries it"),
            ));
        }
    };
    Ok(Axis {
        name: (name).clone(),
        kind: a.kind,
        direction,
        point,
        nc_sign,
        limits,
        continuous: a.continuous,
        wrap: a.wrap,
        side,
        dynamics: Dynamics { vmax: d[0] * scale, amax: d[1] * scale, jmax: d[2] * scale, rapid: rapid * scale },
    })
}

pub(crate) fn unit_direction(a: [f64; 3], place: &str) -> Result<Vec3, MachineError> {
    let v = vec3(a);
    let n = v.norm();
    if !n.is_finite() || (n - 1.0).abs() > tol::DIRECTION_NORM {
        return Err(MachineError::invalid(
            place,
            format!("direction ({}, {}, {}) has norm {n}, not 1", a[0], a[1], a[2]),
            format!("give a unit vector, e.g. [1, 0, 0] (norm within {} of 1)", tol::DIRECTION_NORM),
        ));
    }
    Ok(v / n)
}

/// A point of the description: finite and within [`tol::MAX_COORDINATE`] of the origin.
pub(crate) fn point_in_range(a: [f64; 3], place: &str) -> Result<Point3, MachineError> {
    if a.iter().all(|v| v.is_finite() && v.abs() <= tol::MAX_COORDINATE) {
        return Ok(Point3::new(a[0], a[1], a[2]));
    }
    Err(MachineError::invalid(
        place,
        format!("point [{:?}, {:?}, {:?}] is not finite or outside +-{:e} mm", a[0], a[1], a[2], tol::MAX_COORDINATE),
        "give finite coordinates in mm (machine frame at q = 0)",
    ))
}

/// Every `[dynamics]` and `[rapid]` entry names a declared axis.
pub(crate) fn check_dynamics_keys(raw: &RawMachine) -> Result<(), MachineError> {
    for key in raw.dynamics.keys().chain(raw.rapid.keys()) {
        if !raw.axes.contains_key(key) {
            return Err(MachineError::invalid(
                format!("dynamics.{key}"),
                format!("no axis named {key}"),
                "remove the entry or declare the axis under [axes]",
            ));
        }
    }
    Ok(())
}

/// The first three axes (the linear ones) span space.
pub(crate) fn check_linear_independence(axes: &[Axis]) -> Result<(), MachineError> {
    let lin = Matrix3::from_columns(&[axes[0].direction, axes[1].direction, axes[2].direction]);
    if lin.determinant().abs() < tol::LINEAR_INDEPENDENCE {
        return Err(MachineError::invalid(
            "axes",
            "the three linear axis directions are not independent",
            "give linear directions that span space (normally e_x, e_y, e_z)",
        ));
    }
    Ok(())
}

/// The description as written (TOML errors with their line and column).
pub(crate) fn parse_raw(text: &str) -> Result<RawMachine, MachineError> {
    toml::from_str(text).map_err(|e| {
        let (line, column) = e.span().map_or((1, 1), |s| line_column(text, s.start));
        MachineError::Parse { line, column, message: e.message().trim().to_string() }
    })
}

/// The schema id and the largest spindle speed of a description, checked.
pub(crate) fn check_schema_and_spindle(raw: &RawMachine) -> Result<Option<f64>, MachineError> {
    if raw.schema != SCHEMA {
        return Err(MachineError::invalid(
            "schema",
            format!("unknown schema `{}`", raw.schema),
            format!("write schema = \"{SCHEMA}\""),
        ));
    }
    match raw.spindle.max_speed {
        Some(n) if !(n.is_finite() && n > 0.0) => Err(MachineError::invalid(
            "spindle.max_speed",
            format!("{n} is not a positive speed"),
            "give the largest spindle speed in 1/min (> 0), or remove it (no limit)",
        )),
        n => Ok(n),
    }
}

fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rfind('\n').map_or(before.chars().count(), |i| before[i + 1..].chars().count()) + 1;
    (line, column)
}

impl Machine {
    /// Parses and validates a `scallop.machine/1` description.
    ///
    /// ```
    /// let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../machines/matsuura-mx330.toml")).unwrap();
    /// let m = scallop_machine::Machine::from_toml_str(&text).unwrap();
    /// assert_eq!(m.axis_names(), ["X", "Y", "Z", "A", "C"]);
    /// ```
    ///
    /// # Errors
    /// [`MachineError::Parse`] with line and column for malformed TOML or unknown
    /// fields; [`MachineError::Invalid`] naming the field for a bad value;
    /// [`MachineError::Unsupported`] for machines other than 3 linear + 2 rotary.
    pub fn from_toml_str(text: &str) -> Result<Machine, MachineError> {
        Self::validate(parse_raw(text)?)
    }

    /// One of the shipped descriptions of `machines/` by short name: `mx330`, `ucp710`,
    /// `generic-tt-bc`, `generic-hh-ca`, `generic-ht-bc`, `linuxcnc-xyzac-trt`,
    /// `linuxcnc-xyzbc-trt`.
    ///
    /// ```
    /// assert!(scallop_machine::Machine::builtin("ucp710").is_ok());
    /// assert!(scallop_machine::Machine::builtin("nope").is_err());
    /// ```
    ///
    /// # Errors
    /// [`MachineError::BadInput`] for an unknown name.
    pub fn builtin(short_name: &str) -> Result<Machine, MachineError> {
        let text =
            BUILTIN.iter().find(|(n, _)| *n == short_name).map(|(_, t)| *t).ok_or_else(|| MachineError::BadInput {
                place: "Machine::builtin".into(),
                problem: format!("no shipped machine named `{short_name}`"),
                fix: format!("use one of {:?}", Self::builtin_names()),
            })?;
        Self::from_toml_str(text)
    }

    /// Short names accepted by [`Machine::builtin`].
    ///
    /// ```
    /// assert_eq!(scallop_machine::Machine::builtin_names().len(), 7);
    /// ```
    #[must_use]
    pub fn builtin_names() -> Vec<&'static str> {
        BUILTIN.iter().map(|(n, _)| *n).collect()
    }

    #[allow(clippy::too_many_lines, reason = "one linear validation pass, field by field")]
    fn validate(raw: RawMachine) -> Result<Machine, MachineError> {
        let max_spindle_speed = check_schema_and_spindle(&raw)?;
        // Axis order: linear first, then rotary, each sorted by name (BTreeMap order).
        let mut names: Vec<&String> =
            raw.axes.iter().filter(|(_, a)| a.kind == AxisKind::Linear).map(|(n, _)| n).collect();
        let n_linear = names.len();
        names.extend(raw.axes.iter().filter(|(_, a)| a.kind == AxisKind::Rotary).map(|(n, _)| n));
        if n_linear == 3 && names.len() == 3 {
            return Err(MachineError::Unsupported {
                place: "axes".into(),
                what: format!("the 3-axis machine `{}` in 5-axis or 3+2 output", raw.name),
                fix: "name a 5-axis machine here; a 3-axis machine is named by a job's `machine` key (docs/job.md)"
                    .into(),
            });
        }
        if n_linear != 3 || names.len() != 5 {
            return Err(MachineError::Unsupported {
                place: "axes".into(),
                what: format!("a machine with {n_linear} linear and {} rotary axes", names.len() - n_linear),
                fix: "describe 3 linear and 2 rotary axes (3- and 4-axis machines come later)".into(),
            });
        }
        let Some(chains) = raw.chains.as_ref() else {
            return Err(MachineError::invalid(
                "chains",
                "missing",
                "add [chains] with part = [...] and tool = [...] (the axes that carry the part and the tool)",
            ));
        };
        let mut axes = Vec::with_capacity(5);
        for name in &names {
            axes.push(axis_of(&raw, name)?);
        }
        check_dynamics_keys(&raw)?;
        let index_of = |n: &String| names.iter().position(|m| *m == n);
        let chain = |list: &[String], which: &str| -> Result<Vec<usize>, MachineError> {
            let mut out = Vec::new();
            for n in list {
                let i = index_of(n).ok_or_else(|| {
                    MachineError::invalid(
                        format!("chains.{which}"),
                        format!("unknown axis {n}"),
                        "declare it under [axes] or remove it from the chain",
                    )
                })?;
                if out.contains(&i) {
                    return Err(MachineError::invalid(
                        format!("chains.{which}"),
                        format!("axis {n} listed twice"),
                        "list every axis once",
                    ));
                }
                out.push(i);
            }
            Ok(out)
        };
        let part_chain = chain(&chains.part, "part")?;
        let tool_chain = chain(&chains.tool, "tool")?;
        check_linear_independence(&axes)?;
        if axes[3].direction.cross(&axes[4].direction).norm() < tol::PARALLEL {
            return Err(MachineError::invalid(
                format!("axes.{}.direction", axes[4].name),
                format!("rotary axes {} and {} are parallel", axes[3].name, axes[4].name),
                "a 5-axis machine needs two non-parallel rotary axes",
            ));
        }
        let (Some(tool_axis), Some(gauge_point)) = (raw.spindle.tool_axis, raw.spindle.gauge_point) else {
            return Err(MachineError::invalid(
                "spindle",
                "missing gauge_point or tool_axis",
                "add spindle = { gauge_point = [x, y, z], tool_axis = [0, 0, 1] } (mm, machine frame at q = 0)",
            ));
        };
        let tool_axis = unit_direction(tool_axis, "spindle.tool_axis")?;
        let gauge_point = point_in_range(gauge_point, "spindle.gauge_point")?;
        let part_frame = part_frame_of(raw.part_frame.as_ref())?;
        let preferred_branch = match raw.kinematics.preferred_branch {
            None => None,
            Some(p) => {
                let axis = index_of(&p.axis).filter(|i| *i >= 3).ok_or_else(|| {
                    MachineError::invalid(
                        "kinematics.preferred_branch.axis",
                        format!("`{}` is not a rotary axis", p.axis),
                        "name one of the rotary axes",
                    )
                })?;
                let sign = match p.sign {
                    1 => 1.0,
                    -1 => -1.0,
                    s => {
                        return Err(MachineError::invalid(
                            "kinematics.preferred_branch.sign",
                            format!("{s} is not +1 or -1"),
                            "write sign = 1 or sign = -1",
                        ));
                    }
                };
                Some(PreferredBranch { axis, sign })
            }
        };
        let pole_eps = raw.kinematics.pole_eps.unwrap_or(tol::POLE_EPS_DEFAULT);
        if !(pole_eps.is_finite() && pole_eps > 0.0 && pole_eps < 1.0) {
            return Err(MachineError::invalid(
                "kinematics.pole_eps",
                format!("{pole_eps} is not in (0, 1)"),
                format!("give a small positive value, default {}", tol::POLE_EPS_DEFAULT),
            ));
        }
        check_controller(&raw.nc, &raw.tcp)?;
        let nc = raw.nc;
        Ok(Machine {
            name: raw.name,
            source: raw.source,
            controlled_point: raw.controlled_point,
            tool_length_mode: raw.tool_length_mode,
            part_frame,
            gauge_point,
            tool_axis,
            axes,
            part_chain,
            tool_chain,
            family: raw.kinematics.family,
            preferred_branch,
            pole_eps,
            tcp: raw.tcp,
            nc,
            max_spindle_speed,
        })
    }

    /// The machine's name.
    ///
    /// ```
    /// assert_eq!(scallop_machine::Machine::builtin("mx330").unwrap().name(), "matsuura-mx330-bettine2019");
    /// ```
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The source of the values.
    ///
    /// ```
    /// assert!(scallop_machine::Machine::builtin("mx330").unwrap().source().contains("Bettine"));
    /// ```
    #[must_use]
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The axes in joint order (linear first, then rotary, each sorted by name).
    ///
    /// ```
    /// assert_eq!(scallop_machine::Machine::builtin("ucp710").unwrap().axes().len(), 5);
    /// ```
    #[must_use]
    pub fn axes(&self) -> &[Axis] {
        &self.axes
    }

    /// Axis names in joint order.
    ///
    /// ```
    /// assert_eq!(scallop_machine::Machine::builtin("linuxcnc-xyzbc-trt").unwrap().axis_names(), ["X", "Y", "Z", "B", "C"]);
    /// ```
    #[must_use]
    pub fn axis_names(&self) -> Vec<&str> {
        self.axes.iter().map(|a| a.name.as_str()).collect()
    }

    /// Index of the axis named `name` in joint order.
    ///
    /// ```
    /// assert_eq!(scallop_machine::Machine::builtin("mx330").unwrap().axis_by_name("C"), Some(4));
    /// ```
    #[must_use]
    pub fn axis_by_name(&self, name: &str) -> Option<usize> {
        self.axes.iter().position(|a| a.name == name)
    }

    /// The chain from the bed to the part (axis indices, carrying order).
    ///
    /// ```
    /// assert_eq!(scallop_machine::Machine::builtin("mx330").unwrap().part_chain(), [0, 1, 3, 4]);
    /// ```
    #[must_use]
    pub fn part_chain(&self) -> &[usize] {
        &self.part_chain
    }

    /// The chain from the bed to the spindle.
    ///
    /// ```
    /// assert_eq!(scallop_machine::Machine::builtin("mx330").unwrap().tool_chain(), [2]);
    /// ```
    #[must_use]
    pub fn tool_chain(&self) -> &[usize] {
        &self.tool_chain
    }

    /// The default part frame W0 (x_M = W0 * x_W).
    ///
    /// ```
    /// let m = scallop_machine::Machine::builtin("mx330").unwrap();
    /// assert_eq!(m.part_frame(), &scallop_geom::nalgebra::Isometry3::identity());
    /// ```
    #[must_use]
    pub fn part_frame(&self) -> &Isometry3<f64> {
        &self.part_frame
    }

    /// Gauge point g0 of the spindle at q = 0 (machine frame).
    ///
    /// ```
    /// assert_eq!(scallop_machine::Machine::builtin("mx330").unwrap().gauge_point(), scallop_geom::Point3::origin());
    /// ```
    #[must_use]
    pub fn gauge_point(&self) -> Point3 {
        self.gauge_point
    }

    /// Tool axis a0 at q = 0 (unit, tip towards spindle).
    ///
    /// ```
    /// assert_eq!(scallop_machine::Machine::builtin("mx330").unwrap().tool_axis(), scallop_geom::Vec3::z());
    /// ```
    #[must_use]
    pub fn tool_axis(&self) -> Vec3 {
        self.tool_axis
    }

    /// The point the CL data controls.
    ///
    /// ```
    /// use scallop_machine::ControlledPoint;
    /// assert_eq!(scallop_machine::Machine::builtin("mx330").unwrap().controlled_point(), ControlledPoint::BallCentre);
    /// ```
    #[must_use]
    pub fn controlled_point(&self) -> ControlledPoint {
        self.controlled_point
    }

    /// Who applies the tool length.
    ///
    /// ```
    /// use scallop_machine::ToolLengthMode;
    /// assert_eq!(scallop_machine::Machine::builtin("ucp710").unwrap().tool_length_mode(), ToolLengthMode::Controller);
    /// ```
    #[must_use]
    pub fn tool_length_mode(&self) -> ToolLengthMode {
        self.tool_length_mode
    }

    /// The declared family choice (`kinematics.family`).
    ///
    /// ```
    /// use scallop_machine::FamilyChoice;
    /// assert_eq!(scallop_machine::Machine::builtin("mx330").unwrap().family(), FamilyChoice::TtAc);
    /// ```
    #[must_use]
    pub fn family(&self) -> FamilyChoice {
        self.family
    }

    /// The branch preference used when continuity does not decide.
    ///
    /// ```
    /// let m = scallop_machine::Machine::builtin("mx330").unwrap();
    /// assert_eq!(m.preferred_branch().unwrap().sign, -1.0);
    /// ```
    #[must_use]
    pub fn preferred_branch(&self) -> Option<&PreferredBranch> {
        self.preferred_branch.as_ref()
    }

    /// Pole threshold on `rho = |sin(tilt)|`.
    ///
    /// ```
    /// assert!(scallop_machine::Machine::builtin("mx330").unwrap().pole_eps() > 0.0);
    /// ```
    #[must_use]
    pub fn pole_eps(&self) -> f64 {
        self.pole_eps
    }

    /// TCP capability.
    ///
    /// ```
    /// assert!(scallop_machine::Machine::builtin("ucp710").unwrap().tcp().supported);
    /// ```
    #[must_use]
    pub fn tcp(&self) -> &Tcp {
        &self.tcp
    }

    /// The largest spindle speed (1/min), when the description gives it
    /// (`spindle.max_speed`).
    ///
    /// ```
    /// assert_eq!(scallop_machine::Machine::builtin("ucp710").unwrap().max_spindle_speed(), None);
    /// ```
    #[must_use]
    pub fn max_spindle_speed(&self) -> Option<f64> {
        self.max_spindle_speed
    }

    /// Controller conventions.
    ///
    /// ```
    /// use scallop_machine::Dialect;
    /// assert_eq!(scallop_machine::Machine::builtin("ucp710").unwrap().nc().dialect, Dialect::Siemens840d);
    /// ```
    #[must_use]
    pub fn nc(&self) -> &Nc {
        &self.nc
    }

    /// ISO 841 report (spec 2.2, test K7): for each axis in joint order, whether a
    /// positive NC word moves the tool relative to the part along +e of its letter.
    ///
    /// ```
    /// use scallop_machine::Iso841;
    /// let r = scallop_machine::Machine::builtin("ucp710").unwrap().iso841_report();
    /// assert!(r.iter().all(|(_, s)| *s == Iso841::Iso));
    /// ```
    #[must_use]
    pub fn iso841_report(&self) -> Vec<(String, Iso841)> {
        self.axes
            .iter()
            .map(|a| {
                let expected = match a.name.as_str() {
                    "X" | "A" => Some(Vec3::x()),
                    "Y" | "B" => Some(Vec3::y()),
                    "Z" | "C" => Some(Vec3::z()),
                    _ => None,
                };
                let sigma = if a.side == ChainSide::Tool { 1.0 } else { -1.0 };
                let motion = a.direction * (sigma * a.nc_sign);
                let sense = match expected {
                    Some(e) if (motion - e).norm() < tol::PARALLEL => Iso841::Iso,
                    Some(e) if (motion + e).norm() < tol::PARALLEL => Iso841::TableMotionSense,
                    _ => Iso841::NotAxisAligned,
                };
                (a.name.clone(), sense)
            })
            .collect()
    }
}
