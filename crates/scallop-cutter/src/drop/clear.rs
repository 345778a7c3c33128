//! A whole-triangle rejection for the ball: below its centre's height, the
//! ball with its tip at `t` holds exactly the points closer than R to its
//! centre `O = (c, t + R)`, and above that height the cylinder of radius R
//! (the cutter continues upwards). A triangle wholly at or below the centre's
//! height and at least R from `O` therefore meets no point of the cutter: no
//! contact of it can hold the tip above `t` (raising the cutter by `s` moves
//! `O` by `s`, so a triangle `R + g` away gives contacts at most `t - g`). At
//! the drop height every triangle is at least R from the centre and only those
//! that touch are at R, so the test rejects nearly every candidate that the
//! bounds by height and distance keep, for about the cost of one edge test.
//!
//! The squared distance of a point to a triangle is Ericson's closest-point
//! region test ("Real-Time Collision Detection", 2005, section 5.1.5); the
//! rejection keeps the prune slack of the squared distances, and where the
//! face region's barycentric coordinates come out of the triangle (a sliver,
//! rounding) it rejects nothing, so it is conservative: the heights do not
//! change.

use scallop_geom::{Point3, tol};

/// Whether the ball of radius `radius` with its tip at height `tip` above the
/// XY point (`cx`, `cy`) certainly leaves the triangle `corners` untouched
/// (see the module's documentation). False on NaN.
#[inline]
pub(super) fn ball_clear_of(corners: &[Point3; 3], radius: f64, cx: f64, cy: f64, tip: f64) -> bool {
    ball_clearance(corners, radius, cx, cy, tip).is_some()
}

/// [`ball_clear_of`] with a margin: `Some(g)` when the ball is clear, where
/// every centre `O'` within `g` (3D) of this one, `O = (cx, cy, tip + R)`,
/// with the triangle still at or below its height, passes the same test (the
/// distance to the triangle is 1-Lipschitz in the centre: `|O' T| >= |O T| -
/// |O' O|`, and `g` leaves room for the slack of `O'`, whose distance to the
/// first corner is at most `|a O| + |O T|`); `g` is 0 when there is no such
/// room. `None` when not clear.
#[inline]
pub(super) fn ball_clearance(corners: &[Point3; 3], radius: f64, cx: f64, cy: f64, tip: f64) -> Option<f64> {
    let oz = tip + radius;
    let [a, b, c] = corners;
    let top = a.z.max(b.z).max(c.z);
    if top > oz || top.is_nan() || oz.is_nan() {
        return None; // a point above the centre's height may be in the cylinder
    }
    let o = [cx, cy, oz];
    let d2 = distance2(o, [a.x, a.y, a.z], [b.x, b.y, b.z], [c.x, c.y, c.z])?;
    let (ax, ay, az) = (a.x - cx, a.y - cy, a.z - oz);
    let r2 = radius * radius;
    let a2 = ax * ax + ay * ay + az * az;
    let limit = r2 + tol::REL_PRUNE_SLACK * (r2 + a2);
    if d2.partial_cmp(&limit) != Some(std::cmp::Ordering::Greater) {
        return None; // within reach, or NaN
    }
    let d = d2.sqrt();
    let far = a2.sqrt() + d;
    Some((d - (r2 + tol::REL_PRUNE_SLACK * (r2 + far * far)).sqrt()).max(0.0))
}

fn sub(p: [f64; 3], q: [f64; 3]) -> [f64; 3] {
    [p[0] - q[0], p[1] - q[1], p[2] - q[2]]
}

fn dot(p: [f64; 3], q: [f64; 3]) -> f64 {
    p[0] * q[0] + p[1] * q[1] + p[2] * q[2]
}

/// `|v - s p - t q|^2`.
fn norm2_off(v: [f64; 3], s: f64, p: [f64; 3], t: f64, q: [f64; 3]) -> f64 {
    let w = [v[0] - s * p[0] - t * q[0], v[1] - s * p[1] - t * q[1], v[2] - s * p[2] - t * q[2]];
    dot(w, w)
}

/// Squared distance from `p` to the triangle `a b c` by Ericson's Voronoi
/// regions; `None` where the face region's barycentric coordinates fall out of
/// [0, 1] beyond rounding (degenerate triangles) or a value is not finite.
#[inline]
fn distance2(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Option<f64> {
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return Some(dot(ap, ap)); // corner a
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return Some(dot(bp, bp)); // corner b
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return finite(norm2_off(ap, v, ab, 0.0, ac)); // edge ab
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return Some(dot(cp, cp)); // corner c
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return finite(norm2_off(ap, 0.0, ab, w, ac)); // edge ac
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return finite(norm2_off(bp, w, sub(c, b), 0.0, ab)); // edge bc
    }
    let sum = va + vb + vc;
    let (v, w) = (vb / sum, vc / sum);
    let margin = tol::REL_ROUNDING;
    if !(v >= -margin && w >= -margin && v + w <= 1.0 + margin) {
        return None;
    }
    finite(norm2_off(ap, v, ab, w, ac)) // face
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CutterShape;
    use crate::drop::{ALL_FEATURES, ClPoint, drop_features};
    use crate::shape::Profile;
    use scallop_geom::rng::SplitMix64;
    use scallop_geom::{Point2, Vec3};

    /// A random triangle and its upward normal (`None` when degenerate), a centre
    /// near it, and the ball's own contact with the triangle there.
    fn random_case(profile: &Profile, rng: &mut SplitMix64) -> Option<([Point3; 3], Vec3, Point2, ClPoint)> {
        let mut q = || Point3::new(rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5), rng.uniform(-1.0, 1.0));
        let t = [q(), q(), q()];
        let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
        if n.norm() == 0.0 {
            return None;
        }
        let n: Vec3 = if n.z < 0.0 { -n / n.norm() } else { n / n.norm() };
        let c = Point2::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
        let mut own = ClPoint::floor(c, -100.0);
        drop_features(profile, &t, &n, 0, ALL_FEATURES, &mut own);
        Some((t, n, c, own))
    }

    /// A triangle the ball is clear of at a tip height never gives a contact
    /// above that height: random triangles and points, tips just below, at and
    /// above the triangle's own contact.
    #[test]
    fn a_clear_triangle_never_raises_the_ball() {
        let profile = Profile::new(&CutterShape::Ball { radius: 1.0 });
        let mut rng = SplitMix64::new(20_261_206);
        let mut cleared = 0;
        for _ in 0..20_000 {
            let Some((t, _, c, own)) = random_case(&profile, &mut rng) else { continue };
            for offset in [-0.3, -1e-6, -1e-12, 0.0, 1e-12, 1e-6, 0.2, 1.5] {
                let tip = own.tip.z + offset;
                if ball_clear_of(&t, 1.0, c.x, c.y, tip) {
                    cleared += 1;
                    assert!(own.tip.z <= tip, "{t:?} at {c:?}: contact {} above the clear tip {tip}", own.tip.z);
                }
            }
        }
        assert!(cleared > 10_000, "the test clears triangles ({cleared})");
    }

    /// Every centre within the margin of [`ball_clearance`] (the triangle still
    /// at or below it) passes the test too, and the triangle does not raise
    /// the ball there: random triangles, centres, and moves in every direction
    /// up to just under the margin.
    #[test]
    fn a_centre_within_the_clearance_is_clear() {
        let profile = Profile::new(&CutterShape::Ball { radius: 1.0 });
        let mut rng = SplitMix64::new(20_261_207);
        let mut moved = 0;
        for _ in 0..20_000 {
            let Some((t, n, c, own)) = random_case(&profile, &mut rng) else { continue };
            let tip = own.tip.z + rng.uniform(-0.2, 0.5);
            let Some(g) = ball_clearance(&t, 1.0, c.x, c.y, tip) else { continue };
            for u in [0.3, 0.9, 0.999, 1.0 - 1e-9] {
                let (theta, phi) = (rng.uniform(0.0, 6.3), rng.uniform(-1.5, 1.5));
                let d = [phi.cos() * theta.cos(), phi.cos() * theta.sin(), phi.sin()].map(|v| v * u * g);
                let (c2, tip2) = (Point2::new(c.x + d[0], c.y + d[1]), tip + d[2]);
                if t.iter().any(|p| p.z > tip2 + 1.0) {
                    continue; // above the centre: the cylinder, not the ball
                }
                moved += 1;
                assert!(ball_clear_of(&t, 1.0, c2.x, c2.y, tip2), "{t:?}: {c2:?} at {tip2}, {} of the margin {g}", u);
                let mut there = ClPoint::floor(c2, -100.0);
                drop_features(&profile, &t, &n, 0, ALL_FEATURES, &mut there);
                assert!(there.tip.z <= tip2, "{t:?}: contact {} above {tip2}", there.tip.z);
            }
        }
        assert!(moved > 10_000, "the test moves clear centres ({moved})");
    }

    /// The region test against dense sampling of the triangle: never above
    /// the sampled minimum, and close to it.
    #[test]
    fn distance_matches_dense_sampling() {
        let mut rng = SplitMix64::new(7);
        let mut r = || rng.uniform(-2.0, 2.0);
        for _ in 0..300 {
            let (a, b, c, p) = ([r(), r(), r()], [r(), r(), r()], [r(), r(), r()], [r(), r(), r()]);
            let Some(d2) = distance2(p, a, b, c) else { continue };
            let n = 300;
            let mut best = f64::INFINITY;
            for i in 0..=n {
                for j in 0..=n - i {
                    let (s, t) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
                    let q = [
                        a[0] + s * (b[0] - a[0]) + t * (c[0] - a[0]),
                        a[1] + s * (b[1] - a[1]) + t * (c[1] - a[1]),
                        a[2] + s * (b[2] - a[2]) + t * (c[2] - a[2]),
                    ];
                    let w = sub(p, q);
                    best = best.min(dot(w, w));
                }
            }
            assert!(d2 <= best + 1e-12, "{d2} > sampled {best}");
            assert!(best.sqrt() - d2.sqrt() <= 0.03, "{d2} far below sampled {best}");
        }
    }
}
