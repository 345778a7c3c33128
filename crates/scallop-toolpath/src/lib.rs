//! The toolpath intermediate representation: moves of the tool tip in the
//! part frame (mm, mm/min), with their kind, and simple measures.
//!
//! ```
//! use scallop_geom::Point3;
//! use scallop_toolpath::{Move, MoveKind, Toolpath};
//! let mut path = Toolpath::new(1000.0);
//! path.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 10.0)));
//! path.push(Move::new(MoveKind::Plunge, Point3::new(0.0, 0.0, 0.0)));
//! path.push(Move::new(MoveKind::Feed, Point3::new(3.0, 4.0, 0.0)));
//! assert_eq!(path.length(MoveKind::Feed), 5.0);
//! ```
//!
//! # Invariants
//! - Never performs I/O. Coordinates are finite (checked by [`Toolpath::push`] in debug builds).
//! - Positions are tool tips in the part frame. The tool axis of a move is +Z
//!   unless the path carries tool axes ([`Toolpath::push_with_axis`]): a
//!   run-length side list, so a 3-axis path pays nothing and a 3+2 path one
//!   entry. Per-move feeds work the same way ([`Toolpath::set_feed_from`]).

use scallop_geom::{Point2, Point3, Vec3};

mod arcs;

pub use arcs::{
    ArcMove, ArcPlane, FittedPath, MAX_ARC_POINTS, MAX_CHORDS_PER_ARC, MAX_RADIUS, MAX_SWEEP, MIN_RADIUS, Segment,
    fit_arcs,
};

/// What a move is for; decides how it is emitted and coloured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MoveKind {
    /// Positioning at rapid rate, out of the material.
    Rapid,
    /// Descent into the material at the plunge feed.
    Plunge,
    /// Cutting move at the cutting feed.
    Feed,
    /// Connection between passes at cutting feed, on the CL surface.
    Link,
    /// Retract to the clearance height (emitted at rapid rate).
    Retract,
}

/// One straight move of the tool tip to `to`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Move {
    /// Kind of move.
    pub kind: MoveKind,
    /// End point of the tool tip (mm, part frame).
    pub to: Point3,
}

impl Move {
    /// A move of `kind` to `to`.
    #[must_use]
    pub fn new(kind: MoveKind, to: Point3) -> Move {
        Move { kind, to }
    }
}

/// The circle of a move that is a circular arc in the XY plane (G17), from
/// the previous move's end to the move's own `to`; z changes linearly with the
/// angle (a helix when the ends differ in z). Attached to a move by
/// [`Toolpath::push_arc`]; the move itself keeps its end point, so a consumer
/// that ignores arcs sees the chord.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcXY {
    /// Centre of the circle (mm).
    pub center: Point2,
    /// Signed swept angle (rad): positive counter-clockwise (G3), negative
    /// clockwise (G2); a full circle is +-2 pi.
    pub sweep: f64,
}

impl ArcXY {
    /// The points of the arc from `from` to `to` as chords whose sagitta is at
    /// most `sagitta` (mm), `from` excluded and `to` the last one; z linear in
    /// the angle. At most [`MAX_CHORDS_PER_ARC`] chords (a larger count is
    /// capped: its sagitta is then larger); one chord when the radius is within
    /// `sagitta`.
    ///
    /// ```
    /// use scallop_geom::{Point2, Point3};
    /// use scallop_toolpath::ArcXY;
    /// let half = ArcXY { center: Point2::origin(), sweep: std::f64::consts::PI };
    /// let (from, to) = (Point3::new(10.0, 0.0, 0.0), Point3::new(-10.0, 0.0, 1.0));
    /// let points = half.chords(&from, &to, 0.01);
    /// assert_eq!(points.last(), Some(&to));
    /// assert!(points.iter().all(|p| (p.x.hypot(p.y) - 10.0).abs() < 1e-9));
    /// // Each chord of a 10 mm circle within 0.01 mm sagitta spans at most 2 acos(0.999).
    /// assert!(points.len() as f64 >= std::f64::consts::PI / (2.0 * 0.999f64.acos()));
    /// ```
    #[must_use]
    pub fn chords(&self, from: &Point3, to: &Point3, sagitta: f64) -> Vec<Point3> {
        let c = self.center;
        let radius = (from.x - c.x).hypot(from.y - c.y);
        let n = if radius > sagitta && sagitta > 0.0 {
            let step = 2.0 * (1.0 - sagitta / radius).acos();
            // A whole number of chords, capped.
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            let n = (self.sweep.abs() / step).ceil().min(MAX_CHORDS_PER_ARC as f64) as usize;
            n.max(1)
        } else {
            1
        };
        let a0 = (from.y - c.y).atan2(from.x - c.x);
        let mut points: Vec<Point3> = (1..n)
            .map(|i| {
                let f = i as f64 / n as f64;
                let a = a0 + self.sweep * f;
                Point3::new(c.x + radius * a.cos(), c.y + radius * a.sin(), from.z + (to.z - from.z) * f)
            })
            .collect();
        points.push(*to);
        points
    }
}

/// A sequence of moves from an unspecified start (the first move is a rapid in practice).
#[derive(Debug, Clone, PartialEq)]
pub struct Toolpath {
    /// Cutting feed (mm/min).
    pub feed: f64,
    /// Plunge feed (mm/min).
    pub plunge_feed: f64,
    moves: Vec<Move>,
    /// (move index, arc), increasing indices; empty for straight-line paths.
    arcs: Vec<(usize, ArcXY)>,
    /// (first move index, unit tool axis), increasing indices: the axis of a
    /// move is that of the last entry at or before it, +Z before the first.
    axes: Vec<(usize, Vec3)>,
    /// (first move index, programmed feed in mm/min), increasing indices: the
    /// feed of a move is that of the last entry at or before it; before the
    /// first, the path's feed by kind ([`Toolpath::feed_of`]).
    feeds: Vec<(usize, f64)>,
}

impl Toolpath {
    /// An empty toolpath with the cutting feed; the plunge feed is half of it.
    #[must_use]
    pub fn new(feed: f64) -> Toolpath {
        Toolpath {
            feed,
            plunge_feed: 0.5 * feed,
            moves: Vec::new(),
            arcs: Vec::new(),
            axes: Vec::new(),
            feeds: Vec::new(),
        }
    }

    /// Appends a move with the tool axis `axis` (normalised here; part frame,
    /// from the tip towards the spindle). The axis holds for the following
    /// moves pushed with [`Toolpath::push`] too.
    ///
    /// ```
    /// use scallop_geom::{Point3, Vec3};
    /// use scallop_toolpath::{Move, MoveKind, Toolpath};
    /// let mut path = Toolpath::new(1000.0);
    /// path.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 10.0)));
    /// path.push_with_axis(Move::new(MoveKind::Feed, Point3::new(1.0, 0.0, 0.0)), Vec3::new(0.0, 3.0, 4.0));
    /// path.push(Move::new(MoveKind::Feed, Point3::new(2.0, 0.0, 0.0)));
    /// assert_eq!(path.axis(0), Vec3::z());
    /// assert_eq!(path.axis(2), Vec3::new(0.0, 0.6, 0.8));
    /// assert!(path.has_tool_axes());
    /// ```
    pub fn push_with_axis(&mut self, m: Move, axis: Vec3) {
        let n = axis.norm();
        debug_assert!(n.is_finite() && n > 0.0, "bad tool axis {axis:?}");
        let unit = axis / n;
        if self.current_axis() != unit {
            self.axes.push((self.moves.len(), unit));
        }
        self.push(m);
    }

    /// Appends a move along an XY arc (as [`Toolpath::push_arc`]) with the
    /// tool axis `axis` (as [`Toolpath::push_with_axis`]).
    ///
    /// ```
    /// use scallop_geom::{Point2, Point3, Vec3};
    /// use scallop_toolpath::{ArcXY, Move, MoveKind, Toolpath};
    /// let mut path = Toolpath::new(1000.0);
    /// path.push(Move::new(MoveKind::Feed, Point3::new(10.0, 0.0, 0.0)));
    /// let half = ArcXY { center: Point2::new(5.0, 0.0), sweep: std::f64::consts::PI };
    /// path.push_arc_with_axis(Move::new(MoveKind::Feed, Point3::new(0.0, 0.0, 0.0)), Vec3::x(), half);
    /// assert_eq!((path.arc(1), path.axis(1)), (Some(half), Vec3::x()));
    /// ```
    pub fn push_arc_with_axis(&mut self, m: Move, axis: Vec3, arc: ArcXY) {
        let n = axis.norm();
        debug_assert!(n.is_finite() && n > 0.0, "bad tool axis {axis:?}");
        let unit = axis / n;
        if self.current_axis() != unit {
            self.axes.push((self.moves.len(), unit));
        }
        self.push_arc(m, arc);
    }

    /// The tool axis of move `index` (unit, part frame).
    #[must_use]
    pub fn axis(&self, index: usize) -> Vec3 {
        match self.axes.partition_point(|&(k, _)| k <= index) {
            0 => Vec3::z(),
            slot => self.axes[slot - 1].1,
        }
    }

    /// Whether any move has a tool axis other than +Z.
    #[must_use]
    pub fn has_tool_axes(&self) -> bool {
        self.axes.iter().any(|&(_, a)| a != Vec3::z())
    }

    fn current_axis(&self) -> Vec3 {
        self.axes.last().map_or(Vec3::z(), |&(_, a)| a)
    }

    /// Sets the programmed feed (mm/min) of the moves from the next one pushed
    /// on; `None` returns to the path's feeds by kind.
    ///
    /// ```
    /// use scallop_geom::Point3;
    /// use scallop_toolpath::{Move, MoveKind, Toolpath};
    /// let mut path = Toolpath::new(1000.0);
    /// path.push(Move::new(MoveKind::Plunge, Point3::new(0.0, 0.0, 0.0)));
    /// path.set_feed_from(Some(250.0));
    /// path.push(Move::new(MoveKind::Feed, Point3::new(1.0, 0.0, 0.0)));
    /// assert_eq!((path.feed_of(0), path.feed_of(1)), (500.0, 250.0));
    /// assert!(path.has_feeds());
    /// ```
    pub fn set_feed_from(&mut self, feed: Option<f64>) {
        let feed = feed.unwrap_or(f64::NAN);
        debug_assert!(feed.is_nan() || (feed.is_finite() && feed > 0.0), "bad feed {feed}");
        let current = self.feeds.last().map_or(f64::NAN, |&(_, f)| f);
        if current.to_bits() != feed.to_bits() {
            match self.feeds.last_mut() {
                Some(last) if last.0 == self.moves.len() => last.1 = feed,
                _ => self.feeds.push((self.moves.len(), feed)),
            }
        }
    }

    /// The programmed feed of move `index` (mm/min): the one set by
    /// [`Toolpath::set_feed_from`], else the plunge feed for plunges and the
    /// cutting feed for the rest (rapids included: their rate is the machine's).
    #[must_use]
    pub fn feed_of(&self, index: usize) -> f64 {
        let set = match self.feeds.partition_point(|&(k, _)| k <= index) {
            0 => f64::NAN,
            slot => self.feeds[slot - 1].1,
        };
        if !set.is_nan() {
            return set;
        }
        match self.moves.get(index).map(|m| m.kind) {
            Some(MoveKind::Plunge) => self.plunge_feed,
            _ => self.feed,
        }
    }

    /// Whether some moves carry a feed of their own.
    #[must_use]
    pub fn has_feeds(&self) -> bool {
        self.feeds.iter().any(|&(_, f)| !f.is_nan())
    }

    /// Appends the moves of `other` with their arcs, tool axes and feeds.
    ///
    /// ```
    /// use scallop_geom::{Point3, Vec3};
    /// use scallop_toolpath::{Move, MoveKind, Toolpath};
    /// let mut a = Toolpath::new(1000.0);
    /// a.push(Move::new(MoveKind::Feed, Point3::new(0.0, 0.0, 0.0)));
    /// let mut b = Toolpath::new(1000.0);
    /// b.push_with_axis(Move::new(MoveKind::Feed, Point3::new(1.0, 0.0, 0.0)), Vec3::x());
    /// a.extend_from(&b);
    /// assert_eq!((a.moves().len(), a.axis(1)), (2, Vec3::x()));
    /// ```
    pub fn extend_from(&mut self, other: &Toolpath) {
        for (i, m) in other.moves.iter().enumerate() {
            self.set_feed_from(other.feed_override(i));
            let axis = other.axis(i);
            if axis != self.current_axis() {
                self.axes.push((self.moves.len(), axis));
            }
            match other.arc(i) {
                Some(arc) => self.push_arc(*m, arc),
                None => self.push(*m),
            }
        }
        self.set_feed_from(None);
    }

    /// The feed move `index` carries of its own (mm/min), `None` when it takes
    /// the path's feed by kind.
    #[must_use]
    pub fn feed_override(&self, index: usize) -> Option<f64> {
        match self.feeds.partition_point(|&(k, _)| k <= index) {
            0 => None,
            slot => Some(self.feeds[slot - 1].1).filter(|f| !f.is_nan()),
        }
    }

    /// Appends a move along a circular arc in the XY plane ending at `m.to`
    /// (see [`ArcXY`]).
    ///
    /// ```
    /// use scallop_geom::{Point2, Point3};
    /// use scallop_toolpath::{ArcXY, Move, MoveKind, Toolpath};
    /// let mut path = Toolpath::new(1000.0);
    /// path.push(Move::new(MoveKind::Feed, Point3::new(10.0, 0.0, 0.0)));
    /// let half = ArcXY { center: Point2::new(5.0, 0.0), sweep: std::f64::consts::PI };
    /// path.push_arc(Move::new(MoveKind::Feed, Point3::new(0.0, 0.0, 0.0)), half);
    /// assert_eq!(path.arc(1), Some(half));
    /// assert_eq!(path.arc(0), None);
    /// assert_eq!(path.arc_count(), 1);
    /// ```
    pub fn push_arc(&mut self, m: Move, arc: ArcXY) {
        debug_assert!(arc.center.coords.iter().all(|c| c.is_finite()) && arc.sweep.is_finite(), "bad arc {arc:?}");
        self.arcs.push((self.moves.len(), arc));
        self.push(m);
    }

    /// The arc of move `index`, `None` for a straight move.
    #[must_use]
    pub fn arc(&self, index: usize) -> Option<ArcXY> {
        self.arcs.binary_search_by_key(&index, |&(k, _)| k).ok().map(|slot| self.arcs[slot].1)
    }

    /// Number of arc moves.
    #[must_use]
    pub fn arc_count(&self) -> usize {
        self.arcs.len()
    }

    /// Appends a move.
    pub fn push(&mut self, m: Move) {
        debug_assert!(m.to.coords.iter().all(|c| c.is_finite()), "non-finite move {m:?}");
        self.moves.push(m);
    }

    /// The moves.
    #[must_use]
    pub fn moves(&self) -> &[Move] {
        &self.moves
    }

    /// Total length of the moves of `kind` (mm); the first move has no length.
    #[must_use]
    pub fn length(&self, kind: MoveKind) -> f64 {
        self.moves.windows(2).filter(|w| w[1].kind == kind).map(|w| (w[1].to - w[0].to).norm()).sum()
    }

    /// Number of moves of `kind`.
    #[must_use]
    pub fn count(&self, kind: MoveKind) -> usize {
        self.moves.iter().filter(|m| m.kind == kind).count()
    }
}

/// Removes interior points of a polyline whose removal keeps every removed
/// point within `max_deviation` of the kept chord (Douglas-Peucker, iterative,
/// endpoints kept). Returns the indices kept, in order.
///
/// ```
/// use scallop_geom::Point3;
/// let line: Vec<Point3> = (0..10).map(|i| Point3::new(f64::from(i), 0.0, 0.0)).collect();
/// assert_eq!(scallop_toolpath::simplify(&line, 1e-9), vec![0, 9]);
/// ```
#[must_use]
pub fn simplify(points: &[Point3], max_deviation: f64) -> Vec<usize> {
    douglas_peucker(points, |pa, pb, interior| {
        let ab = pb - pa;
        let len2 = ab.norm_squared();
        let mut worst = (0.0f64, None);
        for (k, p) in interior {
            let ap = p - pa;
            let d = if len2 > 0.0 { (ap - ab * (ap.dot(&ab) / len2).clamp(0.0, 1.0)).norm() } else { ap.norm() };
            if d > worst.0 {
                worst = (d, Some(k));
            }
        }
        if worst.0 > max_deviation { worst.1 } else { None }
    })
}

/// Iterative Douglas-Peucker: `split(a, b, interior)` returns the interior point
/// (index, from `interior`: the points strictly between `a` and `b`) that must be
/// kept, if any; the endpoints are always kept. Returns the kept indices in order.
fn douglas_peucker<'p>(
    points: &'p [Point3],
    split: impl Fn(Point3, Point3, &mut dyn Iterator<Item = (usize, &'p Point3)>) -> Option<usize>,
) -> Vec<usize> {
    let n = points.len();
    if n <= 2 {
        return (0..n).collect();
    }
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[n - 1] = true;
    let mut stack = vec![(0usize, n - 1)];
    while let Some((a, b)) = stack.pop() {
        let mut interior = points.iter().enumerate().take(b).skip(a + 1);
        if let Some(k) = split(points[a], points[b], &mut interior) {
            keep[k] = true;
            stack.push((a, k));
            stack.push((k, b));
        }
    }
    (0..n).filter(|&i| keep[i]).collect()
}

/// Like [`simplify`], but one-sided for a 3-axis CL polyline: a point is
/// removed only when the kept chord passes through or above it (never below: a
/// chord below a CL point would drive the cutter into the part) and within
/// `max_deviation` of it. Vertical offsets are measured at the point's
/// position along the chord in XY. Returns the indices kept, in order.
///
/// ```
/// use scallop_geom::Point3;
/// // A hill: straight chords would pass below the crest, so the crest is kept.
/// let hill: Vec<Point3> = (0..11).map(|i| f64::from(i)).map(|x| Point3::new(x, 0.0, -0.001 * (x - 5.0).powi(2))).collect();
/// assert!(scallop_toolpath::simplify_above(&hill, 1.0).len() > 2);
/// // A valley: the chord lies above every point, so it goes.
/// let valley: Vec<Point3> = hill.iter().map(|p| Point3::new(p.x, 0.0, -p.z)).collect();
/// assert_eq!(scallop_toolpath::simplify_above(&valley, 1.0), vec![0, 10]);
/// ```
#[must_use]
pub fn simplify_above(points: &[Point3], max_deviation: f64) -> Vec<usize> {
    douglas_peucker(points, |pa, pb, interior| {
        let ab = pb - pa;
        let len2 = ab.xy().norm_squared();
        // The worst offender: any point above the chord, else the largest deviation.
        let mut worst: Option<(bool, f64, usize)> = None;
        for (k, p) in interior {
            let t = if len2 > 0.0 { ((p - pa).xy().dot(&ab.xy()) / len2).clamp(0.0, 1.0) } else { 0.0 };
            let chord = pa + ab * t;
            let (above, dev) = (p.z > chord.z, (p - chord).norm());
            if above || dev > max_deviation {
                let candidate = (above, dev, k);
                worst = Some(match worst {
                    Some(w) if (w.0, w.1) >= (candidate.0, candidate.1) => w,
                    _ => candidate,
                });
            }
        }
        worst.map(|w| w.2)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simplify_keeps_deviation_within_budget() {
        let pts: Vec<Point3> =
            (0..200).map(|i| f64::from(i) * 0.05).map(|x| Point3::new(x, 0.0, (x * 1.3).sin())).collect();
        let tol = 0.01;
        let kept = simplify(&pts, tol);
        assert!(kept.len() < pts.len() / 2);
        for w in kept.windows(2) {
            let (a, b) = (pts[w[0]], pts[w[1]]);
            for p in &pts[w[0]..=w[1]] {
                let ab = b - a;
                let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                assert!((p - a - ab * t).norm() <= tol + 1e-12);
            }
        }
        // idempotent
        let again: Vec<Point3> = kept.iter().map(|&i| pts[i]).collect();
        assert_eq!(simplify(&again, tol).len(), again.len());
    }

    #[test]
    fn simplify_above_never_passes_below_a_removed_point() {
        let pts: Vec<Point3> = (0..400)
            .map(|i| f64::from(i) * 0.05)
            .map(|x| Point3::new(x, 0.3 * x, (x * 1.3).sin() + 0.2 * (x * 5.1).cos()))
            .collect();
        let tol = 0.01;
        let kept = simplify_above(&pts, tol);
        assert!(kept.len() < pts.len());
        for w in kept.windows(2) {
            let (a, b) = (pts[w[0]], pts[w[1]]);
            let ab = b - a;
            for p in &pts[w[0]..=w[1]] {
                let t = ((p - a).xy().dot(&ab.xy()) / ab.xy().norm_squared()).clamp(0.0, 1.0);
                let chord = a + ab * t;
                assert!(p.z <= chord.z + 1e-12, "chord below a CL point at {p}");
                assert!((p - chord).norm() <= tol + 1e-12);
            }
        }
    }
}
