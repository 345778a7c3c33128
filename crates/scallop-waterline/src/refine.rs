//! Bisection on the exact drop-cutter, and the adaptive splitting of chords.

use rayon::prelude::*;
use scallop_cutter::{ClPoint, Cutter, drop_cutter, drop_triangle};
use scallop_geom::{Aabb2, Point2, Vec2};
use scallop_mesh::MeshIndex;

use crate::{Loop, tol};

/// The side test at one height: is the cutter with its tip at `z` cutting
/// into the part at (x, y)?
pub(crate) struct Probe<'a> {
    pub(crate) cutter: &'a Cutter,
    pub(crate) index: &'a MeshIndex,
    pub(crate) z: f64,
    /// Width of the final bisection bracket.
    pub(crate) tolerance: f64,
    /// The grid step.
    pub(crate) step: f64,
}

impl<'a> Probe<'a> {
    /// Tip height of the exact drop-cutter at `p` minus z, floored at
    /// `-step` (a floor only prunes the search; it never changes the sign, so
    /// `height(p) > 0` is exactly "the cutter at z cuts into the part at p").
    pub(crate) fn height(&self, p: Point2) -> f64 {
        drop_cutter(self.cutter, self.index, p, self.z - self.step).tip.z - self.z
    }

    /// Tip height of the drop-cutter on the one triangle in `slot` at `p`,
    /// minus z, floored as [`Probe::height`]: the full height is the maximum of
    /// these over all triangles. The set where it is > 0 is convex (the cutter
    /// and the triangle are convex), so it meets a segment in one interval.
    pub(crate) fn triangle_height(&self, slot: usize, p: Point2) -> f64 {
        let mut best = ClPoint::floor(p, self.z - self.step);
        let index = self.index;
        drop_triangle(self.cutter, index.corners(slot), index.normal(slot), index.original_index(slot), &mut best);
        best.tip.z - self.z
    }

    /// The probe restricted to points of the box `[lo, hi]`: the triangles
    /// within the cutter's reach of the box, sorted by decreasing top, so that
    /// each evaluation scans a short list instead of searching the index.
    pub(crate) fn local(&'a self, lo: Point2, hi: Point2) -> Local<'a> {
        let radius = self.cutter.radius();
        let reach =
            Aabb2 { min: Point2::new(lo.x - radius, lo.y - radius), max: Point2::new(hi.x + radius, hi.y + radius) };
        let mut slots = Vec::new();
        self.index.collect_box(&reach, &mut slots);
        let floor = self.z - self.step;
        let mut candidates: Vec<Candidate> = slots
            .into_iter()
            .map(|slot| {
                let slot = slot as usize;
                let b = self.index.xy_box(slot);
                Candidate { zmax: self.index.zmax(slot), min: b.min, max: b.max, slot }
            })
            .filter(|c| c.zmax + self.index.slack() > floor)
            .collect();
        // Decreasing top, ties by slot: a deterministic order.
        candidates.sort_unstable_by(|a, b| b.zmax.total_cmp(&a.zmax).then(a.slot.cmp(&b.slot)));
        Local { probe: self, lo, hi, candidates }
    }
}

/// A triangle within reach of a [`Local`] box.
struct Candidate {
    zmax: f64,
    min: Point2,
    max: Point2,
    slot: usize,
}

/// A [`Probe`] with the candidate triangles of one box (a chord's or a grid
/// edge's neighbourhood). Heights equal [`Probe::height`] bit for bit: the
/// same per-triangle contacts (`drop_triangle`, as `drop_cutter` evaluates
/// them), maximised over every triangle that can raise the result; points
/// outside the box fall back to the index.
pub(crate) struct Local<'a> {
    probe: &'a Probe<'a>,
    lo: Point2,
    hi: Point2,
    candidates: Vec<Candidate>,
}

impl Local<'_> {
    /// [`Probe::height`] through the candidate list.
    fn height(&self, p: Point2) -> f64 {
        self.height_slot(p).0
    }

    /// [`Local::height`] and the slot of the triangle that gives it (`None` on
    /// the floor, or for a point outside the box).
    pub(crate) fn height_slot(&self, p: Point2) -> (f64, Option<usize>) {
        let probe = self.probe;
        if !(p.x >= self.lo.x && p.x <= self.hi.x && p.y >= self.lo.y && p.y <= self.hi.y) {
            return (probe.height(p), None);
        }
        let radius = probe.cutter.radius();
        let shape = probe.cutter.shape();
        let mut best = ClPoint::floor(p, probe.z - probe.step);
        let mut best_slot = None;
        // The index's rounding slack on its bounds, as `drop_cutter` prunes.
        let slack = probe.index.slack();
        for c in &self.candidates {
            if c.zmax + slack <= best.tip.z {
                break; // sorted: no later triangle reaches above the best contact
            }
            let dx = (c.min.x - p.x).max(0.0).max(p.x - c.max.x);
            let dy = (c.min.y - p.y).max(0.0).max(p.y - c.max.y);
            let distance = dx.hypot(dy);
            if distance > radius || c.zmax - shape.height_at(distance) + slack <= best.tip.z {
                continue;
            }
            let slot = c.slot;
            let before = best.tip.z;
            drop_triangle(
                probe.cutter,
                probe.index.corners(slot),
                probe.index.normal(slot),
                probe.index.original_index(slot),
                &mut best,
            );
            if best.tip.z > before {
                best_slot = Some(slot);
            }
        }
        (best.tip.z - probe.z, best_slot)
    }

    /// Shrinks the bracket from `inside` (height `h_in > 0`) to `outside`
    /// (height `h_out <= 0`) to the tolerance and returns its outside end.
    ///
    /// Every step keeps a true bracket (each new point is classified by the
    /// exact drop-cutter). Where the height is smooth, the secant guess
    /// `t = h_in / (h_in - h_out)` lands within the tolerance of the contour and
    /// two probes half a tolerance either side of it close the bracket; where it
    /// is not (vertical walls, creases), a step that did not halve the bracket
    /// is followed by a bisection, so the worst case is twice plain bisection.
    pub(crate) fn bisect_heights(&self, inside: Point2, h_in: f64, outside: Point2, h_out: f64) -> Point2 {
        self.bracket(inside, h_in, outside, h_out).1
    }

    /// As [`Local::bisect_heights`], returning both ends of the final bracket
    /// (inside, outside).
    fn bracket(&self, mut inside: Point2, mut h_in: f64, mut outside: Point2, mut h_out: f64) -> (Point2, Point2) {
        let mut bisect_next = false;
        loop {
            let width = (outside - inside).norm();
            if width <= self.probe.tolerance {
                return (inside, outside);
            }
            let secant = h_in - h_out;
            let use_secant = !bisect_next && secant.is_finite() && secant > 0.0;
            let (a, b) = (inside, outside);
            let steps: [Option<f64>; 2] = if use_secant {
                let t = (h_in / secant).clamp(0.0, 1.0);
                let half = SECANT_PROBE * self.probe.tolerance / width;
                [Some((t - half).max(0.0)), Some((t + half).min(1.0))]
            } else {
                [Some(0.5), None]
            };
            for s in steps.into_iter().flatten() {
                let p = a + (b - a) * s;
                if p == inside || p == outside {
                    continue;
                }
                let h = self.height(p);
                if h > 0.0 {
                    (inside, h_in) = (p, h);
                } else {
                    (outside, h_out) = (p, h);
                    break;
                }
            }
            let after = (outside - inside).norm();
            if after >= width {
                // Down to adjacent floats (or a guess on an end): stop on the outside.
                return (inside, outside);
            }
            // A secant step that did not halve the bracket: the height is not
            // smooth here (a wall, a crease): plain bisection from now on.
            bisect_next |= use_secant && after > 0.5 * width;
        }
    }

    /// Where the contour crosses the line through `mid` along `normal` (unit,
    /// pointing inside): [`Near::Within`] if it does within `accept` of `mid`
    /// (one probe); otherwise probes at doubling distances up to `reach` and
    /// refines the first change of side found; [`Near::Missing`] if none.
    fn contour_near(&self, mid: Point2, normal: Vec2, accept: f64, reach: f64) -> Near {
        let h_mid = self.height(mid);
        let mid_in = h_mid > 0.0;
        let towards = if mid_in { -normal } else { normal };
        let mut r = accept;
        loop {
            let p = mid + towards * r;
            let h = self.height(p);
            if (h > 0.0) != mid_in {
                if r <= accept {
                    return Near::Within;
                }
                return Near::Found(if mid_in {
                    self.bisect_heights(mid, h_mid, p, h)
                } else {
                    self.bisect_heights(p, h, mid, h_mid)
                });
            }
            if r >= reach {
                return Near::Missing;
            }
            r = (PROBE_GROWTH * r).min(reach);
        }
    }
}

impl Local<'_> {
    /// The contour crossings on the segment from `a` to `b`, both inside (the
    /// cutter at z cuts there), in order from `a`: the ends of the gaps
    /// (outside intervals) between them, each an outside point within the
    /// crossing tolerance of an inside one. `slot_a` is the triangle that
    /// gives the height at `a`.
    ///
    /// A cover walk: the triangle that lifts the cutter above z at the current
    /// point does so on one interval of the segment (convexity, see
    /// [`Probe::triangle_height`]); its end is bisected on that triangle alone,
    /// and the full drop-cutter there either finds the next triangle (no gap)
    /// or starts a gap, whose far end is bisected on the full drop-cutter. A
    /// gap of any width above the crossing tolerance is found, however far it
    /// is from the grid samples (the fibres of OpenCAMLib's push-cutter find
    /// the same intervals); an inside sliver within a gap is not looked for.
    pub(crate) fn gaps(&self, a: Point2, slot_a: usize, b: Point2, h_b: f64) -> Vec<Point2> {
        let probe = self.probe;
        let mut out = Vec::new();
        let (mut at, mut slot) = (a, slot_a);
        for _ in 0..MAX_COVER_STEPS {
            if probe.triangle_height(slot, b) > 0.0 {
                break; // this triangle covers the rest of the segment
            }
            let end = self.triangle_end(slot, at, b);
            let (h, next) = self.height_slot(end);
            if h > 0.0 {
                match next {
                    Some(next) if end != at => (at, slot) = (end, next),
                    _ => break,
                }
                continue;
            }
            // A gap starts at `end`: its far end, towards the inside end `b`.
            let (inside, outside) = self.bracket(b, h_b, end, h);
            out.push(end);
            out.push(outside);
            let (h_in, next) = self.height_slot(inside);
            match next {
                Some(next) if h_in > 0.0 && inside != at => (at, slot) = (inside, next),
                _ => break,
            }
        }
        out
    }

    /// The first point from `inside` towards `outside` (the triangle in `slot`
    /// lifting the cutter above z at the first, not at the second) where that
    /// triangle no longer does, within the crossing tolerance: bisection on the
    /// one triangle.
    fn triangle_end(&self, slot: usize, mut inside: Point2, mut outside: Point2) -> Point2 {
        let probe = self.probe;
        while (outside - inside).norm() > probe.tolerance {
            let mid = Point2::new(0.5 * (inside.x + outside.x), 0.5 * (inside.y + outside.y));
            if mid == inside || mid == outside {
                break;
            }
            if probe.triangle_height(slot, mid) > 0.0 {
                inside = mid;
            } else {
                outside = mid;
            }
        }
        outside
    }
}

/// Most triangles a cover walk along one grid edge steps through before it
/// gives up (the walk usually takes one to three).
const MAX_COVER_STEPS: usize = 256;

/// What [`Local::contour_near`] found.
enum Near {
    /// The contour is within the accepted distance.
    Within,
    /// The contour point found (farther).
    Found(Point2),
    /// No change of side within reach.
    Missing,
}

/// Margin of a chord's candidate box, in reaches (chord length or grid step).
const CHORD_MARGIN: f64 = 1.5;

/// Growth of the probe distance from one probe to the next.
const PROBE_GROWTH: f64 = 2.0;

/// Probe offset either side of a secant guess, in crossing tolerances: just
/// under a half, so that two probes that straddle the contour close the bracket.
const SECANT_PROBE: f64 = 0.45;

/// Points strictly between `a` and `b` that bring every chord within
/// `chord_tolerance` of the contour at its midpoint (as far as the probe
/// along the chord's normal finds the contour), in order from `a` to `b`.
fn refine_chord(local: &Local<'_>, a: Point2, b: Point2, chord_tolerance: f64, depth: u32, out: &mut Vec<Point2>) {
    let probe = local.probe;
    let d = b - a;
    let length = d.norm();
    if depth >= tol::MAX_REFINE_DEPTH || length <= tol::MIN_CHORD_PER_CROSSING * probe.tolerance {
        return;
    }
    let normal = Vec2::new(-d.y, d.x) / length; // left of a -> b: the inside
    let mid = Point2::new(0.5 * (a.x + b.x), 0.5 * (a.y + b.y));
    // Within a grid cell the contour may bulge up to about a cell away from the
    // chord joining its two crossings (a ridge along the diagonal): reach that far.
    let Near::Found(on) = local.contour_near(mid, normal, chord_tolerance, length.max(probe.step)) else { return };
    if on == a || on == b {
        return;
    }
    refine_chord(local, a, on, chord_tolerance, depth + 1, out);
    out.push(on);
    refine_chord(local, on, b, chord_tolerance, depth + 1, out);
}

/// Closed loops from the grid chains, every chord refined (in parallel over
/// chords; the result does not depend on the number of threads).
pub(crate) fn refine_loops(probe: &Probe<'_>, chains: &[Vec<Point2>], chord_tolerance: f64, z: f64) -> Vec<Loop> {
    let chords: Vec<(Point2, Point2)> =
        chains.iter().flat_map(|c| (0..c.len()).map(move |i| (c[i], c[(i + 1) % c.len()]))).collect();
    let inserted: Vec<Vec<Point2>> = chords
        .par_iter()
        .with_min_len(4)
        .map(|&(a, b)| {
            let mut out = Vec::new();
            // Probes stay within about one reach (the chord or a grid step) of the chord.
            let margin = CHORD_MARGIN * (a - b).norm().max(probe.step);
            let lo = Point2::new(a.x.min(b.x) - margin, a.y.min(b.y) - margin);
            let hi = Point2::new(a.x.max(b.x) + margin, a.y.max(b.y) + margin);
            refine_chord(&probe.local(lo, hi), a, b, chord_tolerance, 0, &mut out);
            out
        })
        .collect();
    let mut loops = Vec::with_capacity(chains.len());
    let mut at = 0;
    for chain in chains {
        let mut points = Vec::with_capacity(chain.len());
        for (p, extra) in chain.iter().zip(&inserted[at..at + chain.len()]) {
            points.push(*p);
            points.extend_from_slice(extra);
        }
        at += chain.len();
        loops.push(Loop { z, points });
    }
    loops
}

#[cfg(test)]
mod tests {
    use scallop_cutter::{Cutter, CutterShape};
    use scallop_geom::{Point2, Point3};
    use scallop_mesh::{MeshIndex, TriMesh};

    use super::Probe;

    /// The candidate list gives the index's heights bit for bit, inside its box and out.
    #[test]
    fn local_heights_equal_the_index_heights() {
        let height =
            |i: usize, j: usize| ((i * 7 + j * 13) % 11) as f64 * 0.7 + if (i + j) % 5 == 0 { 4.0 } else { 0.0 };
        let at = |i: usize, j: usize| Point3::new(i as f64 * 3.0, j as f64 * 3.0, height(i, j));
        let mut soup = Vec::new();
        for j in 0..6 {
            for i in 0..6 {
                soup.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                soup.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        let mesh = TriMesh::from_soup(&soup).expect("terrain").0;
        let index = MeshIndex::build(&mesh);
        for shape in [
            CutterShape::Flat { radius: 1.5 },
            CutterShape::Ball { radius: 2.0 },
            CutterShape::Bull { radius: 2.0, corner: 0.5 },
            CutterShape::Cone { radius: 2.0, half_angle: 0.5 },
        ] {
            let cutter = Cutter::new(shape, 30.0).expect("cutter");
            let probe = Probe { cutter: &cutter, index: &index, z: 3.3, tolerance: 1e-7, step: 0.5 };
            let local = probe.local(Point2::new(4.0, 5.0), Point2::new(9.0, 8.0));
            for k in 0..400 {
                let p = Point2::new(2.0 + (k % 20) as f64 * 0.41, 3.0 + (k / 20) as f64 * 0.33);
                assert_eq!(local.height(p).to_bits(), probe.height(p).to_bits(), "{shape:?} at {p:?}");
            }
        }
    }
}
