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
//! - The tool axis is +Z (3-axis); multi-axis poses come with the machine layer.

use scallop_geom::Point3;

mod arcs;

pub use arcs::{ArcMove, ArcPlane, FittedPath, MAX_ARC_POINTS, MAX_RADIUS, MAX_SWEEP, MIN_RADIUS, Segment, fit_arcs};

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

/// A sequence of moves from an unspecified start (the first move is a rapid in practice).
#[derive(Debug, Clone, PartialEq)]
pub struct Toolpath {
    /// Cutting feed (mm/min).
    pub feed: f64,
    /// Plunge feed (mm/min).
    pub plunge_feed: f64,
    moves: Vec<Move>,
}

impl Toolpath {
    /// An empty toolpath with the cutting feed; the plunge feed is half of it.
    #[must_use]
    pub fn new(feed: f64) -> Toolpath {
        Toolpath { feed, plunge_feed: 0.5 * feed, moves: Vec::new() }
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
