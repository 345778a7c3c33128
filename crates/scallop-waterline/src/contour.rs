//! Marching squares on the exact drop-cutter samples: grid-edge crossings,
//! linked cell by cell into closed, oriented chains.
//!
//! Cell (i, j) has corners `c0 = (i, j)`, `c1 = (i+1, j)`, `c2 = (i+1, j+1)`,
//! `c3 = (i, j+1)` (counter-clockwise) and edge `k` from `ck` to `c(k+1)`.
//! Walking the cell boundary counter-clockwise, a crossing is an *exit* where
//! the walk leaves the inside (`ck` in, `c(k+1)` out) and an *entry* where it
//! comes back. With the inside on the left of the contour, the contour runs
//! from the exit to an entry. One exit and one entry: they are linked. A
//! saddle (two opposite corners in, two out) has two of each: if its centre
//! is inside, the two inside corners are joined and each exit links to the
//! next edge counter-clockwise (`k + 1`); otherwise each inside corner is cut
//! off alone and each exit links to the previous edge (`k + 3`).
//! Every crossing edge is an exit of one of its two cells and an entry of the
//! other (the two cells walk it in opposite directions), so the links form a
//! permutation of the crossings: disjoint closed chains.
//!
//! An edge with both ends inside may still hold a gap (a sliver of outside
//! narrower than the step): where no single triangle certifies it
//! (`WaterlineGrid::cover_of`), it is walked (`refine::Local::gaps`) and holds
//! two crossings per gap. A cell then has several exits: walking its boundary
//! the crossings alternate exit, entry. A cell with one exit links it to its
//! entry; a cell with more (a saddle, a gap next to another outside stretch)
//! is linked by subdivision (`cell.rs`), so that no link runs across a thin
//! feature inside the cell.

use rayon::prelude::*;
use scallop_geom::Point2;

use crate::cell::{Cell, Resolver, simple_links};
use crate::refine::Probe;
use crate::{Level, WaterlineGrid};

/// The crossings of one grid edge, in increasing x (horizontal) or y
/// (vertical).
struct EdgeCrossings {
    id: usize,
    points: Vec<Point2>,
    /// Number of the first crossing in the flat list of all crossings.
    offset: usize,
}

/// The links (exit, entry) of one cell and the crossings it adds inside.
type CellLinks = (Vec<(usize, usize)>, Vec<Point2>);

/// Grid edge numbering: horizontal edges first, then vertical ones.
struct Numbering {
    nx: usize,
    ny: usize,
}

impl Numbering {
    fn h(&self, i: usize, j: usize) -> usize {
        j * (self.nx - 1) + i
    }
    fn v(&self, i: usize, j: usize) -> usize {
        (self.nx - 1) * self.ny + j * self.nx + i
    }
    /// The two ends (sample indices) of an edge.
    fn ends(&self, id: usize) -> ([usize; 2], [usize; 2]) {
        let horizontal = (self.nx - 1) * self.ny;
        if id < horizontal {
            let (i, j) = (id % (self.nx - 1), id / (self.nx - 1));
            ([i, j], [i + 1, j])
        } else {
            let k = id - horizontal;
            let (i, j) = (k % self.nx, k / self.nx);
            ([i, j], [i, j + 1])
        }
    }
    /// The cells on either side of an edge that lie in the grid.
    fn cells(&self, id: usize) -> impl Iterator<Item = [usize; 2]> {
        let horizontal = (self.nx - 1) * self.ny;
        let ([i, j], _) = self.ends(id);
        let (nx, ny) = (self.nx, self.ny);
        let pair = if id < horizontal {
            [Some([i, j]).filter(|_| j + 1 < ny), j.checked_sub(1).map(|jm| [i, jm])]
        } else {
            [Some([i, j]).filter(|_| i + 1 < nx), i.checked_sub(1).map(|im| [im, j])]
        };
        pair.into_iter().flatten()
    }
}

/// The crossings of every edge that holds some, in increasing edge number:
/// one per edge with ends on different sides, two per gap on an edge with
/// both ends inside that no triangle certifies.
fn edge_crossings(grid: &WaterlineGrid<'_>, level: &Level, probe: &Probe<'_>) -> Vec<EdgeCrossings> {
    let (nx, ny) = (grid.nx, grid.ny);
    let num = Numbering { nx, ny };
    // (edge, first end inside, crossing edge (else a gap candidate)). Every
    // edge from a sample lies in its block's square: only the blocks where the
    // contour may pass hold crossings or gaps.
    let mut todo: Vec<(usize, bool, bool)> = Vec::new();
    // Runs [start, end) of `todo` from one block, with the block's square:
    // one candidate list serves the block's edges (the heights are the same).
    let mut runs: Vec<(usize, usize, Point2, Point2)> = Vec::new();
    for b in grid.mixed_blocks(level) {
        let ([i0, i1], [j0, j1]) = grid.block_range(b);
        let start = todo.len();
        for j in j0..j1 {
            for i in i0..i1 {
                let a = grid.inside(level, i, j);
                for (dir, [ib, jb]) in [(0, [i + 1, j]), (1, [i, j + 1])] {
                    if ib >= nx || jb >= ny {
                        continue;
                    }
                    let id = if dir == 0 { num.h(i, j) } else { num.v(i, j) };
                    if a != grid.inside(level, ib, jb) {
                        todo.push((id, a, true));
                    } else if a && grid.cover(level, [i, j], dir) <= level.z {
                        todo.push((id, true, false));
                    }
                }
            }
        }
        if todo.len() > start {
            let (lo, hi) = (grid.point(i0, j0), grid.point(i1.min(nx - 1), j1.min(ny - 1)));
            runs.push((start, todo.len(), lo, hi));
        }
    }
    let z = probe.z;
    let height = |k: usize| grid.sample(k % nx, k / nx).0;
    let slot_at = |k: usize| grid.sample(k % nx, k / nx).1;
    let floored = |k: usize| (height(k) - z).max(-grid.step);
    let mut found: Vec<(usize, Vec<Point2>)> = runs
        .par_iter()
        .flat_map_iter(|&(start, end, lo, hi)| {
            let local = probe.local(lo, hi);
            todo[start..end]
                .iter()
                .map(|&(id, first_inside, crossing)| {
                    let ([ia, ja], [ib, jb]) = num.ends(id);
                    let (ka, kb) = (ja * nx + ia, jb * nx + ib);
                    let (a, b) = (grid.point(ia, ja), grid.point(ib, jb));
                    if !crossing {
                        return (id, local.gaps(a, slot_at(ka) as usize, b, floored(kb)));
                    }
                    // Floored as `Probe::height` floors them, so the secant sees one function.
                    let slot = |k: usize| (slot_at(k) != u32::MAX).then_some(slot_at(k) as usize);
                    let p = if first_inside {
                        local.bisect_heights(a, floored(ka), slot(ka), b, floored(kb))
                    } else {
                        local.bisect_heights(b, floored(kb), slot(kb), a, floored(ka))
                    };
                    (id, vec![p])
                })
                .collect::<Vec<_>>()
        })
        .collect();
    found.sort_unstable_by_key(|f| f.0);
    let mut offset = 0;
    let mut out = Vec::new();
    for (id, points) in found {
        if !points.is_empty() {
            let n = points.len();
            out.push(EdgeCrossings { id, offset, points });
            offset += n;
        }
    }
    out
}

/// The chains of crossing points of `grid` at the probe's height, each
/// starting at its smallest crossing (edge number, then along the edge),
/// listed in that order.
pub(crate) fn trace(grid: &WaterlineGrid<'_>, level: &Level, probe: &Probe<'_>) -> Vec<Vec<Point2>> {
    let (nx, ny) = (grid.nx, grid.ny);
    let edges = edge_crossings(grid, level, probe);
    let Some(last) = edges.last() else { return Vec::new() };
    let total = last.offset + last.points.len();
    let num = Numbering { nx, ny };
    let mut cells: Vec<[usize; 2]> = edges.iter().flat_map(|e| num.cells(e.id)).collect();
    cells.sort_unstable_by_key(|c| (c[1], c[0]));
    cells.dedup();
    let find = |id: usize| edges.binary_search_by_key(&id, |e| e.id).ok().map(|k| &edges[k]);
    let points: Vec<Point2> = edges.iter().flat_map(|e| e.points.iter().copied()).collect();
    // Per cell: its links, and the crossings it adds (numbered from `total`).
    let linked: Vec<CellLinks> = cells
        .par_iter()
        .with_min_len(16)
        .map(|&[i, j]| {
            let walk = [(num.h(i, j), true), (num.v(i + 1, j), true), (num.h(i, j + 1), false), (num.v(i, j), false)];
            let mut sides: [Vec<usize>; 4] = Default::default();
            for (side, &(id, forward)) in walk.iter().enumerate() {
                let Some(e) = find(id) else { continue };
                let n = e.points.len();
                sides[side].extend((0..n).map(|s| e.offset + if forward { s } else { n - 1 - s }));
            }
            let corners = [grid.point(i, j), grid.point(i + 1, j), grid.point(i + 1, j + 1), grid.point(i, j + 1)];
            let at = |[a, b]: [usize; 2]| grid.inside(level, a, b);
            let cell =
                Cell { corners, inside: [at([i, j]), at([i + 1, j]), at([i + 1, j + 1]), at([i, j + 1])], sides };
            if let Some(links) = simple_links(&cell) {
                return (links, Vec::new()); // no index query for a plain cell
            }
            let local = probe.local(corners[0], corners[2]);
            let mut resolver = Resolver::new(&local, total);
            let links = resolver.link(&cell, &|id| points[id], 0);
            (links, resolver.into_new_nodes())
        })
        .collect();
    let mut points = points;
    let mut next = vec![usize::MAX; total];
    for (links, added) in linked {
        // Renumber the cell's new crossings after those already placed.
        let shift = points.len() - total;
        let renumber = |id: usize| if id >= total { id + shift } else { id };
        next.resize(points.len() + added.len(), usize::MAX);
        points.extend(added);
        for (from, to) in links {
            next[renumber(from)] = renumber(to);
        }
    }
    chains(&next, &points)
}

/// Closed chains of the permutation `next`, each from its smallest crossing.
fn chains(next: &[usize], points: &[Point2]) -> Vec<Vec<Point2>> {
    let mut seen = vec![false; next.len()];
    let mut out = Vec::new();
    for start in 0..next.len() {
        if seen[start] {
            continue;
        }
        let mut chain = Vec::new();
        let mut at = start;
        while !seen[at] {
            seen[at] = true;
            chain.push(points[at]);
            at = next[at];
            // INVARIANT: the border samples are outside (padding), so every crossing
            // lies between two cells and has a successor.
            debug_assert!(at != usize::MAX, "open chain");
            if at == usize::MAX {
                break;
            }
        }
        out.push(chain);
    }
    out
}
