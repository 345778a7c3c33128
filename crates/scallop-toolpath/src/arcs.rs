//! Arc fitting: runs of consecutive cutting moves replaced by circular (or helical)
//! arcs in one of the three principal planes, the only planes ISO controllers
//! (LinuxCNC, Fanuc, grbl) interpolate: `G17` XY, `G18` ZX, `G19` YZ.
//!
//! A parallel-planes pass lies in a vertical plane; it can become arcs only when
//! that plane is a principal one (feed direction a multiple of 90 degrees: `G18`
//! or `G19`); horizontal runs (constant Z) become `G17` arcs. Controllers move
//! the plane's normal axis linearly with the angle (a helix), so a run may drift
//! along the normal; the drift is part of the checked deviation.
//!
//! **Guarantee.** Every toolpath vertex a [`Segment::Arc`] replaces, and the
//! midpoint of every replaced chord, lies within `tolerance` of the emitted arc
//! (radial error in the plane combined with the normal error at the same angle).
//! Arcs turn less than [`MAX_SWEEP`] and have radii below [`MAX_RADIUS`].

use std::f64::consts::PI;

use scallop_geom::Point3;

use crate::{Move, MoveKind, Toolpath};

/// Largest angle (rad) one arc turns: below a half turn, so the `R` form is
/// unambiguous and no controller reads a full circle.
pub const MAX_SWEEP: f64 = 0.95 * PI;

/// Largest arc radius (mm): flatter runs stay lines (an arc gains nothing there
/// and its centre words would be huge).
pub const MAX_RADIUS: f64 = 1000.0;

/// Smallest arc radius (mm): tighter circles are left as lines (their centre is
/// sensitive to the rounding of the emitted words).
pub const MIN_RADIUS: f64 = 0.05;

/// Most toolpath vertices one arc may replace (bounds the quadratic check).
pub const MAX_ARC_POINTS: usize = 512;

/// Most chords [`crate::ArcXY::chords`] cuts one arc into (bounds the work and
/// memory of a tiny sagitta on a large arc).
pub const MAX_CHORDS_PER_ARC: usize = 65_536;

/// A principal plane of circular interpolation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ArcPlane {
    /// `G17`: the XY plane, normal +Z.
    Xy,
    /// `G18`: the ZX plane, normal +Y.
    Zx,
    /// `G19`: the YZ plane, normal +X.
    Yz,
}

impl ArcPlane {
    /// Coordinate indices `(u, v, n)` of the plane, right-handed (`u x v = n`).
    ///
    /// ```
    /// assert_eq!(scallop_toolpath::ArcPlane::Zx.axes(), (2, 0, 1));
    /// ```
    #[must_use]
    pub fn axes(self) -> (usize, usize, usize) {
        match self {
            ArcPlane::Xy => (0, 1, 2),
            ArcPlane::Zx => (2, 0, 1),
            ArcPlane::Yz => (1, 2, 0),
        }
    }

    /// The plane-selection code (`G17`, `G18`, `G19`).
    #[must_use]
    pub fn code(self) -> &'static str {
        match self {
            ArcPlane::Xy => "G17",
            ArcPlane::Zx => "G18",
            ArcPlane::Yz => "G19",
        }
    }
}

/// A circular or helical move from the previous position to `to`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcMove {
    /// `Feed` or `Link`.
    pub kind: MoveKind,
    /// End point (mm).
    pub to: Point3,
    /// Centre (mm); its normal coordinate is the start's (only `u`, `v` matter).
    pub center: Point3,
    /// Plane of the circle.
    pub plane: ArcPlane,
    /// Counter-clockwise seen from the positive end of the plane's normal (`G3`);
    /// else clockwise (`G2`).
    pub ccw: bool,
    /// Angle turned (rad, positive).
    pub sweep: f64,
}

impl ArcMove {
    /// Radius in the plane (mm).
    #[must_use]
    pub fn radius(&self) -> f64 {
        let (u, v, _) = self.plane.axes();
        (self.to[u] - self.center[u]).hypot(self.to[v] - self.center[v])
    }

    /// The point at fraction `s` in `[0, 1]` of the arc that starts at `from`.
    #[must_use]
    pub fn point_at(&self, from: &Point3, s: f64) -> Point3 {
        let (u, v, n) = self.plane.axes();
        let (c, r) = ((self.center[u], self.center[v]), self.radius());
        let a0 = (from[v] - c.1).atan2(from[u] - c.0);
        let a = a0 + if self.ccw { s * self.sweep } else { -s * self.sweep };
        let mut p = *from;
        p[u] = c.0 + r * a.cos();
        p[v] = c.1 + r * a.sin();
        p[n] = from[n] + s * (self.to[n] - from[n]);
        p
    }
}

/// One output segment of [`fit_arcs`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Segment {
    /// A straight move, as in the toolpath.
    Line(Move),
    /// An arc replacing toolpath moves.
    Arc(ArcMove),
}

impl Segment {
    /// End point.
    #[must_use]
    pub fn to(&self) -> Point3 {
        match self {
            Segment::Line(m) => m.to,
            Segment::Arc(a) => a.to,
        }
    }
}

/// The result of [`fit_arcs`]: segments and, per segment, the index of the last
/// toolpath move it replaces (so segment `k` covers the moves after
/// `last[k - 1]` up to `last[k]`).
#[derive(Debug, Clone, PartialEq)]
pub struct FittedPath {
    /// Segments in order.
    pub segments: Vec<Segment>,
    /// Index of the last toolpath move of each segment.
    pub last: Vec<usize>,
    /// Cutting feed (mm/min).
    pub feed: f64,
    /// Plunge feed (mm/min).
    pub plunge_feed: f64,
}

impl FittedPath {
    /// The path without arcs (every move a line).
    #[must_use]
    pub fn lines(path: &Toolpath) -> FittedPath {
        FittedPath {
            segments: path.moves().iter().map(|m| Segment::Line(*m)).collect(),
            last: (0..path.moves().len()).collect(),
            feed: path.feed,
            plunge_feed: path.plunge_feed,
        }
    }

    /// The path with its XY arcs ([`Toolpath::arc`]) as `G17` arc segments and
    /// every other move a line: arcs planned as arcs, written as they are.
    ///
    /// ```
    /// use scallop_geom::{Point2, Point3};
    /// use scallop_toolpath::{ArcXY, FittedPath, Move, MoveKind, Segment, Toolpath};
    /// let mut path = Toolpath::new(1000.0);
    /// path.push(Move::new(MoveKind::Rapid, Point3::new(10.0, 0.0, 0.0)));
    /// let quarter = ArcXY { center: Point2::new(0.0, 0.0), sweep: -std::f64::consts::FRAC_PI_2 };
    /// path.push_arc(Move::new(MoveKind::Feed, Point3::new(0.0, -10.0, 0.0)), quarter);
    /// let f = FittedPath::with_xy_arcs(&path);
    /// let Segment::Arc(a) = f.segments[1] else { panic!("an arc") };
    /// assert!(!a.ccw && (a.sweep - std::f64::consts::FRAC_PI_2).abs() < 1e-15 && a.radius() == 10.0);
    /// ```
    #[must_use]
    pub fn with_xy_arcs(path: &Toolpath) -> FittedPath {
        let moves = path.moves();
        let segments = moves
            .iter()
            .enumerate()
            .map(|(k, m)| match (k, path.arc(k)) {
                (1.., Some(arc)) => Segment::Arc(ArcMove {
                    kind: m.kind,
                    to: m.to,
                    center: Point3::new(arc.center.x, arc.center.y, moves[k - 1].to.z),
                    plane: ArcPlane::Xy,
                    ccw: arc.sweep > 0.0,
                    sweep: arc.sweep.abs(),
                }),
                _ => Segment::Line(*m),
            })
            .collect();
        FittedPath { segments, last: (0..moves.len()).collect(), feed: path.feed, plunge_feed: path.plunge_feed }
    }

    /// Number of arcs.
    #[must_use]
    pub fn arcs(&self) -> usize {
        self.segments.iter().filter(|s| matches!(s, Segment::Arc(_))).count()
    }
}

/// Replaces runs of at least two consecutive `Feed` (or `Link`) moves by arcs in a
/// principal plane, each within `tolerance` (mm) of every vertex and chord midpoint
/// it replaces (see the module docs). Greedy: from each start the longest run that
/// fits is taken, planes tried in the order XY, ZX, YZ. A non-positive or
/// non-finite tolerance fits nothing.
///
/// ```
/// use scallop_geom::Point3;
/// use scallop_toolpath::{fit_arcs, Move, MoveKind, Segment, Toolpath};
/// // A quarter circle of radius 10 in the ZX plane, sampled every 3 degrees.
/// let mut path = Toolpath::new(1000.0);
/// path.push(Move::new(MoveKind::Rapid, Point3::new(10.0, 2.0, 0.0)));
/// for i in 1..=30 {
///     let a = f64::from(i) * 3f64.to_radians();
///     path.push(Move::new(MoveKind::Feed, Point3::new(10.0 * a.cos(), 2.0, 10.0 * a.sin())));
/// }
/// let fitted = fit_arcs(&path, 5e-3); // the 3-degree chords bulge 3.4 um from the circle
/// assert_eq!(fitted.segments.len(), 2);
/// assert!(matches!(fitted.segments[1], Segment::Arc(a) if (a.radius() - 10.0).abs() < 1e-9));
/// ```
#[must_use]
pub fn fit_arcs(path: &Toolpath, tolerance: f64) -> FittedPath {
    let moves = path.moves();
    let mut out = FittedPath { segments: Vec::new(), last: Vec::new(), feed: path.feed, plunge_feed: path.plunge_feed };
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return FittedPath::lines(path);
    }
    let mut i = 0;
    while i < moves.len() {
        let m = moves[i];
        // An arc starts at the previous position (moves[i - 1].to) and needs at
        // least two moves of one cutting kind.
        let arcable = |k: usize| matches!(moves[k].kind, MoveKind::Feed | MoveKind::Link) && moves[k].kind == m.kind;
        let mut best: Option<(usize, ArcMove)> = None;
        if i > 0 && arcable(i) {
            let start = i - 1;
            let mut end = i + 1;
            while end < moves.len() && arcable(end) && end - start <= MAX_ARC_POINTS {
                let pts: Vec<Point3> = moves[start..=end].iter().map(|m| m.to).collect();
                // Greedy: grow while the run fits; the first misfit ends it.
                match fit_run(&pts, m.kind, tolerance) {
                    Some(a) => best = Some((end, a)),
                    None => break,
                }
                end += 1;
            }
        }
        if let Some((end, arc)) = best {
            out.segments.push(Segment::Arc(arc));
            out.last.push(end);
            i = end + 1;
        } else {
            out.segments.push(Segment::Line(m));
            out.last.push(i);
            i += 1;
        }
    }
    out
}

/// An arc through `pts` (first = start position) within `tolerance`, if any.
fn fit_run(pts: &[Point3], kind: MoveKind, tolerance: f64) -> Option<ArcMove> {
    for plane in [ArcPlane::Xy, ArcPlane::Zx, ArcPlane::Yz] {
        if let Some(a) = fit_in_plane(pts, plane, kind, tolerance) {
            return Some(a);
        }
    }
    None
}

fn fit_in_plane(pts: &[Point3], plane: ArcPlane, kind: MoveKind, tolerance: f64) -> Option<ArcMove> {
    let (u, v, n) = plane.axes();
    let (first, last) = (pts[0], pts[pts.len() - 1]);
    let mid = pts[pts.len() / 2];
    // Circle through first, mid and last in the plane.
    let (ax, ay) = (first[u], first[v]);
    let (bx, by) = (mid[u] - ax, mid[v] - ay);
    let (cx, cy) = (last[u] - ax, last[v] - ay);
    let d = 2.0 * (bx * cy - by * cx);
    let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
    if d.abs() <= f64::EPSILON * (b2 + c2) {
        return None; // collinear in this plane
    }
    let (ox, oy) = ((cy * b2 - by * c2) / d, (bx * c2 - cx * b2) / d);
    let r = ox.hypot(oy);
    if !(MIN_RADIUS..=MAX_RADIUS).contains(&r) {
        return None;
    }
    let center = (ax + ox, ay + oy);
    let ccw = d > 0.0;
    let angle = |p: &Point3| (p[v] - center.1).atan2(p[u] - center.0);
    let a0 = angle(&first);
    // Unwrapped signed progress of each point along the turning direction.
    let progress = |p: &Point3| {
        let mut da = angle(p) - a0;
        if !ccw {
            da = -da;
        }
        da.rem_euclid(2.0 * PI)
    };
    let sweep = progress(&last);
    if !(sweep > 0.0 && sweep < MAX_SWEEP) {
        return None;
    }
    let (n0, n1) = (first[n], last[n]);
    let deviation = |p: &Point3| -> Option<f64> {
        let s = progress(p);
        if s > sweep + 1e-12 && s < 2.0 * PI - 1e-9 {
            return None; // beyond the end: not on this arc
        }
        let s = if s > sweep { 0.0 } else { s };
        let radial = (p[u] - center.0).hypot(p[v] - center.1) - r;
        let normal = p[n] - (n0 + (n1 - n0) * s / sweep);
        Some(radial.hypot(normal))
    };
    let mut previous = -1.0;
    for w in pts.windows(2) {
        let s = progress(&w[1]);
        if s <= previous - 1e-12 && s < 2.0 * PI - 1e-9 {
            return None; // the points go back: not a monotone arc
        }
        previous = s;
        let midpoint = Point3::from((w[0].coords + w[1].coords) * 0.5);
        for p in [w[1], midpoint] {
            if deviation(&p).is_none_or(|e| e > tolerance) {
                return None;
            }
        }
    }
    let mut c = first;
    c[u] = center.0;
    c[v] = center.1;
    Some(ArcMove { kind, to: last, center: c, plane, ccw, sweep })
}

#[cfg(test)]
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
mod tests {
    use super::*;

    fn helix(plane: ArcPlane, radius: f64, turn: f64, drift: f64, n: usize) -> Toolpath {
        let (u, v, w) = plane.axes();
        let mut path = Toolpath::new(1000.0);
        let at = |s: f64| {
            let mut p = Point3::new(1.0, 2.0, 3.0);
            p[u] += radius * (turn * s).cos();
            p[v] += radius * (turn * s).sin();
            p[w] += drift * s;
            p
        };
        path.push(Move::new(MoveKind::Rapid, at(0.0)));
        for i in 1..=n {
            #[allow(clippy::cast_precision_loss, reason = "small counts")]
            path.push(Move::new(MoveKind::Feed, at(i as f64 / n as f64)));
        }
        path
    }

    #[test]
    fn every_replaced_point_lies_on_the_emitted_arc() {
        for plane in [ArcPlane::Xy, ArcPlane::Zx, ArcPlane::Yz] {
            for (turn, drift) in [(2.5, 0.0), (-2.5, 0.0), (5.0, 3.0), (-1.0, -0.5)] {
                let path = helix(plane, 7.0, turn, drift, 400);
                let tol = 1e-3;
                let fitted = fit_arcs(&path, tol);
                assert!(fitted.arcs() >= 1, "{plane:?} {turn}");
                let mut from = path.moves()[0].to;
                let mut first = 1;
                for (seg, &last) in fitted.segments.iter().zip(&fitted.last).skip(1) {
                    if let Segment::Arc(a) = seg {
                        assert_eq!(a.plane, plane);
                        for m in path.moves()[first..=last].iter().step_by(7) {
                            // Sampled every < 0.4 um along the arc.
                            let d = (0..=50_000)
                                .map(|k| (a.point_at(&from, f64::from(k) / 50_000.0) - m.to).norm())
                                .fold(f64::INFINITY, f64::min);
                            assert!(d <= tol + 4e-4, "{plane:?}: {d}");
                        }
                    }
                    from = seg.to();
                    first = last + 1;
                }
                assert_eq!(fitted.last.last(), Some(&(path.moves().len() - 1)));
            }
        }
    }

    #[test]
    fn straight_runs_and_corners_stay_lines() {
        let mut path = Toolpath::new(1000.0);
        path.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 0.0)));
        for i in 1..50 {
            let t = f64::from(i) * 0.2;
            path.push(Move::new(MoveKind::Feed, Point3::new(t * 0.6, t * 0.8, -0.3 * t)));
        }
        path.push(Move::new(MoveKind::Feed, Point3::new(0.0, 20.0, 0.0)));
        path.push(Move::new(MoveKind::Plunge, Point3::new(0.0, 20.0, -5.0)));
        let fitted = fit_arcs(&path, 1e-3);
        assert_eq!(fitted.arcs(), 0);
        assert_eq!(fitted, FittedPath::lines(&path));
    }
}
