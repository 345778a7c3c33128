//! Verification of a cut stock against the design part.

use rayon::prelude::*;
use scallop_geom::predicates::{in_triangle, orient2d};
use scallop_geom::{Aabb2, Aabb3, Point2, Tolerances};
use scallop_mesh::MeshIndex;

use crate::tol::WORST_REPORTED;
use crate::zmap::index_range;
use crate::{MoveId, SimError, ZMap};

/// Rows per band of the part rasterisation (fixed: results do not depend on threads).
const PART_BAND_ROWS: usize = 16;

/// Algorithm knobs of [`verify`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerifyOptions {
    /// Largest allowed penetration of the stock below the part (mm); the
    /// stock's rounding epsilon is added. Normally `Tolerances::gouge` plus the
    /// chordal error the program is allowed to have.
    pub gouge_tolerance: f64,
    /// How many of the deepest gouge cells a [`SimError::Gouge`] lists.
    pub worst_reported: usize,
    /// Width (mm) of the strip along the edge of the part's footprint that
    /// the scallop figures [`Verification::max_thickness`] leave out (its
    /// largest thickness is reported apart, in
    /// [`Verification::margin_max_thickness`]; gouges are checked everywhere).
    /// A finishing plan guarantees its scallop height where neighbouring passes
    /// both shape the surface; near the part's open edge the surface is shaped by
    /// pass ends and by the first and last planes (half a spacing inside the
    /// edge) instead. With scallop's `Boundary::ContactInside` rule every cutter
    /// location that shapes a point farther than the cutter radius R from the
    /// edge has its contact inside the part, so R is the margin that matches it.
    /// 0 (the default): the whole footprint.
    pub scallop_margin: f64,
}

impl Default for VerifyOptions {
    /// No gouge allowed beyond rounding; the 20 deepest cells reported.
    fn default() -> Self {
        VerifyOptions { gouge_tolerance: 0.0, worst_reported: WORST_REPORTED, scallop_margin: 0.0 }
    }
}

impl VerifyOptions {
    /// Options taking the gouge tolerance from the job's tolerances.
    ///
    /// ```
    /// use scallop_geom::Tolerances;
    /// let o = scallop_sim::VerifyOptions::from_tolerances(&Tolerances { path: 0.01, gouge: 0.002 });
    /// assert_eq!(o.gouge_tolerance, 0.002);
    /// ```
    #[must_use]
    pub fn from_tolerances(tolerances: &Tolerances) -> Self {
        VerifyOptions { gouge_tolerance: tolerances.gouge, ..Self::default() }
    }
}

/// One stock cell below the part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GougeCell {
    /// Cell (column, row).
    pub cell: (usize, usize),
    /// Cell centre.
    pub at: Point2,
    /// Stock height there.
    pub stock_z: f64,
    /// Part top there.
    pub part_z: f64,
    /// `part_z - stock_z` (mm, > 0).
    pub depth: f64,
    /// The last move that lowered the cell (the one that cut it this deep).
    pub cut_by: Option<MoveId>,
}

/// The verdict of [`verify`] when the stock is safe.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Verification {
    /// Cells with part under them.
    pub part_cells: usize,
    /// Largest `stock - part` over part cells (mm): the material left, the
    /// scallop where the surface was finished (0 when no cell has part).
    pub max_scallop: f64,
    /// Where `max_scallop` is (the first such cell in row order).
    pub max_scallop_at: Option<Point2>,
    /// Smallest `stock - part` over part cells (mm; >= minus the gouge tolerance).
    pub min_deviation: f64,
    /// Largest material thickness along the part normal, `(stock - part) |n_z|`
    /// with `n` the normal of the part triangle under the cell centre (the
    /// distance from the stock point to that triangle's plane), over the part
    /// cells at least [`VerifyOptions::scallop_margin`] inside the footprint's
    /// edge (mm; 0 when there are none). This is the scallop height as a
    /// finishing plan defines it (along the normal, not vertically).
    pub max_thickness: f64,
    /// Where `max_thickness` is (the first such cell in row order).
    pub max_thickness_at: Option<Point2>,
    /// Largest normal thickness in the edge strip left out of
    /// `max_thickness` (mm; 0 without a margin): reported, never hidden.
    pub margin_max_thickness: f64,
    /// Part cells inside the margin, where `max_thickness` is measured.
    pub scallop_cells: usize,
    /// Volume of stock left (mm^3), see [`ZMap::volume`].
    pub remaining_volume: f64,
    /// Volume removed from the full stock box (mm^3).
    pub removed_volume: f64,
    /// Volume of stock above the part over part cells (mm^3): what finishing would still remove.
    pub excess_volume: f64,
}

/// The part's top z under each cell centre (vertical ray: the highest
/// triangle containing the centre, exact inside test), row-major with x
/// fastest; `f64::NEG_INFINITY` where no triangle lies under the centre.
/// Rasterised per triangle over fixed bands of rows, in parallel; a maximum
/// is exact, so the result does not depend on the thread count.
///
/// ```
/// use scallop_geom::{Aabb3, Point3};
/// use scallop_mesh::{MeshIndex, TriMesh};
/// use scallop_sim::{ZMap, part_heights};
/// let p = |x, y, z| Point3::new(x, y, z);
/// let (mesh, _) = TriMesh::from_soup(&[[p(0., 0., 1.), p(4., 0., 1.), p(0., 4., 3.)]]).unwrap();
/// let zmap = ZMap::new(Aabb3 { min: p(0., 0., 0.), max: p(4., 4., 5.) }, 1.0).unwrap();
/// let top = part_heights(&zmap, &MeshIndex::build(&mesh));
/// assert_eq!(top[0], 1.25); // centre (0.5, 0.5): z = 1 + 0.5 * 0.5
/// assert_eq!(top[15], f64::NEG_INFINITY); // centre (3.5, 3.5) is outside
/// ```
#[must_use]
pub fn part_heights(zmap: &ZMap, part: &MeshIndex) -> Vec<f64> {
    part_surface(zmap, part).into_iter().map(|(z, _)| z).collect()
}

/// The design part sampled once on a z-map's grid: the part's top z under
/// each cell centre and the `|n_z|` of the triangle that gives it (see
/// [`part_heights`]). Rasterising the part is a large share of a simulation;
/// a field built once serves [`ZMap::part_collisions_in`], [`verify_in`] and
/// the caller's own deviation figures. It belongs to the grid it was built on
/// (stock box and cell counts), not to the heights, so it stays valid while
/// the stock is cut.
///
/// ```
/// use scallop_geom::{Aabb3, Point3};
/// use scallop_mesh::{MeshIndex, TriMesh};
/// use scallop_sim::{PartField, VerifyOptions, ZMap, part_heights, verify, verify_in};
/// let p = |x, y, z| Point3::new(x, y, z);
/// let (mesh, _) = TriMesh::from_soup(&[[p(-1., -1., 1.), p(9., -1., 1.), p(-1., 9., 2.)]]).unwrap();
/// let part = MeshIndex::build(&mesh);
/// let zmap = ZMap::new(Aabb3 { min: p(0., 0., 0.), max: p(4., 4., 3.) }, 0.5).unwrap();
/// let field = PartField::new(&zmap, &part);
/// assert_eq!(field.heights().collect::<Vec<_>>(), part_heights(&zmap, &part));
/// let o = VerifyOptions::default();
/// assert_eq!(verify_in(&zmap, &field, &o), verify(&zmap, &part, &o));
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct PartField {
    stock: Aabb3,
    nx: usize,
    ny: usize,
    surface: Vec<(f64, f64)>,
}

impl PartField {
    /// Rasterises `part` on `zmap`'s grid (parallel, deterministic).
    #[must_use]
    pub fn new(zmap: &ZMap, part: &MeshIndex) -> PartField {
        PartField { stock: zmap.stock(), nx: zmap.nx(), ny: zmap.ny(), surface: part_surface(zmap, part) }
    }

    /// The part's top z per cell, row-major with x fastest, `f64::NEG_INFINITY`
    /// where no triangle lies under the centre (the values of [`part_heights`]).
    pub fn heights(&self) -> impl ExactSizeIterator<Item = f64> + '_ {
        self.surface.iter().map(|&(z, _)| z)
    }

    /// Cells along x and y.
    #[must_use]
    pub fn cells(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// Whether the field was built on `zmap`'s grid (same stock box and cells).
    #[must_use]
    pub fn fits(&self, zmap: &ZMap) -> bool {
        self.nx == zmap.nx() && self.ny == zmap.ny() && self.stock == zmap.stock()
    }

    /// `Ok` when the field fits `zmap`.
    pub(crate) fn check(&self, zmap: &ZMap) -> Result<(), SimError> {
        if self.fits(zmap) {
            Ok(())
        } else {
            Err(SimError::FieldGrid { field: [self.nx, self.ny], zmap: [zmap.nx(), zmap.ny()] })
        }
    }

    pub(crate) fn surface(&self) -> &[(f64, f64)] {
        &self.surface
    }
}

/// [`part_heights`] with the `|n_z|` of the triangle that gives each height
/// (the highest one; of equal heights the least steep), `(NEG_INFINITY, 0)`
/// where no triangle lies under the centre.
pub(crate) fn part_surface(zmap: &ZMap, part: &MeshIndex) -> Vec<(f64, f64)> {
    let (nx, ny) = (zmap.nx(), zmap.ny());
    let (cell_x, cell_y) = zmap.cell_size();
    let stock = zmap.stock();
    let mut top = vec![(f64::NEG_INFINITY, 0.0); nx * ny];
    top.par_chunks_mut(PART_BAND_ROWS * nx).enumerate().for_each_init(Vec::new, |slots, (band, out)| {
        let rows = out.len() / nx;
        let j0 = band * PART_BAND_ROWS;
        let y_lo = zmap.cell_center(0, j0).y;
        let y_hi = zmap.cell_center(0, j0 + rows - 1).y;
        let strip = Aabb2 {
            min: Point2::new(stock.min.x, y_lo - 0.5 * cell_y),
            max: Point2::new(stock.max.x, y_hi + 0.5 * cell_y),
        };
        slots.clear();
        part.collect_box(&strip, slots);
        for &slot in slots.iter() {
            let [a, b, c] = *part.corners(slot as usize);
            let (a2, b2, c2) = (a.xy(), b.xy(), c.xy());
            let normal = (b - a).cross(&(c - a));
            let length = normal.norm();
            let nz = if length > 0.0 { (normal.z / length).abs() } else { 0.0 };
            let bx = part.xy_box(slot as usize);
            let Some((i0, i1)) = index_range(bx.min.x, bx.max.x, stock.min.x, cell_x, nx) else { continue };
            let Some((r0, r1)) = index_range(bx.min.y, bx.max.y, stock.min.y, cell_y, ny) else { continue };
            for j in r0.max(j0)..=r1.min(j0 + rows - 1) {
                for i in i0..=i1 {
                    let p = zmap.cell_center(i, j);
                    if !in_triangle(&p, &a2, &b2, &c2) {
                        continue;
                    }
                    // Barycentric weights of one sign inside: z is a convex combination.
                    let (wa, wb, wc) = (orient2d(&b2, &c2, &p), orient2d(&c2, &a2, &p), orient2d(&a2, &b2, &p));
                    let total = wa + wb + wc;
                    let z = if total == 0.0 { a.z.max(b.z).max(c.z) } else { (wa * a.z + wb * b.z + wc * c.z) / total };
                    let cell = &mut out[(j - j0) * nx + i];
                    // A lexicographic maximum: independent of the triangle order.
                    if z.total_cmp(&cell.0).then(nz.total_cmp(&cell.1)).is_gt() {
                        *cell = (z, nz);
                    }
                }
            }
        }
    });
    top
}

/// Squared distance (mm^2) from each cell centre to the nearest centre of a
/// cell with `inside == false`, the cells just outside the grid counting as
/// outside: an exact Euclidean distance transform (lower envelope of
/// parabolas, one pass along rows, one along columns; Felzenszwalb and
/// Huttenlocher 2012). Rows and columns are independent and each is computed
/// the same way on any thread count.
pub(crate) fn edge_distance2(inside: &[bool], nx: usize, ny: usize, cell_x: f64, cell_y: f64) -> Vec<f64> {
    // Along rows: the sites are the outside cells and the two virtual ones.
    let rows = envelope_pass(nx, ny, cell_x, |j, i| (!inside[j * nx + i]).then_some(0.0));
    // Along columns: the sites are every cell with its row distance, plus the
    // two virtual outside cells.
    let columns = envelope_pass(ny, nx, cell_y, |i, j| Some(rows[j * nx + i]));
    let mut d2 = vec![0.0; nx * ny];
    for (i, column) in columns.chunks(ny).enumerate() {
        for (j, &v) in column.iter().enumerate() {
            d2[j * nx + i] = v;
        }
    }
    d2
}

/// One pass of the distance transform over `lines` lines of `n` cells `step`
/// apart: each line's lower envelope ([`lower_envelope`]) of the sites
/// `(k, f)` with `site(line, k) == Some(f)`, plus the two virtual outside
/// cells at -1 and `n`. Lines in parallel, line after line in the result.
fn envelope_pass(n: usize, lines: usize, step: f64, site: impl Fn(usize, usize) -> Option<f64> + Sync) -> Vec<f64> {
    let mut out = vec![0.0; n * lines];
    out.par_chunks_mut(n).enumerate().for_each_init(
        || (Vec::new(), Vec::new()),
        |(sites, env), (line, out)| {
            sites.clear();
            sites.push((-1.0, 0.0));
            for k in 0..n {
                if let Some(f) = site(line, k) {
                    // Cell indices far below 2^52: exact.
                    sites.push((k as f64, f));
                }
            }
            sites.push((n as f64, 0.0));
            lower_envelope(sites, step, env, out);
        },
    );
    out
}

/// `out[q] = min over sites (s, f) of ((q - s) step)^2 + f` for q in 0..out.len();
/// `sites` sorted by position.
fn lower_envelope(sites: &[(f64, f64)], step: f64, env: &mut Vec<((f64, f64), f64)>, out: &mut [f64]) {
    // Each parabola in world units: (x - s step)^2 + f, with the abscissa from
    // which it is the lowest.
    env.clear();
    for &(s, f) in sites {
        let x = s * step;
        let mut from = f64::NEG_INFINITY;
        while let Some(&((px, pf), pfrom)) = env.last() {
            // Intersection of the new parabola with the last one on the envelope.
            let meet = ((f + x * x) - (pf + px * px)) / (2.0 * (x - px));
            if meet <= pfrom {
                env.pop();
            } else {
                from = meet;
                break;
            }
        }
        env.push(((x, f), from));
    }
    let mut k = 0;
    for (q, slot) in out.iter_mut().enumerate() {
        let x = q as f64 * step;
        while k + 1 < env.len() && env[k + 1].1 <= x {
            k += 1;
        }
        let ((px, pf), _) = env[k];
        *slot = (x - px) * (x - px) + pf;
    }
}

#[derive(Default)]
struct RowStats {
    part_cells: usize,
    max: Option<(f64, usize)>,
    min: Option<f64>,
    excess: f64,
    gouges: usize,
    worst: Vec<GougeCell>,
    outside: Option<(usize, f64, f64)>,
    thickness: Option<(f64, usize)>,
    margin_thickness: f64,
    scallop_cells: usize,
}

fn deepest_first(a: &GougeCell, b: &GougeCell) -> std::cmp::Ordering {
    b.depth.total_cmp(&a.depth).then((a.cell.1, a.cell.0).cmp(&(b.cell.1, b.cell.0)))
}

/// Compares the stock with the part cell by cell (signed deviation
/// `stock - part` at every cell centre with part under it) and returns the
/// scallop and volume figures, or the gouges.
///
/// # Errors
/// [`SimError::Gouge`] when some cell lies below the part by more than
/// `options.gouge_tolerance` plus the stock's epsilon (deepest cells first,
/// each with the move that cut it); [`SimError::PartOutsideStock`] when an
/// uncut cell is below the part (the stock box does not contain the part).
///
/// ```
/// use scallop_geom::{Aabb3, Point3};
/// use scallop_mesh::{MeshIndex, TriMesh};
/// use scallop_sim::{VerifyOptions, ZMap, verify};
/// let p = |x, y, z| Point3::new(x, y, z);
/// let (plane, _) = TriMesh::from_soup(&[[p(-1., -1., 1.), p(9., -1., 1.), p(-1., 9., 1.)]]).unwrap();
/// let zmap = ZMap::new(Aabb3 { min: p(0., 0., 0.), max: p(4., 4., 3.) }, 0.5).unwrap();
/// let v = verify(&zmap, &MeshIndex::build(&plane), &VerifyOptions::default()).unwrap();
/// assert_eq!(v.max_scallop, 2.0); // nothing cut yet: 2 mm of stock above the part
/// assert_eq!(v.removed_volume, 0.0);
/// assert_eq!((v.max_thickness, v.scallop_cells), (2.0, 64)); // a level part: along the normal too
/// // A 1 mm margin leaves out the footprint's outer ring of cells (the part
/// // covers the stock; the grid's edge is the footprint's edge).
/// let o = VerifyOptions { scallop_margin: 1.0, ..VerifyOptions::default() };
/// let v = verify(&zmap, &MeshIndex::build(&plane), &o).unwrap();
/// assert_eq!((v.scallop_cells, v.margin_max_thickness), (16, 2.0));
/// ```
pub fn verify(zmap: &ZMap, part: &MeshIndex, options: &VerifyOptions) -> Result<Verification, SimError> {
    verify_in(zmap, &PartField::new(zmap, part), options)
}

/// [`verify`] with the part already rasterised on the stock's grid.
///
/// # Errors
/// Those of [`verify`]; [`SimError::FieldGrid`] when `field` was built on
/// another grid than `zmap`'s.
pub fn verify_in(zmap: &ZMap, field: &PartField, options: &VerifyOptions) -> Result<Verification, SimError> {
    field.check(zmap)?;
    let top = field.surface();
    let (nx, ny) = (zmap.nx(), zmap.ny());
    let (cell_x, cell_y) = zmap.cell_size();
    let margin = options.scallop_margin.max(0.0);
    let edge2 = (margin > 0.0).then(|| {
        let inside: Vec<bool> = top.iter().map(|&(z, _)| z != f64::NEG_INFINITY).collect();
        edge_distance2(&inside, nx, ny, cell_x, cell_y)
    });
    let margin2 = margin * margin;
    let area = cell_x * cell_y;
    let limit = options.gouge_tolerance + zmap.eps();
    let keep = options.worst_reported;
    let rows: Vec<RowStats> = zmap
        .heights()
        .par_chunks(nx)
        .zip(top.par_chunks(nx))
        .enumerate()
        .map(|(j, (stock_row, part_row))| {
            let mut s = RowStats::default();
            for (i, (&stock_z, &(part_z, nz))) in stock_row.iter().zip(part_row).enumerate() {
                if part_z == f64::NEG_INFINITY {
                    continue;
                }
                s.part_cells += 1;
                let dev = stock_z - part_z;
                let thickness = dev * nz;
                if edge2.as_ref().is_none_or(|d| d[j * nx + i] > margin2) {
                    s.scallop_cells += 1;
                    if s.thickness.is_none_or(|(m, _)| thickness > m) {
                        s.thickness = Some((thickness, i));
                    }
                } else {
                    s.margin_thickness = s.margin_thickness.max(thickness);
                }
                if s.max.is_none_or(|(m, _)| dev > m) {
                    s.max = Some((dev, i));
                }
                s.min = Some(s.min.map_or(dev, |m| m.min(dev)));
                s.excess += dev.max(0.0);
                if -dev > limit {
                    let cut_by = zmap.last_cut(i, j);
                    if cut_by.is_none() {
                        if s.outside.is_none() {
                            s.outside = Some((i, stock_z, part_z));
                        }
                        continue;
                    }
                    s.gouges += 1;
                    s.worst.push(GougeCell {
                        cell: (i, j),
                        at: zmap.cell_center(i, j),
                        stock_z,
                        part_z,
                        depth: -dev,
                        cut_by,
                    });
                }
            }
            s.worst.sort_by(deepest_first);
            s.worst.truncate(keep);
            s.excess *= area;
            s
        })
        .collect();

    let mut part_cells = 0;
    let mut max: Option<(f64, (usize, usize))> = None;
    let mut min_deviation: Option<f64> = None;
    let mut excess_volume = 0.0;
    let mut gouges = 0;
    let mut worst = Vec::new();
    let mut thickness: Option<(f64, (usize, usize))> = None;
    let mut margin_max_thickness = 0.0f64;
    let mut scallop_cells = 0;
    for (j, s) in rows.into_iter().enumerate() {
        if let Some((m, i)) = s.thickness
            && thickness.is_none_or(|(best, _)| m > best)
        {
            thickness = Some((m, (i, j)));
        }
        margin_max_thickness = margin_max_thickness.max(s.margin_thickness);
        scallop_cells += s.scallop_cells;
        if let Some((i, stock_z, part_z)) = s.outside {
            return Err(SimError::PartOutsideStock { at: zmap.cell_center(i, j), stock_z, part_z });
        }
        part_cells += s.part_cells;
        if let Some((m, i)) = s.max
            && max.is_none_or(|(best, _)| m > best)
        {
            max = Some((m, (i, j)));
        }
        if let Some(m) = s.min {
            min_deviation = Some(min_deviation.map_or(m, |b: f64| b.min(m)));
        }
        excess_volume += s.excess;
        gouges += s.gouges;
        worst.extend(s.worst);
    }
    if gouges > 0 {
        worst.sort_by(deepest_first);
        worst.truncate(keep);
        return Err(SimError::Gouge { count: gouges, tolerance: options.gouge_tolerance, worst });
    }
    let remaining_volume = zmap.volume();
    Ok(Verification {
        part_cells,
        max_scallop: max.map_or(0.0, |(m, _)| m),
        max_scallop_at: max.map(|(_, (i, j))| zmap.cell_center(i, j)),
        min_deviation: min_deviation.unwrap_or(0.0),
        max_thickness: thickness.map_or(0.0, |(m, _)| m),
        max_thickness_at: thickness.map(|(_, (i, j))| zmap.cell_center(i, j)),
        margin_max_thickness,
        scallop_cells,
        remaining_volume,
        removed_volume: zmap.initial_volume() - remaining_volume,
        excess_volume,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The distance transform equals the brute-force minimum over outside
    /// centres (and the virtual ring just outside the grid) on scattered masks.
    #[test]
    fn edge_distance_matches_brute_force() {
        let (nx, ny, cx, cy) = (23usize, 17usize, 0.3, 0.5);
        for seed in 1..6u64 {
            let mut state = seed;
            let inside: Vec<bool> = (0..nx * ny)
                .map(|_| {
                    state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
                    (state >> 33) % 7 != 0
                })
                .collect();
            let d2 = edge_distance2(&inside, nx, ny, cx, cy);
            let (nxi, nyi) = (nx as i64, ny as i64);
            for j in 0..nyi {
                for i in 0..nxi {
                    let mut best = f64::INFINITY;
                    for b in -1..=nyi {
                        for a in -1..=nxi {
                            let outside = a < 0 || b < 0 || a == nxi || b == nyi || !inside[(b * nxi + a) as usize];
                            if outside {
                                let (dx, dy) = ((a - i) as f64 * cx, (b - j) as f64 * cy);
                                best = best.min(dx * dx + dy * dy);
                            }
                        }
                    }
                    let got = d2[(j * nxi + i) as usize];
                    assert!((got - best).abs() <= 1e-9 * best.max(1.0), "({i}, {j}): {got} vs {best}");
                }
            }
        }
    }
}
