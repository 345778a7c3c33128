//! The walls of a tool-centre region as chords in buckets, for the exact
//! tests of adaptive clearing's short steps: whether a point lies in the
//! region (crossings of a ray, even-odd) and whether a step leaves it (a
//! proper crossing of a wall, or an end outside).

use scallop_contour::{P2, Region};

/// The chords of a region's rings, bucketed by squares.
pub(crate) struct Edges {
    segs: Vec<(P2, P2)>,
    x0: f64,
    y0: f64,
    side: f64,
    nx: usize,
    ny: usize,
    buckets: Vec<Vec<u32>>,
}

fn dist2(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// The sign of the turn a, b, c (positive: counter-clockwise).
fn orient(a: P2, b: P2, c: P2) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

impl Edges {
    /// The rings of `region` as chords within `chord` (mm), in buckets of
    /// side `side` (mm).
    pub fn new(region: &Region, chord: f64, side: f64) -> Edges {
        let mut segs = Vec::new();
        for ring in region.rings() {
            let pts = ring.to_points(chord);
            for (k, a) in pts.iter().enumerate() {
                let b = pts[(k + 1) % pts.len()];
                if dist2(*a, b) > 0.0 {
                    segs.push((*a, b));
                }
            }
        }
        let (lo, hi) = region.bounds().unwrap_or(([0.0, 0.0], [0.0, 0.0]));
        let side = side.max(1e-6);
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "bounded positive counts")]
        let (nx, ny) = (((hi[0] - lo[0]) / side).ceil() as usize + 3, ((hi[1] - lo[1]) / side).ceil() as usize + 3);
        let mut edges =
            Edges { segs: Vec::new(), x0: lo[0] - side, y0: lo[1] - side, side, nx, ny, buckets: Vec::new() };
        edges.buckets = vec![Vec::new(); nx * ny];
        for (k, &(a, b)) in segs.iter().enumerate() {
            let (i0, j0) = edges.cell([a[0].min(b[0]), a[1].min(b[1])]);
            let (i1, j1) = edges.cell([a[0].max(b[0]), a[1].max(b[1])]);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    #[allow(clippy::cast_possible_truncation, reason = "segment counts are far below 2^32")]
                    edges.buckets[j * nx + i].push(k as u32);
                }
            }
        }
        edges.segs = segs;
        edges
    }

    /// The bucket of `p`, clamped to the grid.
    fn cell(&self, p: P2) -> (usize, usize) {
        #[allow(
            clippy::cast_possible_truncation,
            clippy::cast_sign_loss,
            clippy::cast_precision_loss,
            reason = "clamped"
        )]
        let c = |v: f64, n: usize| v.floor().clamp(0.0, (n - 1) as f64) as usize;
        (c((p[0] - self.x0) / self.side, self.nx), c((p[1] - self.y0) / self.side, self.ny))
    }

    /// Whether `p` lies in the region: the walls crossed by the ray from `p`
    /// towards +x, each counted in the bucket that holds the crossing.
    pub fn contains(&self, p: P2) -> bool {
        let (i0, j) = self.cell(p);
        let mut odd = false;
        for i in i0..self.nx {
            #[allow(clippy::cast_precision_loss, reason = "grid indices")]
            let (bx0, bx1) = (self.x0 + i as f64 * self.side, self.x0 + (i + 1) as f64 * self.side);
            for &k in &self.buckets[j * self.nx + i] {
                let (a, b) = self.segs[k as usize];
                if (a[1] > p[1]) == (b[1] > p[1]) {
                    continue;
                }
                let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
                let last = i + 1 == self.nx;
                if x > p[0] && (x >= bx0 || i == i0) && (x < bx1 || last) {
                    odd = !odd;
                }
            }
        }
        odd
    }

    /// Whether the step from `a` (in the region) to `b` stays in it: `b`
    /// inside and no wall crossed on the way (touching a wall is inside).
    pub fn contains_segment(&self, a: P2, b: P2) -> bool {
        self.contains(b)
            && !self.walls_near(a, b, 0.0).any(|(p, q)| {
                let (o1, o2) = (orient(p, q, a), orient(p, q, b));
                let (o3, o4) = (orient(a, b, p), orient(a, b, q));
                o1 * o2 < 0.0 && o3 * o4 < 0.0
            })
    }

    /// The walls in the buckets that hold the box of `a`-`b` grown by `margin`
    /// (a wall in several buckets comes once per bucket).
    fn walls_near(&self, a: P2, b: P2, margin: f64) -> impl Iterator<Item = (P2, P2)> + '_ {
        let (i0, j0) = self.cell([a[0].min(b[0]) - margin, a[1].min(b[1]) - margin]);
        let (i1, j1) = self.cell([a[0].max(b[0]) + margin, a[1].max(b[1]) + margin]);
        (j0..=j1)
            .flat_map(move |j| (i0..=i1).map(move |i| j * self.nx + i))
            .flat_map(move |c| self.buckets[c].iter().map(move |&k| self.segs[k as usize]))
    }
}

impl Edges {
    /// Whether the segment `a`-`b` keeps inside the chords but for pieces
    /// of at most `slack` (mm) each (a wall touched or run along counts as
    /// inside): the test of `Region::contains_segment` on these chords
    /// without its ends' test, done on the walls near the segment instead
    /// of by clipping it by every ring. The segment is cut where it meets a
    /// wall (a crossing, a touch, the ends of a stretch along one), and each
    /// piece is classed by its middle.
    pub fn keeps_inside(&self, a: P2, b: P2, slack: f64) -> bool {
        let d = [b[0] - a[0], b[1] - a[1]];
        let l2 = d[0] * d[0] + d[1] * d[1];
        if l2 <= slack * slack {
            return true;
        }
        let cross = |u: P2, v: P2| u[0] * v[1] - u[1] * v[0];
        let along = |p: P2| ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2;
        let mut cuts = vec![0.0, 1.0];
        for (p, q) in self.walls_near(a, b, ON_WALL) {
            // A wall that touches the segment or runs along it.
            let near = |x: P2, s: P2, t: P2| seg_dist2(x, s, t) <= ON_WALL * ON_WALL;
            let (pn, qn) = (near(p, a, b), near(q, a, b));
            if pn {
                cuts.push(along(p));
            }
            if qn {
                cuts.push(along(q));
            }
            if near(a, p, q) {
                cuts.push(0.0);
            }
            if near(b, p, q) {
                cuts.push(1.0);
            }
            if pn || qn {
                continue;
            }
            let e = [q[0] - p[0], q[1] - p[1]];
            let den = cross(d, e);
            if den == 0.0 {
                continue;
            }
            let ap = [p[0] - a[0], p[1] - a[1]];
            let (t, u) = (cross(ap, e) / den, cross(ap, d) / den);
            if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u) {
                cuts.push(t);
            }
        }
        cuts.iter_mut().for_each(|t| *t = t.clamp(0.0, 1.0));
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let length = l2.sqrt();
        let mut out = 0.0;
        for w in cuts.windows(2) {
            let piece = (w[1] - w[0]) * length;
            let t = 0.5 * (w[0] + w[1]);
            let m = [a[0] + t * d[0], a[1] + t * d[1]];
            let on_wall = || self.walls_near(m, m, ON_WALL).any(|(p, q)| seg_dist2(m, p, q) <= ON_WALL * ON_WALL);
            if self.contains(m) || on_wall() {
                out = 0.0;
            } else {
                out += piece;
                if out > slack {
                    return false;
                }
            }
        }
        true
    }
}

/// How near (mm) a point is to a wall to lie on it, for
/// [`Edges::keeps_inside`]: the rounding of coordinates of 100 mm.
const ON_WALL: f64 = 1e-9;

impl Edges {
    /// Whether every chord is farther than `margin` from the segment `a`-`b`.
    pub fn clear_of(&self, a: P2, b: P2, margin: f64) -> bool {
        let m2 = margin * margin;
        !self.walls_near(a, b, margin).any(|(p, q)| {
            let (o1, o2) = (orient(p, q, a), orient(p, q, b));
            let (o3, o4) = (orient(a, b, p), orient(a, b, q));
            (o1 * o2 <= 0.0 && o3 * o4 <= 0.0)
                || seg_dist2(a, p, q) <= m2
                || seg_dist2(b, p, q) <= m2
                || seg_dist2(p, a, b) <= m2
                || seg_dist2(q, a, b) <= m2
        })
    }
}

/// The squared distance from `p` to the segment `a`-`b`.
fn seg_dist2(p: P2, a: P2, b: P2) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 { (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0) } else { 0.0 };
    dist2(p, [a[0] + t * dx, a[1] + t * dy])
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A 20 x 20 square with a square hole, grown by 1 mm (arcs at the
    /// outer corners), as the adaptive planner's holder.
    fn grown() -> Region {
        let outer = vec![[0.0, 0.0], [20.0, 0.0], [20.0, 20.0], [0.0, 20.0]];
        let hole = vec![[8.0, 8.0], [8.0, 12.0], [12.0, 12.0], [12.0, 8.0]];
        Region::from_polygons(&[outer, hole], false).offset(-1.0)
    }

    proptest! {
        /// The quick accept of the adaptive planner's holder test
        /// (`Planner::in_holder`): a start inside the chords and a segment
        /// farther than twice the tolerance from them is inside by the
        /// clipping test too.
        #[test]
        fn clear_of_the_chords_is_inside(a in (-3.0..23.0f64, -3.0..23.0f64), b in (-3.0..23.0f64, -3.0..23.0f64)) {
            let region = grown();
            let tolerance = 1e-3;
            let e = Edges::new(&region, tolerance, 0.7);
            let (a, b) = ([a.0, a.1], [b.0, b.1]);
            if e.contains(a) && e.clear_of(a, b, 2.0 * tolerance + 1e-3) {
                prop_assert!(region.contains_segment(a, b, tolerance));
            }
        }
    }

    /// A point on one of the chords of `e` (`k` picks the chord, `t` the
    /// place along it).
    fn on_chord(e: &Edges, k: usize, t: f64) -> P2 {
        let (p, q) = e.segs[k % e.segs.len()];
        [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]
    }

    proptest! {
        /// The chords' segment test equals the clipping test of
        /// `Region::contains_segment` (with its ends' test) on segments
        /// anywhere, from a wall and between two walls, where the segment
        /// does not hug a wall; a segment along a wall is inside (the
        /// clipping test, which rounds both to its integer grid, finds a
        /// sliver of it outside as often as not).
        #[test]
        fn keeps_inside_is_the_clipping_test(
            a in (-3.0..23.0f64, -3.0..23.0f64),
            b in (-3.0..23.0f64, -3.0..23.0f64),
            k in 0usize..10_000,
            j in 0usize..10_000,
            t in 0.0..1.0f64,
            u in 0.0..1.0f64,
            kind in 0usize..4,
        ) {
            let region = grown();
            let tolerance = 1e-3;
            let e = Edges::new(&region, tolerance, 0.7);
            let slack = scallop_contour::tol::LINK_SLACK;
            let (a, b) = match kind {
                0 => ([a.0, a.1], [b.0, b.1]),
                1 => (on_chord(&e, k, t), [b.0, b.1]),
                2 => (on_chord(&e, k, t), on_chord(&e, j, u)),
                _ => {
                    prop_assert!(e.keeps_inside(on_chord(&e, k, t), on_chord(&e, k, u), slack));
                    return Ok(());
                }
            };
            // The clipping test rounds to its integer grid: where the
            // segment's middle hugs a wall (within 1e-5 mm), it is noise.
            let m = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            prop_assume!(e.segs.iter().all(|&(p, q)| seg_dist2(m, p, q) > 1e-10));
            let chords = region.contains(a) && region.contains(b) && e.keeps_inside(a, b, slack);
            prop_assert_eq!(chords, region.contains_segment(a, b, tolerance), "{:?} {:?}", a, b);
        }
    }

    #[test]
    fn keeps_inside_along_and_across_walls() {
        let outer = vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
        let hole = vec![[4.0, 4.0], [4.0, 6.0], [6.0, 6.0], [6.0, 4.0]];
        let region = Region::from_polygons(&[outer, hole], false);
        let e = Edges::new(&region, 1e-3, 0.7);
        // Along the outer wall, along the hole's side, touching its corner.
        assert!(e.keeps_inside([0.0, 0.0], [10.0, 0.0], 1e-6));
        assert!(e.keeps_inside([4.0, 3.0], [4.0, 7.0], 1e-6));
        assert!(e.keeps_inside([3.5, 4.5], [4.5, 3.5], 1e-6));
        // Across the hole, out of the square and back, out by a hair.
        assert!(!e.keeps_inside([3.0, 5.0], [7.0, 5.0], 1e-6));
        assert!(!e.keeps_inside([9.0, 1.0], [9.0, -1.0], 1e-6));
        assert!(!e.keeps_inside([9.0, 9.0], [10.0 + 1e-5, 9.5], 1e-6));
        assert!(e.keeps_inside([9.0, 9.0], [10.0 + 1e-7, 9.5], 1e-6));
    }

    #[test]
    fn clear_of_sees_walls_and_arcs() {
        let region = grown();
        let e = Edges::new(&region, 1e-3, 0.7);
        assert!(e.clear_of([2.0, 2.0], [6.0, 3.0], 0.01));
        // Across the hole, close to an outer corner's arc, close to a wall.
        assert!(!e.clear_of([2.0, 10.0], [18.0, 10.0], 0.01));
        assert!(e.clear_of([20.0, 20.0], [20.6, 20.6], 0.01));
        assert!(!e.clear_of([20.0, 20.0], [20.703, 20.703], 0.01));
        assert!(!e.clear_of([2.0, -0.995], [6.0, -0.995], 0.01));
    }

    #[test]
    fn points_and_steps_against_a_square_with_a_hole() {
        let outer = vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
        let hole = vec![[4.0, 4.0], [4.0, 6.0], [6.0, 6.0], [6.0, 4.0]];
        let region = Region::from_polygons(&[outer, hole], false);
        let e = Edges::new(&region, 1e-3, 0.7);
        for (p, want) in [([1.0, 1.0], true), ([5.0, 5.0], false), ([11.0, 5.0], false), ([3.9, 5.0], true)] {
            assert_eq!(e.contains(p), want, "{p:?}");
            assert_eq!(region.contains(p), want, "{p:?}");
        }
        assert!(e.contains_segment([1.0, 1.0], [3.0, 3.0]));
        assert!(!e.contains_segment([3.0, 5.0], [4.5, 5.0]));
        // Across the hole's corner and out again: both ends in the region.
        assert!(!e.contains_segment([3.5, 4.8], [4.8, 3.5]));
        // Touching the corner only: in.
        assert!(e.contains_segment([3.5, 4.5], [4.5, 3.5]));
        assert!(!e.contains_segment([9.0, 9.0], [10.5, 9.0]));
    }
}
