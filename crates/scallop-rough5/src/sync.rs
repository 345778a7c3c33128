//! SPU synchronisation of a path curve with its tilt curve (Jousselin 2020,
//! Ch. 2 §1.2.3, Eq. 3.10) and the pitch angle theta_t (Eq. 3.7).
//!
//! Both curves are stepped with the same parameter s in [0, 1], a constant
//! fraction of each curve's own length: `s_T = s_D = s`. Their start points:
//! P_T0 is given (the closest vertex to a hint, e.g. the end of the previous
//! pass), and P_D0 is the vertex of the tilt curve closest to the line through
//! P_T0 along the level normal there (a zero-tilt start, spec 5.10 [IMPL]).
//! The tilt curve is reversed when it turns the other way about the level
//! normal than the path curve, so that both run the same way.

use scallop_geom::{Point3, Vec3};
use scallop_guides::Curve;

use crate::tol;

/// One synchronised pair: the path point, its tilt point, the level normal
/// and the unit tangent of the path curve there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SyncPoint {
    /// P_T on the path curve (level S_n).
    pub path: Point3,
    /// P_D on the tilt curve (level S_{n+1}), or `None` for zero tilt.
    pub tilt: Option<Point3>,
    /// Unit normal of the level at P_T, turned upwards (+z side).
    pub normal: Vec3,
    /// Unit tangent of the path curve at P_T (direction of travel).
    pub tangent: Vec3,
}

impl SyncPoint {
    /// The tool axis: from P_T to P_D, or +Z without a tilt point (or when
    /// the two points coincide).
    #[must_use]
    pub fn axis(&self) -> Vec3 {
        match self.tilt {
            Some(d) if (d - self.path).norm() > tol::MIN_AXIS_LENGTH => (d - self.path).normalize(),
            _ => Vec3::z(),
        }
    }
}

/// The pitch angle theta_t (Eq. 3.7) of the tool axis `u` in the frame of the
/// feed direction `tangent` and the level normal `normal`, evaluated as
/// `atan2(u.f, u.n)` with f the tangent made orthogonal to n (spec 6.2):
/// negative when pushing, positive when pulling.
///
/// ```
/// use scallop_geom::Vec3;
/// let t = 0.2f64;
/// let u = Vec3::new(t.sin(), 0.0, t.cos()); // leaning forwards along +x
/// let theta = scallop_rough5::pitch_angle(&u, &Vec3::x(), &Vec3::z());
/// assert!((theta - t).abs() < 1e-12);
/// ```
#[must_use]
pub fn pitch_angle(u: &Vec3, tangent: &Vec3, normal: &Vec3) -> f64 {
    let f = tangent - normal * tangent.dot(normal);
    let len = f.norm();
    if len == 0.0 {
        return 0.0;
    }
    let f = f / len;
    u.dot(&f).atan2(u.dot(normal))
}

/// A closed or open curve by arc length.
struct ArcCurve {
    points: Vec<Point3>,
    normals: Vec<Vec3>,
    /// Cumulative length at each point (and at the closing point for a
    /// closed curve).
    cum: Vec<f64>,
    closed: bool,
}

impl ArcCurve {
    /// The curve started at vertex `first` (rotated when closed).
    fn new(curve: &Curve, first: usize) -> ArcCurve {
        let n = curve.line.points.len();
        let order: Vec<usize> =
            if curve.line.closed { (0..n).map(|k| (first + k) % n).collect() } else { (0..n).collect() };
        let points: Vec<Point3> = order.iter().map(|&k| curve.line.points[k]).collect();
        let normals: Vec<Vec3> = order.iter().map(|&k| curve.normals[k]).collect();
        let mut cum = vec![0.0];
        let count = if curve.line.closed { n } else { n - 1 };
        for k in 0..count {
            let d = (points[(k + 1) % n] - points[k]).norm();
            cum.push(cum[k] + d);
        }
        ArcCurve { points, normals, cum, closed: curve.line.closed }
    }

    fn length(&self) -> f64 {
        self.cum.last().copied().unwrap_or(0.0)
    }

    /// Point, normal and unit tangent at arc length `s` (clamped).
    fn at(&self, s: f64) -> (Point3, Vec3, Vec3) {
        let n = self.points.len();
        let s = s.clamp(0.0, self.length());
        let seg = self.cum.partition_point(|&c| c <= s).saturating_sub(1).min(self.cum.len().saturating_sub(2));
        let (i, j) = (seg, if self.closed { (seg + 1) % n } else { (seg + 1).min(n - 1) });
        let len = self.cum[seg + 1] - self.cum[seg];
        let w = if len > 0.0 { ((s - self.cum[seg]) / len).clamp(0.0, 1.0) } else { 0.0 };
        let p = self.points[i] + (self.points[j] - self.points[i]) * w;
        let nrm = self.normals[i] * (1.0 - w) + self.normals[j] * w;
        let t = self.points[j] - self.points[i];
        let t = if t.norm() > 0.0 { t.normalize() } else { Vec3::x() };
        (p, up(nrm), t)
    }
}

/// A normal turned to the +z side, unit (+Z when degenerate).
fn up(n: Vec3) -> Vec3 {
    let len = n.norm();
    if len == 0.0 || !len.is_finite() {
        return Vec3::z();
    }
    let n = n / len;
    if n.z < 0.0 { -n } else { n }
}

/// The vertex of `curve` closest to `p` (the lowest index on ties).
#[must_use]
pub fn closest_vertex(curve: &Curve, p: &Point3) -> usize {
    let mut best = (0, f64::INFINITY);
    for (k, q) in curve.line.points.iter().enumerate() {
        let d = (q - p).norm_squared();
        if d < best.1 {
            best = (k, d);
        }
    }
    best.0
}

/// Signed turning of a closed curve about +Z (twice its signed plan area).
fn plan_turning(curve: &Curve) -> f64 {
    let p = &curve.line.points;
    (0..p.len())
        .map(|k| {
            let (a, b) = (p[k], p[(k + 1) % p.len()]);
            a.x * b.y - b.x * a.y
        })
        .sum()
}

/// Synchronises `path` (started at its vertex closest to `start`) with
/// `tilt` (or zero tilt when `None`) by SPU, `count + 1` pairs for `count`
/// steps of about `step` mm along the path curve (the last pair closes a
/// closed curve).
#[must_use]
pub fn synchronise(path: &Curve, tilt: Option<&Curve>, start: &Point3, step: f64) -> Vec<SyncPoint> {
    if path.line.points.len() < 2 {
        return Vec::new();
    }
    let cp = ArcCurve::new(path, closest_vertex(path, start));
    let count = ((cp.length() / step).ceil() as usize).clamp(2, tol::MAX_PASS_POINTS);
    let (p0, n0, _) = cp.at(0.0);
    let ct = tilt.filter(|t| t.line.points.len() >= 2).map(|t| {
        let same_way = plan_turning(t) * plan_turning(path) >= 0.0 || !path.line.closed;
        let t = if same_way { t.clone() } else { t.reversed() };
        // P_D0: the vertex closest to the line through P_T0 along n0.
        let mut best = (0, f64::INFINITY);
        for (k, q) in t.line.points.iter().enumerate() {
            let d = q - p0;
            let off = (d - n0 * d.dot(&n0)).norm_squared();
            if off < best.1 {
                best = (k, off);
            }
        }
        ArcCurve::new(&t, best.0)
    });
    (0..=count)
        .map(|k| {
            let s = k as f64 / count as f64;
            let (p, n, t) = cp.at(s * cp.length());
            let d = ct.as_ref().map(|c| c.at(s * c.length()).0);
            SyncPoint { path: p, tilt: d, normal: n, tangent: t }
        })
        .collect()
}

/// Inserts pairs (linear between neighbours) wherever the tool axis turns by
/// more than `max_step` (rad) from one pair to the next.
#[must_use]
pub fn limit_angular_step(points: &[SyncPoint], max_step: f64) -> Vec<SyncPoint> {
    let mut out: Vec<SyncPoint> = Vec::with_capacity(points.len());
    for (k, b) in points.iter().enumerate() {
        if k > 0 {
            let a = points[k - 1];
            let angle = a.axis().angle(&b.axis());
            if angle > max_step.max(tol::ANGLE_EPS) {
                let parts = (angle / max_step).ceil() as usize;
                for i in 1..parts {
                    let w = i as f64 / parts as f64;
                    let lerp = |x: Point3, y: Point3| x + (y - x) * w;
                    out.push(SyncPoint {
                        path: lerp(a.path, b.path),
                        tilt: a.tilt.zip(b.tilt).map(|(x, y)| lerp(x, y)),
                        normal: up(a.normal * (1.0 - w) + b.normal * w),
                        tangent: a.tangent,
                    });
                }
            }
        }
        out.push(*b);
    }
    out
}
