//! Machine-aware time (spec section 8): the jerk-limited velocity-change primitive, the
//! four-case stop-to-stop block time, and a look-ahead feed profile along a joint-space
//! path with per-axis velocity, acceleration and jerk limits. Units: mm (or rad) and s.
//!
//! ```text
//! T_acc(dv) = 2 sqrt(dv/J)          if dv <= A^2/J      (A not reached)
//!           = dv/A + A/J            otherwise
//! d(va, vb) = (va + vb)/2 T_acc(|vb - va|)             (distance used)
//! ```

use crate::chain::{Joints, Kinematics};
use crate::error::MachineError;
use crate::tol;

/// Velocity, acceleration and jerk limits of a path or an axis (mm/s, mm/s², mm/s³).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Velocity.
    pub v: f64,
    /// Acceleration.
    pub a: f64,
    /// Jerk.
    pub j: f64,
}

/// Time of a velocity change `dv` with zero acceleration at both ends (spec 8.2).
///
/// ```
/// assert!((scallop_machine::time::t_acc(40.0, 2500.0, 5000.0) - 0.178885).abs() < 1e-6);
/// ```
#[must_use]
pub fn t_acc(dv: f64, a: f64, j: f64) -> f64 {
    let dv = dv.abs();
    if dv <= a * a / j { 2.0 * (dv / j).sqrt() } else { dv / a + a / j }
}

/// Distance used by a velocity change from `va` to `vb` (spec 8.2).
///
/// ```
/// let d = scallop_machine::time::change_distance(0.0, 40.0, 2500.0, 5000.0);
/// assert!((d - 3.577709).abs() < 1e-6);
/// ```
#[must_use]
pub fn change_distance(va: f64, vb: f64, a: f64, j: f64) -> f64 {
    (va + vb) / 2.0 * t_acc(vb - va, a, j)
}

/// The velocity `vb >= va` reachable within `s` (capped by `limits.v`), by bisection.
fn reach(va: f64, s: f64, limits: &Limits) -> f64 {
    if va >= limits.v || change_distance(va, limits.v, limits.a, limits.j) <= s {
        return limits.v.max(va);
    }
    let (mut lo, mut hi) = (va, limits.v);
    for _ in 0..tol::TIME_BISECTION_ITERATIONS {
        let mid = 0.5 * (lo + hi);
        if change_distance(va, mid, limits.a, limits.j) <= s { lo = mid } else { hi = mid }
    }
    lo
}

/// Time and peak velocity of a block of length `s` entered at `v0` and left at `v1`
/// (spec 8.5): cruise at `V` if there is room, else the peak solving
/// `d(v0, vp) + d(vp, v1) = s`.
///
/// ```
/// use scallop_machine::time::{block_time, Limits};
/// let (t, peak) = block_time(0.0, 0.0, 100.0, &Limits { v: 40.0, a: 2500.0, j: 5000.0 });
/// assert!((t - 2.678885).abs() < 1e-6 && peak == 40.0);
/// ```
#[must_use]
pub fn block_time(v0: f64, v1: f64, s: f64, limits: &Limits) -> (f64, f64) {
    let Limits { v, a, j } = *limits;
    let used = |vp: f64| change_distance(v0, vp, a, j) + change_distance(vp, v1, a, j);
    let vp = if used(v) <= s {
        v
    } else {
        let (mut lo, mut hi) = (v0.max(v1), v);
        for _ in 0..tol::TIME_BISECTION_ITERATIONS {
            let mid = 0.5 * (lo + hi);
            if used(mid) <= s { lo = mid } else { hi = mid }
        }
        lo
    };
    let cruise = if vp > 0.0 { (s - used(vp)).max(0.0) / vp } else { 0.0 };
    (t_acc(vp - v0, a, j) + t_acc(vp - v1, a, j) + cruise, vp)
}

/// Which stop-to-stop regime a block falls in (spec 8.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopCase {
    /// V and A reached.
    VelocityAndAcceleration,
    /// V reached, A not.
    VelocityOnly,
    /// Neither reached.
    Neither,
    /// A reached, V not.
    AccelerationOnly,
}

/// Stop-to-stop time model (spec 8.6, `finishing.md` 7).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TimeModel {
    /// The four cases (default).
    #[default]
    SCurve,
    /// \[COMPAT\] the thesis's three cases chosen by the smallest of `t_A`, `t_V`, `t_l`:
    /// labels case 4 as case 1 (wrong when A is reached but V is not).
    Thesis,
}

/// Closed-form stop-to-stop time of a block of length `length` (spec 8.6): time, case
/// and peak velocity.
///
/// ```
/// use scallop_machine::time::{stop_to_stop, Limits, StopCase, TimeModel};
/// let l = Limits { v: 500.0, a: 2100.0, j: 50000.0 }; // UCP 710 Z rapid
/// let (t, case, peak) = stop_to_stop(100.0, &l, TimeModel::SCurve);
/// assert_eq!(case, StopCase::AccelerationOnly);
/// assert!((t - 0.480452).abs() < 1e-6 && (peak - 416.275).abs() < 1e-3);
/// ```
#[must_use]
pub fn stop_to_stop(length: f64, limits: &Limits, model: TimeModel) -> (f64, StopCase, f64) {
    let Limits { v, a, j } = *limits;
    let l = length / 2.0;
    let (t_a, t_v, t_l) = (a / j, (v / j).sqrt(), (l / j).cbrt());
    let case1 = || (2.0 * l / v + a / j + v / a, StopCase::VelocityAndAcceleration, v);
    let case2 = || (2.0 * l / v + 2.0 * (v / j).sqrt(), StopCase::VelocityOnly, v);
    let case3 = || (4.0 * t_l, StopCase::Neither, j * t_l * t_l);
    let case4 = || {
        let vp = (-a * a / j + (a.powi(4) / (j * j) + 8.0 * l * a).sqrt()) / 2.0;
        (2.0 * (vp / a + a / j), StopCase::AccelerationOnly, vp)
    };
    match model {
        TimeModel::Thesis => {
            if t_l <= t_a && t_l <= t_v {
                case3()
            } else if t_v <= t_a {
                case2()
            } else {
                case1()
            }
        }
        TimeModel::SCurve => {
            if v * j <= a * a {
                if t_l >= t_v { case2() } else { case3() }
            } else if length >= v * (v / a + a / j) {
                case1()
            } else if length > 2.0 * a.powi(3) / (j * j) {
                case4()
            } else {
                case3()
            }
        }
    }
}

/// Feed profile of one block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockProfile {
    /// Equivalent length `s_k = F_k T_k` (mm).
    pub length: f64,
    /// Entry, peak and exit velocities along `s` (mm/s).
    pub entry: f64,
    /// Peak velocity (mm/s).
    pub peak: f64,
    /// Exit velocity (mm/s).
    pub exit: f64,
    /// Block time (s), at least `nc.min_block_time`.
    pub time: f64,
}

/// Result of [`path_time`].
#[derive(Clone, Debug, PartialEq)]
pub struct TimeReport {
    /// Total time (s).
    pub total: f64,
    /// One profile per block.
    pub blocks: Vec<BlockProfile>,
    /// Peak speed of each axis (mm/s or rad/s), joint order.
    pub axis_peak_speed: Joints,
    /// Junction velocity caps (mm/s) between consecutive blocks (spec 8.3).
    pub junction_caps: Vec<f64>,
    /// Time lost to each axis's limits (s), joint order: `total` minus the total with that
    /// axis's velocity, acceleration and jerk limits lifted (all other limits kept). A
    /// marginal attribution: the sum can differ from the total loss when two axes bind
    /// on the same block.
    pub axis_time_lost: [f64; 5],
    /// Time at the commanded feed alone (s): `sum s_k / F_k`, the floor no machine beats.
    pub feed_time: f64,
}

/// Time of a joint-space polyline `joints` fed at `feeds[k]` (mm/min, block `k` from
/// `joints[k]` to `joints[k + 1]`), starting and ending at rest: per-block path limits
/// from the axis limits (8.1), junction caps (8.3), backward and forward look-ahead
/// (8.4), block times (8.5).
///
/// ```
/// use scallop_machine::{Kinematics, Machine, Joints, time::path_time};
/// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
/// let q = [Joints::new(0.0, 0.0, 50.0, 0.0, 0.0), Joints::new(100.0, 0.0, 50.0, 0.0, 0.0)];
/// let r = path_time(&k, &q, &[2400.0]).unwrap();
/// assert!((r.total - 2.678885).abs() < 1e-6);
/// ```
///
/// # Errors
/// [`MachineError::BadInput`] when `feeds` does not have one entry per block or a feed
/// is not positive.
pub fn path_time(kin: &Kinematics, joints: &[Joints], feeds: &[f64]) -> Result<TimeReport, MachineError> {
    let mut report = profile(kin, joints, feeds, 0)?;
    for i in 0..kin.machine().axes().len().min(5) {
        let relaxed = profile(kin, joints, feeds, 1 << i)?;
        report.axis_time_lost[i] = (report.total - relaxed.total).max(0.0);
    }
    Ok(report)
}

/// The look-ahead profile of [`path_time`] with the velocity, acceleration and jerk
/// limits of the axes `lifted` (joint order) lifted, every other limit kept: the time
/// those axes cost together is [`path_time`]'s total less this one's (per block, the
/// blocks' times). `axis_time_lost` is left at zero.
///
/// ```
/// use scallop_machine::{Kinematics, Machine, Joints, time::{path_time, path_time_lifting}};
/// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
/// let q = [Joints::new(0.0, 0.0, 50.0, 0.0, 0.0), Joints::new(100.0, 0.0, 50.0, 0.0, 0.0)];
/// let (all, free) = (path_time(&k, &q, &[2400.0]).unwrap(), path_time_lifting(&k, &q, &[2400.0], &[0]).unwrap());
/// assert!(free.total < all.total && (free.total - 2.5).abs() < 1e-3);
/// ```
///
/// # Errors
/// As [`path_time`].
pub fn path_time_lifting(
    kin: &Kinematics,
    joints: &[Joints],
    feeds: &[f64],
    lifted: &[usize],
) -> Result<TimeReport, MachineError> {
    profile(kin, joints, feeds, lifted.iter().filter(|&&i| i < 32).fold(0, |m, &i| m | (1 << i)))
}

/// The look-ahead profile of [`path_time`]; `relax` (bit `i` for axis `i`) lifts axes' dynamic limits
/// (velocity, acceleration, jerk) to measure the time that axis costs.
fn profile(kin: &Kinematics, joints: &[Joints], feeds: &[f64], relax: u32) -> Result<TimeReport, MachineError> {
    let n = joints.len().saturating_sub(1);
    if feeds.len() != n || feeds.iter().any(|f| !(f.is_finite() && *f > 0.0)) {
        return Err(MachineError::BadInput {
            place: "time::path_time".into(),
            problem: format!("{} blocks but {} feeds (all must be positive)", n, feeds.len()),
            fix: "give one positive feed (mm/min) per block".into(),
        });
    }
    let machine = kin.machine();
    let poses: Vec<_> = joints.iter().map(|q| kin.fk(q)).collect();
    let mut s = Vec::with_capacity(n);
    let mut e: Vec<Joints> = Vec::with_capacity(n);
    let mut limits = Vec::with_capacity(n);
    for k in 0..n {
        let f = feeds[k] / 60.0;
        let length = (poses[k + 1].tip - poses[k].tip).norm();
        let (oa, ob) = (poses[k].axis, poses[k + 1].axis);
        let dphi = oa.cross(&ob).norm().atan2(oa.dot(&ob));
        let axis_time = (0..machine.axes().len().min(5))
            .map(|i| (joints[k + 1][i] - joints[k][i]).abs() / dynamics(machine, i, relax).0)
            .fold(0.0, f64::max);
        let t_vel = (length / f).max(machine.nc().r_ref * dphi / f).max(axis_time);
        let sk = f * t_vel;
        let ek = if sk > 0.0 { (joints[k + 1] - joints[k]) / sk } else { Joints::zeros() };
        let (mut a, mut j) = (f64::INFINITY, f64::INFINITY);
        for i in 0..machine.axes().len().min(5) {
            if ek[i].abs() > tol::AXIS_DIRECTION_ZERO {
                let (_, amax, jmax) = dynamics(machine, i, relax);
                a = a.min(amax / ek[i].abs());
                j = j.min(jmax / ek[i].abs());
            }
        }
        s.push(sk);
        e.push(ek);
        limits.push(Limits { v: f, a, j });
    }
    // Junction caps between block k-1 and k (index k = 1..n-1).
    let mut caps = vec![0.0; n + 1];
    for (k, cap) in caps.iter_mut().enumerate().take(n).skip(1) {
        *cap = junction_cap(kin, &poses, &e, &s, feeds, k, relax);
    }
    // Look-ahead.
    let mut v = caps.clone();
    v[0] = 0.0;
    v[n] = 0.0;
    for k in (0..n).rev() {
        v[k] = v[k].min(reach(v[k + 1], s[k], &limits[k]));
    }
    for k in 0..n {
        v[k + 1] = v[k + 1].min(reach(v[k], s[k], &limits[k]));
    }
    let mut blocks = Vec::with_capacity(n);
    let mut total = 0.0;
    let mut axis_peak_speed = Joints::zeros();
    for k in 0..n {
        let (t, peak) = block_time(v[k], v[k + 1], s[k], &limits[k]);
        let t = t.max(machine.nc().min_block_time);
        total += t;
        for i in 0..5 {
            axis_peak_speed[i] = axis_peak_speed[i].max(peak * e[k][i].abs());
        }
        blocks.push(BlockProfile { length: s[k], entry: v[k], peak, exit: v[k + 1], time: t });
    }
    let feed_time = (0..n).map(|k| s[k] / (feeds[k] / 60.0)).sum();
    Ok(TimeReport {
        total,
        blocks,
        axis_peak_speed,
        junction_caps: caps[1..n.max(1)].to_vec(),
        axis_time_lost: [0.0; 5],
        feed_time,
    })
}

/// What sets a feed block's time at its velocity limits alone (before acceleration and
/// jerk): the programmed tip feed, the orientation feed (`nc.r_ref` times the tool axis's
/// turn, at the same feed), or one axis's velocity (joint order).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VelocityBound {
    /// The tip's programmed feed.
    Feed,
    /// The tool axis's turn at `nc.r_ref` from the tip, at the programmed feed.
    Orientation,
    /// The velocity limit of axis `i`.
    Axis(usize),
}

/// The velocity-limited time of the feed block `qa -> qb` at `feed` (mm/min), as
/// [`path_time`] takes it (spec 8.1): `(t_feed, t_vel, bound)` with `t_feed` the tip's
/// length over the feed, `t_vel >= t_feed` the largest of that, the orientation feed's
/// time and every axis's travel over its velocity limit, and the term that gives it.
/// [`path_time`]'s block time is at least `t_vel`; what it takes beyond is the
/// acceleration and jerk limits' (the look-ahead, the junction caps).
///
/// ```
/// use scallop_machine::{Kinematics, Machine, Joints, time::{velocity_bound, VelocityBound}};
/// let k = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 0.0);
/// let (a, b) = (Joints::new(0.0, 0.0, 50.0, 0.0, 0.0), Joints::new(10.0, 0.0, 50.0, 0.0, 0.0));
/// let (t_feed, t_vel, bound) = velocity_bound(&k, &a, &b, 2400.0);
/// assert!((t_feed - 0.25).abs() < 1e-9 && t_vel == t_feed && bound == VelocityBound::Feed);
/// ```
#[must_use]
pub fn velocity_bound(kin: &Kinematics, qa: &Joints, qb: &Joints, feed: f64) -> (f64, f64, VelocityBound) {
    let machine = kin.machine();
    let f = feed / 60.0;
    let (pa, pb) = (kin.fk(qa), kin.fk(qb));
    let t_feed = (pb.tip - pa.tip).norm() / f;
    let dphi = pa.axis.cross(&pb.axis).norm().atan2(pa.axis.dot(&pb.axis));
    let mut best = (t_feed, VelocityBound::Feed);
    let t_orient = machine.nc().r_ref * dphi / f;
    if t_orient > best.0 {
        best = (t_orient, VelocityBound::Orientation);
    }
    for i in 0..machine.axes().len().min(5) {
        let t = (qb[i] - qa[i]).abs() / dynamics(machine, i, 0).0;
        if t > best.0 {
            best = (t, VelocityBound::Axis(i));
        }
    }
    (t_feed, best.0, best.1)
}

/// The axis whose stop-to-stop profile sets the time of the rapid `qa -> qb`
/// ([`rapid_time`]); `None` when no axis moves.
#[must_use]
pub fn rapid_bound(machine: &crate::Machine, qa: &Joints, qb: &Joints) -> Option<usize> {
    let mut best: Option<(f64, usize)> = None;
    for (i, axis) in machine.axes().iter().enumerate() {
        let d = (qb[i] - qa[i]).abs();
        if d > 0.0 {
            let l = Limits { v: axis.dynamics.rapid, a: axis.dynamics.amax, j: axis.dynamics.jmax };
            let t = stop_to_stop(d, &l, TimeModel::SCurve).0;
            if best.is_none_or(|(b, _)| t > b) {
                best = Some((t, i));
            }
        }
    }
    best.map(|(_, i)| i)
}

/// Velocity, acceleration and jerk limits of axis `i`, scaled by
/// [`tol::RELAXED_AXIS_FACTOR`] when `relax` has its bit (finite, so the S-curve formulas
/// never see `inf / inf`).
fn dynamics(machine: &crate::Machine, i: usize, relax: u32) -> (f64, f64, f64) {
    let d = &machine.axes()[i].dynamics;
    let f = if relax & (1 << i) != 0 { tol::RELAXED_AXIS_FACTOR } else { 1.0 };
    (d.vmax * f, d.amax * f, d.jmax * f)
}

/// Junction velocity cap between blocks `k - 1` and `k` (spec 8.3).
fn junction_cap(
    kin: &Kinematics,
    poses: &[crate::chain::Pose],
    e: &[Joints],
    s: &[f64],
    feeds: &[f64],
    k: usize,
    relax: u32,
) -> f64 {
    let machine = kin.machine();
    let feed_cap = feeds[k - 1].min(feeds[k]) / 60.0;
    if machine.nc().corner_tolerance <= 0.0 {
        return 0.0;
    }
    let d1 = poses[k].tip - poses[k - 1].tip;
    let d2 = poses[k + 1].tip - poses[k].tip;
    let theta = if d1.norm() > 0.0 && d2.norm() > 0.0 { d1.cross(&d2).norm().atan2(d1.dot(&d2)) } else { 0.0 };
    let de = e[k] - e[k - 1];
    let mean = (s[k - 1] + s[k]) / 2.0;
    let translating = d1.norm() > 0.0 && d2.norm() > 0.0;
    if translating && theta <= tol::SMOOTH_JUNCTION {
        // Smooth regime: v^2 de/s <= amax, v^3 d2e/s^2 <= jmax.
        // Second difference of e along the path: centred on the junction when both
        // neighbours exist, one-sided at the ends, the jump itself for two blocks.
        let d2e = if k >= 2 && k + 1 < e.len() {
            ((e[k + 1] - e[k]) - (e[k - 1] - e[k - 2])) / 2.0
        } else if k + 1 < e.len() {
            (e[k + 1] - e[k]) - de
        } else if k >= 2 {
            de - (e[k - 1] - e[k - 2])
        } else {
            de
        };
        let mut cap = feed_cap;
        for i in 0..machine.axes().len().min(5) {
            let (_, amax, jmax) = dynamics(machine, i, relax);
            if de[i].abs() > tol::AXIS_DIRECTION_ZERO {
                cap = cap.min((amax * mean / de[i].abs()).sqrt());
            }
            if d2e[i].abs() > tol::AXIS_DIRECTION_ZERO {
                cap = cap.min((jmax * mean * mean / d2e[i].abs()).cbrt());
            }
        }
        cap
    } else {
        // Corner regime: blend of length s_b within the controller's tolerance.
        let blend = if translating {
            (4.0 * machine.nc().corner_tolerance / (theta / 2.0).sin()).min(s[k - 1] / 2.0).min(s[k] / 2.0)
        } else {
            s[k - 1].min(s[k]) / 2.0
        };
        let fits = |v: f64| {
            (0..machine.axes().len().min(5)).all(|i| {
                let (_, amax, jmax) = dynamics(machine, i, relax);
                let dv = v * de[i].abs();
                v * t_acc(dv, amax, jmax) <= blend
            })
        };
        if fits(feed_cap) {
            return feed_cap;
        }
        let (mut lo, mut hi) = (0.0, feed_cap);
        for _ in 0..tol::TIME_BISECTION_ITERATIONS {
            let mid = 0.5 * (lo + hi);
            if fits(mid) { lo = mid } else { hi = mid }
        }
        lo
    }
}

/// Time of a rapid move `qa -> qb` with independent axes: the slowest axis's
/// stop-to-stop profile at its rapid velocity (spec 8.4).
///
/// ```
/// use scallop_machine::{Machine, Joints, time::rapid_time};
/// let m = Machine::builtin("ucp710").unwrap();
/// let t = rapid_time(&m, &Joints::zeros(), &Joints::new(100.0, 0.0, 0.0, 0.0, 0.0));
/// assert!((t - 0.861774).abs() < 1e-6);
/// ```
#[must_use]
pub fn rapid_time(machine: &crate::Machine, qa: &Joints, qb: &Joints) -> f64 {
    machine
        .axes()
        .iter()
        .enumerate()
        .map(|(i, axis)| {
            let d = (qb[i] - qa[i]).abs();
            if d > 0.0 {
                let l = Limits { v: axis.dynamics.rapid, a: axis.dynamics.amax, j: axis.dynamics.jmax };
                stop_to_stop(d, &l, TimeModel::SCurve).0
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max)
}
