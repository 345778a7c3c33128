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

use rayon::prelude::*;
use scallop_geom::Point2;

use crate::WaterlineGrid;
use crate::refine::Probe;

/// The chains of crossing points of `grid` at the probe's height, each
/// starting at its smallest edge number, listed in that order.
pub(crate) fn trace(grid: &WaterlineGrid<'_>, probe: &Probe<'_>) -> Vec<Vec<Point2>> {
    let (nx, ny) = (grid.nx, grid.ny);
    let z = probe.z;
    let inside: Vec<bool> = grid.heights.par_iter().map(|&h| h > z).collect();
    let is_in = |i: usize, j: usize| inside[j * nx + i];
    let horizontal = (nx - 1) * ny;
    let edge_h = |i: usize, j: usize| j * (nx - 1) + i;
    let edge_v = |i: usize, j: usize| horizontal + j * nx + i;

    // Crossing edges in increasing edge number, with their inside and outside ends.
    let mut edges: Vec<(usize, [usize; 2], [usize; 2])> = Vec::new();
    for j in 0..ny {
        for i in 0..nx - 1 {
            let (a, b) = (is_in(i, j), is_in(i + 1, j));
            if a != b {
                let (pin, pout) = if a { ([i, j], [i + 1, j]) } else { ([i + 1, j], [i, j]) };
                edges.push((edge_h(i, j), pin, pout));
            }
        }
    }
    for j in 0..ny - 1 {
        for i in 0..nx {
            let (a, b) = (is_in(i, j), is_in(i, j + 1));
            if a != b {
                let (pin, pout) = if a { ([i, j], [i, j + 1]) } else { ([i, j + 1], [i, j]) };
                edges.push((edge_v(i, j), pin, pout));
            }
        }
    }
    if edges.is_empty() {
        return Vec::new();
    }
    let points: Vec<Point2> = edges
        .par_iter()
        .with_min_len(16)
        .map(|&(_, [ia, ja], [ib, jb])| {
            // Floored as `Probe::height` floors them, so the secant sees one function.
            let (h_in, h_out) = (grid.heights[ja * nx + ia] - z, (grid.heights[jb * nx + ib] - z).max(-grid.step));
            let (a, b) = (grid.point(ia, ja), grid.point(ib, jb));
            let local = probe.local(Point2::new(a.x.min(b.x), a.y.min(b.y)), Point2::new(a.x.max(b.x), a.y.max(b.y)));
            local.bisect_heights(a, h_in, b, h_out)
        })
        .collect();
    let slot = |id: usize| {
        // INVARIANT: only called with the number of a crossing edge, which is in `edges`.
        edges.binary_search_by_key(&id, |e| e.0).unwrap_or_else(|_| unreachable!("edge {id} is not a crossing"))
    };

    // Mixed cells, and which saddles have their centre inside.
    let mut cells: Vec<(usize, usize, u8)> = Vec::new();
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let mask = u8::from(is_in(i, j))
                | u8::from(is_in(i + 1, j)) << 1
                | u8::from(is_in(i + 1, j + 1)) << 2
                | u8::from(is_in(i, j + 1)) << 3;
            if mask != 0 && mask != 0b1111 {
                cells.push((i, j, mask));
            }
        }
    }
    let saddle_inside: Vec<bool> = cells
        .par_iter()
        .map(|&(i, j, mask)| {
            (mask == 0b0101 || mask == 0b1010) && {
                let (a, b) = (grid.point(i, j), grid.point(i + 1, j + 1));
                probe.is_inside(Point2::new(0.5 * (a.x + b.x), 0.5 * (a.y + b.y)))
            }
        })
        .collect();

    let mut next = vec![usize::MAX; edges.len()];
    for (&(i, j, mask), &centre_in) in cells.iter().zip(&saddle_inside) {
        let cell_edges = [edge_h(i, j), edge_v(i + 1, j), edge_h(i, j + 1), edge_v(i, j)];
        let corner_in = |k: usize| mask >> (k % 4) & 1 == 1;
        let saddle = mask == 0b0101 || mask == 0b1010;
        for k in 0..4 {
            if !(corner_in(k) && !corner_in(k + 1)) {
                continue; // not an exit
            }
            let entry = if saddle {
                if centre_in { (k + 1) % 4 } else { (k + 3) % 4 }
            } else {
                // The only entry of the cell.
                (1..4).map(|s| (k + s) % 4).find(|&e| !corner_in(e) && corner_in(e + 1)).unwrap_or(k)
            };
            debug_assert!(!corner_in(entry) && corner_in(entry + 1), "cell ({i}, {j}) mask {mask:04b}");
            next[slot(cell_edges[k])] = slot(cell_edges[entry]);
        }
    }

    let mut seen = vec![false; edges.len()];
    let mut chains = Vec::new();
    for start in 0..edges.len() {
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
            // edge lies between two cells and has a successor.
            debug_assert!(at != usize::MAX, "open chain");
            if at == usize::MAX {
                break;
            }
        }
        chains.push(chain);
    }
    chains
}
