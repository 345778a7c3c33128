//! Edge contact, in the edge's canonical frame: the tip's XY at the origin,
//! the edge along the x axis at perpendicular distance d, its height
//! `z(x) = z_a + m (x - x_a)`. The cutter meets the vertical plane of the edge
//! in the curve `h(sqrt(x^2 + d^2))` (OpenCAMLib's "dual geometry": an offset
//! ellipse for the bull-nose), so the tip height of a contact at x is
//!
//! ```text
//! f(x) = z(x) - h(rho(x)),   rho(x) = sqrt(x^2 + d^2),   |x| <= x_R = sqrt(R^2 - d^2)
//! ```
//!
//! Every profile h is convex and non-decreasing in rho and rho is convex in x,
//! so f is concave: its maximum over the edge's part inside the disk is the
//! unconstrained maximiser clamped to that interval. For m >= 0 the maximiser
//! solves `h'(rho) x / rho = m` (mirror x for m < 0):
//!
//! ```text
//! flat:  x = x_R if m > 0 (else any; 0)
//! ball:  x = m x_R / sqrt(1 + m^2)
//! cone:  k = m tan(a); x = x_R if k >= 1, else d k / sqrt(1 - k^2)
//! bull:  a polynomial in s = rho - (R - r) with one sign change on the corner,
//!        solved by Newton steps kept inside a shrinking bracket (see below).
//! ```
//!
//! f is flat at its maximum, so a parameter error e moves the height by O(e^2).

use scallop_geom::{Point2, Point3, tol};

use super::{ClPoint, Contact};
use crate::CutterShape;
use crate::shape::Profile;

/// Iteration cap of the bull-nose root finder; the bracket halves at least
/// every other step, so 200 is far beyond what f64 resolution needs.
const MAX_ITERATIONS: usize = 200;

pub(super) fn drop_edge(profile: &Profile, a: &Point3, b: &Point3, triangle: usize, c: Point2, best: &mut ClPoint) {
    let (ex, ey) = (b.x - a.x, b.y - a.y);
    let len2 = ex * ex + ey * ey;
    if len2 == 0.0 {
        return; // vertical edge: its upper corner is the highest contact
    }
    let (px, py) = (a.x - c.x, a.y - c.y);
    if edge_below(profile, [px, py, a.z], [ex, ey, b.z - a.z], len2, best.tip.z) {
        return;
    }
    drop_edge_exact(profile, a, b, triangle, c, best);
}

/// [`drop_edge`] without the bounds of [`edge_below`]: the edge frame and the
/// contact.
fn drop_edge_exact(profile: &Profile, a: &Point3, b: &Point3, triangle: usize, c: Point2, best: &mut ClPoint) {
    let (ex, ey) = (b.x - a.x, b.y - a.y);
    let radius = profile.radius;
    let len2 = ex * ex + ey * ey;
    if len2 == 0.0 {
        return;
    }
    let (px, py) = (a.x - c.x, a.y - c.y);
    let len = len2.sqrt();
    let (ux, uy) = (ex / len, ey / len);
    let xa = px * ux + py * uy;
    let d = (px * uy - py * ux).abs();
    if d > radius {
        return;
    }
    let x_r = (radius * radius - d * d).sqrt();
    let lo = xa.max(-x_r);
    let hi = (xa + len).min(x_r);
    if lo > hi {
        return;
    }
    let m = (b.z - a.z) / len;
    // The edge's height at x, kept between its ends' heights: on a nearly
    // vertical edge (its XY length at the rounding level of `xa`, as a wall's
    // edge whose ends differ by 1e-17 mm in XY) `x - xa` is off by a rounding
    // unit of `xa`, which the slope `m` would magnify past the edge's top.
    let z_at = |x: f64| {
        let t = (x - xa) / len;
        if t >= 1.0 {
            b.z
        } else if t <= 0.0 {
            a.z
        } else {
            a.z + m * (x - xa)
        }
    };
    // Upper bound: the highest point of the chord, lifted by the profile at the
    // smallest distance d (h is non-decreasing).
    if z_at(lo).max(z_at(hi)) - profile.height(d) <= best.tip.z {
        return;
    }
    let x = if matches!(profile.shape, CutterShape::Bull { .. }) && m != 0.0 {
        // Mirror so that the edge rises with x, solve, mirror back.
        let (l, h) = if m > 0.0 { (lo, hi) } else { (-hi, -lo) };
        // The line's height at x = 0 (the bound of `bull_edge` adds m x to it).
        match bull_edge(profile, m.abs(), d, l, h, a.z - m * xa, best.tip.z) {
            Some(x) => {
                if m > 0.0 {
                    x
                } else {
                    -x
                }
            }
            None => return,
        }
    } else {
        let x_c = maximiser(profile, m.abs(), d, x_r);
        (if m < 0.0 { -x_c } else { x_c }).clamp(lo, hi)
    };
    let zc = z_at(x);
    let tip = zc - profile.height((x * x + d * d).sqrt());
    if tip > best.tip.z {
        let t = ((x - xa) / len).clamp(0.0, 1.0);
        best.tip.z = tip;
        best.contact = Contact::Edge { triangle, point: Point3::new(a.x + t * ex, a.y + t * ey, zc) };
    }
}

/// Whether no contact on the edge from `p` (its first corner, XY relative to
/// the tip's XY, z absolute) along `e` (`len2 = |e_xy|^2 > 0`) can hold the
/// tip above `best`. Two bounds, before the edge frame (two square roots, four
/// divisions) is built:
/// - the edge's line farther than R, or its highest corner lifted by the
///   profile at the line's distance d (h is non-decreasing) not above `best`;
/// - for the ball, the highest contact with the whole line: with the line's
///   height `z0` at its point nearest the tip's XY and slope `m`, the maximum of
///   `z0 + m x - h(sqrt(x^2 + d^2))` over |x| <= x_R is
///   `z0 + x_R sqrt(1 + m^2) - R` (at `x = m x_R / sqrt(1 + m^2)`, see the
///   module's table), no lower than the contact on the edge itself.
///
/// Conservative: d is lowered past its rounding (the cross product may
/// cancel) and each bound carries the prune slack of its terms, so where the
/// exact test of [`drop_edge`] would raise `best` this is false and no height
/// changes. False on NaN.
#[inline]
fn edge_below(profile: &Profile, [px, py, za]: [f64; 3], [ex, ey, dz]: [f64; 3], len2: f64, best: f64) -> bool {
    let cross = px * ey - py * ex;
    let d2 = cross * cross / len2 - tol::REL_ROUNDING * (px * px + py * py + len2);
    let (radius, d2) = (profile.radius, d2.max(0.0));
    let r2 = radius * radius;
    if d2 > r2 {
        return true;
    }
    let z_top = za.max(za + dz);
    let slack = tol::REL_PRUNE_SLACK * (z_top.abs() + best.abs() + radius + 1.0);
    if z_top - profile.height_sq(d2) + slack <= best {
        return true;
    }
    if let CutterShape::Ball { .. } = profile.shape {
        let rise = dz * (px * ex + py * ey) / len2; // m x_a: the line's height at the foot is za - rise
        let lift = ((r2 - d2) * (1.0 + dz * dz / len2)).sqrt(); // x_R sqrt(1 + m^2)
        let slack = tol::REL_PRUNE_SLACK * (za.abs() + rise.abs() + lift + best.abs() + radius + 1.0);
        return za - rise + lift - radius + slack <= best;
    }
    false
}

/// The x >= 0 that maximises `m x - h(sqrt(x^2 + d^2))` on [0, x_r], for m >= 0.
fn maximiser(profile: &Profile, m: f64, d: f64, x_r: f64) -> f64 {
    match profile.shape {
        CutterShape::Flat { .. } => {
            if m > 0.0 {
                x_r
            } else {
                0.0
            }
        }
        CutterShape::Ball { .. } => m * x_r / (1.0 + m * m).sqrt(),
        CutterShape::Cone { .. } => {
            let k = m * profile.tan;
            if k >= 1.0 { x_r } else { (d * k / (1.0 - k * k).sqrt()).min(x_r) }
        }
        CutterShape::Bull { .. } => {
            if m == 0.0 {
                0.0
            } else {
                let (a, r) = (profile.flat_radius, profile.corner);
                bull_maximiser(a, r, m, d, (d - a).max(0.0), r, 0.5 * ((d - a).max(0.0) + r)).min(x_r)
            }
        }
    }
}

/// Slope of g(x) = m x - h(rho(x)) for the bull-nose: m - h'(rho) x / rho
/// (+inf or -inf where h' is infinite, at rho = R).
fn bull_slope(a: f64, r: f64, m: f64, d: f64, x: f64) -> f64 {
    let rho = (x * x + d * d).sqrt();
    let s = rho - a;
    if s <= 0.0 || rho == 0.0 {
        return m;
    }
    let q = r * r - s * s;
    if q <= 0.0 {
        return if x > 0.0 { f64::NEG_INFINITY } else { f64::INFINITY };
    }
    m - s / q.sqrt() * x / rho
}

/// The maximiser of g(x) = m x - h(rho(x)) on [l, h] for a bull-nose and
/// m > 0, or `None` when even an upper bound of the contact height
/// `z0 + max g` cannot beat `best`. Concavity gives both shortcuts:
/// g' >= 0 at h or g' <= 0 at l puts the maximum at that end; otherwise the two
/// end tangents lie above g and meet above its maximum (the bound), and their
/// crossing is a good first guess for the root finder.
fn bull_edge(profile: &Profile, m: f64, d: f64, l: f64, h: f64, z0: f64, best: f64) -> Option<f64> {
    let (a, r) = (profile.flat_radius, profile.corner);
    let slope_h = bull_slope(a, r, m, d, h);
    if slope_h >= 0.0 {
        return Some(h);
    }
    let slope_l = bull_slope(a, r, m, d, l);
    if slope_l <= 0.0 {
        return Some(l);
    }
    let g = |x: f64| m * x - profile.height((x * x + d * d).sqrt());
    let (g_l, g_h) = (g(l), g(h));
    let (bound, guess) = match (slope_l.is_finite(), slope_h.is_finite()) {
        (true, true) => {
            let x = ((g_h - g_l + slope_l * l - slope_h * h) / (slope_l - slope_h)).clamp(l, h);
            (g_l + slope_l * (x - l), x)
        }
        (true, false) => (g_l + slope_l * (h - l), h),
        (false, true) => (g_h + slope_h * (l - h), l),
        (false, false) => (f64::INFINITY, 0.5 * (l + h)),
    };
    let slack = tol::REL_PRUNE_SLACK * (z0.abs() + best.abs() + profile.radius + 1.0);
    if z0 + bound + slack <= best {
        return None;
    }
    let s_of = |x: f64| ((x * x + d * d).sqrt() - a).clamp(0.0, r);
    // The root has x > 0 (g' > 0 for x <= 0) and lies in (l, h).
    let (s_lo, s_hi) = (s_of(l.max(0.0)), s_of(h));
    let x = bull_maximiser(a, r, m, d, s_lo, s_hi, s_of(guess.max(0.0)));
    Some(x.clamp(l, h))
}

/// Solves h'(rho) x / rho = m on the corner of the bull-nose, without
/// trigonometry. With s = rho - a (a = R - r, 0 <= s <= r),
/// h' = s / sqrt(r^2 - s^2) and x = sqrt(rho^2 - d^2); squaring gives
///
/// ```text
/// P(s) = s^2 ((a + s)^2 - d^2) - m^2 (a + s)^2 (r^2 - s^2)
///      = rho^2 (r^2 - s^2) (g(s)^2 - m^2),   g = h' x / rho increasing,
/// ```
///
/// so P changes sign exactly once on [s_0, r] (P(s_0) <= 0 <= P(r)), where
/// s_0 = max(0, d - a). Newton steps kept inside a shrinking bracket
/// [`s_lo`, `s_hi`] (narrowed by the caller where it knows more), from `s_start`.
/// Returns x >= 0.
fn bull_maximiser(a: f64, r: f64, m: f64, d: f64, s_lo: f64, s_hi: f64, s_start: f64) -> f64 {
    let m2 = m * m;
    let (r2, d2) = (r * r, d * d);
    let (mut lo, mut hi) = (s_lo, s_hi);
    let tol = tol::PARAMETER_CONVERGENCE * r;
    let mut s = if s_start > lo && s_start < hi { s_start } else { 0.5 * (lo + hi) };
    if hi <= lo {
        s = hi;
    }
    for _ in 0..MAX_ITERATIONS {
        let rho = a + s;
        let (rho2, s2) = (rho * rho, s * s);
        let p = s2 * (rho2 - d2) - m2 * rho2 * (r2 - s2);
        if p < 0.0 {
            lo = s;
        } else {
            hi = s;
        }
        // P' = 2s (rho^2 - d^2) + 2 s^2 rho - m^2 (2 rho (r^2 - s^2) - 2 s rho^2)
        let dp = 2.0 * s * (rho2 - d2) + 2.0 * s2 * rho - m2 * (2.0 * rho * (r2 - s2) - 2.0 * s * rho2);
        let newton = s - p / dp;
        let next = if dp > 0.0 && newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        let step = (next - s).abs();
        s = next;
        if step <= tol || hi - lo <= tol {
            break;
        }
    }
    let rho = a + s;
    (rho * rho - d2).max(0.0).sqrt()
}

#[cfg(test)]
// `unwrap` is allowed in tests by clippy.toml.
#[allow(clippy::float_cmp, reason = "tests: exact values are intended")]
mod tests {
    use super::*;

    /// max of m x - h(rho(x)) by dense sampling, for comparison.
    fn sampled_max(shape: &CutterShape, m: f64, d: f64, x_r: f64) -> f64 {
        let n = 200_000;
        (0..=n)
            .map(|i| {
                let x = -x_r + 2.0 * x_r * f64::from(i) / f64::from(n);
                m * x - shape.height_at((x * x + d * d).sqrt())
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// The bounds of `edge_below` never skip an edge whose exact contact
    /// would raise the best height: random edges, tips and best heights around
    /// the exact contact (just below, at and above it), every shape.
    #[test]
    fn edge_below_never_skips_a_raising_edge() {
        use scallop_geom::rng::SplitMix64;
        let shapes = [
            CutterShape::Flat { radius: 1.0 },
            CutterShape::Ball { radius: 1.0 },
            CutterShape::Bull { radius: 1.0, corner: 0.3 },
            CutterShape::Cone { radius: 1.0, half_angle: 0.6 },
        ];
        let mut rng = SplitMix64::new(20_261_206);
        let mut skipped = 0;
        for shape in shapes {
            let profile = Profile::new(&shape);
            for _ in 0..20_000 {
                let mut q = || Point3::new(rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5), rng.uniform(-1.0, 1.0));
                let (a, b) = (q(), q());
                let c = Point2::new(0.0, 0.0);
                let mut exact = ClPoint::floor(c, -100.0);
                drop_edge_exact(&profile, &a, &b, 0, c, &mut exact);
                for offset in [-0.3, -1e-6, -1e-12, 0.0, 1e-12, 0.2] {
                    let start = ClPoint::floor(c, exact.tip.z + offset);
                    let (mut pruned, mut full) = (start, start);
                    drop_edge(&profile, &a, &b, 0, c, &mut pruned);
                    drop_edge_exact(&profile, &a, &b, 0, c, &mut full);
                    assert_eq!(pruned, full, "{shape:?} {a:?} {b:?} offset {offset}");
                    let ends = [a.x - c.x, a.y - c.y, a.z];
                    let (ex, ey) = (b.x - a.x, b.y - a.y);
                    if ex * ex + ey * ey > 0.0
                        && edge_below(&profile, ends, [ex, ey, b.z - a.z], ex * ex + ey * ey, start.tip.z)
                    {
                        skipped += 1;
                    }
                }
            }
        }
        assert!(skipped > 10_000, "the bounds skip edges ({skipped})");
    }

    #[test]
    fn maximiser_beats_dense_sampling_for_every_shape() {
        let shapes = [
            CutterShape::Flat { radius: 2.0 },
            CutterShape::Ball { radius: 2.0 },
            CutterShape::Bull { radius: 2.0, corner: 0.5 },
            CutterShape::Bull { radius: 2.0, corner: 2.0 },
            CutterShape::Bull { radius: 2.0, corner: 1e-3 },
            CutterShape::Cone { radius: 2.0, half_angle: 0.7 },
        ];
        for shape in shapes {
            for &d in &[0.0, 0.3, 1.2, 1.6, 1.99] {
                for &m in &[0.0, 0.01, 0.3, 1.0, 4.0, 100.0] {
                    let x_r = (4.0_f64 - d * d).sqrt();
                    let x = maximiser(&Profile::new(&shape), m, d, x_r);
                    assert!((0.0..=x_r).contains(&x), "{shape:?} d={d} m={m}: x={x}");
                    let ours = m * x - shape.height_at((x * x + d * d).sqrt());
                    let sampled = sampled_max(&shape, m, d, x_r);
                    // ours is the true maximum: never below the samples, and above by
                    // no more than the sampling step can hide (slope * step).
                    assert!(ours >= sampled - 1e-12, "{shape:?} d={d} m={m}: {ours} < {sampled}");
                    assert!(ours <= sampled + (m + 50.0) * 4.0 * x_r / 200_000.0, "{shape:?} d={d} m={m}");
                }
            }
        }
    }
}
