//! Look before computing, roughing (`scallop run --plan-only`, docs/job.md):
//! the levels of a roughing operation (`scallop_rough::level_heights`, the
//! planner's own) and the contour-parallel passes of each, counted on a grid
//! instead of offsetting polygons; a rest operation (one after another
//! roughing operation) on the stock the earlier ones left, by the planner's
//! own rule (`scallop_rough::limit_to_material`) on the grid.
//!
//! The grid covers the stock grown by the largest tool radius (where a tool
//! centre may go) with cells of half the smallest stepover (at most
//! [`MAX_CELLS`] a side), or of the stock simulation's resolution when a
//! roughing operation follows another (at most [`MAX_REST_CELLS`] a side:
//! the leftovers must be resolved finer than the rule's margin, a cell's
//! diagonal of the simulation, or the allowance on every wall would read as
//! material to remove). The part's height in each cell is its highest
//! triangle over the cell's centre (or vertex in it). At a level, the
//! tool-centre region is the grid less the cells within the tool radius plus
//! the radial allowance of a cell where the part stands above the level
//! (less the axial allowance): a flat end's envelope. The offset pattern cuts
//! the region's boundary, then every stepover inwards; each offset is as many
//! closed passes as its boundary has loops (its connected pieces plus their
//! holes), until nothing is left. Distances are exact Euclidean distances
//! between cell centres (Felzenszwalb and Huttenlocher 2012, "Distance
//! Transforms of Sampled Functions", Theory of Computing 8, section 2).
//!
//! Leftovers. The model keeps the material top of every cell (the stock box's
//! top at first, no material outside the box). Each roughing operation cuts,
//! at each of its levels `z`, every cell within its tool radius of the
//! level's region down to `z` (the offsets at a stepover up to the radius
//! sweep the whole region grown by the radius, docs/roughing.md). A later
//! operation's level keeps, as the planner does, only the centres within its
//! radius of material above `z` (by `MIN_CHIP`) that lies within the radius
//! less the margin of the region; the margin is the simulation cell's
//! diagonal plus `MIN_CHIP`, as in the planner. Finishing operations are not
//! modelled in the leftovers.

use rayon::prelude::*;
use scallop_geom::Aabb3;
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_rough::{RoughSettings, level_heights, tol as rtol};

use crate::{Estimate, FinishJob};

/// Cells of the grid along its longer side, at most (roughing alone).
pub const MAX_CELLS: usize = 256;

/// Cells of the grid along its longer side, at most, when a roughing
/// operation follows another (the leftovers are read).
pub const MAX_REST_CELLS: usize = 512;

/// The estimate's model of a job's roughing: the grid, the part's heights on
/// it and the material the operations estimated so far left (module docs).
pub(crate) struct RoughModel {
    grid: Grid,
    cell: f64,
    heights: Vec<f64>,
    /// Material top per cell (`-inf`: none).
    tops: Vec<f64>,
    /// Whether no operation has cut yet (the planner then plans from the box).
    whole: bool,
    /// The rest rule's margin (mm): the simulation cell's diagonal plus `MIN_CHIP`.
    margin: f64,
}

impl RoughModel {
    /// The model of the stock box `stock` around `mesh` for tools up to
    /// `radius`, with cells of `cell` mm at the least (grown to keep at most
    /// `max_cells` a side); `sim_resolution` sizes the rest rule's margin.
    #[must_use]
    pub(crate) fn new(
        mesh: &TriMesh,
        stock: &Aabb3,
        radius: f64,
        (cell, max_cells): (f64, usize),
        sim_resolution: f64,
    ) -> Self {
        let (w, h) = (stock.max.x - stock.min.x + 2.0 * radius, stock.max.y - stock.min.y + 2.0 * radius);
        #[allow(clippy::cast_precision_loss, reason = "a small constant")]
        let cell = cell.max(w.max(h) / max_cells as f64);
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "bounded by max_cells")]
        let (nx, ny) = ((w / cell).ceil().max(1.0) as usize, (h / cell).ceil().max(1.0) as usize);
        let grid = Grid { nx: nx + 2, ny: ny + 2 };
        let corner = (stock.min.x - radius - cell, stock.min.y - radius - cell);
        let heights = part_heights(mesh, &grid, corner, cell);
        let tops = (0..grid.len())
            .map(|k| {
                let (x, y) = grid.centre(k, corner, cell);
                let inside = (stock.min.x..=stock.max.x).contains(&x) && (stock.min.y..=stock.max.y).contains(&y);
                if inside { stock.max.z } else { f64::NEG_INFINITY }
            })
            .collect();
        let margin = sim_resolution.hypot(sim_resolution) + rtol::MIN_CHIP;
        RoughModel { grid, cell, heights, tops, whole: true, margin }
    }

    /// The estimate of a roughing operation of `job` with `settings` from
    /// `stock` on the part indexed by `index` (levels by the planner's
    /// `level_heights`); the material it cuts is taken off the model when
    /// `later` (a roughing operation follows that reads it).
    pub(crate) fn estimate(
        &mut self,
        job: &FinishJob,
        (settings, later): (&RoughSettings, bool),
        stock: &Aabb3,
        index: &MeshIndex,
    ) -> Estimate {
        let r = job.cutter.radius();
        let ae = settings.stepover * 2.0 * r;
        let cell = self.cell;
        let zs = level_heights(index, stock, settings);
        // The part above a level is the cells of heights from the lowest one
        // over the level (less the axial allowance): the levels between two
        // heights share their region, computed once.
        let key = |z: f64| {
            let floor = z - settings.axial_allowance;
            self.heights.iter().copied().filter(|&h| h > floor).fold(f64::INFINITY, f64::min)
        };
        let keys: Vec<f64> = zs.iter().map(|&z| key(z)).collect();
        let mut distinct = keys.clone();
        distinct.sort_by(f64::total_cmp);
        distinct.dedup();
        let regions: Vec<Vec<bool>> =
            distinct.par_iter().map(|&h| self.region(h, r + settings.radial_allowance)).collect();
        let region_of = |h: f64| &regions[distinct.partition_point(|&d| d < h)];
        let level = |z: f64, region: &[bool]| {
            let limited;
            let region = if self.whole {
                region
            } else {
                limited = self.limit_to_material(region, z, r);
                &limited
            };
            // The planner leaves out the passes (and the stretches of them)
            // that never come within R of the material (docs/roughing.md,
            // "Air"): the passes are counted on the cells that do.
            // (From the whole box, `z` is the region's key, not a level: the
            // material is the box.)
            let material: Vec<bool> =
                self.tops.iter().map(|&t| if self.whole { t.is_finite() } else { t > z + rtol::MIN_CHIP }).collect();
            let reach = within(&self.grid, &material, (r / cell - 1.0).max(0.0));
            let (count, cells) = offset_passes(&self.grid, region, &reach, ae / cell);
            // The offsets sweep the region grown by the tool radius down to z.
            let swept = if later { within(&self.grid, region, r / cell) } else { Vec::new() };
            (count > 0).then_some((count, cells, swept))
        };
        // From the whole box a level's passes depend on its region only.
        let shared: Vec<Option<(usize, usize, Vec<bool>)>> = if self.whole {
            distinct.par_iter().zip(&regions).map(|(&h, region)| level(h, region)).collect()
        } else {
            Vec::new()
        };
        let cut: Vec<Option<(usize, usize, Vec<bool>)>> = if self.whole {
            keys.iter().map(|&h| shared[distinct.partition_point(|&d| d < h)].clone()).collect()
        } else {
            zs.par_iter().zip(&keys).map(|(&z, &h)| level(z, region_of(h))).collect()
        };
        let (mut passes, mut area, mut levels) = (0usize, 0.0, 0usize);
        for (z, level) in zs.iter().zip(cut) {
            let Some((count, cells, swept)) = level else { continue };
            levels += 1;
            passes += count;
            #[allow(clippy::cast_precision_loss, reason = "cell counts")]
            let cells = cells as f64;
            area += cells * cell * cell;
            for (top, _) in self.tops.iter_mut().zip(&swept).filter(|(_, s)| **s) {
                *top = top.min(*z);
            }
        }
        self.whole = false;
        let feed = job.machine[0] * 1000.0 / 60.0; // m/min -> mm/s
        Estimate {
            strategy: "rough",
            direction_deg: 0.0,
            direction_given: false,
            planes: 0,
            levels,
            passes,
            spacing_mm: [ae, ae],
            feed_length_mm: area / ae,
            time_at_feed_s: area / ae / feed,
        }
    }

    /// The tool-centre region of a level (module docs): the cells farther
    /// than `reach` from the part's cells of heights `lowest` and up.
    fn region(&self, lowest: f64, reach: f64) -> Vec<bool> {
        let part: Vec<bool> = self.heights.iter().map(|&p| p >= lowest).collect();
        let clear = distances(&self.grid, &part);
        (0..self.grid.len()).map(|k| !self.grid.frame(k) && (clear[k] - 0.5) * self.cell > reach).collect()
    }

    /// `scallop_rough::limit_to_material` on the grid: the cells of `region`
    /// within `r` of the material above `z` (by `MIN_CHIP`) that lies within
    /// `r` less the margin of the region.
    fn limit_to_material(&self, region: &[bool], z: f64, r: f64) -> Vec<bool> {
        let cell = self.cell;
        let near = within(&self.grid, region, (r - self.margin).max(0.0) / cell);
        let removable: Vec<bool> = (0..self.grid.len()).map(|k| near[k] && self.tops[k] > z + rtol::MIN_CHIP).collect();
        let to_material = within(&self.grid, &removable, r / cell);
        region.iter().zip(&to_material).map(|(&inside, &near)| inside && near).collect()
    }
}

/// The passes of the offset pattern in `region` at a stepover of `step`
/// cells (module docs), on the cells of `reach` only, and the region's
/// cells, counted in the region's box.
fn offset_passes(grid: &Grid, region: &[bool], reach: &[bool], step: f64) -> (usize, usize) {
    let Some((i0, j0, i1, j1)) = grid.bounds(region) else { return (0, 0) };
    // The box with a frame of one empty cell.
    let sub = Grid { nx: i1 - i0 + 3, ny: j1 - j0 + 3 };
    let inside: Vec<bool> = (0..sub.len())
        .map(|k| {
            let (i, j) = (k % sub.nx, k / sub.nx);
            !sub.frame(k) && region[(j + j0 - 1) * grid.nx + i + i0 - 1]
        })
        .collect();
    let at = |k: usize| (k / sub.nx + j0 - 1) * grid.nx + k % sub.nx + i0 - 1;
    let inward = distances(&sub, &inside.iter().map(|c| !c).collect::<Vec<bool>>());
    let mut passes = 0;
    let mut k = 0.0;
    loop {
        let offset: Vec<bool> = (0..sub.len()).map(|i| inside[i] && inward[i] - 0.5 >= k * step).collect();
        if sub.loops(&offset) == 0 {
            break;
        }
        // The offset's boundary cells within reach: each connected stretch
        // is a pass (a whole ring, or the stretch of one that reaches).
        let edge = |i: usize| {
            let (x, y) = (i % sub.nx, i / sub.nx);
            [(x + 1, y), (x - 1, y), (x, y + 1), (x, y - 1)].iter().any(|&(a, b)| !offset[b * sub.nx + a])
        };
        let reached: Vec<bool> =
            (0..sub.len()).map(|i| offset[i] && !sub.frame(i) && edge(i) && reach[at(i)]).collect();
        passes += components(&sub, &reached);
        k += 1.0;
    }
    (passes, inside.iter().filter(|&&c| c).count())
}

/// The connected pieces of the cells `set` of `grid` (8-neighbours; the
/// frame holds none).
fn components(grid: &Grid, set: &[bool]) -> usize {
    let mut seen = vec![false; grid.len()];
    let mut count = 0;
    let mut stack = Vec::new();
    for k in 0..grid.len() {
        if !set[k] || seen[k] {
            continue;
        }
        count += 1;
        seen[k] = true;
        stack.push(k);
        while let Some(c) = stack.pop() {
            let (x, y) = (c % grid.nx, c / grid.nx);
            for (dx, dy) in [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
                let (a, b) = (x.wrapping_add_signed(dx), y.wrapping_add_signed(dy));
                if a < grid.nx && b < grid.ny {
                    let n = b * grid.nx + a;
                    if set[n] && !seen[n] {
                        seen[n] = true;
                        stack.push(n);
                    }
                }
            }
        }
    }
    count
}

/// A grid of `nx * ny` cells, x fastest, whose outer ring is the frame (outside).
struct Grid {
    nx: usize,
    ny: usize,
}

impl Grid {
    fn len(&self) -> usize {
        self.nx * self.ny
    }

    fn frame(&self, k: usize) -> bool {
        let (i, j) = (k % self.nx, k / self.nx);
        i == 0 || j == 0 || i + 1 == self.nx || j + 1 == self.ny
    }

    #[allow(clippy::cast_precision_loss, reason = "cell indices")]
    fn centre(&self, k: usize, (x0, y0): (f64, f64), cell: f64) -> (f64, f64) {
        (x0 + ((k % self.nx) as f64 + 0.5) * cell, y0 + ((k / self.nx) as f64 + 0.5) * cell)
    }

    /// The box of the cells of `set`: (i0, j0, i1, j1), inclusive.
    fn bounds(&self, set: &[bool]) -> Option<(usize, usize, usize, usize)> {
        let mut b: Option<(usize, usize, usize, usize)> = None;
        for k in (0..self.len()).filter(|&k| set[k]) {
            let (i, j) = (k % self.nx, k / self.nx);
            b = Some(b.map_or((i, j, i, j), |(a, c, e, f)| (a.min(i), c.min(j), e.max(i), f.max(j))));
        }
        b
    }

    /// The 4-connected pieces of `set` (which leaves the frame out).
    fn pieces(&self, set: &[bool]) -> usize {
        let mut seen = vec![false; self.len()];
        let mut stack = Vec::new();
        let mut count = 0;
        for start in 0..self.len() {
            if seen[start] || !set[start] {
                continue;
            }
            count += 1;
            seen[start] = true;
            stack.push(start);
            while let Some(k) = stack.pop() {
                // Off the frame: the four neighbours are in the grid.
                for n in [k + 1, k - 1, k + self.nx, k - self.nx] {
                    if set[n] && !seen[n] {
                        seen[n] = true;
                        stack.push(n);
                    }
                }
            }
        }
        count
    }

    /// The Euler number of `set` (4-connected; its complement 8-connected):
    /// pieces less holes, from the counts of 2 x 2 windows with one set
    /// cell, three, or two on a diagonal (Gray 1971, "Local properties of
    /// binary images in two dimensions", IEEE Trans. Computers C-20(5)).
    fn euler(&self, set: &[bool]) -> isize {
        let (mut one, mut three, mut diagonal) = (0isize, 0isize, 0isize);
        for j in 0..self.ny - 1 {
            for i in 0..self.nx - 1 {
                let k = j * self.nx + i;
                let [a, b, c, d] = [set[k], set[k + 1], set[k + self.nx], set[k + self.nx + 1]];
                match u8::from(a) + u8::from(b) + u8::from(c) + u8::from(d) {
                    1 => one += 1,
                    3 => three += 1,
                    2 if a == d => diagonal += 1,
                    _ => {}
                }
            }
        }
        (one - three + 2 * diagonal) / 4
    }

    /// Boundary loops of `set` (which leaves the frame out): its pieces plus
    /// its holes, `2 pieces - euler`.
    fn loops(&self, set: &[bool]) -> usize {
        (2 * self.pieces(set).cast_signed() - self.euler(set)).max(0).cast_unsigned()
    }
}

/// The cells whose centre lies within `reach` cells of a `from` cell's
/// centre: [`distances`] on the box of `from` grown by `reach`.
fn within(grid: &Grid, from: &[bool], reach: f64) -> Vec<bool> {
    let mut out = vec![false; grid.len()];
    let Some((i0, j0, i1, j1)) = grid.bounds(from) else { return out };
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a grid's size at most")]
    let grow = (reach.max(0.0).ceil() as usize).min(grid.nx + grid.ny) + 1;
    let (a0, b0) = (i0.saturating_sub(grow), j0.saturating_sub(grow));
    let (a1, b1) = ((i1 + grow).min(grid.nx - 1), (j1 + grow).min(grid.ny - 1));
    let sub = Grid { nx: a1 - a0 + 1, ny: b1 - b0 + 1 };
    let at = |k: usize| (k / sub.nx + b0) * grid.nx + k % sub.nx + a0;
    let set: Vec<bool> = (0..sub.len()).map(|k| from[at(k)]).collect();
    for (k, d) in distances(&sub, &set).into_iter().enumerate() {
        out[at(k)] = d <= reach;
    }
    out
}

/// Euclidean distance (in cells) of every cell's centre to the nearest
/// `from` cell's centre (`inf` when there is none): the exact transform of
/// Felzenszwalb and Huttenlocher (2012, section 2), along the rows and then
/// along the columns, each line in parallel.
fn distances(grid: &Grid, from: &[bool]) -> Vec<f64> {
    let (nx, ny) = (grid.nx, grid.ny);
    let mut d: Vec<f64> = from.iter().map(|&f| if f { 0.0 } else { f64::INFINITY }).collect();
    if !from.contains(&true) {
        return d;
    }
    d.par_chunks_mut(nx).for_each_init(Scratch::default, |scratch, row| squared_1d(row, scratch));
    let mut t = vec![0.0; nx * ny];
    for (j, row) in d.chunks(nx).enumerate() {
        for (i, v) in row.iter().enumerate() {
            t[i * ny + j] = *v;
        }
    }
    t.par_chunks_mut(ny).for_each_init(Scratch::default, |scratch, column| squared_1d(column, scratch));
    for (i, column) in t.chunks(ny).enumerate() {
        for (j, v) in column.iter().enumerate() {
            d[j * nx + i] = v.sqrt();
        }
    }
    d
}

/// Buffers of [`squared_1d`], kept from line to line.
#[derive(Default)]
struct Scratch {
    f: Vec<f64>,
    v: Vec<usize>,
    z: Vec<f64>,
}

/// The lower envelope of the parabolas `(q - p)^2 + f(p)` over `line`, in
/// place (the 1-D squared distance transform; `inf` entries are no parabola).
fn squared_1d(line: &mut [f64], scratch: &mut Scratch) {
    if line.iter().all(|x| x.is_infinite()) {
        return;
    }
    let Scratch { f, v, z } = scratch;
    f.clear();
    f.extend_from_slice(line);
    v.clear();
    z.clear();
    #[allow(clippy::cast_precision_loss, reason = "cell indices")]
    let meet = |p: usize, q: usize| {
        let (pf, qf) = (p as f64, q as f64);
        ((f[q] + qf * qf) - (f[p] + pf * pf)) / (2.0 * (qf - pf))
    };
    // The parabolas of the envelope and where each starts to be lowest.
    for q in (0..f.len()).filter(|&q| f[q].is_finite()) {
        if v.is_empty() {
            v.push(q);
            z.push(f64::NEG_INFINITY);
            continue;
        }
        let mut s = meet(v[v.len() - 1], q);
        while s <= z[z.len() - 1] {
            v.pop();
            z.pop();
            s = meet(v[v.len() - 1], q);
        }
        v.push(q);
        z.push(s);
    }
    let mut k = 0;
    for (q, out) in line.iter_mut().enumerate() {
        #[allow(clippy::cast_precision_loss, reason = "cell indices")]
        let qf = q as f64;
        while k + 1 < v.len() && z[k + 1] < qf {
            k += 1;
        }
        #[allow(clippy::cast_precision_loss, reason = "cell indices")]
        let dq = qf - v[k] as f64;
        *out = dq * dq + f[v[k]];
    }
}

/// The part's height over each cell (`-inf` where none): the highest
/// triangle over the cell's centre, or vertex in the cell.
fn part_heights(mesh: &TriMesh, grid: &Grid, (x0, y0): (f64, f64), cell: f64) -> Vec<f64> {
    let mut out = vec![f64::NEG_INFINITY; grid.len()];
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "clamped cell indices")]
    let at = |x: f64, n: usize, o: f64| (((x - o) / cell).floor().max(0.0) as usize).min(n - 1);
    for t in 0..mesh.triangles().len() {
        let p = mesh.triangle(t);
        for q in &p {
            let k = at(q.y, grid.ny, y0) * grid.nx + at(q.x, grid.nx, x0);
            out[k] = out[k].max(q.z);
        }
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let det = e1.x * e2.y - e1.y * e2.x;
        if det.abs() < 1e-12 {
            continue;
        }
        let lo = (p[0].x.min(p[1].x).min(p[2].x), p[0].y.min(p[1].y).min(p[2].y));
        let hi = (p[0].x.max(p[1].x).max(p[2].x), p[0].y.max(p[1].y).max(p[2].y));
        for j in at(lo.1, grid.ny, y0)..=at(hi.1, grid.ny, y0) {
            for i in at(lo.0, grid.nx, x0)..=at(hi.0, grid.nx, x0) {
                #[allow(clippy::cast_precision_loss, reason = "cell indices")]
                let (x, y) = (x0 + (i as f64 + 0.5) * cell - p[0].x, y0 + (j as f64 + 0.5) * cell - p[0].y);
                let (u, v) = ((x * e2.y - y * e2.x) / det, (e1.x * y - e1.y * x) / det);
                if u >= 0.0 && v >= 0.0 && u + v <= 1.0 {
                    let k = j * grid.nx + i;
                    out[k] = out[k].max(p[0].z + u * e1.z + v * e2.z);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid of `n x n` cells (frame included) with the cells at distance
    /// `inner..outer` (in cells) from the centre set.
    fn ring(n: usize, inner: f64, outer: f64) -> (Grid, Vec<bool>) {
        let grid = Grid { nx: n, ny: n };
        #[allow(clippy::cast_precision_loss, reason = "small grids")]
        let c = (n as f64 - 1.0) / 2.0;
        #[allow(clippy::cast_precision_loss, reason = "small grids")]
        let set = (0..n * n)
            .map(|k| {
                let d = ((k % n) as f64 - c).hypot((k / n) as f64 - c);
                !grid.frame(k) && d >= inner && d < outer
            })
            .collect();
        (grid, set)
    }

    #[test]
    fn a_disc_has_one_loop_an_annulus_two_and_nothing_none() {
        let (grid, disc) = ring(41, 0.0, 15.0);
        assert_eq!(grid.loops(&disc), 1);
        let (grid, annulus) = ring(41, 6.0, 15.0);
        assert_eq!(grid.loops(&annulus), 2);
        assert_eq!(grid.loops(&vec![false; grid.len()]), 0);
    }

    /// The transform against brute force on scattered sets (a seeded
    /// generator): exact Euclidean distances between cell centres.
    #[test]
    fn distances_are_the_brute_force_euclidean_distances() {
        let mut rng = scallop_geom::rng::SplitMix64::new(22);
        for n in [1usize, 7, 23] {
            let grid = Grid { nx: n + 3, ny: n };
            let from: Vec<bool> = (0..grid.len()).map(|_| rng.unit() < 0.05).collect();
            let d = distances(&grid, &from);
            for (k, v) in d.iter().enumerate() {
                let (i, j) = (k % grid.nx, k / grid.nx);
                #[allow(clippy::cast_precision_loss, reason = "small grids")]
                let best = (0..grid.len())
                    .filter(|&s| from[s])
                    .map(|s| ((s % grid.nx) as f64 - i as f64).hypot((s / grid.nx) as f64 - j as f64))
                    .fold(f64::INFINITY, f64::min);
                let same = if best.is_finite() { (v - best).abs() <= 1e-9 * best } else { v.is_infinite() };
                assert!(same, "cell {k}: {v} vs {best}");
            }
        }
    }

    /// Two triangles over the rectangle `[x0, x1] x [y0, y1]` at height `z`.
    fn quad(x0: f64, y0: f64, x1: f64, y1: f64, z: f64) -> [[scallop_geom::Point3; 3]; 2] {
        let p = |x, y| scallop_geom::Point3::new(x, y, z);
        [[p(x0, y0), p(x1, y0), p(x1, y1)], [p(x0, y0), p(x1, y1), p(x0, y1)]]
    }

    fn flat_job(radius: f64) -> FinishJob {
        let shape = scallop_cutter::CutterShape::Flat { radius };
        let cutter = scallop_cutter::Cutter::new(shape, 30.0).expect("a valid cutter");
        FinishJob { cutter, ..FinishJob::choi_demo() }
    }

    fn settings(stepdown: f64, stepover: f64, allowance: f64) -> RoughSettings {
        RoughSettings {
            stepdown,
            stepover,
            radial_allowance: allowance,
            axial_allowance: allowance,
            pattern: scallop_rough::Pattern::Offset,
            direction: scallop_rough::Direction::Climb,
        }
    }

    /// Over a part below the stock (a floor at the stock's bottom), every
    /// level's region is the stock grown by the tool radius, a W x H
    /// rectangle: its offsets at ae are non-empty while k ae < H / 2, so each
    /// level makes ceil(H / (2 ae)) passes (the grid may add or drop one).
    #[test]
    fn a_rectangle_level_makes_its_offsets_one_pass_each() {
        let (mesh, _) = TriMesh::from_soup(&quad(0.0, 0.0, 40.0, 20.0, 0.0)).expect("a floor");
        let stock =
            Aabb3 { min: scallop_geom::Point3::new(0.0, 0.0, 0.0), max: scallop_geom::Point3::new(40.0, 20.0, 6.0) };
        let (r, set) = (3.0, settings(2.0, 0.3, 0.0));
        let ae = set.stepover * 2.0 * r;
        let mut model = RoughModel::new(&mesh, &stock, r, (0.25 * ae, MAX_CELLS), 0.1);
        let index = MeshIndex::build(&mesh);
        let e = model.estimate(&flat_job(r), (&set, false), &stock, &index);
        let levels = level_heights(&index, &stock, &set).len();
        assert_eq!(e.levels, levels);
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small count")]
        let per_level = ((20.0 + 2.0 * r) / (2.0 * ae)).ceil() as usize;
        assert!(e.passes.abs_diff(levels * per_level) <= levels, "{} passes, {levels} x {per_level}", e.passes);
    }

    /// A rest operation after a roughing operation finds less to cut than the
    /// same operation from the whole box (metamorphic): on a block with a
    /// square-cornered pocket, a 10 mm end mill leaves the corners, a 4 mm
    /// one after it cuts only there.
    #[test]
    fn rest_after_roughing_estimates_fewer_passes_than_from_the_box() {
        let soup = [
            quad(0.0, 0.0, 60.0, 8.0, 15.0),
            quad(0.0, 32.0, 60.0, 40.0, 15.0),
            quad(0.0, 8.0, 10.0, 32.0, 15.0),
            quad(50.0, 8.0, 60.0, 32.0, 15.0),
            quad(10.0, 8.0, 50.0, 32.0, 5.0),
        ]
        .concat();
        let (mesh, _) = TriMesh::from_soup(&soup).expect("a pocket");
        let stock =
            Aabb3 { min: scallop_geom::Point3::new(0.0, 0.0, 0.0), max: scallop_geom::Point3::new(60.0, 40.0, 16.0) };
        let index = MeshIndex::build(&mesh);
        let (rough, rest) = (settings(2.5, 0.3, 0.3), settings(1.5, 0.25, 0.3));
        let model = || RoughModel::new(&mesh, &stock, 5.0, (0.1, MAX_REST_CELLS), 0.1);
        let mut after = model();
        let first = after.estimate(&flat_job(5.0), (&rough, true), &stock, &index);
        let limited = after.estimate(&flat_job(2.0), (&rest, false), &stock, &index);
        let whole = model().estimate(&flat_job(2.0), (&rest, false), &stock, &index);
        assert!(first.passes > 0 && limited.passes > 0, "{first:?} {limited:?}");
        assert!(limited.passes < whole.passes, "rest {} vs from the box {}", limited.passes, whole.passes);
        assert!(limited.feed_length_mm < whole.feed_length_mm);
    }
}
