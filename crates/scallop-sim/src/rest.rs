//! Material the cutter cannot reach, told apart from the scallop on the
//! machined surface (issue 15, item 4).
//!
//! The lowest surface any 3-axis program of a cutter can leave over a part is
//! its **reach**: at a point `p`, the lowest height of the cutter's lower
//! surface over every cutter location that does not penetrate the part,
//! `reach(p) = min over c of (CL(c) + h(|p - c|))` with `CL` the drop-cutter
//! tip height and `h` the cutter profile (OpenCAMLib's `height(r)`), over the
//! locations `c` within the cutter radius of `p`: the morphological opening of
//! the part by the cutter. Where `reach(p)` stands above the part (a concave
//! corner sharper than the cutter, a slot narrower than it), no program can
//! finish the surface there: all the material the program left over it is
//! rest material, reported with its place, area and depth. Where the reach
//! lies within the limit of the surface, the scallop a plan must hold is what
//! the program left above `max(part, reach)`.
//!
//! `CL` is sampled on the stock's grid, so `reach` is known within the grid's
//! sampling: the cells whose machined thickness still exceeds the limit are
//! reported as a scallop over the limit, never hidden as rest material.

use rayon::prelude::*;
use scallop_cutter::{Cutter, drop_cutter};
use scallop_geom::{Point2, Point3};
use scallop_mesh::MeshIndex;

use crate::verify::{PartField, edge_distance2};
use crate::{VerifyOptions, ZMap};

/// One connected place of rest material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestPlace {
    /// Its deepest cell's centre.
    pub at: Point2,
    /// Its area (mm^2, cells times cell area, in XY).
    pub area: f64,
    /// Its largest thickness of material left, along the part normal (mm).
    pub depth: f64,
}

/// The material left over a part, split (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct RestSplit {
    /// Largest thickness along the normal above `max(part, reach)` over the
    /// cells where the scallop is measured: the scallop on the machined
    /// surface (mm).
    pub machined_max: f64,
    /// Where `machined_max` is.
    pub machined_at: Option<Point2>,
    /// Area of the cells whose surface the cutter cannot reach within the limit (mm^2).
    pub unreachable_area: f64,
    /// Largest thickness of material left over that surface (mm).
    pub unreachable_depth: f64,
    /// The places, largest first (at most [`crate::tol::WORST_REPORTED`]).
    pub places: Vec<RestPlace>,
    /// The cells of the machined surface whose scallop exceeds the limit,
    /// thickest first (at most [`crate::tol::OVER_REPORTED`]): the places a
    /// planner has to refine.
    pub machined_over: Vec<OverCell>,
}

/// A cell of the machined surface with more than the limit left on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OverCell {
    /// The part's surface point under the cell's centre (mm).
    pub at: Point3,
    /// The vertical component of the part's normal there.
    pub nz: f64,
    /// The scallop there, along the normal (mm).
    pub thickness: f64,
    /// The tip of the sampled cutter location whose cutter comes lowest over
    /// the cell (the one that defines the reach there): the cutter that
    /// touches the part at the cell. Where other faces hold the cutter off
    /// (a hollow of the drop-cutter surface) it is not where a cutter resting
    /// on the cell's facet alone would stand. `None` where no location was
    /// sampled within the cutter radius.
    pub reached_from: Option<Point3>,
}

/// Splits the material the program left on `zmap` over the part (`field`,
/// `part`) into the scallop on the machined surface and rest material the
/// `cutter` cannot reach. Only the cells where the scallop is measured
/// (`options.scallop_margin` inside the footprint) and whose thickness exceeds
/// `limit` (mm) are examined; the others keep their thickness.
#[must_use]
pub fn split_rest(
    zmap: &ZMap,
    field: &PartField,
    part: &MeshIndex,
    cutter: &Cutter,
    options: &VerifyOptions,
    limit: f64,
) -> RestSplit {
    let (nx, ny) = (zmap.nx(), zmap.ny());
    let (cx, cy) = zmap.cell_size();
    let top = field.surface();
    let margin = options.scallop_margin.max(0.0);
    let edge2 = (margin > 0.0).then(|| {
        let inside: Vec<bool> = top.iter().map(|&(z, _)| z != f64::NEG_INFINITY).collect();
        edge_distance2(&inside, nx, ny, cx, cy)
    });
    let measured = |k: usize| top[k].0 != f64::NEG_INFINITY && edge2.as_ref().is_none_or(|d| d[k] > margin * margin);
    let thickness = |k: usize| (zmap.heights()[k] - top[k].0) * top[k].1;
    let candidates: Vec<usize> = (0..nx * ny).filter(|&k| measured(k) && thickness(k) > limit).collect();
    let reach = Reach::new(zmap, part, cutter, &candidates);
    // Per candidate: (machined thickness, rest thickness): a cell whose surface
    // the cutter cannot reach within the limit is rest, all its material counted.
    let split: Vec<(f64, f64, Option<Point3>)> = candidates
        .par_iter()
        .map(|&k| {
            let (part_z, nz) = top[k];
            let (r, from) = reach.at(k);
            let r = r.max(part_z);
            if (r - part_z) * nz > limit {
                (0.0, thickness(k), from)
            } else {
                ((zmap.heights()[k] - r) * nz, 0.0, from)
            }
        })
        .collect();
    let mut machined: Option<(f64, usize)> = None;
    for k in (0..nx * ny).filter(|&k| measured(k) && thickness(k) <= limit) {
        let t = thickness(k);
        if machined.is_none_or(|(m, _)| t > m) {
            machined = Some((t, k));
        }
    }
    let mut rest = vec![0.0; nx * ny];
    for (&k, &(m, r, _)) in candidates.iter().zip(&split) {
        if machined.is_none_or(|(best, _)| m > best) {
            machined = Some((m, k));
        }
        rest[k] = r;
    }
    let mut machined_over: Vec<OverCell> = candidates
        .iter()
        .zip(&split)
        .filter(|&(_, &(m, _, _))| m > limit)
        .map(|(&k, &(m, _, reached_from))| {
            let c = zmap.cell_center(k % nx, k / nx);
            OverCell { at: Point3::new(c.x, c.y, top[k].0), nz: top[k].1, thickness: m, reached_from }
        })
        .collect();
    machined_over.sort_by(|a, b| {
        b.thickness.total_cmp(&a.thickness).then(a.at.x.total_cmp(&b.at.x)).then(a.at.y.total_cmp(&b.at.y))
    });
    machined_over.truncate(crate::tol::OVER_REPORTED);
    let places = rest_places(&rest, zmap);
    let area = cx * cy;
    #[allow(clippy::cast_precision_loss, reason = "cell counts")]
    let unreachable_area = rest.iter().filter(|&&r| r > 0.0).count() as f64 * area;
    RestSplit {
        machined_max: machined.map_or(0.0, |(m, _)| m),
        machined_at: machined.map(|(_, k)| zmap.cell_center(k % nx, k / nx)),
        unreachable_area,
        unreachable_depth: rest.iter().copied().fold(0.0, f64::max),
        places,
        machined_over,
    }
}

/// The drop-cutter sampled at the cell centres within the cutter radius of
/// the candidate cells, and the reach computed from it.
struct Reach<'a> {
    zmap: &'a ZMap,
    cutter: &'a Cutter,
    /// Tip height per cell (NaN where not needed).
    cl: Vec<f64>,
}

impl<'a> Reach<'a> {
    fn new(zmap: &'a ZMap, part: &MeshIndex, cutter: &'a Cutter, candidates: &[usize]) -> Reach<'a> {
        let (nx, ny) = (zmap.nx(), zmap.ny());
        let mut need = vec![false; nx * ny];
        let (ri, rj) = Self::radius_cells(zmap, cutter);
        for &k in candidates {
            let (i, j) = (k % nx, k / nx);
            for jj in j.saturating_sub(rj)..=(j + rj).min(ny - 1) {
                for ii in i.saturating_sub(ri)..=(i + ri).min(nx - 1) {
                    need[jj * nx + ii] = true;
                }
            }
        }
        let floor = zmap.stock().min.z - part.bounds().diagonal() - 1.0;
        let cl = (0..nx * ny)
            .into_par_iter()
            .map(|k| {
                if need[k] {
                    drop_cutter(cutter, part, zmap.cell_center(k % nx, k / nx), floor).tip.z
                } else {
                    f64::NAN
                }
            })
            .collect();
        Reach { zmap, cutter, cl }
    }

    fn radius_cells(zmap: &ZMap, cutter: &Cutter) -> (usize, usize) {
        let (cx, cy) = zmap.cell_size();
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "small positive counts")]
        ((cutter.radius() / cx).ceil() as usize, (cutter.radius() / cy).ceil() as usize)
    }

    /// `reach` at cell `k` (module docs), over the sampled locations, and the
    /// tip of the location it comes from.
    fn at(&self, k: usize) -> (f64, Option<Point3>) {
        let (nx, ny) = (self.zmap.nx(), self.zmap.ny());
        let (ri, rj) = Self::radius_cells(self.zmap, self.cutter);
        let (i, j) = (k % nx, k / nx);
        let p = self.zmap.cell_center(i, j);
        let (radius, shape) = (self.cutter.radius(), self.cutter.shape());
        let (mut best, mut from) = (f64::INFINITY, None);
        for jj in j.saturating_sub(rj)..=(j + rj).min(ny - 1) {
            for ii in i.saturating_sub(ri)..=(i + ri).min(nx - 1) {
                let c = self.cl[jj * nx + ii];
                let q = self.zmap.cell_center(ii, jj);
                let d = (q - p).norm();
                if d <= radius && c.is_finite() && c + shape.height_at(d) < best {
                    best = c + shape.height_at(d);
                    from = Some(Point3::new(q.x, q.y, c));
                }
            }
        }
        (best, from)
    }
}

/// The connected places (4-neighbours) of the cells of `zmap` with `rest > 0`
/// (one value per cell, row-major), largest first, at most
/// [`crate::tol::WORST_REPORTED`].
#[must_use]
pub fn rest_places(rest: &[f64], zmap: &ZMap) -> Vec<RestPlace> {
    let (nx, ny) = (zmap.nx(), zmap.ny());
    let (cx, cy) = zmap.cell_size();
    let mut seen = vec![false; rest.len()];
    let mut out = Vec::new();
    let mut stack = Vec::new();
    for start in 0..rest.len() {
        if seen[start] || rest[start] <= 0.0 {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        let (mut cells, mut deepest) = (0usize, (0.0, start));
        while let Some(k) = stack.pop() {
            cells += 1;
            if rest[k] > deepest.0 {
                deepest = (rest[k], k);
            }
            let (i, j) = (k % nx, k / nx);
            let mut visit = |n: usize| {
                if !seen[n] && rest[n] > 0.0 {
                    seen[n] = true;
                    stack.push(n);
                }
            };
            if i > 0 {
                visit(k - 1);
            }
            if i + 1 < nx {
                visit(k + 1);
            }
            if j > 0 {
                visit(k - nx);
            }
            if j + 1 < ny {
                visit(k + nx);
            }
        }
        #[allow(clippy::cast_precision_loss, reason = "cell counts")]
        let area = cells as f64 * cx * cy;
        out.push(RestPlace { at: zmap.cell_center(deepest.1 % nx, deepest.1 / nx), area, depth: deepest.0 });
    }
    out.sort_by(|a, b| b.area.total_cmp(&a.area).then(b.depth.total_cmp(&a.depth)));
    out.truncate(crate::tol::WORST_REPORTED);
    out
}
