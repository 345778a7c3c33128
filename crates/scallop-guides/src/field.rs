//! The signed Euclidean distance to a set of curves on a support: positive on
//! the left of the curves (their inside), negative on the right. Its zero set
//! is the curves, so iso-lines at a positive value are inward offsets only
//! (the inward trimming of Jousselin 2020, Ch. 2 §3.2.1, without a separate
//! trimming pass). The side of a point is read at its foot on the curves with
//! the left vector `n × T` (an average of the two neighbours' at a corner: the
//! pseudo-normal rule, Bærentzen & Aanæs 2005, applied to polylines).

use scallop_geom::{Point3, Vec3};
use scallop_mesh::{Polyline3, PolylineFoot, PolylineQuery, segment_parameter};

use crate::support::Curve;
use crate::tol;

/// Signed distance to a set of curves.
#[derive(Debug, Clone)]
pub struct CurveField {
    query: PolylineQuery,
    /// Per curve, per segment: the unit left vector.
    left: Vec<Vec<Vec3>>,
}

impl CurveField {
    /// The field of `curves` (each with its surface normals).
    #[must_use]
    pub fn new(curves: &[Curve]) -> CurveField {
        let curves: Vec<Curve> = curves.iter().map(merge_close_points).collect();
        let left = curves
            .iter()
            .map(|c| {
                (0..c.line.segment_count())
                    .map(|s| {
                        let (a, b) = c.line.segment(s);
                        let n_pts = c.line.points.len();
                        let normal = |i: usize| c.normals.get(i).copied().unwrap_or_else(Vec3::z);
                        let n = normal(s) + normal((s + 1) % n_pts);
                        let l = n.cross(&(b - a));
                        let len = l.norm();
                        if len > 0.0 { l / len } else { Vec3::zeros() }
                    })
                    .collect()
            })
            .collect();
        let lines: Vec<Polyline3> = curves.into_iter().map(|c| c.line).collect();
        CurveField { query: PolylineQuery::new(lines), left }
    }

    /// The curves' polylines.
    #[must_use]
    pub fn curves(&self) -> &[Polyline3] {
        self.query.curves()
    }

    /// The nearest point of the curves to `p`.
    #[must_use]
    pub fn foot(&self, p: &Point3) -> Option<PolylineFoot> {
        self.query.closest(p)
    }

    /// The nearest point of the curves to `p` if within `max_distance`.
    #[must_use]
    pub fn foot_within(&self, p: &Point3, max_distance: f64) -> Option<PolylineFoot> {
        self.query.closest_within(p, max_distance)
    }

    /// As [`CurveField::foot_within`], searching from a nearby point's foot.
    #[must_use]
    pub fn foot_near(&self, p: &Point3, max_distance: f64, hint: Option<&PolylineFoot>) -> Option<PolylineFoot> {
        match hint {
            Some(h) => self.query.closest_near(p, max_distance, h),
            None => self.query.closest_within(p, max_distance),
        }
    }

    /// The unit left vector of segment `segment` of curve `curve` (tangent
    /// to the support, toward the inside; zero for a degenerate segment).
    pub(crate) fn left(&self, curve: usize, segment: usize) -> Vec3 {
        self.left[curve][segment]
    }

    /// Signed distance from `p`: `+d` on the inside (left), `-d` outside.
    #[must_use]
    pub fn signed(&self, p: &Point3) -> f64 {
        self.foot(p).map_or(f64::NEG_INFINITY, |f| self.signed_at(p, &f))
    }

    /// Signed distance given the foot of `p`.
    #[must_use]
    pub fn signed_at(&self, p: &Point3, f: &PolylineFoot) -> f64 {
        let left = &self.left[f.curve];
        let line = &self.query.curves()[f.curve];
        let n = left.len();
        let l = if n == 0 {
            Vec3::zeros()
        } else if f.t <= 0.0 && (line.closed || f.segment > 0) {
            left[(f.segment + n - 1) % n] + left[f.segment]
        } else if f.t >= 1.0 && (line.closed || f.segment + 1 < n) {
            left[f.segment] + left[(f.segment + 1) % n]
        } else {
            left[f.segment]
        };
        if (p - f.point).dot(&l) >= 0.0 { f.distance } else { -f.distance }
    }
}

/// `count` consecutive segments of curve `curve` from segment `first`
/// (round the end of a closed curve).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stretch {
    curve: usize,
    first: usize,
    count: usize,
}

impl CurveField {
    /// The segments of the feet `a` and `b` and those between them (the
    /// shorter way round a closed curve), with one more at each end, if the
    /// feet are on one curve and these are at most `max` segments.
    pub(crate) fn stretch(&self, a: &PolylineFoot, b: &PolylineFoot, max: usize) -> Option<Stretch> {
        let line = self.curves().get(a.curve).filter(|_| a.curve == b.curve)?;
        let n = line.segment_count();
        let (lo, hi) = (a.segment.min(b.segment), a.segment.max(b.segment));
        if hi >= n {
            return None;
        }
        let (first, count) = if !line.closed {
            let first = lo.saturating_sub(1);
            (first, (hi + 1).min(n - 1) - first + 1)
        } else if lo + n - hi < hi - lo {
            ((hi + n - 1) % n, (lo + n - hi + 3).min(n))
        } else {
            ((lo + n - 1) % n, (hi - lo + 3).min(n))
        };
        (count <= max).then_some(Stretch { curve: a.curve, first, count })
    }

    /// The signed distance from `p` to the segments of `stretch` only, the
    /// side read as in [`CurveField::signed_at`]: the same value as
    /// [`CurveField::signed`] wherever the foot of `p` is on the stretch.
    pub(crate) fn signed_on(&self, p: &Point3, stretch: &Stretch) -> f64 {
        let line = &self.curves()[stretch.curve];
        let n = line.segment_count();
        let mut best = (f64::INFINITY, stretch.first, 0.0, *p);
        for k in 0..stretch.count {
            let segment = (stretch.first + k) % n;
            let (a, b) = line.segment(segment);
            let t = segment_parameter(p, &a, &b);
            let q = a + (b - a) * t;
            let d2 = (q - p).norm_squared();
            if d2 < best.0 {
                best = (d2, segment, t, q);
            }
        }
        let (d2, segment, t, point) = best;
        self.signed_at(p, &PolylineFoot { curve: stretch.curve, segment, t, point, distance: d2.sqrt() })
    }
}

/// `c` without the points within [`tol::MERGE_DISTANCE`] of the point kept
/// before them: a shorter segment has no reliable direction, and its left
/// vector would decide the side of the points whose foot is its end.
fn merge_close_points(c: &Curve) -> Curve {
    if c.normals.len() != c.line.points.len() {
        return c.clone();
    }
    let mut points: Vec<Point3> = Vec::with_capacity(c.line.points.len());
    let mut normals = Vec::with_capacity(c.line.points.len());
    for (p, n) in c.line.points.iter().zip(&c.normals) {
        if points.last().is_none_or(|q: &Point3| (p - q).norm() > tol::MERGE_DISTANCE) {
            points.push(*p);
            normals.push(*n);
        }
    }
    if c.line.closed && points.len() > 2 && (points[0] - points[points.len() - 1]).norm() <= tol::MERGE_DISTANCE {
        points.pop();
        normals.pop();
    }
    if points.len() < 2 {
        return c.clone();
    }
    Curve { line: Polyline3::new(points, c.line.closed), normals }
}
