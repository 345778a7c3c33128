//! 2D contours for scallop: polylines with circular-arc segments (bulge),
//! offsets that keep the arcs, booleans, area, orientation and containment.
//!
//! The adapter over `cavalier_contours` (offsets, arcs end to end) and
//! `i_overlay` (robust booleans of straight-edged polygons): arcs go to the
//! booleans as chords within a tolerance the caller passes, and come back as
//! arcs where [`Contour::from_points`] fits them. A [`Region`] is a set of
//! rings with the filled area on their left: outer boundaries counter-clockwise,
//! holes clockwise. Units mm.

use cavalier_contours::polyline::{
    PlineOrientation, PlineSource, PlineSourceMut, Polyline, seg_arc_radius_and_center, seg_closest_point,
};
use cavalier_contours::shape_algorithms::{Shape, ShapeOffsetOptions};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::clip::FloatClip;
use i_overlay::float::single::SingleFloatOverlay;
use i_overlay::string::clip::ClipRule;

mod fit;
mod fold;
pub mod tol;

/// A point of the plane (mm).
pub type P2 = [f64; 2];

/// Why a contour could not be made. Each variant names the place and the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ContourError {
    /// A coordinate or bulge that is not a finite number.
    #[error("vertex {index} of a contour is not finite; give finite coordinates (mm)")]
    NotFinite {
        /// The vertex.
        index: usize,
    },
    /// A closed contour with fewer than three distinct points, or no area.
    #[error("a closed contour needs at least three distinct points and an area above {min_area} mm^2")]
    Degenerate {
        /// The smallest area kept ([`tol::MIN_AREA`]).
        min_area: f64,
    },
}

/// One vertex: the point and the bulge of the segment that starts here
/// (`tan(sweep / 4)`, positive counter-clockwise; 0 for a straight segment).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vertex {
    /// X (mm).
    pub x: f64,
    /// Y (mm).
    pub y: f64,
    /// Bulge of the segment to the next vertex, in `[-1, 1]`.
    pub bulge: f64,
}

/// A segment of a contour: a line, or an arc with its centre and signed sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Segment {
    /// Straight from `from` to `to`.
    Line {
        /// Start.
        from: P2,
        /// End.
        to: P2,
    },
    /// Circular from `from` to `to` about `center`, turning `sweep` radians
    /// (positive counter-clockwise).
    Arc {
        /// Start.
        from: P2,
        /// End.
        to: P2,
        /// Centre.
        center: P2,
        /// Signed sweep (rad), `|sweep| <= pi`.
        sweep: f64,
    },
}

/// A polyline with arc segments, open or closed.
#[derive(Debug, Clone)]
pub struct Contour {
    pline: Polyline<f64>,
}

impl Contour {
    /// A contour through `vertices`.
    ///
    /// # Errors
    /// [`ContourError::NotFinite`].
    pub fn new(vertices: &[Vertex], closed: bool) -> Result<Contour, ContourError> {
        let mut pline = if closed { Polyline::new_closed() } else { Polyline::new() };
        for (index, v) in vertices.iter().enumerate() {
            if !(v.x.is_finite() && v.y.is_finite() && v.bulge.is_finite()) {
                return Err(ContourError::NotFinite { index });
            }
            pline.add(v.x, v.y, v.bulge.clamp(-1.0, 1.0));
        }
        Ok(Contour { pline })
    }

    /// A contour of straight segments through `points`.
    ///
    /// # Errors
    /// [`ContourError::NotFinite`].
    pub fn polygon(points: &[P2], closed: bool) -> Result<Contour, ContourError> {
        let v: Vec<Vertex> = points.iter().map(|p| Vertex { x: p[0], y: p[1], bulge: 0.0 }).collect();
        Contour::new(&v, closed)
    }

    /// A counter-clockwise circle (two half arcs).
    ///
    /// # Errors
    /// [`ContourError::NotFinite`].
    pub fn circle(center: P2, radius: f64) -> Result<Contour, ContourError> {
        let (x, y) = (center[0], center[1]);
        Contour::new(&[Vertex { x: x - radius, y, bulge: 1.0 }, Vertex { x: x + radius, y, bulge: 1.0 }], true)
    }

    /// A contour through `points` with runs of them replaced by arcs that pass
    /// within `tolerance` of every point and chord midpoint they replace
    /// (greedy, longest run first; at most a half turn per arc).
    ///
    /// # Errors
    /// [`ContourError::NotFinite`].
    pub fn from_points(points: &[P2], closed: bool, tolerance: f64) -> Result<Contour, ContourError> {
        Contour::new(&fit::fit_arcs(points, closed, tolerance), closed)
    }

    fn from_pline(pline: Polyline<f64>) -> Contour {
        Contour { pline }
    }

    /// The vertices.
    #[must_use]
    pub fn vertices(&self) -> Vec<Vertex> {
        self.pline.iter_vertexes().map(|v| Vertex { x: v.x, y: v.y, bulge: v.bulge }).collect()
    }

    /// Number of vertices.
    #[must_use]
    pub fn len(&self) -> usize {
        self.pline.vertex_count()
    }

    /// No vertex.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.pline.vertex_count() == 0
    }

    /// Closed (the last vertex joins the first).
    #[must_use]
    pub fn is_closed(&self) -> bool {
        self.pline.is_closed()
    }

    /// Signed area (mm^2): positive counter-clockwise; 0 for an open contour.
    #[must_use]
    pub fn signed_area(&self) -> f64 {
        self.pline.area()
    }

    /// Counter-clockwise (a positive area).
    #[must_use]
    pub fn is_ccw(&self) -> bool {
        self.pline.orientation() == PlineOrientation::CounterClockwise
    }

    /// Length (mm).
    #[must_use]
    pub fn length(&self) -> f64 {
        self.pline.path_length()
    }

    /// Winding number of a closed contour about `p` (0 for an open one).
    #[must_use]
    pub fn winding_number(&self, p: P2) -> i32 {
        self.pline.winding_number(cavalier_contours::core::math::Vector2::new(p[0], p[1]))
    }

    /// The same contour run backwards.
    #[must_use]
    pub fn reversed(&self) -> Contour {
        let mut p = self.pline.clone();
        p.invert_direction_mut();
        Contour::from_pline(p)
    }

    /// The same closed contour starting at vertex `k`.
    #[must_use]
    pub fn rotated(&self, k: usize) -> Contour {
        let n = self.len();
        let mut p = if self.is_closed() { Polyline::new_closed() } else { Polyline::new() };
        for i in 0..n {
            let v = self.pline.at((k + i) % n);
            p.add(v.x, v.y, v.bulge);
        }
        Contour::from_pline(p)
    }

    /// The closed contour starting at the point of it nearest to `p` (a
    /// vertex is inserted there unless one is within [`tol::POS_EQUAL`]).
    #[must_use]
    pub fn starting_near(&self, p: P2) -> Contour {
        let q = cavalier_contours::core::math::Vector2::new(p[0], p[1]);
        let n = self.len();
        let mut best = (f64::INFINITY, 0, q);
        for i in 0..self.segment_count() {
            let (a, b) = (self.pline.at(i), self.pline.at((i + 1) % n));
            let c = seg_closest_point(a, b, q, tol::POS_EQUAL);
            let d = (c - q).length();
            if d < best.0 {
                best = (d, i, c);
            }
        }
        let (_, i, c) = best;
        let (a, b) = (self.pline.at(i), self.pline.at((i + 1) % n));
        if (c - a.pos()).length() <= tol::POS_EQUAL {
            return self.rotated(i);
        }
        if (c - b.pos()).length() <= tol::POS_EQUAL {
            return self.rotated((i + 1) % n);
        }
        let split = cavalier_contours::polyline::seg_split_at_point(a, b, c, tol::POS_EQUAL);
        let mut pl = Polyline::new_closed();
        pl.add(split.split_vertex.x, split.split_vertex.y, split.split_vertex.bulge);
        for k in 1..n {
            let v = self.pline.at((i + k) % n);
            pl.add(v.x, v.y, v.bulge);
        }
        // The split segment's first half ends the loop.
        let last = self.pline.at(i);
        pl.add(last.x, last.y, split.updated_start.bulge);
        Contour::from_pline(pl)
    }

    fn segment_count(&self) -> usize {
        let n = self.len();
        if self.is_closed() { n } else { n.saturating_sub(1) }
    }

    /// The segments in order.
    #[must_use]
    pub fn segments(&self) -> Vec<Segment> {
        let n = self.len();
        (0..self.segment_count())
            .map(|i| {
                let (a, b) = (self.pline.at(i), self.pline.at((i + 1) % n));
                let (from, to) = ([a.x, a.y], [b.x, b.y]);
                if a.bulge.abs() <= tol::BULGE_ZERO {
                    Segment::Line { from, to }
                } else {
                    let (_, c) = seg_arc_radius_and_center(a, b);
                    Segment::Arc { from, to, center: [c.x, c.y], sweep: 4.0 * a.bulge.atan() }
                }
            })
            .collect()
    }

    /// The contour as points joined by chords, each within `tolerance` of its
    /// arc (the closing point of a closed contour not repeated).
    #[must_use]
    pub fn to_points(&self, tolerance: f64) -> Vec<P2> {
        let chorded = self.pline.arcs_to_approx_lines(tolerance.max(tol::MIN_CHORD_TOLERANCE));
        let p = chorded.as_ref().unwrap_or(&self.pline);
        p.iter_vertexes().map(|v| [v.x, v.y]).collect()
    }

    /// The offset contours of a closed contour at signed distance `d` to its
    /// left (inwards for a counter-clockwise contour), arcs kept.
    #[must_use]
    pub fn offset(&self, d: f64) -> Vec<Contour> {
        self.pline.parallel_offset(d).into_iter().map(Contour::from_pline).collect()
    }

    /// The closed contour without its redundant folds: stretches that run
    /// along a line, turn back along it (within `width`, mm) and run forward
    /// over it again; the contour kept passes within `width` of every point
    /// removed (`docs/roughing.md`, "Offset rings without folds"). An open
    /// contour is returned as it is.
    ///
    /// ```
    /// use scallop_contour::Contour;
    /// // The bottom edge runs 0 -> 4, back to 1 and forward to 4 again.
    /// let c = Contour::polygon(&[[0., 0.], [4., 0.], [1., 0.], [4., 0.], [4., 4.], [0., 4.]], true).unwrap();
    /// assert_eq!(c.without_folds(1e-3).len(), 4);
    /// ```
    #[must_use]
    pub fn without_folds(&self, width: f64) -> Contour {
        if !self.is_closed() {
            return self.clone();
        }
        let v = self.vertices();
        let kept = fold::unfold(&v, width);
        if kept.len() == v.len() {
            return self.clone();
        }
        let mut pline = Polyline::new_closed();
        for x in kept {
            pline.add(x.x, x.y, x.bulge);
        }
        Contour { pline }
    }

    /// The first point.
    #[must_use]
    pub fn start(&self) -> Option<P2> {
        (!self.is_empty()).then(|| {
            let v = self.pline.at(0);
            [v.x, v.y]
        })
    }

    /// Where a pass along the contour ends: the first point of a closed
    /// contour, the last vertex of an open one.
    #[must_use]
    pub fn end(&self) -> Option<P2> {
        if self.is_closed() {
            return self.start();
        }
        (!self.is_empty()).then(|| {
            let v = self.pline.at(self.pline.vertex_count() - 1);
            [v.x, v.y]
        })
    }
}

/// A filled area of the plane: rings with the area on their left (outer
/// boundaries counter-clockwise, holes clockwise), not crossing each other.
#[derive(Debug, Clone, Default)]
pub struct Region {
    rings: Vec<Contour>,
}

impl Region {
    /// The empty region.
    #[must_use]
    pub fn empty() -> Region {
        Region { rings: Vec::new() }
    }

    /// A region of one outer boundary and holes inside it, each turned to the
    /// region's orientation (outer counter-clockwise, holes clockwise).
    ///
    /// # Errors
    /// [`ContourError::Degenerate`] when the outer boundary has no area.
    pub fn with_holes(outer: Contour, holes: Vec<Contour>) -> Result<Region, ContourError> {
        if outer.signed_area().abs() <= tol::MIN_AREA {
            return Err(ContourError::Degenerate { min_area: tol::MIN_AREA });
        }
        let mut rings = vec![if outer.is_ccw() { outer } else { outer.reversed() }];
        for h in holes {
            if h.signed_area().abs() > tol::MIN_AREA {
                rings.push(if h.is_ccw() { h.reversed() } else { h });
            }
        }
        Ok(Region { rings })
    }

    /// The union of polygons given as point rings, read with the non-zero
    /// rule when `oriented` is false (every ring fills its inside) and with
    /// the positive rule when it is true (a ring fills its left: clockwise
    /// rings are holes).
    #[must_use]
    pub fn from_polygons(rings: &[Vec<P2>], oriented: bool) -> Region {
        let subject: Vec<Vec<P2>> = rings.iter().filter(|r| r.len() >= 3).cloned().collect();
        let rule = if oriented { FillRule::Positive } else { FillRule::NonZero };
        let empty: Vec<Vec<P2>> = Vec::new();
        Region::from_shapes(&subject.overlay_as::<i64>(&empty, OverlayRule::Subject, rule))
    }

    /// As [`Region::from_polygons`], each ring first thinned by Douglas-Peucker
    /// at `eps` (mm): dense rings (sampled contours) offset faster and more
    /// robustly; the boundary moves by at most `eps`.
    #[must_use]
    pub fn from_polygons_simplified(rings: &[Vec<P2>], oriented: bool, eps: f64) -> Region {
        let thin: Vec<Vec<P2>> = rings.iter().map(|r| fit::simplify_ring(r, eps)).collect();
        Region::from_polygons(&thin, oriented)
    }

    fn from_shapes(shapes: &[Vec<Vec<P2>>]) -> Region {
        let mut rings = Vec::new();
        for shape in shapes {
            for (k, ring) in shape.iter().enumerate() {
                let Ok(c) = Contour::polygon(ring, true) else { continue };
                let a = c.signed_area();
                if a.abs() <= tol::MIN_AREA {
                    continue;
                }
                // i_overlay lists each shape's outer boundary first, then its holes.
                let want_ccw = k == 0;
                rings.push(if (a > 0.0) == want_ccw { c } else { c.reversed() });
            }
        }
        Region { rings }
    }

    /// The rings.
    #[must_use]
    pub fn rings(&self) -> &[Contour] {
        &self.rings
    }

    /// No ring.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.rings.is_empty()
    }

    /// Area (mm^2).
    #[must_use]
    pub fn area(&self) -> f64 {
        self.rings.iter().map(Contour::signed_area).sum()
    }

    /// `p` is inside (winding number above 0; a point on a ring is either).
    #[must_use]
    pub fn contains(&self, p: P2) -> bool {
        self.rings.iter().map(|r| r.winding_number(p)).sum::<i32>() > 0
    }

    /// The disc of radius `r` about `c` lies in the region: `c` is inside
    /// and no ring passes nearer than `r` (arcs exact). The same test as
    /// `self.offset(r).contains(c)` without building the offset.
    #[must_use]
    pub fn holds_disc(&self, c: P2, r: f64) -> bool {
        let q = cavalier_contours::core::math::Vector2::new(c[0], c[1]);
        self.contains(c)
            && self
                .rings
                .iter()
                .all(|ring| ring.pline.closest_point(q, tol::POS_EQUAL).is_none_or(|hit| hit.distance >= r))
    }

    /// Bounding box `(min, max)` of the rings' vertices and arcs.
    #[must_use]
    pub fn bounds(&self) -> Option<(P2, P2)> {
        let mut it = self.rings.iter().filter_map(|r| r.pline.extents());
        let first = it.next()?;
        let init = ([first.min_x, first.min_y], [first.max_x, first.max_y]);
        Some(it.fold(init, |(lo, hi), b| {
            ([lo[0].min(b.min_x), lo[1].min(b.min_y)], [hi[0].max(b.max_x), hi[1].max(b.max_y)])
        }))
    }

    /// The region offset inwards by `d` (outwards for `d < 0`), arcs kept:
    /// the points of the region at least `d` from its complement.
    #[must_use]
    pub fn offset(&self, d: f64) -> Region {
        if self.is_empty() {
            return Region::empty();
        }
        if d.abs() <= tol::POS_EQUAL {
            return self.clone();
        }
        let shape = Shape::from_plines(self.rings.iter().map(|r| r.pline.clone()));
        let options = ShapeOffsetOptions {
            pos_equal_eps: tol::POS_EQUAL,
            offset_dist_eps: tol::OFFSET_DIST,
            slice_join_eps: tol::OFFSET_DIST,
        };
        let out = shape.parallel_offset(d, &options);
        let rings = out
            .ccw_plines
            .into_iter()
            .chain(out.cw_plines)
            .map(|p| Contour::from_pline(p.polyline).without_folds(tol::FOLD_WIDTH))
            .filter(|c| c.signed_area().abs() > tol::MIN_AREA)
            .collect();
        Region { rings }
    }

    fn polygons(&self, tolerance: f64) -> Vec<Vec<P2>> {
        self.rings.iter().map(|r| r.to_points(tolerance)).collect()
    }

    fn boolean(&self, other: &Region, rule: OverlayRule, tolerance: f64) -> Region {
        let (a, b) = (self.polygons(tolerance), other.polygons(tolerance));
        Region::from_shapes(&a.overlay_as::<i64>(&b, rule, FillRule::Positive))
    }

    /// Union; arcs go through as chords within `tolerance` (mm).
    #[must_use]
    pub fn union(&self, other: &Region, tolerance: f64) -> Region {
        self.boolean(other, OverlayRule::Union, tolerance)
    }

    /// Intersection; arcs as chords within `tolerance` (mm).
    #[must_use]
    pub fn intersection(&self, other: &Region, tolerance: f64) -> Region {
        self.boolean(other, OverlayRule::Intersect, tolerance)
    }

    /// `self` minus `other`; arcs as chords within `tolerance` (mm).
    #[must_use]
    pub fn difference(&self, other: &Region, tolerance: f64) -> Region {
        self.boolean(other, OverlayRule::Difference, tolerance)
    }

    /// Whether the straight segment from `a` to `b` stays inside the region
    /// (its chords within `tolerance` of the arcs; touching the boundary counts
    /// as inside).
    #[must_use]
    pub fn contains_segment(&self, a: P2, b: P2, tolerance: f64) -> bool {
        if !(self.contains(a) && self.contains(b)) {
            return false;
        }
        let line = vec![a, b];
        let outside = line.clip_by_as::<i64>(
            &self.polygons(tolerance),
            FillRule::Positive,
            ClipRule { invert: true, boundary_included: false },
        );
        outside.iter().all(|piece| piece.windows(2).all(|w| dist(w[0], w[1]) <= tol::LINK_SLACK))
    }

    /// The connected parts: each outer boundary with the holes directly inside it.
    #[must_use]
    pub fn components(&self) -> Vec<Region> {
        let (outers, holes): (Vec<&Contour>, Vec<&Contour>) = self.rings.iter().partition(|r| r.is_ccw());
        let mut parts: Vec<Region> = outers.iter().map(|o| Region { rings: vec![(*o).clone()] }).collect();
        for h in holes {
            let Some(p) = h.start() else { continue };
            // The smallest outer boundary around the hole's first vertex holds it.
            let owner = outers
                .iter()
                .enumerate()
                .filter(|(_, o)| o.winding_number(p) != 0)
                .min_by(|a, b| a.1.signed_area().total_cmp(&b.1.signed_area()))
                .map(|(k, _)| k);
            if let Some(k) = owner {
                parts[k].rings.push(h.clone());
            }
        }
        parts
    }

    /// The rings that are outer boundaries (counter-clockwise).
    pub fn outers(&self) -> impl Iterator<Item = &Contour> {
        self.rings.iter().filter(|r| r.is_ccw())
    }
}

fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}
