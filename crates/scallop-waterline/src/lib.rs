//! The waterline kernel: the closed contours, at a height z, of where a cutter
//! (flat, ball, bull-nose, cone) with its tip at z touches a triangle mesh.
//!
//! The part, seen from above by a 3-axis cutter, is the height field of the
//! exact drop-cutter `d(x, y)` (`scallop_cutter::drop_cutter`: the lowest tip
//! height at (x, y) that penetrates nothing). The cutter with its tip at height
//! z cuts into the part exactly where `d(x, y) > z`; the waterline at z is the
//! boundary of that set:
//!
//! ```text
//!   inside(z) = { (x, y) : d(x, y) > z }      waterline(z) = boundary of inside(z)
//! ```
//!
//! It is found by contouring, in the manner of marching squares (Lorensen and
//! Cline, "Marching cubes", SIGGRAPH 1987, in two dimensions), with every
//! decision taken on the exact drop-cutter, never on an interpolated height:
//! 1. `d` is sampled on a grid padded by the cutter radius (in parallel), so
//!    every border sample is outside and every loop closes inside the grid;
//!    the grid is cut into blocks, each bounded below and above (everywhere in
//!    it, not only at its samples) by drop-cutters of a smaller and a larger
//!    cutter at its centre, and a level samples only the blocks whose bounds
//!    straddle z (and their neighbours): no contour passes through the others;
//! 2. each grid edge whose ends are on different sides holds one crossing,
//!    found by bisection on the exact drop-cutter to
//!    [`WaterlineOptions::crossing_tolerance`]; the point kept is the outside
//!    end of the final bracket, so the cutter at z placed on any loop point
//!    never penetrates the part;
//! 3. each cell links its exit crossing to its entry crossing (walking the
//!    cell boundary counter-clockwise); a saddle cell (two opposite corners
//!    inside) is resolved by the drop-cutter at its centre;
//! 4. chords are split where the contour, probed by bisection along the
//!    chord's normal at its midpoint, lies farther than
//!    [`WaterlineOptions::chord_tolerance`] from it (adaptive, as OpenCAMLib's
//!    adaptive waterline refines its fibres);
//! 5. islands that no sample sees are sampled again finer around the mesh
//!    vertex they hold; then every mesh point inside the contour with a margin
//!    (vertices, and points of edges just above z) is checked to lie inside
//!    the loops, and a thin arm of inside that crosses a grid edge between two
//!    outside samples, found that way, is spliced into its loop (`arms.rs`).
//!
//! Loops are oriented with the inside (where the cutter at z would cut into
//! the part) on their left: an outer boundary runs counter-clockwise, a
//! pocket's boundary clockwise. See `docs/waterline.md`.
//!
//! ```
//! use scallop_cutter::{Cutter, CutterShape};
//! use scallop_geom::Point3;
//! use scallop_mesh::{MeshIndex, TriMesh};
//! use scallop_waterline::{WaterlineOptions, waterline};
//! // A square plateau 10 x 10 mm, 5 mm high (top and four walls).
//! let p = |x, y, z| Point3::new(x, y, z);
//! let (a, b, c, d) = (p(0., 0., 5.), p(10., 0., 5.), p(10., 10., 5.), p(0., 10., 5.));
//! let (a0, b0, c0, d0) = (p(0., 0., 0.), p(10., 0., 0.), p(10., 10., 0.), p(0., 10., 0.));
//! let soup = [[a, b, c], [a, c, d], [a0, b0, b], [a0, b, a], [b0, c0, c], [b0, c, b],
//!             [c0, d0, d], [c0, d, c], [d0, a0, a], [d0, a, d]];
//! let (mesh, _) = TriMesh::from_soup(&soup).unwrap();
//! let index = MeshIndex::build(&mesh);
//! let flat = Cutter::new(CutterShape::Flat { radius: 2.0 }, 20.0).unwrap();
//! let loops = waterline(&flat, &index, 2.0, &WaterlineOptions::default()).unwrap();
//! assert_eq!(loops.len(), 1);
//! assert!(loops[0].is_outer()); // counter-clockwise around the plateau
//! // The contour is the square offset by the cutter radius (rounded corners).
//! let x_max = loops[0].points.iter().map(|q| q.x).fold(f64::MIN, f64::max);
//! assert!((x_max - 12.0).abs() < 1e-6);
//! ```
//!
//! # Invariants
//! - Every decision (which side a sample is on) is the exact drop-cutter
//!   compared with z; the crossings are brackets of width
//!   `crossing_tolerance` on it, and each loop point is on the outside end.
//! - Loops are closed (the last point joins the first), oriented with the
//!   inside on the left, and listed in a deterministic order; the output does
//!   not depend on the number of threads (parallel work uses indexed collects).
//! - Never performs I/O; never prints.

mod arms;
mod cell;
mod contour;
mod refine;
pub use scallop_geom::tol::waterline as tol;

use std::sync::{Arc, OnceLock};

use rayon::prelude::*;
use scallop_cutter::{ClPoint, Contact, Cutter, CutterShape, drop_grid, drop_patch, drop_triangle};
use scallop_geom::{Point2, predicates::orient2d};
use scallop_mesh::MeshIndex;

/// Algorithm knobs of the waterline kernel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WaterlineOptions {
    /// Grid step of the drop-cutter sampling (mm); `None`: the cutter radius
    /// times [`tol::STEP_PER_RADIUS`]. An island or a pocket of the contour
    /// narrower than the step may fall between samples and be missed.
    pub step: Option<f64>,
    /// Width of the final bisection bracket of each contour point (mm).
    pub crossing_tolerance: f64,
    /// Largest deviation between a chord and the contour at the chord's
    /// midpoint (mm); longer chords are split.
    pub chord_tolerance: f64,
}

impl Default for WaterlineOptions {
    /// ```
    /// let o = scallop_waterline::WaterlineOptions::default();
    /// assert_eq!(o.chord_tolerance, scallop_waterline::tol::CHORD_TOLERANCE);
    /// ```
    fn default() -> Self {
        WaterlineOptions {
            step: None,
            crossing_tolerance: tol::CROSSING_TOLERANCE,
            chord_tolerance: tol::CHORD_TOLERANCE,
        }
    }
}

/// Why a waterline could not be computed. Each variant says the cause and the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum WaterlineError {
    /// The mesh has no triangles: give a part with at least one triangle.
    #[error("the mesh has no triangles; give a part with at least one triangle")]
    EmptyMesh,
    /// The height is NaN or infinite: give a finite z in mm.
    #[error("z = {z} is not a finite height; give a finite z in mm")]
    NonFiniteZ {
        /// The height given.
        z: f64,
    },
    /// The height is outside the part's z range [zmin, zmax): no contour there.
    #[error("z = {z} lies outside the part's height range [{zmin}, {zmax}); give a z in that range")]
    ZOutsidePart {
        /// The height given.
        z: f64,
        /// Lowest point of the part.
        zmin: f64,
        /// Highest point of the part (excluded: nothing is above it).
        zmax: f64,
    },
    /// The grid step is not a finite number > 0 (and larger than the crossing tolerance).
    #[error(
        "grid step {step} mm is not a finite number above the crossing tolerance {crossing} mm; give a step > 0 such as R/4"
    )]
    BadStep {
        /// The step given.
        step: f64,
        /// The crossing tolerance.
        crossing: f64,
    },
    /// The grid would have more samples than [`tol::MAX_SAMPLES`]: use a larger step.
    #[error("the sampling grid would have {nx} x {ny} samples, more than {max}; use a larger step")]
    TooManySamples {
        /// Samples along X.
        nx: f64,
        /// Samples along Y.
        ny: f64,
        /// The limit.
        max: usize,
    },
    /// A tolerance is not finite or below the rounding level of the model.
    #[error(
        "{name} = {value} mm is not a finite tolerance of at least {min:e} mm (the model's rounding level); give a larger one"
    )]
    BadTolerance {
        /// Which option.
        name: &'static str,
        /// The value given.
        value: f64,
        /// Smallest value accepted for this model.
        min: f64,
    },
}

/// A closed contour at height `z`: the last point joins the first. The
/// inside (where the cutter at z would cut into the part) is on the left.
#[derive(Debug, Clone, PartialEq)]
pub struct Loop {
    /// Tip height of the cutter (mm).
    pub z: f64,
    /// Tip positions in XY (mm), without repeating the first at the end.
    pub points: Vec<Point2>,
}

impl Loop {
    /// Signed area (shoelace formula, mm^2): positive counter-clockwise.
    ///
    /// ```
    /// use scallop_geom::Point2;
    /// let l = scallop_waterline::Loop { z: 0.0, points: vec![Point2::new(0., 0.), Point2::new(2., 0.), Point2::new(0., 1.)] };
    /// assert_eq!(l.signed_area(), 1.0);
    /// ```
    #[must_use]
    pub fn signed_area(&self) -> f64 {
        let n = self.points.len();
        let twice: f64 = (0..n)
            .map(|i| {
                let (a, b) = (self.points[i], self.points[(i + 1) % n]);
                a.x * b.y - a.y * b.x
            })
            .sum();
        0.5 * twice
    }

    /// An outer boundary (counter-clockwise, material inside) rather than the
    /// boundary of a pocket (clockwise).
    ///
    /// ```
    /// use scallop_geom::Point2;
    /// let l = scallop_waterline::Loop { z: 0.0, points: vec![Point2::new(0., 0.), Point2::new(0., 1.), Point2::new(1., 0.)] };
    /// assert!(!l.is_outer());
    /// ```
    #[must_use]
    pub fn is_outer(&self) -> bool {
        self.signed_area() > 0.0
    }

    /// Winding number of the loop around `p` (exact orientation predicates):
    /// the sum over all loops of a level is 1 inside and 0 outside.
    ///
    /// ```
    /// use scallop_geom::Point2;
    /// let l = scallop_waterline::Loop { z: 0.0, points: vec![Point2::new(0., 0.), Point2::new(2., 0.), Point2::new(0., 2.)] };
    /// assert_eq!(l.winding_number(Point2::new(0.5, 0.5)), 1);
    /// assert_eq!(l.winding_number(Point2::new(3.0, 3.0)), 0);
    /// ```
    #[must_use]
    pub fn winding_number(&self, p: Point2) -> i32 {
        let n = self.points.len();
        let mut w = 0;
        for i in 0..n {
            let (a, b) = (&self.points[i], &self.points[(i + 1) % n]);
            if a.y <= p.y {
                if b.y > p.y && orient2d(a, b, &p) > 0.0 {
                    w += 1;
                }
            } else if b.y <= p.y && orient2d(a, b, &p) < 0.0 {
                w -= 1;
            }
        }
        w
    }

    /// Length of the closed polyline (mm).
    ///
    /// ```
    /// use scallop_geom::Point2;
    /// let l = scallop_waterline::Loop { z: 0.0, points: vec![Point2::new(0., 0.), Point2::new(3., 0.), Point2::new(3., 4.)] };
    /// assert_eq!(l.length(), 12.0);
    /// ```
    #[must_use]
    pub fn length(&self) -> f64 {
        let n = self.points.len();
        (0..n).map(|i| (self.points[(i + 1) % n] - self.points[i]).norm()).sum()
    }
}

/// The waterline loops of `cutter` on the part in `index` at tip height `z`.
/// For several heights on one part, build one [`WaterlineGrid`] and call
/// [`WaterlineGrid::loops`] per height: the drop-cutter grid is shared.
///
/// # Errors
/// [`WaterlineError`]: empty mesh, z not finite or outside the part's height
/// range, bad step or tolerance, too many samples.
///
/// ```
/// use scallop_cutter::{Cutter, CutterShape};
/// use scallop_geom::Point3;
/// use scallop_mesh::{MeshIndex, TriMesh};
/// use scallop_waterline::{WaterlineError, WaterlineOptions, waterline};
/// let p = |x, y, z| Point3::new(x, y, z);
/// let (mesh, _) = TriMesh::from_soup(&[[p(0., 0., 0.), p(4., 0., 0.), p(0., 4., 3.)]]).unwrap();
/// let index = MeshIndex::build(&mesh);
/// let ball = Cutter::new(CutterShape::Ball { radius: 1.0 }, 10.0).unwrap();
/// let err = waterline(&ball, &index, f64::NAN, &WaterlineOptions::default()).unwrap_err();
/// assert!(matches!(err, WaterlineError::NonFiniteZ { .. }));
/// ```
pub fn waterline(
    cutter: &Cutter,
    index: &MeshIndex,
    z: f64,
    options: &WaterlineOptions,
) -> Result<Vec<Loop>, WaterlineError> {
    check_z(index, z)?;
    WaterlineGrid::new(cutter, index, options)?.loops(z)
}

/// The exact drop-cutter sampled on a padded grid over a part: the shared
/// first stage of every waterline height on that part and cutter.
///
/// The grid is cut into square blocks of samples. For each block, two
/// drop-cutters at its centre, of a smaller and a larger cutter (see
/// [`block_bounds`]), bound the drop-cutter everywhere in the block (between
/// the samples too). A level z samples only the blocks where the bounds
/// straddle z, and their neighbours: elsewhere the cutter at z cuts everywhere
/// in the block or nowhere, so no contour passes through it. Blocks are
/// sampled once, when a level first needs them (the same exact drop-cutter as
/// a full grid: the loops are the same).
#[derive(Debug, Clone)]
pub struct WaterlineGrid<'a> {
    cutter: &'a Cutter,
    index: &'a MeshIndex,
    options: WaterlineOptions,
    origin: Point2,
    step: f64,
    nx: usize,
    ny: usize,
    /// Tip height of "nothing under the cutter".
    floor: f64,
    /// Index slot of each triangle by its original number.
    slot_of: Arc<[u32]>,
    /// Samples per block side.
    block: usize,
    /// `block` is `1 << shift`.
    shift: u32,
    /// Blocks along X and Y.
    bx: usize,
    by: usize,
    /// Per block, row-major: bounds `[lower, upper]` of the drop-cutter over
    /// the closed square from its first sample to the first samples of the
    /// next blocks (so every grid edge and cell lies in some block's square).
    bounds: Vec<[f64; 2]>,
    /// Rounding margin of the bounds (mm): a block is decided by them only
    /// when z is farther than this from both.
    margin: f64,
    /// Per block, once sampled: its own samples.
    samples: Vec<OnceLock<Samples>>,
    /// Per block, once needed: for each of its samples, for the edges to its
    /// +x and +y neighbours, the height above which the edge is certainly
    /// inside when both ends are (see `cover_of`).
    covers: Vec<OnceLock<Vec<[f64; 2]>>>,
    /// Set once every block is sampled ([`WaterlineGrid::height`]).
    all: OnceLock<()>,
}

/// The drop-cutter at the samples of one block, row-major, x fastest.
#[derive(Debug, Clone)]
struct Samples {
    /// Samples along X in this block.
    width: usize,
    /// Tip heights.
    heights: Vec<f64>,
    /// Index slot of the triangle giving each height (`u32::MAX`: the floor).
    slots: Vec<u32>,
}

/// Where a level's contour may lie, block by block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Side {
    /// The cutter at z cuts everywhere in the block's square.
    In,
    /// Nowhere.
    Out,
    /// Somewhere: the block is sampled.
    Mixed,
}

/// One level: its height, the side of every block and of every sample.
pub(crate) struct Level {
    pub(crate) z: f64,
    sides: Vec<Side>,
    /// Per sample, row-major: the cutter at z cuts into the part there.
    inside: Vec<bool>,
}

impl<'a> WaterlineGrid<'a> {
    /// Samples the drop-cutter of `cutter` on `index` over the part's footprint
    /// widened by the cutter radius and padding.
    ///
    /// # Errors
    /// [`WaterlineError`]: empty mesh, bad step or tolerance, too many samples.
    ///
    /// ```
    /// use scallop_cutter::{Cutter, CutterShape};
    /// use scallop_geom::Point3;
    /// use scallop_mesh::{MeshIndex, TriMesh};
    /// use scallop_waterline::{WaterlineGrid, WaterlineOptions};
    /// let p = |x, y, z| Point3::new(x, y, z);
    /// let (mesh, _) = TriMesh::from_soup(&[[p(0., 0., 0.), p(4., 0., 0.), p(0., 4., 3.)]]).unwrap();
    /// let index = MeshIndex::build(&mesh);
    /// let ball = Cutter::new(CutterShape::Ball { radius: 1.0 }, 10.0).unwrap();
    /// let grid = WaterlineGrid::new(&ball, &index, &WaterlineOptions::default()).unwrap();
    /// let levels: Vec<_> = [0.5, 1.0, 2.0].iter().map(|&z| grid.loops(z).unwrap()).collect();
    /// assert!(levels.iter().all(|loops| loops.len() == 1));
    /// ```
    pub fn new(cutter: &'a Cutter, index: &'a MeshIndex, options: &WaterlineOptions) -> Result<Self, WaterlineError> {
        Self::with_progress(cutter, index, options, &|_, _| {})
    }

    /// As [`WaterlineGrid::new`], calling `progress(rows_done, rows)` as rows
    /// of the grid are sampled (from any thread).
    ///
    /// # Errors
    /// As [`WaterlineGrid::new`].
    ///
    /// ```
    /// use std::sync::atomic::{AtomicUsize, Ordering};
    /// use scallop_cutter::{Cutter, CutterShape};
    /// use scallop_geom::Point3;
    /// use scallop_mesh::{MeshIndex, TriMesh};
    /// use scallop_waterline::{WaterlineGrid, WaterlineOptions};
    /// let p = |x, y, z| Point3::new(x, y, z);
    /// let (mesh, _) = TriMesh::from_soup(&[[p(0., 0., 0.), p(4., 0., 0.), p(0., 4., 3.)]]).unwrap();
    /// let index = MeshIndex::build(&mesh);
    /// let ball = Cutter::new(CutterShape::Ball { radius: 1.0 }, 10.0).unwrap();
    /// let last = AtomicUsize::new(0);
    /// let grid = WaterlineGrid::with_progress(&ball, &index, &WaterlineOptions::default(),
    ///     &|done, _| { last.fetch_max(done, Ordering::Relaxed); }).unwrap();
    /// assert_eq!(last.into_inner(), grid.shape().1);
    /// ```
    pub fn with_progress(
        cutter: &'a Cutter,
        index: &'a MeshIndex,
        options: &WaterlineOptions,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Self, WaterlineError> {
        if index.is_empty() {
            return Err(WaterlineError::EmptyMesh);
        }
        let bounds = index.bounds();
        let scale = [bounds.min.x, bounds.min.y, bounds.min.z, bounds.max.x, bounds.max.y, bounds.max.z]
            .iter()
            .fold(1.0_f64, |m, v| m.max(v.abs()));
        let min_tol = tol::REL_MIN_TOLERANCE * scale;
        for (name, value) in
            [("crossing_tolerance", options.crossing_tolerance), ("chord_tolerance", options.chord_tolerance)]
        {
            if !(value.is_finite() && value >= min_tol) {
                return Err(WaterlineError::BadTolerance { name, value, min: min_tol });
            }
        }
        let radius = cutter.radius();
        let step = options.step.unwrap_or(radius * tol::STEP_PER_RADIUS);
        if !(step.is_finite() && step > options.crossing_tolerance) {
            return Err(WaterlineError::BadStep { step, crossing: options.crossing_tolerance });
        }
        let pad = radius + tol::PAD_CELLS * step;
        let origin = Point2::new(bounds.min.x - pad, bounds.min.y - pad);
        let count = |extent: f64| ((extent + 2.0 * pad) / step).ceil() + 1.0;
        let (nx_f, ny_f) = (count(bounds.max.x - bounds.min.x), count(bounds.max.y - bounds.min.y));
        #[allow(clippy::cast_precision_loss)] // a limit, compared in f64 to avoid overflow
        let max = tol::MAX_SAMPLES as f64;
        if !(nx_f * ny_f <= max) {
            return Err(WaterlineError::TooManySamples { nx: nx_f, ny: ny_f, max: tol::MAX_SAMPLES });
        }
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // checked above: 1 <= n <= MAX_SAMPLES
        let (nx, ny) = (nx_f as usize, ny_f as usize);
        let mut grid = Self::lazy(cutter, index, options, origin, step, [nx, ny], None);
        grid.bound_blocks(scale, progress);
        Ok(grid)
    }

    /// A grid of `n[0] x n[1]` samples from `origin` at `step`, none sampled
    /// yet, every block without bounds (sampled by the first level).
    fn lazy(
        cutter: &'a Cutter,
        index: &'a MeshIndex,
        options: &WaterlineOptions,
        origin: Point2,
        step: f64,
        [nx, ny]: [usize; 2],
        slot_of: Option<Arc<[u32]>>,
    ) -> Self {
        let floor = index.bounds().min.z - cutter.shape().profile_height() - tol::FLOOR_MARGIN;
        let slot_of = slot_of.unwrap_or_else(|| {
            let mut slot_of = vec![u32::MAX; index.len()];
            for slot in 0..index.len() {
                slot_of[index.original_index(slot)] = u32::try_from(slot).unwrap_or(u32::MAX);
            }
            slot_of.into()
        });
        // A block spans about BLOCK_SPAN_PER_RADIUS cutter radii (its bounds
        // are drop-cutters of cutters that much smaller and larger), a power of
        // two of samples (a sample's block by shifts).
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // clamped to a small range
        let shift = (tol::BLOCK_SPAN_PER_RADIUS * cutter.radius() / step)
            .log2()
            .round()
            .clamp(tol::BLOCK_SAMPLES_MIN.ilog2().into(), tol::BLOCK_SAMPLES_MAX.ilog2().into())
            as u32;
        let block = 1usize << shift;
        let (bx, by) = (nx.div_ceil(block), ny.div_ceil(block));
        WaterlineGrid {
            cutter,
            index,
            options: *options,
            origin,
            step,
            nx,
            ny,
            floor,
            slot_of,
            block,
            shift,
            bx,
            by,
            bounds: vec![[f64::NEG_INFINITY, f64::INFINITY]; bx * by],
            margin: 0.0,
            samples: (0..bx * by).map(|_| OnceLock::new()).collect(),
            covers: (0..bx * by).map(|_| OnceLock::new()).collect(),
            all: OnceLock::new(),
        }
    }

    /// Bounds every block by two drop-cutters at its centre ([`block_bounds`]),
    /// calling `progress(rows_done, rows)` as rows of blocks are bounded.
    fn bound_blocks(&mut self, scale: f64, progress: &(dyn Fn(usize, usize) + Sync)) {
        let block = self.block;
        #[allow(clippy::cast_precision_loss)]
        let half = 0.5 * block as f64 * self.step;
        // The closed square of a block lies within this distance of its centre.
        let reach = half * std::f64::consts::SQRT_2 * (1.0 + tol::REL_BLOCK_MARGIN);
        let Some((lows, (high, high_offset))) = block_bounds(self.cutter.shape(), reach) else {
            progress(self.ny, self.ny);
            return;
        };
        self.margin = tol::REL_BLOCK_MARGIN * scale;
        let (bx, by, ny, floor, index) = (self.bx, self.by, self.ny, self.floor, self.index);
        let first = self.point(0, 0);
        // The block centres, a grid: each bounding cutter dropped on it by
        // `drop_grid` (candidate lists shared along rows; the heights of
        // `drop_cutter` bit for bit).
        #[allow(clippy::cast_precision_loss)]
        let xs: Vec<f64> = (0..bx).map(|i| first.x + i as f64 * 2.0 * half + half).collect();
        #[allow(clippy::cast_precision_loss)]
        let ys: Vec<f64> = (0..by).map(|j| first.y + j as f64 * 2.0 * half + half).collect();
        let mut bounds = vec![[f64::NEG_INFINITY, f64::NEG_INFINITY]; bx * by];
        for (l, offset) in &lows {
            let cl = drop_grid(l, index, &xs, &ys, floor, &|_| {});
            for (b, c) in bounds.iter_mut().zip(&cl) {
                b[0] = b[0].max(c.tip.z - offset);
            }
        }
        let rows = |done: usize| progress((done * block).min(ny), ny);
        let cl = drop_grid(&high, index, &xs, &ys, floor, &rows);
        for (b, c) in bounds.iter_mut().zip(&cl) {
            b[1] = c.tip.z + high_offset;
        }
        self.bounds = bounds;
    }

    /// The side of every block at height `z`, with the samples (and the
    /// covers) that tracing that level reads: the blocks whose bounds straddle
    /// z and their +x, +y and +xy neighbours (whose first samples close the
    /// block's square).
    pub(crate) fn level(&self, z: f64) -> Level {
        let sides: Vec<Side> = self
            .bounds
            .iter()
            .map(|&[lower, upper]| {
                if lower > z + self.margin {
                    Side::In
                } else if upper < z - self.margin {
                    Side::Out
                } else {
                    Side::Mixed
                }
            })
            .collect();
        let (bx, by) = (self.bx, self.by);
        let mut needed = vec![false; bx * by];
        for (b, _) in sides.iter().enumerate().filter(|(_, s)| **s == Side::Mixed) {
            let (i, j) = (b % bx, b / bx);
            for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                if i + di < bx && j + dj < by {
                    needed[(j + dj) * bx + i + di] = true;
                }
            }
        }
        let todo: Vec<usize> = (0..bx * by).filter(|&b| needed[b] && self.samples[b].get().is_none()).collect();
        todo.par_iter().for_each(|&b| {
            self.block_samples(b);
        });
        let mixed: Vec<usize> =
            (0..bx * by).filter(|&b| sides[b] == Side::Mixed && self.covers[b].get().is_none()).collect();
        mixed.par_iter().with_min_len(4).for_each(|&b| {
            self.block_cover(b);
        });
        let (nx, shift) = (self.nx, self.shift);
        let mut inside = vec![false; nx * self.ny];
        inside.par_chunks_mut(nx).enumerate().for_each(|(j, row)| {
            let bj = j >> shift;
            for (bi, run) in row.chunks_mut(self.block).enumerate() {
                let b = bj * bx + bi;
                match sides[b] {
                    Side::In => run.fill(true),
                    Side::Out => {}
                    Side::Mixed => {
                        let s = self.block_samples(b);
                        let heights = &s.heights[(j & (self.block - 1)) * s.width..][..s.width];
                        for (v, &h) in run.iter_mut().zip(heights) {
                            *v = h > z;
                        }
                    }
                }
            }
        });
        Level { z, sides, inside }
    }

    /// The samples of block `b`, sampled on first use.
    fn block_samples(&self, b: usize) -> &Samples {
        self.samples[b].get_or_init(|| {
            let ([i0, i1], [j0, j1]) = self.block_range(b);
            #[allow(clippy::cast_precision_loss)]
            let xs: Vec<f64> = (i0..i1).map(|i| self.origin.x + i as f64 * self.step).collect();
            #[allow(clippy::cast_precision_loss)]
            let ys: Vec<f64> = (j0..j1).map(|j| self.origin.y + j as f64 * self.step).collect();
            let cl = drop_patch(self.cutter, self.index, &xs, &ys, self.floor);
            Samples {
                width: i1 - i0,
                heights: cl.iter().map(|c| c.tip.z).collect(),
                slots: cl
                    .iter()
                    .map(|c| match c.contact {
                        Contact::Floor => u32::MAX,
                        Contact::Vertex { triangle, .. }
                        | Contact::Edge { triangle, .. }
                        | Contact::Facet { triangle, .. } => self.slot_of[triangle],
                    })
                    .collect(),
            }
        })
    }

    /// The covers of the edges from the samples of block `b` (its +x, +y and
    /// +xy neighbours sampled on first use).
    fn block_cover(&self, b: usize) -> &Vec<[f64; 2]> {
        self.covers[b].get_or_init(|| {
            let ([i0, i1], [j0, j1]) = self.block_range(b);
            let (nx, ny) = (self.nx, self.ny);
            let own = self.block_samples(b);
            let slot = |i: usize, j: usize| {
                if i < i1 && j < j1 { own.slots[(j - j0) * own.width + (i - i0)] } else { self.sample(i, j).1 }
            };
            (j0..j1)
                .flat_map(|j| (i0..i1).map(move |i| (i, j)))
                .map(|(i, j)| {
                    let here = slot(i, j);
                    [
                        if i + 1 < nx {
                            self.cover_of([i, j], here, [i + 1, j], slot(i + 1, j))
                        } else {
                            f64::NEG_INFINITY
                        },
                        if j + 1 < ny {
                            self.cover_of([i, j], here, [i, j + 1], slot(i, j + 1))
                        } else {
                            f64::NEG_INFINITY
                        },
                    ]
                })
                .collect()
        })
    }

    /// The samples `[i0, i1) x [j0, j1)` of block `b`.
    pub(crate) fn block_range(&self, b: usize) -> ([usize; 2], [usize; 2]) {
        let (i0, j0) = ((b % self.bx) * self.block, (b / self.bx) * self.block);
        ([i0, (i0 + self.block).min(self.nx)], [j0, (j0 + self.block).min(self.ny)])
    }

    /// The block holding sample (i, j) and the sample's number in it.
    fn locate(&self, i: usize, j: usize) -> (usize, usize) {
        let (bi, bj) = (i >> self.shift, j >> self.shift);
        let b = bj * self.bx + bi;
        let mask = self.block - 1;
        let width = self.block.min(self.nx - (bi << self.shift));
        (b, (j & mask) * width + (i & mask))
    }

    /// Drop-cutter height and contact slot at sample (i, j) (sampled on first use).
    pub(crate) fn sample(&self, i: usize, j: usize) -> (f64, u32) {
        let (b, k) = self.locate(i, j);
        let s = self.block_samples(b);
        debug_assert_eq!(s.heights.len() % s.width, 0);
        (s.heights[k], s.slots[k])
    }

    /// Whether the cutter at the level's height cuts into the part at sample (i, j).
    pub(crate) fn inside(&self, level: &Level, i: usize, j: usize) -> bool {
        level.inside[j * self.nx + i]
    }

    /// The blocks of `level` where its contour may pass, in increasing order.
    pub(crate) fn mixed_blocks<'l>(&self, level: &'l Level) -> impl Iterator<Item = usize> + 'l {
        level.sides.iter().enumerate().filter(|(_, s)| **s == Side::Mixed).map(|(b, _)| b)
    }

    /// The cover (see `cover_of`) of the edge from sample (i, j) to its +x
    /// (`dir` 0) or +y (1) neighbour, both inside at the level: `+inf` (no gap
    /// possible) where a block holding the edge is inside throughout.
    pub(crate) fn cover(&self, level: &Level, [i, j]: [usize; 2], dir: usize) -> f64 {
        let (b, k) = self.locate(i, j);
        if level.sides[b] == Side::In {
            return f64::INFINITY;
        }
        // An edge on the first row or column of its block lies in the
        // square of the block before it too.
        let other = if dir == 0 {
            (j % self.block == 0 && j > 0).then(|| b - self.bx)
        } else {
            (i % self.block == 0 && i > 0).then(|| b - 1)
        };
        if other.is_some_and(|o| level.sides[o] == Side::In) {
            return f64::INFINITY;
        }
        self.block_cover(b)[k][dir]
    }

    /// The height below which the grid edge from sample `a` to sample `b` is
    /// entirely inside whenever both ends are: the larger of the height of
    /// `a`'s triangle at `b` and of `b`'s triangle at `a`. The cutter at z cuts
    /// one triangle on a convex set of positions (the cutter and the triangle
    /// are convex), so a triangle above z at both ends is above z along the
    /// whole edge. Where neither is, a gap may hide between the samples: the
    /// edge is walked at that level (`refine::Local::gaps`).
    /// `sa` and `sb` are the contact slots of the samples.
    fn cover_of(&self, a: [usize; 2], sa: u32, b: [usize; 2], sb: u32) -> f64 {
        if sa == u32::MAX || sb == u32::MAX {
            return f64::NEG_INFINITY; // an end on the floor is never inside
        }
        if sa == sb {
            return f64::INFINITY;
        }
        let at = |slot: u32, p: Point2| {
            let slot = slot as usize;
            let mut best = ClPoint::floor(p, f64::NEG_INFINITY);
            let ix = self.index;
            drop_triangle(self.cutter, ix.corners(slot), ix.normal(slot), ix.original_index(slot), &mut best);
            best.tip.z
        };
        at(sa, self.point(b[0], b[1])).max(at(sb, self.point(a[0], a[1])))
    }

    /// Samples along X and Y.
    #[must_use]
    pub fn shape(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// The first sample (lowest x and y), mm; sample (i, j) is at
    /// `origin + (i, j) * step`.
    #[must_use]
    pub fn origin(&self) -> Point2 {
        self.origin
    }

    /// The grid step (mm).
    #[must_use]
    pub fn step(&self) -> f64 {
        self.step
    }

    /// The drop-cutter tip height at sample `(i, j)` (mm; `i` below the first
    /// and `j` below the second number of [`WaterlineGrid::shape`]).
    #[must_use]
    pub fn height(&self, i: usize, j: usize) -> f64 {
        // Every block at once, in parallel, the first time.
        self.all.get_or_init(|| {
            (0..self.samples.len()).into_par_iter().for_each(|b| {
                self.block_samples(b);
            });
        });
        self.sample(i, j).0
    }

    /// The part's height range `[zmin, zmax)` where waterlines exist.
    #[must_use]
    pub fn z_range(&self) -> (f64, f64) {
        let b = self.index.bounds();
        (b.min.z, b.max.z)
    }

    /// The loops at tip height `z`, in a deterministic order (by their first
    /// grid crossing), each starting at its first grid crossing (or, where an
    /// arm was spliced in across it, at a later point of the loop).
    ///
    /// # Errors
    /// [`WaterlineError::NonFiniteZ`], [`WaterlineError::ZOutsidePart`].
    pub fn loops(&self, z: f64) -> Result<Vec<Loop>, WaterlineError> {
        check_z(self.index, z)?;
        let probe = refine::Probe {
            cutter: self.cutter,
            index: self.index,
            z,
            tolerance: self.options.crossing_tolerance,
            step: self.step,
        };
        let level = self.level(z);
        let chains = contour::trace(self, &level, &probe);
        let mut loops = refine::refine_loops(&probe, &chains, self.options.chord_tolerance, z);
        loops.extend(self.islands(&level));
        arms::mend(self, &probe, self.options.chord_tolerance, &mut loops);
        Ok(loops)
    }

    /// Islands of inside that no grid sample sees: each contains the top
    /// vertex of a triangle above z (the cutter cuts a triangle on a convex
    /// set that holds the part of the triangle above z), so a vertex above z
    /// in a cell whose block of 3 x 3 cells has every sample outside marks
    /// one. A square 3 cells wide centred on the vertex is sampled again
    /// [`tol::ISLAND_REFINE`] times finer, the vertex itself a sample (inside,
    /// so an island of any size is seen), and contoured; the loops found there
    /// (whose finer border is outside) are added, each once. An island that
    /// reaches past its block is not looked for (the sampling limit); a thin
    /// arm of a larger region is looked for after this (`arms.rs`).
    fn islands(&self, level: &Level) -> Vec<Loop> {
        let (nx, ny, z) = (self.nx, self.ny, level.z);
        let outside = |i: usize, j: usize| !self.inside(level, i, j);
        let mut peaks: Vec<Point2> = Vec::new();
        for slot in 0..self.index.len() {
            for v in self.index.corners(slot) {
                if v.z <= z {
                    continue;
                }
                let (fx, fy) = ((v.x - self.origin.x) / self.step, (v.y - self.origin.y) / self.step);
                #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)] // the padded grid holds the part
                let (i, j) = (fx.floor().max(1.0) as usize, fy.floor().max(1.0) as usize);
                if i + 2 < nx && j + 2 < ny && (j - 1..j + 3).all(|jj| (i - 1..i + 3).all(|ii| outside(ii, jj))) {
                    peaks.push(Point2::new(v.x, v.y));
                }
            }
        }
        peaks.sort_unstable_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        peaks.dedup();
        let mut found: Vec<Loop> = Vec::new();
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let half = (1.5 * tol::ISLAND_REFINE) as usize;
        let fine = self.step / tol::ISLAND_REFINE;
        for v in peaks {
            if found.iter().any(|f| f.winding_number(v) != 0) {
                continue;
            }
            // The vertex is a sample of the finer grid: it is inside, so its island is seen.
            #[allow(clippy::cast_precision_loss)]
            let origin = Point2::new(v.x - half as f64 * fine, v.y - half as f64 * fine);
            let n = 2 * half + 1;
            let patch =
                Self::lazy(self.cutter, self.index, &self.options, origin, fine, [n, n], Some(self.slot_of.clone()));
            let border_in =
                (0..n).any(|k| [(k, 0), (k, n - 1), (0, k), (n - 1, k)].iter().any(|&(a, b)| patch.sample(a, b).0 > z));
            if border_in {
                continue;
            }
            let probe = refine::Probe {
                cutter: self.cutter,
                index: self.index,
                z,
                tolerance: self.options.crossing_tolerance,
                step: fine,
            };
            let chains = contour::trace(&patch, &patch.level(z), &probe);
            for l in refine::refine_loops(&probe, &chains, self.options.chord_tolerance, z) {
                if !found.iter().any(|f| f.winding_number(l.points[0]) != 0 || l.winding_number(f.points[0]) != 0) {
                    found.push(l);
                }
            }
        }
        found
    }

    fn point(&self, i: usize, j: usize) -> Point2 {
        #[allow(clippy::cast_precision_loss)]
        Point2::new(self.origin.x + i as f64 * self.step, self.origin.y + j as f64 * self.step)
    }
}

/// A cutter and the offset of its tip (mm) that bound the drop-cutter (see [`block_bounds`]).
type Bound = (Cutter, f64);

/// Cutters with an offset of their tip that bound the drop-cutter over a
/// disc: for every point `p` within `d` of a point `c`, the exact drop-cutter
/// at `p` is at least `drop(cutter, c) - offset` for each lower cutter and at
/// most `drop(upper, c) + offset`; `None` where the upper shape cannot be
/// built. No lower cutter (`d` at least the radius): the drop-cutter is not
/// bounded from below.
///
/// The drop-cutter at `p` is `max over the part's points q of q.z - h(|q - p|)`
/// for the profile `h` (infinite beyond the radius: the shank). A profile
/// `h'` with `h(|q - p|) <= h'(|q - c|) + offset` for every q (the cutter of
/// profile `h'` at `c`, raised by the offset, lies inside the cutter at `p`)
/// gives a lower bound; one with `h''(|q - c|) - offset <= h(|q - p|)` (the
/// cutter at `p` lies inside the one at `c`, lowered) the upper. With
/// `|p - c| <= d`:
/// - flat R: flat R - d and flat R + d;
/// - ball R: ball R - d raised by d (its centre at the height of the big
///   ball's, at most d away: internally tangent at most); also a smaller ball
///   s = R - sqrt(d^2 + k^2) raised by sqrt(d^2 + k^2) - k, k = R / 2 (its
///   centre k below the big ball's, so the two are tangent at most; its shank,
///   of radius s within d of the axis, stays inside the big ball's slice
///   of radius sqrt(R^2 - k^2) above its centre when `s + d` is at most that):
///   nearer the surface under a flat part. Above: bull-nose R + d with
///   corner R (the ball swept over a disc of radius d);
/// - bull-nose (R, r) (a ball r swept over a disc of radius R - r): bull-nose
///   (R - d, r) while d <= R - r, else ball R - d raised by d - (R - r) (inside
///   the ball r at the disc's point nearest `c`); bull-nose (R + d, r) above;
/// - cone R of half angle a: cone R - d raised by d cot a, and cone R + d
///   lowered by d cot a (the triangle inequality on `|q - c| cot a`).
fn block_bounds(shape: &CutterShape, d: f64) -> Option<(Vec<Bound>, Bound)> {
    let mut lower = Vec::new();
    let upper = match *shape {
        CutterShape::Flat { radius } => {
            if radius > d {
                lower.push((CutterShape::Flat { radius: radius - d }, 0.0));
            }
            (CutterShape::Flat { radius: radius + d }, 0.0)
        }
        CutterShape::Ball { radius } => {
            if radius > d {
                lower.push((CutterShape::Ball { radius: radius - d }, d));
            }
            let k = 0.5 * radius;
            let far = d.hypot(k);
            let s = radius - far;
            if s > 0.0 && s + d <= (radius * radius - k * k).sqrt() {
                lower.push((CutterShape::Ball { radius: s }, far - k));
            }
            (CutterShape::Bull { radius: radius + d, corner: radius }, 0.0)
        }
        CutterShape::Bull { radius, corner } => {
            if d <= radius - corner {
                lower.push((CutterShape::Bull { radius: radius - d, corner }, 0.0));
            } else if radius > d {
                lower.push((CutterShape::Ball { radius: radius - d }, d - (radius - corner)));
            }
            (CutterShape::Bull { radius: radius + d, corner }, 0.0)
        }
        CutterShape::Cone { radius, half_angle } => {
            let rise = d / half_angle.tan();
            if radius > d {
                lower.push((CutterShape::Cone { radius: radius - d, half_angle }, rise));
            }
            (CutterShape::Cone { radius: radius + d, half_angle }, rise)
        }
    };
    let build = |s: CutterShape| Cutter::new(s, s.profile_height() + 1.0).ok();
    // A lower shape that cannot be built (too small a radius) is left out.
    let lower = lower.into_iter().filter_map(|(s, offset)| Some((build(s)?, offset))).collect();
    Some((lower, (build(upper.0)?, upper.1)))
}

fn check_z(index: &MeshIndex, z: f64) -> Result<(), WaterlineError> {
    if !z.is_finite() {
        return Err(WaterlineError::NonFiniteZ { z });
    }
    if index.is_empty() {
        return Err(WaterlineError::EmptyMesh);
    }
    let b = index.bounds();
    if !(z >= b.min.z && z < b.max.z) {
        return Err(WaterlineError::ZOutsidePart { z, zmin: b.min.z, zmax: b.max.z });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;
    use scallop_cutter::{Cutter, CutterShape, drop_cutter};
    use scallop_geom::{Point2, Point3};
    use scallop_mesh::{MeshIndex, TriMesh};

    use super::{WaterlineGrid, WaterlineOptions, block_bounds};

    /// Every cutter shape of radius `r` (0 <= `t` < 1 picks the corner and the cone angle).
    fn shapes(r: f64, t: f64) -> [CutterShape; 4] {
        [
            CutterShape::Flat { radius: r },
            CutterShape::Ball { radius: r },
            CutterShape::Bull { radius: r, corner: r * (0.05 + 0.95 * t) },
            CutterShape::Cone { radius: r, half_angle: 0.2 + 1.1 * t },
        ]
    }

    /// A terrain of 6 x 6 cells of 2 mm over heights `h` (row-major, 7 x 7),
    /// with cliffs where a height is large.
    fn terrain(h: &[f64]) -> MeshIndex {
        let at = |i: usize, j: usize| Point3::new(i as f64 * 2.0, j as f64 * 2.0, h[j * 7 + i]);
        let mut soup = Vec::new();
        for j in 0..6 {
            for i in 0..6 {
                soup.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                soup.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        MeshIndex::build(&TriMesh::from_soup(&soup).expect("terrain").0)
    }

    fn heights() -> impl Strategy<Value = Vec<f64>> {
        prop::collection::vec((0.0..3.0f64, prop::bool::weighted(0.2)), 49)
            .prop_map(|v| v.into_iter().map(|(h, cliff)| if cliff { h + 6.0 } else { h }).collect())
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, .. ProptestConfig::default() })]

        /// The block bounds hold at every point within their reach (not only at
        /// samples), for every cutter shape: each lower bound is at most the
        /// exact drop-cutter there, the upper bound at least.
        #[test]
        fn block_bounds_hold_over_the_disc(
            h in heights(),
            r in 0.5..3.0f64,
            t in 0.0..1.0f64,
            frac in 0.02..1.2f64,
            c in (1.0..11.0f64, 1.0..11.0f64),
            at in prop::collection::vec((0.0..1.0f64, 0.0..std::f64::consts::TAU), 12),
        ) {
            let index = terrain(&h);
            let floor = -20.0;
            let (d, c) = (frac * r, Point2::new(c.0, c.1));
            for shape in shapes(r, t) {
                let cutter = Cutter::new(shape, 50.0).expect("cutter");
                let Some((lows, (high, high_offset))) = block_bounds(&shape, d) else { continue };
                let lowers: Vec<f64> =
                    lows.iter().map(|(l, offset)| drop_cutter(l, &index, c, floor).tip.z - offset).collect();
                let upper = drop_cutter(&high, &index, c, floor).tip.z + high_offset;
                for &(rho, phi) in &at {
                    // The rim of the disc too (rho near 1), where the bounds are tight.
                    let p = c + scallop_geom::Vec2::new(phi.cos(), phi.sin()) * (d * rho.sqrt());
                    let exact = drop_cutter(&cutter, &index, p, floor).tip.z;
                    for (k, &lower) in lowers.iter().enumerate() {
                        prop_assert!(lower <= exact + 1e-9, "{shape:?} d {d}: lower {k} {lower} > {exact} at {p:?}");
                    }
                    prop_assert!(exact <= upper + 1e-9, "{shape:?} d {d}: {exact} > upper {upper} at {p:?}");
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 12, .. ProptestConfig::default() })]

        /// The grid that samples only the blocks whose bounds straddle a level
        /// gives the same loops as the grid that samples every block.
        #[test]
        fn skipped_blocks_give_the_same_loops(
            h in heights(),
            r in 0.8..2.0f64,
            t in 0.0..1.0f64,
            levels in prop::collection::vec(0.0..1.0f64, 3),
        ) {
            let index = terrain(&h);
            let b = index.bounds();
            for shape in shapes(r, t) {
                let cutter = Cutter::new(shape, 50.0).expect("cutter");
                // A step of R / 8: blocks of several samples, bounded.
                let options = WaterlineOptions { step: Some(r / 8.0), ..WaterlineOptions::default() };
                let lazy = WaterlineGrid::new(&cutter, &index, &options).expect("grid");
                prop_assert!(lazy.bounds.iter().any(|&[lo, hi]| lo > f64::NEG_INFINITY && hi < f64::INFINITY));
                let mut full = WaterlineGrid::new(&cutter, &index, &options).expect("grid");
                full.bounds.iter_mut().for_each(|x| *x = [f64::NEG_INFINITY, f64::INFINITY]);
                for &f in &levels {
                    let z = b.min.z + f * (b.max.z - b.min.z);
                    prop_assert_eq!(lazy.loops(z).expect("lazy"), full.loops(z).expect("full"), "{:?} z {}", shape, z);
                }
            }
        }
    }
}
