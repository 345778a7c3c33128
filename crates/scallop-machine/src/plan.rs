//! From inverse solutions to one joint vector per pose: rotary unwrapping to the shortest
//! path within the strokes (spec 3.7), axis-limit checks, and the branch selection
//! policy (spec 3.5, greedy streaming form): continuity with the previous joints first,
//! then the strokes, then the user preference.

use std::f64::consts::PI;

use crate::chain::{Joints, Kinematics, Pose};
use crate::desc::{AxisKind, Machine};
use crate::error::MachineError;
use crate::ik::{Branch, IkSolution};
use crate::tol;

/// The winding `raw + 2 pi n` of a rotary value for the move from `previous`: the one
/// nearest `previous` (shortest path) if it is inside `limits` (joint units, rad), else
/// the admissible winding nearest to it. Returns the value and whether it is an unwind
/// (not the shortest path), or `None` when no winding fits the stroke.
///
/// ```
/// use scallop_machine::plan::unwrap_angle;
/// let d = std::f64::consts::PI / 180.0;
/// let (c, unwound) = unwrap_angle(-170.0 * d, 170.0 * d, None).unwrap();
/// assert!((c - 190.0 * d).abs() < 1e-12 && !unwound);
/// let (c, unwound) = unwrap_angle(-170.0 * d, 170.0 * d, Some((-PI, PI))).unwrap();
/// # use std::f64::consts::PI;
/// assert!((c + 170.0 * d).abs() < 1e-12 && unwound);
/// ```
#[must_use]
pub fn unwrap_angle(raw: f64, previous: f64, limits: Option<(f64, f64)>) -> Option<(f64, bool)> {
    let turn = 2.0 * PI;
    let nearest = (previous - raw) / turn;
    let n_near = crate::feed::round_fast(nearest);
    let value = raw + n_near * turn;
    let Some((lo, hi)) = limits else {
        return Some((value, false));
    };
    let (lo, hi) = (lo - tol::LIMIT_SLACK, hi + tol::LIMIT_SLACK);
    if value >= lo && value <= hi {
        return Some((value, false));
    }
    let n_min = ((lo - raw) / turn).ceil();
    let n_max = ((hi - raw) / turn).floor();
    if n_min > n_max {
        return None;
    }
    // The admissible winding nearest to `previous`.
    let n = nearest.clamp(n_min, n_max).round().clamp(n_min, n_max);
    Some((raw + n * turn, true))
}

/// Checks every axis of `q` against its stroke; the error names the block, the axis
/// and the NC word.
///
/// ```
/// use scallop_machine::{Machine, Joints, plan::check_limits};
/// let m = Machine::builtin("mx330").unwrap();
/// assert!(check_limits(&m, &Joints::new(0.0, 0.0, 100.0, -0.5, 9.0), Some(3)).is_ok());
/// let err = check_limits(&m, &Joints::new(0.0, 0.0, 100.0, 0.5, 0.0), Some(3)).unwrap_err();
/// assert!(err.to_string().contains("block 3: axis A"));
/// ```
///
/// # Errors
/// [`MachineError::LimitViolation`] for the first axis (joint order) outside its stroke.
pub fn check_limits(machine: &Machine, q: &Joints, block: Option<usize>) -> Result<(), MachineError> {
    for (i, axis) in machine.axes().iter().enumerate() {
        if let Some((lo, hi)) = axis.joint_limits()
            && (q[i] < lo - tol::LIMIT_SLACK || q[i] > hi + tol::LIMIT_SLACK)
        {
            let (min, max) = axis.limits.map_or((lo, hi), |l| l);
            let to_word = |v: f64| if axis.kind == AxisKind::Rotary { v.to_degrees() } else { v };
            return Err(MachineError::LimitViolation {
                block,
                axis: axis.name.clone(),
                value: axis.to_nc_word(q[i]),
                min: to_word(min),
                max: to_word(max),
                unit: axis.unit(),
            });
        }
    }
    Ok(())
}

/// Something the planner did that the post-processor or the user should know.
#[derive(Clone, Debug, PartialEq)]
pub enum Event {
    /// The branch changed at this block with a jump of the pole axis above 90 deg (a
    /// flip; a continuous pole crossing is not reported).
    BranchChange {
        /// Block index.
        block: usize,
        /// The new branch.
        to: Branch,
    },
    /// A rotary took a winding other than the shortest path because of its stroke
    /// (a long move: needs a retract if cutting).
    Unwind {
        /// Block index.
        block: usize,
        /// Axis name.
        axis: String,
        /// Rotation of this block (deg).
        delta_deg: f64,
    },
    /// The tool axis was on the pole: the pole axis was held at its previous value.
    PoleHold {
        /// Block index.
        block: usize,
    },
    /// The pole axis turns in place at the pole (tool axis and tip fixed) to continue on
    /// the other branch (spec 3.6 rule 3): allowed while cutting, leaves a dwell mark.
    PoleFlip {
        /// Block index (the move into this pose crosses or touches the pole).
        block: usize,
        /// The pole axis.
        axis: String,
        /// Its rotation (deg).
        delta_deg: f64,
        /// Time of the rotation at the axis's maximum velocity (s).
        seconds: f64,
    },
    /// A rotary jump above the flip threshold on a non-cutting move (retract, reorient,
    /// approach).
    Reorient {
        /// Block index.
        block: usize,
        /// The axis with the largest jump.
        axis: String,
        /// Its rotation (deg).
        delta_deg: f64,
    },
}

/// The chosen joints of one pose.
#[derive(Clone, Debug, PartialEq)]
pub struct Selected {
    /// Joint values with rotaries unwrapped.
    pub joints: Joints,
    /// The branch.
    pub branch: Branch,
    /// For each joint (joint order), whether it took an unwinding move (rotaries only).
    pub unwound: [bool; 5],
    /// The pose was on the pole.
    pub at_pole: bool,
}

/// The strokes of a machine per joint, read once: the joint limits ([`Axis::joint_limits`])
/// and the accepted range with [`tol::LIMIT_SLACK`] (infinite without limits).
///
/// [`Axis::joint_limits`]: crate::desc::Axis::joint_limits
pub(crate) struct Strokes {
    limits: [Option<(f64, f64)>; 5],
    accepted: [(f64, f64); 5],
}

impl Strokes {
    pub(crate) fn new(machine: &Machine) -> Strokes {
        let mut limits = [None; 5];
        let mut accepted = [(f64::NEG_INFINITY, f64::INFINITY); 5];
        for (i, axis) in machine.axes().iter().enumerate().take(5) {
            limits[i] = axis.joint_limits();
            if let Some((lo, hi)) = limits[i] {
                accepted[i] = (lo - tol::LIMIT_SLACK, hi + tol::LIMIT_SLACK);
            }
        }
        Strokes { limits, accepted }
    }

    /// [`check_limits`], the error built only on a violation.
    pub(crate) fn check(&self, machine: &Machine, q: &Joints, block: Option<usize>) -> Result<(), MachineError> {
        if self.inside(q) { Ok(()) } else { check_limits(machine, q, block) }
    }

    /// [`check_limits`] without the error: whether every joint is within its stroke.
    fn inside(&self, q: &Joints) -> bool {
        // Written as `!(outside)` so that a NaN passes, as in `check_limits`.
        (0..5).all(|i| !(q[i] < self.accepted[i].0 || q[i] > self.accepted[i].1))
    }
}

/// Unwraps `sol` against `previous` (rotaries) and checks all strokes.
fn admissible(
    machine: &Machine,
    strokes: &Strokes,
    sol: &IkSolution,
    previous: Option<&Joints>,
) -> Result<Selected, MachineError> {
    admissible_with(machine, strokes, sol, unwrap_rotaries(strokes, &sol.joints, previous))
}

/// The rotaries (joints 3 and 4) of `raw` unwrapped against `previous` within their
/// strokes, and whether each took an unwinding move; with no admissible winding, the
/// shortest-path value (the stroke check then reports it).
fn unwrap_rotaries(strokes: &Strokes, raw: &Joints, previous: Option<&Joints>) -> ([f64; 2], [bool; 2]) {
    let (a, b) = (unwrap_one(strokes, raw, previous, 3), unwrap_one(strokes, raw, previous, 4));
    ([a.0, b.0], [a.1, b.1])
}

/// Joint `i` of [`unwrap_rotaries`].
fn unwrap_one(strokes: &Strokes, raw: &Joints, previous: Option<&Joints>, i: usize) -> (f64, bool) {
    let prev = previous.map_or(0.0, |p| p[i]);
    match unwrap_angle(raw[i], prev, strokes.limits[i]) {
        Some((v, u)) => (v, u && previous.is_some()),
        // No winding fits: report the shortest-path value.
        None => (unwrap_angle(raw[i], prev, None).map_or(raw[i], |(v, _)| v), false),
    }
}

/// [`admissible`] with the rotaries already unwrapped ([`unwrap_rotaries`]).
fn admissible_with(
    machine: &Machine,
    strokes: &Strokes,
    sol: &IkSolution,
    (values, unwound): ([f64; 2], [bool; 2]),
) -> Result<Selected, MachineError> {
    let mut q = sol.joints;
    q[3] = values[0];
    q[4] = values[1];
    if !strokes.inside(&q) {
        check_limits(machine, &q, None)?;
    }
    Ok(Selected {
        joints: q,
        branch: sol.branch,
        unwound: [false, false, false, unwound[0], unwound[1]],
        at_pole: sol.at_pole,
    })
}

/// Whether the candidate `sol` from the state `p` is dropped as a jump while cutting
/// (spec 3.6 rule 3): its rotaries unwrapped as [`admissible`] does, a jump above
/// `flip_threshold` that is not a pole flip (`crosses`: the tool axis crosses the pole in
/// the block). Such a candidate is dropped whether or not its strokes hold. Also returns
/// the unwrapped rotaries ([`unwrap_rotaries`]) of a kept candidate. `pole` is joint 3 or
/// 4 (the rotaries), the tilt axis the other one.
fn jumps_on_rotaries(
    strokes: &Strokes,
    sol: &IkSolution,
    p: &State,
    flip_threshold: f64,
    pole: usize,
    crosses: impl Fn() -> bool,
) -> (bool, ([f64; 2], [bool; 2])) {
    // A jump of the tilt axis (not the pole axis) drops the candidate whatever the pole
    // axis does: decided on one unwrapping.
    let tilt = 7 - pole;
    let t = unwrap_one(strokes, &sol.joints, Some(&p.q), tilt);
    if (t.0 - p.q[tilt]).abs() > flip_threshold {
        return (true, ([0.0; 2], [false; 2]));
    }
    let c = unwrap_one(strokes, &sol.joints, Some(&p.q), pole);
    let (a, b) = if tilt == 3 { (t, c) } else { (c, t) };
    let unwrapped = ([a.0, b.0], [a.1, b.1]);
    let dq = [unwrapped.0[0] - p.q[3], unwrapped.0[1] - p.q[4]];
    let jump = dq.map(|d| d.abs() > flip_threshold);
    if jump == [false, false] {
        return (false, unwrapped);
    }
    let only_pole = (0..2).all(|r| jump[r] == (r + 3 == pole));
    (!(only_pole && (p.at_pole || sol.at_pole || crosses())), unwrapped)
}

/// The joints reached by following the CL move `a -> b` continuously from `qa`: the tool
/// axis is swept along the great circle (`slerp`, the tip along the chord) in steps small
/// enough that every rotary turns at most [`tol::TRACK_STEP`] per step, each step taking
/// the inverse solution nearest the previous one. The rotaries keep their windings (a
/// continuous turn of more than 180 deg is not reduced), so the result is the one joint
/// vector that a continuous motion of the machine along this move reaches: a large
/// rotary change near the pole or of a genuine reorientation, not a branch flip (the
/// other inverse solution) nor an unwinding. `None` when a step has no inverse or the
/// steps do not resolve the motion (an exact singularity inside the move).
///
/// ```
/// use scallop_geom::{Point3, Vec3};
/// use scallop_machine::{Kinematics, Machine, Pose, plan::{select, track}};
/// let k = Kinematics::new(&Machine::builtin("linuxcnc-xyzac-trt").unwrap(), 0.0);
/// // Near the pole: the axis turns 7 deg, C about 40 deg.
/// let a = Pose::new(Point3::new(0.0, 0.0, 0.0), Vec3::new(0.036833608501, -0.078989928337, 0.996194698092));
/// let b = Pose::new(Point3::new(0.5, 0.0, 0.0), Vec3::new(-0.044943455528, -0.167731259497, 0.984807753012));
/// let qa = select(&k, k.ik(&a, &scallop_machine::Joints::zeros()).unwrap().as_slice(), None, None).unwrap().joints;
/// let qb = track(&k, &a, &b, &qa).unwrap();
/// assert!((k.fk(&qb).axis - b.axis).norm() < 1e-9);
/// assert!((qb[4] - qa[4]).abs().to_degrees() > 30.0 && (qb[3] - qa[3]).abs().to_degrees() < 10.0);
/// ```
#[must_use]
pub fn track(kin: &Kinematics, a: &Pose, b: &Pose, qa: &Joints) -> Option<Joints> {
    let rotaries = [3, 4];
    let mut q = *qa;
    let mut s = 0.0f64;
    let mut step = tol::TRACK_FIRST_STEP;
    let mut evaluations = 0usize;
    while s < 1.0 {
        evaluations += 1;
        if evaluations > tol::TRACK_MAX_EVALUATIONS {
            return None;
        }
        let t = (s + step).min(1.0);
        let pose = crate::feed::interpolate(a, b, t);
        let sols = kin.ik(&pose, &q).ok()?;
        let mut best: Option<(f64, Joints)> = None;
        for sol in sols.as_slice() {
            let mut c = sol.joints;
            for &i in &rotaries {
                c[i] = unwrap_angle(c[i], q[i], None).map_or(c[i], |(v, _)| v);
            }
            let turn = rotaries.iter().map(|&i| (c[i] - q[i]).abs()).fold(0.0, f64::max);
            if best.as_ref().is_none_or(|(d, _)| turn < *d) {
                best = Some((turn, c));
            }
        }
        let (turn, c) = best?;
        if turn > tol::TRACK_STEP {
            if step <= tol::TRACK_MIN_STEP {
                return None; // a discontinuity: no continuous motion follows the move
            }
            step /= 2.0;
            continue;
        }
        q = c;
        s = t;
        step = (step * 2.0).min(tol::TRACK_FIRST_STEP);
    }
    Some(q)
}

/// The rotaries of `tracked` (unwound: `false`) when the rotaries of the inverse solution
/// `raw` equal them modulo a turn, i.e. when `raw` is the pose that the continuous motion
/// reaches; `None` for another branch.
fn continuation(raw: &Joints, tracked: &Joints) -> Option<([f64; 2], [bool; 2])> {
    let turn = 2.0 * PI;
    let same = |i: usize| {
        let d = (raw[i] - tracked[i]) / turn;
        ((d - d.round()) * turn).abs() <= tol::TRACK_MATCH
    };
    (same(3) && same(4)).then_some(([tracked[3], tracked[4]], [false, false]))
}

/// Velocity-limited time of the move `a -> b`: `max_j |dq_j| / vmax_j` (spec 3.5).
///
/// ```
/// use scallop_machine::{Machine, Joints, plan::move_time};
/// let m = Machine::builtin("mx330").unwrap();
/// let t = move_time(&m, &Joints::zeros(), &Joints::new(0.0, 0.0, 0.0, 0.0, 198f64.to_radians()));
/// assert!((t - 1.0).abs() < 1e-12);
/// ```
#[must_use]
pub fn move_time(machine: &Machine, a: &Joints, b: &Joints) -> f64 {
    machine.axes().iter().enumerate().map(|(i, ax)| (b[i] - a[i]).abs() / ax.dynamics.vmax).fold(0.0, f64::max)
}

/// Chooses one of the inverse solutions: candidates outside the strokes (after
/// unwrapping) are dropped; with a previous joint vector the candidate with the
/// smallest velocity-limited move time wins (continuity); ties and the first point go
/// to the machine's `preferred_branch`, then the smaller |tilt|, then the smaller
/// |pole axis| value.
///
/// ```
/// use scallop_geom::{Point3, Vec3};
/// use scallop_machine::{Kinematics, Machine, Joints, Pose, Branch, plan::select};
/// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
/// let pose = Pose::new(Point3::new(0.0, 0.0, 0.0), Vec3::new(0.0, 0.5, 1.0));
/// let sols = k.ik(&pose, &Joints::zeros()).unwrap();
/// let s = select(&k, sols.as_slice(), None, Some(0)).unwrap();
/// assert_eq!(s.branch, Branch::Negative); // A in [-125, 10]: only branch (-) fits
/// ```
///
/// # Errors
/// [`MachineError::LimitViolation`] (naming the axis of the preferred candidate) when no
/// candidate fits the strokes.
pub fn select(
    kin: &Kinematics,
    solutions: &[IkSolution],
    previous: Option<&Joints>,
    block: Option<usize>,
) -> Result<Selected, MachineError> {
    let machine = kin.machine();
    let mut best: Option<(Selected, f64)> = None;
    let mut first_error = None;
    let preference = |s: &Selected| -> (u8, f64, f64) {
        let preferred = machine.preferred_branch().is_some_and(|p| {
            let word = machine.axes()[p.axis].to_nc_word(s.joints[p.axis]);
            word * p.sign > 0.0
        });
        (u8::from(!preferred), s.joints[kin.tilt_axis()].abs(), s.joints[kin.pole_axis()].abs())
    };
    let strokes = Strokes::new(machine);
    for sol in solutions {
        match admissible(machine, &strokes, sol, previous) {
            Ok(s) => {
                let cost = previous.map_or(0.0, |p| move_time(machine, p, &s.joints));
                let better = match &best {
                    None => true,
                    Some((b, bc)) => {
                        if (cost - bc).abs() > tol::COST_TIE * (1.0 + bc.abs()) {
                            cost < *bc
                        } else {
                            preference(&s) < preference(b)
                        }
                    }
                };
                if better {
                    best = Some((s, cost));
                }
            }
            Err(e) => {
                if first_error.is_none() {
                    first_error = Some(e);
                }
            }
        }
    }
    match (best, first_error) {
        (Some((s, _)), _) => Ok(s),
        (None, Some(e)) => Err(block.map_or(e.clone(), |b| e.at_block(b))),
        (None, None) => Err(MachineError::BadInput {
            place: "plan::select".into(),
            problem: "no inverse solution given".into(),
            fix: "pass the solutions of Kinematics::ik".into(),
        }),
    }
}

/// A path in joint space with the planner's events.
#[derive(Clone, Debug, PartialEq)]
pub struct JointPath {
    /// Joint vectors: one per input pose, plus the in-place rotations of pole flips.
    pub joints: Vec<Joints>,
    /// For each joint vector, the index of its pose.
    pub pose_index: Vec<usize>,
    /// What happened on the way.
    pub events: Vec<Event>,
}

/// Inverse kinematics of a whole path, greedy streaming form of spec 3.5: each pose is
/// solved with the previous joints held at the pole and [`select`]ed for continuity.
/// No look-ahead: a path that must flip at the pole to stay within the strokes later
/// needs [`plan_path`].
/// `start` is the machine state before the first pose (`None`: no previous state, the
/// preference decides).
///
/// ```
/// use scallop_geom::{Point3, Vec3};
/// use scallop_machine::{Kinematics, Machine, Pose, plan::solve_path};
/// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
/// let poses: Vec<Pose> = (0..10)
///     .map(|i| Pose::new(Point3::new(i as f64, 0.0, 50.0), Vec3::new(0.0, 0.1 * i as f64, 1.0)))
///     .collect();
/// let path = solve_path(&k, &poses, None).unwrap();
/// assert_eq!(path.joints.len(), 10);
/// ```
///
/// # Errors
/// The first error, with its block index: [`MachineError::Unreachable`],
/// [`MachineError::LimitViolation`] (axis named) or [`MachineError::NoConvergence`].
pub fn solve_path(kin: &Kinematics, poses: &[Pose], start: Option<Joints>) -> Result<JointPath, MachineError> {
    let mut joints: Vec<Joints> = Vec::with_capacity(poses.len());
    let mut events = Vec::new();
    let mut previous = start;
    let mut previous_branch: Option<Branch> = None;
    for (block, pose) in poses.iter().enumerate() {
        let hold = previous.unwrap_or_else(Joints::zeros);
        let sols = kin.ik(pose, &hold).map_err(|e| e.at_block(block))?;
        let s = select(kin, sols.as_slice(), previous.as_ref(), Some(block))?;
        if s.at_pole {
            events.push(Event::PoleHold { block });
        } else {
            // A flip is a branch change with a pole-axis jump; crossing the pole along a
            // great circle changes the tilt sign with the pole axis still (spec 3.6 rule 2).
            let pole = kin.pole_axis();
            let jump = (s.joints[pole] - hold[pole]).abs() > tol::BRANCH_JUMP;
            if previous_branch.is_some_and(|b| b != s.branch) && jump {
                events.push(Event::BranchChange { block, to: s.branch });
            }
            previous_branch = Some(s.branch);
        }
        for i in (0..5).filter(|i| s.unwound[*i]) {
            let delta = s.joints[i] - hold[i];
            events.push(Event::Unwind {
                block,
                axis: kin.machine().axes()[i].name.clone(),
                delta_deg: delta.to_degrees(),
            });
        }
        previous = Some(s.joints);
        joints.push(s.joints);
    }
    let pose_index = (0..joints.len()).collect();
    Ok(JointPath { joints, pose_index, events })
}

/// Options of [`plan_path`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanOptions {
    /// A rotary move above this in one block (rad) is a jump: a flip or an unwind.
    pub flip_threshold: f64,
    /// Time charged for a jump on a non-cutting move (retract, reorient, approach; s).
    pub reorient_penalty: f64,
    /// Rapids bring the pole axis back to its winding nearest zero (within its stroke),
    /// the long way if need be: the job asks to unwind (cable wraps, a controller that
    /// counts turns), instead of the shortest move.
    pub unwind_rapids: bool,
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            flip_threshold: tol::FLIP_THRESHOLD_DEFAULT,
            reorient_penalty: tol::REORIENT_PENALTY_DEFAULT,
            unwind_rapids: false,
        }
    }
}

#[derive(Clone, Debug)]
struct State {
    q: Joints,
    at_pole: bool,
    cost: f64,
    /// Preference key of the first pose of this chain (spec 3.5 ties).
    first: (u8, f64, f64),
    back: usize,
    edge: Edge,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Edge {
    Plain,
    PoleFlip,
    Reorient(usize),
}

fn preference_key(kin: &Kinematics, q: &Joints) -> (u8, f64, f64) {
    let machine = kin.machine();
    let preferred =
        machine.preferred_branch().is_some_and(|p| machine.axes()[p.axis].to_nc_word(q[p.axis]) * p.sign > 0.0);
    (u8::from(!preferred), q[kin.tilt_axis()].abs(), q[kin.pole_axis()].abs())
}

fn better(a: &State, b: &State) -> bool {
    if (a.cost - b.cost).abs() > tol::COST_TIE * (1.0 + b.cost.abs()) { a.cost < b.cost } else { a.first < b.first }
}

/// The pole direction in the part frame (tool axis at tilt 0).
fn pole_direction(kin: &Kinematics) -> scallop_geom::Vec3 {
    let u = kin.machine().axes()[kin.pole_axis()].direction;
    let a0 = kin.machine().tool_axis();
    let signed = if u.dot(&a0) < 0.0 { -u } else { u };
    kin.part_frame().inverse_transform_vector(&signed)
}

/// Whether the great-circle arc from `a` to `b` passes within `eps` of the unit vector `c`.
fn arc_passes(a: &scallop_geom::Vec3, b: &scallop_geom::Vec3, c: &scallop_geom::Vec3, eps: f64) -> bool {
    let n = a.cross(b);
    let len = n.norm();
    if len <= eps {
        return (a - c).norm() <= eps || (b - c).norm() <= eps;
    }
    let n = n / len;
    if c.dot(&n).abs() > eps {
        return false;
    }
    let p = c - n * c.dot(&n);
    a.cross(&p).dot(&n) >= 0.0 && p.cross(b).dot(&n) >= 0.0 && p.dot(c) > 0.0
}

/// Inverse kinematics of a whole path by dynamic programming over the inverse branches
/// and rotary windings (spec 3.5, Viterbi with at most [`tol::PLAN_BEAM`] candidates per
/// pose). Edge cost: the velocity-limited time `max_j |dq_j| / vmax_j`. A rotary jump
/// above `flip_threshold` is allowed while cutting only as a pole flip (only the pole
/// axis jumps, and the tool axis is on the pole at one end of the block or crosses it
/// within the block; spec 3.6 rule 3); on a non-cutting move it costs
/// `reorient_penalty` more. Ties go to the machine's preferred branch at the first pose,
/// then the smaller |tilt|, then the smaller |pole axis|. A pole flip at a pose on the
/// pole is emitted as an extra joint vector at that pose (an in-place rotation).
///
/// `cutting[i]` says whether the move into pose `i` is in the material.
///
/// ```
/// use scallop_geom::{Point3, Vec3};
/// use scallop_machine::{Kinematics, Machine, Pose, plan::{plan_path, Event, PlanOptions}};
/// let k = Kinematics::new(&Machine::builtin("mx330").unwrap(), 100.0);
/// // Tool axis swept through the pole in the YZ plane, tip fixed: A <= 10 deg forces a flip.
/// let poses: Vec<Pose> = (-30..=30)
///     .map(|i| { let p = (i as f64).to_radians(); Pose::new(Point3::new(0.0, 0.0, 20.0), Vec3::new(0.0, p.sin(), p.cos())) })
///     .collect();
/// let path = plan_path(&k, &poses, &vec![true; poses.len()], None, &PlanOptions::default()).unwrap();
/// assert_eq!(path.events.iter().filter(|e| matches!(e, Event::PoleFlip { .. })).count(), 1);
/// ```
///
/// # Errors
/// [`MachineError::BadInput`] when `cutting` and `poses` differ in length; the first
/// pose with no admissible solution gives its [`MachineError::LimitViolation`] or
/// [`MachineError::Unreachable`] with the block; [`MachineError::FlipWhileCutting`] when
/// every way on needs a jump inside the material.
pub fn plan_path(
    kin: &Kinematics,
    poses: &[Pose],
    cutting: &[bool],
    start: Option<Joints>,
    options: &PlanOptions,
) -> Result<JointPath, MachineError> {
    if cutting.len() != poses.len() {
        return Err(MachineError::BadInput {
            place: "plan::plan_path".into(),
            problem: format!("{} poses but {} cutting flags", poses.len(), cutting.len()),
            fix: "give one cutting flag per pose".into(),
        });
    }
    plan_input(kin, &(poses, cutting), start, options)
}

/// The poses of a path and whether the move into each is in the material: what
/// [`plan_path`] reads (slices, or the CL records themselves without copies).
pub(crate) trait PathInput {
    /// Number of poses.
    fn len(&self) -> usize;
    /// Pose `i`.
    fn pose(&self, i: usize) -> &Pose;
    /// Whether the move into pose `i` is in the material.
    fn cutting(&self, i: usize) -> bool;
    /// Whether the move into pose `i` is a rapid (links are not).
    fn is_rapid(&self, i: usize) -> bool {
        !self.cutting(i)
    }
}

impl PathInput for (&[Pose], &[bool]) {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn pose(&self, i: usize) -> &Pose {
        &self.0[i]
    }
    fn cutting(&self, i: usize) -> bool {
        self.1[i]
    }
}

/// One state of the beam kept for the backtracking: the joints, how it was reached and
/// its predecessor in the previous layer.
#[derive(Clone, Copy, Debug)]
struct Node {
    q: Joints,
    edge: Edge,
    back: u8,
    at_pole: bool,
}

/// [`plan_path`] on any [`PathInput`]. When no way through fits the strokes, the path is
/// planned again with the pole axis free to take the windings one turn either way on the
/// non-cutting moves (rapids and links may unwind for a later cut): three times the
/// candidates, so only when they are needed.
pub(crate) fn plan_input(
    kin: &Kinematics,
    input: &impl PathInput,
    start: Option<Joints>,
    options: &PlanOptions,
) -> Result<JointPath, MachineError> {
    match plan_layers(kin, input, start, options, false) {
        Err(e @ (MachineError::LimitViolation { .. } | MachineError::FlipWhileCutting { .. }))
            if kin.machine().axes()[kin.pole_axis()].joint_limits().is_some()
                && (0..input.len()).any(|i| !input.cutting(i)) =>
        {
            plan_layers(kin, input, start, options, true).map_err(|_| e)
        }
        other => other,
    }
}

/// [`plan_input`]; `unwind`: the pole axis may also take the windings one turn either way
/// on non-cutting moves. One layer of candidate states per pose ([`Planner::layer`]),
/// kept in a [`Beam`], then the best chain backtracked and turned into joints and events
/// ([`Planner::joint_path`]).
fn plan_layers(
    kin: &Kinematics,
    input: &impl PathInput,
    start: Option<Joints>,
    options: &PlanOptions,
    unwind: bool,
) -> Result<JointPath, MachineError> {
    let n_poses = input.len();
    let planner = Planner::new(kin, input, start.is_some(), options, unwind);
    let root = State {
        q: start.unwrap_or_else(Joints::zeros),
        at_pole: false,
        cost: 0.0,
        first: (0, 0.0, 0.0),
        back: 0,
        edge: Edge::Plain,
    };
    let mut beam = Beam::with_capacity(n_poses);
    // The full states of the previous and the next layer in two reused vectors.
    let mut next: Vec<State> = Vec::new();
    let mut previous: Vec<State> = vec![root];
    // The inverse of the current pose, reused pose after pose.
    let mut shared = crate::ik::LazyIk::empty();
    for i in 0..n_poses {
        planner.layer(i, &previous, &mut next, &mut shared)?;
        beam.push(&next);
        std::mem::swap(&mut previous, &mut next);
    }
    let chain = beam.backtrack(n_poses);
    Ok(planner.joint_path(&chain, start))
}

/// The layers' nodes in one arena: layer i is `arena[offsets[i]..offsets[i + 1]]` (no
/// allocation per pose).
struct Beam {
    arena: Vec<Node>,
    offsets: Vec<u32>,
}

impl Beam {
    fn with_capacity(n_poses: usize) -> Beam {
        let mut offsets: Vec<u32> = Vec::with_capacity(n_poses + 1);
        offsets.push(0);
        Beam { arena: Vec::with_capacity(n_poses + n_poses / 4), offsets }
    }

    /// Appends the (sorted, truncated) states of the next layer.
    fn push(&mut self, layer: &[State]) {
        self.arena.extend(layer.iter().map(|s| Node {
            q: s.q,
            edge: s.edge,
            // INVARIANT: `back` indexes the previous layer, at most PLAN_BEAM states.
            back: u8::try_from(s.back).unwrap_or(u8::MAX),
            at_pole: s.at_pole,
        }));
        // INVARIANT: a path has fewer than 2^32 / PLAN_BEAM poses.
        self.offsets.push(u32::try_from(self.arena.len()).unwrap_or(u32::MAX));
    }

    /// The chain of nodes from the first pose to the best final state (layers are
    /// sorted: the best is first).
    fn backtrack(&self, n_poses: usize) -> Vec<&Node> {
        let layers = self.offsets.windows(2).map(|w| &self.arena[w[0] as usize..w[1] as usize]);
        let mut chain: Vec<&Node> = Vec::with_capacity(n_poses);
        if let Some(last) = layers.clone().next_back() {
            let mut idx = 0;
            for layer in layers.rev() {
                let s = &layer[idx];
                chain.push(s);
                idx = usize::from(s.back);
            }
            debug_assert_eq!(chain.len(), n_poses);
            debug_assert!(!last.is_empty());
        }
        chain.reverse();
        chain
    }
}

/// The two rotaries (joints 3 and 4) unwrapped, and whether each took an unwinding move
/// ([`unwrap_rotaries`]).
type Rotaries = ([f64; 2], [bool; 2]);

/// Why candidates of a layer were not kept: the first stroke or reach error, the smallest
/// rotary jump while cutting (joint, size), and whether the jump shortcut dropped one.
#[derive(Default)]
struct Rejected {
    first_error: Option<MachineError>,
    smallest_jump: Option<(usize, f64)>,
    dropped: bool,
}

/// What one run of [`plan_layers`] reads at every pose.
struct Planner<'a, I: PathInput> {
    kin: &'a Kinematics,
    machine: &'a Machine,
    input: &'a I,
    options: &'a PlanOptions,
    strokes: Strokes,
    pole: usize,
    pole_dir: scallop_geom::Vec3,
    eps: f64,
    /// A machine state precedes the first pose.
    has_start: bool,
    /// The pole axis may unwind by a turn either way on non-cutting moves.
    unwind: bool,
}

impl<'a, I: PathInput> Planner<'a, I> {
    fn new(kin: &'a Kinematics, input: &'a I, has_start: bool, options: &'a PlanOptions, unwind: bool) -> Self {
        let machine = kin.machine();
        Planner {
            kin,
            machine,
            input,
            options,
            strokes: Strokes::new(machine),
            pole: kin.pole_axis(),
            pole_dir: pole_direction(kin),
            eps: machine.pole_eps(),
            has_start,
            unwind,
        }
    }

    /// Whether the tool axis crosses the pole on the move into pose `i > 0`.
    fn crosses_pole(&self, i: usize) -> bool {
        arc_passes(&self.input.pose(i - 1).axis, &self.input.pose(i).axis, &self.pole_dir, self.eps)
    }

    /// The states of pose `i` reached from `preds` into `next`, sorted best first and cut
    /// to the beam; an error naming the block when none is left.
    fn layer(
        &self,
        i: usize,
        preds: &[State],
        next: &mut Vec<State>,
        shared: &mut crate::ik::LazyIk,
    ) -> Result<(), MachineError> {
        let pose = self.input.pose(i);
        // Off the pole the inverse does not depend on the held joints: solve once (the
        // position step of each branch only when a candidate needs it).
        self.kin.ik_lazy(pose, &preds[0].q, shared).map_err(|e| e.at_block(i))?;
        let polar =
            shared.sols.as_slice().iter().any(|s| s.at_pole) || self.kin.solver() == crate::chain::Solver::Numeric;
        // A candidate that jumps while cutting is dropped on its rotary values alone,
        // before its linear joints are solved and its strokes checked: kept candidates are
        // the same. When that leaves the layer empty, it is expanded again without the
        // shortcut, for the error the full checks give.
        let mut rejected = Rejected::default();
        for shortcut in [true, false] {
            next.clear();
            rejected = Rejected::default();
            for (pi, p) in preds.iter().enumerate() {
                let mut own;
                let sols = if polar && pi > 0 {
                    own = crate::ik::LazyIk::complete(self.kin.ik(pose, &p.q).map_err(|e| e.at_block(i))?);
                    &mut own
                } else {
                    &mut *shared
                };
                self.expand(i, pi, p, sols, shortcut, next, &mut rejected);
            }
            if !(next.is_empty() && rejected.dropped) {
                break;
            }
        }
        if next.is_empty() {
            if let Some((j, d)) = rejected.smallest_jump {
                return Err(MachineError::FlipWhileCutting {
                    block: i,
                    axis: self.machine.axes()[j].name.clone(),
                    delta_deg: d.to_degrees(),
                });
            }
            return Err(rejected.first_error.unwrap_or(MachineError::Unreachable {
                block: Some(i),
                axis: [pose.axis.x, pose.axis.y, pose.axis.z],
            }));
        }
        // Deterministic order, then the beam.
        next.sort_by(|a, b| {
            if better(a, b) {
                std::cmp::Ordering::Less
            } else if better(b, a) {
                std::cmp::Ordering::Greater
            } else {
                std::cmp::Ordering::Equal
            }
        });
        next.truncate(tol::PLAN_BEAM);
        Ok(())
    }

    /// The states of pose `i` reached from the predecessor `p` (index `pi`) through the
    /// inverse solutions `sols`, merged into `next`.
    #[allow(clippy::too_many_arguments, reason = "the loop state of one layer")]
    fn expand(
        &self,
        i: usize,
        pi: usize,
        p: &State,
        sols: &mut crate::ik::LazyIk,
        shortcut: bool,
        next: &mut Vec<State>,
        rejected: &mut Rejected,
    ) {
        let has_previous = i > 0 || self.has_start;
        // The continuous motion along this cutting move from `p` (computed once per
        // predecessor, only when a candidate jumps).
        let mut tracked: Option<Option<Joints>> = None;
        let check_cut = has_previous && self.input.cutting(i);
        // The jump test of each candidate (at most two inverse solutions), and whether one
        // of them needs no jump: then that one is the continuation (the two solutions
        // differ by half a turn of the pole axis) and the others are not tracked (the
        // dense-path case costs nothing more).
        let mut pre = [(false, ([0.0; 2], [false; 2])); 2];
        let mut any_plain = false;
        if check_cut {
            for (k, slot) in pre.iter_mut().enumerate().take(sols.sols.as_slice().len()) {
                *slot = jumps_on_rotaries(
                    &self.strokes,
                    &sols.sols.as_slice()[k],
                    p,
                    self.options.flip_threshold,
                    self.pole,
                    || i > 0 && self.crosses_pole(i),
                );
                any_plain |= !slot.0;
            }
        }
        let n_sols = sols.sols.as_slice().len();
        for (k, &(jumps, u)) in pre.iter().enumerate().take(n_sols) {
            let (unwrapped, continuous) = if check_cut {
                let raw = &sols.sols.as_slice()[k].joints;
                match self.cut_rotaries(i, p, raw, (jumps, u), any_plain, shortcut, &mut tracked) {
                    Some(kept) => kept,
                    None => {
                        rejected.dropped = true;
                        continue;
                    }
                }
            } else {
                (None, false)
            };
            self.kin.complete(sols, k);
            let sol = &sols.sols.as_slice()[k];
            let checked = match unwrapped {
                Some(u) => admissible_with(self.machine, &self.strokes, sol, u),
                None => admissible(self.machine, &self.strokes, sol, has_previous.then_some(&p.q)),
            };
            let cand = match checked {
                Ok(c) => c,
                Err(e) => {
                    rejected.first_error.get_or_insert(e.at_block(i));
                    continue;
                }
            };
            for cand in self.variants(i, cand).into_iter().flatten() {
                let Some((cost, edge)) = self.edge(i, p, &cand, has_previous, continuous, rejected) else {
                    continue;
                };
                let first = if i == 0 { preference_key(self.kin, &cand.joints) } else { p.first };
                let state = State { q: cand.joints, at_pole: cand.at_pole, cost: p.cost + cost, first, back: pi, edge };
                merge_state(next, state);
            }
        }
    }

    /// The rotaries of a candidate (inverse solution `raw`) on a cutting move from `p`,
    /// from its jump test `(jumps, unwrapped)`: `None` drops it (a jump while cutting,
    /// under the shortcut); else the unwrapped rotaries when already known and whether the
    /// candidate is the continuous motion along the move ([`track`], a large rotary change
    /// allowed while cutting, near the pole or a genuine reorientation).
    #[allow(clippy::too_many_arguments, reason = "the loop state of one candidate")]
    fn cut_rotaries(
        &self,
        i: usize,
        p: &State,
        raw: &Joints,
        (jumps, u): (bool, Rotaries),
        any_plain: bool,
        shortcut: bool,
        tracked: &mut Option<Option<Joints>>,
    ) -> Option<(Option<Rotaries>, bool)> {
        if !jumps {
            return Some((shortcut.then_some(u), false));
        }
        if any_plain {
            return if shortcut { None } else { Some((None, false)) };
        }
        // The candidate is the tracked joints modulo a turn, and takes the tracked windings.
        let from = if i > 0 { *self.input.pose(i - 1) } else { self.kin.fk(&p.q) };
        let t = tracked.get_or_insert_with(|| track(self.kin, &from, self.input.pose(i), &p.q));
        match t.as_ref().and_then(|t| continuation(raw, t)) {
            Some(u) => Some((Some(u), true)),
            None if shortcut => None,
            None => Some((None, false)),
        }
    }

    /// The candidate `cand` of pose `i`, and off the material the windings of the pole
    /// axis one turn either way (within its stroke) that a later cut may need; on a rapid
    /// of a job that unwinds, the pole axis at its winding nearest zero.
    fn variants(&self, i: usize, mut cand: Selected) -> [Option<Selected>; 3] {
        let pole = self.pole;
        if self.options.unwind_rapids && self.input.is_rapid(i) {
            let turn = 2.0 * PI;
            let mut q = cand.joints;
            q[pole] -= turn * (q[pole] / turn).round();
            if self.strokes.inside(&q) && (q[pole] - cand.joints[pole]).abs() > 0.0 {
                cand.joints = q;
                cand.unwound[pole] = true;
            }
        }
        let mut variants = [None, None, None];
        if self.unwind && !self.input.cutting(i) {
            for (slot, sign) in [(1, 1.0), (2, -1.0)] {
                let mut v = cand.clone();
                v.joints[pole] += sign * 2.0 * PI;
                if self.strokes.inside(&v.joints) {
                    v.unwound[pole] = true;
                    variants[slot] = Some(v);
                }
            }
        }
        variants[0] = Some(cand);
        variants
    }

    /// The cost and kind of the move from `p` to `cand` at pose `i`: the move time, a pole
    /// flip, or a reorientation with its penalty off the material; `None` for a jump while
    /// cutting (recorded in `rejected` for the error).
    fn edge(
        &self,
        i: usize,
        p: &State,
        cand: &Selected,
        has_previous: bool,
        continuous: bool,
        rejected: &mut Rejected,
    ) -> Option<(f64, Edge)> {
        if !has_previous {
            return Some((0.0, Edge::Plain));
        }
        let dq = cand.joints - p.q;
        let jump = [3, 4].map(|j| dq[j].abs() > self.options.flip_threshold);
        // The move time only for candidates that are kept (a jump while cutting is
        // dropped before it is needed).
        let t = || move_time(self.machine, &p.q, &cand.joints);
        if jump == [false, false] || continuous {
            return Some((t(), Edge::Plain));
        }
        let only_pole = (0..2).all(|r| jump[r] == (r + 3 == self.pole));
        let crosses = p.at_pole || cand.at_pole || (i > 0 && self.crosses_pole(i));
        let j = if dq[3].abs() >= dq[4].abs() { 3 } else { 4 };
        if only_pole && crosses {
            Some((t(), Edge::PoleFlip))
        } else if self.input.cutting(i) {
            if rejected.smallest_jump.is_none_or(|(_, d)| dq[j].abs() < d) {
                rejected.smallest_jump = Some((j, dq[j].abs()));
            }
            None
        } else {
            Some((t() + self.options.reorient_penalty, Edge::Reorient(j)))
        }
    }

    /// The joints and events of the backtracked `chain`: a pole flip at a pose on the
    /// pole adds the in-place rotation as an extra joint vector.
    fn joint_path(&self, chain: &[&Node], start: Option<Joints>) -> JointPath {
        let (pole, machine) = (self.pole, self.machine);
        let mut joints = Vec::with_capacity(chain.len() + 2);
        let mut pose_index = Vec::with_capacity(chain.len() + 2);
        let mut events = Vec::new();
        for (i, s) in chain.iter().enumerate() {
            let prev = if i == 0 { start } else { Some(chain[i - 1].q) };
            match (s.edge, prev) {
                (Edge::PoleFlip, Some(pq)) => {
                    let delta = s.q[pole] - pq[pole];
                    let axis = &machine.axes()[pole];
                    events.push(Event::PoleFlip {
                        block: i,
                        axis: axis.name.clone(),
                        delta_deg: delta.to_degrees(),
                        seconds: delta.abs() / axis.dynamics.vmax,
                    });
                    if let Some((q, at)) = self.turn_in_place(chain, i, pq) {
                        joints.push(q);
                        pose_index.push(at);
                    }
                }
                (Edge::Reorient(j), Some(pq)) => events.push(Event::Reorient {
                    block: i,
                    axis: machine.axes()[j].name.clone(),
                    delta_deg: (s.q[j] - pq[j]).to_degrees(),
                }),
                _ => {}
            }
            if s.at_pole {
                events.push(Event::PoleHold { block: i });
            }
            joints.push(s.q);
            pose_index.push(i);
        }
        JointPath { joints, pose_index, events }
    }

    /// The in-place rotation of the pole flip into pose `i` (from the joints `pq`) and
    /// the pose it turns at: the previous pose when it is on the pole, else pose `i` when
    /// it is; `None` when neither is (a flip crossing the pole inside the block).
    fn turn_in_place(&self, chain: &[&Node], i: usize, pq: Joints) -> Option<(Joints, usize)> {
        let (pole, s) = (self.pole, chain[i]);
        if i > 0 && chain[i - 1].at_pole {
            // Turn in place at the previous (polar) pose.
            let mut q = pq;
            q[pole] = s.q[pole];
            self.kin.solve_linear(&self.input.pose(i - 1).tip, &mut q);
            Some((q, i - 1))
        } else if s.at_pole {
            let mut q = s.q;
            q[pole] = pq[pole];
            self.kin.solve_linear(&self.input.pose(i).tip, &mut q);
            Some((q, i))
        } else {
            None
        }
    }
}

/// Adds `state` to the layer `next`, or keeps the better of it and a state with the same
/// joints.
fn merge_state(next: &mut Vec<State>, state: State) {
    match next.iter_mut().find(|s| (s.q - state.q).amax() < tol::SAME_JOINTS) {
        Some(existing) => {
            if better(&state, existing) {
                *existing = state;
            }
        }
        None => next.push(state),
    }
}
