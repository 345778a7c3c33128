//! Arms: pieces of inside that cross a grid edge between two outside samples
//! (a thin arm of a larger region), which neither the grid nor the chord
//! checks see, found from the mesh and spliced into the loop they belong to.
//!
//! The inside at z is the union, over the mesh points q above z, of the disks
//! of radius `r(q.z - z)` around q's XY, where `r(h)` is the cutter's radius at
//! height h above its tip ([`CutterShape::radius_at`]: 0 at the tip of a ball
//! or a cone, R for a flat end; the drop-cutter takes the cutter as unbounded
//! above): the cutter with its tip at z anywhere in that disk holds q. So every
//! *witness* below lies inside the true contour with a margin of at least
//! [`tol::ARM_MARGIN`] chord tolerances, and must lie inside the loops (which
//! stay within about a chord tolerance of the contour):
//! - every mesh vertex above z whose margin `r(v.z - z)` is that large;
//! - every point where a mesh edge crosses the height `z + h0`, `h0` the
//!   height where the cutter's radius reaches that margin (for a flat end, a
//!   crossing tolerance above z): the tip of a ridge's arm, where the ridge
//!   runs down through z between its vertices (the vertices may all lie
//!   inside the traced loops), which a vertex-only check misses;
//! - points every half grid step along the part of each edge between `z + h0`
//!   and the height where the margin reaches 0.75 steps ([`BAND_RADIUS`]; a
//!   higher point's disk holds a grid sample): the neck of an arm whose base
//!   and far end the grid saw, but not its middle.
//!
//! A witness outside every loop (exact winding numbers, all loops of the level
//! summed, the chords binned in bands one grid step high) is recovered where
//! it is, and only there. The *spine* of its arm runs from the chord of the
//! loops that cuts across the arm's base (for an edge witness the first chord
//! met going up the edge, which is inside all the way; for a vertex the
//! nearest chord) through the witness to the *tip*, the first crossing of the
//! contour going on down the edge (or away from the chord), found from inside
//! by [`Local::contour_near`]. The witness is joined to the chord if the walk
//! from it to the chord stays inside to within a chord tolerance of it.
//! The arm's sides are found from inside: from points along the spine (8
//! evenly spread, more at halving distances towards the base), the nearest
//! crossing to the right and to the left of the spine (a chord refined from
//! outside a thin arm may probe across it; from inside, the probe finds the
//! nearest crossing however thin the arm); side points behind the crossed
//! chord or inside the loop are dropped. The chord `a -> b` is replaced by
//! `a`, the right side out to the tip, the left side back, `b`, every new
//! chord refined as any chord is ([`refine_chord`]). The arm lies on the right
//! of `a -> b` (outside the old loop) and its inside on the left of the new
//! path, so the loop keeps its orientation and stays closed. Where the new
//! path crosses a neighbouring chord of the same loop (the arm's base spans
//! several chords) or itself (the loop had traced part of the arm and turned
//! back), the run of replaced chords grows (up to [`MAX_RUN`]); a crossing
//! with another loop refuses the splice (loops never cross).
//!
//! Where the spine, on its way to the tip, enters another loop (the grid saw
//! a far piece of the arm and traced it alone), the two loops are joined by a
//! *bridge*: out along the right side to that loop's chord, around that loop,
//! back along the left side; the spine enters it across a chord `a1 -> b1`
//! with its inside on the left, so `b1` is on the spine's right and both
//! loops keep their sense. A bridge that would cross a loop is refused.
//!
//! What the check guarantees: after it, every witness lies inside the loops,
//! except one whose recovery was refused (not joined to the chord, no contour
//! within reach, or a splice or bridge that would cross a loop), and then the
//! loops are those of the trace. What it does not: an arm that holds no
//! witness (one made by a face point alone, whose edges and vertices lie
//! inside the loops; one whose witnesses lie within the margin of a chord); an
//! island that reaches past the 3 x 3 block `islands()` samples (its witnesses
//! are not joined to a chord); a piece of an arm traced as its own loop that
//! overlaps the main loop without any witness outside both (the two loops
//! then cross); a sliver of outside within an arm. The cost is one pass over
//! the mesh and one winding number per witness per level, and the recovery
//! only where a witness is outside.

use rayon::prelude::*;
use scallop_cutter::CutterShape;
use scallop_geom::{Point2, Vec2, predicates::orient2d};

use crate::refine::{CHORD_MARGIN, Local, Near, Probe, long_chord, refine_chord};
use crate::{Loop, WaterlineGrid, tol};

/// Most passes of check and recovery per level (a splice may move a chord
/// off another witness; the next pass finds it).
const MAX_PASSES: usize = 4;

/// The loops of `grid` at the probe's height, mended: each witness outside
/// every loop is recovered as the module docs say.
pub(crate) fn mend(grid: &WaterlineGrid<'_>, probe: &Probe<'_>, chord_tolerance: f64, loops: &mut Vec<Loop>) {
    let witnesses = witnesses(probe.cutter.shape(), probe.index, probe.z, chord_tolerance, probe.tolerance, grid.step);
    if witnesses.is_empty() || loops.is_empty() {
        return;
    }
    // Witnesses whose recovery was refused, by their coordinates' bits, sorted.
    let mut refused: Vec<(u64, u64)> = Vec::new();
    let key = |p: Point2| (p.x.to_bits(), p.y.to_bits());
    for _ in 0..MAX_PASSES {
        let bands = Bands::new(loops, grid.origin.y, grid.step, grid.ny);
        let missed: Vec<Witness> = witnesses
            .par_iter()
            .with_min_len(256)
            .filter(|w| bands.winding(w.at) == 0 && refused.binary_search(&key(w.at)).is_err())
            .copied()
            .collect();
        if missed.is_empty() {
            return;
        }
        let mut spliced = false;
        for w in missed {
            // An earlier splice of this pass may have taken it in.
            if loops.iter().map(|l| l.winding_number(w.at)).sum::<i32>() != 0 {
                continue;
            }
            if splice(probe, grid.step, chord_tolerance, loops, w) {
                spliced = true;
            } else {
                if let Err(at) = refused.binary_search(&key(w.at)) {
                    refused.insert(at, key(w.at));
                }
            }
        }
        if !spliced {
            return;
        }
    }
}

/// A mesh point inside the contour with margin (module docs), and for a
/// point on an edge the edge's downhill direction in XY: the edge stays
/// inside down to z, so the arm's tip lies that way.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Witness {
    at: Point2,
    downhill: Option<Vec2>,
}

/// The witnesses of the level (module docs), each mesh vertex and edge once
/// (from the triangle that owns it), in slot order.
fn witnesses(
    shape: &CutterShape,
    index: &scallop_mesh::MeshIndex,
    z: f64,
    chord_tolerance: f64,
    crossing: f64,
    step: f64,
) -> Vec<Witness> {
    let margin = tol::ARM_MARGIN * chord_tolerance;
    // Above this height a point's disk holds a grid sample (radius 0.71 step).
    let band = BAND_RADIUS * step;
    let band_top = z + if band < shape.radius() { shape.height_at(band) } else { shape.profile_height() };
    // The height where the cutter's radius reaches the margin (strictly above z).
    let h0 = if margin < shape.radius() { shape.height_at(margin) } else { shape.profile_height() }.max(crossing);
    let clip = z + h0;
    let mut out = Vec::new();
    for slot in 0..index.len() {
        if index.zmax(slot) <= clip {
            continue;
        }
        let corners = index.corners(slot);
        let owned = index.owned_features(slot);
        for k in 0..3 {
            let v = corners[k];
            if owned & (1 << k) != 0 && v.z > z && shape.radius_at(v.z - z) >= margin {
                out.push(Witness { at: Point2::new(v.x, v.y), downhill: None });
            }
            let w = corners[(k + 1) % 3];
            if owned & (1 << (3 + k)) == 0 {
                continue;
            }
            let (lo, hi) = if v.z < w.z { (v, w) } else { (w, v) };
            let d = Vec2::new(lo.x - hi.x, lo.y - hi.y);
            let len = d.norm();
            let downhill = (len > 0.0 && lo.z < hi.z).then(|| d / len);
            let at = |t: f64| Point2::new(lo.x + t * (hi.x - lo.x), lo.y + t * (hi.y - lo.y));
            if lo.z <= clip && hi.z > clip {
                out.push(Witness { at: at((clip - lo.z) / (hi.z - lo.z)), downhill });
            }
            // The part of the edge in the band [clip, band_top], one witness per half step.
            if hi.z < clip || lo.z > band_top || len.is_nan() || len <= 0.0 {
                continue;
            }
            let dz = hi.z - lo.z;
            let (t0, t1) =
                if dz > 0.0 { (((clip - lo.z) / dz).max(0.0), ((band_top - lo.z) / dz).min(1.0)) } else { (0.0, 1.0) };
            let count = ((t1 - t0) * len / (WITNESS_SPACING * step)).floor();
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            // at most the edge's length in half steps
            let count = if count > 0.0 { count as usize } else { 0 };
            #[allow(clippy::cast_precision_loss)]
            out.extend(
                (1..=count).map(|q| Witness { at: at(t0 + (t1 - t0) * q as f64 / (count + 1) as f64), downhill }),
            );
        }
    }
    out
}

/// The chords of all loops of a level in horizontal bands one grid step high
/// (a chord in every band its y range meets): the winding number of a point
/// needs only the chords of its band.
struct Bands {
    y0: f64,
    height: f64,
    bands: Vec<Vec<(Point2, Point2)>>,
}

impl Bands {
    fn new(loops: &[Loop], y0: f64, height: f64, n: usize) -> Self {
        let mut bands = Bands { y0, height, bands: vec![Vec::new(); n.max(1)] };
        for l in loops {
            let m = l.points.len();
            for i in 0..m {
                let (a, b) = (l.points[i], l.points[(i + 1) % m]);
                let (lo, hi) = (bands.band(a.y.min(b.y)), bands.band(a.y.max(b.y)));
                for band in &mut bands.bands[lo..=hi] {
                    band.push((a, b));
                }
            }
        }
        bands
    }

    fn band(&self, y: f64) -> usize {
        let f = ((y - self.y0) / self.height).floor();
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, clippy::cast_precision_loss)]
        let k = if f > 0.0 { (f as usize).min(self.bands.len() - 1) } else { 0 };
        k
    }

    /// The winding number of all loops around `p` (as [`Loop::winding_number`]).
    fn winding(&self, p: Point2) -> i32 {
        let mut w = 0;
        for (a, b) in &self.bands[self.band(p.y)] {
            if a.y <= p.y {
                if b.y > p.y && orient2d(a, b, &p) > 0.0 {
                    w += 1;
                }
            } else if b.y <= p.y && orient2d(a, b, &p) < 0.0 {
                w -= 1;
            }
        }
        w
    }
}

/// Recovers the arm holding the witness `w` (inside the contour, outside every
/// loop) into the loop of the chord across its base; `false` if refused
/// (module docs).
fn splice(probe: &Probe<'_>, step: f64, chord_tolerance: f64, loops: &mut Vec<Loop>, witness: Witness) -> bool {
    let w = witness.at;
    // The chord across the arm's base: for a point of an edge, the first
    // chord met going back up the edge (the edge is inside all the way);
    // else the nearest chord.
    let Some((l, i, c)) = witness
        .downhill
        .and_then(|u| first_chord(loops, w, -u, f64::INFINITY, None))
        .or_else(|| nearest_chord(loops, w))
    else {
        return false;
    };
    let n = loops[l].points.len();
    let (a, b) = (loops[l].points[i], loops[l].points[(i + 1) % n]);
    let d = w - c;
    let dist = d.norm();
    if dist.is_nan() || dist <= 0.0 {
        return false;
    }
    // Towards the tip: down the witness's edge, else away from the chord.
    let u: Vec2 = witness.downhill.unwrap_or(d / dist);
    let reach = probe.cutter.radius() + step;
    let tip_far = w + u * reach;
    let span = (b - a).norm().max(dist + reach).max(step);
    let margin = CHORD_MARGIN * span;
    let (lo, hi) = bounds([a, b, w, tip_far]);
    let local: Local<'_> =
        probe.local(Point2::new(lo.x - margin, lo.y - margin), Point2::new(hi.x + margin, hi.y + margin));
    let h_w = local.height_slot(w).0;
    if h_w.is_nan() || h_w <= 0.0 {
        return false;
    }
    // Joined to the chord: inside from the witness to c, or to within a chord
    // tolerance of c (a loop point is the outside end of its bracket, the walk
    // may meet the contour at a grazing angle).
    let joined = match local.contour_near(w, d / dist, probe.tolerance, dist) {
        Near::Missing => true,
        Near::Found(p) => (p - c).norm() <= chord_tolerance,
        Near::Within => false,
    };
    if !joined {
        return false;
    }
    // From the inside witness along u (the normal given points the other way).
    let Near::Found(tip) = local.contour_near(w, -u, probe.tolerance, reach) else { return false };
    // The arm may run into a piece of itself that the grid saw and traced
    // as a loop of its own: the two loops are joined by a bridge.
    if let Some((k, j, c1)) = first_chord(loops, w, u, (tip - w).norm(), Some(l)) {
        return bridge(&local, probe.tolerance, chord_tolerance, reach, loops, (l, i), (k, j), [c, w, c1]);
    }
    let (mut right, mut left) = sides(&local, [c, w, tip], true, probe.tolerance, chord_tolerance, reach);
    // Only the sides beyond the chord (on its right) and outside the loop
    // (near the base a side point may lie behind the chord).
    let beyond = |p: &Point2| orient2d(&a, &b, p) < 0.0 && loops[l].winding_number(*p) == 0;
    right.retain(beyond);
    left.retain(beyond);
    let mut sides = right;
    sides.push(tip);
    sides.extend(left.into_iter().rev());
    // The chords across the arm's base: the nearest one, and its neighbours
    // while the new path crosses them (the arm's base may span several).
    let points = &loops[l].points;
    let (mut back, mut ahead) = (0, 0);
    loop {
        if back + ahead >= MAX_RUN.min(n / 2) {
            return false;
        }
        let (s, e) = ((i + n - back) % n, (i + 1 + ahead) % n);
        let (a, b) = (points[s], points[e]);
        let mut new = Vec::new();
        refine_through(&local, a, &sides, b, chord_tolerance, &mut new);
        let path = framed(a, &new, b);
        let run = back + ahead; // chords s..s + run (mod n) are replaced
        match crossing(loops, &|k, j| k == l && (j + n - s) % n <= run, &path) {
            Crossing::None => {
                let mut mended = Vec::with_capacity(n + new.len());
                if s < e {
                    mended.extend_from_slice(&points[..=s]);
                    mended.extend_from_slice(&new);
                    mended.extend_from_slice(&points[e..]);
                } else {
                    // The run wraps past the first point: the loop starts at b.
                    mended.extend_from_slice(&points[e..=s]);
                    mended.extend_from_slice(&new);
                }
                loops[l].points = mended;
                return true;
            }
            Crossing::Chord(k, j) if k == l => {
                // Take the crossed chord (and those between) into the run, on its side.
                let (after, before) = ((j + n - e) % n, (s + n - 1 - j) % n);
                if after <= before {
                    ahead += after + 1;
                } else {
                    back += before + 1;
                }
            }
            // The new path turns back across itself: the run ends on a
            // side of the arm the traced loop took (a partly traced arm).
            Crossing::Path => (back, ahead) = (back + 1, ahead + 1),
            Crossing::Chord(..) => return false,
        }
    }
}

/// The sides of an arm around its spine (`c` on the crossed chord, the
/// witness, the far end: the tip if `to_tip`, else the point where the spine
/// enters another loop), inside but at its ends: the contour found from
/// points along the spine, probed from each to its right and to its left
/// (from an inside point the probe finds the nearest crossing, however thin
/// the arm), as (right, left), each in order along the spine. The points are
/// [`SIDE_PROBES`] - 1 evenly spread, and more at halving distances from `c`
/// (and from the far end when it is not a tip) down to [`BASE_MARGIN`] chord
/// tolerances, so that the first side points lie close to the arm's base.
fn sides(
    local: &Local<'_>,
    spine: [Point2; 3],
    to_tip: bool,
    tolerance: f64,
    chord_tolerance: f64,
    reach: f64,
) -> (Vec<Point2>, Vec<Point2>) {
    let legs = [spine[1] - spine[0], spine[2] - spine[1]];
    let (l0, l1) = (legs[0].norm(), legs[1].norm());
    let total = l0 + l1;
    if l1.is_nan() || l1 <= 0.0 {
        return (Vec::new(), Vec::new());
    }
    #[allow(clippy::cast_precision_loss)]
    let mut at: Vec<f64> = (1..SIDE_PROBES).map(|k| total * k as f64 / SIDE_PROBES as f64).collect();
    #[allow(clippy::cast_precision_loss)]
    let mut s = total / SIDE_PROBES as f64;
    while at.len() < MAX_SIDE_PROBES && s > BASE_MARGIN * chord_tolerance {
        s *= 0.5;
        at.push(s);
        if !to_tip {
            at.push(total - s); // the far end is a base too
        }
    }
    at.sort_unstable_by(f64::total_cmp);
    let (mut right, mut left) = (Vec::new(), Vec::new());
    for s in at {
        let (p, dir) = if s < l0 {
            (spine[0] + legs[0] * (s / l0), legs[0] / l0)
        } else {
            (spine[1] + legs[1] * ((s - l0) / l1), legs[1] / l1)
        };
        let r = Vec2::new(dir.y, -dir.x);
        // `contour_near` walks against the normal given from an inside point.
        if let Near::Found(q) = local.contour_near(p, -r, tolerance, reach) {
            right.push(q);
        }
        if let Near::Found(q) = local.contour_near(p, r, tolerance, reach) {
            left.push(q);
        }
    }
    (right, left)
}

/// Radius, in grid steps, of a witness's disk above which it holds a grid
/// sample (half the cell's diagonal is 0.71 steps): below it, an edge is
/// also checked between its ends.
const BAND_RADIUS: f64 = 0.75;

/// Spacing, in grid steps, of the witnesses along an edge within the band.
const WITNESS_SPACING: f64 = 0.5;

/// Points evenly spread along an arm's spine probed for its sides.
const SIDE_PROBES: usize = 8;

/// Most points along an arm's spine probed for its sides.
const MAX_SIDE_PROBES: usize = 32;

/// Nearest distance to the chord, in chord tolerances, of a point of an arm's
/// spine probed for its sides (the chord may lie a chord tolerance inside the
/// contour: nearer, the probe could run along the contour).
const BASE_MARGIN: f64 = 4.0;

/// Most chords of a loop one splice replaces.
const MAX_RUN: usize = 32;

/// What [`crossing`] found.
enum Crossing {
    None,
    /// A chord of a loop: (loop, chord index).
    Chord(usize, usize),
    /// Two chords of the path.
    Path,
}

/// The first chord of `loops` (other than those `replaced(loop, chord)`)
/// that a chord of `path` crosses at a point interior to both, or a crossing
/// of two chords of `path`.
fn crossing(loops: &[Loop], replaced: &dyn Fn(usize, usize) -> bool, path: &[Point2]) -> Crossing {
    let (lo, hi) = bounds(path.iter().copied());
    let segs: Vec<(Point2, Point2)> = path.windows(2).map(|s| (s[0], s[1])).collect();
    for (l, lp) in loops.iter().enumerate() {
        let n = lp.points.len();
        for i in 0..n {
            let (a, b) = (lp.points[i], lp.points[(i + 1) % n]);
            if a.x.max(b.x) < lo.x || a.x.min(b.x) > hi.x || a.y.max(b.y) < lo.y || a.y.min(b.y) > hi.y {
                continue;
            }
            if !replaced(l, i) && segs.iter().any(|&(p, q)| proper_cross(p, q, a, b)) {
                return Crossing::Chord(l, i);
            }
        }
    }
    let self_crossing = segs
        .iter()
        .enumerate()
        .any(|(k, &(p, q))| segs.get(k + 2..).unwrap_or(&[]).iter().any(|&(a, b)| proper_cross(p, q, a, b)));
    if self_crossing { Crossing::Path } else { Crossing::None }
}

/// The first chord of `loops` (but loop `skip`) met from `p` going along the
/// unit vector `dir`, within `limit`: (loop, chord index, the point met).
fn first_chord(
    loops: &[Loop],
    p: Point2,
    dir: Vec2,
    limit: f64,
    skip: Option<usize>,
) -> Option<(usize, usize, Point2)> {
    let mut best: Option<(f64, usize, usize, Point2)> = None;
    for (l, lp) in loops.iter().enumerate() {
        if skip == Some(l) {
            continue;
        }
        let n = lp.points.len();
        for i in 0..n {
            let (a, b) = (lp.points[i], lp.points[(i + 1) % n]);
            // p + t dir = a + s (b - a), 0 < t <= limit, 0 <= s <= 1.
            let e = b - a;
            let den = dir.x * e.y - dir.y * e.x;
            if den == 0.0 {
                continue;
            }
            let ap = a - p;
            let t = (ap.x * e.y - ap.y * e.x) / den;
            let s = (ap.x * dir.y - ap.y * dir.x) / den;
            if t > 0.0 && t <= limit && (0.0..=1.0).contains(&s) && best.is_none_or(|(bt, ..)| t < bt) {
                best = Some((t, l, i, p + dir * t));
            }
        }
    }
    best.map(|(_, l, i, c)| (l, i, c))
}

/// Joins loop `k` into loop `l` by the arm whose spine runs from `c` (on
/// chord `i` of loop `l`) through the witness to `c1` (on chord `j` of loop
/// `k`, which the spine enters): out along the arm's right side to loop `k`,
/// around loop `k`, back along the left side. Orientation: the spine enters
/// loop `k` across its chord `a1 -> b1` (inside on its left), so `b1` lies on
/// the right of the spine, and the merged loop keeps both loops' sense.
/// `false` (nothing changed) if the new path would cross a loop.
#[allow(clippy::too_many_arguments)]
fn bridge(
    local: &Local<'_>,
    tolerance: f64,
    chord_tolerance: f64,
    reach: f64,
    loops: &mut Vec<Loop>,
    (l, i): (usize, usize),
    (k, j): (usize, usize),
    spine: [Point2; 3],
) -> bool {
    let (n, m) = (loops[l].points.len(), loops[k].points.len());
    let (a, b) = (loops[l].points[i], loops[l].points[(i + 1) % n]);
    let (a1, b1) = (loops[k].points[j], loops[k].points[(j + 1) % m]);
    let (mut right, mut left) = sides(local, spine, false, tolerance, chord_tolerance, reach);
    // Only the sides in the gap between the two loops: beyond both chords
    // crossed (on their right) and outside both loops (near either base a
    // side point may lie behind a chord, or on a loop).
    let apart = |p: &Point2| {
        orient2d(&a, &b, p) < 0.0
            && orient2d(&a1, &b1, p) < 0.0
            && loops[l].winding_number(*p) == 0
            && loops[k].winding_number(*p) == 0
    };
    right.retain(apart);
    left.retain(apart);
    let mut new = Vec::new();
    refine_through(local, a, &right, b1, chord_tolerance, &mut new);
    new.push(b1);
    // Around loop k from b1 (pushed) to a1.
    new.extend((2..=m).map(|s| loops[k].points[(j + s) % m]));
    let left: Vec<Point2> = left.iter().rev().copied().collect();
    refine_through(local, a1, &left, b, chord_tolerance, &mut new);
    let path = framed(a, &new, b);
    if !matches!(crossing(loops, &|q, r| (q, r) == (l, i) || q == k, &path), Crossing::None) {
        return false;
    }
    let points = &loops[l].points;
    let mut merged = Vec::with_capacity(n + new.len());
    merged.extend_from_slice(&points[..=i]);
    merged.extend_from_slice(&new);
    merged.extend_from_slice(&points[i + 1..]);
    loops[l].points = merged;
    loops.remove(k);
    true
}

/// The chord of `loops` nearest to `p`: (loop, chord index, nearest point).
/// Appends to `new` the chords from `from` through `through` to `to`, each
/// refined to the chord tolerance, with the points of `through` (not `to`).
fn refine_through(
    local: &Local<'_>,
    from: Point2,
    through: &[Point2],
    to: Point2,
    chord_tolerance: f64,
    new: &mut Vec<Point2>,
) {
    let mut from = from;
    let long = long_chord(local.probe, chord_tolerance);
    for &p in through.iter().chain([&to]) {
        refine_chord(local, (from, p), chord_tolerance, long, 0, new);
        if p != to {
            new.push(p);
        }
        from = p;
    }
}

/// The path `a`, `inner`..., `b`.
fn framed(a: Point2, inner: &[Point2], b: Point2) -> Vec<Point2> {
    let mut path = Vec::with_capacity(inner.len() + 2);
    path.push(a);
    path.extend_from_slice(inner);
    path.push(b);
    path
}

fn nearest_chord(loops: &[Loop], p: Point2) -> Option<(usize, usize, Point2)> {
    let mut best: Option<(f64, usize, usize, Point2)> = None;
    for (l, lp) in loops.iter().enumerate() {
        let n = lp.points.len();
        for i in 0..n {
            let (a, b) = (lp.points[i], lp.points[(i + 1) % n]);
            let ab = b - a;
            let len2 = ab.norm_squared();
            let t = if len2 > 0.0 { ((p - a).dot(&ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
            let c = a + ab * t;
            let d2 = (p - c).norm_squared();
            if best.is_none_or(|(bd, ..)| d2 < bd) {
                best = Some((d2, l, i, c));
            }
        }
    }
    best.map(|(_, l, i, c)| (l, i, c))
}

/// Segments p-q and a-b cross at a point interior to both (exact predicates).
fn proper_cross(p: Point2, q: Point2, a: Point2, b: Point2) -> bool {
    let (o1, o2) = (orient2d(&p, &q, &a), orient2d(&p, &q, &b));
    let (o3, o4) = (orient2d(&a, &b, &p), orient2d(&a, &b, &q));
    let apart = |s: f64, t: f64| (s > 0.0 && t < 0.0) || (s < 0.0 && t > 0.0);
    apart(o1, o2) && apart(o3, o4)
}

fn bounds(points: impl IntoIterator<Item = Point2>) -> (Point2, Point2) {
    let mut lo = Point2::new(f64::INFINITY, f64::INFINITY);
    let mut hi = Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
    for p in points {
        (lo, hi) = (Point2::new(lo.x.min(p.x), lo.y.min(p.y)), Point2::new(hi.x.max(p.x), hi.y.max(p.y)));
    }
    (lo, hi)
}
