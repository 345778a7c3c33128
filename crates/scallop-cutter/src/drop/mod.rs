//! Drop-cutter: the lowest tool-tip z at (x, y) where the cutter touches the
//! mesh and penetrates nothing.
//!
//! The result is the maximum, over every triangle within the cutter's disk,
//! of three contact candidates (after OpenCAMLib's design, re-derived here):
//! - [`vertex`]: a corner at horizontal distance rho <= R gives `z - h(rho)`;
//! - [`facet`]: the cutter's support point towards the triangle's plane, when it
//!   lies inside the triangle (exact predicate; the boundary is covered by the
//!   edge and vertex cases, so the interior test may be strict or closed);
//! - [`edge`]: the maximum of `z(x) - h(sqrt(x^2 + d^2))` along the edge, a
//!   concave function, solved per shape in closed form or by a safeguarded
//!   Newton iteration on a monotone function (bull-nose).
//!
//! Pruning: a contact on a triangle is never higher than the triangle's highest
//! corner, so a triangle (or a subtree of the index) whose highest z does not
//! exceed the best height found so far is skipped. Skipping cannot change the
//! maximum, so the indexed result equals [`drop_cutter_brute_force`] exactly.

mod clear;
mod edge;
mod facet;
mod reach;
mod vertex;

use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use scallop_geom::{Aabb2, Point2, Point3, Vec3, tol};
use scallop_mesh::MeshIndex;

use crate::Cutter;
use crate::shape::Profile;

/// Which feature of the mesh the cutter rests on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Contact {
    /// Nothing under the cutter: the tip sits on the floor height.
    Floor,
    /// A triangle corner.
    Vertex {
        /// Triangle number in the source mesh.
        triangle: usize,
        /// Contact point on the mesh.
        point: Point3,
    },
    /// A triangle edge.
    Edge {
        /// Triangle number in the source mesh.
        triangle: usize,
        /// Contact point on the mesh.
        point: Point3,
    },
    /// The interior of a triangle.
    Facet {
        /// Triangle number in the source mesh.
        triangle: usize,
        /// Contact point on the mesh.
        point: Point3,
    },
}

/// A cutter location: the tool tip (lowest point of the cutter on its axis) and the contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClPoint {
    /// Tool tip (mm).
    pub tip: Point3,
    /// What the cutter touches.
    pub contact: Contact,
}

impl ClPoint {
    /// A point resting on the floor.
    #[must_use]
    pub fn floor(xy: Point2, floor: f64) -> ClPoint {
        ClPoint { tip: Point3::new(xy.x, xy.y, floor), contact: Contact::Floor }
    }
}

/// Raises `best` to the highest contact of `cutter` at `best.tip.xy` with one
/// triangle (`corners`, unit `normal` with z >= 0, number `triangle` for the
/// report). Only strictly higher candidates replace `best`.
pub fn drop_triangle(cutter: &Cutter, corners: &[Point3; 3], normal: &Vec3, triangle: usize, best: &mut ClPoint) {
    drop_triangle_profile(&Profile::new(cutter.shape()), corners, normal, triangle, best);
}

#[inline]
fn drop_triangle_profile(profile: &Profile, corners: &[Point3; 3], normal: &Vec3, triangle: usize, best: &mut ClPoint) {
    drop_features(profile, corners, normal, triangle, ALL_FEATURES, best);
}

/// All corners and edges: see [`MeshIndex::owned_features`] for the bits.
const ALL_FEATURES: u8 = 0b11_1111;

/// A feature bit of [`BoxDrop::drop_one_features`] past the corners and
/// edges: the facet is left out (set by [`BoxDrop::contact_features`] for a
/// corner or edge contact; the index's owned features never set it).
const NO_FACET: u8 = 0b100_0000;

/// The contacts of one triangle, its corners and edges restricted to `features`.
#[inline]
fn drop_features(
    profile: &Profile,
    corners: &[Point3; 3],
    normal: &Vec3,
    triangle: usize,
    features: u8,
    best: &mut ClPoint,
) {
    let c = Point2::new(best.tip.x, best.tip.y);
    let plane = if features & NO_FACET == 0 { facet::plane_contact(profile, corners, normal, c) } else { None };
    if let Some(plane) = &plane {
        // Nothing on the triangle's plane can hold the tip above the plane contact
        // (the slack keeps this conservative under rounding).
        let slack = tol::REL_PRUNE_SLACK * (plane.tip.abs() + profile.radius + 1.0);
        if plane.tip + slack <= best.tip.z {
            return;
        }
    }
    vertex::drop_vertices(profile, corners, features, triangle, c, best);
    if let Some(plane) = &plane {
        facet::drop_facet(plane, corners, triangle, best);
    }
    for k in 0..3 {
        let (a, b) = (&corners[k], &corners[(k + 1) % 3]);
        if features & (1 << (3 + k)) != 0 && a.z.max(b.z) > best.tip.z {
            edge::drop_edge(profile, a, b, triangle, c, best);
        }
    }
}

/// Drop-cutter at one point through the index. `floor` is the lowest tip
/// height returned (where nothing is under the cutter).
#[must_use]
pub fn drop_cutter(cutter: &Cutter, index: &MeshIndex, xy: Point2, floor: f64) -> ClPoint {
    drop_seeded(cutter, index, xy, floor, None).0
}

/// Drop-cutter that first tries the triangle in `seed` (typically the contact
/// of the neighbouring grid point): its contact is a valid lower bound that
/// lets the search prune from the start. Returns the slot of the contact.
fn drop_seeded(
    cutter: &Cutter,
    index: &MeshIndex,
    xy: Point2,
    floor: f64,
    seed: Option<usize>,
) -> (ClPoint, Option<usize>) {
    let profile = Profile::new(cutter.shape());
    let mut best = ClPoint::floor(xy, floor);
    let mut best_slot = None;
    if let Some(slot) = seed {
        drop_triangle_profile(&profile, index.corners(slot), index.normal(slot), index.original_index(slot), &mut best);
        if !matches!(best.contact, Contact::Floor) {
            best_slot = Some(slot);
        }
    }
    drop_search(&profile, index, &mut best, &mut best_slot);
    (best, best_slot)
}

/// The index search of [`drop_seeded`] from `best` (its tip's XY is the point).
fn drop_search(profile: &Profile, index: &MeshIndex, best: &mut ClPoint, best_slot: &mut Option<usize>) {
    let mut bound = best.tip.z;
    let xy = Point2::new(best.tip.x, best.tip.y);
    index.visit_disk(
        xy,
        profile.radius,
        |d2| profile.height(d2.sqrt()),
        &mut bound,
        |slot, bound| {
            let before = best.tip.z;
            drop_triangle_profile(profile, index.corners(slot), index.normal(slot), index.original_index(slot), best);
            if best.tip.z > before {
                *best_slot = Some(slot);
            }
            *bound = best.tip.z;
        },
    );
}

/// The test oracle: every triangle, no index, no pruning.
#[must_use]
pub fn drop_cutter_brute_force(cutter: &Cutter, index: &MeshIndex, xy: Point2, floor: f64) -> ClPoint {
    let profile = Profile::new(cutter.shape());
    let mut best = ClPoint::floor(xy, floor);
    for slot in 0..index.len() {
        drop_triangle_profile(&profile, index.corners(slot), index.normal(slot), index.original_index(slot), &mut best);
    }
    best
}

/// Drop-cutter at many points, in parallel; the output is in input order and
/// does not depend on the number of threads.
#[must_use]
pub fn drop_points(cutter: &Cutter, index: &MeshIndex, points: &[Point2], floor: f64) -> Vec<ClPoint> {
    points.par_iter().with_min_len(256).map(|&p| drop_cutter(cutter, index, p, floor)).collect()
}

/// Drop-cutter on the grid `xs` x `ys`, row-major with x fastest, in parallel
/// over rows. `progress(rows_done)` is called after each row (from any thread).
///
/// Each row is cut into blocks of neighbouring points that share one candidate
/// list (the triangles whose XY box meets the block's reach), sorted by an
/// upper bound of what each can give anywhere in the block: a point scans it until no remaining triangle can rise above its
/// current best, seeded with the previous point's contact triangle. The
/// result equals [`drop_cutter`] at every point, bit for bit.
#[must_use]
pub fn drop_grid(
    cutter: &Cutter,
    index: &MeshIndex,
    xs: &[f64],
    ys: &[f64],
    floor: f64,
    progress: &(dyn Fn(usize) + Sync),
) -> Vec<ClPoint> {
    let done = AtomicUsize::new(0);
    let profile = Profile::new(cutter.shape());
    let radius = profile.radius;
    // Each row writes its own slice of the output: no per-row vectors, no
    // serial concatenation at the end.
    // Initialised in parallel too: a serial fill of a large grid (64 bytes a
    // point) would be the serial fraction that limits the second thread.
    let mut out: Vec<ClPoint> =
        (0..xs.len() * ys.len()).into_par_iter().map(|_| ClPoint::floor(Point2::origin(), floor)).collect();
    if xs.is_empty() {
        return out;
    }
    out.par_chunks_mut(xs.len()).zip(ys.par_iter()).for_each_init(BlockScratch::default, |scratch, (row, &y)| {
        let mut seed = None;
        let mut start = 0;
        while start < xs.len() {
            // A block spans about one cutter diameter (at most BLOCK_POINTS points).
            let mut end = start + 1;
            while end < xs.len() && end - start < BLOCK_POINTS && (xs[end] - xs[start]).abs() <= 2.0 * radius {
                end += 1;
            }
            let (x0, x1) = (xs[start].min(xs[end - 1]), xs[start].max(xs[end - 1]));
            scratch.fill(index, &profile, [x0, y], [x1, y]);
            for (slot_out, &x) in row[start..end].iter_mut().zip(&xs[start..end]) {
                let (cl, slot) =
                    drop_candidates(&profile, index, &scratch.sorted, Point2::new(x, y), floor, seed, None);
                seed = slot;
                *slot_out = cl;
            }
            start = end;
        }
        progress(done.fetch_add(1, Ordering::Relaxed) + 1);
    });
    out
}

/// Drop-cutter on the small grid `xs` x `ys` (row-major, x fastest), on the
/// calling thread, with one candidate list for the whole patch (as a block of
/// [`drop_grid`] shares one for a run of a row): for patches a few samples
/// wide, where a list per row would cost more than the drops. Rows are walked
/// back and forth, each point seeded with its predecessor's contact. The
/// heights equal [`drop_cutter`]'s at every point, bit for bit; where two
/// triangles give the same height, the contact reported may differ.
#[must_use]
pub fn drop_patch(cutter: &Cutter, index: &MeshIndex, xs: &[f64], ys: &[f64], floor: f64) -> Vec<ClPoint> {
    let mut out: Vec<ClPoint> = vec![ClPoint::floor(Point2::origin(), floor); xs.len() * ys.len()];
    let (Some(&x0), Some(&x1), Some(&y0), Some(&y1)) = (xs.first(), xs.last(), ys.first(), ys.last()) else {
        return out;
    };
    let profile = Profile::new(cutter.shape());
    let mut scratch = BlockScratch::default();
    scratch.fill(index, &profile, [x0.min(x1), y0.min(y1)], [x0.max(x1), y0.max(y1)]);
    let mut seed = None;
    for (j, &y) in ys.iter().enumerate() {
        let row = &mut out[j * xs.len()..(j + 1) * xs.len()];
        for k in 0..xs.len() {
            let i = if j % 2 == 0 { k } else { xs.len() - 1 - k };
            let (cl, slot) =
                drop_candidates(&profile, index, &scratch.sorted, Point2::new(xs[i], y), floor, seed, None);
            seed = slot;
            row[i] = cl;
        }
    }
    out
}

/// Drop-cutter at a sequence of nearby points (a path sampled densely), in
/// parallel over blocks of consecutive points; the output is in input order.
///
/// Consecutive points whose XY box stays within one cutter diameter (at most
/// 64 points) share one candidate list, as the rows of [`drop_grid`] do, each
/// point seeded with its predecessor's contact triangle. The result equals
/// [`drop_cutter`] at every point, bit for bit, and does not depend on the
/// number of threads. Far-apart points simply make blocks of one.
#[must_use]
pub fn drop_path(cutter: &Cutter, index: &MeshIndex, points: &[Point2], floor: f64) -> Vec<ClPoint> {
    let profile = Profile::new(cutter.shape());
    let span = 2.0 * profile.radius;
    // Blocks: [start, end) with their boxes.
    let mut blocks: Vec<(usize, usize, [f64; 2], [f64; 2])> = Vec::new();
    let mut start = 0;
    while start < points.len() {
        let (mut lo, mut hi) = ([points[start].x, points[start].y], [points[start].x, points[start].y]);
        let mut end = start + 1;
        while end < points.len() && end - start < BLOCK_POINTS {
            let p = points[end];
            let (nlo, nhi) = ([lo[0].min(p.x), lo[1].min(p.y)], [hi[0].max(p.x), hi[1].max(p.y)]);
            // Negated so that a NaN coordinate ends the block.
            if !(nhi[0] - nlo[0] <= span && nhi[1] - nlo[1] <= span) {
                break;
            }
            (lo, hi) = (nlo, nhi);
            end += 1;
        }
        blocks.push((start, end, lo, hi));
        start = end;
    }
    let mut out: Vec<ClPoint> = points.iter().map(|&p| ClPoint::floor(p, floor)).collect();
    let mut chunks: Vec<&mut [ClPoint]> = Vec::with_capacity(blocks.len());
    let mut rest: &mut [ClPoint] = &mut out;
    for &(start, end, _, _) in &blocks {
        let (head, tail) = rest.split_at_mut(end - start);
        chunks.push(head);
        rest = tail;
    }
    chunks.into_par_iter().zip(blocks.par_iter()).for_each_init(BlockScratch::default, |scratch, (chunk, block)| {
        let &(start, end, lo, hi) = block;
        if lo.iter().chain(&hi).all(|v| v.is_finite()) {
            scratch.fill(index, &profile, lo, hi);
            let mut seed = None;
            for (slot_out, &xy) in chunk.iter_mut().zip(&points[start..end]) {
                let (cl, slot) = drop_candidates(&profile, index, &scratch.sorted, xy, floor, seed, None);
                seed = slot;
                *slot_out = cl;
            }
        } else {
            for (slot_out, &xy) in chunk.iter_mut().zip(&points[start..end]) {
                *slot_out = drop_cutter(cutter, index, xy, floor);
            }
        }
    });
    out
}

/// The drop-cutter restricted to the points of one box: the triangles within
/// the cutter's reach of the box, sorted by decreasing upper bound (as the
/// blocks of [`drop_grid`]), so that many evaluations near each other (a
/// bisection, a cell's subdivision) share one index query. Every height is
/// [`drop_cutter`]'s up to rounding: the same contacts, each mesh corner and
/// edge tested once, by the triangle that owns it (as [`drop_grid`]), where
/// the index tests a shared edge from both triangles (in opposite directions,
/// which can differ in the last bit); on a triangle soup, bit for bit. Points
/// outside the box fall back to the index.
#[derive(Debug, Clone)]
pub struct BoxDrop<'a> {
    profile: Profile,
    index: &'a MeshIndex,
    lo: Point2,
    hi: Point2,
    candidates: Vec<Candidate>,
    /// Per candidate, the ball's last clear centre and its margin squared
    /// (see [`drop_candidates`]); a negative margin matches nothing.
    clear: Vec<Cell<[f64; 4]>>,
}

impl<'a> BoxDrop<'a> {
    /// The candidate list of `cutter` on `index` for points of the box `[lo, hi]`.
    ///
    /// ```
    /// use scallop_cutter::{BoxDrop, Cutter, CutterShape, drop_cutter};
    /// use scallop_geom::{Point2, Point3};
    /// use scallop_mesh::{MeshIndex, TriMesh};
    /// let p = |x, y, z| Point3::new(x, y, z);
    /// let (mesh, _) = TriMesh::from_soup(&[[p(0., 0., 0.), p(4., 0., 0.), p(0., 4., 3.)]]).unwrap();
    /// let index = MeshIndex::build(&mesh);
    /// let ball = Cutter::new(CutterShape::Ball { radius: 1.0 }, 10.0).unwrap();
    /// let local = BoxDrop::new(&ball, &index, Point2::new(0., 0.), Point2::new(1., 1.));
    /// let q = Point2::new(0.5, 0.7);
    /// assert_eq!(local.drop(q, -5.0, None).0, drop_cutter(&ball, &index, q, -5.0));
    /// ```
    #[must_use]
    pub fn new(cutter: &Cutter, index: &'a MeshIndex, lo: Point2, hi: Point2) -> Self {
        let profile = Profile::new(cutter.shape());
        let mut scratch = BlockScratch::default();
        scratch.fill(index, &profile, [lo.x, lo.y], [hi.x, hi.y]);
        let clear = vec![Cell::new([0.0, 0.0, 0.0, -1.0]); scratch.sorted.len()];
        BoxDrop { profile, index, lo, hi, candidates: scratch.sorted, clear }
    }

    /// Drop-cutter at `xy` with the tip floored at `floor`, first trying the
    /// triangle in `seed` (a valid lower bound: same result), and the slot of
    /// the triangle that gives the height (`None` on the floor).
    #[must_use]
    pub fn drop(&self, xy: Point2, floor: f64, seed: Option<usize>) -> (ClPoint, Option<usize>) {
        let inside = xy.x >= self.lo.x && xy.x <= self.hi.x && xy.y >= self.lo.y && xy.y <= self.hi.y;
        if inside {
            drop_candidates(&self.profile, self.index, &self.candidates, xy, floor, seed, Some(&self.clear))
        } else {
            let mut best = ClPoint::floor(xy, floor);
            let mut best_slot = None;
            drop_search(&self.profile, self.index, &mut best, &mut best_slot);
            (best, best_slot)
        }
    }

    /// The drop-cutter on the one triangle in `slot` at `xy` (all its corners
    /// and edges), floored at `floor`, as [`drop_triangle`].
    #[must_use]
    pub fn drop_one(&self, slot: usize, xy: Point2, floor: f64) -> ClPoint {
        let mut best = ClPoint::floor(xy, floor);
        let ix = self.index;
        drop_triangle_profile(&self.profile, ix.corners(slot), ix.normal(slot), ix.original_index(slot), &mut best);
        best
    }
}

impl BoxDrop<'_> {
    /// The drop-cutter on the one triangle in `slot` at `xy` restricted to
    /// its facet and the corners and edges in `features` (bits as
    /// [`MeshIndex::owned_features`]; with bit 6 set, as
    /// [`BoxDrop::contact_features`] sets it for a corner or an edge contact,
    /// without the facet), floored at `floor`: at most
    /// [`BoxDrop::drop_one`]'s height (a maximum over fewer contacts), and
    /// equal to it where the features hold `drop_one`'s contact. Cheaper where
    /// few edges are kept (an edge contact costs most).
    #[must_use]
    pub fn drop_one_features(&self, slot: usize, features: u8, xy: Point2, floor: f64) -> ClPoint {
        let mut best = ClPoint::floor(xy, floor);
        let ix = self.index;
        drop_features(&self.profile, ix.corners(slot), ix.normal(slot), ix.original_index(slot), features, &mut best);
        best
    }

    /// The corners and edges (bits as [`MeshIndex::owned_features`]) of the
    /// triangle in `slot` that hold `contact`, a contact of that triangle: a
    /// corner's bit; an edge's bit and its two corners' bits; every bit for a
    /// facet contact (the contact moves onto an edge where the facet's ends),
    /// or for a contact of another triangle or the floor. For a corner or an
    /// edge, bit 6 too: the facet left out (it did not hold the contact, and a
    /// plane contact costs about as much as a corner and an edge's bounds).
    /// Either way [`BoxDrop::drop_one_features`] on these features gives the
    /// triangle's height, bit for bit.
    #[must_use]
    pub fn contact_features(&self, slot: usize, contact: &Contact) -> u8 {
        let corners = self.index.corners(slot);
        match contact {
            Contact::Vertex { point, .. } => {
                corners.iter().position(|c| c == point).map_or(ALL_FEATURES, |k| (1 << k) | NO_FACET)
            }
            Contact::Edge { point, .. } => {
                // The edge nearest the contact point in space (the point was
                // computed on it; in XY alone the edges of a vertical facet
                // overlap).
                let distance = |k: usize| {
                    let (a, b) = (&corners[k], &corners[(k + 1) % 3]);
                    let (e, w) = (*b - *a, *point - *a);
                    let len2 = e.dot(&e);
                    let t = if len2 > 0.0 { (w.dot(&e) / len2).clamp(0.0, 1.0) } else { 0.0 };
                    (w - e * t).norm()
                };
                // Every edge as near, up to rounding (a contact at a corner lies
                // on two edges, which may differ in the last bit there).
                let d = [distance(0), distance(1), distance(2)];
                let near =
                    d.iter().copied().fold(f64::INFINITY, f64::min) + tol::REL_ROUNDING * (point.coords.norm() + 1.0);
                (0..3)
                    .filter(|&k| d[k] <= near)
                    .fold(NO_FACET, |bits, k| bits | (1 << (3 + k)) | (1 << k) | (1 << ((k + 1) % 3)))
            }
            Contact::Facet { .. } | Contact::Floor => ALL_FEATURES,
        }
    }

    /// The gradient (mm per mm, in XY) at `xy` of the tip height given by a
    /// contact at `contact`'s point with the cutter at `xy` (of the triangle's
    /// height, or of the drop-cutter's, where that contact is its only one):
    /// by the envelope theorem, the derivative of `q.z - h(|q - xy|)` in `xy`
    /// at the contact point q, `h'(rho) (q - xy) / rho`. `None` on the floor,
    /// where the contact is on the cutter's axis or the profile's slope is 0 or
    /// infinite there (a flat bottom, a ball's rim). A guess for root finders:
    /// the heights themselves come from evaluations.
    #[must_use]
    pub fn contact_gradient(&self, contact: &Contact, xy: Point2) -> Option<[f64; 2]> {
        let q = match contact {
            Contact::Vertex { point, .. } | Contact::Edge { point, .. } | Contact::Facet { point, .. } => point,
            Contact::Floor => return None,
        };
        let (dx, dy) = (q.x - xy.x, q.y - xy.y);
        let rho = (dx * dx + dy * dy).sqrt();
        // On the axis, or on the rim (a cone's, which holds the contact
        // while the cutter moves: the envelope theorem does not apply there).
        if !(rho > 0.0 && rho < RIM_FRACTION * self.profile.radius) {
            return None;
        }
        let k = self.profile.slope(rho)? / rho;
        Some([k * dx, k * dy])
    }

    /// Whether the one triangle in `slot` lifts the cutter at `xy` above `z`:
    /// the answer of `drop_one(slot, xy, floor).tip.z > z` for any floor below
    /// z (every contact is computed as there), found with the search pruned
    /// at z instead of at the floor (the bounds that skip a corner, an edge or
    /// the whole triangle keep the prune slack).
    #[must_use]
    pub fn lifts(&self, slot: usize, xy: Point2, z: f64) -> bool {
        let mut best = ClPoint::floor(xy, z);
        let ix = self.index;
        drop_triangle_profile(&self.profile, ix.corners(slot), ix.normal(slot), ix.original_index(slot), &mut best);
        best.tip.z > z
    }

    /// A guess of where, going from `a` to `b`, the triangle in `slot` stops
    /// lifting the cutter with its tip at `z` above z, as a parameter in
    /// [0, 1]: the last point of the segment whose cutter axis is within R
    /// (in XY) of the triangle's part above `z + h(R)`, which the cutter's
    /// cylindrical body holds. There the triangle's height jumps from above z
    /// to its floor unless a lower part of it holds the cutter further on;
    /// `None` if that part is empty or out of reach. A guess only: the caller
    /// classifies the points near it by [`BoxDrop::drop_one`].
    #[must_use]
    pub fn rim_exit(&self, slot: usize, z: f64, a: Point2, b: Point2) -> Option<f64> {
        let radius = self.profile.radius;
        reach::rim_exit(self.index.corners(slot), radius, z + self.profile.height(radius), a, b)
    }
}

/// Contacts this far out of the cutter's radius or farther are on its rim
/// ([`BoxDrop::contact_gradient`]).
const RIM_FRACTION: f64 = 1.0 - 1e-9;

/// Reusable buffers of one worker: the candidates of the current block.
#[derive(Default)]
struct BlockScratch {
    slots: Vec<u32>,
    unsorted: Vec<Candidate>,
    keys: Vec<(u64, u32)>,
    sorted: Vec<Candidate>,
}

impl BlockScratch {
    /// The triangles within reach of the block's box `[lo, hi]` (a segment
    /// `[x0, x1] x {y}` for a grid row), sorted by decreasing bound (ties by
    /// slot, so the order is deterministic).
    fn fill(&mut self, index: &MeshIndex, profile: &Profile, lo: [f64; 2], hi: [f64; 2]) {
        let radius = profile.radius;
        let ([x0, y0], [x1, y1]) = (lo, hi);
        let reach = Aabb2 { min: Point2::new(x0 - radius, y0 - radius), max: Point2::new(x1 + radius, y1 + radius) };
        self.slots.clear();
        index.collect_box(&reach, &mut self.slots);
        // Bound valid for every point of the block: the triangle's top lifted by
        // the profile at its distance to the block's box.
        self.unsorted.clear();
        self.unsorted.extend(self.slots.iter().map(|&slot| {
            let slot = slot as usize;
            let b = index.xy_box(slot);
            let zmax = index.zmax(slot);
            let dx = (b.min.x - x1).max(0.0).max(x0 - b.max.x);
            let dy = (b.min.y - y1).max(0.0).max(y0 - b.max.y);
            let d2 = (dx * dx + dy * dy).min(radius * radius);
            let ub = zmax - profile.height(d2.sqrt());
            let lines = *index.edge_lines(slot);
            Candidate { ub, zmax, min: [b.min.x, b.min.y], max: [b.max.x, b.max.y], lines, slot }
        }));
        // Sort small keys, not the candidates: descending bound, then slot.
        self.keys.clear();
        self.keys.extend(
            self.unsorted
                .iter()
                .enumerate()
                .map(|(i, c)| (!total_order_key(c.ub), u32::try_from(i).unwrap_or(u32::MAX))),
        );
        self.keys.sort_unstable();
        self.sorted.clear();
        self.sorted.extend(self.keys.iter().map(|&(_, i)| self.unsorted[i as usize]));
    }
}

/// A u64 whose unsigned order is the total order of f64 (`f64::total_cmp`).
fn total_order_key(v: f64) -> u64 {
    let bits = v.to_bits();
    if bits >> 63 == 1 { !bits } else { bits | (1 << 63) }
}

/// Most points sharing one candidate list.
const BLOCK_POINTS: usize = 64;

/// A triangle near a block of grid points.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    /// Upper bound of the tip height this triangle can give anywhere in the block.
    ub: f64,
    zmax: f64,
    min: [f64; 2],
    max: [f64; 2],
    /// The triangle's XY edge lines ([`MeshIndex::edge_lines`]).
    lines: [[f64; 3]; 3],
    slot: usize,
}

/// Whether the triangle in `slot` cannot hold the tip at `xy` above `best`:
/// out of reach by its XY box or its edge lines, or its top lifted by the
/// profile at that distance not above `best` (the bounds of the scan of
/// [`drop_candidates`], with the same slack).
fn out_of_reach(profile: &Profile, index: &MeshIndex, slot: usize, xy: Point2, best: f64) -> bool {
    let slack = index.slack();
    let d2 = index.xy_box(slot).distance_squared(&xy);
    let side = (index.edge_distance(slot, xy) - slack).max(0.0);
    let d2 = d2.max(side * side);
    d2 > profile.radius * profile.radius || index.zmax(slot) - profile.height_sq(d2) + slack <= best
}

/// Drop-cutter at `xy` over `candidates` sorted by decreasing bound `ub`,
/// which must hold every triangle within the cutter's reach of `xy`. With
/// `clear_cache` (one entry per candidate, for the ball), a candidate whose
/// last clearance test found the ball clear by a margin g (the centre, g^2)
/// is skipped while the ball's centre stays within g of that centre and at
/// or above the triangle's top ([`clear::ball_clearance`]): the same skip as
/// the test, without its closest-point computation.
fn drop_candidates(
    profile: &Profile,
    index: &MeshIndex,
    candidates: &[Candidate],
    xy: Point2,
    floor: f64,
    seed: Option<usize>,
    clear_cache: Option<&[Cell<[f64; 4]>]>,
) -> (ClPoint, Option<usize>) {
    let mut best = ClPoint::floor(xy, floor);
    let mut best_slot = None;
    let slack = index.slack();
    let r2 = profile.radius * profile.radius;
    // The seed is tested first unless the bounds of the scan below show it
    // cannot rise above the floor (a floor at the level, where only the side
    // is wanted, and the seed out of reach); its own corners and edges only,
    // as the scan tests every candidate: an edge it shares with a neighbour
    // that owns it is tested there (unless the neighbour's bound shows it
    // cannot rise above the best), not twice.
    if let Some(slot) = seed.filter(|&slot| !out_of_reach(profile, index, slot, xy, best.tip.z)) {
        let (corners, normal, triangle) = (index.corners(slot), index.normal(slot), index.original_index(slot));
        drop_features(profile, corners, normal, triangle, index.owned_features(slot), &mut best);
        if !matches!(best.contact, Contact::Floor) {
            best_slot = Some(slot);
        }
    }
    let ball = matches!(profile.shape, crate::CutterShape::Ball { .. });
    for (i, c) in candidates.iter().enumerate() {
        if c.ub + slack <= best.tip.z {
            break; // sorted: nothing after this can rise above the best
        }
        if seed == Some(c.slot) {
            continue; // already tested (its own corners and edges)
        }
        let dx = (c.min[0] - xy.x).max(0.0).max(xy.x - c.max[0]);
        let dy = (c.min[1] - xy.y).max(0.0).max(xy.y - c.max[1]);
        let d2 = dx * dx + dy * dy;
        // A bound (up to rounding, which the slack covers): skipping cannot change the height.
        if d2 > r2 || c.zmax - profile.height_sq(d2) + slack <= best.tip.z {
            continue;
        }
        // The same bound at the distance to the triangle's edge lines (a long
        // thin triangle's box reaches far past it), lowered by the slack to
        // cover its rounding.
        let side = MeshIndex::line_distance(&c.lines, xy) - slack;
        if side > 0.0 && (side > profile.radius || c.zmax - profile.height_sq(side * side) + slack <= best.tip.z) {
            continue;
        }
        if ball {
            // The ball at the best height is clear of the whole triangle: skip it.
            if let Some(cache) = clear_cache {
                let oz = best.tip.z + profile.radius;
                let [x, y, z, g2] = cache[i].get();
                let (dx, dy, dz) = (xy.x - x, xy.y - y, oz - z);
                if c.zmax <= oz && dx * dx + dy * dy + dz * dz < g2 {
                    continue; // within the margin of an earlier clear centre
                }
                if let Some(g) = clear::ball_clearance(index.corners(c.slot), profile.radius, xy.x, xy.y, best.tip.z) {
                    cache[i].set([xy.x, xy.y, oz, g * g]);
                    continue;
                }
            } else if clear::ball_clear_of(index.corners(c.slot), profile.radius, xy.x, xy.y, best.tip.z) {
                continue;
            }
        }
        let before = best.tip.z;
        let (slot, features) = (c.slot, index.owned_features(c.slot));
        drop_features(
            profile,
            index.corners(slot),
            index.normal(slot),
            index.original_index(slot),
            features,
            &mut best,
        );
        if best.tip.z > before {
            best_slot = Some(c.slot);
        }
    }
    (best, best_slot)
}
