//! Roughing operations of a job (`kind = "rough"`, docs/job.md): z-level
//! offset clearing from the stock box by `scallop-rough`, cut and proven on
//! the job's one stock like every other operation.

use scallop_geom::{Aabb3, Tolerances};
use scallop_rough::{MaterialMap, Motion, RoughSettings, plan_rough_from};
use scallop_strategy::Report;
use scallop_toolpath::FittedPath;

use crate::finish::{cutter_text, finishing_params};
use crate::{EngineError, FinishJob, PreparedPart};

/// A planned roughing operation.
pub(crate) struct PlannedRough {
    /// The toolpath and its figures (the planner's counts filled in).
    pub(crate) toolpath: scallop_toolpath::Toolpath,
    /// Times and lengths.
    pub(crate) report: Report,
    /// Levels planned.
    pub(crate) levels: usize,
    /// The settings it was planned with.
    pub(crate) settings: RoughSettings,
}

/// Plans the roughing of the prepared part from `stock` with the cutter,
/// feeds and clearance of `job` (`clearance` above the part's top), limited
/// to the material the earlier operations left when `material` is given.
///
/// # Errors
/// [`EngineError::Rough`].
pub(crate) fn plan_rough_operation(
    job: &FinishJob,
    settings: &RoughSettings,
    prepared: &PreparedPart,
    stock: &Aabb3,
    material: Option<&MaterialMap>,
    clearance: f64,
    tolerances: &Tolerances,
) -> Result<PlannedRough, EngineError> {
    let mut params = finishing_params(job, 0.0);
    params.clearance = clearance;
    let part_top = prepared.mesh.bounds().max.z;
    let motion = Motion { clearance_z: part_top + clearance, feed: job.machine[0] * 1000.0 };
    let plan = plan_rough_from(&prepared.index, &job.cutter, stock, material, settings, &motion, tolerances.path)?;
    let mut toolpath = plan.toolpath;
    toolpath.plunge_feed = params.plunge_feed * 60.0;
    let mut report = Report::timed(&toolpath, &params);
    report.passes = plan.passes;
    report.planes = plan.levels.len();
    report.links = plan.links;
    report.retracts = plan.retracts;
    Ok(PlannedRough { toolpath, report, levels: plan.levels.len(), settings: *settings })
}

/// The program's path (XY arcs as planned) and the operation's header comments.
pub(crate) fn fit_and_comment(job: &FinishJob, op: &PlannedRough) -> (FittedPath, Vec<String>) {
    let (r, settings) = (&op.report, &op.settings);
    let comments = vec![
        format!("part: {}", job.part_name),
        format!(
            "tool: {}; roughing: {} levels, stepdown {} mm, stepover {} D, stock to leave {} mm radial, {} mm axial",
            cutter_text(job.cutter.shape()),
            op.levels,
            settings.stepdown,
            settings.stepover,
            settings.radial_allowance,
            settings.axial_allowance
        ),
        format!(
            "predicted machining time {:.1} s (stop-to-stop), {:.1} s (look-ahead), rapids {:.1} s",
            r.machining_time_s, r.machining_time_lookahead_s, r.rapid_time_s
        ),
    ];
    (FittedPath::with_xy_arcs(&op.toolpath), comments)
}

/// The in-process stock of `zmap` as the roughing planner reads it, `None`
/// while the stock is whole (the first cut plans from the box).
///
/// # Errors
/// [`EngineError::Rough`] when the grid is refused (never for a z-map the
/// simulator built).
pub(crate) fn material_of(zmap: &scallop_sim::ZMap) -> Result<Option<MaterialMap>, EngineError> {
    let b = zmap.stock();
    let full = b.max.z - zmap.eps();
    if zmap.heights().iter().all(|&h| h >= full) {
        return Ok(None);
    }
    let empty = b.min.z + zmap.eps();
    let tops = zmap.heights().iter().map(|&h| if h > empty { h } else { f64::NEG_INFINITY }).collect();
    let (cx, cy) = zmap.cell_size();
    Ok(Some(MaterialMap::new([b.min.x, b.min.y], [cx, cy], zmap.nx(), zmap.ny(), tops)?))
}
