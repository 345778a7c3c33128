//! Tessellation of patches into a [`TriMesh`] within a chordal tolerance.
//!
//! # The bound
//! The mesh is a (u, v) grid; each cell `hu x hv` is split along its diagonal into
//! two triangles whose parameter-space images are right triangles with legs `hu`
//! and `hv`. Let `L` be the linear interpolation of `S` over such a triangle at
//! parameter `x`, with barycentric weights `l_k` of the corners `x_k`. Taylor's
//! theorem with integral remainder along the segments `x -> x_k` (inside the
//! triangle, which is convex) gives, since `sum l_k (x_k - x) = 0`:
//!
//! ```text
//! S(x) - L(x) = -sum_k l_k  integral_0^1 (1 - t) D2S(x + t d_k)[d_k, d_k] dt,   d_k = x_k - x
//! |D2S[d, d]| <= du^2 Muu + 2 |du dv| Muv + dv^2 Mvv      (Muu = max |Suu| etc. over the cell)
//! ```
//!
//! With normalised coordinates `x = (s hu, t hv)`, `s, t >= 0`, `s + t <= 1`, the
//! three weighted sums are `sum l_k du_k^2 = s (1 - s) hu^2`, `sum l_k dv_k^2 =
//! t (1 - t) hv^2` and `sum l_k |du_k dv_k| = s t (3 - 2s - 2t) hu hv`. Each is at
//! most 1/4 (times its scale), all at the hypotenuse midpoint, so
//!
//! ```text
//! dist(S(x), mesh) <= |S(x) - L(x)| <= (hu^2 Muu + 2 hu hv Muv + hv^2 Mvv) / 8.
//! ```
//!
//! The second derivatives need only be bounded inside each cell, and they may jump
//! at knots, so grid lines include every knot (each knot span is subdivided
//! evenly); the bound then holds even for C0 knots.
//!
//! # The maxima
//! - Polynomial patches (Bezier or NURBS without weights): **guaranteed**. `Suu` is
//!   a B-spline (Bezier) surface of degree `(p - 2, q)` whose control points are the
//!   scaled second differences of the net,
//!   `R_ij = (p - 1)(Q_{i+1,j} - Q_ij) / (U_{i+p+1} - U_{i+2})` with
//!   `Q_ij = p (P_{i+1,j} - P_ij) / (U_{i+p+1} - U_{i+1})` (for Bezier:
//!   `p (p - 1) (P_{i+2,j} - 2 P_{i+1,j} + P_ij)`); its basis functions are
//!   non-negative and sum to 1, so `|Suu| <= max |R_ij|`. The same holds for `Suv`
//!   (first differences in both directions) and `Svv`.
//! - Rational patches: the maxima of `|Suu|`, `|Suv|`, `|Svv|` over a grid of
//!   `tol::SAMPLES_PER_SPAN` intervals per span, times `tol::SAMPLED_BOUND_SAFETY`.
//!   An estimate, not a proof; [`Tessellation::guaranteed`] says which applies.
//!
//! # The grid
//! For cell sizes `(hu, hv) = (Du / nu, Dv / nv)` (`D` = domain widths), the
//! smallest `nu * nv` with bound `<= tol` is found by trying each feasible `nu`
//! and solving the quadratic in `hv` for the largest admissible value:
//! `hv = (8 tol - Muu hu^2) / (Muv hu + sqrt(Muv^2 hu^2 + Mvv (8 tol - Muu hu^2)))`.
//! Knot spans then get `ceil(nu * span / Du)` cells each, which never makes a cell
//! larger. Mesh vertices are welded by [`TriMesh::from_indexed`] (a move of at most
//! `scallop_geom::tol::REL_WELD` times the model diagonal) and triangles at
//! collapsed edges are dropped (they have no area).

use scallop_geom::{Point3, Vec3};
use scallop_mesh::{MeshDiagnostics, MeshError, TriMesh};

use crate::closest::subdivide;
use crate::error::{Direction, PatchLabel, SurfaceError};
use crate::patch::Patch;
use crate::tol;

/// Bounds on the norms of the second derivatives over the whole domain (per unit
/// parameter squared), from [`Patch::second_derivative_bounds`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SecondDerivativeBounds {
    /// Bound on `|Suu|`.
    pub uu: f64,
    /// Bound on `|Suv|`.
    pub uv: f64,
    /// Bound on `|Svv|`.
    pub vv: f64,
    /// Whether these are proven bounds (polynomial patches) or sampled estimates
    /// times a safety factor (rational patches).
    pub guaranteed: bool,
}

impl SecondDerivativeBounds {
    /// The chordal bound `(hu^2 Muu + 2 hu hv Muv + hv^2 Mvv) / 8` of a cell `hu x hv`.
    #[must_use]
    pub fn chordal_bound(&self, hu: f64, hv: f64) -> f64 {
        (hu * hu * self.uu + 2.0 * hu * hv * self.uv + hv * hv * self.vv) / 8.0
    }
}

/// A tessellation and what it guarantees.
#[derive(Clone, Debug)]
pub struct Tessellation {
    /// The triangle mesh (orientation: triangle normals follow `Su x Sv`).
    pub mesh: TriMesh,
    /// What building the mesh cleaned up (welded vertices, dropped degenerate triangles).
    pub diagnostics: MeshDiagnostics,
    /// Achieved bound on the distance from any surface point to the mesh (mm), the
    /// largest over all patches; `<= tol` up to rounding.
    pub chordal_bound: f64,
    /// Whether `chordal_bound` is proven (all patches polynomial) or estimated.
    pub guaranteed: bool,
    /// Grid cells `[along u, along v]` used for each patch, in order.
    pub cells: Vec<[usize; 2]>,
}

/// A planned grid of one patch.
struct Grid {
    us: Vec<f64>,
    vs: Vec<f64>,
    bound: f64,
    guaranteed: bool,
}

impl Patch {
    /// Bounds on `|Suu|`, `|Suv|`, `|Svv|` over the domain (see the
    /// [module docs](crate::tessellate) for how they are obtained).
    ///
    /// ```
    /// let set = scallop_surface::builtin("rubio").unwrap();
    /// let rubio = &set.patches()[0];
    /// let m = rubio.second_derivative_bounds();
    /// assert!(m.guaranteed && rubio.derivatives(0.3, 0.8).duu.norm() <= m.uu);
    /// ```
    #[must_use]
    pub fn second_derivative_bounds(&self) -> SecondDerivativeBounds {
        if self.is_rational() { self.sampled_second_derivatives() } else { self.control_net_second_derivatives() }
    }

    fn control_net_second_derivatives(&self) -> SecondDerivativeBounds {
        let [rows, columns] = self.control_shape();
        let net: Vec<Vec<Vec3>> =
            (0..rows).map(|i| (0..columns).map(|j| self.control_point(i, j).coords).collect()).collect();
        let knots_u = self.knot_vector(Direction::U);
        let knots_v = self.knot_vector(Direction::V);
        let [p, q] = self.degree();
        let du = differentiate(&net, &knots_u, p, Direction::U);
        let duu = differentiate(&du, &knots_u, p.saturating_sub(1), Direction::U);
        let duv = differentiate(&du, &knots_v, q, Direction::V);
        let dv = differentiate(&net, &knots_v, q, Direction::V);
        let dvv = differentiate(&dv, &knots_v, q.saturating_sub(1), Direction::V);
        let max_norm = |m: &Vec<Vec<Vec3>>| m.iter().flatten().map(Vec3::norm).fold(0.0, f64::max);
        SecondDerivativeBounds { uu: max_norm(&duu), uv: max_norm(&duv), vv: max_norm(&dvv), guaranteed: true }
    }

    fn sampled_second_derivatives(&self) -> SecondDerivativeBounds {
        let [us, vs] = Direction::BOTH.map(|d| subdivide(&self.span_breaks(d), |_| tol::SAMPLES_PER_SPAN));
        let (mut uu, mut uv, mut vv) = (0.0_f64, 0.0_f64, 0.0_f64);
        // At a knot the derivatives are those of the span to the right; the left limit is
        // approached by the neighbouring samples.
        for &u in &us {
            for &v in &vs {
                let d = self.derivatives(u, v);
                uu = uu.max(d.duu.norm());
                uv = uv.max(d.duv.norm());
                vv = vv.max(d.dvv.norm());
            }
        }
        let s = tol::SAMPLED_BOUND_SAFETY;
        SecondDerivativeBounds { uu: s * uu, uv: s * uv, vv: s * vv, guaranteed: false }
    }

    /// Tessellates the patch so that every surface point lies within `tolerance`
    /// (mm) of the mesh (see the [module docs](crate::tessellate) for the bound and its proof).
    ///
    /// ```
    /// let set = scallop_surface::builtin("choi").unwrap();
    /// let choi = &set.patches()[0];
    /// let t = choi.tessellate(0.05).unwrap();
    /// assert!(t.guaranteed && t.chordal_bound <= 0.05);
    /// assert!((t.mesh.area() - 3241.0).abs() < 5.0);
    /// ```
    ///
    /// # Errors
    /// [`SurfaceError::BadTolerance`], [`SurfaceError::TooFine`] or
    /// [`SurfaceError::Mesh`] (the surface collapses to a curve or a point).
    pub fn tessellate(&self, tolerance: f64) -> Result<Tessellation, SurfaceError> {
        tessellate_patches(std::slice::from_ref(self), tolerance)
    }

    fn plan_grid(&self, tolerance: f64) -> Result<Grid, SurfaceError> {
        let m = self.second_derivative_bounds();
        let domain = self.domain();
        let widths = [domain.u[1] - domain.u[0], domain.v[1] - domain.v[0]];
        let too_fine = |cells: usize| SurfaceError::TooFine {
            patch: PatchLabel::named(self.name()),
            cells,
            limit: tol::MAX_TESSELLATION_CELLS,
        };
        let limit = tol::MAX_TESSELLATION_CELLS;
        let budget = 8.0 * tolerance;
        // Fewest cells along u with Muu hu^2 < 8 tol, and along v with Mvv hv^2 < 8 tol.
        let least = |width: f64, m2: f64| -> f64 { (width * (m2 / budget).sqrt()).floor() + 1.0 };
        let (least_u, least_v) = (least(widths[0], m.uu), least(widths[1], m.vv));
        let least_cells = least_u * least_v; // +inf or NaN for absurd curvature/tolerance ratios
        if least_cells.is_nan() || least_cells > to_f64(limit) {
            return Err(too_fine(saturate(least_cells)));
        }
        let (least_u, least_v) = (saturate(least_u), saturate(least_v));
        let mut best: Option<[usize; 2]> = None;
        let mut nu = least_u;
        while nu <= limit && best.is_none_or(|[bu, bv]| nu.saturating_mul(least_v) < bu * bv) {
            let hu = widths[0] / to_f64(nu);
            let room = budget - m.uu * hu * hu;
            if room > 0.0 {
                let denominator = m.uv * hu + (m.uv * m.uv * hu * hu + m.vv * room).sqrt();
                let hv = if denominator > 0.0 { room / denominator } else { f64::INFINITY };
                let mut nv = saturate((widths[1] / hv).ceil()).max(1);
                while nv < limit && m.chordal_bound(hu, widths[1] / to_f64(nv)) > tolerance {
                    nv += 1; // rounding in the quadratic
                }
                if m.chordal_bound(hu, widths[1] / to_f64(nv)) <= tolerance
                    && best.is_none_or(|[bu, bv]| nu.saturating_mul(nv) < bu * bv)
                {
                    best = Some([nu, nv]);
                }
            }
            nu += 1;
        }
        let Some([nu, nv]) = best else { return Err(too_fine(limit.saturating_add(1))) };
        let per_direction = [nu, nv];
        let [us, vs] = Direction::BOTH.map(|direction| {
            let d = direction.index();
            let breaks = self.span_breaks(direction);
            let n = to_f64(per_direction[d]);
            subdivide(&breaks, |s| saturate(((breaks[s + 1] - breaks[s]) / widths[d] * n).ceil()))
        });
        let cells = (us.len() - 1).saturating_mul(vs.len() - 1);
        if cells > limit {
            return Err(too_fine(cells));
        }
        let largest = |values: &[f64]| values.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
        let bound = m.chordal_bound(largest(&us), largest(&vs));
        Ok(Grid { us, vs, bound, guaranteed: m.guaranteed })
    }
}

/// Tessellates several patches into one mesh (shared edges are welded when their
/// vertices coincide). Errors name the patch by its index in `patches`.
pub(crate) fn tessellate_patches(patches: &[Patch], tolerance: f64) -> Result<Tessellation, SurfaceError> {
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(SurfaceError::BadTolerance { value: tolerance });
    }
    let mut vertices: Vec<Point3> = Vec::new();
    let mut triangles: Vec<[usize; 3]> = Vec::new();
    let mut chordal_bound = 0.0_f64;
    let mut guaranteed = true;
    let mut cells = Vec::with_capacity(patches.len());
    for (index, patch) in patches.iter().enumerate() {
        let grid = patch.plan_grid(tolerance).map_err(|e| e.with_patch_index(index))?;
        let base = vertices.len();
        let stride = grid.vs.len();
        for &u in &grid.us {
            for &v in &grid.vs {
                vertices.push(patch.point(u, v));
            }
        }
        for i in 0..grid.us.len() - 1 {
            for j in 0..stride - 1 {
                let a = base + i * stride + j;
                let (b, c, d) = (a + stride, a + stride + 1, a + 1);
                // (b - a) ~ Su du, (c - a) ~ Su du + Sv dv: normals follow Su x Sv.
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            }
        }
        chordal_bound = chordal_bound.max(grid.bound);
        guaranteed &= grid.guaranteed;
        cells.push([grid.us.len() - 1, grid.vs.len() - 1]);
    }
    let (mesh, diagnostics) = TriMesh::from_indexed(&vertices, &triangles).map_err(|source| {
        // Name the patch owning the triangle the error is about; `AllDegenerate` is
        // about every patch, so the first one is named.
        let triangle = match &source {
            MeshError::NonFinite { triangle, .. } | MeshError::IndexOutOfRange { triangle, .. } => *triangle,
            _ => 0,
        };
        let mut first_triangle = 0;
        let mut index = 0;
        for (k, [nu, nv]) in cells.iter().enumerate() {
            if triangle >= first_triangle {
                index = k;
            }
            first_triangle += 2 * nu * nv;
        }
        let patch = patches
            .get(index)
            .map_or_else(PatchLabel::default, |p| PatchLabel { index: Some(index), name: p.name().to_owned() });
        SurfaceError::Mesh { patch, source }
    })?;
    Ok(Tessellation { mesh, diagnostics, chordal_bound, guaranteed, cells })
}

/// Control points of the derivative in `direction` of a B-spline net of `degree`
/// with `knots` (The NURBS Book eq. 3.8); spans of zero length give zero points.
fn differentiate(net: &[Vec<Vec3>], knots: &[f64], degree: usize, direction: Direction) -> Vec<Vec<Vec3>> {
    if degree == 0 {
        return Vec::new();
    }
    let p = to_f64(degree);
    // The net may already be a derivative: its knot vector is `knots` with `offset`
    // knots dropped at each end.
    let offset = (knots.len() - (net_len(net, direction) + degree + 1)) / 2;
    let coefficient = |k: usize| {
        let span = knots[offset + k + degree + 1] - knots[offset + k + 1];
        if span > 0.0 { p / span } else { 0.0 }
    };
    match direction {
        Direction::U => (0..net.len().saturating_sub(1))
            .map(|i| net[i].iter().zip(&net[i + 1]).map(|(a, b)| (b - a) * coefficient(i)).collect())
            .collect(),
        Direction::V => net
            .iter()
            .map(|row| (0..row.len().saturating_sub(1)).map(|j| (row[j + 1] - row[j]) * coefficient(j)).collect())
            .collect(),
    }
}

fn net_len(net: &[Vec<Vec3>], direction: Direction) -> usize {
    match direction {
        Direction::U => net.len(),
        Direction::V => net.first().map_or(0, Vec::len),
    }
}

#[allow(clippy::cast_precision_loss)]
fn to_f64(n: usize) -> f64 {
    n as f64
}

/// A non-negative float as a count, saturating (NaN and +inf saturate to `usize::MAX`).
#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
fn saturate(x: f64) -> usize {
    if x.is_nan() { usize::MAX } else { x as usize }
}
