//! A square grid of samples over a tool-centre region for adaptive clearing:
//! the region's inside (a scanline fill), distance fields kept by stamping
//! (minimum of distances to stamped points and segments, read by bilinear
//! interpolation), the first-order fast marching method for distances
//! measured inside the region (Sethian 1996, "A fast marching level set
//! method for monotonically advancing fronts", PNAS 93(4), equation 3).
//!
//! Samples sit at the cells' centres; `BIG` stands for "far" (unreached,
//! outside the stamping radius) and keeps the arithmetic finite.

use std::cell::Cell;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

use scallop_contour::{P2, Region};

use crate::{RoughError, tol};

/// A value beyond every distance of a grid (mm).
pub(crate) const BIG: f64 = 1e12;

/// The margin (mm) of [`Grid::quiet`]'s comparisons, far above the rounding
/// of a bilinear sample of values of a few millimetres (about 1e-15 mm).
const QUIET_MARGIN: f64 = 1e-9;

/// The largest field values (mm) [`Grid::quiet`] compares by their
/// difference (rounding about 1e-13 mm).
const QUIET_VALUES: f64 = 1e3;

/// Side (squares) of the blocks of [`Blocks`].
const BLOCK: usize = 8;

/// Bounds per block of `BLOCK` x `BLOCK` squares (a square is the four
/// cell centres a bilinear sample reads, named by its lower-left cell) for
/// [`Grid::quiet`]: the largest swept distance over the block's
/// cells (every corner of its squares) and the least distance from the
/// region. The region's field never changes; the swept one goes down as
/// the tool moves and up when a stamp is undone, so its bound is kept
/// lazily: a change marks the blocks of the cell stale ([`Blocks::lowered`],
/// [`Blocks::changed`]), and a stale bound is recomputed when read. A bound
/// is never below its block's values: a cell that goes down leaves the old
/// bound above them, an undo marks it stale.
pub(crate) struct Blocks {
    nbx: usize,
    nx: usize,
    ny: usize,
    top: Vec<Cell<f64>>,
    stale: Vec<Cell<bool>>,
    least_reach: Vec<f64>,
}

impl Blocks {
    /// The bounds of a swept field and of `reach` (fields of `grid`), the
    /// swept field's all stale.
    pub fn new(grid: &Grid, reach: &[f64]) -> Blocks {
        let (nbx, nby) = (grid.nx.div_ceil(BLOCK), grid.ny.div_ceil(BLOCK));
        let mut blocks = Blocks {
            nbx,
            nx: grid.nx,
            ny: grid.ny,
            top: vec![Cell::new(BIG); nbx * nby],
            stale: vec![Cell::new(true); nbx * nby],
            least_reach: vec![0.0; nbx * nby],
        };
        for b in 0..nbx * nby {
            blocks.least_reach[b] = blocks.cells(b).map(|k| reach[k]).fold(f64::INFINITY, f64::min);
        }
        blocks
    }

    /// The cells of block `b`: the corners of its squares.
    fn cells(&self, b: usize) -> impl Iterator<Item = usize> + '_ {
        let (bi, bj) = (b % self.nbx, b / self.nbx);
        let (i0, j0) = (bi * BLOCK, bj * BLOCK);
        let (i1, j1) = ((i0 + BLOCK).min(self.nx - 1), (j0 + BLOCK).min(self.ny - 1));
        (j0..=j1).flat_map(move |j| (i0..=i1).map(move |i| j * self.nx + i))
    }

    /// The largest value of `swept` over block `b`'s cells, recomputed
    /// when stale.
    fn top_swept(&self, b: usize, swept: &[f64]) -> f64 {
        if self.stale[b].get() {
            self.top[b].set(self.cells(b).map(|k| swept[k]).fold(f64::NEG_INFINITY, f64::max));
            self.stale[b].set(false);
        }
        self.top[b].get()
    }

    /// Cell `k` went down from `old`: its blocks' bounds may fall, which
    /// matters only to the comparisons with thresholds under `old`, none
    /// under `least` (the bound stays above the values either way).
    #[inline]
    pub fn lowered(&self, k: usize, old: f64, least: f64) {
        if old > least {
            self.changed(k);
        }
    }

    /// Cell `k` changed: the blocks it is a cell of are stale (a cell on a
    /// block's lower or left side is also its neighbour's upper or right).
    #[inline]
    pub fn changed(&self, k: usize) {
        let (i, j) = (k % self.nx, k / self.nx);
        let (bi, bj) = (i / BLOCK, j / BLOCK);
        let left = i % BLOCK == 0 && bi > 0;
        let below = j % BLOCK == 0 && bj > 0;
        self.stale[bj * self.nbx + bi].set(true);
        if left {
            self.stale[bj * self.nbx + bi - 1].set(true);
        }
        if below {
            self.stale[(bj - 1) * self.nbx + bi].set(true);
            if left {
                self.stale[(bj - 1) * self.nbx + bi - 1].set(true);
            }
        }
    }

    /// Every bound of the swept field stale (the field replaced).
    pub fn reset(&self) {
        self.stale.iter().for_each(|c| c.set(true));
    }
}

/// The grid: `nx * ny` cells of side `h` from `(x0, y0)` (the lower-left corner).
#[derive(Debug, Clone)]
pub(crate) struct Grid {
    pub x0: f64,
    pub y0: f64,
    pub h: f64,
    pub nx: usize,
    pub ny: usize,
}

impl Grid {
    /// A grid covering `lo..hi` with a margin of `margin`, cells of side `h`
    /// (grown when more than [`tol::MAX_GRID_CELLS`] cells would be needed).
    pub fn new(lo: P2, hi: P2, margin: f64, h: f64) -> Result<Grid, RoughError> {
        let (w, ht) = (hi[0] - lo[0] + 2.0 * margin, hi[1] - lo[1] + 2.0 * margin);
        if !(w.is_finite() && ht.is_finite() && h > 0.0) {
            return Err(RoughError::TooMuchWork { what: "grid cells", limit: tol::MAX_GRID_CELLS });
        }
        #[allow(clippy::cast_precision_loss, reason = "a bound well below 2^52")]
        let area_cells = w * ht / (h * h);
        #[allow(clippy::cast_precision_loss, reason = "a bound well below 2^52")]
        let h = if area_cells > tol::MAX_GRID_CELLS as f64 { (w * ht / tol::MAX_GRID_CELLS as f64).sqrt() } else { h };
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "bounded positive counts")]
        let (nx, ny) = ((w / h).ceil() as usize + 2, (ht / h).ceil() as usize + 2);
        Ok(Grid { x0: lo[0] - margin - h, y0: lo[1] - margin - h, h, nx, ny })
    }

    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// The centre of cell `k`.
    pub fn centre(&self, k: usize) -> P2 {
        let (i, j) = (k % self.nx, k / self.nx);
        #[allow(clippy::cast_precision_loss, reason = "grid indices")]
        let p = [self.x0 + (i as f64 + 0.5) * self.h, self.y0 + (j as f64 + 0.5) * self.h];
        p
    }

    /// The cell index range (inclusive) of the centres within `r` of the box `lo..hi`.
    fn range(&self, lo: P2, hi: P2, r: f64) -> (usize, usize, usize, usize) {
        let clamp = |v: f64, n: usize| {
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, clippy::cast_precision_loss)]
            let c = v.clamp(0.0, (n - 1) as f64) as usize;
            c
        };
        let i0 = clamp(((lo[0] - r - self.x0) / self.h - 0.5).floor(), self.nx);
        let i1 = clamp(((hi[0] + r - self.x0) / self.h - 0.5).ceil(), self.nx);
        let j0 = clamp(((lo[1] - r - self.y0) / self.h - 0.5).floor(), self.ny);
        let j1 = clamp(((hi[1] + r - self.y0) / self.h - 0.5).ceil(), self.ny);
        (i0, i1, j0, j1)
    }

    /// The field `f` at `p`, bilinear between the four nearest centres
    /// ([`BIG`] off the grid).
    pub fn sample(&self, f: &[f64], p: P2) -> f64 {
        self.locate(p).map_or(BIG, |at| Self::interpolate(f, self.nx, at))
    }

    /// Where [`Grid::sample`] reads at `p`: the lower-left centre of the
    /// four and the weights along x and y; `None` off the grid (where a
    /// sample is [`BIG`]). One location serves every field.
    pub fn locate(&self, p: P2) -> Option<(usize, f64, f64)> {
        let u = (p[0] - self.x0) / self.h - 0.5;
        let v = (p[1] - self.y0) / self.h - 0.5;
        #[allow(clippy::cast_precision_loss, reason = "grid sizes")]
        let inside = u >= 0.0 && v >= 0.0 && u < (self.nx - 1) as f64 && v < (self.ny - 1) as f64;
        if !inside {
            return None;
        }
        // Non-negative: truncation is the floor. Through 32 bits (a grid's
        // side is far below 2^32 cells, [`tol::MAX_GRID_CELLS`]): the same
        // integers, converted both ways in fewer instructions.
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "checked above")]
        let (iu, iv) = (u as u32, v as u32);
        let at = (iv as usize * self.nx + iu as usize, u - f64::from(iu), v - f64::from(iv));
        Some(at)
    }

    /// The field `f` (rows of `nx`) at a location of [`Grid::locate`].
    #[inline]
    pub fn interpolate(f: &[f64], nx: usize, (k, a, b): (usize, f64, f64)) -> f64 {
        // One bounds check for the four (the slice's length is known).
        let s = &f[k..k + nx + 2];
        let (f00, f10, f01, f11) = (s[0], s[1], s[nx], s[nx + 1]);
        (f00 * (1.0 - a) + f10 * a) * (1.0 - b) + (f01 * (1.0 - a) + f11 * a) * b
    }

    /// Whether no sample of the fields in the box `lo..hi` can be "material"
    /// (`swept > swept_max` and `reach < reach_min`): every square between
    /// four centres that meets the box and passes `relevant` (given its
    /// middle) has all four `swept` values at most `swept_max` less
    /// [`QUIET_MARGIN`], or all four `reach` values at least `reach_min` plus
    /// it, or all four `swept - reach` at most `swept_max - reach_min` less
    /// it (along a wall the passes slid on). [`Grid::sample`] is a convex combination of a square's four
    /// values, so it lies within their range up to rounding, far below the
    /// margin; samples off the grid are [`BIG`] in both fields. Exact: `true`
    /// only when every sample in the box would say "not material". With
    /// `blocks` (bounds of these `swept` and `reach`), the blocks of squares
    /// whose bounds settle every square in them are skipped: the same
    /// answer.
    #[allow(clippy::too_many_arguments, reason = "the fields, the box, the thresholds and the blocks")]
    pub fn quiet(
        &self,
        swept: &[f64],
        reach: &[f64],
        (lo, hi): (P2, P2),
        relevant: impl Fn(P2) -> bool,
        swept_max: f64,
        reach_min: f64,
        blocks: Option<&Blocks>,
    ) -> bool {
        let (smax, rmin) = (swept_max - QUIET_MARGIN, reach_min + QUIET_MARGIN);
        let gap = swept_max - reach_min - QUIET_MARGIN;
        // Squares (iu, iv) hold the samples with floor(u) = iu, u = (x - x0) / h - 0.5.
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, clippy::cast_precision_loss)]
        let span = |a: f64, b: f64, o: f64, n: usize| {
            let last = (n - 2) as f64;
            let i0 = ((a - o) / self.h - 0.5).floor().max(0.0);
            let i1 = ((b - o) / self.h - 0.5).floor().min(last);
            (i0 <= i1).then_some((i0 as usize, i1 as usize))
        };
        let (Some((i0, i1)), Some((j0, j1))) =
            (span(lo[0], hi[0], self.x0, self.nx), span(lo[1], hi[1], self.y0, self.ny))
        else {
            return true;
        };
        let nx = self.nx;
        let square = |i: usize, j: usize| {
            let k = j * nx + i;
            let (a, b, c, d) = (k, k + 1, k + nx, k + nx + 1);
            let low = swept[a] <= smax && swept[b] <= smax && swept[c] <= smax && swept[d] <= smax;
            if low || (reach[a] >= rmin && reach[b] >= rmin && reach[c] >= rmin && reach[d] >= rmin) {
                return true;
            }
            // Or `swept - reach` at most `swept_max - reach_min` (less
            // the margin) at all four: bilinear too, so everywhere in the
            // square, where `swept > swept_max` then means `reach >
            // reach_min` (values below `QUIET_VALUES` only, so that the
            // rounding stays far below the margin).
            let close = |n: usize| swept[n] < QUIET_VALUES && reach[n] < QUIET_VALUES && swept[n] - reach[n] <= gap;
            if close(a) && close(b) && close(c) && close(d) {
                return true;
            }
            #[allow(clippy::cast_precision_loss, reason = "grid indices")]
            let mid = [self.x0 + (i as f64 + 1.0) * self.h, self.y0 + (j as f64 + 1.0) * self.h];
            !relevant(mid)
        };
        let Some(blocks) = blocks else {
            return (j0..=j1).all(|j| (i0..=i1).all(|i| square(i, j)));
        };
        for bj in j0 / BLOCK..=j1 / BLOCK {
            for bi in i0 / BLOCK..=i1 / BLOCK {
                let b = bj * blocks.nbx + bi;
                if blocks.least_reach[b] >= rmin || blocks.top_swept(b, swept) <= smax {
                    continue;
                }
                let (ja, jb) = (j0.max(bj * BLOCK), j1.min(bj * BLOCK + BLOCK - 1));
                let (ia, ib) = (i0.max(bi * BLOCK), i1.min(bi * BLOCK + BLOCK - 1));
                if !(ja..=jb).all(|j| (ia..=ib).all(|i| square(i, j))) {
                    return false;
                }
            }
        }
        true
    }

    /// Cells whose centre lies inside `region` (non-zero winding of its
    /// rings as chords within `tolerance`), row by row.
    pub fn fill(&self, region: &Region, tolerance: f64) -> Vec<bool> {
        let rings: Vec<Vec<P2>> = region.rings().iter().map(|c| c.to_points(tolerance)).collect();
        self.fill_rings(&rings)
    }

    /// [`Grid::fill`] of closed rings of points.
    pub fn fill_rings(&self, rings: &[Vec<P2>]) -> Vec<bool> {
        let mut inside = vec![false; self.len()];
        let mut cross: Vec<(f64, i32)> = Vec::new();
        for j in 0..self.ny {
            let y = self.centre(j * self.nx)[1];
            cross.clear();
            for ring in rings {
                for (k, a) in ring.iter().enumerate() {
                    let b = ring[(k + 1) % ring.len()];
                    if (a[1] <= y) != (b[1] <= y) {
                        let x = a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                        cross.push((x, if b[1] > a[1] { 1 } else { -1 }));
                    }
                }
            }
            cross.sort_by(|p, q| p.0.total_cmp(&q.0));
            let mut wind = 0;
            for w in 0..cross.len() {
                wind += cross[w].1;
                if wind != 0 && w + 1 < cross.len() {
                    let (lo, hi) = (cross[w].0, cross[w + 1].0);
                    let (i0, i1, _, _) = self.range([lo, y], [hi, y], 0.0);
                    for i in i0..=i1 {
                        let x = self.centre(i)[0];
                        if x > lo && x <= hi {
                            inside[j * self.nx + i] = true;
                        }
                    }
                }
            }
        }
        inside
    }

    /// `f = min(f, distance to the segment a-b)` within `r` of it; the old
    /// values go to `undo` when given.
    pub fn stamp_segment(&self, f: &mut [f64], a: P2, b: P2, r: f64, undo: Option<&mut Vec<(usize, f64)>>) {
        self.stamp_segment_over(f, a, b, r, f64::NEG_INFINITY, undo);
    }

    /// The `floor` of [`Grid::stamp_segment_over`] for a distance field
    /// read only against thresholds of `lowest` or more: two cells under
    /// it (more than a cell's diagonal).
    pub fn settled(&self, lowest: f64) -> f64 {
        lowest - 2.0 * self.h
    }

    /// [`Grid::stamp_segment`], leaving alone the cells whose value is at
    /// most `floor` already (not even measured). Where the field is a
    /// distance to what was stamped, its values at adjacent centres differ
    /// by at most the diagonal `sqrt(2) h`, so a square with a cell left at
    /// or under `floor` has all four values at most `floor + sqrt(2) h`
    /// before and after: every sample there compares the same with a
    /// threshold above that, and only such comparisons read the field.
    pub fn stamp_segment_over(
        &self,
        f: &mut [f64],
        a: P2,
        b: P2,
        r: f64,
        floor: f64,
        mut undo: Option<&mut Vec<(usize, f64)>>,
    ) {
        self.stamp_segment_with(f, a, b, r, floor, |k, old| {
            if let Some(u) = undo.as_deref_mut() {
                u.push((k, old));
            }
        });
    }

    /// [`Grid::stamp_segment_over`], telling `wrote` each cell it lowers
    /// and the cell's old value.
    pub fn stamp_segment_with(
        &self,
        f: &mut [f64],
        a: P2,
        b: P2,
        r: f64,
        floor: f64,
        mut wrote: impl FnMut(usize, f64),
    ) {
        let lo = [a[0].min(b[0]), a[1].min(b[1])];
        let hi = [a[0].max(b[0]), a[1].max(b[1])];
        let (i0, i1, j0, j1) = self.range(lo, hi, r);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let l2 = dx * dx + dy * dy;
        for j in j0..=j1 {
            #[allow(clippy::cast_precision_loss, reason = "grid indices")]
            let y = self.y0 + (j as f64 + 0.5) * self.h;
            // The row's cells within `r` of the segment's box (a superset
            // of those within `r` of the segment), one cell more each side.
            let gap = if y < lo[1] {
                lo[1] - y
            } else if y > hi[1] {
                y - hi[1]
            } else {
                0.0
            };
            if gap > r {
                continue;
            }
            let half = (r * r - gap * gap).sqrt();
            let (ri0, ri1, _, _) = self.range([lo[0] - half, y], [hi[0] + half, y], self.h);
            for i in ri0.max(i0)..=ri1.min(i1) {
                let k = j * self.nx + i;
                if f[k] <= floor {
                    continue;
                }
                // As `centre(k)`.
                #[allow(clippy::cast_precision_loss, reason = "grid indices")]
                let c = [self.x0 + (i as f64 + 0.5) * self.h, y];
                // As `(num / l2).clamp(0.0, 1.0)`, the division only where it
                // does not clamp (most cells of a short segment's capsule lie
                // beyond its ends).
                let num = (c[0] - a[0]) * dx + (c[1] - a[1]) * dy;
                let t =
                    if l2 > 0.0 && num > 0.0 { if num >= l2 { 1.0 } else { (num / l2).clamp(0.0, 1.0) } } else { 0.0 };
                let (ex, ey) = (c[0] - a[0] - t * dx, c[1] - a[1] - t * dy);
                let d2 = ex * ex + ey * ey;
                if d2 <= r * r && d2 < f[k] * f[k] {
                    let d = d2.sqrt();
                    if d < f[k] {
                        wrote(k, f[k]);
                        f[k] = d;
                    }
                }
            }
        }
    }

    /// Distances from the sources `seeds` (cell, value) through the cells
    /// where `open` holds, by fast marching ([`BIG`] where not reached).
    pub fn march(&self, open: &[bool], seeds: &[(usize, f64)]) -> Vec<f64> {
        let mut t = vec![BIG; self.len()];
        let mut known = vec![false; self.len()];
        let mut heap = BinaryHeap::new();
        for &(k, v) in seeds {
            if open[k] && v < t[k] {
                t[k] = v;
                heap.push(Reverse((v.to_bits(), k)));
            }
        }
        let h = self.h;
        while let Some(Reverse((bits, k))) = heap.pop() {
            if known[k] || f64::from_bits(bits) > t[k] {
                continue;
            }
            known[k] = true;
            for n in self.neighbours(k) {
                if known[n] || !open[n] {
                    continue;
                }
                let a = t[n - 1].min(t[n + 1]);
                let b = t[n - self.nx].min(t[n + self.nx]);
                let (a, b) = if a <= b { (a, b) } else { (b, a) };
                let v = if b - a >= h { a + h } else { 0.5 * (a + b + (2.0 * h * h - (b - a) * (b - a)).sqrt()) };
                if v < t[n] {
                    t[n] = v;
                    heap.push(Reverse((v.to_bits(), n)));
                }
            }
        }
        t
    }

    /// The 4-neighbours of `k` that are not on the grid's border.
    fn neighbours(&self, k: usize) -> impl Iterator<Item = usize> + '_ {
        let (i, j) = (k % self.nx, k / self.nx);
        let cand = [
            (i > 1).then(|| k - 1),
            (i + 2 < self.nx).then(|| k + 1),
            (j > 1).then(|| k - self.nx),
            (j + 2 < self.ny).then(|| k + self.nx),
        ];
        cand.into_iter().flatten()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// [`Grid::quiet`] says "no material" only where no sample in the box
        /// finds any: fields as the adaptive planner's (a distance from swept
        /// centres, [`BIG`] beyond the stamping radius, here just past the
        /// threshold; a distance from the region), their thresholds crossed
        /// inside the box.
        #[test]
        fn quiet_boxes_hold_no_material_sample(
            s in (0.0..4.0f64, 0.0..4.0f64), w in (0.0..4.0f64, 0.0..4.0f64),
            centre in (0.0..4.0f64, 0.0..4.0f64), half in 0.05..1.5f64, t in 0.6..1.4f64, cut in 0.0..0.15f64,
        ) {
            let g = Grid::new([0.0, 0.0], [4.0, 4.0], 0.5, 0.13).expect("grid");
            let swept: Vec<f64> = (0..g.len())
                .map(|k| {
                    let c = g.centre(k);
                    let d = (c[0] - s.0).hypot(c[1] - s.1);
                    if d <= t + cut { d } else { BIG }
                })
                .collect();
            let reach: Vec<f64> = (0..g.len()).map(|k| (g.centre(k)[0] - w.0).abs() + 0.3 * (g.centre(k)[1] - w.1)).collect();
            let (lo, hi) = ([centre.0 - half, centre.1 - half], [centre.0 + half, centre.1 + half]);
            if g.quiet(&swept, &reach, (lo, hi), |_| true, t, t, None) {
                for i in 0..=40u32 {
                    for j in 0..=40u32 {
                        let q = [lo[0] + (hi[0] - lo[0]) * f64::from(i) / 40.0, lo[1] + (hi[1] - lo[1]) * f64::from(j) / 40.0];
                        let material = g.sample(&swept, q) > t && g.sample(&reach, q) < t;
                        prop_assert!(!material, "material at {q:?}");
                    }
                }
            }
        }
    }

    proptest! {
        /// [`Grid::quiet`] with blocks answers as without them on a swept
        /// field a walk stamps (the blocks told of each lowered cell) and
        /// partly undoes (told of each restored one), then resets: boxes
        /// anywhere, thresholds about R, a region field with a wall.
        #[test]
        fn blocks_answer_as_the_squares(
            start in (1.0..5.0f64, 1.0..5.0f64), turns in proptest::collection::vec(-0.8..0.8f64, 1..40),
            len in 0.05..0.5f64, r in 0.4..1.2f64, undo_from in 0usize..40, wall in 0.5..5.5f64,
            boxes in proptest::collection::vec((0.0..6.0f64, 0.0..6.0f64, 0.05..2.5f64, -0.01..0.01f64), 12),
        ) {
            let g = Grid::new([0.0, 0.0], [6.0, 6.0], 1.0, 0.09).expect("grid");
            let reach: Vec<f64> = (0..g.len()).map(|k| (g.centre(k)[0] - wall).max(0.0)).collect();
            let blocks = Blocks::new(&g, &reach);
            let mut swept = vec![BIG; g.len()];
            // Boxes anywhere and about the walk's points.
            let mut around = boxes.clone();
            let mut q = [start.0, start.1];
            let mut h0 = 0.0f64;
            for (n, t) in turns.iter().enumerate() {
                h0 += t;
                q = [q[0] + len * h0.cos(), q[1] + len * h0.sin()];
                if n % 3 == 0 {
                    around.push((q[0], q[1], 0.3 + 0.1 * (n % 7) as f64, 0.0));
                }
            }
            let check = |swept: &[f64]| -> Result<(), TestCaseError> {
                for &(x, y, half, dt) in &around {
                    let bounds = ([x - half, y - half], [x + half, y + half]);
                    let ring = |m: P2| (m[0] - x).hypot(m[1] - y) >= 0.3 * half;
                    let want = g.quiet(swept, &reach, bounds, ring, r + dt, r - dt, None);
                    prop_assert_eq!(g.quiet(swept, &reach, bounds, ring, r + dt, r - dt, Some(&blocks)), want);
                }
                Ok(())
            };
            check(&swept)?;
            let (mut p, mut heading) = ([start.0, start.1], 0.0f64);
            let mut undo = Vec::new();
            for (n, t) in turns.iter().enumerate() {
                heading += t;
                let q = [p[0] + len * heading.cos(), p[1] + len * heading.sin()];
                g.stamp_segment_with(&mut swept, p, q, r + 2.0 * g.h, f64::NEG_INFINITY, |k, old| {
                    if n >= undo_from {
                        undo.push((k, old));
                    }
                    blocks.lowered(k, old, r - 0.02);
                });
                p = q;
            }
            check(&swept)?;
            for &(k, old) in undo.iter().rev() {
                swept[k] = old;
                blocks.changed(k);
            }
            check(&swept)?;
            swept = vec![BIG; g.len()];
            blocks.reset();
            check(&swept)?;
        }
    }

    proptest! {
        /// A walk of short moves stamped with cells at most
        /// [`Grid::settled`] left alone reads the same as stamped in full
        /// against every threshold from the lowest up: exact where a cell
        /// is over the floor, never under the full field, and every
        /// bilinear sample on the same side of each threshold.
        #[test]
        fn stamps_over_the_floor_read_as_full_stamps(
            start in (1.0..3.0f64, 1.0..3.0f64), turns in proptest::collection::vec(-0.8..0.8f64, 1..60),
            len in 0.02..0.4f64, r in 0.4..1.2f64, chip in 0.0..0.05f64,
        ) {
            let g = Grid::new([0.0, 0.0], [4.0, 4.0], 1.5, 0.07).expect("grid");
            let w = r + 2.0 * g.h;
            let lowest = r - chip;
            let floor = g.settled(lowest);
            let (mut full, mut over) = (vec![BIG; g.len()], vec![BIG; g.len()]);
            let (mut p, mut heading) = ([start.0, start.1], 0.0f64);
            g.stamp_segment(&mut full, p, p, w, None);
            g.stamp_segment_over(&mut over, p, p, w, floor, None);
            for t in &turns {
                heading += t;
                let q = [p[0] + len * heading.cos(), p[1] + len * heading.sin()];
                g.stamp_segment(&mut full, p, q, w, None);
                g.stamp_segment_over(&mut over, p, q, w, floor, None);
                p = q;
            }
            for k in 0..g.len() {
                prop_assert!(over[k] >= full[k]);
                prop_assert!(over[k] <= floor || over[k].to_bits() == full[k].to_bits(), "cell {k}: {} vs {}", over[k], full[k]);
            }
            let thresholds = [lowest, lowest + 0.5 * g.h, r, r + 0.005, r + 2.0 * g.h];
            for i in 0..=160u32 {
                for j in 0..=160u32 {
                    let q = [0.1 + 3.8 * f64::from(i) / 160.0, 0.1 + 3.8 * f64::from(j) / 160.0];
                    let (a, b) = (g.sample(&full, q), g.sample(&over, q));
                    for t in thresholds {
                        prop_assert_eq!(a > t, b > t, "at {:?}, threshold {}: {} vs {}", q, t, a, b);
                    }
                }
            }
        }
    }

    #[test]
    fn quiet_says_yes_in_cleared_area_and_no_next_to_material() {
        let g = Grid::new([0.0, 0.0], [4.0, 4.0], 0.5, 0.13).expect("grid");
        // Cleared (swept within 0.5) left of x = 2, material right of it.
        let swept: Vec<f64> = (0..g.len()).map(|k| if g.centre(k)[0] < 2.0 { 0.5 } else { BIG }).collect();
        let reach = vec![0.0; g.len()];
        assert!(g.quiet(&swept, &reach, ([0.5, 0.5], [1.5, 3.5]), |_| true, 1.0, 1.0, None));
        assert!(!g.quiet(&swept, &reach, ([1.5, 0.5], [2.5, 3.5]), |_| true, 1.0, 1.0, None));
        // The same box, the squares across x = 2 left out as irrelevant.
        assert!(g.quiet(&swept, &reach, ([1.5, 0.5], [2.5, 3.5]), |m| m[0] < 1.8, 1.0, 1.0, None));
        // Cleared left of x = 2, outside the region right of it: every
        // centre is either swept or out of reach, but samples between the
        // two find material (swept far, reach near): not quiet.
        let reach: Vec<f64> = (0..g.len()).map(|k| if g.centre(k)[0] < 2.0 { 0.0 } else { 2.0 }).collect();
        let boxed = ([1.5, 0.5], [2.5, 3.5]);
        assert!(!g.quiet(&swept, &reach, boxed, |_| true, 1.0, 1.0, None));
        let between = (0..=100).map(|i| [1.9 + 0.002 * f64::from(i), 2.0]);
        assert!(between.into_iter().any(|q| g.sample(&swept, q) > 1.0 && g.sample(&reach, q) < 1.0));
        // Along a wall the passes slid on: swept a little over reach. Within
        // the thresholds' gap, quiet; beyond it, samples find material.
        let reach: Vec<f64> = (0..g.len()).map(|k| g.centre(k)[0]).collect();
        let along = ([0.5, 0.5], [1.5, 3.5]);
        let material = |swept: &[f64]| {
            (0..=200).any(|i| {
                g.sample(swept, [0.5 + 0.005 * f64::from(i), 2.0]) > 1.005
                    && g.sample(&reach, [0.5 + 0.005 * f64::from(i), 2.0]) < 0.98
            })
        };
        let slid: Vec<f64> = reach.iter().map(|x| x + 0.01).collect();
        assert!(g.quiet(&slid, &reach, along, |_| true, 1.005, 0.98, None) && !material(&slid));
        let left: Vec<f64> = reach.iter().map(|x| x + 0.05).collect();
        assert!(!g.quiet(&left, &reach, along, |_| true, 1.005, 0.98, None) && material(&left));
    }
}
