//! SPU synchronisation of a path curve with its tilt curve (Jousselin 2020,
//! Ch. 2 §1.2.3, Eq. 3.10) and the pitch angle theta_t (Eq. 3.7).
//!
//! Both curves are stepped with the same parameter s in [0, 1], a constant
//! fraction of each curve's own length: `s_T = s_D = s`. Their start points:
//! P_T0 is given (the closest vertex to a hint, e.g. the end of the previous
//! pass), and P_D0 is the point of the tilt curve closest to the line through
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
    /// The unit tool axis: from P_T to P_D (+Z without a tilt point), or
    /// interpolated between two pairs by [`limit_angular_step`].
    pub axis: Vec3,
}

impl SyncPoint {
    /// The tool axis.
    #[must_use]
    pub fn axis(&self) -> Vec3 {
        self.axis
    }
}

/// The axis from P_T to P_D, or +Z without a tilt point (or when the two
/// points coincide).
fn pair_axis(path: &Point3, tilt: Option<&Point3>) -> Vec3 {
    match tilt {
        Some(d) if (d - path).norm() > tol::MIN_AXIS_LENGTH => (d - path).normalize(),
        _ => Vec3::z(),
    }
}

/// Tilt from +Z and azimuth about +Z of a unit axis (azimuth 0 on the pole).
fn spherical(u: &Vec3) -> (f64, f64) {
    let tilt = u.z.clamp(-1.0, 1.0).acos();
    let azimuth = if tilt > tol::ANGLE_EPS { u.y.atan2(u.x) } else { 0.0 };
    (tilt, azimuth)
}

/// The azimuth change from `a` to `b` the shorter way (0 when either is
/// on the pole +Z).
fn azimuth_change(a: &Vec3, b: &Vec3) -> f64 {
    let ((ta, fa), (tb, fb)) = (spherical(a), spherical(b));
    if ta <= tol::ANGLE_EPS || tb <= tol::ANGLE_EPS {
        return 0.0;
    }
    let d = (fb - fa).rem_euclid(std::f64::consts::TAU);
    if d > std::f64::consts::PI { d - std::f64::consts::TAU } else { d }
}

/// Steps needed from axis `a` to axis `b` so that no step turns the axis by
/// more than `max_step` nor its azimuth about +Z (the rotary table of a
/// table-table machine) by more than `max_azimuth` (rad).
#[must_use]
pub fn axis_steps(a: &Vec3, b: &Vec3, max_step: f64, max_azimuth: f64) -> usize {
    // The interpolated path (tilt and azimuth linear) is no longer than
    // |dt| + sin(t_max) |dphi| on the unit sphere (ds^2 = dt^2 + sin^2 t dphi^2),
    // and each step turns the axis by at most its share of that length.
    let ((ta, _), (tb, _)) = (spherical(a), spherical(b));
    let dphi = azimuth_change(a, b).abs();
    let length = (tb - ta).abs() + ta.max(tb).min(std::f64::consts::FRAC_PI_2).sin() * dphi;
    let by_angle = (length.max(a.angle(b)) / max_step.max(tol::ANGLE_EPS)).ceil();
    let by_azimuth = (dphi / max_azimuth.max(tol::ANGLE_EPS)).ceil();
    by_angle.max(by_azimuth).max(1.0) as usize
}

/// The axis at `w` in [0, 1] from `a` to `b`: tilt from +Z and azimuth
/// interpolated linearly (the azimuth the shorter way, the pole taking the
/// other axis's azimuth), so a machine's rotaries turn evenly and never
/// flip through the pole.
#[must_use]
pub fn interpolate_axis(a: &Vec3, b: &Vec3, w: f64) -> Vec3 {
    let ((ta, fa), (tb, fb)) = (spherical(a), spherical(b));
    let fa = if ta <= tol::ANGLE_EPS { fb } else { fa };
    let f = fa + azimuth_change(a, b) * w;
    let t = ta + (tb - ta) * w;
    Vec3::new(t.sin() * f.cos(), t.sin() * f.sin(), t.cos())
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

    /// Arc length of the point of the curve closest to the line through
    /// `p` along the unit `n` (P_D0 of spec 5.10; the first on ties).
    fn closest_to_line(&self, p: &Point3, n: &Vec3) -> f64 {
        let flat = |q: &Point3| {
            let d = q - p;
            d - n * d.dot(n)
        };
        let mut best = (0.0, f64::INFINITY);
        for seg in 0..self.cum.len() - 1 {
            let (a, b) = (flat(&self.points[seg]), flat(&self.points[(seg + 1) % self.points.len()]));
            let ab = b - a;
            let len2 = ab.norm_squared();
            let w = if len2 > 0.0 { (-a.dot(&ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
            let d = (a + ab * w).norm_squared();
            if d < best.1 {
                best = (self.cum[seg] + w * (self.cum[seg + 1] - self.cum[seg]), d);
            }
        }
        best.0
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

/// The reference structure of one pass (Jousselin 2020, Fig. 3.15): the path
/// curve started at P_T0 and the tilt curve turned the same way, with the
/// arc length of P_D0 on it; immutable while the pass is reparameterised.
pub(crate) struct PassCurves {
    path: ArcCurve,
    tilt: Option<(ArcCurve, f64)>,
}

impl PassCurves {
    /// The curves of the pass `path` (started at its vertex closest to
    /// `start`) and `tilt`; `None` for fewer than two path points.
    pub(crate) fn new(path: &Curve, tilt: Option<&Curve>, start: &Point3) -> Option<PassCurves> {
        if path.line.points.len() < 2 {
            return None;
        }
        let cp = ArcCurve::new(path, closest_vertex(path, start));
        let (p0, n0, _) = cp.at(0.0);
        let ct = tilt.filter(|t| t.line.points.len() >= 2).map(|t| {
            let same_way = plan_turning(t) * plan_turning(path) >= 0.0 || !path.line.closed;
            let t = if same_way { t.clone() } else { t.reversed() };
            let c = ArcCurve::new(&t, 0);
            let s0 = c.closest_to_line(&p0, &n0);
            (c, s0)
        });
        Some(PassCurves { path: cp, tilt: ct })
    }

    /// Length of the path curve (mm).
    pub(crate) fn path_length(&self) -> f64 {
        self.path.length()
    }

    /// The pair at the fractions `s_t` of the path curve and `s_d` of the
    /// tilt curve from their start points (the path fraction taken modulo 1
    /// outside [0, 1] on a closed curve, the tilt position modulo its length).
    pub(crate) fn pair(&self, s_t: f64, s_d: f64) -> SyncPoint {
        let s_t = if self.path.closed && !(0.0..=1.0).contains(&s_t) { s_t.rem_euclid(1.0) } else { s_t };
        let (p, n, t) = self.path.at(s_t * self.path.length());
        let d = self
            .tilt
            .as_ref()
            .map(|(c, s0)| c.at((s0 + s_d * c.length()).rem_euclid(c.length().max(f64::MIN_POSITIVE))).0);
        SyncPoint { path: p, tilt: d, normal: n, tangent: t, axis: pair_axis(&p, d.as_ref()) }
    }
}

/// Synchronises `path` (started at its vertex closest to `start`) with
/// `tilt` (or zero tilt when `None`) by SPU, `count + 1` pairs for `count`
/// steps of about `step` mm along the path curve (the last pair closes a
/// closed curve).
#[must_use]
pub fn synchronise(path: &Curve, tilt: Option<&Curve>, start: &Point3, step: f64) -> Vec<SyncPoint> {
    let Some(curves) = PassCurves::new(path, tilt, start) else { return Vec::new() };
    let count = ((curves.path_length() / step).ceil() as usize).clamp(2, tol::MAX_PASS_POINTS);
    (0..=count)
        .map(|k| {
            let s = k as f64 / count as f64;
            curves.pair(s, s)
        })
        .collect()
}

/// Inserts pairs (positions linear between neighbours, axes by
/// [`interpolate_axis`]) wherever the tool axis turns by more than
/// `max_step` or its azimuth by more than `max_azimuth` (rad) from one pair to
/// the next.
#[must_use]
pub fn limit_angular_step(points: &[SyncPoint], max_step: f64, max_azimuth: f64) -> Vec<SyncPoint> {
    let mut out: Vec<SyncPoint> = Vec::with_capacity(points.len());
    for (k, b) in points.iter().enumerate() {
        if k > 0 {
            let a = points[k - 1];
            let parts = axis_steps(&a.axis, &b.axis, max_step, max_azimuth);
            for i in 1..parts {
                let w = i as f64 / parts as f64;
                let lerp = |x: Point3, y: Point3| x + (y - x) * w;
                out.push(SyncPoint {
                    path: lerp(a.path, b.path),
                    tilt: a.tilt.zip(b.tilt).map(|(x, y)| lerp(x, y)),
                    normal: up(a.normal * (1.0 - w) + b.normal * w),
                    tangent: a.tangent,
                    axis: interpolate_axis(&a.axis, &b.axis, w),
                });
            }
        }
        out.push(*b);
    }
    out
}
