//! The in-process stock as a roughing operation sees it (docs/roughing.md,
//! "Roughing from the in-process stock"; rest roughing).
//!
//! The stock the earlier operations left is given as material tops on a grid
//! of cells (a z-map: material from the stock's bottom up to the top of each
//! cell). At a level z, the cells with material above z form a region of
//! the plane (the union of their squares). A level's tool-centre region is
//! then cut down to the centres from which the tool reaches material it
//! would remove: material farther than the tool radius from every centre of
//! the level's region lies in the allowance or under the part and is left,
//! so the tool does not re-run passes in cleared air or along walls already
//! at the allowance.

use std::collections::HashMap;

use scallop_contour::{P2, Region};

use crate::{RoughError, tol};

/// Material tops on a grid of `nx * ny` cells (row-major, x fastest); a cell
/// with no material holds `f64::NEG_INFINITY`.
#[derive(Debug, Clone)]
pub struct MaterialMap {
    min: P2,
    cell: P2,
    nx: usize,
    ny: usize,
    tops: Vec<f64>,
}

/// The four directions of the cell edges, counter-clockwise from east.
const STEPS: [(isize, isize); 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];

impl MaterialMap {
    /// The map of `nx * ny` cells of size `cell` from the corner `min`.
    ///
    /// # Errors
    /// [`RoughError::BadSetting`] (key `stock`) for an empty or oversized
    /// grid, a cell size that is not a finite positive number, a top count
    /// that does not match, or a NaN top.
    pub fn new(min: P2, cell: P2, nx: usize, ny: usize, tops: Vec<f64>) -> Result<MaterialMap, RoughError> {
        let bad = |fix| Err(RoughError::BadSetting { key: "stock", value: f64::NAN, fix });
        if nx == 0 || ny == 0 || nx.saturating_mul(ny) > tol::MAX_MATERIAL_CELLS || tops.len() != nx * ny {
            return bad("give a stock grid with at least one cell, at most MAX_MATERIAL_CELLS, one top per cell");
        }
        if !(cell.iter().all(|c| c.is_finite() && *c > 0.0) && min.iter().all(|m| m.is_finite())) {
            return bad("give a stock grid with a finite corner and finite cells > 0 mm");
        }
        if tops.iter().any(|t| t.is_nan()) {
            return bad("give material tops that are numbers (NEG_INFINITY where a cell is empty)");
        }
        Ok(MaterialMap { min, cell, nx, ny, tops })
    }

    /// The cells' size (mm).
    #[must_use]
    pub fn cell_size(&self) -> P2 {
        self.cell
    }

    /// The highest material top over the cells that meet the box `[lo, hi]`,
    /// `None` when none of them holds material.
    #[must_use]
    pub fn top_in(&self, lo: P2, hi: P2) -> Option<f64> {
        let (i0, i1) = self.span(lo[0], hi[0], 0)?;
        let (j0, j1) = self.span(lo[1], hi[1], 1)?;
        (j0..=j1)
            .flat_map(|j| (i0..=i1).map(move |i| (i, j)))
            .map(|(i, j)| self.tops[j * self.nx + i])
            .filter(|t| t.is_finite())
            .reduce(f64::max)
    }

    /// The cells of axis `axis` that meet `[lo, hi]`, clamped to the grid.
    fn span(&self, lo: f64, hi: f64, axis: usize) -> Option<(usize, usize)> {
        let n = if axis == 0 { self.nx } else { self.ny };
        #[allow(clippy::cast_precision_loss, reason = "cell counts far below 2^52")]
        let last = (n - 1) as f64;
        let a = ((lo - self.min[axis]) / self.cell[axis]).floor().max(0.0);
        let b = ((hi - self.min[axis]) / self.cell[axis]).floor().min(last);
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "clamped to [0, n - 1]")]
        (a <= b && a.is_finite() && b.is_finite()).then(|| (a as usize, b as usize))
    }

    fn holds(&self, i: isize, j: isize, z: f64) -> bool {
        #[allow(clippy::cast_sign_loss, reason = "checked non-negative")]
        let inside = i >= 0 && j >= 0 && (i as usize) < self.nx && (j as usize) < self.ny;
        #[allow(clippy::cast_sign_loss, reason = "checked non-negative")]
        let k = if inside { j as usize * self.nx + i as usize } else { 0 };
        inside && self.tops[k] > z
    }

    /// The cells holding material above `z`, as a region: the union of their
    /// squares, outlines thinned by Douglas-Peucker at half a cell.
    #[must_use]
    pub fn above(&self, z: f64) -> Region {
        let rings = self.outlines(z);
        Region::from_polygons_simplified(&rings, true, 0.5 * self.cell[0].min(self.cell[1]))
    }

    /// The boundaries of the cells above `z`, material on the left (outer
    /// boundaries counter-clockwise, holes clockwise), corner points only.
    /// Two cells that touch at a corner only are kept apart: at a vertex
    /// with two ways out, the walk turns left.
    fn outlines(&self, z: f64) -> Vec<Vec<P2>> {
        let edges = self.boundary_edges(z);
        let mut out: HashMap<(isize, isize), u8> = HashMap::with_capacity(edges.len());
        for &(v, d) in &edges {
            *out.entry(v).or_default() |= 1 << d;
        }
        let mut used: HashMap<(isize, isize), u8> = HashMap::with_capacity(edges.len());
        let mut rings = Vec::new();
        for &(v0, d0) in &edges {
            if used.get(&v0).is_some_and(|m| m & (1 << d0) != 0) {
                continue;
            }
            let mut ring = Vec::new();
            let (mut v, mut d) = (v0, d0);
            loop {
                *used.entry(v).or_default() |= 1 << d;
                let next = (v.0 + STEPS[d].0, v.1 + STEPS[d].1);
                let ways = out.get(&next).copied().unwrap_or(0);
                let Some(nd) = [(d + 1) % 4, d, (d + 3) % 4].into_iter().find(|&c| ways & (1 << c) != 0) else {
                    break;
                };
                if nd != d {
                    ring.push(self.point(next));
                }
                if next == v0 && nd == d0 {
                    break;
                }
                (v, d) = (next, nd);
            }
            if ring.len() >= 3 {
                rings.push(ring);
            }
        }
        rings
    }

    /// The directed edges of the cells above `z` that border a cell without
    /// material: `(start vertex, direction)`, in the cells' order.
    fn boundary_edges(&self, z: f64) -> Vec<((isize, isize), usize)> {
        let mut edges = Vec::new();
        for j in 0..self.ny {
            for i in 0..self.nx {
                #[allow(clippy::cast_possible_wrap, reason = "cell counts far below isize::MAX")]
                let (i, j) = (i as isize, j as isize);
                if !self.holds(i, j, z) {
                    continue;
                }
                if !self.holds(i, j - 1, z) {
                    edges.push(((i, j), 0));
                }
                if !self.holds(i + 1, j, z) {
                    edges.push(((i + 1, j), 1));
                }
                if !self.holds(i, j + 1, z) {
                    edges.push(((i + 1, j + 1), 2));
                }
                if !self.holds(i - 1, j, z) {
                    edges.push(((i, j + 1), 3));
                }
            }
        }
        edges
    }

    #[allow(clippy::cast_precision_loss, reason = "cell counts far below 2^52")]
    fn point(&self, v: (isize, isize)) -> P2 {
        [self.min[0] + v.0 as f64 * self.cell[0], self.min[1] + v.1 as f64 * self.cell[1]]
    }
}

/// `region`, a level's tool-centre region at tool-tip height `z`, cut down
/// to the centres from which a tool of radius `r` reaches material it would
/// remove ([`removable_material`]): every centre of the region within `r` of
/// that material. Empty when the level holds nothing to remove. Booleans
/// with chords within `tolerance`.
#[must_use]
pub fn limit_to_material(region: &Region, material: &MaterialMap, z: f64, r: f64, tolerance: f64) -> Region {
    let removable = removable_material(region, material, z, r, tolerance);
    if removable.is_empty() {
        return Region::empty();
    }
    region.intersection(&removable.offset(-r), tolerance)
}

/// The material a tool of radius `r` at the centres of `region` (a level's
/// tool-centre region at tool-tip height `z`) would remove: the material
/// above `z` (by [`tol::MIN_CHIP`]) within `r - margin` of the region, where
/// the margin (a cell's diagonal plus the minimum chip) keeps the cells that
/// only hold the allowance out. Booleans with chords within `tolerance`.
#[must_use]
pub fn removable_material(region: &Region, material: &MaterialMap, z: f64, r: f64, tolerance: f64) -> Region {
    material_met(region, material, z, r, tolerance, false).0
}

/// [`removable_material`] and, when `touched`, the material above `z` (by
/// [`tol::MIN_CHIP`]) within `r` of the region: all that the tool meets at
/// the level, the cells along the walls that the removable material leaves
/// out included (empty when not `touched`). Booleans with chords within
/// `tolerance`.
#[must_use]
pub fn material_met(
    region: &Region,
    material: &MaterialMap,
    z: f64,
    r: f64,
    tolerance: f64,
    touched: bool,
) -> (Region, Region) {
    let [cx, cy] = material.cell_size();
    let margin = cx.hypot(cy) + tol::MIN_CHIP;
    let above = material.above(z + tol::MIN_CHIP);
    if above.is_empty() || region.is_empty() {
        return (Region::empty(), Region::empty());
    }
    let reach = region.offset(-(r - margin).max(0.0));
    let removable = above.intersection(&reach, tolerance);
    let met = if touched && !removable.is_empty() {
        above.intersection(&region.offset(-r), tolerance)
    } else {
        Region::empty()
    };
    (removable, met)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A map of 1 mm cells from the origin, `true` cells at height 10.
    fn map(rows: &[&str]) -> MaterialMap {
        let ny = rows.len();
        let nx = rows[0].len();
        let mut tops = vec![f64::NEG_INFINITY; nx * ny];
        for (j, row) in rows.iter().rev().enumerate() {
            for (i, c) in row.chars().enumerate() {
                if c == '#' {
                    tops[j * nx + i] = 10.0;
                }
            }
        }
        MaterialMap::new([0.0, 0.0], [1.0, 1.0], nx, ny, tops).expect("valid map")
    }

    #[test]
    fn the_region_above_is_the_union_of_the_cells() {
        let m = map(&["......", ".####.", ".#..#.", ".####.", "......", "##...."]);
        let r = m.above(5.0);
        // A 4 x 3 frame with a 2 x 1 hole, and a 2 x 1 bar.
        assert!((r.area() - (12.0 - 2.0 + 2.0)).abs() < 1e-9, "area {}", r.area());
        assert!(r.contains([1.5, 2.5]) && !r.contains([2.5, 3.5]) && r.contains([0.5, 0.5]));
        assert!(m.above(10.0).is_empty(), "nothing strictly above the tops");
    }

    #[test]
    fn cells_touching_at_a_corner_stay_apart() {
        let m = map(&["#.#", ".#.", "#.#"]);
        let r = m.above(0.0);
        assert!((r.area() - 5.0).abs() < 1e-9, "area {}", r.area());
        assert_eq!(r.components().len(), 5);
    }

    #[test]
    fn the_highest_top_in_a_box() {
        let mut m = map(&["##", "#."]);
        m.tops[0] = 3.0;
        assert_eq!(m.top_in([0.2, 0.2], [0.8, 0.8]), Some(3.0));
        assert_eq!(m.top_in([0.0, 0.0], [5.0, 5.0]), Some(10.0));
        assert_eq!(m.top_in([1.2, 0.2], [1.8, 0.8]), None);
        assert_eq!(m.top_in([-5.0, -5.0], [-4.0, -4.0]), None);
    }

    #[test]
    fn bad_maps_are_refused() {
        assert!(MaterialMap::new([0.0, 0.0], [1.0, 1.0], 2, 2, vec![0.0; 3]).is_err());
        assert!(MaterialMap::new([0.0, 0.0], [0.0, 1.0], 1, 1, vec![0.0]).is_err());
        assert!(MaterialMap::new([0.0, 0.0], [1.0, 1.0], 1, 1, vec![f64::NAN]).is_err());
        assert!(MaterialMap::new([f64::INFINITY, 0.0], [1.0, 1.0], 1, 1, vec![0.0]).is_err());
    }

    #[test]
    fn a_level_keeps_only_the_centres_that_reach_material() {
        // 0.5 mm cells over 40 x 40 mm; material left in a 4 mm square in
        // one corner of a 30 x 30 region.
        let n = 80;
        let mut tops = vec![f64::NEG_INFINITY; n * n];
        for j in 0..8 {
            for i in 0..8 {
                tops[(j + 2) * n + i + 2] = 5.0;
            }
        }
        let m = MaterialMap::new([0.0, 0.0], [0.5, 0.5], n, n, tops).expect("valid map");
        let region = Region::from_polygons(&[vec![[1.0, 1.0], [31.0, 1.0], [31.0, 31.0], [1.0, 31.0]]], false);
        let limited = limit_to_material(&region, &m, 0.0, 3.0, 1e-3);
        assert!(!limited.is_empty());
        assert!(limited.area() < 0.2 * region.area(), "area {}", limited.area());
        assert!(limited.contains([3.0, 3.0]) && !limited.contains([20.0, 20.0]));
        assert!(limit_to_material(&region, &m, 6.0, 3.0, 1e-3).is_empty(), "nothing above 6 mm");
    }
}
