//! Joint-space blocks: tip and tool-axis deviation of joint-linear interpolation,
//! subdivision until the tip stays within its tolerance (spec 3.10), and inverse-time
//! (G93) feeds bounded by every axis's velocity limit (spec 3.9).

use scallop_geom::nalgebra::UnitQuaternion;
use scallop_geom::num::golden_section;
use scallop_geom::{Point3, Vec3};

use crate::chain::{Joints, Kinematics, Pose};
use crate::error::MachineError;
use crate::plan::select;
use crate::tol;

/// Distance from `p` to the segment `[a, b]`.
fn distance_to_segment(p: &Point3, a: &Point3, b: &Point3) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 { ((p - a).dot(&ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + ab * t)).norm()
}

/// Spherical interpolation of unit vectors (`a` when they are parallel or opposite).
fn slerp(a: &Vec3, b: &Vec3, s: f64) -> Vec3 {
    UnitQuaternion::rotation_between(a, b).map_or(*a, |r| UnitQuaternion::identity().slerp(&r, s) * a)
}

/// The pose at `s` in [0, 1] of the CL move `a -> b`: the tip on the chord, the tool axis
/// on the great circle.
pub(crate) fn interpolate(a: &Pose, b: &Pose, s: f64) -> Pose {
    Pose::new(Point3::from(a.tip.coords + (b.tip.coords - a.tip.coords) * s), slerp(&a.axis, &b.axis, s))
}

/// Deviation of the joint-linear motion `qa -> qb` from the part-frame block
/// `pose_a -> pose_b`: the largest tip distance to the segment `[P_a, P_b]` and the
/// largest angle (rad) between the tool axis and `slerp(O_a, O_b, s)`, over 16 uniform
/// samples refined by golden section around the worst (spec 3.10).
///
/// ```
/// use scallop_machine::{Kinematics, Machine, Joints, feed::deviation};
/// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
/// let qa = Joints::new(0.0, 0.0, 50.0, 0.0, 0.0);
/// let qb = Joints::new(10.0, 0.0, 50.0, 0.0, 0.0);
/// let (pos, ang) = deviation(&k, &k.fk(&qa), &k.fk(&qb), &qa, &qb);
/// assert!(pos < 1e-12 && ang < 1e-12); // pure translation
/// ```
#[must_use]
pub fn deviation(kin: &Kinematics, pose_a: &Pose, pose_b: &Pose, qa: &Joints, qb: &Joints) -> (f64, f64) {
    let pos_at = |s: f64| {
        let p = kin.fk(&(qa + (qb - qa) * s)).tip;
        distance_to_segment(&p, &pose_a.tip, &pose_b.tip)
    };
    let ang_at = |s: f64| {
        let o = kin.fk(&(qa + (qb - qa) * s)).axis;
        let ideal = slerp(&pose_a.axis, &pose_b.axis, s);
        o.cross(&ideal).norm().atan2(o.dot(&ideal))
    };
    (maximise(pos_at), maximise(ang_at))
}

/// A certified upper bound of [`deviation`] from the joint change alone, or `None` when
/// the block turns too far for the bound (total rotation `Omega >= 1/3` rad).
///
/// Joint-linear motion composes screw motions: rotations at rates `alpha_k` (rad per
/// unit of the block parameter `s`) about lines that the preceding joints carry, and
/// translations at rates `beta_k`. With `Omega = sum |alpha_k|`, `B = sum |beta_k|` and
/// `D` a bound of the tip's distance to every rotary line over the block, the tip's
/// velocity is at most `Omega D + B` and its acceleration at most `4 Omega^2 D + 3 Omega B`
/// (centripetal, the lines' own rotation, and the Coriolis terms of the moving lines,
/// whose points lie within `2 D` of the preceding lines). A `C^2` curve leaves its chord
/// by at most `max |p''| / 8`. The distance to a line changes at most at
/// `3 Omega D + 2 B` per unit `s`, so `D <= (D0 + 2 B) / (1 - 3 Omega)` from its value
/// `D0` at the start. The tool axis turns at most at `Omega`, with `|o''| <= 2 Omega^2`:
/// it leaves its chord by `Omega^2 / 4`, the chord leaves the great circle by `phi^2 / 8
/// <= Omega^2 / 8`, and an angle is at most `pi / 2` times its chord.
///
/// Most blocks of a dense 5-axis path turn by milliradians: the bound settles them
/// without sampling the forward kinematics ([`subdivide`] samples only when the bound
/// cannot decide).
///
/// ```
/// use scallop_machine::{Kinematics, Machine, Joints, feed::{deviation, deviation_bound}};
/// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
/// let qa = Joints::new(0.0, 0.0, 50.0, 0.5, 0.0);
/// let qb = Joints::new(1.0, 0.0, 50.0, 0.5, 0.01);
/// let (pos, ang) = deviation(&k, &k.fk(&qa), &k.fk(&qb), &qa, &qb);
/// let (bp, ba) = deviation_bound(&k, &qa, &qb).unwrap();
/// assert!(pos <= bp && ang <= ba);
/// ```
#[must_use]
pub fn deviation_bound(kin: &Kinematics, qa: &Joints, qb: &Joints) -> Option<(f64, f64)> {
    screw_bound(kin, qa, qb, exact_d0)
}

/// [`deviation_bound`] with the distance `D0` replaced by a cheaper upper bound (no
/// trigonometry: the tip is only known to lie within a radius of a point once it is
/// carried back through a rotary). The bound is monotone in `D0`, so this is at least
/// [`deviation_bound`]: when it passes the tolerance, so does the exact bound. `None`
/// exactly when [`deviation_bound`] is `None`.
///
/// ```
/// use scallop_machine::{Kinematics, Machine, Joints, feed::{deviation_bound, deviation_bound_relaxed}};
/// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
/// let qa = Joints::new(0.0, 0.0, 50.0, 0.5, 0.0);
/// let qb = Joints::new(1.0, 0.0, 50.0, 0.5, 0.01);
/// let (bp, ba) = deviation_bound(&k, &qa, &qb).unwrap();
/// let (rp, ra) = deviation_bound_relaxed(&k, &qa, &qb).unwrap();
/// assert!(bp <= rp && ba == ra);
/// ```
#[must_use]
pub fn deviation_bound_relaxed(kin: &Kinematics, qa: &Joints, qb: &Joints) -> Option<(f64, f64)> {
    screw_bound(kin, qa, qb, relaxed_d0)
}

enum Rates {
    /// No rotary moves.
    Translation,
    /// The block turns too far for the bound (or a joint is not finite).
    TooFar,
    /// `(Omega, B)`.
    Screw(f64, f64),
}

/// The bound of a block from its screw motion, with `d0` giving D0 at `qa` (the
/// tip's largest distance to a rotary line: [`exact_d0`] or [`relaxed_d0`]).
fn screw_bound(kin: &Kinematics, qa: &Joints, qb: &Joints, d0: fn(&Kinematics, &Joints) -> f64) -> Option<(f64, f64)> {
    match rotation_and_translation(kin, qa, qb) {
        Rates::Translation => Some((0.0, 0.0)),
        Rates::TooFar => None,
        Rates::Screw(omega, b) => Some(bound_from(d0(kin, qa), omega, b)),
    }
}

fn rotation_and_translation(kin: &Kinematics, qa: &Joints, qb: &Joints) -> Rates {
    let dq = qb - qa;
    let (mut omega, mut b) = (0.0, 0.0);
    for (i, &rotary) in kin.rotary.iter().enumerate() {
        if rotary {
            omega += dq[i].abs();
        } else {
            b += dq[i].abs();
        }
    }
    if omega == 0.0 {
        // Translations only: the tip moves on the chord, the axis does not turn.
        return Rates::Translation;
    }
    if omega.is_nan() || omega >= tol::BOUND_MAX_ROTATION {
        return Rates::TooFar;
    }
    Rates::Screw(omega, b)
}

fn bound_from(d0: f64, omega: f64, b: f64) -> (f64, f64) {
    let d = (d0 + 2.0 * b) / (1.0 - 3.0 * omega);
    let pos = (4.0 * omega * omega * d + 3.0 * omega * b) / 8.0;
    let ang = std::f64::consts::FRAC_PI_2 * 3.0 * omega * omega / 8.0;
    (pos, ang)
}

/// D0: distance from the tip to each rotary line at the start, both in M. A joint's
/// line is carried by the joints before it in its chain; the distance is invariant
/// under rigid motion, so the tip is carried back instead: walking down the chain,
/// the tip in the frame of joint k is the previous one moved by the inverse of joint
/// k - 1 (one sin_cos per rotary, no transform composition).
fn exact_d0(kin: &Kinematics, qa: &Joints) -> f64 {
    let machine = kin.machine();
    let mut tip_m = kin.t0;
    for &i in machine.tool_chain.iter().rev() {
        let a = &machine.axes[i];
        tip_m = crate::chain::joint_apply(&a.direction, &a.point, a.kind, qa[i], &tip_m);
    }
    let mut d0 = 0.0f64;
    for chain in [&machine.part_chain, &machine.tool_chain] {
        let Some(last) = chain.iter().rposition(|&i| machine.axes[i].kind == crate::AxisKind::Rotary) else {
            continue;
        };
        let mut p = tip_m;
        for &i in &chain[..=last] {
            let a = &machine.axes[i];
            if a.kind == crate::AxisKind::Rotary {
                let off = p - a.point;
                d0 = d0.max((off - a.direction * off.dot(&a.direction)).norm());
            }
            if i != chain[last] {
                p = crate::chain::joint_apply(&a.direction, &a.point, a.kind, -qa[i], &p);
            }
        }
    }
    d0
}

/// An upper bound of [`exact_d0`] without trigonometry: the carried tip is tracked as a
/// ball `(c, r)`. A translation moves the centre; a rotation about a line through `p`
/// keeps the distance to `p`, so the ball becomes `(p, |c - p| + r)`; the distance to a
/// line is at most the centre's distance plus `r`. Inflated by a relative and an
/// absolute slack so that it also bounds the rounded [`exact_d0`].
fn relaxed_d0(kin: &Kinematics, qa: &Joints) -> f64 {
    let machine = kin.machine();
    if let Some((p1, k)) = kin.ball_bound {
        // Tool chain of linear axes: the tip in M is exact; part chain of rotaries: the
        // precomputed ball walk (see `chain::ball_bound`).
        let mut tip = kin.t0;
        for &i in machine.tool_chain.iter().rev() {
            tip += machine.axes[i].direction * qa[i];
        }
        let d0 = (tip - p1).norm() + k;
        return d0 * (1.0 + tol::BOUND_PRETEST_SLACK) + tol::BOUND_PRETEST_SLACK;
    }
    let (mut tip, mut r) = (kin.t0, 0.0f64);
    for &i in machine.tool_chain.iter().rev() {
        let a = &machine.axes[i];
        match a.kind {
            crate::AxisKind::Linear => tip += a.direction * qa[i],
            crate::AxisKind::Rotary => {
                r += (tip - a.point).norm();
                tip = a.point;
            }
        }
    }
    let mut d0 = 0.0f64;
    for chain in [&machine.part_chain, &machine.tool_chain] {
        let (mut c, mut rc) = (tip, r);
        for &i in chain {
            let a = &machine.axes[i];
            match a.kind {
                crate::AxisKind::Rotary => {
                    let off = c - a.point;
                    d0 = d0.max((off - a.direction * off.dot(&a.direction)).norm() + rc);
                    rc += off.norm();
                    c = a.point;
                }
                crate::AxisKind::Linear => c -= a.direction * qa[i],
            }
        }
    }
    d0 * (1.0 + tol::BOUND_PRETEST_SLACK) + tol::BOUND_PRETEST_SLACK
}

/// Max of `f` on [0, 1]: uniform samples, then golden section around the best.
fn maximise(f: impl Fn(f64) -> f64) -> f64 {
    let n = tol::DEVIATION_SAMPLES;
    let step = 1.0 / n as f64;
    let (mut best_s, mut best) = (0.0, f(0.0));
    for k in 1..=n {
        let s = k as f64 * step;
        let v = f(s);
        if v > best {
            best = v;
            best_s = s;
        }
    }
    let (lo, hi) = ((best_s - step).max(0.0), (best_s + step).min(1.0));
    let end = golden_section(f, (lo, hi), tol::DEVIATION_REFINE_ITERATIONS, None, |f1, f2| f1 > f2);
    best.max(end.inner[0].1).max(end.inner[1].1)
}

/// One sub-block end: the part-frame pose and its joints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockEnd {
    /// Pose in the part frame.
    pub pose: Pose,
    /// Joint values.
    pub joints: Joints,
}

/// Subdivides the joint-space block `qa -> qb` (poses `pose_a -> pose_b`) by bisection
/// until joint-linear motion keeps the tip within `tol_pos` (mm) of the segment and the
/// tool axis within `tol_ang` (rad) of the great circle (spec 3.10): the midpoint is
/// `P_m = (P_a + P_b)/2`, `O_m = slerp(O_a, O_b, 1/2)`, solved continuing the branch and
/// windings of `qa`. Returns the block ends after `qa` (the last one is `qb`).
///
/// ```
/// use scallop_geom::{Point3, Vec3};
/// use scallop_machine::{Kinematics, Machine, Joints, feed::subdivide};
/// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
/// let qa = Joints::new(0.0, 0.0, 50.0, 0.5, 0.0);
/// let qb = Joints::new(0.0, 0.0, 50.0, 0.5, 0.3);
/// let ends = subdivide(&k, &k.fk(&qa), &k.fk(&qb), &qa, &qb, 0.01, 1.0, 0).unwrap();
/// assert!(ends.len() > 1 && ends.last().unwrap().joints == qb);
/// ```
///
/// # Errors
/// [`MachineError::SubdivisionFailed`] after 16 levels; the inverse's errors for a
/// midpoint, with `block`.
#[allow(clippy::too_many_arguments, reason = "a block is two poses, two joint vectors and two tolerances")]
pub fn subdivide(
    kin: &Kinematics,
    pose_a: &Pose,
    pose_b: &Pose,
    qa: &Joints,
    qb: &Joints,
    tol_pos: f64,
    tol_ang: f64,
    block: usize,
) -> Result<Vec<BlockEnd>, MachineError> {
    let mut out = Vec::new();
    subdivide_into(kin, (pose_a, qa), (pose_b, qb), (tol_pos, tol_ang), block, &mut out)?;
    Ok(out)
}

/// [`subdivide`] appending the block ends to `out` (no allocation per block when `out`
/// is reused). `a` and `b` are `(pose, joints)`, `tolerance` is `(tol_pos, tol_ang)`.
///
/// # Errors
/// As [`subdivide`].
pub fn subdivide_into(
    kin: &Kinematics,
    a: (&Pose, &Joints),
    b: (&Pose, &Joints),
    tolerance: (f64, f64),
    block: usize,
    out: &mut Vec<BlockEnd>,
) -> Result<(), MachineError> {
    split(kin, a, b, tolerance, block, 0, out)
}

fn split(
    kin: &Kinematics,
    a: (&Pose, &Joints),
    b: (&Pose, &Joints),
    tolerance: (f64, f64),
    block: usize,
    depth: usize,
    out: &mut Vec<BlockEnd>,
) -> Result<(), MachineError> {
    // The trigonometry-free bound first: it settles nearly every block of a dense path;
    // when it passes, the exact bound (never smaller) would pass too.
    if let Some((pos, ang)) = deviation_bound_relaxed(kin, a.1, b.1)
        && pos <= tolerance.0
        && ang <= tolerance.1
    {
        out.push(BlockEnd { pose: *b.0, joints: *b.1 });
        return Ok(());
    }
    if let Some((pos, ang)) = deviation_bound(kin, a.1, b.1)
        && pos <= tolerance.0
        && ang <= tolerance.1
    {
        out.push(BlockEnd { pose: *b.0, joints: *b.1 });
        return Ok(());
    }
    let (pos, ang) = deviation(kin, a.0, b.0, a.1, b.1);
    if pos <= tolerance.0 && ang <= tolerance.1 {
        out.push(BlockEnd { pose: *b.0, joints: *b.1 });
        return Ok(());
    }
    if depth >= tol::SUBDIVISION_MAX_DEPTH {
        return Err(MachineError::SubdivisionFailed { block, deviation: pos, depth });
    }
    let mid = Pose::new(Point3::from((a.0.tip.coords + b.0.tip.coords) / 2.0), slerp(&a.0.axis, &b.0.axis, 0.5));
    // At the pole (C free, e.g. a pole flip) the midpoint takes the mean pole-axis value
    // and the other axes are solved for it (spec 3.10): that is the hold of the inverse.
    let pole = kin.pole_axis();
    let mut hold = *a.1;
    hold[pole] = (a.1[pole] + b.1[pole]) / 2.0;
    let sols = kin.ik(&mid, &hold).map_err(|e| e.at_block(block))?;
    // The solution nearest the joint-space midpoint: the continuation of a large but
    // continuous rotary move (near the pole, a reorientation) is nearer to it than to
    // either end, and the windings are those between the ends.
    let halfway = (a.1 + b.1) / 2.0;
    let mut q_mid = select(kin, sols.as_slice(), Some(&halfway), Some(block))?.joints;
    if (q_mid - a.1).amax() > (b.1 - a.1).amax() + tol::BRANCH_JUMP {
        // The midpoint jumped branch (a flip inside the block): interpolate the pole
        // axis and solve the rest for it.
        q_mid = hold;
        kin.solve_linear(&mid.tip, &mut q_mid);
    }
    split(kin, a, (&mid, &q_mid), tolerance, block, depth + 1, out)?;
    split(kin, (&mid, &q_mid), b, tolerance, block, depth + 1, out)
}

pub(crate) use scallop_geom::num::{floor_fast, round_fast};

/// `10f64.powi(e)` by table for `|e| <= 9`, bit for bit: the exponentiation by squaring
/// is exact for these powers and a negative power is the reciprocal of the positive one.
/// The scale of a word rounded to `e` decimals, here and in `scallop-post`.
///
/// ```
/// use scallop_machine::feed::pow10i;
/// for e in -9..=9 {
///     assert_eq!(pow10i(e).to_bits(), 10f64.powi(e).to_bits());
/// }
/// ```
#[must_use]
pub fn pow10i(e: i32) -> f64 {
    const POW10: [f64; 10] = [1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9];
    match usize::try_from(e.unsigned_abs()).ok().and_then(|k| POW10.get(k)) {
        Some(&p) if e >= 0 => p,
        Some(&p) => 1.0 / p,
        None => 10f64.powi(e),
    }
}

/// Inverse-time feed word of the block `qa -> qb` (spec 3.9):
/// `T = max(L/F, r_ref·Δφ/F, max_j |Δq_j|/vmax_j, T_min)` and `F_inv = 1/T` in 1/min,
/// rounded down to `nc.decimals.feed` so that no axis exceeds its velocity limit.
/// `feed` is the programmed tip feed in mm/min.
///
/// ```
/// use scallop_machine::{Kinematics, Machine, Joints, feed::inverse_time_feed};
/// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
/// let qa = Joints::new(0.0, 0.0, 50.0, 0.0, 0.0);
/// let qb = Joints::new(10.0, 0.0, 50.0, 0.0, 0.0);
/// assert_eq!(inverse_time_feed(&k, &k.fk(&qa), &k.fk(&qb), &qa, &qb, 1000.0), 100.0);
/// ```
#[must_use]
pub fn inverse_time_feed(kin: &Kinematics, pose_a: &Pose, pose_b: &Pose, qa: &Joints, qb: &Joints, feed: f64) -> f64 {
    let machine = kin.machine();
    let f = feed / 60.0; // mm/s
    let length = (pose_b.tip - pose_a.tip).norm();
    let rate = crate::plan::move_time(machine, qa, qb);
    let others = (length / f).max(rate).max(machine.nc().min_block_time);
    // The rotation term needs its atan2 only when it may be the largest: for an angle
    // below 90 deg, dphi = atan(s / c) <= s / c, so a slightly inflated r_ref s / c / F
    // below the other terms proves that the maximum is theirs (the same value).
    let (sin_phi, cos_phi) = (pose_a.axis.cross(&pose_b.axis).norm(), pose_a.axis.dot(&pose_b.axis));
    let r_ref = machine.nc().r_ref;
    let t = if cos_phi > 0.0 && r_ref * (sin_phi / cos_phi) / f * (1.0 + tol::ROTATION_TERM_SLACK) < others {
        others
    } else {
        let dphi = sin_phi.atan2(cos_phi);
        (length / f).max(r_ref * dphi / f).max(rate).max(machine.nc().min_block_time)
    };
    let scale = pow10i(i32::from(machine.nc().decimals.feed));
    let exact = 60.0 / t;
    // Round down, but keep an exact value when it is already representable.
    let nearest = round_fast(exact * scale) / scale;
    if (exact - nearest).abs() <= tol::FEED_ROUNDING * exact { nearest } else { floor_fast(exact * scale) / scale }
}
