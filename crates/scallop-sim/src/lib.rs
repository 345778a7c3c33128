//! Stock simulation for scallop: the independent oracle that proves a 3-axis
//! program. It knows nothing of how a toolpath was planned, only the cutter,
//! the moves and the stock.
//!
//! - [`ZMap`]: the stock as a height field on a regular XY grid. [`ZMap::cut`]
//!   lowers every cell centre to the lowest point of the cutter's lower envelope
//!   swept along each straight move, solved exactly per shape (flat, ball,
//!   bull-nose, cone; see [`swept_floor`]), and checks rapids and the shank and
//!   holder against the in-process stock ([`CutReport`]);
//!   [`ZMap::part_collisions`] checks them against the design part.
//! - [`verify`]: the signed deviation `stock - part` per cell against a design
//!   part (a [`scallop_mesh::MeshIndex`]): max scallop, volumes, and gouges as errors.
//! - [`simulate`]: both, with every safety problem as an `Err`.
//! - [`PartField`]: the part rasterised once on the grid, shared by [`simulate`]'s
//!   [`ZMap::part_collisions_in`] and [`verify_in`].
//! - [`StockView`]: the read-only view of either stock that an operation gets
//!   of what the operations before it left.
//! - [`DexelStock`]: the multi-axis stock (tri-dexels: rays along X, Y and Z,
//!   each a list of material intervals), cut by cutters with any tool axis
//!   along 3-axis, 3+2 and simultaneous 5-axis moves ([`ToolMove`]); the
//!   swept solid of a fixed-axis move is solved per ray exactly or by a
//!   certified bracket, 5-axis moves are split into fixed-axis sub-steps
//!   within [`DexelOptions::axis_tolerance`]; the shank and holder are
//!   checked against the stock and the part ([`DexelStock::part_collisions`]);
//!   [`verify_dexel`] compares
//!   every ray with the part; [`simulate_dexel`] does both.
//! - [`pocket_engagement`]: the engagement angle of a 2.5D pocket program
//!   measured on the material it leaves ([`Pocket`]), links, air cuts and the
//!   reachable area left uncut.
//!
//! ```
//! use scallop_cutter::{Cutter, CutterShape};
//! use scallop_geom::{Aabb3, Point3};
//! use scallop_mesh::{MeshIndex, TriMesh};
//! use scallop_sim::{VerifyOptions, simulate};
//! use scallop_toolpath::{Move, MoveKind, Toolpath};
//! let p = |x, y, z| Point3::new(x, y, z);
//! // The part: a plane at z = 0 over the stock 10 x 10 x 2 (top at z = 1).
//! let (plane, _) = TriMesh::from_soup(&[[p(-5., -5., 0.), p(30., -5., 0.), p(-5., 30., 0.)]]).unwrap();
//! let part = MeshIndex::build(&plane);
//! let stock = Aabb3 { min: p(0., 0., -1.), max: p(10., 10., 1.) };
//! let ball = Cutter::new(CutterShape::Ball { radius: 1.0 }, 10.0).unwrap();
//! // Raster passes along x every 0.5 mm at z = 0.
//! let mut path = Toolpath::new(1000.0);
//! path.push(Move::new(MoveKind::Rapid, p(-2., -1., 5.)));
//! for k in 0..25 {
//!     let y = -1.0 + 0.5 * f64::from(k);
//!     let (x0, x1) = if k % 2 == 0 { (-2.0, 12.0) } else { (12.0, -2.0) };
//!     path.push(Move::new(MoveKind::Plunge, p(x0, y, 0.)));
//!     path.push(Move::new(MoveKind::Feed, p(x1, y, 0.)));
//! }
//! path.push(Move::new(MoveKind::Retract, p(-2., 11., 5.)));
//! let sim = simulate(stock, 0.05, &ball, &path, &part, &VerifyOptions::default()).unwrap();
//! // The scallop between passes 0.5 mm apart, R - sqrt(R^2 - 0.25^2), within
//! // the grid's bound (the cusp's slope 0.26 times half a cell, 0.025 mm).
//! let theory = 1.0 - (1.0f64 - 0.0625).sqrt();
//! assert!(sim.verification.max_scallop <= theory + 1e-12);
//! assert!(sim.verification.max_scallop >= theory - 0.26 * 0.025);
//! // The passes at y = -1, 10.5 and 11 run past the stock's edges, where their
//! // neighbours left nothing to cut: 3 of 25 feed moves cut air.
//! assert_eq!(sim.cut.air_feed_moves, 3);
//! ```
//!
//! # Invariants
//! - Never performs I/O; never prints.
//! - Removal is exact at cell centres: a cell's height is the minimum over the
//!   moves of the swept envelope above its centre (closed forms, or a bracketed
//!   root of a monotone derivative for the bull-nose), never sampled along a move. The
//!   only approximation is the grid itself.
//! - Output is deterministic: work is split into fixed bands of grid rows, each
//!   applying the moves in program order, results are collected by index and
//!   every float sum runs in a fixed order; the result does not depend on the
//!   number of threads.
//! - Safety problems (gouges, rapids into stock, shank and holder collisions,
//!   a part outside the stock) are errors ([`SimError`]), never warnings.
//! - Heights only decrease and never go below the stock box bottom.

mod dexel;
mod engagement;
mod envelope;
mod error;
mod rest;
#[cfg(test)]
mod test_support;
pub use scallop_geom::tol::sim as tol;
mod verify;
mod view;
mod zmap;

use scallop_cutter::Cutter;
use scallop_geom::Aabb3;
use scallop_mesh::MeshIndex;
use scallop_toolpath::Toolpath;

pub use dexel::{
    DexelCollision, DexelGouge, DexelOptions, DexelPart, DexelReport, DexelStock, DexelVerification, MAX_RAYS,
    MAX_SUBSTEPS, StickOut, ToolMove, verify_dexel,
};
pub use engagement::{
    EngagementOptions, EngagementReport, Pocket, engagement_angle, pocket_engagement, stock_engagement,
};
pub use envelope::swept_floor;
pub use error::SimError;
pub use rest::{OverCell, RestPlace, RestSplit, rest_places, split_rest};
pub use verify::{GougeCell, PartField, Verification, VerifyOptions, part_heights, verify, verify_in};
pub use view::StockView;
pub use zmap::{Collision, CutReport, MAX_CELLS, MoveId, RapidHit, ToolPart, ZMap};

/// Everything [`simulate`] found about a safe program.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// The stock after the program.
    pub zmap: ZMap,
    /// Move by move figures (removed volume, air cuts).
    pub cut: CutReport,
    /// Deviation from the part (scallop, volumes).
    pub verification: Verification,
}

/// Cuts a fresh stock box at `resolution` with `cutter` along `toolpath`, then
/// verifies it against `part`.
///
/// # Errors
/// Stock errors of [`ZMap::new`]; then, in this order, the safety errors of
/// rapids into stock ([`SimError::RapidIntoStock`]), shank or holder against
/// the part ([`SimError::PartCollision`], see [`ZMap::part_collisions`]),
/// against the stock ([`SimError::HolderCollision`], [`CutReport::check`]),
/// then the errors of [`verify`] (part outside the stock, gouges).
///
/// ```
/// use scallop_cutter::{Cutter, CutterShape};
/// use scallop_geom::{Aabb3, Point3};
/// use scallop_mesh::{MeshIndex, TriMesh};
/// use scallop_sim::{SimError, VerifyOptions, simulate};
/// use scallop_toolpath::{Move, MoveKind, Toolpath};
/// let p = |x, y, z| Point3::new(x, y, z);
/// let (plane, _) = TriMesh::from_soup(&[[p(-5., -5., 0.), p(30., -5., 0.), p(-5., 30., 0.)]]).unwrap();
/// let stock = Aabb3 { min: p(0., 0., -1.), max: p(10., 10., 1.) };
/// let flat = Cutter::new(CutterShape::Flat { radius: 1.0 }, 10.0).unwrap();
/// let mut path = Toolpath::new(1000.0);
/// path.push(Move::new(MoveKind::Rapid, p(-2., 5., 5.)));
/// path.push(Move::new(MoveKind::Rapid, p(5., 5., 0.5))); // a rapid into the stock
/// let err = simulate(stock, 0.1, &flat, &path, &MeshIndex::build(&plane), &VerifyOptions::default());
/// assert!(matches!(err, Err(SimError::RapidIntoStock { count: 1, .. })));
/// ```
pub fn simulate(
    stock: Aabb3,
    resolution: f64,
    cutter: &Cutter,
    toolpath: &Toolpath,
    part: &MeshIndex,
    options: &VerifyOptions,
) -> Result<Simulation, SimError> {
    simulate_with_progress(stock, resolution, cutter, toolpath, part, options, &|_, _| {})
}

/// [`simulate`], calling `progress(done, total)` as the cut proceeds (bands
/// of rows cut, of all bands; see [`ZMap::cut_with_progress`]).
///
/// # Errors
/// As [`simulate`].
pub fn simulate_with_progress(
    stock: Aabb3,
    resolution: f64,
    cutter: &Cutter,
    toolpath: &Toolpath,
    part: &MeshIndex,
    options: &VerifyOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Simulation, SimError> {
    let mut zmap = ZMap::new(stock, resolution)?;
    let cut = zmap.cut_with_progress(cutter, toolpath, progress)?;
    if !cut.rapid_hits.is_empty() {
        cut.check()?;
    }
    // The part under the stock means a collision with the part is one with
    // the stock too: the part's comes first, as no roughing can fix it.
    // The part rasterised once for both checks.
    let field = PartField::new(&zmap, part);
    let collisions = zmap.part_collisions_in(&field, cutter, toolpath, cut.operation)?;
    if !collisions.is_empty() {
        return Err(SimError::PartCollision { collisions });
    }
    cut.check()?;
    let verification = verify_in(&zmap, &field, options)?;
    Ok(Simulation { zmap, cut, verification })
}

/// Everything [`simulate_dexel`] found about a safe multi-axis program.
#[derive(Debug, Clone)]
pub struct DexelSimulation {
    /// The stock after the program.
    pub stock: DexelStock,
    /// Move by move figures (removed volume, air cuts).
    pub cut: DexelReport,
    /// Material left and volumes.
    pub verification: DexelVerification,
}

/// Cuts a fresh tri-dexel stock box at `resolution` with `cutter` along
/// `moves` (any tool axes), then verifies it against `part`.
///
/// # Errors
/// Stock errors of [`DexelStock::new`], move errors of [`DexelStock::cut`];
/// then, in this order, rapids into stock ([`SimError::RapidIntoStock`]),
/// shank or holder against the part ([`SimError::DexelPartCollision`], see
/// [`DexelStock::part_collisions`]; only when `options.check_collisions`),
/// against the stock ([`SimError::DexelCollision`]), gouges
/// ([`SimError::DexelGouge`]).
///
/// ```
/// use scallop_cutter::{Cutter, CutterShape};
/// use scallop_geom::{Aabb3, Point3, Vec3};
/// use scallop_mesh::TriMesh;
/// use scallop_sim::{DexelOptions, DexelPart, SimError, ToolMove, VerifyOptions, simulate_dexel};
/// use scallop_toolpath::MoveKind;
/// let p = |x, y, z| Point3::new(x, y, z);
/// // The part: a plane at z = 0; the stock 10 x 10 x 2 (top at z = 1).
/// let (plane, _) = TriMesh::from_soup(&[[p(-5., -5., 0.), p(30., -5., 0.), p(-5., 30., 0.)]]).unwrap();
/// let part = DexelPart::new(&plane);
/// let stock = Aabb3 { min: p(0., 0., -1.), max: p(10., 10., 1.) };
/// let flat = Cutter::new(CutterShape::Flat { radius: 2.0 }, 10.0).unwrap();
/// // A flat end mill tilted 30 degrees about X, its tip 0.2 mm below the plane: a gouge.
/// let axis = Vec3::new(0.0, -0.5, 0.75f64.sqrt());
/// let mv = |kind, x: f64, z: f64| ToolMove::new(kind, p(x, 5., z), axis);
/// let path = [mv(MoveKind::Rapid, -4., 6.), mv(MoveKind::Plunge, -4., -0.2), mv(MoveKind::Feed, 14., -0.2)];
/// let err = simulate_dexel(stock, 0.25, &flat, &path, &part, &DexelOptions::default(), &VerifyOptions::default());
/// let Err(SimError::DexelGouge { worst, .. }) = err else { panic!("expected a gouge") };
/// assert_eq!(worst[0].cut_by.map(|m| m.index), Some(2));
/// ```
pub fn simulate_dexel(
    stock: Aabb3,
    resolution: f64,
    cutter: &Cutter,
    moves: &[ToolMove],
    part: &DexelPart,
    options: &DexelOptions,
    verify_options: &VerifyOptions,
) -> Result<DexelSimulation, SimError> {
    let mut dexels = DexelStock::new(stock, resolution)?;
    let cut = dexels.cut(cutter, moves, options)?;
    if !cut.rapid_hits.is_empty() {
        cut.check()?;
    }
    if options.check_collisions {
        let collisions = dexels.part_collisions(part, cutter, moves, options, cut.operation)?;
        if !collisions.is_empty() {
            return Err(SimError::DexelPartCollision { collisions });
        }
    }
    cut.check()?;
    let verification = verify_dexel(&dexels, part, verify_options)?;
    Ok(DexelSimulation { stock: dexels, cut, verification })
}
