//! The API boundary of scallop: a part (mesh or parametric surfaces) and the
//! machining settings in, cutter locations, toolpaths, G-code text and
//! reports out. Orchestration only: the geometry lives in the crates below.
//! [`run_finishing`] machines a part in one direction or 3+2 setup;
//! [`run_job`] runs a job's operations in order on one simulated stock;
//! [`finish_zones`] machines a zone plan of the optimiser zone by zone (each in
//! its direction or 3+2 orientation) and proves it on the simulated stock;
//! [`run_rough5`] plans, proves and posts a 5-axis roughing operation of a
//! test part (`kind = "rough5"`).
//!
//! ```
//! use scallop_engine::{Part, prepare_part};
//! use scallop_geom::Tolerances;
//! let part = Part::builtin("choi").unwrap();
//! let prepared = prepare_part(&part, &Tolerances { path: 0.01, gouge: 0.0 }).unwrap();
//! assert!(prepared.chordal_error <= 0.0025 + 1e-12);
//! ```
//!
//! # Invariants
//! - Never performs I/O and never prints; progress goes through callbacks.
//! - Deterministic: the same inputs give the same outputs on any thread count.

mod budget;
mod demo;
mod estimate;
mod finish;
mod grid;
mod job;
mod refine;
mod rough;
mod rough5;
mod rough_estimate;
mod zones;

use scallop_geom::Tolerances;
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_surface::SurfaceSet;

pub use budget::{ARC_SHARE, Budget};
pub use demo::{DemoOutput, DemoSettings, DemoSummary, run_demo};
pub use estimate::{Estimate, estimate_job, estimate_operation};
pub use finish::{
    FinishDetails, FinishJob, FinishOutput, FinishReport, FinishStep, OutputOptions, RestPlaceReport, RestReport,
    Setup, Strategy, auto_direction_deg, run_finishing, run_finishing_with_progress, stock_box,
};
pub use grid::{GridAxis, GridError, MAX_GRID_POINTS};
pub use job::{
    EngagementFigures, Job, JobOutput, JobPhase, JobReport, JobStep, LeftFigures, Operation, OperationReport,
    STOCK_CLEARANCE_MM, StockFigures, StockShape, run_job, run_job_with_progress,
};
pub use rough5::{
    BlockTime, FaceReport, OnMachine, Posted, ProgramTime, Rough5Job, Rough5Metrics, Rough5Output, Rough5Step,
    TcpWords, TimeShare, block_times, on_machine, path_dynamics, post_tcp, program_time, rough5_metrics,
    rough5_settings, run_rough5, time_breakdown,
};
pub use zones::{
    ProgramCandidate, ZONE_MARGIN_PER_RADIUS, ZONE_MARGIN_PER_SPACING, ZONE_MARGIN_ROUNDS, ZoneFigures,
    ZoneFinishOutput, ZoneFinishReport, ZonePlanSpec, ZoneSpec, finish_candidates, finish_zones,
};

/// Why the engine rejected a request. Each variant says the cause and the fix.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EngineError {
    /// Surfaces could not be tessellated within the tolerance.
    #[error("tessellating the surfaces failed: {0}")]
    Surface(#[from] scallop_surface::SurfaceError),
    /// A tolerance that is not a finite positive number.
    #[error("the path tolerance {0} mm must be a finite number > 0")]
    BadTolerance(f64),
    /// A cutter that is not a real tool.
    #[error("cutter: {0}")]
    Cutter(#[from] scallop_cutter::CutterError),
    /// The roughing planner refused (a setting, the part's waterline).
    #[error("roughing: {0}")]
    Rough(#[from] scallop_rough::RoughError),
    /// A grid that makes no sense.
    #[error("{0}")]
    Grid(#[from] GridError),
    /// The finishing planner refused (a parameter, an unreachable surface, a
    /// scallop over the height asked).
    #[error("finishing: {0}")]
    Strategy(#[from] scallop_strategy::StrategyError),
    /// The surface analysis failed (degenerate samples).
    #[error("analysis: {0}")]
    Analysis(scallop_analysis::AnalysisError),
    /// The stock simulation found a safety problem (gouge, rapid into stock,
    /// collision) or could not run.
    #[error("verification: {0}")]
    Verification(#[from] scallop_sim::SimError),
    /// The simulated stock holds more than the scallop height between passes
    /// (beyond the simulator's resolution bound) where the planner measures no
    /// scallop itself (the network planner).
    #[error(
        "verification: the simulated scallop {measured:.4} mm near ({x:.3}, {y:.3}) mm exceeds sh {limit} mm \
         plus the stock's resolution bound {bound:.4} mm; fix: use finishing.strategy = \"parallel\" \
         (measured spacing) or a finer verify.resolution"
    )]
    ScallopNotHeld {
        /// Largest simulated scallop (normal thickness, mm).
        measured: f64,
        /// Where (mm).
        x: f64,
        /// Where (mm).
        y: f64,
        /// The scallop height asked for (mm).
        limit: f64,
        /// The simulator's resolution bound (mm).
        bound: f64,
    },
    /// The drop-cutter planner refused one zone of a zone plan.
    #[error("finishing zone {zone} along {direction_deg:.2} deg: {source}")]
    Zone {
        /// The zone's label.
        zone: u32,
        /// Its feed direction (degrees).
        direction_deg: f64,
        /// Why.
        source: scallop_strategy::StrategyError,
    },
    /// The stock simulation measured a scallop above the height asked plus the
    /// simulation's resolution bound: the program does not finish the surface
    /// as promised (a planner bug, or zones too narrow for their margins).
    #[error(
        "verification: the simulated scallop {height} mm near ({x:.3}, {y:.3}) mm exceeds {limit} mm \
         (scallop height plus the simulation's resolution bound); use a finer `verify.resolution`, \
         fewer zones, or report the job as a planner bug"
    )]
    ScallopExceeded {
        /// Simulated scallop (mm).
        height: f64,
        /// The limit (mm).
        limit: f64,
        /// Place (mm).
        x: f64,
        /// Place (mm).
        y: f64,
    },
    /// A test part without the faces a 5-axis roughing operation needs.
    #[error("the test part: {0}")]
    TestPart(#[from] scallop_parts::PartError),
    /// The 5-axis roughing planner refused, or its tri-dexel proof found a
    /// rapid into stock or a shank or holder collision.
    #[error("5-axis roughing: {0}")]
    Rough5(#[from] scallop_rough5::Rough5Error),
    /// The 5-axis roughing program removes stock outside the volume to remove.
    #[error(
        "the program is not safe: it removes {volume:.1} mm3 outside the volume to remove, {depth:.3} mm deep along Z \
         near ({x:.3}, {y:.3}, {z:.3}) (tolerance {tolerance} mm, rough5.sim_tolerance)"
    )]
    Rough5Gouge {
        /// Volume removed outside (mm^3).
        volume: f64,
        /// Its longest piece along one Z ray (mm).
        depth: f64,
        /// Where (mm).
        x: f64,
        /// Where (mm).
        y: f64,
        /// Where (mm).
        z: f64,
        /// The depth allowed (mm).
        tolerance: f64,
    },
    /// The program cannot be written as asked (dialect, machine, 3+2 setup).
    #[error("output: {what}; fix: {fix}")]
    Output {
        /// What cannot be written.
        what: String,
        /// What to do.
        fix: String,
    },
}

/// A part to machine.
#[derive(Debug, Clone)]
pub enum Part {
    /// A triangle mesh (mm).
    Mesh(TriMesh),
    /// Parametric patches (mm).
    Surfaces(SurfaceSet),
}

impl Part {
    /// A built-in part by name (`choi`, `rubio`: the Bezier test surfaces of the finishing spec).
    #[must_use]
    pub fn builtin(name: &str) -> Option<Part> {
        scallop_surface::builtin(name).map(Part::Surfaces)
    }
}

/// A part ready for drop-cutter queries.
#[derive(Debug, Clone)]
pub struct PreparedPart {
    /// The mesh the queries run on (the part itself, or its tessellation).
    pub mesh: TriMesh,
    /// The XY index of `mesh`.
    pub index: MeshIndex,
    /// Largest distance between the true part and `mesh` (mm): 0 for a mesh part,
    /// the tessellation's chordal bound for surfaces. Drop-cutter heights on the
    /// mesh are within this of the heights on the true surface.
    pub chordal_error: f64,
    /// Whether `chordal_error` is proven (polynomial patches) or estimated.
    pub chordal_error_guaranteed: bool,
}

/// Prepares a part: surfaces are tessellated within `tol.tessellation()` (the
/// share of the path tolerance budgeted for it), then indexed.
///
/// # Errors
/// A bad tolerance or a surface that cannot be tessellated that finely.
pub fn prepare_part(part: &Part, tol: &Tolerances) -> Result<PreparedPart, EngineError> {
    if !(tol.path.is_finite() && tol.path > 0.0) {
        return Err(EngineError::BadTolerance(tol.path));
    }
    let (mesh, chordal_error, guaranteed) = match part {
        Part::Mesh(mesh) => (mesh.clone(), 0.0, true),
        Part::Surfaces(set) => {
            let t = set.tessellate(tol.tessellation())?;
            (t.mesh, t.chordal_bound, t.guaranteed)
        }
    };
    let index = MeshIndex::build(&mesh);
    Ok(PreparedPart { mesh, index, chordal_error, chordal_error_guaranteed: guaranteed })
}
