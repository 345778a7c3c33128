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

use std::collections::BTreeMap;

use crate::cell::{self, Base, Cell, Resolver, simple_links};
use crate::refine::Probe;
use crate::{Level, WaterlineGrid};

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
/// both ends inside that no triangle certifies. Each edge's crossings are in
/// increasing x (horizontal) or y (vertical).
fn edge_crossings(grid: &WaterlineGrid<'_>, level: &Level, probe: &Probe<'_>) -> Vec<(usize, Vec<Point2>)> {
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
    found.retain(|f| !f.1.is_empty());
    found
}

/// The links (exit, entry) of one cell in the numbering of the round that
/// linked it, the crossings it adds inside (numbered from the round's grid
/// crossings' count, cell by cell), and the pieces of grid edges among its
/// sides that hold more crossings than were found on them (the edge, the
/// piece's ends).
struct Linked {
    links: Vec<(usize, usize)>,
    added: Vec<Point2>,
    asked: Vec<(usize, Point2, Point2)>,
}

/// A crossing named independently of the numbering: the `s`-th crossing
/// (along the edge) of grid edge `edge`, or a cell's `k`-th new crossing.
#[derive(Clone, Copy)]
enum Node {
    Grid { edge: usize, s: usize },
    New(usize),
}

/// The crossings of the grid edges, numbered: the edges in order, each along
/// the edge.
struct Numbered {
    offsets: Vec<usize>,
    points: Vec<Point2>,
}

impl Numbered {
    fn new(edges: &[(usize, Vec<Point2>)]) -> Self {
        let mut offsets = Vec::with_capacity(edges.len());
        let mut points: Vec<Point2> = Vec::new();
        for e in edges {
            offsets.push(points.len());
            points.extend(&e.1);
        }
        Numbered { offsets, points }
    }

    /// The name of crossing `id` (a grid crossing below the count, else a
    /// cell's new one).
    fn name(&self, edges: &[(usize, Vec<Point2>)], id: usize) -> Node {
        if id >= self.points.len() {
            return Node::New(id - self.points.len());
        }
        let k = self.offsets.partition_point(|&o| o <= id) - 1;
        Node::Grid { edge: edges[k].0, s: id - self.offsets[k] }
    }
}

/// A piece of a grid edge, as a sortable key: the edge and its ends' bits.
type PieceKey = (usize, [u64; 4]);

fn piece_key(&(id, p, q): &(usize, Point2, Point2)) -> PieceKey {
    (id, [p.x.to_bits(), p.y.to_bits(), q.x.to_bits(), q.y.to_bits()])
}

/// Rounds of [`trace`] that look for the other crossings of pieces of grid
/// edges whose midpoint disagrees with their crossings, before the cells left
/// are decided unsplit there (a second round is needed only where the
/// crossings found in the first make a neighbouring cell ambiguous and its
/// split finds another).
const SIDE_ROUNDS: usize = 3;

/// The chains of crossing points of `grid` at the probe's height, each
/// starting at its smallest crossing (edge number, then along the edge),
/// listed in that order.
///
/// Cells are linked in rounds: a cell whose split finds the midpoint of a
/// piece of a grid edge on the wrong side for the crossings of that piece (the
/// edge holds more crossings than step 2 gave it) names the piece; its
/// crossings are then found again on its two halves (`cell::refine_piece`),
/// the same for both cells that share the edge, and the cells along the edges
/// changed are linked again. Where no cell names a piece (nearly always),
/// there is one round.
pub(crate) fn trace(grid: &WaterlineGrid<'_>, level: &Level, probe: &Probe<'_>) -> Vec<Vec<Point2>> {
    let (nx, ny) = (grid.nx, grid.ny);
    let num = Numbering { nx, ny };
    let mut edges = edge_crossings(grid, level, probe);
    if edges.is_empty() {
        return Vec::new();
    }
    let mut cells: Vec<[usize; 2]> = edges.iter().flat_map(|e| num.cells(e.0)).collect();
    cells.sort_unstable_by_key(|c| (c[1], c[0]));
    cells.dedup();
    let mut numbered = Numbered::new(&edges);
    let first = link_cells(grid, level, probe, &num, &edges, &numbered, &cells);
    if first.iter().all(|r| r.asked.is_empty()) {
        let Numbered { mut points, .. } = numbered;
        let total = points.len();
        let mut next = vec![usize::MAX; total];
        for cell in first {
            // Renumber the cell's new crossings after those already placed.
            let shift = points.len() - total;
            let renumber = |id: usize| if id >= total { id + shift } else { id };
            next.resize(points.len() + cell.added.len(), usize::MAX);
            points.extend(cell.added);
            for (from, to) in cell.links {
                next[renumber(from)] = renumber(to);
            }
        }
        return chains(&next, &points);
    }
    // Some pieces of grid edges hold more crossings: the links by name, so
    // that the cells not linked again keep theirs when the numbering changes.
    type Named = (Vec<(Node, Node)>, Vec<Point2>);
    let named = |edges: &[(usize, Vec<Point2>)], numbered: &Numbered, r: Linked| -> Named {
        let links = r.links.iter().map(|&(a, b)| (numbered.name(edges, a), numbered.name(edges, b))).collect();
        (links, r.added)
    };
    let mut asked: Vec<(usize, Point2, Point2)> = first.iter().flat_map(|r| r.asked.iter().copied()).collect();
    let mut linked: BTreeMap<(usize, usize), Named> =
        cells.iter().zip(first).map(|(c, r)| ((c[1], c[0]), named(&edges, &numbered, r))).collect();
    let mut applied: Vec<PieceKey> = Vec::new();
    for _ in 1..SIDE_ROUNDS {
        asked.retain(|p| applied.binary_search(&piece_key(p)).is_err());
        asked.sort_unstable_by_key(piece_key);
        asked.dedup_by_key(|p| piece_key(p));
        // The pieces by edge, each edge's applied in key order.
        let mut by_edge: Vec<(usize, Vec<(Point2, Point2)>)> = Vec::new();
        for &(id, p, q) in &asked {
            match by_edge.last_mut() {
                Some(last) if last.0 == id => last.1.push((p, q)),
                _ => by_edge.push((id, vec![(p, q)])),
            }
        }
        let fixed: Vec<(usize, Vec<Point2>)> = by_edge
            .par_iter()
            .map(|(id, pieces)| {
                let ([ia, ja], [ib, jb]) = num.ends(*id);
                let (a, b) = (grid.point(ia, ja), grid.point(ib, jb));
                let local = probe.local(a, b);
                let mut found =
                    edges.binary_search_by_key(id, |e| e.0).map_or_else(|_| Vec::new(), |k| edges[k].1.clone());
                for &(p, q) in pieces {
                    // `None` (an inside point without a contact triangle) leaves the crossings as they were.
                    let _ = cell::refine_piece(&local, &mut found, a, b, p, q);
                }
                (*id, found)
            })
            .collect();
        applied.extend(asked.iter().map(piece_key));
        applied.sort_unstable();
        let mut again: Vec<[usize; 2]> = fixed.iter().flat_map(|f| num.cells(f.0)).collect();
        again.sort_unstable_by_key(|c| (c[1], c[0]));
        again.dedup();
        if again.is_empty() {
            break;
        }
        for (id, points) in fixed {
            match edges.binary_search_by_key(&id, |e| e.0) {
                Ok(k) => edges[k].1 = points,
                Err(k) => edges.insert(k, (id, points)),
            }
        }
        edges.retain(|e| !e.1.is_empty());
        numbered = Numbered::new(&edges);
        let results = link_cells(grid, level, probe, &num, &edges, &numbered, &again);
        asked = results.iter().flat_map(|r| r.asked.iter().copied()).collect();
        for (c, r) in again.iter().zip(results) {
            linked.insert((c[1], c[0]), named(&edges, &numbered, r));
        }
    }
    // Number the crossings: the grid edges' in edge order, then each cell's
    // new ones in cell order (row by row).
    let Numbered { offsets, mut points } = Numbered::new(&edges);
    let total = points.len();
    let mut next = vec![usize::MAX; total];
    for (links, added) in linked.into_values() {
        let base = points.len();
        let number = |n: Node| match n {
            Node::Grid { edge, s } => {
                // INVARIANT: a cell links only crossings of the edges it was given.
                let k = edges.binary_search_by_key(&edge, |e| e.0).unwrap_or_default();
                offsets[k] + s
            }
            Node::New(k) => base + k,
        };
        next.resize(base + added.len(), usize::MAX);
        points.extend(added);
        for (from, to) in links {
            next[number(from)] = number(to);
        }
    }
    chains(&next, &points)
}

/// The links of `cells` (in that order) with the crossings of `edges` (sorted
/// by edge number), numbered as `numbered`.
fn link_cells(
    grid: &WaterlineGrid<'_>,
    level: &Level,
    probe: &Probe<'_>,
    num: &Numbering,
    edges: &[(usize, Vec<Point2>)],
    numbered: &Numbered,
    cells: &[[usize; 2]],
) -> Vec<Linked> {
    let points = &numbered.points;
    let total = points.len();
    cells
        .par_iter()
        .with_min_len(16)
        .map(|&[i, j]| {
            let walk = [(num.h(i, j), true), (num.v(i + 1, j), true), (num.h(i, j + 1), false), (num.v(i, j), false)];
            let mut sides: [Vec<usize>; 4] = Default::default();
            for (side, &(id, forward)) in walk.iter().enumerate() {
                let Ok(k) = edges.binary_search_by_key(&id, |e| e.0) else { continue };
                let (n, offset) = (edges[k].1.len(), numbered.offsets[k]);
                sides[side].extend((0..n).map(|s| offset + if forward { s } else { n - 1 - s }));
            }
            let corners = [grid.point(i, j), grid.point(i + 1, j), grid.point(i + 1, j + 1), grid.point(i, j + 1)];
            let at = |[a, b]: [usize; 2]| grid.inside(level, a, b);
            let cell = Cell {
                corners,
                inside: [at([i, j]), at([i + 1, j]), at([i + 1, j + 1]), at([i, j + 1])],
                sides,
                bases: [Base::Grid(0), Base::Grid(1), Base::Grid(2), Base::Grid(3)],
            };
            if let Some(links) = simple_links(&cell) {
                // No index query for a plain cell.
                return Linked { links, added: Vec::new(), asked: Vec::new() };
            }
            let local = probe.local(corners[0], corners[2]);
            let mut resolver = Resolver::new(&local, total);
            let links = resolver.resolve(&cell, &|id| points[id]);
            let (added, asked) = resolver.into_parts();
            Linked { links, added, asked: asked.into_iter().map(|(k, p, q)| (walk[k].0, p, q)).collect() }
        })
        .collect()
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
