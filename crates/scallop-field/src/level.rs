//! Axial levels: offsets of a surface (several iso-levels of one distance
//! field) and morph levels between two surfaces, as welded meshes.

use rayon::prelude::*;
use scallop_geom::Point3;
use scallop_mesh::TriMesh;

use crate::{FieldError, Grid, IsoMesh, Surface, distance_field, iso_surface, morph_field, tol};

/// Which sheet of an unsigned offset to keep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The side the surface's triangle normals point to.
    Along,
    /// The side behind the surface.
    Against,
    /// Both sheets, with the rounded caps around an open surface's boundary.
    Both,
}

/// Settings of level extraction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelOptions {
    /// Voxel size `h` (mm): the levels lie within `h / 2` of the exact offset
    /// on smooth parts of the surface (docs/guides.md).
    pub voxel: f64,
    /// Bound on the grid's samples (memory); [`tol::DEFAULT_MAX_SAMPLES`] by default.
    pub max_samples: usize,
    /// The sheet kept (offset levels only).
    pub side: Side,
}

impl Default for LevelOptions {
    fn default() -> Self {
        LevelOptions { voxel: 0.5, max_samples: tol::DEFAULT_MAX_SAMPLES, side: Side::Along }
    }
}

/// The offsets of `surface` at each distance of `distances` (mm, positive),
/// extracted from one unsigned distance field (Jousselin 2020, Ch. 2 section
/// 3.1, Eq. 2.6), each reduced to the sheet on `options.side` (side of each
/// triangle's centroid by the pseudo-normal of its closest point), in the order
/// of `distances`.
///
/// # Errors
/// [`FieldError::BadDistance`] for a distance that is not finite and positive,
/// the grid's errors ([`Grid::around`]), [`FieldError::EmptyLevel`] when a level
/// has no triangle on the chosen side, and mesh validation errors.
pub fn offset_levels(surface: &Surface, distances: &[f64], options: &LevelOptions) -> Result<Vec<TriMesh>, FieldError> {
    let mut max_d = 0.0f64;
    for (index, &d) in distances.iter().enumerate() {
        if !(d.is_finite() && d > 0.0) {
            return Err(FieldError::BadDistance { index, value: d });
        }
        max_d = max_d.max(d);
    }
    let margin = max_d + tol::BAND_MARGIN_VOXELS * options.voxel;
    let grid = Grid::around(&surface.mesh().bounds(), margin, options.voxel, options.max_samples)?;
    let field = distance_field(surface, grid, margin);
    distances
        .iter()
        .enumerate()
        .map(|(index, &d)| {
            let iso = iso_surface(&field, d);
            // A centroid lies within the band (iso + 2 h) of the surface.
            let band = d + tol::BAND_MARGIN_VOXELS * options.voxel;
            let kept = keep(&iso, |p| match options.side {
                Side::Both => true,
                Side::Along => surface.side_within(p, band) > 0.0,
                Side::Against => surface.side_within(p, band) < 0.0,
            });
            to_mesh(&kept, index, d)
        })
        .collect()
}

/// `count` morph levels between `bottom` (S_1) and `top` (S_2): the zero sets
/// of Eq. 2.7 of Jousselin 2020 (Ch. 2 section 3.1) for `m = k / (count + 1)`,
/// `k = 1..=count`, bottom first. Both distance fields are computed once over
/// the box of the two surfaces, every sample exact (the grid gets half of
/// `options.max_samples`, as two fields are held). With unsigned distances Eq. 2.7 has a second,
/// spurious zero set outside the slab between the surfaces; a triangle is kept
/// only when its centroid lies between them: the directions to its closest
/// points on S_1 and S_2 are opposed (negative dot product).
///
/// # Errors
/// [`FieldError::BadMorphCount`] for `count == 0`, the grid's errors,
/// [`FieldError::EmptyLevel`] and mesh validation errors.
pub fn morph_levels(
    bottom: &Surface,
    top: &Surface,
    count: usize,
    options: &LevelOptions,
) -> Result<Vec<TriMesh>, FieldError> {
    if count == 0 {
        return Err(FieldError::BadMorphCount);
    }
    let mut bounds = bottom.mesh().bounds();
    bounds.grow(&top.mesh().bounds().min);
    bounds.grow(&top.mesh().bounds().max);
    let margin = tol::BAND_MARGIN_VOXELS * options.voxel;
    let grid = Grid::around(&bounds, margin, options.voxel, options.max_samples / 2)?;
    let (d1, d2) =
        rayon::join(|| distance_field(bottom, grid, f64::INFINITY), || distance_field(top, grid, f64::INFINITY));
    (1..=count)
        .map(|k| {
            #[allow(clippy::cast_precision_loss, reason = "level counts far below 2^52")]
            let m = k as f64 / (count + 1) as f64;
            let iso = iso_surface(&morph_field(&d1, &d2, m), 0.0);
            let kept = keep(&iso, |p| {
                let (Some(c1), Some(c2)) = (bottom.closest(p, f64::INFINITY), top.closest(p, f64::INFINITY)) else {
                    return false;
                };
                (c1.point - p).dot(&(c2.point - p)) < 0.0
            });
            to_mesh(&kept, k - 1, m)
        })
        .collect()
}

/// The triangles of `iso` whose centroid passes `test`, in order (tested in
/// parallel, collected by index).
fn keep(iso: &IsoMesh, test: impl Fn(&Point3) -> bool + Sync) -> IsoMesh {
    let pass: Vec<bool> = iso
        .triangles
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| iso.vertices[i]);
            test(&Point3::from((a.coords + b.coords + c.coords) / 3.0))
        })
        .collect();
    let triangles = iso.triangles.iter().zip(pass).filter(|(_, p)| *p).map(|(t, _)| *t).collect();
    IsoMesh { vertices: iso.vertices.clone(), triangles }
}

fn to_mesh(iso: &IsoMesh, index: usize, value: f64) -> Result<TriMesh, FieldError> {
    if iso.triangles.is_empty() {
        return Err(FieldError::EmptyLevel { index, value });
    }
    Ok(TriMesh::from_indexed(&iso.vertices, &iso.triangles)?.0)
}
