//! The 2D raster of an engagement evaluation: square cells with flags that
//! decide most probes of the tool's periphery at once and send the others to
//! an exact test, and the Euclidean distance transform that gives the
//! pocket's opening by the tool.
//!
//! Flags of a cell (side `h`, half diagonal `c = h / sqrt 2`): `MATERIAL` its
//! centre lies inside the pocket; `WALL` it lies within `h` of a wall (a probe
//! there is tested exactly with [`Pocket::contains`]); `SURE` its centre lies
//! within `R - c` of a stamped move, so the whole cell was cut; `NEAR` within
//! `R + c` (a probe there is tested exactly against the stamped moves of its
//! bucket); `CLEARED` within `R` (the cell's centre was cut: the uncut area).

use rayon::prelude::*;
use scallop_geom::{Point2, Vec2};

use super::{Pocket, segment_distance};
use crate::SimError;
use crate::tol::ENGAGEMENT_CONTACT;
use crate::zmap::{MAX_CELLS, cells_along};

const MATERIAL: u8 = 1;
const CLEARED: u8 = 2;
const WALL: u8 = 4;
const SURE: u8 = 8;
const NEAR: u8 = 16;
/// Cells per side of a bucket of stamped moves.
const BUCKET_CELLS: usize = 16;

/// Square cells of side `h` from `min`; `nx` by `ny`, row-major.
pub(super) struct Raster {
    min: Point2,
    h: f64,
    nx: usize,
    ny: usize,
    flags: Vec<u8>,
    /// Stamped moves, and per bucket of `BUCKET_CELLS^2` cells the moves
    /// whose disc of radius `R + ENGAGEMENT_CONTACT` may reach it.
    moves: Vec<(Point2, Point2)>,
    buckets: Vec<Vec<u32>>,
    bx: usize,
}

/// `x` such that `coef x + offset` lies in `[lo, hi]`: all `x` (`None` for
/// the bounds) or none when `coef` is 0.
fn slab(coef: f64, offset: f64, lo: f64, hi: f64) -> Option<(f64, f64)> {
    if coef == 0.0 {
        return (lo..=hi).contains(&offset).then_some((f64::NEG_INFINITY, f64::INFINITY));
    }
    let (a, b) = ((lo - offset) / coef, (hi - offset) / coef);
    Some((a.min(b), a.max(b)))
}

/// The interval of `x` on the line at height `y` within `radius` of the
/// segment `a b` (a capsule: convex, so one interval), `None` when empty.
pub(super) fn capsule_row(a: Point2, b: Point2, radius: f64, y: f64) -> Option<(f64, f64)> {
    let disc = |c: Point2| {
        let dy = y - c.y;
        let w2 = radius * radius - dy * dy;
        (w2 >= 0.0).then(|| (c.x - w2.sqrt(), c.x + w2.sqrt()))
    };
    let mut hull: Option<(f64, f64)> = None;
    let mut add = |i: Option<(f64, f64)>| {
        if let Some((lo, hi)) = i.filter(|(lo, hi)| lo <= hi) {
            hull = Some(hull.map_or((lo, hi), |(l, h)| (l.min(lo), h.max(hi))));
        }
    };
    add(disc(a));
    add(disc(b));
    let d = b - a;
    let length = d.norm();
    if length > 0.0 {
        let (ux, uy) = (d.x / length, d.y / length);
        // Along: (x - ax) ux + (y - ay) uy in [0, L]; across: -(x - ax) uy + (y - ay) ux in [-R, R].
        let along = slab(ux, -a.x * ux + (y - a.y) * uy, 0.0, length);
        let across = slab(-uy, a.x * uy + (y - a.y) * ux, -radius, radius);
        if let (Some(p), Some(q)) = (along, across) {
            add(Some((p.0.max(q.0), p.1.min(q.1))));
        }
    }
    hull
}

impl Raster {
    /// The pocket's box at cell size `h`, material where the cell centre is
    /// inside the pocket (even-odd rule over all its rings).
    pub(super) fn new(pocket: &Pocket, h: f64) -> Result<Raster, SimError> {
        if !(h.is_finite() && h > 0.0) {
            return Err(SimError::BadResolution { resolution: h });
        }
        // Two cells of margin around the pocket: the walls have outside cells.
        let b = pocket.bounds();
        let pad = Vec2::new(2.0 * h, 2.0 * h);
        let b = scallop_geom::Aabb2 { min: b.min - pad, max: b.max + pad };
        let (fx, fy) = (cells_along(b.max.x - b.min.x, h), cells_along(b.max.y - b.min.y, h));
        if fx * fy > MAX_CELLS as f64 {
            // Saturating conversions: only used in the message.
            return Err(SimError::TooManyCells { nx: fx as usize, ny: fy as usize, limit: MAX_CELLS });
        }
        // Below MAX_CELLS: exact conversions.
        let (nx, ny) = (fx as usize, fy as usize);
        let (bx, by) = (nx.div_ceil(BUCKET_CELLS), ny.div_ceil(BUCKET_CELLS));
        let mut raster = Raster {
            min: b.min,
            h,
            nx,
            ny,
            flags: vec![0; nx * ny],
            moves: Vec::new(),
            buckets: vec![Vec::new(); bx * by],
            bx,
        };
        let min = raster.min;
        raster.flags.par_chunks_mut(nx).enumerate().for_each(|(j, row)| {
            let y = min.y + (j as f64 + 0.5) * h;
            let mut xs = pocket.crossings(y);
            xs.sort_by(f64::total_cmp);
            for pair in xs.chunks_exact(2) {
                for flag in &mut row[first_cell(pair[0], min.x, h, nx)..first_cell(pair[1], min.x, h, nx)] {
                    *flag |= MATERIAL;
                }
            }
        });
        for ring in pocket.rings() {
            for (a, b) in ring.iter().zip(ring.iter().cycle().skip(1)) {
                raster.fill(*a, *b, h, WALL);
            }
        }
        Ok(raster)
    }

    pub(super) fn cell_size(&self) -> f64 {
        self.h
    }

    fn index(&self, p: Point2) -> Option<usize> {
        let (i, j) = (((p.x - self.min.x) / self.h).floor(), ((p.y - self.min.y) / self.h).floor());
        // Cell counts below MAX_CELLS: exact conversions after the range check.
        (i >= 0.0 && j >= 0.0 && i < self.nx as f64 && j < self.ny as f64).then(|| j as usize * self.nx + i as usize)
    }

    /// Whether `q` lies in the pocket and farther than `radius +
    /// ENGAGEMENT_CONTACT` from every stamped move (exact; the flags only
    /// spare the exact tests).
    pub(super) fn is_uncut(&self, q: Point2, pocket: &Pocket, radius: f64) -> bool {
        let Some(k) = self.index(q) else { return false };
        let f = self.flags[k];
        let inside = if f & WALL != 0 { pocket.contains(q) } else { f & MATERIAL != 0 };
        if !inside || f & SURE != 0 {
            return false;
        }
        if f & NEAR == 0 {
            return true;
        }
        let (i, j) = (k % self.nx / BUCKET_CELLS, k / self.nx / BUCKET_CELLS);
        let reach = radius + ENGAGEMENT_CONTACT;
        self.buckets[j * self.bx + i].iter().all(|&m| {
            let (a, b) = self.moves[m as usize];
            segment_distance(q, a, b) > reach
        })
    }

    /// Sets `flag` on every cell whose centre lies within `radius` of `a b`.
    fn fill(&mut self, a: Point2, b: Point2, radius: f64, flag: u8) {
        if radius <= 0.0 {
            return;
        }
        let (y0, y1) = (a.y.min(b.y) - radius, a.y.max(b.y) + radius);
        let (j0, j1) = (first_cell(y0, self.min.y, self.h, self.ny), first_cell(y1, self.min.y, self.h, self.ny));
        for j in j0..j1 {
            let y = self.min.y + (j as f64 + 0.5) * self.h;
            if let Some((x0, x1)) = capsule_row(a, b, radius, y) {
                let (i0, i1) =
                    (first_cell(x0, self.min.x, self.h, self.nx), first_cell(x1, self.min.x, self.h, self.nx));
                for cell in &mut self.flags[j * self.nx + i0..j * self.nx + i1] {
                    *cell |= flag;
                }
            }
        }
    }

    /// Records the move `a b` of a tool of `radius` as cut: flags and buckets.
    pub(super) fn stamp(&mut self, a: Point2, b: Point2, radius: f64) {
        let c = self.h * std::f64::consts::FRAC_1_SQRT_2;
        self.fill(a, b, radius, CLEARED);
        self.fill(a, b, radius - c, SURE);
        self.fill(a, b, radius + c + ENGAGEMENT_CONTACT, NEAR);
        // INVARIANT: fewer moves than u32::MAX (a toolpath's moves, checked by the caller).
        let index = u32::try_from(self.moves.len()).unwrap_or(u32::MAX);
        self.moves.push((a, b));
        let reach = radius + c + ENGAGEMENT_CONTACT;
        let side = self.h * BUCKET_CELLS as f64;
        let bucket = |v: f64, min: f64, n: usize| {
            // Clamped to the bucket grid: exact conversions.
            ((v - min) / side).floor().clamp(0.0, n as f64 - 1.0) as usize
        };
        let by = self.buckets.len() / self.bx;
        let (i0, i1) =
            (bucket(a.x.min(b.x) - reach, self.min.x, self.bx), bucket(a.x.max(b.x) + reach, self.min.x, self.bx));
        let (j0, j1) = (bucket(a.y.min(b.y) - reach, self.min.y, by), bucket(a.y.max(b.y) + reach, self.min.y, by));
        for j in j0..=j1 {
            for i in i0..=i1 {
                self.buckets[j * self.bx + i].push(index);
            }
        }
    }

    /// Cells in the pocket (material at the start), and the cells in the
    /// pocket's opening by a disc of `radius` (the union of the discs whose
    /// centres lie at least `radius + margin` inside the pocket, by cell
    /// centres) still uncut.
    pub(super) fn opening_uncut(&self, radius: f64, margin: f64) -> (usize, usize, usize) {
        let outside: Vec<bool> = self.flags.iter().map(|f| f & MATERIAL == 0).collect();
        let to_wall = self.distance_squared(&outside);
        let reach = (radius + margin) / self.h;
        let centres: Vec<bool> = to_wall.iter().map(|&d| d >= reach * reach).collect();
        let to_centre = self.distance_squared(&centres);
        let r2 = (radius / self.h) * (radius / self.h);
        let material = self.flags.iter().filter(|&&f| f & MATERIAL != 0).count();
        let reachable = to_centre.iter().zip(&self.flags).filter(|&(&d, &f)| d <= r2 && f & MATERIAL != 0);
        let (mut reachable_cells, mut uncut) = (0, 0);
        for (_, &f) in reachable {
            reachable_cells += 1;
            uncut += usize::from(f == MATERIAL);
        }
        (material, reachable_cells, uncut)
    }

    /// Squared distance (in cells) from each cell centre to the nearest
    /// centre of a `feature` cell (exact on the grid; Felzenszwalb and
    /// Huttenlocher 2012, "Distance transforms of sampled functions", Theory
    /// of Computing 8, section 2), infinite when there is none.
    fn distance_squared(&self, feature: &[bool]) -> Vec<f64> {
        let (nx, ny) = (self.nx, self.ny);
        let mut d: Vec<f64> = feature.iter().map(|&f| if f { 0.0 } else { f64::INFINITY }).collect();
        d.par_chunks_mut(nx).for_each(lower_envelope);
        let mut columns: Vec<f64> = (0..nx * ny).map(|k| d[(k % ny) * nx + k / ny]).collect();
        columns.par_chunks_mut(ny).for_each(lower_envelope);
        (0..nx * ny).map(|k| columns[(k % nx) * ny + k / nx]).collect()
    }
}

/// The first cell whose centre lies at or beyond `x` (`0..=n`).
fn first_cell(x: f64, min: f64, h: f64, n: usize) -> usize {
    let k = ((x - min) / h - 0.5).ceil();
    // Clamped to 0..=n (below MAX_CELLS): exact conversions.
    k.clamp(0.0, n as f64) as usize
}

/// One dimension of the squared distance transform in place: `f[q]` becomes
/// `min over p of (q - p)^2 + f[p]` (the lower envelope of parabolas).
fn lower_envelope(f: &mut [f64]) {
    let n = f.len();
    let sites: Vec<usize> = (0..n).filter(|&q| f[q].is_finite()).collect();
    if sites.is_empty() {
        return;
    }
    let input = f.to_vec();
    let square = |q: usize| (q * q) as f64;
    // Where the parabolas of sites p < q meet.
    let meet = |p: usize, q: usize| ((input[q] + square(q)) - (input[p] + square(p))) / (2.0 * (q - p) as f64);
    let mut hull: Vec<usize> = Vec::with_capacity(sites.len());
    let mut starts: Vec<f64> = Vec::with_capacity(sites.len());
    for &q in &sites {
        while let Some(&p) = hull.last() {
            let s = meet(p, q);
            if s <= *starts.last().unwrap_or(&f64::NEG_INFINITY) {
                hull.pop();
                starts.pop();
            } else {
                hull.push(q);
                starts.push(s);
                break;
            }
        }
        if hull.is_empty() {
            hull.push(q);
            starts.push(f64::NEG_INFINITY);
        }
    }
    let mut k = 0;
    for (q, value) in f.iter_mut().enumerate() {
        while k + 1 < hull.len() && starts[k + 1] < q as f64 {
            k += 1;
        }
        let p = hull[k];
        let dq = q as f64 - p as f64;
        *value = dq * dq + input[p];
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The transform equals the brute-force minimum over feature cells.
    #[test]
    fn distance_transform_is_the_brute_force_minimum() {
        let square = Pocket::new(vec![vec![
            Point2::new(0.0, 0.0),
            Point2::new(3.0, 0.0),
            Point2::new(3.0, 2.0),
            Point2::new(0.0, 2.0),
        ]])
        .unwrap();
        let raster = Raster::new(&square, 0.25).unwrap();
        let (nx, ny) = (raster.nx, raster.ny);
        let feature: Vec<bool> = (0..nx * ny).map(|k| (k * 7919) % 13 == 0).collect();
        let d = raster.distance_squared(&feature);
        for (k, value) in d.iter().enumerate() {
            let (i, j) = ((k % nx) as f64, (k / nx) as f64);
            let brute = (0..nx * ny)
                .filter(|&m| feature[m])
                .map(|m| ((m % nx) as f64 - i).powi(2) + ((m / nx) as f64 - j).powi(2))
                .fold(f64::INFINITY, f64::min);
            // Sums of squared small integers: exact.
            assert_eq!(value.to_bits(), brute.to_bits(), "cell {k}");
        }
    }

    proptest! {
        /// A point's row interval of a capsule contains it exactly when its
        /// distance to the segment is within the radius.
        #[test]
        fn capsule_rows_match_the_distance(ax in -5.0..5.0f64, ay in -5.0..5.0f64, bx in -5.0..5.0f64,
                                            by in -5.0..5.0f64, r in 0.1..3.0f64, x in -9.0..9.0f64, y in -9.0..9.0f64) {
            let (a, b, p) = (Point2::new(ax, ay), Point2::new(bx, by), Point2::new(x, y));
            let d = segment_distance(p, a, b);
            let inside = capsule_row(a, b, r, y).is_some_and(|(lo, hi)| lo <= x && x <= hi);
            if (d - r).abs() > 1e-9 {
                prop_assert_eq!(inside, d < r);
            }
        }
    }
}
