//! Verification of a tri-dexel stock against the design part, ray by ray.
//!
//! The part along a ray is a list of intervals:
//! - a **closed** mesh (every edge shared by an even number of triangles) is
//!   a solid: the ray's crossings with its triangles, found with an exact
//!   inside test on the triangle's projection along the ray under a symbolic
//!   perturbation of the ray (so a ray through an edge or a vertex crosses
//!   exactly one of the triangles there), are paired by parity;
//! - an **open** mesh is a height field, as in [`crate::verify`]: the part is
//!   everything below its highest triangle. A Z ray holds the part from the
//!   stock bottom to that height; an X or Y ray at height `z` holds it where
//!   the surface's section by the ray's vertical plane lies at or above `z`
//!   (the union over triangles of the sub-segments of their sections above
//!   `z`: exact).
//!
//! Each part interval end carries `|d . n|`, `n` the unit normal of the
//! triangle there (0 where the interval is cut by the stock box or ends at
//! the side of an open part's footprint: no part surface there), so that a
//! length along the ray from that end converts to a thickness along the part
//! normal (exact for a locally planar part).
//!
//! - **Material left**: a piece of stock outside the part that touches a
//!   part surface end, its length along the ray and times `|d . n|`.
//! - **Gouge depth** of a piece of part without stock: for a closed part and
//!   on Z rays, its length from the part surface it opens times `|d . n|` (a
//!   piece inside a part interval, a ray running just under the surface,
//!   touches no surface and is measured by the rays that cross the surface
//!   there); for an open part on an X or Y ray, the largest
//!   `(surface z - ray z) |n_z|` over the piece (the distance below the
//!   surface, exact for a locally planar part).

use rayon::prelude::*;
use scallop_geom::predicates::orient2d;
use scallop_geom::{Aabb2, Aabb3, Point2, Point3};
use scallop_mesh::{MeshIndex, TriMesh};

use super::DexelStock;
use crate::{MoveId, SimError, VerifyOptions};

/// The design part for [`verify_dexel`]: the mesh's index and whether it is
/// a closed solid.
#[derive(Debug, Clone)]
pub struct DexelPart {
    index: MeshIndex,
    closed: bool,
}

impl DexelPart {
    /// Indexes `mesh`; it is a closed solid when every edge is shared by an
    /// even number of triangles, else a height field (see the module docs).
    #[must_use]
    pub fn new(mesh: &TriMesh) -> DexelPart {
        let mut edges: Vec<(u32, u32)> = mesh
            .triangles()
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
            .map(|(a, b)| if a < b { (a, b) } else { (b, a) })
            .collect();
        edges.sort_unstable();
        let closed = !edges.is_empty() && edges.chunk_by(|a, b| a == b).all(|run| run.len() % 2 == 0);
        DexelPart { index: MeshIndex::build(mesh), closed }
    }

    /// Whether the part is a closed solid (else a height field).
    #[must_use]
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// The part along the ray through `o` along `axis`: sorted disjoint
    /// `(s0, s1, w0, w1)` (coordinates along the axis and `|d . n|` at each end).
    #[must_use]
    pub fn intervals(&self, o: &Point3, axis: usize) -> Vec<PartSpan> {
        self.ray(o, axis).0
    }

    /// The box holding the part's material: the mesh's box, reaching down
    /// without bound for an open part (a height field is everything below
    /// its surface).
    pub(crate) fn material_box(&self) -> Aabb3 {
        let mut b = self.index.bounds();
        if !self.closed {
            b.min.z = f64::NEG_INFINITY;
        }
        b
    }

    /// The part's material along every ray of family `axis` of `grid`,
    /// clipped to the ray's extent, in ray order (parallel over lines of rays
    /// sharing their candidate triangles; each ray is computed alone, so the
    /// result does not depend on the thread count).
    pub(crate) fn family_material(&self, grid: &DexelStock, axis: usize) -> Vec<Vec<[f64; 2]>> {
        let (nu, nv) = grid.grid(axis);
        let (lo, hi) = (grid.stock().min[axis], grid.stock().max[axis]);
        let (outer, inner) = if axis == 0 { (nu, nv) } else { (nv, nu) };
        let ray_of = |a: usize, b: usize| if axis == 0 { (a, b) } else { (b, a) };
        let lines: Vec<Vec<(usize, Vec<[f64; 2]>)>> = (0..outer)
            .into_par_iter()
            .map(|a| {
                let mut slots = Vec::new();
                if axis != 2 {
                    let (iu, iv) = ray_of(a, 0);
                    self.candidates(&grid.ray_origin(axis, iu, iv), axis, &mut slots);
                }
                (0..inner)
                    .map(|b| {
                        let (iu, iv) = ray_of(a, b);
                        let o = grid.ray_origin(axis, iu, iv);
                        if axis == 2 {
                            self.candidates(&o, axis, &mut slots);
                        }
                        let spans = self.ray_in(&o, axis, &slots).0;
                        let clipped = spans
                            .iter()
                            .map(|&(s0, s1, _, _)| [s0.max(lo), s1.min(hi)])
                            .filter(|s| s[1] > s[0])
                            .collect();
                        (iv * nu + iu, clipped)
                    })
                    .collect()
            })
            .collect();
        let mut out = vec![Vec::new(); nu * nv];
        for (index, spans) in lines.into_iter().flatten() {
            out[index] = spans;
        }
        out
    }

    /// The part intervals and, for an open part on an X or Y ray, the
    /// surface's section pieces `(s_a, z_a, s_b, z_b, |n_z|)`.
    fn ray(&self, o: &Point3, axis: usize) -> (Vec<PartSpan>, Vec<Section>) {
        let mut slots = Vec::new();
        self.candidates(o, axis, &mut slots);
        self.ray_in(o, axis, &slots)
    }

    /// The triangles whose XY box meets the ray's XY shadow (a point for a Z
    /// ray, a line for an X or Y ray: shared by all rays of that line).
    fn candidates(&self, o: &Point3, axis: usize, slots: &mut Vec<u32>) {
        let b = self.index.bounds();
        let query = match axis {
            2 => Aabb2 { min: Point2::new(o.x, o.y), max: Point2::new(o.x, o.y) },
            0 => Aabb2 { min: Point2::new(b.min.x, o.y), max: Point2::new(b.max.x, o.y) },
            _ => Aabb2 { min: Point2::new(o.x, b.min.y), max: Point2::new(o.x, b.max.y) },
        };
        slots.clear();
        self.index.collect_box(&query, slots);
    }

    /// [`DexelPart::ray`] among the candidate triangles `slots`.
    fn ray_in(&self, o: &Point3, axis: usize, slots: &[u32]) -> (Vec<PartSpan>, Vec<Section>) {
        if self.closed {
            (self.solid(o, axis, slots), Vec::new())
        } else if axis == 2 {
            let mut top: Option<(f64, f64)> = None;
            for &slot in slots {
                if let Some((s, w)) = self.crossing(o, axis, slot as usize)
                    && top.is_none_or(|(t, _)| s > t)
                {
                    top = Some((s, w));
                }
            }
            (top.map(|(s, w)| vec![(f64::NEG_INFINITY, s, 0.0, w)]).unwrap_or_default(), Vec::new())
        } else {
            self.section(o, axis, slots)
        }
    }

    /// Where the ray crosses triangle `slot` (perturbed inside test), with `|d . n|`.
    fn crossing(&self, o: &Point3, axis: usize, slot: usize) -> Option<(f64, f64)> {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let t = self.index.corners(slot);
        let n = self.index.normal(slot);
        if n[axis] == 0.0 {
            return None;
        }
        let p = |q: &Point3| Point2::new(q[u], q[v]);
        let (a, b, c, q) = (p(&t[0]), p(&t[1]), p(&t[2]), Point2::new(o[u], o[v]));
        let area = orient2d(&a, &b, &c);
        if area == 0.0 {
            return None;
        }
        let side = |x: &Point2, y: &Point2| {
            let s = orient2d(x, y, &q);
            if s != 0.0 {
                s > 0.0
            } else {
                // q + (e, e^2): the sign of cross(y - x, (e, e^2)).
                let (dx, dy) = (y.x - x.x, y.y - x.y);
                if dy != 0.0 { dy < 0.0 } else { dx > 0.0 }
            }
        };
        let want = area > 0.0;
        if side(&a, &b) != want || side(&b, &c) != want || side(&c, &a) != want {
            return None;
        }
        let s = t[0][axis] - (n[u] * (o[u] - t[0][u]) + n[v] * (o[v] - t[0][v])) / n[axis];
        Some((s, n[axis].abs() / n.norm()))
    }

    /// A closed solid along the ray: crossings paired by parity.
    fn solid(&self, o: &Point3, axis: usize, slots: &[u32]) -> Vec<PartSpan> {
        let mut hits: Vec<(f64, f64)> = slots.iter().filter_map(|&s| self.crossing(o, axis, s as usize)).collect();
        hits.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
        hits.chunks_exact(2).map(|p| (p[0].0, p[1].0, p[0].1, p[1].1)).collect()
    }

    /// An open height field along a horizontal ray: where its section lies at
    /// or above the ray (ends at the footprint's side carry 0: stock beyond
    /// the footprint is no material on the part, and removed part there is
    /// measured vertically, [`section_depth`]), with the section pieces.
    fn section(&self, o: &Point3, axis: usize, slots: &[u32]) -> (Vec<PartSpan>, Vec<Section>) {
        // The ray runs along `axis` at height o.z in the vertical plane c = o[c].
        let c = 1 - axis;
        let level = o.z;
        let mut pieces: Vec<PartSpan> = Vec::new();
        let mut sections: Vec<Section> = Vec::new();
        for &slot in slots {
            let t = self.index.corners(slot as usize);
            let n = self.index.normal(slot as usize);
            // Points of the triangle's edges on the plane, as (s, z).
            let mut pts: Vec<(f64, f64)> = Vec::with_capacity(3);
            for (i, j) in [(0, 1), (1, 2), (2, 0)] {
                // Canonical order: the same edge gives the same point in both triangles.
                let (p, q) = if (t[i][0], t[i][1], t[i][2]) <= (t[j][0], t[j][1], t[j][2]) {
                    (t[i], t[j])
                } else {
                    (t[j], t[i])
                };
                let (dp, dq) = (p[c] - o[c], q[c] - o[c]);
                if dp == 0.0 {
                    pts.push((p[axis], p.z));
                }
                if (dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0) {
                    let f = dp / (dp - dq);
                    pts.push((p[axis] + f * (q[axis] - p[axis]), p.z + f * (q.z - p.z)));
                }
            }
            let Some(&first) = pts.first() else { continue };
            let (mut a, mut b) = (first, first);
            for &p in &pts {
                if p.0 < a.0 {
                    a = p;
                }
                if p.0 > b.0 {
                    b = p;
                }
            }
            if b.0 <= a.0 {
                continue;
            }
            let w = n[axis].abs() / n.norm();
            sections.push((a.0, a.1, b.0, b.1, n.z.abs() / n.norm()));
            let (above_a, above_b) = (a.1 >= level, b.1 >= level);
            let cross = || a.0 + (level - a.1) / (b.1 - a.1) * (b.0 - a.0);
            match (above_a, above_b) {
                (true, true) => pieces.push((a.0, b.0, 0.0, 0.0)),
                (true, false) => pieces.push((a.0, cross(), 0.0, w)),
                (false, true) => pieces.push((cross(), b.0, w, 0.0)),
                (false, false) => {}
            }
        }
        pieces.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
        let mut out: Vec<PartSpan> = Vec::with_capacity(pieces.len());
        for p in pieces {
            match out.last_mut() {
                Some(last) if p.0 <= last.1 => {
                    if p.1 > last.1 {
                        last.1 = p.1;
                        last.3 = p.3;
                    }
                }
                _ => out.push(p),
            }
        }
        (out, sections)
    }
}

/// A part interval along a ray: `(s0, s1, w0, w1)`, the ends and `|d . n|` there.
type PartSpan = (f64, f64, f64, f64);

/// A piece of an open part's section by a vertical plane: `(s_a, z_a, s_b,
/// z_b, |n_z|)` along the ray's axis.
type Section = (f64, f64, f64, f64, f64);

/// The depth below an open part's surface of the deepest point of
/// `[g0, g1]` at height `level`: the largest `(z - level) |n_z|` over the
/// section pieces above it (the normal distance for a locally planar part;
/// the section is linear on each piece, so the ends of the overlap decide).
fn section_depth(sections: &[Section], level: f64, g0: f64, g1: f64) -> f64 {
    let mut depth = 0.0f64;
    for &(sa, za, sb, zb, nz) in sections {
        let (a, b) = (g0.max(sa), g1.min(sb));
        if a > b {
            continue;
        }
        for s in [a, b] {
            let z = za + (s - sa) / (sb - sa) * (zb - za);
            depth = depth.max((z - level) * nz);
        }
    }
    depth
}

/// One piece of part material removed along a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DexelGouge {
    /// The ray family (0 = X, 1 = Y, 2 = Z).
    pub axis: usize,
    /// The ray `(iu, iv)` in its family.
    pub ray: (usize, usize),
    /// Middle of the removed piece of part.
    pub at: Point3,
    /// Its depth along the part normal (mm): its length along the ray times
    /// `|d . n|` at the part surface it opens.
    pub depth: f64,
    /// Its length along the ray (mm).
    pub length: f64,
    /// The first move whose sweep cut into it.
    pub cut_by: Option<MoveId>,
}

/// The verdict of [`verify_dexel`] when the stock is safe.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DexelVerification {
    /// Z rays with part on them.
    pub part_rays: usize,
    /// Largest `stock top - part top` over the Z rays with part (mm): the
    /// material left measured vertically, as [`crate::Verification::max_scallop`].
    pub max_scallop: f64,
    /// Where `max_scallop` is (the part top on the first such ray).
    pub max_scallop_at: Option<Point3>,
    /// Smallest `stock top - part top` over the Z rays with part (mm).
    pub min_deviation: f64,
    /// Largest material thickness on the part, per family: the longest piece
    /// of stock outside the part that touches the part, along the ray (mm).
    pub max_left_along: [f64; 3],
    /// Largest material thickness along the part normal over all rays: such a
    /// piece's length times `|d . n|` at the part surface it touches (mm;
    /// exact for a locally planar part).
    pub max_thickness: f64,
    /// Where `max_thickness` is (the part surface point).
    pub max_thickness_at: Option<Point3>,
    /// Volume of stock left (mm^3), on the Z rays.
    pub remaining_volume: f64,
    /// Volume removed from the full stock box (mm^3).
    pub removed_volume: f64,
    /// Volume of stock outside the part on the Z rays with part (mm^3).
    pub excess_volume: f64,
}

/// What one band of rays found.
#[derive(Default)]
struct BandFindings {
    part_rays: usize,
    scallop: Option<(f64, Point3)>,
    min_dev: f64,
    along: f64,
    thickness: Option<(f64, Point3)>,
    excess: f64,
    gouges: Vec<DexelGouge>,
}

/// Compares every ray of `stock` with `part`: material left (vertically on
/// the Z rays, along each ray, and along the part normal) and gouges (part
/// material removed deeper than `options.gouge_tolerance` plus the stock's
/// epsilon, measured along the part normal; each named with the first move
/// that cut it). Parallel over fixed bands of rays; the result does not
/// depend on the thread count. [`VerifyOptions::scallop_margin`] is not used
/// (no footprint margin on rays).
///
/// # Errors
/// [`SimError::DexelGouge`] with the deepest [`VerifyOptions::worst_reported`] gouges.
pub fn verify_dexel(
    stock: &DexelStock,
    part: &DexelPart,
    options: &VerifyOptions,
) -> Result<DexelVerification, SimError> {
    let limit = options.gouge_tolerance + stock.eps();
    let mut max_left_along = [0.0; 3];
    let mut total = BandFindings { min_dev: f64::INFINITY, ..BandFindings::default() };
    let mut thickness: Option<(f64, Point3)> = None;
    let mut gouges = Vec::new();
    for (axis, left_along) in max_left_along.iter_mut().enumerate() {
        let (nu, nv) = stock.grid(axis);
        // Rows of rays sharing the XY line of their shadow (X rays of one y,
        // Y rays of one x): their candidate triangles are found once.
        let (outer, inner) = if axis == 0 { (nu, nv) } else { (nv, nu) };
        let ray_of = |a: usize, b: usize| if axis == 0 { (a, b) } else { (b, a) };
        let bands: Vec<BandFindings> = (0..outer)
            .into_par_iter()
            .map(|a| {
                let mut f = BandFindings { min_dev: f64::INFINITY, ..BandFindings::default() };
                let mut slots = Vec::new();
                if axis != 2 {
                    let (iu, iv) = ray_of(a, 0);
                    part.candidates(&stock.ray_origin(axis, iu, iv), axis, &mut slots);
                }
                for b in 0..inner {
                    let (iu, iv) = ray_of(a, b);
                    let shared = (axis != 2).then_some(slots.as_slice());
                    ray_findings(stock, part, axis, iu, iv, limit, shared, &mut f);
                }
                f
            })
            .collect();
        for f in bands {
            total.part_rays += f.part_rays;
            if let Some((s, p)) = f.scallop
                && total.scallop.is_none_or(|(t, _)| s > t)
            {
                total.scallop = Some((s, p));
            }
            total.min_dev = total.min_dev.min(f.min_dev);
            total.excess += f.excess;
            *left_along = f64::max(*left_along, f.along);
            if let Some((t, p)) = f.thickness
                && thickness.is_none_or(|(b, _)| t > b)
            {
                thickness = Some((t, p));
            }
            gouges.extend(f.gouges);
        }
    }
    if !gouges.is_empty() {
        let count = gouges.len();
        gouges.sort_by(|a, b| b.depth.total_cmp(&a.depth));
        gouges.truncate(options.worst_reported.max(1));
        for g in &mut gouges {
            g.cut_by = first_cut(stock, g);
        }
        return Err(SimError::DexelGouge { count, tolerance: options.gouge_tolerance, worst: gouges });
    }
    let remaining = stock.volume();
    let (cx, cy, _) = (stock.cell_size()[0], stock.cell_size()[1], 0);
    Ok(DexelVerification {
        part_rays: total.part_rays,
        max_scallop: total.scallop.map_or(0.0, |s| s.0),
        max_scallop_at: total.scallop.map(|s| s.1),
        min_deviation: if total.min_dev.is_finite() { total.min_dev } else { 0.0 },
        max_left_along,
        max_thickness: thickness.map_or(0.0, |t| t.0),
        max_thickness_at: thickness.map(|t| t.1),
        remaining_volume: remaining,
        removed_volume: stock.initial_volume() - remaining,
        excess_volume: total.excess * cx * cy,
    })
}

/// The first sweep (program order) that cut into the gouge's piece.
fn first_cut(stock: &DexelStock, g: &DexelGouge) -> Option<MoveId> {
    let o = stock.ray_origin(g.axis, g.ray.0, g.ray.1);
    let half = 0.5 * g.length;
    let (a, b) = (g.at[g.axis] - half, g.at[g.axis] + half);
    stock
        .history()
        .filter(|(step, _)| step.crosses(&o, g.axis))
        .find(|(step, body)| step.interval(body, &o, g.axis).is_some_and(|(s0, s1)| s1.min(b) > s0.max(a)))
        .map(|(step, _)| step.id())
}

/// Compares one ray (among the candidate triangles `slots` when given).
#[allow(clippy::too_many_arguments)] // private; one call site.
fn ray_findings(
    stock: &DexelStock,
    part: &DexelPart,
    axis: usize,
    iu: usize,
    iv: usize,
    limit: f64,
    slots: Option<&[u32]>,
    f: &mut BandFindings,
) {
    let box_ = stock.stock();
    let (lo, hi) = (box_.min[axis], box_.max[axis]);
    let o = stock.ray_origin(axis, iu, iv);
    let at = |s: f64| {
        let mut p = o;
        p[axis] = s;
        p
    };
    let (spans, sections) = match slots {
        Some(slots) => part.ray_in(&o, axis, slots),
        None => part.ray(&o, axis),
    };
    let spans: Vec<PartSpan> = spans
        .into_iter()
        .filter(|p| p.1 > lo && p.0 < hi)
        .map(|(a, b, wa, wb)| if a < lo { (lo, b, 0.0, wb) } else { (a, b, wa, wb) })
        .map(|(a, b, wa, wb)| if b > hi { (a, hi, wa, 0.0) } else { (a, b, wa, wb) })
        .collect();
    if spans.is_empty() {
        return;
    }
    let (nu, _) = stock.grid(axis);
    let index = iv * nu + iu;
    let full = [[lo, hi]];
    let material: &[[f64; 2]] = if stock.ray_is_full(axis, index) { &full } else { stock.ray(axis, index) };
    if axis == 2 {
        f.part_rays += 1;
        let top_stock = material.last().map_or(lo, |s| s[1]);
        let top_part = spans[spans.len() - 1].1;
        let dev = top_stock - top_part;
        if f.scallop.is_none_or(|(s, _)| dev > s) {
            f.scallop = Some((dev, at(top_part)));
        }
        f.min_dev = f.min_dev.min(dev);
    }
    // Gouges: part pieces not covered by material.
    for &(p0, p1, w0, w1) in &spans {
        let mut cursor = p0;
        let mut gaps: Vec<(f64, f64)> = Vec::new();
        for s in material {
            if s[1] <= cursor {
                continue;
            }
            if s[0] >= p1 {
                break;
            }
            if s[0] > cursor {
                gaps.push((cursor, s[0]));
            }
            cursor = cursor.max(s[1]);
        }
        if cursor < p1 {
            gaps.push((cursor, p1));
        }
        for (g0, g1) in gaps {
            let len = g1 - g0;
            let depth = if sections.is_empty() {
                // Measured from the part surface the piece opens; a piece
                // inside a part span (a ray running just under the surface)
                // is measured by the rays that cross the surface there.
                let w = match (g0 <= p0, g1 >= p1) {
                    (true, true) => w0.max(w1),
                    (true, false) => w0,
                    (false, true) => w1,
                    (false, false) => 0.0,
                };
                len * w
            } else {
                section_depth(&sections, o.z, g0, g1)
            };
            if depth > limit {
                f.gouges.push(DexelGouge {
                    axis,
                    ray: (iu, iv),
                    at: at(0.5 * (g0 + g1)),
                    depth,
                    length: len,
                    cut_by: None,
                });
            }
        }
    }
    // Material outside the part: pieces of stock between part spans.
    for s in material {
        let mut pieces: Vec<(f64, f64)> = vec![(s[0], s[1])];
        for &(p0, p1, _, _) in &spans {
            let mut next = Vec::with_capacity(pieces.len() + 1);
            for (a, b) in pieces {
                if b <= p0 || a >= p1 {
                    next.push((a, b));
                } else {
                    if a < p0 {
                        next.push((a, p0));
                    }
                    if b > p1 {
                        next.push((p1, b));
                    }
                }
            }
            pieces = next;
        }
        for (a, b) in pieces {
            let len = b - a;
            if len <= 0.0 {
                continue;
            }
            if axis == 2 {
                f.excess += len;
            }
            // Touching the part: a span ends where the piece starts, or starts
            // where it ends (exactly: the piece was cut at those values).
            let mut w: Option<(f64, f64)> = None;
            for &(p0, p1, w0, w1) in &spans {
                #[allow(clippy::float_cmp, reason = "the piece's ends are copies of the span's")]
                if p1 == a {
                    w = Some(w.map_or((w1, a), |x| if w1 > x.0 { (w1, a) } else { x }));
                }
                #[allow(clippy::float_cmp, reason = "the piece's ends are copies of the span's")]
                if p0 == b {
                    w = Some(w.map_or((w0, b), |x| if w0 > x.0 { (w0, b) } else { x }));
                }
            }
            if let Some((w, s)) = w.filter(|w| w.0 > 0.0) {
                f.along = f.along.max(len);
                let t = len * w;
                if f.thickness.is_none_or(|(b, _)| t > b) {
                    f.thickness = Some((t, at(s)));
                }
            }
        }
    }
}
