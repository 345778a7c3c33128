//! 3D polylines (open or closed) with arc length and barycentre, and the
//! point-to-polyline distance through a [`Bvh`] over the segments of a set of
//! polylines.

use scallop_geom::{Aabb3, Point3, Vec3};

use crate::Bvh;

/// A 3D polyline; a closed one joins its last point back to its first (the
/// first point is not repeated).
#[derive(Clone, Debug, PartialEq)]
pub struct Polyline3 {
    /// The points in travel order (mm).
    pub points: Vec<Point3>,
    /// Whether the last point joins the first.
    pub closed: bool,
}

impl Polyline3 {
    /// A polyline through `points`.
    #[must_use]
    pub fn new(points: Vec<Point3>, closed: bool) -> Polyline3 {
        Polyline3 { points, closed }
    }

    /// Number of segments.
    #[must_use]
    pub fn segment_count(&self) -> usize {
        match (self.points.len(), self.closed) {
            (0 | 1, _) => 0,
            (2, true) => 1,
            (n, true) => n,
            (n, false) => n - 1,
        }
    }

    /// End points of segment `i`.
    #[must_use]
    pub fn segment(&self, i: usize) -> (Point3, Point3) {
        let n = self.points.len();
        (self.points[i], self.points[(i + 1) % n])
    }

    /// Total length (mm).
    ///
    /// ```
    /// use scallop_geom::Point3;
    /// let sq = scallop_mesh::Polyline3::new(
    ///     vec![Point3::origin(), Point3::new(1., 0., 0.), Point3::new(1., 1., 0.), Point3::new(0., 1., 0.)], true);
    /// assert_eq!(sq.length(), 4.0);
    /// assert_eq!(sq.barycentre(), Some(Point3::new(0.5, 0.5, 0.0)));
    /// ```
    #[must_use]
    pub fn length(&self) -> f64 {
        (0..self.segment_count()).map(|i| self.segment_length(i)).sum()
    }

    /// Length of segment `i` (mm).
    #[must_use]
    pub fn segment_length(&self, i: usize) -> f64 {
        let (a, b) = self.segment(i);
        (b - a).norm()
    }

    /// Arc-length-weighted centroid (Jousselin 2020, Ch. 2 §3.2.2: the
    /// barycentre that sets the projection direction; a vertex average would
    /// be biased by the sampling density). `None` for a zero-length polyline.
    #[must_use]
    pub fn barycentre(&self) -> Option<Point3> {
        let mut sum = Vec3::zeros();
        let mut total = 0.0;
        for i in 0..self.segment_count() {
            let (a, b) = self.segment(i);
            let l = (b - a).norm();
            sum += (a.coords + b.coords) * (0.5 * l);
            total += l;
        }
        (total > 0.0).then(|| Point3::from(sum / total))
    }

    /// Box of the points, `None` when empty.
    #[must_use]
    pub fn bounds(&self) -> Option<Aabb3> {
        Aabb3::from_points(self.points.iter().copied())
    }

    /// The same polyline travelled the other way.
    #[must_use]
    pub fn reversed(&self) -> Polyline3 {
        let mut points = self.points.clone();
        points.reverse();
        Polyline3 { points, closed: self.closed }
    }
}

/// The point of a polyline set nearest to a query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolylineFoot {
    /// Which polyline of the set.
    pub curve: usize,
    /// Which segment of it.
    pub segment: usize,
    /// Parameter along the segment, in `[0, 1]`.
    pub t: f64,
    /// The nearest point (mm).
    pub point: Point3,
    /// Distance from the query (mm).
    pub distance: f64,
}

/// A set of polylines with a hierarchy over their segments (degenerate
/// polylines of one point count as one zero-length segment).
#[derive(Debug, Clone)]
pub struct PolylineQuery {
    curves: Vec<Polyline3>,
    /// (curve, segment) of each item.
    items: Vec<(u32, u32)>,
    bvh: Bvh,
}

impl PolylineQuery {
    /// Indexes `curves`.
    ///
    /// ```
    /// use scallop_geom::Point3;
    /// use scallop_mesh::{Polyline3, PolylineQuery};
    /// let line = Polyline3::new(vec![Point3::origin(), Point3::new(10., 0., 0.)], false);
    /// let q = PolylineQuery::new(vec![line]);
    /// let f = q.closest(&Point3::new(3., 4., 0.)).unwrap();
    /// assert_eq!((f.distance, f.t), (4.0, 0.3));
    /// ```
    #[must_use]
    pub fn new(curves: Vec<Polyline3>) -> PolylineQuery {
        let mut items = Vec::new();
        let mut boxes = Vec::new();
        for (c, curve) in curves.iter().enumerate() {
            let n = curve.segment_count();
            let segs = if n == 0 && !curve.points.is_empty() { 1 } else { n };
            for s in 0..segs {
                let (a, b) = if n == 0 { (curve.points[0], curve.points[0]) } else { curve.segment(s) };
                boxes.push(Aabb3 { min: a.inf(&b), max: a.sup(&b) });
                items.push((u32::try_from(c).unwrap_or(u32::MAX), u32::try_from(s).unwrap_or(u32::MAX)));
            }
        }
        PolylineQuery { curves, items, bvh: Bvh::build(&boxes) }
    }

    /// The indexed polylines.
    #[must_use]
    pub fn curves(&self) -> &[Polyline3] {
        &self.curves
    }

    fn ends(&self, item: usize) -> (Point3, Point3) {
        let (c, s) = self.items[item];
        let curve = &self.curves[c as usize];
        if curve.segment_count() == 0 { (curve.points[0], curve.points[0]) } else { curve.segment(s as usize) }
    }

    /// The nearest point of the set to `p`; `None` for an empty set.
    #[must_use]
    pub fn closest(&self, p: &Point3) -> Option<PolylineFoot> {
        self.closest_within(p, f64::INFINITY)
    }

    /// The nearest point of the set to `p` if within `max_distance`.
    #[must_use]
    pub fn closest_within(&self, p: &Point3, max_distance: f64) -> Option<PolylineFoot> {
        let (item, d2) = self.bvh.nearest(p, max_distance * max_distance, |i| {
            let (a, b) = self.ends(i);
            let t = segment_parameter(p, &a, &b);
            (a + (b - a) * t - p).norm_squared()
        })?;
        let (a, b) = self.ends(item);
        let t = segment_parameter(p, &a, &b);
        let (c, s) = self.items[item];
        Some(PolylineFoot { curve: c as usize, segment: s as usize, t, point: a + (b - a) * t, distance: d2.sqrt() })
    }

    /// As [`PolylineQuery::closest_within`], searching from the segment of
    /// `hint` (a foot of a nearby point): its distance bounds the search, so
    /// coherent queries prune more. The result does not depend on the hint.
    #[must_use]
    pub fn closest_near(&self, p: &Point3, max_distance: f64, hint: &PolylineFoot) -> Option<PolylineFoot> {
        let Some(curve) = self.curves.get(hint.curve) else { return self.closest_within(p, max_distance) };
        if hint.segment >= curve.segment_count() {
            return self.closest_within(p, max_distance);
        }
        let (a, b) = curve.segment(hint.segment);
        let d = (a + (b - a) * segment_parameter(p, &a, &b) - p).norm();
        // A relative margin keeps the hint's own segment inside the bound
        // despite rounding in the squared comparison.
        self.closest_within(p, max_distance.min(d * (1.0 + 1e-12)))
    }

    /// Distance from `p` to the set (infinite for an empty set).
    #[must_use]
    pub fn distance(&self, p: &Point3) -> f64 {
        self.closest(p).map_or(f64::INFINITY, |f| f.distance)
    }
}

/// Parameter in `[0, 1]` of the point of segment `[a, b]` nearest to `p`.
#[must_use]
pub fn segment_parameter(p: &Point3, a: &Point3, b: &Point3) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    if l2.is_nan() || l2 <= 0.0 {
        return 0.0;
    }
    ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
}
