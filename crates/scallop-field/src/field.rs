//! Scalar fields on a [`Grid`], stored by blocks of [`tol::BLOCK`]^3 samples: a
//! block outside the band that matters is not stored and reads as `+inf`.

use rayon::prelude::*;
use scallop_geom::Point3;

use crate::{Grid, Surface, tol};

/// Samples of a scalar field; blocks outside the band are absent (`+inf`).
#[derive(Debug, Clone)]
pub struct Field {
    grid: Grid,
    nb: [usize; 3],
    blocks: Vec<Option<Box<[f64]>>>,
}

const B: usize = tol::BLOCK;

impl Field {
    /// The grid.
    #[must_use]
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The value at sample `(i, j, k)`; `+inf` beyond the band.
    #[must_use]
    pub fn value(&self, i: usize, j: usize, k: usize) -> f64 {
        let b = i / B + self.nb[0] * (j / B + self.nb[1] * (k / B));
        match &self.blocks[b] {
            Some(v) => v[i % B + B * (j % B + B * (k % B))],
            None => f64::INFINITY,
        }
    }

    /// Samples computed exactly (stored blocks times their size).
    #[must_use]
    pub fn stored_samples(&self) -> usize {
        self.blocks.iter().filter(|b| b.is_some()).count() * B * B * B
    }

    /// Whether block `b` holds a sample that could be finite: the field is
    /// stored there.
    fn stored(&self, b: usize) -> bool {
        self.blocks[b].is_some()
    }

    /// A field filled block by block, in parallel and in block order (the same
    /// values on any thread count). `fill` gets the block's first sample and
    /// returns its `B^3` values, or `None` when the whole block is beyond the band.
    fn from_blocks<F>(grid: Grid, fill: F) -> Field
    where
        F: Fn([usize; 3]) -> Option<Box<[f64]>> + Sync,
    {
        let dims = grid.dims();
        let nb = dims.map(|d| d.div_ceil(B));
        let blocks = (0..nb[0] * nb[1] * nb[2])
            .into_par_iter()
            .map(|b| fill([b % nb[0] * B, (b / nb[0]) % nb[1] * B, b / (nb[0] * nb[1]) * B]))
            .collect();
        Field { grid, nb, blocks }
    }

    /// Fills one block from a function of the sample position (samples beyond
    /// the grid read `+inf`).
    fn block_values(grid: &Grid, first: [usize; 3], f: impl Fn(Point3) -> f64) -> Box<[f64]> {
        let dims = grid.dims();
        let mut v = vec![f64::INFINITY; B * B * B];
        for k in 0..B.min(dims[2] - first[2]) {
            for j in 0..B.min(dims[1] - first[1]) {
                for i in 0..B.min(dims[0] - first[0]) {
                    v[i + B * (j + B * k)] = f(grid.point(first[0] + i, first[1] + j, first[2] + k));
                }
            }
        }
        v.into_boxed_slice()
    }
}

/// The unsigned distance from every sample to `surface` (Eq. 2.6 of Jousselin
/// 2020, Ch. 2 section 3.1), computed exactly up to `cutoff` (mm) and `+inf`
/// beyond. A block whose centre is farther than `cutoff` plus its half-diagonal
/// is skipped whole; an infinite cutoff computes every sample.
#[must_use]
pub fn distance_field(surface: &Surface, grid: Grid, cutoff: f64) -> Field {
    let h = grid.h();
    #[allow(clippy::cast_precision_loss, reason = "B is 8")]
    let half = (B - 1) as f64 * 0.5;
    let reach = half * h * 3f64.sqrt();
    Field::from_blocks(grid, |first| {
        let centre = grid.point(first[0], first[1], first[2]) + scallop_geom::Vec3::repeat(half * h);
        surface.closest(&centre, cutoff + reach)?;
        // The distance is 1-Lipschitz: the previous sample's distance plus the
        // step bounds this one's, which prunes the search from its start.
        let last = std::cell::Cell::new((f64::INFINITY, centre));
        Some(Field::block_values(&grid, first, |p| {
            let (d, q) = last.get();
            let bound = ((d + (p - q).norm()) * (1.0 + tol::LIPSCHITZ_SLACK)).min(cutoff);
            let d = surface.closest(&p, bound).map_or(f64::INFINITY, |c| c.dist2.sqrt());
            last.set((d, p));
            d
        }))
    })
}

/// The morph field of Eq. 2.7 of Jousselin 2020 (Ch. 2 section 3.1),
/// `m d(P, S_2) - (1 - m) d(P, S_1)`, from the two distance fields on one grid.
/// Its zero set lies where `d_1 / (d_1 + d_2) = m`.
#[must_use]
pub fn morph_field(d1: &Field, d2: &Field, m: f64) -> Field {
    let grid = d1.grid;
    Field::from_blocks(grid, |first| {
        let b = first[0] / B + d1.nb[0] * (first[1] / B + d1.nb[1] * (first[2] / B));
        if !(d1.stored(b) && d2.stored(b)) {
            return None;
        }
        let dims = grid.dims();
        let mut v = vec![f64::INFINITY; B * B * B];
        for k in 0..B.min(dims[2] - first[2]) {
            for j in 0..B.min(dims[1] - first[1]) {
                for i in 0..B.min(dims[0] - first[0]) {
                    let (x, y, z) = (first[0] + i, first[1] + j, first[2] + k);
                    v[i + B * (j + B * k)] = m * d2.value(x, y, z) - (1.0 - m) * d1.value(x, y, z);
                }
            }
        }
        Some(v.into_boxed_slice())
    })
}
