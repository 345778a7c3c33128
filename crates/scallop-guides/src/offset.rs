//! Path curves: iterated inward offsets of a curve on a support by Marching
//! Facets (Jousselin 2020, Ch. 2 §3.2.1, the scalar method). Each curve is
//! the iso-line at `a_e` of the signed distance to the previous one (one field
//! per curve: iso-levels of one field would drift apart by more than `a_e` on
//! curved supports), until no facet is crossed. Several loops at a step mean
//! the offset split (Ch. 2 §3.3, Fig. 2.39b).

use scallop_geom::Point3;
use scallop_mesh::{FastMap, PolylineFoot};

use crate::facets::{Isolines, edge_root, march_facets};
use crate::field::CurveField;
use crate::support::{Curve, Support, check_curve};
use crate::{GuideError, tol};

/// One offset step.
#[derive(Clone, Debug, PartialEq)]
pub struct OffsetStep {
    /// The loops (or open chains) of this offset, inside on their left.
    pub curves: Vec<Curve>,
    /// Whether this step has more loops than the one before (a split).
    pub split: bool,
    /// Facets flagged as crossed by the medial axis.
    pub flagged: usize,
    /// Flagged facets whose segment got a repair point.
    pub repaired: usize,
}

/// The successive inward offsets of `limit` (inside on the left of each
/// curve, see [`Curve::inside_left`]) on `support`, `step` (the radial
/// engagement a_e, mm) apart, until they vanish. The first entry is the first
/// offset (C_n itself is not repeated). A loop narrower than
/// [`tol::SLIVER_WIDTH_FACETS`] facets (mean width `2 area / length`) counts
/// as vanished: it is the iso-line of a distance whose maximum barely passes
/// the step, below the mesh's resolution, and where the region is a strip of
/// about twice the step it breaks into a row of such slivers.
///
/// # Errors
/// [`GuideError::BadLength`] for a non-positive step, [`GuideError::BadCurve`]
/// for an unusable curve, [`GuideError::NotVanishing`] if the offsets do not
/// vanish within `diagonal / step + 2` steps.
pub fn offset_curves(support: &Support, limit: &[Curve], step: f64) -> Result<Vec<OffsetStep>, GuideError> {
    check_step(step)?;
    for (i, c) in limit.iter().enumerate() {
        check_curve(c, i)?;
    }
    iterate(support, limit, step, offset_once)
}

/// The loop of [`offset_curves`] with `once` as the single extraction.
fn iterate(
    support: &Support,
    limit: &[Curve],
    step: f64,
    once: impl Fn(&Support, &[Curve], f64) -> Isolines,
) -> Result<Vec<OffsetStep>, GuideError> {
    let guard = (support.mesh().bounds().diagonal() / step).ceil() as usize + tol::EXTRA_STEPS;
    let mut current: Vec<Curve> = limit.to_vec();
    let mut steps: Vec<OffsetStep> = Vec::new();
    while !current.is_empty() {
        if steps.len() >= guard {
            return Err(GuideError::NotVanishing { steps: steps.len() });
        }
        let mut iso = once(support, &current, step);
        let sliver = tol::SLIVER_WIDTH_FACETS * support.facet_size();
        iso.curves.retain(|c| !c.line.closed || 2.0 * c.signed_area().abs() >= sliver * c.line.length());
        if iso.curves.is_empty() {
            break;
        }
        let split = iso.curves.len() > current.len() && !steps.is_empty();
        current = iso.curves.clone();
        steps.push(OffsetStep { curves: iso.curves, split, flagged: iso.flagged, repaired: iso.repaired });
    }
    Ok(steps)
}

/// The single iso-line at `distance` inside `curves` (one Marching Facets
/// extraction over the whole support).
///
/// # Errors
/// [`GuideError::BadLength`] for a non-positive distance,
/// [`GuideError::BadCurve`] for an unusable curve.
pub fn offset_curve(support: &Support, curves: &[Curve], distance: f64) -> Result<Isolines, GuideError> {
    check_step(distance)?;
    for (i, c) in curves.iter().enumerate() {
        check_curve(c, i)?;
    }
    Ok(offset_once(support, curves, distance))
}

/// One Marching Facets extraction that follows the iso-line from facet to
/// facet (docs/guides-curves.md, "The iso-line is followed"): the distance
/// is measured only at the corners of the facets it crosses, and at the few
/// vertices a seed walk passes over. Each segment of the curves that no loop
/// found so far covers ([`Follow::cover`]) gives a seed: the facet nearest to
/// its middle moved `distance` along its left vector (tangent to the
/// support, inward), where the segment's offset lies if no other part of the
/// curves is nearer. From there a walk toward the iso-line finds a crossed
/// edge ([`Follow::seed`]), and the loop through it is followed
/// ([`Follow::follow`]). Values, feet and crossings are those of a full scan
/// that measures every vertex within `distance` + two facets.
fn offset_once(support: &Support, curves: &[Curve], distance: f64) -> Isolines {
    let field = CurveField::new(curves);
    let mut follow = Follow::new(support, &field, distance);
    for (c, line) in field.curves().iter().enumerate() {
        for s in 0..line.segment_count() {
            if follow.covered[c][s] {
                continue;
            }
            let (a, b) = line.segment(s);
            let target = Point3::from((a.coords + b.coords) * 0.5) + field.left(c, s) * distance;
            let found = follow.facets.len();
            follow.seed(support.query().closest_point(&target).triangle);
            follow.cover(found);
        }
    }
    let Follow { values, feet, mut facets, .. } = follow;
    facets.sort_unstable();
    let foot = |v: u32| feet.get(&v);
    // Roots search from the foot of a nearby vertex: the same foot, found faster.
    let exact = |p: &Point3, v: u32| {
        let f = field.foot_near(p, f64::INFINITY, foot(v));
        f.map_or(f64::NEG_INFINITY, |f| field.signed_at(p, &f)) - distance
    };
    let verts = support.mesh().vertices();
    let guess = |a: u32, b: u32, ga: f64, gb: f64| {
        stretch_root(&field, distance, [(verts[a as usize], foot(a)?, ga), (verts[b as usize], foot(b)?, gb)])
    };
    let medial = |f: usize| medial_facet(support, f, |v| foot(v).map(|f| f.point));
    march_facets(support, &values, facets.iter().map(|&f| f as usize), &exact, &guess, &medial)
}

/// The first guess of a crossing (docs/guides-curves.md, "A first guess from
/// the stretch under the edge"): on the edge between `ends` (each its
/// point, its foot on the curves and its value), the root of the signed
/// distance to the stretch of the curves between the two feet
/// ([`CurveField::stretch`], at most [`tol::ROOT_GUESS_SEGMENTS`]
/// segments) minus `distance`. A few segments and no tree: far cheaper than
/// the exact field, and equal to it wherever the crossing's foot is on that
/// stretch, so the exact field usually confirms it in one evaluation.
fn stretch_root(field: &CurveField, distance: f64, ends: [(Point3, &PolylineFoot, f64); 2]) -> Option<f64> {
    let [(pa, fa, ga), (pb, fb, gb)] = ends;
    if !ga.is_finite() || !gb.is_finite() {
        return None;
    }
    let stretch = field.stretch(fa, fb, tol::ROOT_GUESS_SEGMENTS)?;
    let g = |t: f64| field.signed_on(&(pa + (pb - pa) * t), &stretch) - distance;
    Some(edge_root(g, ga, gb, (pb - pa).norm()))
}

/// A facet never seeded nor followed.
const UNSEEN: u8 = 0;
/// A facet a seed walk started from.
const SEEDED: u8 = 1;
/// A facet the iso-line crosses, found by following it.
const CROSSED: u8 = 2;

/// The state of one extraction: the vertices measured so far and the facets
/// found crossed.
struct Follow<'a> {
    support: &'a Support,
    field: &'a CurveField,
    distance: f64,
    /// The bound of a measurement: `distance` + two facets.
    reach: f64,
    /// Per vertex, the signed distance minus `distance`; NaN where not
    /// measured, infinite for a corner beyond the reach given its side.
    values: Vec<f64>,
    /// The feet of the measured vertices.
    feet: FastMap<u32, PolylineFoot>,
    /// Per facet, [`UNSEEN`], [`SEEDED`] or [`CROSSED`].
    marks: Vec<u8>,
    /// The facets found crossed, in the order found.
    facets: Vec<u32>,
    /// Per curve of the field, per segment: whether a loop found is its
    /// offset.
    covered: Vec<Vec<bool>>,
}

impl<'a> Follow<'a> {
    fn new(support: &'a Support, field: &'a CurveField, distance: f64) -> Follow<'a> {
        Follow {
            support,
            field,
            distance,
            reach: distance + 2.0 * support.facet_size(),
            values: vec![f64::NAN; support.mesh().vertices().len()],
            feet: FastMap::default(),
            marks: vec![UNSEEN; support.mesh().triangles().len()],
            facets: Vec::new(),
            covered: field.curves().iter().map(|c| vec![false; c.segment_count()]).collect(),
        }
    }

    /// Marks as covered the segments of the curves whose offset passes
    /// through the crossed facets `facets[from..]`: per facet not crossed by
    /// the medial axis ([`medial_facet`]), the segments of its corners' feet
    /// and those between them along the shorter way, if not longer than
    /// twice [`tol::MEDIAL_FOOT_FACTOR`] facet sizes (a longer way means the
    /// feet are near each other across a gap, not along the curve).
    fn cover(&mut self, from: usize) {
        let tris = self.support.mesh().triangles();
        let bound = 2.0 * tol::MEDIAL_FOOT_FACTOR * self.support.facet_size();
        for &f in &self.facets[from..] {
            let t = tris[f as usize];
            let [Some(a), Some(b), Some(c)] = t.map(|v| self.feet.get(&v)) else { continue };
            if a.curve != b.curve
                || a.curve != c.curve
                || medial_facet(self.support, f as usize, |v| self.feet.get(&v).map(|f| f.point))
            {
                continue;
            }
            let line = &self.field.curves()[a.curve];
            let mut s = [a.segment, b.segment, c.segment];
            s.sort_unstable();
            let n = line.segment_count();
            // The arcs from each foot's segment forward to the one before it
            // (only the first on an open curve).
            let arcs = [(s[0], s[2] - s[0]), (s[1], s[0] + n - s[1]), (s[2], s[1] + n - s[2])];
            let arcs = if line.closed { &arcs[..] } else { &arcs[..1] };
            let Some(&(start, len)) = arcs.iter().min_by_key(|a| a.1) else { continue };
            let seg = |k: usize| (start + k) % n;
            let length: f64 = (1..len)
                .map(|k| {
                    let (p, q) = line.segment(seg(k));
                    (q - p).norm()
                })
                .sum();
            if length <= bound {
                for k in 0..=len {
                    self.covered[a.curve][seg(k)] = true;
                }
            }
        }
    }

    /// The value of vertex `v` (NaN beyond the reach), measured once,
    /// searching from the foot of vertex `near` if measured (the same foot,
    /// found faster).
    fn measure(&mut self, v: u32, near: Option<u32>) -> f64 {
        let known = self.values[v as usize];
        if !known.is_nan() {
            return known;
        }
        let p = self.support.mesh().vertices()[v as usize];
        let hint = near.and_then(|n| self.feet.get(&n));
        let Some(f) = self.field.foot_near(&p, self.reach, hint) else { return f64::NAN };
        let g = self.field.signed_at(&p, &f) - self.distance;
        self.values[v as usize] = g;
        self.feet.insert(v, f);
        g
    }

    /// A walk from a corner of facet `f` to the iso-line: from vertex to
    /// neighbour, up the values while negative, down while positive, until
    /// an edge changes state (whose loop is then followed) or no neighbour
    /// is nearer the iso-line (no loop passes there: the offset vanished or
    /// another part of the curves is nearer).
    fn seed(&mut self, f: usize) {
        if self.marks[f] != UNSEEN {
            return;
        }
        self.marks[f] = SEEDED;
        let support = self.support;
        let mut v = support.mesh().triangles()[f][0];
        let mut gv = self.measure(v, None);
        while gv.is_finite() {
            let mut best = (v, gv);
            for &w in support.neighbours(v as usize) {
                let gw = self.measure(w, Some(v));
                if !gw.is_finite() {
                    continue;
                }
                if (gw > 0.0) != (gv > 0.0) {
                    self.follow(v, w);
                    return;
                }
                if (gv > 0.0 && gw < best.1) || (gv <= 0.0 && gw > best.1) {
                    best = (w, gw);
                }
            }
            if best.0 == v {
                return;
            }
            (v, gv) = best;
        }
    }

    /// Marks every facet reachable from the crossed edge `(a, b)` through
    /// crossed edges, measuring the third corner of each. A corner beyond
    /// the reach takes the side of the lower-numbered end of the edge it
    /// was reached from: it is more than a facet from the curves, so no
    /// edge from it crosses them.
    fn follow(&mut self, a: u32, b: u32) {
        let support = self.support;
        let tris = support.mesh().triangles();
        let mut stack = vec![(a, b)];
        while let Some((a, b)) = stack.pop() {
            for &f in support.vertex_facets(a as usize) {
                let t = tris[f as usize];
                if self.marks[f as usize] == CROSSED || !t.contains(&b) {
                    continue;
                }
                self.marks[f as usize] = CROSSED;
                self.facets.push(f);
                let Some(c) = t.into_iter().find(|&x| x != a && x != b) else { continue };
                if self.measure(c, Some(a)).is_nan() {
                    let side = self.values[a.min(b) as usize] > 0.0;
                    self.values[c as usize] = if side { f64::INFINITY } else { f64::NEG_INFINITY };
                }
                let pos = |v: u32| self.values[v as usize] > 0.0;
                let next = if pos(a) == pos(c) { (b, c) } else { (a, c) };
                stack.push(next);
            }
        }
    }
}

/// Whether facet `f` is crossed by the medial axis: the feet of its corners
/// (`foot(v)`, `None` when not measured) are farther apart than
/// [`tol::MEDIAL_FOOT_FACTOR`] times its longest edge.
fn medial_facet(support: &Support, f: usize, foot: impl Fn(u32) -> Option<Point3>) -> bool {
    let mesh = support.mesh();
    let [Some(a), Some(b), Some(c)] = mesh.triangles()[f].map(foot) else { return false };
    let spread = (a - b).norm().max((b - c).norm()).max((c - a).norm());
    let tri = mesh.triangle(f);
    let size = (tri[1] - tri[0]).norm().max((tri[2] - tri[1]).norm()).max((tri[0] - tri[2]).norm());
    spread > tol::MEDIAL_FOOT_FACTOR * size
}

pub(crate) fn check_step(step: f64) -> Result<(), GuideError> {
    if step.is_finite() && step > 0.0 { Ok(()) } else { Err(GuideError::BadLength { name: "a_e", value: step }) }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, reason = "a test: a panic is the failure report")]

    use proptest::prelude::*;
    use scallop_mesh::{Polyline3, TriMesh};

    use super::*;

    /// The brute-force oracle of [`offset_once`]: every vertex within the
    /// reach measured, the others given their side by a flood over the vertex
    /// adjacency from the measured ones (taken in order), every facet marched.
    /// The crossings start from the same first guesses ([`stretch_root`] on
    /// the feet of the edge's ends), so the comparison is of the following;
    /// `every_point_is_on_the_iso_line` checks the roots.
    fn offset_once_scan(support: &Support, curves: &[Curve], distance: f64) -> Isolines {
        let field = CurveField::new(curves);
        let reach = distance + 2.0 * support.facet_size();
        let verts = support.mesh().vertices();
        let feet: Vec<Option<PolylineFoot>> = verts.iter().map(|p| field.foot_within(p, reach)).collect();
        let mut values: Vec<f64> =
            verts.iter().zip(&feet).map(|(p, f)| f.map_or(f64::NAN, |f| field.signed_at(p, &f) - distance)).collect();
        let mut queue: std::collections::VecDeque<usize> = (0..verts.len()).filter(|&v| feet[v].is_some()).collect();
        loop {
            while let Some(u) = queue.pop_front() {
                let side = if values[u] > 0.0 { f64::INFINITY } else { f64::NEG_INFINITY };
                for &w in support.neighbours(u) {
                    if values[w as usize].is_nan() {
                        values[w as usize] = side;
                        queue.push_back(w as usize);
                    }
                }
            }
            let Some(v) = values.iter().position(|x| x.is_nan()) else { break };
            values[v] = if field.signed(&verts[v]) > 0.0 { f64::INFINITY } else { f64::NEG_INFINITY };
            queue.push_back(v);
        }
        let exact = |p: &Point3, _| field.signed(p) - distance;
        let guess = |a: u32, b: u32, ga: f64, gb: f64| {
            let end = |v: u32| Some((verts[v as usize], feet[v as usize].as_ref()?));
            let ((pa, fa), (pb, fb)) = (end(a)?, end(b)?);
            stretch_root(&field, distance, [(pa, fa, ga), (pb, fb, gb)])
        };
        let medial = |f: usize| medial_facet(support, f, |v| feet[v as usize].map(|f| f.point));
        march_facets(support, &values, 0..support.mesh().triangles().len(), &exact, &guess, &medial)
    }

    /// `z = height(x, y)` over `[-half, half]^2` in `n x n` cells.
    fn terrain(n: usize, half: f64, height: impl Fn(f64, f64) -> f64) -> Support {
        let mut v = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (x, y) = (2.0 * half * i as f64 / n as f64 - half, 2.0 * half * j as f64 / n as f64 - half);
                v.push(Point3::new(x, y, height(x, y)));
            }
        }
        Support::new(TriMesh::from_indexed(&v, &scallop_mesh::grid_triangles(n, n)).unwrap().0)
    }

    /// A closed loop of 240 points `r(t)` about `(cx, cy)` lifted onto `support`.
    fn polar_loop(
        support: &Support,
        height: impl Fn(f64, f64) -> f64,
        cx: f64,
        cy: f64,
        r: impl Fn(f64) -> f64,
    ) -> Curve {
        let pts: Vec<Point3> = (0..240)
            .map(|i| {
                let t = std::f64::consts::TAU * f64::from(i) / 240.0;
                let (x, y) = (cx + r(t) * t.cos(), cy + r(t) * t.sin());
                support.query().closest_point(&Point3::new(x, y, height(x, y))).point
            })
            .collect();
        support.curve(Polyline3::new(pts, true)).unwrap().inside_left()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// Following the iso-line from the seeds gives, bit for bit, the
        /// offsets of the full scan on random terrains and random star-shaped
        /// loops (peanuts split).
        #[test]
        fn following_gives_the_full_scan_offsets(
            n in 24usize..64, amp in 0.0..6.0f64, wx in 6.0..30.0f64, wy in 6.0..30.0f64,
            r0 in 8.0..17.0f64, wobble in 0.0..0.45f64, lobes in 1u32..5, phase in 0.0..6.3f64,
            cx in -3.0..3.0f64, a_e in 1.0..6.0f64,
        ) {
            let height = move |x: f64, y: f64| amp * (x / wx).sin() * (y / wy).cos();
            let support = terrain(n, 20.0, height);
            let limit = polar_loop(&support, height, cx, 0.0, |t| r0 * (1.0 + wobble * (f64::from(lobes) * t + phase).sin()));
            let fast = iterate(&support, std::slice::from_ref(&limit), a_e, offset_once).unwrap();
            let scan = iterate(&support, std::slice::from_ref(&limit), a_e, offset_once_scan).unwrap();
            // The loop holds a disc of radius r0 (1 - wobble): a_e under half of it leaves an offset.
            prop_assert!(!fast.is_empty() || 2.0 * a_e > r0 * (1.0 - wobble));
            prop_assert_eq!(fast, scan);
        }

        /// Every point of every offset, found from a first guess or not, is
        /// within the root tolerance of the iso-value of the field of the
        /// curves before it.
        #[test]
        fn every_point_is_on_the_iso_line(
            n in 24usize..64, amp in 0.0..6.0f64, r0 in 8.0..17.0f64, wobble in 0.0..0.45f64, lobes in 1u32..5,
            a_e in 1.0..6.0f64,
        ) {
            let height = move |x: f64, y: f64| amp * (x / 9.0).sin() * (y / 13.0).cos();
            let support = terrain(n, 20.0, height);
            let limit = polar_loop(&support, height, 0.0, 0.0, |t| r0 * (1.0 + wobble * (f64::from(lobes) * t).sin()));
            let steps = iterate(&support, std::slice::from_ref(&limit), a_e, offset_once).unwrap();
            let mut previous = vec![limit];
            for step in steps {
                let field = CurveField::new(&previous);
                for p in step.curves.iter().flat_map(|c| c.line.points.iter()) {
                    let g = field.signed(p) - a_e;
                    prop_assert!(g.abs() <= tol::ROOT_TOLERANCE, "{p} is {g} mm off the iso-line");
                }
                previous = step.curves;
            }
        }

        /// A dumbbell whose neck closes before its lobes: the offsets split
        /// into two loops, each found, as by the full scan; likewise two
        /// separate limit loops of different sizes offset together.
        #[test]
        fn every_loop_is_found_when_offsets_split(
            n in 40usize..72, amp in 0.0..4.0f64, neck in 0.58..0.65f64, a_e in 0.8..1.6f64, phase in 0.0..0.3f64,
        ) {
            let height = move |x: f64, y: f64| amp * (x / 11.0).sin() * (y / 13.0).cos();
            let support = terrain(n, 20.0, height);
            let dumbbell = polar_loop(&support, height, 0.0, 0.0, |t| 10.0 * (1.0 + neck * (2.0 * (t + phase)).cos()));
            let fast = iterate(&support, std::slice::from_ref(&dumbbell), a_e, offset_once).unwrap();
            prop_assert!(fast.iter().any(|s| s.split && s.curves.len() == 2));
            prop_assert_eq!(&fast, &iterate(&support, std::slice::from_ref(&dumbbell), a_e, offset_once_scan).unwrap());
            let pair = [
                polar_loop(&support, height, -9.0, -6.0, |_| 8.0),
                polar_loop(&support, height, 10.0, 8.0, |t| 6.0 + 0.5 * (3.0 * t).sin()),
            ];
            let fast = iterate(&support, &pair, a_e, offset_once).unwrap();
            prop_assert_eq!(fast[0].curves.len(), 2);
            prop_assert_eq!(fast, iterate(&support, &pair, a_e, offset_once_scan).unwrap());
        }
    }
}
