//! Where a cutter moving along a segment stops reaching the part of one
//! triangle that its full-width body meets: a guess for the end of a
//! triangle's interval on the segment (the waterline's brackets).
//!
//! With its tip at z the cutter holds every point within R of its axis above
//! `z + h(R)` (the profile's top, above which it is a cylinder of radius R).
//! The triangle's part above that height, `P = T ∩ {z > z + h(R)}` (a convex
//! polygon of at most four corners), therefore lifts the cutter above z
//! wherever the axis is closer than R to P's XY projection: the set of such
//! axis points is `P ⊕ disk(R)`, the union of the disks around P's corners
//! and the strips along its edges. The last parameter of the segment in that
//! union is where the triangle's contact drops abruptly from above z to the
//! floor when nothing lower on the triangle holds the cutter further; there a
//! root finder on the height sees a jump and can only bisect.

use scallop_geom::{Point2, Point3};

/// The largest s in [0, 1] with `a + s (b - a)` within `radius` (XY) of the
/// part of the triangle `corners` above `top`; `None` if there is none (the
/// triangle does not rise above `top`, or the segment stays away from it).
/// A guess only: callers classify the points near it by the exact height.
pub(super) fn rim_exit(corners: &[Point3; 3], radius: f64, top: f64, a: Point2, b: Point2) -> Option<f64> {
    // P's corners (XY): the corners above `top` and the edges' crossings of it.
    let mut poly = [Point2::origin(); 4];
    let mut n = 0;
    for k in 0..3 {
        let (p, q) = (&corners[k], &corners[(k + 1) % 3]);
        let (p_up, q_up) = (p.z > top, q.z > top);
        if p_up {
            poly[n] = Point2::new(p.x, p.y);
            n += 1;
        }
        if p_up != q_up {
            let s = (top - p.z) / (q.z - p.z);
            poly[n] = Point2::new(p.x + s * (q.x - p.x), p.y + s * (q.y - p.y));
            n += 1;
        }
    }
    let d = b - a;
    let dd = d.x * d.x + d.y * d.y;
    if n == 0 || dd.is_nan() || dd <= 0.0 {
        return None;
    }
    let r2 = radius * radius;
    let mut best: Option<f64> = None;
    let mut keep = |t: f64| {
        if t.is_finite() {
            best = Some(best.map_or(t, |b: f64| b.max(t)));
        }
    };
    for i in 0..n {
        let (u, v) = (poly[i], poly[(i + 1) % n]);
        // The disk around u: the larger root of |a + t d - u|^2 = R^2.
        let w = a - u;
        let wd = w.x * d.x + w.y * d.y;
        let disc = wd * wd - dd * (w.x * w.x + w.y * w.y - r2);
        if disc >= 0.0 {
            keep((-wd + disc.sqrt()) / dd);
        }
        // The strip along u -> v: 0 <= (p - u).e <= |e|^2 and |(p - u) x e| <= R |e|,
        // clipped in t (Liang and Barsky).
        let e = v - u;
        let ee = e.x * e.x + e.y * e.y;
        if n == 1 || ee.is_nan() || ee <= 0.0 {
            continue;
        }
        let le = ee.sqrt();
        let (along0, along1) = (w.x * e.x + w.y * e.y, d.x * e.x + d.y * e.y);
        let (across0, across1) = (w.x * e.y - w.y * e.x, d.x * e.y - d.y * e.x);
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for (c0, c1, min, max) in [(along0, along1, 0.0, ee), (across0, across1, -radius * le, radius * le)] {
            if c1 == 0.0 {
                if c0 < min || c0 > max {
                    lo = f64::INFINITY;
                }
            } else {
                let (t0, t1) = ((min - c0) / c1, (max - c0) / c1);
                lo = lo.max(t0.min(t1));
                hi = hi.min(t0.max(t1));
            }
        }
        if lo <= hi {
            keep(hi);
        }
    }
    best.filter(|&t| t >= 0.0).map(|t| t.min(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CutterShape;
    use crate::drop::{ClPoint, drop_triangle};
    use crate::shape::{Cutter, Profile};
    use scallop_geom::rng::SplitMix64;

    /// XY distance from `p` to the part of the triangle above `top`, by dense
    /// sampling of the triangle (independent of the clipping above): never
    /// below the true distance.
    fn sampled_distance(t: &[Point3; 3], top: f64, p: Point2) -> f64 {
        let n = 200;
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=n - i {
                let (s, u) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
                let q = t[0] + (t[1] - t[0]) * s + (t[2] - t[0]) * u;
                if q.z > top {
                    best = best.min(((q.x - p.x).powi(2) + (q.y - p.y).powi(2)).sqrt());
                }
            }
        }
        best
    }

    /// The guess is the segment's last point within R of the triangle's part
    /// above the profile's top: just before it the cutter's body holds that
    /// part (the triangle lifts the cutter above z), just after it nothing of
    /// that part is within R; `None` only where no point of the segment is.
    #[test]
    fn the_rim_exit_is_the_last_point_within_reach_of_the_part_above_the_profile() {
        let mut rng = SplitMix64::new(20_261_206);
        let shapes = [
            CutterShape::Ball { radius: 1.0 },
            CutterShape::Cone { radius: 1.0, half_angle: 0.6 },
            CutterShape::Flat { radius: 1.0 },
            CutterShape::Bull { radius: 1.0, corner: 0.3 },
        ];
        let (mut lifted, mut none) = (0, 0);
        for k in 0..3000 {
            let shape = shapes[k % shapes.len()];
            let profile = Profile::new(&shape);
            let cutter = Cutter::new(shape, 20.0).expect("cutter");
            let mut q = || Point3::new(rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0), rng.uniform(-1.0, 3.0));
            let t = [q(), q(), q()];
            let (a, far) = (Point2::new(t[0].x + 0.3, t[0].y - 0.2), q());
            let b = Point2::new(far.x * 2.0, far.y * 2.0);
            let z = 0.0;
            let top = z + profile.height(1.0);
            let d = b - a;
            let at = |s: f64| a + d * s;
            if let Some(s) = rim_exit(&t, 1.0, top, a, b) {
                assert!((0.0..=1.0).contains(&s), "{s}");
                let eps = 1e-3 / d.norm();
                if s - eps > 0.0 {
                    // Within R of the part above the profile's top: the cutter is lifted.
                    let before = at(s - eps);
                    let gap = sampled_distance(&t, top, before);
                    assert!(gap < 1.0 + 0.05, "{t:?} {a:?} {b:?}: {gap} from the part at {s}");
                    let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
                    if n.norm() > 1e-6 && gap < 1.0 - 0.05 {
                        let n = if n.z < 0.0 { -n / n.norm() } else { n / n.norm() };
                        let mut cl = ClPoint::floor(before, z - 10.0);
                        drop_triangle(&cutter, &t, &n, 0, &mut cl);
                        assert!(cl.tip.z > z, "{shape:?} {t:?}: not lifted before the exit {s}");
                        lifted += 1;
                    }
                }
                if s + eps < 1.0 {
                    let gap = sampled_distance(&t, top, at(s + eps));
                    assert!(gap > 1.0, "{t:?} {a:?} {b:?}: {gap} from the part after the exit {s}");
                }
            } else {
                none += 1;
                for i in 0..=50 {
                    let gap = sampled_distance(&t, top, at(f64::from(i) / 50.0));
                    assert!(gap > 1.0 - 0.05, "{t:?} {a:?} {b:?}: None, but {gap} from the part");
                }
            }
        }
        assert!(lifted > 300 && none > 100, "both cases are exercised ({lifted}, {none})");
    }
}
