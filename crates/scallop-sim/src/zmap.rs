//! The z-map stock: a height field on a regular XY grid, cut by swept cutters.

use std::fmt;
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::{Aabb3, Eps, Point2, Point3};
use scallop_mesh::MeshIndex;
use scallop_toolpath::{Move, MoveKind, Toolpath};

use crate::SimError;
use crate::envelope::SweptMove;
use crate::tol::GRID_SNAP;

/// The largest number of cells a [`ZMap`] may have (16 bytes each): 16 million, 256 MB
/// for the stock and as much again for the part's height field, and a few minutes of
/// cutting and verification on 2 cores (docs/simulation.md); refused before any allocation.
pub const MAX_CELLS: usize = 16_000_000;

/// Rows per band: the unit of parallel work. Fixed, so the partition (and so
/// the order of every floating-point sum) does not depend on the thread count.
const BAND_ROWS: usize = 8;

/// Cells per tile: a run of cells of one row sharing an upper bound of their
/// heights, so that a move skips whole tiles it provably cannot lower.
const TILE: usize = 16;

/// One move of one [`ZMap::cut`] call: `operation` counts the calls on the
/// stock (0 for the first), `index` is the move's position in its toolpath.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct MoveId {
    /// Which [`ZMap::cut`] call (0-based).
    pub operation: u32,
    /// Index of the move in that call's toolpath.
    pub index: u32,
}

impl fmt::Display for MoveId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "move {} of operation {}", self.index, self.operation)
    }
}

impl MoveId {
    fn pack(self) -> u64 {
        ((u64::from(self.operation) << 32) | u64::from(self.index)) + 1
    }

    fn unpack(v: u64) -> Option<MoveId> {
        let v = v.checked_sub(1)?;
        // INVARIANT: both halves of a packed id came from u32 values.
        Some(MoveId { operation: (v >> 32) as u32, index: (v & 0xffff_ffff) as u32 })
    }
}

/// A rapid (or retract) move that removed stock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RapidHit {
    /// The move.
    pub id: MoveId,
    /// Centre of the cell it cut deepest.
    pub at: Point2,
    /// How much it lowered that cell (mm).
    pub depth: f64,
}

/// Which non-cutting part of the tool touched the stock.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToolPart {
    /// The shank (or stock above the flutes within the cutter radius).
    Shank,
    /// Holder segment number (bottom first).
    Holder(usize),
}

impl ToolPart {
    /// A word for messages.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            ToolPart::Shank => "shank",
            ToolPart::Holder(_) => "holder",
        }
    }
}

/// A move that drove the shank or holder into the in-process stock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Collision {
    /// The move.
    pub id: MoveId,
    /// The part of the tool.
    pub part: ToolPart,
    /// Centre of the cell where the penetration is deepest.
    pub at: Point2,
    /// Stock height above the part's lower face there (mm).
    pub depth: f64,
}

/// What one [`ZMap::cut`] did, move by move.
#[derive(Debug, Clone, PartialEq)]
pub struct CutReport {
    /// The operation number given to this call's [`MoveId`]s.
    pub operation: u32,
    /// Volume removed by each move (mm^3), in program order.
    pub removed_by_move: Vec<f64>,
    /// Total removed volume (mm^3): the sum of `removed_by_move`.
    pub removed_volume: f64,
    /// Number of [`MoveKind::Feed`] moves.
    pub feed_moves: usize,
    /// Feed moves that lowered no cell by more than the stock's rounding epsilon.
    pub air_feed_moves: usize,
    /// Length of the feed moves (mm).
    pub feed_length_mm: f64,
    /// Length of the feed moves that cut air (mm).
    pub air_feed_length_mm: f64,
    /// Rapid and retract moves that removed stock, in program order (errors).
    pub rapid_hits: Vec<RapidHit>,
    /// Shank and holder collisions with the in-process stock, in program order (errors).
    pub collisions: Vec<Collision>,
}

impl CutReport {
    /// Share of feed moves that cut air, in [0, 1] (0 when there are none).
    ///
    /// ```
    /// use scallop_cutter::{Cutter, CutterShape};
    /// use scallop_geom::{Aabb3, Point3};
    /// use scallop_sim::ZMap;
    /// use scallop_toolpath::{Move, MoveKind, Toolpath};
    /// let stock = Aabb3 { min: Point3::new(0.0, 0.0, -2.0), max: Point3::new(10.0, 10.0, 0.0) };
    /// let mut zmap = ZMap::new(stock, 0.5).unwrap();
    /// let flat = Cutter::new(CutterShape::Flat { radius: 1.0 }, 5.0).unwrap();
    /// let mut path = Toolpath::new(500.0);
    /// path.push(Move::new(MoveKind::Rapid, Point3::new(-2.0, 5.0, -1.0)));
    /// path.push(Move::new(MoveKind::Feed, Point3::new(12.0, 5.0, -1.0))); // cuts a slot
    /// path.push(Move::new(MoveKind::Feed, Point3::new(-2.0, 5.0, -1.0))); // back through it: air
    /// let report = zmap.cut(&flat, &path).unwrap();
    /// assert_eq!((report.feed_moves, report.air_feed_moves), (2, 1));
    /// assert_eq!(report.air_cut_share(), 0.5);
    /// assert!((report.air_length_share() - 0.5).abs() < 1e-12);
    /// assert!(report.check().is_ok());
    /// ```
    #[must_use]
    pub fn air_cut_share(&self) -> f64 {
        air_share(self.air_feed_moves, self.feed_moves)
    }

    /// Share of the feed length that cut air, in [0, 1] (0 with no feed):
    /// a few long passes in material weigh more than many short moves of a
    /// helix in air, unlike [`CutReport::air_cut_share`].
    #[must_use]
    pub fn air_length_share(&self) -> f64 {
        if self.feed_length_mm > 0.0 { self.air_feed_length_mm / self.feed_length_mm } else { 0.0 }
    }

    /// The safety verdict of the cut: rapid hits first, then collisions.
    ///
    /// # Errors
    /// [`SimError::RapidIntoStock`] when a rapid or retract removed stock,
    /// [`SimError::HolderCollision`] when the shank or holder touched it.
    pub fn check(&self) -> Result<(), SimError> {
        safety_verdict(&self.rapid_hits, &self.collisions, |collisions| SimError::HolderCollision { collisions })
    }
}

/// Share of `feed` moves that cut air, in [0, 1] (0 when there are none): the
/// [`CutReport::air_cut_share`] of both stocks.
pub(crate) fn air_share(air: usize, feed: usize) -> f64 {
    if feed == 0 {
        0.0
    } else {
        // Counts far below 2^52: exact conversions.
        air as f64 / feed as f64
    }
}

/// The safety verdict of a cut on either stock: rapid hits first, then the
/// collisions as `collision_error(collisions)`.
pub(crate) fn safety_verdict<C: Clone>(
    rapid_hits: &[RapidHit],
    collisions: &[C],
    collision_error: impl FnOnce(Vec<C>) -> SimError,
) -> Result<(), SimError> {
    if !rapid_hits.is_empty() {
        return Err(SimError::RapidIntoStock { count: rapid_hits.len(), hits: rapid_hits.to_vec() });
    }
    if !collisions.is_empty() {
        return Err(collision_error(collisions.to_vec()));
    }
    Ok(())
}

/// A height-field stock: one z per cell of a regular XY grid over a stock box,
/// sampled at cell centres, never below the box bottom.
///
/// ```
/// use scallop_geom::{Aabb3, Point3};
/// use scallop_sim::ZMap;
/// let stock = Aabb3 { min: Point3::new(0.0, 0.0, -5.0), max: Point3::new(10.0, 4.0, 0.0) };
/// let zmap = ZMap::new(stock, 0.5).unwrap();
/// assert_eq!((zmap.nx(), zmap.ny()), (20, 8));
/// assert_eq!(zmap.volume(), 200.0);
/// assert!(ZMap::new(stock, 0.0).is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ZMap {
    stock: Aabb3,
    nx: usize,
    ny: usize,
    cell_x: f64,
    cell_y: f64,
    heights: Vec<f64>,
    last_cut: Vec<u64>,
    operations: u32,
    eps: f64,
}

/// Largest distance between a helical arc and the chords it is simulated by
/// (mm): helices are the one case not solved in closed form (their floor
/// `z(theta) + h(rho(theta))` has no convexity to exploit); planar arcs are exact.
const HELIX_SAGITTA: f64 = 1e-4;

/// Largest number of chords of one helical move.
const MAX_HELIX_CHORDS: f64 = 1e6;

/// A move (or a chord of a helical move) prepared for the per-cell solve.
struct Plan {
    /// The move's index in the toolpath.
    id: u32,
    /// XY box of the tip's path.
    box_lo: Point2,
    box_hi: Point2,
    /// Whether the tip's path is an arc (columns from the box, not the stadium).
    arc: bool,
    cutter: SweptMove,
    /// First and one-past-last disc in `discs`.
    discs: (usize, usize),
    /// Lowest z any part of the tool reaches during the move.
    z_low: f64,
    /// Lowest z of the shank and holder discs.
    disc_low: f64,
    reach: f64,
    from: Point2,
    to: Point2,
    rapid: bool,
}

impl Plan {
    #[allow(clippy::too_many_arguments)] // private; the pieces of one move.
    fn new(
        id: u32,
        cutter: SweptMove,
        discs: &[SweptMove],
        first: usize,
        parts: &[(f64, f64, ToolPart)],
        from: &Point3,
        to: &Point3,
        rapid: bool,
    ) -> Plan {
        let reach = parts.iter().fold(cutter.radius(), |r, &(radius, _, _)| r.max(radius));
        let disc_low = discs[first..].iter().fold(f64::INFINITY, |low, d| low.min(d.z_low));
        let (box_lo, box_hi) = cutter.tip_box(from, to);
        Plan {
            id,
            box_lo,
            box_hi,
            arc: cutter.is_arc(),
            z_low: cutter.z_low.min(disc_low),
            cutter,
            discs: (first, discs.len()),
            disc_low,
            reach,
            from: from.xy(),
            to: to.xy(),
            rapid,
        }
    }
}

/// What a band found, sparse per move.
#[derive(Default)]
struct BandOutput {
    /// (move, removed volume, largest lowering).
    removed: Vec<(u32, f64, f64)>,
    /// (move, depth, cell).
    rapid: Vec<(u32, f64, usize)>,
    /// (move, part, depth, cell).
    collisions: Vec<(u32, ToolPart, f64, usize)>,
}

/// Checks the box and the resolution of a new stock.
///
/// # Errors
/// [`SimError::BadResolution`], [`SimError::BadStock`] (empty or not finite).
pub(crate) fn check_stock(stock: &Aabb3, resolution: f64) -> Result<(), SimError> {
    if !(resolution.is_finite() && resolution > 0.0) {
        return Err(SimError::BadResolution { resolution });
    }
    let size = stock.size();
    let finite = stock.min.coords.iter().chain(stock.max.coords.iter()).all(|c| c.is_finite());
    if !(finite && size.x > 0.0 && size.y > 0.0 && size.z > 0.0) {
        return Err(SimError::BadStock { min: stock.min.coords.into(), max: stock.max.coords.into() });
    }
    Ok(())
}

/// Number of cells (at least 1) of a stock grid along a width `w` (mm):
/// `ceil(w / resolution)`, except that a width that is a whole number of cells
/// up to rounding is not rounded up.
pub(crate) fn cells_along(w: f64, resolution: f64) -> f64 {
    let n = w / resolution;
    let n = if (n - n.round()).abs() <= GRID_SNAP * n { n.round() } else { n.ceil() };
    n.max(1.0)
}

impl ZMap {
    /// A full stock box sampled at `resolution` (mm): `ceil(width / resolution)`
    /// cells along x (the same along y), each of width `width / nx <= resolution`,
    /// so the cells tile the box exactly. Every cell starts at the box top.
    ///
    /// # Errors
    /// [`SimError::BadResolution`], [`SimError::BadStock`] (empty or not finite),
    /// [`SimError::TooManyCells`] beyond [`MAX_CELLS`].
    pub fn new(stock: Aabb3, resolution: f64) -> Result<ZMap, SimError> {
        check_stock(&stock, resolution)?;
        let size = stock.size();
        let (fx, fy) = (cells_along(size.x, resolution), cells_along(size.y, resolution));
        let limit = MAX_CELLS as f64;
        if fx * fy > limit {
            // Saturating float-to-int conversions: only used in the message.
            return Err(SimError::TooManyCells { nx: fx as usize, ny: fy as usize, limit: MAX_CELLS });
        }
        // Below MAX_CELLS: exact conversions.
        let (nx, ny) = (fx as usize, fy as usize);
        Ok(ZMap {
            stock,
            nx,
            ny,
            cell_x: size.x / fx,
            cell_y: size.y / fy,
            heights: vec![stock.max.z; nx * ny],
            last_cut: vec![0; nx * ny],
            operations: 0,
            eps: Eps::for_bounds(&stock).0,
        })
    }

    /// Cells along x.
    #[must_use]
    pub fn nx(&self) -> usize {
        self.nx
    }

    /// Cells along y.
    #[must_use]
    pub fn ny(&self) -> usize {
        self.ny
    }

    /// Cell size along x and y (mm), each at most the resolution asked for.
    #[must_use]
    pub fn cell_size(&self) -> (f64, f64) {
        (self.cell_x, self.cell_y)
    }

    /// The stock box.
    #[must_use]
    pub fn stock(&self) -> Aabb3 {
        self.stock
    }

    /// The simulator's resolution bound for `shape` on this grid (mm): how far
    /// the stock's true swept floor can lie below what its cell centres show.
    ///
    /// Every point of the grid lies within `rho = sqrt(cell_x^2 + cell_y^2) / 2`
    /// (half a cell diagonal) of a cell centre, and the height at a centre is
    /// exact. Where the floor has a minimum between centres (the bottom of a
    /// pass, of a gouge), its gradient vanishes there and its curvature is at
    /// most the profile's largest curvature `kappa` (a swept surface is no more
    /// curved across the move than the profile, and along a straight move it is
    /// straight), so the nearest centre lies at most `kappa rho^2 / 2` above it:
    /// ball `kappa = 1 / R`, bull-nose `1 / r` (its corner), flat `0` (a flat
    /// bottom sweeps planes). A cone's tip has no curvature bound; its floor
    /// rises at most `cot(a)` per mm from a minimum, so its bound is `cot(a) rho`.
    /// A deviation measured at the centres (gouge depth, material left) is
    /// therefore within this bound of the true extreme on the floor; at a
    /// ridge between passes (a cusp) the centres can only under-state the
    /// height, by at most the profile's slope there times `rho`.
    ///
    /// ```
    /// use scallop_cutter::CutterShape;
    /// use scallop_geom::{Aabb3, Point3};
    /// use scallop_sim::ZMap;
    /// let stock = Aabb3 { min: Point3::new(0.0, 0.0, -1.0), max: Point3::new(10.0, 10.0, 0.0) };
    /// let zmap = ZMap::new(stock, 0.05).unwrap();
    /// let b = zmap.resolution_bound(&CutterShape::Bull { radius: 5.0, corner: 2.0 });
    /// assert!((b - 0.05f64.powi(2) * 2.0 / 8.0 / 2.0).abs() < 1e-15); // rho^2 / (2 r)
    /// assert_eq!(zmap.resolution_bound(&CutterShape::Flat { radius: 1.0 }), 0.0);
    /// ```
    #[must_use]
    pub fn resolution_bound(&self, shape: &CutterShape) -> f64 {
        let rho2 = 0.25 * (self.cell_x * self.cell_x + self.cell_y * self.cell_y);
        match *shape {
            CutterShape::Flat { .. } => 0.0,
            CutterShape::Ball { radius } => 0.5 * rho2 / radius,
            CutterShape::Bull { corner, .. } => {
                if corner > 0.0 {
                    0.5 * rho2 / corner
                } else {
                    0.0
                }
            }
            CutterShape::Cone { half_angle, .. } => rho2.sqrt() / half_angle.tan(),
        }
    }

    /// The rounding epsilon of the stock (mm): lowerings below it do not count as cuts.
    #[must_use]
    pub fn eps(&self) -> f64 {
        self.eps
    }

    /// Centre of cell `(i, j)` (column, row).
    #[must_use]
    pub fn cell_center(&self, i: usize, j: usize) -> Point2 {
        Point2::new(self.x_of(i), self.y_of(j))
    }

    fn x_of(&self, i: usize) -> f64 {
        // Cell indices are far below 2^52: exact.
        self.stock.min.x + (i as f64 + 0.5) * self.cell_x
    }

    fn y_of(&self, j: usize) -> f64 {
        self.stock.min.y + (j as f64 + 0.5) * self.cell_y
    }

    /// Height of cell `(i, j)`, or `None` outside the grid.
    #[must_use]
    pub fn height(&self, i: usize, j: usize) -> Option<f64> {
        (i < self.nx && j < self.ny).then(|| self.heights[j * self.nx + i])
    }

    /// All heights, row-major with x fastest.
    #[must_use]
    pub fn heights(&self) -> &[f64] {
        &self.heights
    }

    /// The last move that lowered cell `(i, j)` (the one that left its height),
    /// `None` when uncut or outside the grid.
    ///
    /// ```
    /// use scallop_cutter::{Cutter, CutterShape};
    /// use scallop_geom::{Aabb3, Point3};
    /// use scallop_sim::{MoveId, ZMap};
    /// use scallop_toolpath::{Move, MoveKind, Toolpath};
    /// let stock = Aabb3 { min: Point3::new(0.0, 0.0, -2.0), max: Point3::new(4.0, 4.0, 0.0) };
    /// let mut zmap = ZMap::new(stock, 1.0).unwrap();
    /// let ball = Cutter::new(CutterShape::Ball { radius: 1.0 }, 5.0).unwrap();
    /// let mut path = Toolpath::new(500.0);
    /// path.push(Move::new(MoveKind::Rapid, Point3::new(0.5, 0.5, 3.0)));
    /// path.push(Move::new(MoveKind::Plunge, Point3::new(0.5, 0.5, -1.0)));
    /// zmap.cut(&ball, &path).unwrap();
    /// assert_eq!(zmap.cell_center(0, 0), scallop_geom::Point2::new(0.5, 0.5));
    /// assert_eq!(zmap.height(0, 0), Some(-1.0));
    /// assert_eq!(zmap.last_cut(0, 0), Some(MoveId { operation: 0, index: 1 }));
    /// assert_eq!(zmap.last_cut(3, 3), None);
    /// assert_eq!(zmap.last_cut(0, 0).unwrap().to_string(), "move 1 of operation 0");
    /// ```
    #[must_use]
    pub fn last_cut(&self, i: usize, j: usize) -> Option<MoveId> {
        if i < self.nx && j < self.ny { MoveId::unpack(self.last_cut[j * self.nx + i]) } else { None }
    }

    /// Volume of stock left (mm^3): the sum over cells of height above the box bottom
    /// times the cell area (summed row by row, in order).
    #[must_use]
    pub fn volume(&self) -> f64 {
        let bottom = self.stock.min.z;
        let area = self.cell_x * self.cell_y;
        self.heights.chunks(self.nx).map(|row| row.iter().map(|h| h - bottom).sum::<f64>() * area).sum()
    }

    /// Volume of the full stock box (mm^3), in the same cell sum as [`ZMap::volume`].
    #[must_use]
    pub fn initial_volume(&self) -> f64 {
        let area = self.cell_x * self.cell_y;
        let column = self.stock.max.z - self.stock.min.z;
        (0..self.ny).map(|_| (0..self.nx).map(|_| column).sum::<f64>() * area).sum()
    }

    /// Removes the material swept by `cutter` along `toolpath` (straight moves,
    /// tool axis +Z). The first move has no known start: the tool is placed at
    /// its end point (a zero-length move). Each cell centre is lowered to the
    /// lowest point of the cutter's swept lower envelope above it (exact, see
    /// [`crate::swept_floor`]), never below the stock bottom; a z-map removes the
    /// whole column above that point.
    ///
    /// Before each move cuts, the shank (a disc of radius max(R, shank radius) at
    /// the flute length above the tip, so that stock above the flutes, which a
    /// z-map could not keep, is reported too) and each holder segment (a disc of
    /// its larger radius at its bottom: conservative for frusta) are checked
    /// against the in-process stock; penetrations beyond the stock's epsilon go
    /// into [`CutReport::collisions`]. Rapid and retract moves that remove stock
    /// go into [`CutReport::rapid_hits`]. Neither stops the cut; use
    /// [`CutReport::check`].
    ///
    /// Only cells within a move's reach are visited: the rows of its XY box, on
    /// each row the chord of the stadium around the segment, and on the chord
    /// only runs of cells ("tiles") whose height bound lies above a lower bound
    /// of the move's floor there (`z_low + h(d)`, d the distance to the move, see the envelope module), so
    /// skipping never changes a result.
    ///
    /// Work is parallel over fixed bands of grid rows; each band applies the
    /// moves in program order, so the result is identical on any thread count.
    ///
    /// # Errors
    /// [`SimError::TooManyMoves`] when a move index or the operation count
    /// would not fit in `u32`.
    ///
    /// ```
    /// use scallop_cutter::{Cutter, CutterShape};
    /// use scallop_geom::{Aabb3, Point3};
    /// use scallop_sim::ZMap;
    /// use scallop_toolpath::{Move, MoveKind, Toolpath};
    /// let stock = Aabb3 { min: Point3::new(0.0, 0.0, -5.0), max: Point3::new(20.0, 10.0, 0.0) };
    /// let mut zmap = ZMap::new(stock, 0.1).unwrap();
    /// let flat = Cutter::new(CutterShape::Flat { radius: 2.0 }, 10.0).unwrap();
    /// let mut path = Toolpath::new(1000.0);
    /// path.push(Move::new(MoveKind::Rapid, Point3::new(-3.0, 5.0, 5.0)));
    /// path.push(Move::new(MoveKind::Plunge, Point3::new(-3.0, 5.0, -1.0)));
    /// path.push(Move::new(MoveKind::Feed, Point3::new(23.0, 5.0, -1.0)));
    /// path.push(Move::new(MoveKind::Retract, Point3::new(23.0, 5.0, 5.0)));
    /// let report = zmap.cut(&flat, &path).unwrap();
    /// report.check().unwrap();
    /// // A slot 4 mm wide and 1 mm deep through the 20 mm stock.
    /// assert!((report.removed_volume - 80.0).abs() < 1e-9);
    /// assert_eq!(zmap.height(100, 50), Some(-1.0));
    /// ```
    pub fn cut(&mut self, cutter: &Cutter, toolpath: &Toolpath) -> Result<CutReport, SimError> {
        self.cut_with_progress(cutter, toolpath, &|_, _| {})
    }

    /// [`ZMap::cut`] that reports its progress: `progress(done, total)` is
    /// called from the worker threads (in any order) each time a band of grid
    /// rows has applied all its moves, `total` being the number of bands.
    /// The result does not depend on it.
    ///
    /// # Errors
    /// Those of [`ZMap::cut`].
    ///
    /// ```
    /// use std::sync::atomic::{AtomicUsize, Ordering};
    /// use scallop_cutter::{Cutter, CutterShape};
    /// use scallop_geom::{Aabb3, Point3};
    /// use scallop_sim::ZMap;
    /// use scallop_toolpath::{Move, MoveKind, Toolpath};
    /// let stock = Aabb3 { min: Point3::new(0.0, 0.0, -2.0), max: Point3::new(10.0, 10.0, 0.0) };
    /// let mut zmap = ZMap::new(stock, 0.1).unwrap();
    /// let flat = Cutter::new(CutterShape::Flat { radius: 1.0 }, 5.0).unwrap();
    /// let mut path = Toolpath::new(500.0);
    /// path.push(Move::new(MoveKind::Rapid, Point3::new(-2.0, 5.0, -1.0)));
    /// path.push(Move::new(MoveKind::Feed, Point3::new(12.0, 5.0, -1.0)));
    /// let last = AtomicUsize::new(0);
    /// zmap.cut_with_progress(&flat, &path, &|done, total| {
    ///     assert!(done <= total);
    ///     last.fetch_max(done, Ordering::Relaxed);
    /// })
    /// .unwrap();
    /// assert_eq!(last.into_inner(), 13); // 100 rows in bands of 8
    /// ```
    pub fn cut_with_progress(
        &mut self,
        cutter: &Cutter,
        toolpath: &Toolpath,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<CutReport, SimError> {
        let moves = toolpath.moves();
        let operation = self.operations;
        self.operations = self.operations.checked_add(1).ok_or(SimError::TooManyMoves { moves: moves.len() })?;
        self.sweep(cutter, toolpath, operation, true, progress)
    }

    /// Checks the shank and holder of `cutter` along `toolpath` against the
    /// design part itself (not the in-process stock): the part's top under
    /// each cell centre (see [`crate::part_heights`]) is tested against the
    /// same discs as in [`ZMap::cut`] (the shank of radius max(R, shank radius)
    /// from the flute length up, each holder segment), so a part wall higher
    /// than the flutes within R of a pass is found even where the stock was
    /// already cleared. The stock is not changed; `operation` names the moves
    /// (the [`CutReport::operation`] of the cut of the same toolpath).
    /// Penetrations beyond the stock's epsilon, deepest cell per move and part
    /// of the tool, in program order.
    ///
    /// # Errors
    /// [`SimError::TooManyMoves`] when a move index would not fit in `u32`.
    ///
    /// ```
    /// use scallop_cutter::{Cutter, CutterShape};
    /// use scallop_geom::{Aabb3, Point3};
    /// use scallop_mesh::{MeshIndex, TriMesh};
    /// use scallop_sim::{ToolPart, ZMap};
    /// use scallop_toolpath::{Move, MoveKind, Toolpath};
    /// let p = |x, y, z| Point3::new(x, y, z);
    /// // A block 10 mm tall at y >= 6; a pass along y = 5 with a 2 mm ball,
    /// // 3 mm of flutes, 5 mm below the block's top.
    /// let (block, _) = TriMesh::from_soup(&[[p(-5., 6., 10.), p(30., 6., 10.), p(-5., 20., 10.)]]).unwrap();
    /// let zmap = ZMap::new(Aabb3 { min: p(0., 0., -1.), max: p(20., 10., 11.) }, 0.1).unwrap();
    /// let ball = Cutter::new(CutterShape::Ball { radius: 2.0 }, 3.0).unwrap();
    /// let mut path = Toolpath::new(1000.0);
    /// path.push(Move::new(MoveKind::Rapid, p(2., 5., 5.)));
    /// path.push(Move::new(MoveKind::Feed, p(18., 5., 5.)));
    /// let hits = zmap.part_collisions(&MeshIndex::build(&block), &ball, &path, 0).unwrap();
    /// assert_eq!(hits.len(), 2);
    /// assert_eq!((hits[1].id.index, hits[1].part), (1, ToolPart::Shank));
    /// assert!((hits[1].depth - 2.0).abs() < 1e-9); // the wall top 2 mm above the flutes' end
    /// ```
    pub fn part_collisions(
        &self,
        part: &MeshIndex,
        cutter: &Cutter,
        toolpath: &Toolpath,
        operation: u32,
    ) -> Result<Vec<Collision>, SimError> {
        self.part_collisions_in(&crate::PartField::new(self, part), cutter, toolpath, operation)
    }

    /// [`ZMap::part_collisions`] with the part already rasterised on this grid.
    ///
    /// # Errors
    /// Those of [`ZMap::part_collisions`]; [`SimError::FieldGrid`] when
    /// `field` was built on another grid.
    pub fn part_collisions_in(
        &self,
        field: &crate::PartField,
        cutter: &Cutter,
        toolpath: &Toolpath,
        operation: u32,
    ) -> Result<Vec<Collision>, SimError> {
        field.check(self)?;
        let bottom = self.stock.min.z;
        let mut solid = ZMap {
            heights: field.heights().map(|z| if z == f64::NEG_INFINITY { bottom } else { z.max(bottom) }).collect(),
            last_cut: vec![0; self.heights.len()],
            ..*self
        };
        Ok(solid.sweep(cutter, toolpath, operation, false, &|_, _| {})?.collisions)
    }

    /// The body of [`ZMap::cut`]; `remove == false` only checks the discs.
    fn sweep(
        &mut self,
        cutter: &Cutter,
        toolpath: &Toolpath,
        operation: u32,
        remove: bool,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<CutReport, SimError> {
        let moves = toolpath.moves();
        u32::try_from(moves.len()).map_err(|_| SimError::TooManyMoves { moves: moves.len() })?;
        let parts = tool_parts(cutter);
        let (plans, discs) = self.plan_moves(cutter, toolpath, &parts);
        let (start, members) = self.band_members(&plans);
        let bands = start.len() - 1;

        let grid = Grid {
            nx: self.nx,
            ny: self.ny,
            min_x: self.stock.min.x,
            min_y: self.stock.min.y,
            cell_x: self.cell_x,
            cell_y: self.cell_y,
            bottom: self.stock.min.z,
            eps: self.eps,
        };
        let nx = self.nx;
        let done = AtomicUsize::new(0);
        let outputs: Vec<BandOutput> = self
            .heights
            .par_chunks_mut(BAND_ROWS * nx)
            .zip(self.last_cut.par_chunks_mut(BAND_ROWS * nx))
            .enumerate()
            .map(|(band, (heights, last))| {
                let ids = &members[start[band]..start[band + 1]];
                let out = grid.cut_band(band, heights, last, ids, &plans, &discs, &parts, operation, remove);
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, bands);
                out
            })
            .collect();
        Ok(self.merge_bands(&outputs, moves, operation))
    }

    /// Every move of `toolpath` prepared for the per-cell solve (helices as
    /// chords), with the shank and holder discs the plans index into.
    /// The caller has checked that the move count fits in `u32`.
    fn plan_moves(
        &self,
        cutter: &Cutter,
        toolpath: &Toolpath,
        parts: &[(f64, f64, ToolPart)],
    ) -> (Vec<Plan>, Vec<SweptMove>) {
        let moves = toolpath.moves();
        let mut discs = Vec::with_capacity(moves.len() * parts.len());
        let mut plans: Vec<Plan> = Vec::with_capacity(moves.len());
        for (k, m) in moves.iter().enumerate() {
            let from = if k == 0 { m.to } else { moves[k - 1].to };
            // k < moves.len() <= u32::MAX (checked by the caller).
            let id = k as u32;
            let rapid = matches!(m.kind, MoveKind::Rapid | MoveKind::Retract);
            let arc = if k == 0 { None } else { toolpath.arc(k) };
            match arc {
                // A planar arc (z constant within the stock's epsilon): exact (SweptMove::arc).
                Some(arc) if (from.z - m.to.z).abs() <= self.eps => {
                    let first = discs.len();
                    for &(radius, lift, _) in parts {
                        discs.push(SweptMove::arc(None, (radius, lift), &from, &m.to, arc.center, arc.sweep));
                    }
                    let cut = SweptMove::arc(Some(cutter.shape()), (0.0, 0.0), &from, &m.to, arc.center, arc.sweep);
                    plans.push(Plan::new(id, cut, &discs, first, parts, &from, &m.to, rapid));
                }
                // A helix: straight chords within `HELIX_SAGITTA` of it.
                Some(arc) => {
                    let mut a = from;
                    for b in helix_chords(&from, &m.to, arc.center, arc.sweep) {
                        plan_segment(&mut plans, &mut discs, (id, rapid), cutter, parts, &a, &b);
                        a = b;
                    }
                }
                None => plan_segment(&mut plans, &mut discs, (id, rapid), cutter, parts, &from, &m.to),
            }
        }
        (plans, discs)
    }

    /// The plans reaching each band (compressed rows, in program order):
    /// band `b`'s plans are `members[start[b]..start[b + 1]]`.
    fn band_members(&self, plans: &[Plan]) -> (Vec<usize>, Vec<u32>) {
        let bands = self.ny.div_ceil(BAND_ROWS);
        let band_range = |p: &Plan| {
            let (lo, hi) = (p.box_lo.y - p.reach, p.box_hi.y + p.reach);
            self.row_range(lo, hi).map(|(a, b)| (a / BAND_ROWS, b / BAND_ROWS))
        };
        let mut start = vec![0usize; bands + 1];
        for p in plans {
            if let Some((a, b)) = band_range(p) {
                for s in &mut start[a + 1..=b + 1] {
                    *s += 1;
                }
            }
        }
        for b in 0..bands {
            start[b + 1] += start[b];
        }
        let mut fill = start.clone();
        let mut members = vec![0u32; start[bands]];
        for (k, p) in plans.iter().enumerate() {
            if let Some((a, b)) = band_range(p) {
                for f in &mut fill[a..=b] {
                    // The plan's index: one plan a move, MAX_HELIX_CHORDS at most a helix.
                    members[*f] = k as u32;
                    *f += 1;
                }
            }
        }
        (start, members)
    }

    /// The report of one sweep from its bands' outputs, merged in band order:
    /// deterministic sums and tie-breaks.
    fn merge_bands(&self, outputs: &[BandOutput], moves: &[Move], operation: u32) -> CutReport {
        let count = moves.len();
        let mut removed_by_move = vec![0.0; count];
        let mut lowered = vec![0.0f64; count];
        let mut rapid: Vec<Option<(f64, usize)>> = vec![None; count];
        let mut collided: Vec<Vec<(ToolPart, f64, usize)>> = vec![Vec::new(); count];
        for out in outputs {
            for &(k, volume, lower) in &out.removed {
                removed_by_move[k as usize] += volume;
                lowered[k as usize] = lowered[k as usize].max(lower);
            }
            for &(k, depth, cell) in &out.rapid {
                let slot = &mut rapid[k as usize];
                if slot.is_none_or(|(d, _)| depth > d) {
                    *slot = Some((depth, cell));
                }
            }
            for &(k, part, depth, cell) in &out.collisions {
                let list = &mut collided[k as usize];
                match list.iter_mut().find(|(p, _, _)| *p == part) {
                    Some(entry) if depth > entry.1 => *entry = (part, depth, cell),
                    Some(_) => {}
                    None => list.push((part, depth, cell)),
                }
            }
        }
        let nx = self.nx;
        let cell_point = |cell: usize| self.cell_center(cell % nx, cell / nx);
        // k < moves.len() <= u32::MAX (checked by the sweep).
        let id = |k: usize| MoveId { operation, index: k as u32 };
        let feed_moves = moves.iter().filter(|m| m.kind == MoveKind::Feed).count();
        let air_feed_moves =
            moves.iter().zip(&lowered).filter(|(m, l)| m.kind == MoveKind::Feed && **l <= self.eps).count();
        let (mut feed_length_mm, mut air_feed_length_mm) = (0.0, 0.0);
        for (k, m) in moves.iter().enumerate().skip(1).filter(|(_, m)| m.kind == MoveKind::Feed) {
            let len = (m.to - moves[k - 1].to).norm();
            feed_length_mm += len;
            if lowered[k] <= self.eps {
                air_feed_length_mm += len;
            }
        }
        let rapid_hits = rapid
            .iter()
            .enumerate()
            .filter_map(|(k, r)| r.map(|(depth, cell)| RapidHit { id: id(k), at: cell_point(cell), depth }))
            .collect();
        let collisions = collided
            .iter()
            .enumerate()
            .flat_map(|(k, list)| list.iter().map(move |&(part, depth, cell)| (k, part, depth, cell)))
            .map(|(k, part, depth, cell)| Collision { id: id(k), part, at: cell_point(cell), depth })
            .collect();
        let removed_volume = removed_by_move.iter().sum();
        CutReport {
            operation,
            removed_by_move,
            removed_volume,
            feed_moves,
            air_feed_moves,
            feed_length_mm,
            air_feed_length_mm,
            rapid_hits,
            collisions,
        }
    }

    /// Rows whose centres may lie in [lo, hi] (one row of margin each side), or None.
    fn row_range(&self, lo: f64, hi: f64) -> Option<(usize, usize)> {
        index_range(lo, hi, self.stock.min.y, self.cell_y, self.ny)
    }
}

/// The shank and holder as flat discs: (radius, lift above the tip, part).
fn tool_parts(cutter: &Cutter) -> Vec<(f64, f64, ToolPart)> {
    let mut parts = vec![(cutter.radius().max(cutter.shank_radius()), cutter.flute_length(), ToolPart::Shank)];
    let mut lift = cutter.flute_length() + cutter.shank_length();
    for (k, s) in cutter.holder().iter().enumerate() {
        parts.push((s.bottom_radius.max(s.top_radius), lift, ToolPart::Holder(k)));
        lift += s.length;
    }
    parts
}

/// The ends of the straight chords, within `HELIX_SAGITTA` of a helix from
/// `from` to `to` about `center` turning by `sweep` (the last is `to` exactly).
fn helix_chords(from: &Point3, to: &Point3, center: Point2, sweep: f64) -> Vec<Point3> {
    let c = center;
    let r = (from.x - c.x).hypot(from.y - c.y);
    let start = (from.y - c.y).atan2(from.x - c.x);
    let step = if r > HELIX_SAGITTA { 2.0 * (1.0 - HELIX_SAGITTA / r).acos() } else { std::f64::consts::PI };
    // Bounded by MAX_HELIX_CHORDS: exact conversions.
    let chords = (sweep.abs() / step).ceil().clamp(1.0, MAX_HELIX_CHORDS);
    (1..=chords as u32)
        .map(|q| {
            let t = f64::from(q) / chords;
            if q == chords as u32 {
                *to
            } else {
                let theta = start + sweep * t;
                Point3::new(c.x + r * theta.cos(), c.y + r * theta.sin(), from.z + (to.z - from.z) * t)
            }
        })
        .collect()
}

/// Plans the straight segment `a`-`b` of move `id` (its discs first).
fn plan_segment(
    plans: &mut Vec<Plan>,
    discs: &mut Vec<SweptMove>,
    (id, rapid): (u32, bool),
    cutter: &Cutter,
    parts: &[(f64, f64, ToolPart)],
    a: &Point3,
    b: &Point3,
) {
    let first = discs.len();
    for &(radius, lift, _) in parts {
        discs.push(SweptMove::disc(radius, lift, a, b));
    }
    let cut = SweptMove::new(cutter.shape(), a, b);
    plans.push(Plan::new(id, cut, discs, first, parts, a, b, rapid));
}

/// Cell indices whose centres `min + (i + 0.5) cell` may lie in [lo, hi], with
/// one cell of margin each side (the per-cell solve decides exactly).
pub(crate) fn index_range(lo: f64, hi: f64, min: f64, cell: f64, n: usize) -> Option<(usize, usize)> {
    let a = ((lo - min) / cell - 0.5).floor() - 1.0;
    let b = ((hi - min) / cell - 0.5).ceil() + 1.0;
    let last = n as f64 - 1.0;
    if !(b >= 0.0 && a <= last) {
        return None;
    }
    // Clamped to [0, n - 1]: exact conversions.
    Some((a.max(0.0) as usize, b.min(last) as usize))
}

/// The grid geometry, shared by the bands.
#[derive(Clone, Copy)]
struct Grid {
    nx: usize,
    ny: usize,
    min_x: f64,
    min_y: f64,
    cell_x: f64,
    cell_y: f64,
    bottom: f64,
    eps: f64,
}

impl Grid {
    fn x_of(&self, i: usize) -> f64 {
        // Cell indices are far below 2^52: exact.
        self.min_x + (i as f64 + 0.5) * self.cell_x
    }

    #[allow(clippy::too_many_arguments)] // one private call site; the pieces are unrelated borrows.
    fn cut_band(
        &self,
        band: usize,
        heights: &mut [f64],
        last: &mut [u64],
        ids: &[u32],
        plans: &[Plan],
        discs: &[SweptMove],
        parts: &[(f64, f64, ToolPart)],
        operation: u32,
        remove: bool,
    ) -> BandOutput {
        let nx = self.nx;
        let row0 = band * BAND_ROWS;
        let rows = heights.len() / nx;
        let area = self.cell_x * self.cell_y;
        let mut out = BandOutput::default();
        if ids.is_empty() {
            return out;
        }
        // Upper bounds of each tile's heights; heights only go down, so a stale
        // bound stays valid. `dirty` tiles get a fresh one when it matters;
        // every tile starts so (a band of a short program, as the engagement
        // measure cuts one move at a time, meets few of its tiles).
        let tiles_per_row = nx.div_ceil(TILE);
        let tile_cells = |tile: usize| {
            let (local, t) = (tile / tiles_per_row, tile % tiles_per_row);
            local * nx + t * TILE..local * nx + ((t + 1) * TILE).min(nx)
        };
        let tile_max =
            |heights: &[f64], tile: usize| heights[tile_cells(tile)].iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mut tile_top = vec![f64::INFINITY; rows * tiles_per_row];
        let mut dirty = vec![true; tile_top.len()];
        for &k in ids {
            let plan = &plans[k as usize];
            let packed = MoveId { operation, index: plan.id }.pack();
            let (dy_lo, dy_hi) = (plan.box_lo.y - plan.reach, plan.box_hi.y + plan.reach);
            let Some((j0, j1)) = index_range(dy_lo, dy_hi, self.min_y, self.cell_y, self.ny) else { continue };
            let (j0, j1) = (j0.max(row0), j1.min(row0 + rows - 1));
            let (box_x0, box_x1) = (plan.box_lo.x, plan.box_hi.x);
            let (box_y0, box_y1) = (plan.box_lo.y, plan.box_hi.y);
            // Nothing at or below this can touch a disc (collisions need > eps).
            let disc_bound = plan.disc_low + self.eps;
            let mut removed = 0.0;
            let mut max_lower = 0.0f64;
            let mut rapid_worst: Option<(f64, usize)> = None;
            let mut collision_worst: Vec<Option<(f64, usize)>> = vec![None; plan.discs.1 - plan.discs.0];
            for j in j0..=j1 {
                let local = j - row0;
                let y = self.min_y + (j as f64 + 0.5) * self.cell_y;
                let Some((i0, i1)) = self.columns(plan, y) else { continue };
                let dy = (box_y0 - y).max(0.0).max(y - box_y1);
                for t in i0 / TILE..=i1 / TILE {
                    let tile = local * tiles_per_row + t;
                    let (c0, c1) = (i0.max(t * TILE), i1.min(t * TILE + TILE - 1));
                    // Lower bound of the cutter's floor on the tile's centres:
                    // z_low + h(d) with d the distance to the move's box.
                    let (xa, xb) = (self.x_of(c0), self.x_of(c1));
                    let dx = (box_x0 - xb).max(0.0).max(xa - box_x1);
                    let bound =
                        if remove { plan.cutter.floor_bound(dx * dx + dy * dy).min(disc_bound) } else { disc_bound };
                    if tile_top[tile] <= bound {
                        continue;
                    }
                    if dirty[tile] {
                        tile_top[tile] = tile_max(heights, tile);
                        dirty[tile] = false;
                        if tile_top[tile] <= bound {
                            continue;
                        }
                    }
                    let row = &mut heights[local * nx..(local + 1) * nx];
                    let row_last = &mut last[local * nx..(local + 1) * nx];
                    let mut lowered = false;
                    for i in c0..=c1 {
                        let old = row[i];
                        if old <= plan.z_low {
                            continue;
                        }
                        let x = self.x_of(i);
                        if old > disc_bound {
                            for (slot, disc) in discs[plan.discs.0..plan.discs.1].iter().enumerate() {
                                if old - disc.z_low > self.eps {
                                    let depth = old - disc.floor_below(x, y, old);
                                    if depth > self.eps && collision_worst[slot].is_none_or(|(d, _)| depth > d) {
                                        collision_worst[slot] = Some((depth, local * nx + i));
                                    }
                                }
                            }
                        }
                        if !remove || old <= plan.cutter.z_low {
                            continue;
                        }
                        let new = plan.cutter.floor_below(x, y, old).max(self.bottom);
                        if new < old {
                            row[i] = new;
                            row_last[i] = packed;
                            lowered = true;
                            let lower = old - new;
                            removed += lower;
                            max_lower = max_lower.max(lower);
                            if plan.rapid && lower > self.eps && rapid_worst.is_none_or(|(d, _)| lower > d) {
                                rapid_worst = Some((lower, local * nx + i));
                            }
                        }
                    }
                    if lowered {
                        dirty[tile] = true;
                    }
                }
            }
            let to_global = |cell: usize| row0 * nx + cell;
            if removed > 0.0 {
                out.removed.push((plan.id, removed * area, max_lower));
            }
            if let Some((depth, cell)) = rapid_worst {
                out.rapid.push((plan.id, depth, to_global(cell)));
            }
            for (slot, worst) in collision_worst.iter().enumerate() {
                if let Some((depth, cell)) = *worst {
                    out.collisions.push((plan.id, parts[slot].2, depth, to_global(cell)));
                }
            }
        }
        out
    }

    /// Columns the move may reach on the row at `y`: the row's chord of the
    /// stadium (points within `reach` of the segment), the hull of the chords
    /// of the two end discs and of the band between them; the index range has
    /// one cell of margin each side (the per-cell solve decides exactly).
    fn columns(&self, plan: &Plan, y: f64) -> Option<(usize, usize)> {
        if plan.arc {
            return index_range(
                plan.box_lo.x - plan.reach,
                plan.box_hi.x + plan.reach,
                self.min_x,
                self.cell_x,
                self.nx,
            );
        }
        let (a, b, r) = (plan.from, plan.to, plan.reach);
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for end in [a, b] {
            let dy = y - end.y;
            let h2 = r * r - dy * dy;
            if h2 >= 0.0 {
                let h = h2.sqrt();
                lo = lo.min(end.x - h);
                hi = hi.max(end.x + h);
            }
        }
        let (dx, dy) = (b.x - a.x, b.y - a.y);
        let len = dx.hypot(dy);
        if len > 0.0 {
            let (ex, ey) = (dx / len, dy / len);
            // Band: 0 <= (x - ax) ex + (y - ay) ey <= L and |(x - ax) ey - (y - ay) ex| <= r,
            // each a condition coef * x in [low, high].
            let mut band = (f64::NEG_INFINITY, f64::INFINITY);
            let q = y - a.y;
            for (coef, low, high) in
                [(ex, a.x * ex - q * ey, a.x * ex - q * ey + len), (ey, a.x * ey + q * ex - r, a.x * ey + q * ex + r)]
            {
                if coef == 0.0 {
                    if low > 0.0 || high < 0.0 {
                        band = (f64::INFINITY, f64::NEG_INFINITY);
                    }
                } else {
                    let (p, q) = (low / coef, high / coef);
                    band = (band.0.max(p.min(q)), band.1.min(p.max(q)));
                }
            }
            if band.0 <= band.1 {
                lo = lo.min(band.0);
                hi = hi.max(band.1);
            }
        }
        if lo > hi {
            return None;
        }
        index_range(lo, hi, self.min_x, self.cell_x, self.nx)
    }
}
