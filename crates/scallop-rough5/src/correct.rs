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
//! as before. Steps 2 and 3 of the thesis (upper limit
//! curves, axis translation) and the rebuilding loop are not implemented.

use rayon::prelude::*;
use scallop_geom::Vec3;

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
