//! The vectorial offset of a curve on a mesh (Jousselin 2020, Ch. 2 §3.2.1,
//! Eq. 2.8-2.10, Annex A, Alg. 1-3): every point of the curve is pushed by
//! `d N ∧ T` and projected back onto the mesh, the direction corrected until
//! the projection is `d` away (Alg. 1), points closer than `d` to the whole
//! curve dropped (Eq. 2.9), local loops removed (Alg. 2) and the gaps at
//! reflex corners filled by a round joint (Alg. 3). The reference for the
//! scalar method ([`crate::offset_curve`]); it does not split loops.

use scallop_geom::{Point3, Vec3};
use scallop_mesh::{Polyline3, PolylineQuery};

use crate::offset::check_step;
use crate::support::{Curve, Support};
use crate::{GuideError, tol};

/// Settings of the vectorial offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VectorialOptions {
    /// Width of the accepted interval of distances, centred on `d` (mm).
    pub d_tol: f64,
    /// Iteration cap of the direction correction (Alg. 1).
    pub k_max: usize,
    /// Largest distance between consecutive points: the input curve is
    /// subdivided to it first, and the output resampled to it (mm).
    pub spacing: f64,
}

/// Result of [`vectorial_offset`].
#[derive(Clone, Debug, PartialEq)]
pub struct VectorialOffset {
    /// The offset curve, inside on the left.
    pub curve: Curve,
    /// Points dropped by Eq. 2.9 (closer than `d - d_tol / 2` to the curve).
    pub rejected: usize,
    /// Points removed as local loops (Alg. 2).
    pub unlooped: usize,
    /// Points inserted at reflex corners (Alg. 3).
    pub filled: usize,
}

/// The offset of `curve` at distance `d` on its left, on `support`.
///
/// # Errors
/// [`GuideError::BadLength`] for a non-positive `d`, `d_tol` or spacing;
/// [`GuideError::BadCurve`] when fewer than 2 points survive.
pub fn vectorial_offset(
    support: &Support,
    curve: &Curve,
    d: f64,
    opts: &VectorialOptions,
) -> Result<VectorialOffset, GuideError> {
    check_step(d)?;
    for (name, v) in [("d_tol", opts.d_tol), ("spacing", opts.spacing)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(GuideError::BadLength { name, value: v });
        }
    }
    crate::support::check_curve(curve, 0)?;
    let c = subdivide(support, curve, opts.spacing);
    let whole = PolylineQuery::new(vec![c.line.clone()]);
    let n = c.line.points.len();
    let mut rejected = 0;
    let mut pts = Vec::with_capacity(n);
    for i in 0..n {
        let p = shift_point(support, &c, i, d, opts);
        if whole.distance(&p) >= d - opts.d_tol / 2.0 {
            pts.push(p);
        } else {
            rejected += 1;
        }
    }
    let before = pts.len();
    let mut pts = remove_local_loops(pts, c.line.closed);
    let unlooped = before - pts.len();
    if pts.len() < 2 {
        return Err(GuideError::BadCurve { curve: 0, reason: "the offset vanished" });
    }
    let filled = fill_corners(support, &c, &mut pts, d, opts);
    let line = Polyline3::new(pts, c.line.closed);
    let resampled = subdivide(support, &Curve { normals: vec![Vec3::z(); line.points.len()], line }, opts.spacing);
    Ok(VectorialOffset { curve: resampled, rejected, unlooped, filled })
}

/// Alg. 1: the point `i` of `c` shifted by `d` on the left and projected.
fn shift_point(support: &Support, c: &Curve, i: usize, d: f64, opts: &VectorialOptions) -> Point3 {
    let pts = &c.line.points;
    let n = pts.len();
    let (prev, next) = if c.line.closed {
        (pts[(i + n - 1) % n], pts[(i + 1) % n])
    } else {
        (pts[i.saturating_sub(1)], pts[(i + 1).min(n - 1)])
    };
    let t = (next - prev).normalize();
    let p = pts[i];
    let mut proj = support.query().closest_point(&(p + c.normals[i].cross(&t).normalize() * d)).point;
    for _ in 0..opts.k_max {
        let v = proj - p;
        if (v.norm() - d).abs() < opts.d_tol / 2.0 || v.norm() <= 0.0 {
            break;
        }
        proj = support.query().closest_point(&(p + v.normalize() * d)).point;
    }
    proj
}

/// Alg. 2 (as corrected): a point is dropped when its predecessor is closer to
/// its successor than to it; after a pass that dropped points the curve is
/// travelled backwards; closed curves are indexed cyclically.
pub(crate) fn remove_local_loops(mut pts: Vec<Point3>, closed: bool) -> Vec<Point3> {
    let passes = pts.len();
    let mut reversed = false;
    for _ in 0..passes {
        let mut removed = false;
        let mut i = usize::from(!closed);
        while pts.len() > 3 && i < pts.len() - usize::from(!closed) {
            let n = pts.len();
            let (a, b, c) = (pts[(i + n - 1) % n], pts[i], pts[(i + 1) % n]);
            if (c - a).norm() < (b - a).norm() {
                pts.remove(i);
                removed = true;
            } else {
                i += 1;
            }
        }
        if !removed {
            break;
        }
        pts.reverse();
        reversed = !reversed;
    }
    if reversed {
        pts.reverse();
    }
    pts
}

/// Alg. 3 (as corrected): a gap wider than twice the nominal spacing whose
/// middle projects onto a vertex of `c` with a real turn gets a round joint
/// of radius `d` about that vertex, projected onto the support.
fn fill_corners(support: &Support, c: &Curve, pts: &mut Vec<Point3>, d: f64, opts: &VectorialOptions) -> usize {
    let q = PolylineQuery::new(vec![c.line.clone()]);
    let mut out = Vec::with_capacity(pts.len());
    let mut filled = 0;
    let m = pts.len();
    let pairs = if c.line.closed { m } else { m - 1 };
    for i in 0..m {
        out.push(pts[i]);
        if i >= pairs {
            continue;
        }
        let (a, b) = (pts[i], pts[(i + 1) % m]);
        let gap = (b - a).norm();
        if gap <= 2.0 * opts.spacing {
            continue;
        }
        let Some(foot) = q.closest(&Point3::from((a.coords + b.coords) * 0.5)) else { continue };
        if !(foot.t <= 0.0 || foot.t >= 1.0) || !turns(&c.line, &foot) {
            continue;
        }
        let corner = foot.point;
        let k = (gap / opts.spacing).ceil() as usize;
        for j in 1..k {
            let x = a + (b - a) * (j as f64 / k as f64);
            let v = x - corner;
            if v.norm() <= 0.0 {
                continue;
            }
            out.push(support.query().closest_point(&(corner + v.normalize() * d)).point);
            filled += 1;
        }
    }
    *pts = out;
    filled
}

/// Whether the polyline turns at the vertex the foot lies on by more than
/// [`tol::CORNER_TURN`].
fn turns(line: &Polyline3, foot: &scallop_mesh::PolylineFoot) -> bool {
    let n = line.points.len();
    let v = if foot.t <= 0.0 { foot.segment } else { (foot.segment + 1) % n };
    if !line.closed && (v == 0 || v == n - 1) {
        return false;
    }
    let (a, b, c) = (line.points[(v + n - 1) % n], line.points[v], line.points[(v + 1) % n]);
    let (u, w) = (b - a, c - b);
    let (lu, lw) = (u.norm(), w.norm());
    lu > 0.0 && lw > 0.0 && u.dot(&w) / (lu * lw) < tol::CORNER_TURN.cos()
}

/// `c` with every segment longer than `spacing` split evenly, new points
/// projected onto the support; normals from the support.
fn subdivide(support: &Support, c: &Curve, spacing: f64) -> Curve {
    let mut pts = Vec::with_capacity(c.line.points.len());
    for s in 0..c.line.segment_count() {
        let (a, b) = c.line.segment(s);
        let k = ((b - a).norm() / spacing).ceil().max(1.0) as usize;
        pts.push(a);
        for j in 1..k {
            pts.push(support.query().closest_point(&(a + (b - a) * (j as f64 / k as f64))).point);
        }
    }
    if !c.line.closed {
        pts.extend(c.line.points.last().copied());
    }
    let normals = pts.iter().map(|p| support.normal_at(p)).collect();
    Curve { line: Polyline3::new(pts, c.line.closed), normals }
}
