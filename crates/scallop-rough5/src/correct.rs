//! Collision correction, step 1: the planar correction that keeps the pitch
//! angle (Jousselin 2020, Ch. 3 §3, Eq. 3.31, Fig. 3.31; docs/rough5.md,
//! "Collision correction").
//!
//! A synchronised pair whose tool body comes too close to a flank is not
//! dropped at once. Its axis u is turned inside the plane
//! `P_corr = (P_T, X_corr, Y_corr)`, with
//! `X_corr = (T x N) / |T x N|` (T the path tangent, N the level normal) and
//! `Y_corr` the unit projection of u on the plane orthogonal to `X_corr`.
//! Every axis `u(a) = cos a Y_corr + sin a X_corr` has the same projection on
//! the (T, N) plane up to its length, so the pitch angle theta_t (Eq. 3.7) is
//! the same for all of them. The collision-free part of that pencil of axes
//! (the visibility cone of the thesis) is searched outward from the current
//! axis in steps of [`tol::CONE_STEP`] on both sides; the first free axis
//! found is moved back to the cone's limit by bisection, to
//! [`tol::CONE_BISECTION`], so the correction turns the axis as little as it
//! can (the thesis sets u to the nearest limit of the cone). Each tried axis is
//! placed on the level again (the tip moves with the axis) and its body
//! checked, so a corrected pair is collision free by the same test as any
//! other. A pair with no free axis in the plane, or without a tilt point
//! (a level cut with the axis +Z), is left as it was: the planner drops it,
//! as before.
//!
//! Step 2, the spatial correction by the upper levels' limit curves (Ch. 3
//! §3, Fig. 3.32, Eq. 3.32), is [`correct_spatial`] and
//! [`correct_pairs_spatial`]: a colliding pair's axis is turned to pass
//! through a point of a limit curve of a level above, the pitch angle free.
//! Step 3, the axis translation, is in the planner
//! ([`crate::Rough5Settings::translate`]).

use rayon::prelude::*;
use scallop_geom::{Point3, Vec3};
use scallop_mesh::Polyline3;

use crate::collide::BodyCheck;
use crate::place::Placer;
use crate::sync::SyncPoint;
use crate::tol;

/// What the correction did to the pairs of one pass.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CorrectionCount {
    /// Pairs whose tool collided with a flank.
    pub colliding: usize,
    /// Of those, pairs turned in their correction plane to a free axis.
    pub corrected: usize,
    /// Free pairs turned to lean in ahead of a corrected neighbour.
    pub leaned_in: usize,
}

/// The correction plane of a pair: `X_corr`, `Y_corr` and the angle of the
/// pair's axis from `Y_corr` towards `X_corr`; `None` when degenerate.
#[derive(Debug, Clone, Copy)]
struct Plane {
    x: Vec3,
    y: Vec3,
    angle: f64,
}

impl Plane {
    fn of(s: &SyncPoint) -> Option<Plane> {
        let x = s.tangent.cross(&s.normal).try_normalize(tol::ANGLE_EPS)?;
        let y = (s.axis - x * s.axis.dot(&x)).try_normalize(tol::ANGLE_EPS)?;
        Some(Plane { x, y, angle: s.axis.dot(&x).atan2(s.axis.dot(&y)) })
    }

    fn axis(&self, a: f64) -> Vec3 {
        self.y * a.cos() + self.x * a.sin()
    }
}

/// The pair `s` with its axis turned in its correction plane to the nearest
/// axis whose tool, placed on `placer`'s level, clears `body`; `None` when no
/// axis of the plane within [`tol::CONE_HALF_ANGLE`] of the plane's
/// reference direction (and pointing upwards) is free, or the plane is
/// degenerate (the tangent along the normal, or the axis across the plane).
/// Also `None` for a pair without a tilt point (the axis +Z of a level cut
/// untilted): leaning it off the pole would turn the C table of a
/// table-table machine by up to half a turn within one short move.
#[must_use]
pub fn correct_planar(placer: &Placer, body: &BodyCheck, s: &SyncPoint) -> Option<SyncPoint> {
    let plane = Plane::of(s)?;
    free_angle(placer, body, s, &plane).map(|a| with_axis(s, plane.axis(a)))
}

/// The angle of [`correct_planar`]'s axis in `plane`.
fn free_angle(placer: &Placer, body: &BodyCheck, s: &SyncPoint, plane: &Plane) -> Option<f64> {
    s.tilt?;
    let free = |a: f64| {
        let u = plane.axis(a);
        u.z > tol::CONE_MIN_Z && placer.place(&s.path, &u).is_some_and(|p| !body.collides(&p.tip, &p.axis))
    };
    let steps = (tol::CONE_HALF_ANGLE / tol::CONE_STEP).ceil() as usize;
    for k in 1..=2 * steps {
        let side = if k % 2 == 1 { 1.0 } else { -1.0 };
        let a = plane.angle + side * tol::CONE_STEP * k.div_ceil(2) as f64;
        if a.abs() > tol::CONE_HALF_ANGLE || !free(a) {
            continue;
        }
        let (mut blocked, mut clear) = (a - side * tol::CONE_STEP, a);
        while (clear - blocked).abs() > tol::CONE_BISECTION {
            let mid = 0.5 * (blocked + clear);
            if free(mid) {
                clear = mid;
            } else {
                blocked = mid;
            }
        }
        return Some(clear);
    }
    None
}

/// `s` with the unit axis `u`; its tilt point, if any, moved onto the new
/// axis at the same distance from P_T.
fn with_axis(s: &SyncPoint, u: Vec3) -> SyncPoint {
    let tilt = s.tilt.map(|d| s.path + u * (d - s.path).norm());
    SyncPoint { tilt, axis: u, ..*s }
}

/// The pairs of one pass with every colliding pair corrected where its
/// correction plane has a free axis (the others unchanged), and the counts.
///
/// A corrected axis would jump from its free neighbours' axes, and the
/// pairs that the angular-step limit inserts in that jump lean as the
/// neighbours do, into the flank. So the neighbours lean in ahead of the
/// correction: walking away from a corrected pair in both directions, each
/// pair is turned in its own plane to within `max_step` (rad) of the angle
/// before it, towards the side the correction turned (the angles of
/// consecutive pairs are compared as if their planes were one, which they
/// nearly are one CL step apart), until its own angle is within reach. A
/// ramped pair leans away from the flank no less than it did, and the
/// planner still checks every pair it keeps. The result does not depend on
/// the thread count.
#[must_use]
pub fn correct_pairs(
    placer: &Placer,
    body: &BodyCheck,
    pairs: &[SyncPoint],
    max_step: f64,
) -> (Vec<SyncPoint>, CorrectionCount) {
    let found: Vec<(Option<Plane>, bool, Option<f64>)> = pairs
        .par_iter()
        .map(|s| {
            let plane = Plane::of(s);
            let collides = placer.place(&s.path, &s.axis()).is_some_and(|p| body.collides(&p.tip, &p.axis));
            let turned = if collides { plane.and_then(|pl| free_angle(placer, body, s, &pl)) } else { None };
            (plane, collides, turned)
        })
        .collect();
    let count = CorrectionCount {
        colliding: found.iter().filter(|f| f.1).count(),
        corrected: found.iter().filter(|f| f.2.is_some()).count(),
        leaned_in: 0,
    };
    let mut target: Vec<Option<f64>> = found.iter().map(|f| f.2).collect();
    let order: Vec<usize> = (0..pairs.len()).collect();
    ramp(&found, &mut target, order.iter().copied(), max_step);
    ramp(&found, &mut target, order.iter().rev().copied(), max_step);
    let count =
        CorrectionCount { leaned_in: found.iter().zip(&target).filter(|(f, t)| !f.1 && t.is_some()).count(), ..count };
    let out = pairs
        .iter()
        .zip(found.iter().zip(&target))
        .map(|(s, ((plane, _, _), t))| match (plane, t) {
            (Some(pl), Some(a)) => with_axis(s, pl.axis(*a)),
            _ => *s,
        })
        .collect();
    (out, count)
}

/// The point of segment `a`-`b` closest to the ray from `o` along the unit
/// `u` (parameter t >= 0), and its distance to the ray.
fn segment_to_ray(a: &Point3, b: &Point3, o: &Point3, u: &Vec3) -> (Point3, f64) {
    let d = b - a;
    let r = a - o;
    let (aa, bb, dd, ee) = (d.dot(&d), d.dot(u), d.dot(&r), u.dot(&r));
    let denom = aa - bb * bb;
    let mut s = if aa > 0.0 && denom > 1e-12 * aa { ((bb * ee - dd) / denom).clamp(0.0, 1.0) } else { 0.0 };
    let mut t = bb * s + ee;
    if t < 0.0 {
        t = 0.0;
        s = if aa > 0.0 { (-dd / aa).clamp(0.0, 1.0) } else { 0.0 };
    } else if aa > 0.0 {
        // The segment point closest to the ray point found.
        s = ((o + u * t - a).dot(&d) / aa).clamp(0.0, 1.0);
        t = (a + d * s - o).dot(u).max(0.0);
    }
    let q = a + d * s;
    (q, (q - (o + u * t)).norm())
}

/// The point of `line` closest to the ray from `o` along the unit `u`.
fn closest_to_ray(line: &Polyline3, o: &Point3, u: &Vec3) -> Option<Point3> {
    let pts = &line.points;
    let n = pts.len();
    if n == 1 {
        return Some(pts[0]);
    }
    let segments = if line.closed { n } else { n.saturating_sub(1) };
    (0..segments)
        .map(|i| segment_to_ray(&pts[i], &pts[(i + 1) % n], o, u))
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .map(|(q, _)| q)
}

/// The pair `s`, whose tool collides with the flanks, with its axis through
/// P_T and a point of one of the limit curves `upper` of the levels above
/// its tilt curve's (Jousselin 2020, Ch. 3 §3, step 2, Fig. 3.32, Eq. 3.32):
/// on each curve, the point closest to the current axis is a candidate tilt
/// point; the candidate chosen is the one that leans the axis furthest away
/// from the flank. The thesis measures that lean across the feed direction,
/// to the left of T (away from the flank for a pocket kept on the left);
/// here it is measured along the flank normal N_f at the deepest intrusion,
/// made orthogonal to the axis, which holds for either travel direction (for
/// the opposite direction Eq. 3.32 would take the minimum). The new axis's
/// pitch angle theta_t is free:
/// a candidate ahead of or behind the pair changes it.
///
/// The tool along each candidate axis is placed on the level again and
/// checked: the candidate chosen is the one leaning furthest away among
/// those whose tool clears the flanks, or, when none does, among those that
/// reduce the deepest intrusion (step 3 then translates it less). Candidates
/// are above P_T along the level normal and lean at most 60 degrees from +Z
/// ([`tol::CONE_MIN_Z`]). `None` when the pair does not collide, has no tilt
/// point (the axis +Z of a level cut untilted, left alone as by
/// [`correct_planar`]) or no candidate helps.
#[must_use]
pub fn correct_spatial(placer: &Placer, body: &BodyCheck, s: &SyncPoint, upper: &[Polyline3]) -> Option<SyncPoint> {
    s.tilt?;
    let placed = placer.place(&s.path, &s.axis)?;
    let (deficit, normal) = body.intrusion(&placed.tip, &placed.axis)?;
    let across = normal - s.axis * normal.dot(&s.axis);
    let away = match across.try_normalize(tol::ANGLE_EPS) {
        Some(a) => a,
        // The thesis's measure: the left of the feed direction.
        None => s.axis.cross(&s.tangent).try_normalize(tol::ANGLE_EPS)?,
    };
    // (lean away, clears, deficit, axis, tilt point)
    let mut best: Option<(f64, bool, f64, Vec3, Point3)> = None;
    for line in upper {
        let Some(q) = closest_to_ray(line, &s.path, &s.axis) else { continue };
        let Some(v) = (q - s.path).try_normalize(tol::ANGLE_EPS) else { continue };
        if v.z <= tol::CONE_MIN_Z || v.dot(&s.normal) <= 0.0 || (v - s.axis).norm() < tol::ANGLE_EPS {
            continue;
        }
        let Some(p) = placer.place(&s.path, &v) else { continue };
        let found = body.intrusion(&p.tip, &p.axis);
        let (clears, d) = found.map_or((true, 0.0), |(d, _)| (false, d));
        if !clears && d >= deficit {
            continue;
        }
        let lean = v.dot(&away);
        let better = match best {
            None => true,
            Some((l, c, _, _, _)) => (clears && !c) || (clears == c && lean > l),
        };
        if better {
            best = Some((lean, clears, d, v, q));
        }
    }
    best.map(|(_, _, _, v, q)| SyncPoint { tilt: Some(q), axis: v, ..*s })
}

/// The pairs of one pass with every colliding pair corrected by
/// [`correct_spatial`] against the limit curves `upper` of the levels above,
/// and the counts. The neighbours of a corrected pair lean towards its new
/// axis: walking away from it in both directions, a pair more than
/// `max_step` (rad) from the axis before it is turned towards that axis (by
/// [`crate::interpolate_axis`]) to within `max_step` of it, until a pair is
/// within reach (`leaned_in` counts them). Corrected pairs are not turned by
/// the lean-in. The result does not depend on the thread count.
#[must_use]
pub fn correct_pairs_spatial(
    placer: &Placer,
    body: &BodyCheck,
    pairs: &[SyncPoint],
    upper: &[Polyline3],
    max_step: f64,
) -> (Vec<SyncPoint>, CorrectionCount) {
    let found: Vec<(bool, Option<SyncPoint>)> = pairs
        .par_iter()
        .map(|s| {
            let collides = placer.place(&s.path, &s.axis).is_some_and(|p| body.collides(&p.tip, &p.axis));
            (collides, if collides { correct_spatial(placer, body, s, upper) } else { None })
        })
        .collect();
    let mut out: Vec<SyncPoint> = pairs.iter().zip(&found).map(|(s, f)| f.1.unwrap_or(*s)).collect();
    let fixed: Vec<bool> = found.iter().map(|f| f.1.is_some()).collect();
    let mut leaned = vec![false; pairs.len()];
    let n = out.len();
    for forward in [true, false] {
        let mut from_fixed = false;
        for i in 0..n {
            let k = if forward { i } else { n - 1 - i };
            if fixed[k] {
                from_fixed = true;
                continue;
            }
            if !from_fixed || out[k].tilt.is_none() {
                from_fixed = false;
                continue;
            }
            let prev = out[if forward { k - 1 } else { k + 1 }].axis;
            let angle = prev.angle(&out[k].axis);
            if angle <= max_step {
                from_fixed = false;
                continue;
            }
            let axis = crate::sync::interpolate_axis(&prev, &out[k].axis, max_step / angle);
            out[k] = with_axis(&out[k], axis);
            leaned[k] = true;
        }
    }
    let count = CorrectionCount {
        colliding: found.iter().filter(|f| f.0).count(),
        corrected: fixed.iter().filter(|&&f| f).count(),
        leaned_in: leaned.iter().filter(|&&l| l).count(),
    };
    (out, count)
}

/// One sweep of the lean-in of [`correct_pairs`] over the pairs in `order`:
/// a pair (free, or corrected the same way) is turned further to within
/// `max_step` of the one before it when that one was turned more.
fn ramp(
    found: &[(Option<Plane>, bool, Option<f64>)],
    target: &mut [Option<f64>],
    order: impl Iterator<Item = usize>,
    max_step: f64,
) {
    let mut prev: Option<(f64, i8)> = None; // (angle, direction of the turn)
    for k in order {
        let (plane, colliding, corrected) = found[k];
        let Some(plane) = plane.filter(|_| !colliding || corrected.is_some()) else {
            prev = None;
            continue;
        };
        let own = target[k].unwrap_or(plane.angle);
        // Not `signum`, which is 1 for an unturned pair (+0).
        let own_dir: i8 = match own.partial_cmp(&plane.angle) {
            Some(std::cmp::Ordering::Greater) => 1,
            Some(std::cmp::Ordering::Less) => -1,
            _ => 0,
        };
        prev = match prev {
            Some((a, dir)) if own_dir != -dir && f64::from(dir) * (a - f64::from(dir) * max_step - own) > 0.0 => {
                let turned = a - f64::from(dir) * max_step;
                target[k] = Some(turned);
                Some((turned, dir))
            }
            _ if target[k].is_some() => Some((own, own_dir)),
            _ => None,
        };
    }
}
