//! Look before computing, roughing (`scallop run --plan-only`, docs/job.md):
//! the levels of a roughing operation (`scallop_rough::level_heights`, the
//! planner's own) and the contour-parallel passes of each, counted on a grid
//! instead of offsetting polygons.
//!
//! The grid covers the stock grown by the tool radius (where the tool centre
//! may go) with cells of half the stepover (at most [`MAX_CELLS`] a side).
//! The part's height in each cell is its highest triangle over the cell's
//! centre (or vertex in it). At a level, the tool-centre region is the grid
//! less the cells within the tool radius plus the radial allowance of a cell
//! where the part stands above the level (less the axial allowance): a flat
//! end's envelope. The offset pattern cuts the region's boundary, then every
//! stepover inwards; each offset is as many closed passes as its boundary
//! has loops (its connected pieces plus their holes), until nothing is left.
//! Distances are chamfer distances (1 and sqrt 2 steps: at most 8.3 % over
//! the Euclidean distance, never under).

use std::collections::VecDeque;

use scallop_geom::Aabb3;
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_rough::{RoughSettings, level_heights};

use crate::{Estimate, FinishJob};

/// Cells of the grid along its longer side, at most.
pub const MAX_CELLS: usize = 256;

/// The estimate of a roughing operation of `job` with `settings` from
/// `stock`, on the planning mesh `mesh` (see the module documentation).
#[must_use]
pub fn estimate_rough(job: &FinishJob, settings: &RoughSettings, stock: &Aabb3, mesh: &TriMesh) -> Estimate {
    let r = job.cutter.radius();
    let ae = settings.stepover * 2.0 * r;
    let (x0, y0) = (stock.min.x - r, stock.min.y - r);
    let (w, h) = (stock.max.x - stock.min.x + 2.0 * r, stock.max.y - stock.min.y + 2.0 * r);
    #[allow(clippy::cast_precision_loss, reason = "a small constant")]
    let cell = (0.5 * ae).max(w.max(h) / MAX_CELLS as f64);
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "bounded by MAX_CELLS")]
    let (nx, ny) = ((w / cell).ceil().max(1.0) as usize, (h / cell).ceil().max(1.0) as usize);
    let grid = Grid { nx: nx + 2, ny: ny + 2 };
    let heights = part_heights(mesh, &grid, (x0 - cell, y0 - cell), cell);
    let levels = level_heights(&MeshIndex::build(mesh), stock, settings);
    let (mut passes, mut area) = (0usize, 0.0);
    for &z in &levels {
        // Cells the tool centre must keep away from, and their distance (mm).
        let part: Vec<bool> = heights.iter().map(|&p| p > z - settings.axial_allowance).collect();
        let clear = distances(&grid, &part);
        let reach = r + settings.radial_allowance;
        let region: Vec<bool> = (0..grid.len()).map(|k| !grid.frame(k) && clear[k] * cell > reach).collect();
        #[allow(clippy::cast_precision_loss, reason = "cell counts")]
        let cells = region.iter().filter(|&&c| c).count() as f64;
        area += cells * cell * cell;
        let inward = distances(&grid, &region.iter().map(|c| !c).collect::<Vec<bool>>());
        let mut k = 0.0;
        loop {
            let offset: Vec<bool> = (0..grid.len()).map(|i| region[i] && (inward[i] - 0.5) * cell >= k * ae).collect();
            let loops = grid.loops(&offset);
            if loops == 0 {
                break;
            }
            passes += loops;
            k += 1.0;
        }
    }
    let feed = job.machine[0] * 1000.0 / 60.0; // m/min -> mm/s
    Estimate {
        strategy: "rough",
        direction_deg: 0.0,
        direction_given: false,
        planes: 0,
        levels: levels.len(),
        passes,
        spacing_mm: [ae, ae],
        feed_length_mm: area / ae,
        time_at_feed_s: area / ae / feed,
    }
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

    /// Neighbours of `k` (4 or 8 of them).
    fn around(&self, k: usize, eight: bool) -> impl Iterator<Item = usize> + '_ {
        let (i, j) = ((k % self.nx).cast_signed(), (k / self.nx).cast_signed());
        let steps: &[(isize, isize)] = if eight {
            &[(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (1, -1), (-1, 1), (-1, -1)]
        } else {
            &[(1, 0), (-1, 0), (0, 1), (0, -1)]
        };
        steps.iter().filter_map(move |&(di, dj)| {
            let (a, b) = (i + di, j + dj);
            let inside = a >= 0 && b >= 0 && a < self.nx.cast_signed() && b < self.ny.cast_signed();
            inside.then(|| b.cast_unsigned() * self.nx + a.cast_unsigned())
        })
    }

    /// Connected pieces of the cells where `set == want` (4-connected for the
    /// set, 8 for its complement, so the two agree on what a hole is).
    fn pieces(&self, set: &[bool], want: bool) -> usize {
        let mut seen = vec![false; self.len()];
        let mut queue = VecDeque::new();
        let mut count = 0;
        for start in 0..self.len() {
            if seen[start] || set[start] != want {
                continue;
            }
            count += 1;
            seen[start] = true;
            queue.push_back(start);
            while let Some(k) = queue.pop_front() {
                for n in self.around(k, !want) {
                    if !seen[n] && set[n] == want {
                        seen[n] = true;
                        queue.push_back(n);
                    }
                }
            }
        }
        count
    }

    /// Boundary loops of `set` (which leaves the frame out): its pieces plus
    /// its holes (the pieces of the rest but the one around everything).
    fn loops(&self, set: &[bool]) -> usize {
        let pieces = self.pieces(set, true);
        if pieces == 0 { 0 } else { pieces + self.pieces(set, false) - 1 }
    }
}

/// Chamfer distance (in cells) of every cell to the nearest `from` cell.
fn distances(grid: &Grid, from: &[bool]) -> Vec<f64> {
    let (nx, ny) = (grid.nx, grid.ny);
    let mut d: Vec<f64> = from.iter().map(|&f| if f { 0.0 } else { f64::INFINITY }).collect();
    let diagonal = std::f64::consts::SQRT_2;
    let forward = [(-1isize, 0isize, 1.0), (0, -1, 1.0), (-1, -1, diagonal), (1, -1, diagonal)];
    let backward = [(1isize, 0isize, 1.0), (0, 1, 1.0), (1, 1, diagonal), (-1, 1, diagonal)];
    let mut pass = |order: &mut dyn Iterator<Item = usize>, steps: &[(isize, isize, f64)]| {
        for k in order {
            let (i, j) = ((k % nx).cast_signed(), (k / nx).cast_signed());
            for &(di, dj, w) in steps {
                let (a, b) = (i + di, j + dj);
                if a >= 0 && b >= 0 && a < nx.cast_signed() && b < ny.cast_signed() {
                    let v = d[b.cast_unsigned() * nx + a.cast_unsigned()] + w;
                    if v < d[k] {
                        d[k] = v;
                    }
                }
            }
        }
    };
    pass(&mut (0..nx * ny), &forward);
    pass(&mut (0..nx * ny).rev(), &backward);
    d
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

    #[test]
    fn chamfer_distances_are_within_8_3_percent_of_euclidean() {
        let grid = Grid { nx: 61, ny: 61 };
        let centre = 30 * 61 + 30;
        let from: Vec<bool> = (0..grid.len()).map(|k| k == centre).collect();
        let d = distances(&grid, &from);
        for (k, v) in d.iter().enumerate() {
            #[allow(clippy::cast_precision_loss, reason = "small grids")]
            let e = ((k % 61) as f64 - 30.0).hypot((k / 61) as f64 - 30.0);
            assert!(*v >= e - 1e-12 && *v <= 1.0825 * e + 1e-12, "cell {k}: {v} vs {e}");
        }
    }
}
