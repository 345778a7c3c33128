//! From part-frame cutter locations to a joint-space machine program (spec 1.2 stages
//! 2-6): branch and winding selection ([`crate::plan::plan_path`]), subdivision until
//! joint-linear motion keeps the tip within `tol_pos` ([`crate::feed::subdivide`]),
//! inverse-time feeds bounded by the axis velocities ([`crate::feed::inverse_time_feed`])
//! and a verification by forward-kinematics replay. The text is written by
//! `scallop-post`; this crate never formats G-code.

use crate::chain::{Joints, Kinematics, Pose};
use crate::error::MachineError;
use crate::feed::{BlockEnd, deviation, inverse_time_feed, subdivide_into};
use crate::plan::{Event, PlanOptions, check_limits, move_time};
use crate::tol;

/// What a CL move is (spec 1.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motion {
    /// Positioning at rapid rate, out of the material.
    Rapid,
    /// Cutting move.
    Feed,
    /// Descent into the material.
    Plunge,
    /// Connection between passes out of the material at feed rate (jumps allowed).
    Link,
}

impl Motion {
    /// The move is in the material (branch flips forbidden, spec 3.5).
    ///
    /// ```
    /// assert!(scallop_machine::program::Motion::Plunge.is_cutting());
    /// ```
    #[must_use]
    pub fn is_cutting(self) -> bool {
        matches!(self, Motion::Feed | Motion::Plunge)
    }
}

/// One cutter-location record: the move into `pose`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClRecord {
    /// Tip and tool axis in the part frame.
    pub pose: Pose,
    /// Kind of move.
    pub motion: Motion,
    /// Programmed tip feed (mm/min); ignored for rapids.
    pub feed: f64,
}

/// CL records of a 3-axis (or 3+2) toolpath with the constant tool axis `axis` (part
/// frame): rapids and retracts become [`Motion::Rapid`], plunges [`Motion::Plunge`] at the
/// plunge feed, feeds and links keep their kind at the cutting feed.
///
/// ```
/// use scallop_geom::{Point3, Vec3};
/// use scallop_toolpath::{Move, MoveKind, Toolpath};
/// let mut tp = Toolpath::new(1200.0);
/// tp.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 10.0)));
/// tp.push(Move::new(MoveKind::Plunge, Point3::new(0.0, 0.0, 0.0)));
/// let cl = scallop_machine::program::records_from_toolpath(&tp, &Vec3::z());
/// assert_eq!(cl[1].feed, 600.0);
/// ```
#[must_use]
pub fn records_from_toolpath(path: &scallop_toolpath::Toolpath, axis: &scallop_geom::Vec3) -> Vec<ClRecord> {
    use scallop_toolpath::MoveKind;
    path.moves()
        .iter()
        .map(|m| {
            let (motion, feed) = match m.kind {
                MoveKind::Rapid | MoveKind::Retract => (Motion::Rapid, path.feed),
                MoveKind::Plunge => (Motion::Plunge, path.plunge_feed),
                MoveKind::Feed => (Motion::Feed, path.feed),
                MoveKind::Link => (Motion::Link, path.feed),
            };
            ClRecord { pose: Pose::new(m.to, *axis), motion, feed }
        })
        .collect()
}

/// CL records of a toolpath with its own tool axes ([`Toolpath::axis`]) and feeds
/// ([`Toolpath::feed_of`]): rapids and retracts become [`Motion::Rapid`], plunges
/// [`Motion::Plunge`], feeds and links keep their kind.
///
/// [`Toolpath::axis`]: scallop_toolpath::Toolpath::axis
/// [`Toolpath::feed_of`]: scallop_toolpath::Toolpath::feed_of
///
/// ```
/// use scallop_geom::{Point3, Vec3};
/// use scallop_toolpath::{Move, MoveKind, Toolpath};
/// let mut tp = Toolpath::new(1200.0);
/// tp.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 10.0)));
/// tp.push_with_axis(Move::new(MoveKind::Plunge, Point3::new(0.0, 0.0, 0.0)), Vec3::x());
/// let cl = scallop_machine::program::records_of(&tp);
/// assert_eq!((cl[1].feed, cl[1].pose.axis), (600.0, Vec3::x()));
/// ```
#[must_use]
pub fn records_of(path: &scallop_toolpath::Toolpath) -> Vec<ClRecord> {
    use scallop_toolpath::MoveKind;
    path.moves()
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let motion = match m.kind {
                MoveKind::Rapid | MoveKind::Retract => Motion::Rapid,
                MoveKind::Plunge => Motion::Plunge,
                MoveKind::Feed => Motion::Feed,
                MoveKind::Link => Motion::Link,
            };
            ClRecord { pose: Pose::new(m.to, path.axis(i)), motion, feed: path.feed_of(i) }
        })
        .collect()
}

/// Options of [`to_program`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProgramOptions {
    /// Tip tolerance of joint-space interpolation (mm).
    pub tol_pos: f64,
    /// Tool-axis tolerance of joint-space interpolation (rad).
    pub tol_ang: f64,
    /// Branch-selection options.
    pub plan: PlanOptions,
    /// Retract distance (mm) along the tool axis of a link that changes branch or unwinds:
    /// the tool backs off this far from the last cutting pose, the rotaries turn (a rapid),
    /// and it comes back along the new tool axis to the link's end.
    pub retract: f64,
}

impl Default for ProgramOptions {
    fn default() -> Self {
        ProgramOptions {
            tol_pos: tol::JOINT_INTERPOLATION_DEFAULT,
            tol_ang: tol::JOINT_ANGLE_DEFAULT,
            plan: PlanOptions::default(),
            retract: tol::LINK_RETRACT_DEFAULT,
        }
    }
}

/// One joint-space block of a program.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProgramBlock {
    /// Kind of move.
    pub motion: Motion,
    /// Joint values at the block end (mm, rad).
    pub joints: Joints,
    /// NC words at the block end (mm, deg), joint order.
    pub words: [f64; 5],
    /// The part-frame pose at the block end (on the CL segment).
    pub pose: Pose,
    /// Programmed tip feed (mm/min).
    pub feed: f64,
    /// G93 word (1/min) when the controller has inverse time; `None` for rapids.
    pub inverse_time: Option<f64>,
    /// Index of the CL record this block belongs to.
    pub cl_index: usize,
}

/// A joint-space program for one machine, tool length and setup.
#[derive(Clone, Debug, PartialEq)]
pub struct MachineProgram {
    /// Axis names in joint (and word) order.
    pub axis_names: Vec<String>,
    /// Blocks in order; the first is the move to the first CL pose.
    pub blocks: Vec<ProgramBlock>,
    /// Planner events (flips, unwinds, pole holds) by CL index.
    pub events: Vec<Event>,
}

/// Builds the joint-space program of `records` (spec 1.2 stages 2-6). `start` is the
/// machine state before the first record.
///
/// ```
/// use scallop_geom::{Point3, Vec3};
/// use scallop_machine::{Kinematics, Machine, Pose};
/// use scallop_machine::program::{to_program, ClRecord, Motion, ProgramOptions};
/// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
/// let rec = |x: f64, m| ClRecord { pose: Pose::new(Point3::new(x, 0.0, 50.0), Vec3::new(0.0, 0.3, 1.0)), motion: m, feed: 1000.0 };
/// let prog = to_program(&k, &[rec(0.0, Motion::Rapid), rec(10.0, Motion::Feed)], None, &ProgramOptions::default()).unwrap();
/// assert_eq!(prog.blocks.len(), 2);
/// assert_eq!(prog.blocks[1].inverse_time, Some(100.0));
/// ```
///
/// # Errors
/// As [`plan_path`](crate::plan::plan_path) (limit violations name the block and the axis), and
/// [`MachineError::SubdivisionFailed`].
pub fn to_program(
    kin: &Kinematics,
    records: &[ClRecord],
    start: Option<Joints>,
    options: &ProgramOptions,
) -> Result<MachineProgram, MachineError> {
    let machine = kin.machine();
    let path = crate::plan::plan_input(kin, &Records(records), start, &options.plan)?;
    let words = |q: &Joints| {
        let mut w = [0.0; 5];
        for (i, a) in machine.axes().iter().enumerate() {
            w[i] = a.to_nc_word(q[i]);
        }
        w
    };
    let mut blocks: Vec<ProgramBlock> = Vec::with_capacity(path.joints.len());
    // The machine state before the first block; afterwards the previous block's end is
    // read in place (no copies of poses and joints per block).
    let before: Option<(Pose, Joints)> = start.map(|q| (kin.fk(&q), q));
    let strokes = crate::plan::Strokes::new(machine);
    // Block ends of one CL move, reused move after move.
    let mut ends: Vec<BlockEnd> = Vec::new();
    for (q, &i) in path.joints.iter().zip(&path.pose_index) {
        let rec = &records[i];
        ends.clear();
        let previous = blocks.last().map(|b| (&b.pose, &b.joints)).or(before.as_ref().map(|(p, q)| (p, q)));
        // A link that is not the continuous motion along its move (a branch change or an
        // unwinding): retract along the old tool axis, turn the rotaries at the retract
        // distance (a rapid), come back along the new tool axis.
        let detour = match (rec.motion, previous) {
            (Motion::Link, Some((pa, qa))) if is_jump(kin, pa, &rec.pose, qa, q, &options.plan) => {
                let mut back = *qa;
                let tip_a = pa.tip + pa.axis * options.retract;
                kin.solve_linear(&tip_a, &mut back);
                let mut over = *q;
                let tip_b = rec.pose.tip + rec.pose.axis * options.retract;
                kin.solve_linear(&tip_b, &mut over);
                ends.push(BlockEnd { pose: Pose::new(tip_a, pa.axis), joints: back });
                ends.push(BlockEnd { pose: Pose::new(tip_b, rec.pose.axis), joints: over });
                ends.push(BlockEnd { pose: rec.pose, joints: *q });
                true
            }
            _ => false,
        };
        match (rec.motion, previous) {
            _ if detour => {}
            (Motion::Rapid, _) | (_, None) => ends.push(BlockEnd { pose: rec.pose, joints: *q }),
            // In-place rotations (pole flips) are subdivided too: joint-linear X/Y/C
            // motion does not keep the tip still.
            (_, Some((pa, qa))) => {
                subdivide_into(kin, (pa, qa), (&rec.pose, q), (options.tol_pos, options.tol_ang), i, &mut ends)?;
            }
        }
        for (k, end) in ends.iter().enumerate() {
            strokes.check(machine, &end.joints, Some(i))?;
            let previous = blocks.last().map(|b| (&b.pose, &b.joints)).or(before.as_ref().map(|(p, q)| (p, q)));
            // The detour's middle block (the reorientation) is a rapid.
            let motion = if detour && k == 1 { Motion::Rapid } else { rec.motion };
            let inverse_time = match (motion, previous) {
                (Motion::Rapid, _) | (_, None) => None,
                _ if !machine.nc().inverse_time => None,
                (_, Some((pa, qa))) => Some(inverse_time_feed(kin, pa, &end.pose, qa, &end.joints, rec.feed)),
            };
            blocks.push(ProgramBlock {
                motion,
                joints: end.joints,
                words: words(&end.joints),
                pose: end.pose,
                feed: rec.feed,
                inverse_time,
                cl_index: i,
            });
        }
    }
    Ok(MachineProgram {
        axis_names: machine.axis_names().iter().map(|s| (*s).to_string()).collect(),
        blocks,
        events: path.events,
    })
}

/// Whether the joint move `qa -> qb` of the CL move `pa -> pb` is a jump: some rotary
/// turns more than the flip threshold and the move is not the continuous motion along
/// the CL move ([`crate::plan::track`] reaches other joints or other windings).
fn is_jump(kin: &Kinematics, pa: &Pose, pb: &Pose, qa: &Joints, qb: &Joints, plan: &PlanOptions) -> bool {
    let turn = (qb[3] - qa[3]).abs().max((qb[4] - qa[4]).abs());
    if turn <= plan.flip_threshold {
        return false;
    }
    crate::plan::track(kin, pa, pb, qa)
        .is_none_or(|t| (t[3] - qb[3]).abs() > tol::TRACK_MATCH || (t[4] - qb[4]).abs() > tol::TRACK_MATCH)
}

/// The CL records as the planner's input (no copies of the poses).
struct Records<'a>(&'a [ClRecord]);

impl crate::plan::PathInput for Records<'_> {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn pose(&self, i: usize) -> &Pose {
        &self.0[i].pose
    }
    fn cutting(&self, i: usize) -> bool {
        self.0[i].motion.is_cutting()
    }
    fn is_rapid(&self, i: usize) -> bool {
        self.0[i].motion == Motion::Rapid
    }
}

/// What [`verify`] measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Verification {
    /// Largest tip deviation of joint-linear motion from the CL segments (mm).
    pub max_tip_deviation: f64,
    /// Largest tool-axis deviation (rad).
    pub max_axis_deviation: f64,
    /// Largest `|dq_j| F_inv / 60 / vmax_j` over G93 blocks (<= 1 when no axis saturates).
    pub max_rate_ratio: f64,
}

/// Replays `program` through the forward kinematics (spec 3.12, K16 before formatting):
/// block ends must reproduce their poses, joint-linear motion must stay within
/// `tol_pos`/`tol_ang` of the CL segments, every word inside its stroke, and no G93
/// block may ask an axis for more than its velocity.
///
/// ```
/// use scallop_geom::{Point3, Vec3};
/// use scallop_machine::{Kinematics, Machine, Pose};
/// use scallop_machine::program::{to_program, verify, ClRecord, Motion, ProgramOptions};
/// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
/// let rec = |x: f64, m| ClRecord { pose: Pose::new(Point3::new(x, 0.0, 50.0), Vec3::new(x / 300.0, 0.3, 1.0)), motion: m, feed: 1000.0 };
/// let opts = ProgramOptions::default();
/// let prog = to_program(&k, &[rec(0.0, Motion::Rapid), rec(30.0, Motion::Feed)], None, &opts).unwrap();
/// let v = verify(&k, &prog, &opts).unwrap();
/// assert!(v.max_tip_deviation <= opts.tol_pos && v.max_rate_ratio <= 1.0);
/// ```
///
/// # Errors
/// [`MachineError::LimitViolation`] for a word outside its stroke;
/// [`MachineError::SubdivisionFailed`] for a block beyond the tolerances or not
/// reproducing its pose (the safety checks are errors, never warnings).
pub fn verify(
    kin: &Kinematics,
    program: &MachineProgram,
    options: &ProgramOptions,
) -> Result<Verification, MachineError> {
    let machine = kin.machine();
    let mut v = Verification { max_tip_deviation: 0.0, max_axis_deviation: 0.0, max_rate_ratio: 0.0 };
    let slack = 1.0 + tol::VERIFY_SLACK;
    for (k, b) in program.blocks.iter().enumerate() {
        check_limits(machine, &b.joints, Some(b.cl_index))?;
        let back = kin.fk(&b.joints);
        let end_error = (back.tip - b.pose.tip).norm();
        if end_error > options.tol_pos || (back.axis - b.pose.axis).norm() > options.tol_ang {
            return Err(MachineError::SubdivisionFailed { block: b.cl_index, deviation: end_error, depth: 0 });
        }
        let Some(prev) = k.checked_sub(1).map(|p| &program.blocks[p]) else { continue };
        if b.motion == Motion::Rapid {
            continue;
        }
        let (pos, ang) = deviation(kin, &prev.pose, &b.pose, &prev.joints, &b.joints);
        if pos > options.tol_pos * slack || ang > options.tol_ang * slack {
            return Err(MachineError::SubdivisionFailed { block: b.cl_index, deviation: pos, depth: 0 });
        }
        v.max_tip_deviation = v.max_tip_deviation.max(pos);
        v.max_axis_deviation = v.max_axis_deviation.max(ang);
        if let Some(f_inv) = b.inverse_time {
            let t = move_time(machine, &prev.joints, &b.joints);
            v.max_rate_ratio = v.max_rate_ratio.max(t * f_inv / 60.0);
        }
    }
    Ok(v)
}
