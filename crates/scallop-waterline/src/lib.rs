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

use rayon::prelude::*;
use scallop_cutter::{ClPoint, Contact, Cutter, drop_grid, drop_triangle};
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
#[derive(Debug, Clone)]
pub struct WaterlineGrid<'a> {
    cutter: &'a Cutter,
    index: &'a MeshIndex,
    options: WaterlineOptions,
    origin: Point2,
    step: f64,
    nx: usize,
    ny: usize,
    /// Drop-cutter tip heights, row-major, x fastest.
    heights: Vec<f64>,
    /// Index slot of the triangle giving each height (`u32::MAX`: the floor).
    slots: Vec<u32>,
    /// Per sample, for the edges to its +x and +y neighbours: the height above
    /// which the edge is certainly inside when both ends are (see `cover_of`).
    cover: Vec<[f64; 2]>,
}

/// Rows of the grid sampled per `drop_grid` call (bounds the 64-byte cutter
/// locations held at once).
const ROWS_PER_BATCH: usize = 64;

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
        Ok(Self::sample(cutter, index, options, origin, step, [nx, ny], progress))
    }

    /// Samples the drop-cutter on `n[0] x n[1]` points from `origin` at `step`.
    fn sample(
        cutter: &'a Cutter,
        index: &'a MeshIndex,
        options: &WaterlineOptions,
        origin: Point2,
        step: f64,
        [nx, ny]: [usize; 2],
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Self {
        #[allow(clippy::cast_precision_loss)]
        let xs: Vec<f64> = (0..nx).map(|i| origin.x + i as f64 * step).collect();
        #[allow(clippy::cast_precision_loss)]
        let ys: Vec<f64> = (0..ny).map(|j| origin.y + j as f64 * step).collect();
        let floor = index.bounds().min.z - cutter.shape().profile_height() - tol::FLOOR_MARGIN;
        let mut slot_of = vec![u32::MAX; index.len()];
        for slot in 0..index.len() {
            slot_of[index.original_index(slot)] = u32::try_from(slot).unwrap_or(u32::MAX);
        }
        let mut heights = Vec::with_capacity(nx * ny);
        let mut slots = Vec::with_capacity(nx * ny);
        let done = std::sync::atomic::AtomicUsize::new(0);
        for rows in ys.chunks(ROWS_PER_BATCH) {
            let cl = drop_grid(cutter, index, &xs, rows, floor, &|_| {
                let d = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(d, ny);
            });
            heights.par_extend(cl.par_iter().map(|c| c.tip.z));
            slots.par_extend(cl.par_iter().map(|c| match c.contact {
                Contact::Floor => u32::MAX,
                Contact::Vertex { triangle, .. } | Contact::Edge { triangle, .. } | Contact::Facet { triangle, .. } => {
                    slot_of[triangle]
                }
            }));
        }
        let mut grid =
            WaterlineGrid { cutter, index, options: *options, origin, step, nx, ny, heights, slots, cover: Vec::new() };
        grid.cover = (0..nx * ny)
            .into_par_iter()
            .with_min_len(256)
            .map(|k| {
                let (i, j) = (k % nx, k / nx);
                [
                    if i + 1 < nx { grid.cover_of([i, j], [i + 1, j]) } else { f64::NEG_INFINITY },
                    if j + 1 < ny { grid.cover_of([i, j], [i, j + 1]) } else { f64::NEG_INFINITY },
                ]
            })
            .collect();
        grid
    }

    /// The height below which the grid edge from sample `a` to sample `b` is
    /// entirely inside whenever both ends are: the larger of the height of
    /// `a`'s triangle at `b` and of `b`'s triangle at `a`. The cutter at z cuts
    /// one triangle on a convex set of positions (the cutter and the triangle
    /// are convex), so a triangle above z at both ends is above z along the
    /// whole edge. Where neither is, a gap may hide between the samples: the
    /// edge is walked at that level (`refine::Local::gaps`).
    fn cover_of(&self, a: [usize; 2], b: [usize; 2]) -> f64 {
        let (ka, kb) = (a[1] * self.nx + a[0], b[1] * self.nx + b[0]);
        let (sa, sb) = (self.slots[ka], self.slots[kb]);
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
        self.heights[j * self.nx + i]
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
        let chains = contour::trace(self, &probe);
        let mut loops = refine::refine_loops(&probe, &chains, self.options.chord_tolerance, z);
        loops.extend(self.islands(z));
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
    fn islands(&self, z: f64) -> Vec<Loop> {
        let (nx, ny) = (self.nx, self.ny);
        let outside = |i: usize, j: usize| self.heights[j * nx + i] <= z;
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
            let patch = Self::sample(self.cutter, self.index, &self.options, origin, fine, [n, n], &|_, _| {});
            let border_in = (0..n)
                .any(|k| [(k, 0), (k, n - 1), (0, k), (n - 1, k)].iter().any(|&(a, b)| patch.heights[b * n + a] > z));
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
            let chains = contour::trace(&patch, &probe);
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
