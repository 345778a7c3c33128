//! Tilt curves (Jousselin 2020, Ch. 2 §1.2.2, §2.1.3, §3.2.2, Annex A):
//! the innermost path curve projected onto the next level along the line of
//! the two innermost curves' barycentres, the scalar morph between an inner
//! and an outer limit on a mesh (Eq. 2.7 with curves: the zero set of
//! `m d(P, C_outer) - (1 - m) d(P, C_inner)`), and the pairing of a path
//! family with a tilt family: the swap rule of §3.2.2 with a count rule that
//! keeps consecutive curves within a_e on both levels (docs/guides-curves.md).

use rayon::prelude::*;
use scallop_geom::{Point3, Vec3};
use scallop_mesh::{Polyline3, PolylineQuery};

use crate::GuideError;
use crate::facets::march;
use crate::field::CurveField;
use crate::offset::{OffsetStep, check_step};
use crate::support::{Curve, Support};

/// The curve set at morph value `m` in `(0, 1)` between `inner` (small `m`
/// lies near it) and `outer` on `support`, inside on the left. Distances are
/// signed (positive inside `outer`, positive outside `inner`), so the field
/// has no zero outside the band between the two limits: the spurious loops of
/// unsigned distances (inside the inner limit for `m < 1/2`, outside the outer
/// one for `m > 1/2`) do not arise.
#[must_use]
pub fn morph_level(support: &Support, inner: &[Curve], outer: &[Curve], m: f64) -> Vec<Curve> {
    let (fi, fo) = (CurveField::new(inner), CurveField::new(outer));
    let f = |p: &Point3| m * fo.signed(p) + (1.0 - m) * fi.signed(p);
    let values: Vec<f64> = support.mesh().vertices().par_iter().map(f).collect();
    march(support, &values, &f, &|_| false).curves
}

/// `curve` projected onto `target` along `dir` (the nearest hit on the line
/// through each point, both ways); a point whose line misses falls back to
/// the closest point. Returns the curve and the number of fallbacks.
#[must_use]
pub fn project_curve(curve: &Curve, target: &Support, dir: &Vec3) -> (Curve, usize) {
    let mut fallbacks = 0;
    let points: Vec<Point3> = curve
        .line
        .points
        .iter()
        .map(|p| match target.query().project_along(p, dir) {
            Some(hit) => hit.point,
            None => {
                fallbacks += 1;
                target.query().closest_point(p).point
            }
        })
        .collect();
    let normals = points.iter().map(|p| target.normal_at(p)).collect();
    (Curve { line: Polyline3::new(points, curve.line.closed), normals }, fallbacks)
}

/// One level's curves: the support, its limit curve C_n and its offsets.
#[derive(Clone, Copy, Debug)]
pub struct Level<'a> {
    /// The level mesh S_n.
    pub support: &'a Support,
    /// The limit curve C_n (inside on the left).
    pub limit: &'a Curve,
    /// Its offsets by [`crate::offset_curves`], outermost first.
    pub offsets: &'a [OffsetStep],
}

/// Path and tilt curves of one level, paired.
#[derive(Clone, Debug, PartialEq)]
pub struct GuidePairs {
    /// Path curves C_{T n, m} on S_n, innermost (m = 0) to C_n.
    pub path: Vec<Curve>,
    /// Tilt curves C_{D n, m} on S_{n+1}, innermost to C_{n+1}.
    pub tilt: Vec<Curve>,
    /// The number of steps M (M + 1 curves in each family).
    pub steps: usize,
    /// Whether the path family was morphed (the swap, or the count rule).
    pub path_morphed: bool,
    /// Whether the tilt family was morphed.
    pub tilt_morphed: bool,
    /// Projected points whose line missed the target level.
    pub projection_fallbacks: usize,
    /// Largest distance from a point of a path curve to its outer neighbour
    /// and back (mm): the spacing check.
    pub path_spacing: f64,
    /// The same for the tilt curves.
    pub tilt_spacing: f64,
}

/// Pairs the curves of level `n` with level `n + 1` (Jousselin 2020, Ch. 2
/// §3.2.2): the family with more offsets keeps them, the other is morphed
/// between the projection of the innermost offset and its limit; then the
/// count rule `M = max(m_n, m_{n+1}, ceil(H_n / a_e), ceil(H_{n+1} / a_e))`,
/// `H` the largest distance from the outer limit to the inner one less the
/// level's facet size, morphs a family too when its offsets are fewer than M.
///
/// # Errors
/// [`GuideError::BadLength`] for a bad `a_e`, [`GuideError::Split`] when an
/// offset or a morph has several loops (degeneracy zones are not handled
/// here), [`GuideError::Projection`] when the innermost curve has no
/// barycentre.
pub fn pair_levels(n: &Level, n1: &Level, a_e: f64) -> Result<GuidePairs, GuideError> {
    check_step(a_e)?;
    let fam_n = single_family(n, "offsets of C_n")?;
    let fam_n1 = single_family(n1, "offsets of C_n+1")?;
    let (m_n, m_n1) = (fam_n.len() - 1, fam_n1.len() - 1);
    let dir = projection_direction(&fam_n[0], &fam_n1[0])?;
    // Swap rule: the family with more offsets keeps them.
    let keep_path = m_n >= m_n1;
    let (inner_n, inner_n1, fallbacks) = if keep_path {
        let (proj, f) = project_curve(&fam_n[0], n1.support, &dir);
        (fam_n[0].clone(), proj, f)
    } else {
        let (proj, f) = project_curve(&fam_n1[0], n.support, &(-dir));
        (proj, fam_n1[0].clone(), f)
    };
    let h_n = max_distance(n.limit, &inner_n);
    let h_n1 = max_distance(n1.limit, &inner_n1);
    // H is measured between polylines whose chords are within a facet of the
    // true curves: a facet of it is not counted, so an exact multiple of a_e
    // does not get one more step (the spacing stays within a_e + facet size).
    let count = |h: f64, facet: f64| ((h - facet).max(0.0) / a_e).ceil() as usize;
    let steps = m_n.max(m_n1).max(count(h_n, n.support.facet_size())).max(count(h_n1, n1.support.facet_size())).max(1);
    let path_morphed = !(keep_path && steps == m_n);
    let tilt_morphed = keep_path || steps != m_n1;
    let path = if path_morphed { morph_family(n.support, &inner_n, n.limit, steps, "path morph")? } else { fam_n };
    let tilt = if tilt_morphed { morph_family(n1.support, &inner_n1, n1.limit, steps, "tilt morph")? } else { fam_n1 };
    Ok(GuidePairs {
        path_spacing: family_spacing(&path),
        tilt_spacing: family_spacing(&tilt),
        path,
        tilt,
        steps,
        path_morphed,
        tilt_morphed,
        projection_fallbacks: fallbacks,
    })
}

/// The family innermost first: the offsets reversed, then the limit.
fn single_family(level: &Level, what: &'static str) -> Result<Vec<Curve>, GuideError> {
    let mut fam = Vec::with_capacity(level.offsets.len() + 1);
    for (step, s) in level.offsets.iter().enumerate().rev() {
        if s.curves.len() != 1 {
            return Err(GuideError::Split { what, step, loops: s.curves.len() });
        }
        fam.push(s.curves[0].clone());
    }
    fam.push(level.limit.clone());
    Ok(fam)
}

/// The unit direction from the barycentre of `a` to that of `b`, or the mean
/// normal of `a` when they coincide.
fn projection_direction(a: &Curve, b: &Curve) -> Result<Vec3, GuideError> {
    let (Some(ba), Some(bb)) = (a.line.barycentre(), b.line.barycentre()) else {
        return Err(GuideError::Projection { reason: "an innermost curve has zero length" });
    };
    let d = bb - ba;
    if d.norm() > 0.0 {
        return Ok(d.normalize());
    }
    let n: Vec3 = a.normals.iter().sum();
    if n.norm() > 0.0 {
        Ok(n.normalize())
    } else {
        Err(GuideError::Projection { reason: "no direction between the levels" })
    }
}

/// `steps + 1` curves from `inner` to `outer`: both limits and the morphs at
/// `k / steps`, `k = 1..steps - 1`.
fn morph_family(
    support: &Support,
    inner: &Curve,
    outer: &Curve,
    steps: usize,
    what: &'static str,
) -> Result<Vec<Curve>, GuideError> {
    let (inner_set, outer_set) = (std::slice::from_ref(inner), std::slice::from_ref(outer));
    let mids: Vec<Vec<Curve>> = (1..steps)
        .into_par_iter()
        .map(|k| morph_level(support, inner_set, outer_set, k as f64 / steps as f64))
        .collect();
    let mut fam = vec![inner.clone()];
    for (k, mut c) in mids.into_iter().enumerate() {
        if c.len() != 1 {
            return Err(GuideError::Split { what, step: k + 1, loops: c.len() });
        }
        fam.push(c.remove(0));
    }
    fam.push(outer.clone());
    Ok(fam)
}

/// Largest distance from a point of `from` to the polyline `to`.
fn max_distance(from: &Curve, to: &Curve) -> f64 {
    let q = PolylineQuery::new(vec![to.line.clone()]);
    from.line.points.iter().map(|p| q.distance(p)).fold(0.0, f64::max)
}

/// Largest distance between consecutive curves of a family, both ways.
fn family_spacing(fam: &[Curve]) -> f64 {
    fam.windows(2).map(|w| max_distance(&w[0], &w[1]).max(max_distance(&w[1], &w[0]))).fold(0.0, f64::max)
}

/// The vectorial morph with nearest-point pairing (Jousselin 2020, Annex A,
/// Alg. 4): each point of `outer` walks straight towards its nearest point on
/// `inner`; the `steps - 1` intermediate curves (innermost first, the k-th at
/// `k / steps` of the way from `inner`) are projected onto `support` (the
/// walk leaves curved supports) and cleaned of local loops (Alg. 2), since
/// neighbouring walks cross where an outer point passes the inner curve's
/// medial axis. The reference for [`morph_level`].
#[must_use]
pub fn morph_vectorial(support: &Support, inner: &Curve, outer: &Curve, steps: usize) -> Vec<Curve> {
    let q = PolylineQuery::new(vec![inner.line.clone()]);
    let near: Vec<Point3> = outer.line.points.iter().map(|p| q.closest(p).map_or(*p, |f| f.point)).collect();
    (1..steps)
        .map(|k| {
            let w = 1.0 - k as f64 / steps as f64;
            let pts: Vec<Point3> = outer
                .line
                .points
                .iter()
                .zip(&near)
                .map(|(p, n)| support.query().closest_point(&(p + (n - p) * w)).point)
                .collect();
            let pts = crate::vectorial::remove_local_loops(pts, outer.line.closed);
            let normals = pts.iter().map(|p| support.normal_at(p)).collect();
            Curve { line: Polyline3::new(pts, outer.line.closed), normals }
        })
        .collect()
}
