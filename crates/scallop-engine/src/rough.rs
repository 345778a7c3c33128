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

/// Places of unreachable material reported.
const LEFT_PLACES: usize = 10;

/// What a roughing operation with `settings` and `cutter` left above its
/// allowance on the stock `zmap`, over the part `field` and off its outline
/// (down to the lowest level, [`scallop_rough::level_bottom`]).
///
/// Per cell p: the floor `F(p)` is the part's height grown sideways by the
/// radial allowance (the highest part cell within `s` plus a cell's diagonal
/// of p: a wall lies anywhere between two centres, and a wall across the grid
/// steps by a diagonal) plus the axial allowance; off the outline, where no
/// part cell lies within the allowance plus two diagonals, the lowest level
/// `z_b` (cells off it nearer than that are not measured). The
/// material left is `h(p) - F(p)` where above [`LeftFigures::limit_mm`].
/// The lowest the operation's cutter can take the stock at p is
/// `reach(p) = min over centres c within R of p of max(CL(c) + a, z_b) + h_R(|p - c|)`,
/// with CL the drop-cutter of the cutter grown by the radial allowance (the
/// tool the planner keeps off the part) and `h_R` the real cutter's profile
/// (docs/roughing.md): where `reach(p)` stands above `F(p)` plus the limit,
/// the cutter cannot reach. CL is sampled at the cell centres, so `reach` is
/// known within the grid's sampling.
///
/// # Errors
/// [`EngineError::Rough`] for a cone (no grown cutter).
pub(crate) fn left_above_allowance(
    zmap: &scallop_sim::ZMap,
    field: &scallop_sim::PartField,
    prepared: &PreparedPart,
    cutter: &scallop_cutter::Cutter,
    settings: &RoughSettings,
) -> Result<crate::LeftFigures, EngineError> {
    use rayon::prelude::*;
    let (nx, ny) = (zmap.nx(), zmap.ny());
    let (cx, cy) = zmap.cell_size();
    let area = cx * cy;
    let part: Vec<f64> = field.heights().collect();
    let heights = zmap.heights();
    let limit = scallop_rough::tol::MIN_CHIP + zmap.eps();
    // Cell offsets within `d` (centre to centre).
    let disc = |d: f64| -> Vec<(isize, isize, f64)> {
        #[allow(clippy::cast_possible_truncation, reason = "a small count")]
        let (ri, rj) = ((d / cx).floor() as isize, (d / cy).floor() as isize);
        let mut out = Vec::new();
        for dj in -rj..=rj {
            for di in -ri..=ri {
                #[allow(clippy::cast_precision_loss, reason = "small counts")]
                let r = (di as f64 * cx).hypot(dj as f64 * cy);
                if r <= d {
                    out.push((di, dj, r));
                }
            }
        }
        out
    };
    let at = |i: usize, j: usize, o: &(isize, isize, f64)| -> Option<usize> {
        let (ii, jj) = (i.checked_add_signed(o.0)?, j.checked_add_signed(o.1)?);
        (ii < nx && jj < ny).then_some(jj * nx + ii)
    };
    let grow = disc(settings.radial_allowance + cx.hypot(cy));
    // Off the part's outline the levels take the stock down to the lowest
    // level, and no tool goes below it. A cell off it is measured only
    // beyond the allowance plus two diagonals of the part's cells: one for
    // where the outline lies between two centres, one for the planner's
    // region, whose boundary is sampled too (closer, the allowance beside
    // the outline's edge reads as material left).
    let bottom_level = scallop_rough::level_bottom(&prepared.mesh.bounds(), &zmap.stock(), settings);
    let off = disc(settings.radial_allowance + 2.0 * cx.hypot(cy));
    let floor: Vec<f64> = (0..nx * ny)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % nx, k / nx);
            if part[k] == f64::NEG_INFINITY {
                let near = off.iter().filter_map(|o| at(i, j, o)).any(|n| part[n] != f64::NEG_INFINITY);
                return if near { f64::NEG_INFINITY } else { bottom_level };
            }
            grow.iter().filter_map(|o| at(i, j, o)).map(|n| part[n]).fold(f64::NEG_INFINITY, f64::max)
                + settings.axial_allowance
        })
        .collect();
    let left: Vec<usize> =
        (0..nx * ny).filter(|&k| floor[k] != f64::NEG_INFINITY && heights[k] - floor[k] > limit).collect();
    // The grown cutter's drop-cutter at the centres within R of a cell left.
    let reach_disc = disc(cutter.radius());
    let mut need = vec![false; nx * ny];
    for &k in &left {
        for o in &reach_disc {
            if let Some(n) = at(k % nx, k / nx, o) {
                need[n] = true;
            }
        }
    }
    let grown = scallop_rough::grown_cutter(cutter, settings.radial_allowance)?;
    let bottom = zmap.stock().min.z - prepared.mesh.bounds().diagonal() - 1.0;
    let cl: Vec<f64> = (0..nx * ny)
        .into_par_iter()
        .map(|k| {
            if need[k] {
                scallop_cutter::drop_cutter(&grown, &prepared.index, zmap.cell_center(k % nx, k / nx), bottom).tip.z
            } else {
                f64::INFINITY
            }
        })
        .collect();
    let shape = cutter.shape();
    let unreachable: Vec<bool> = left
        .par_iter()
        .map(|&k| {
            let (i, j) = (k % nx, k / nx);
            let reach = reach_disc
                .iter()
                .filter_map(|o| {
                    at(i, j, o).map(|n| (cl[n] + settings.axial_allowance).max(bottom_level) + shape.height_at(o.2))
                })
                .fold(f64::INFINITY, f64::min);
            reach > floor[k] + limit
        })
        .collect();
    let mut figures = crate::LeftFigures {
        limit_mm: limit,
        volume_mm3: 0.0,
        reached_max_mm: 0.0,
        reached_at: None,
        unreachable_area_mm2: 0.0,
        unreachable_volume_mm3: 0.0,
        unreachable_depth_mm: 0.0,
        places: Vec::new(),
    };
    let mut rest = vec![0.0; nx * ny];
    for (&k, &out) in left.iter().zip(&unreachable) {
        let excess = heights[k] - floor[k];
        figures.volume_mm3 += excess * area;
        if out {
            figures.unreachable_area_mm2 += area;
            figures.unreachable_volume_mm3 += excess * area;
            figures.unreachable_depth_mm = figures.unreachable_depth_mm.max(excess);
            rest[k] = excess;
        } else if excess > figures.reached_max_mm {
            figures.reached_max_mm = excess;
            let c = zmap.cell_center(k % nx, k / nx);
            figures.reached_at = Some([c.x, c.y]);
        }
    }
    figures.places = places(&rest, zmap);
    Ok(figures)
}

/// The connected places (4-neighbours) of cells with `rest > 0`, largest
/// first, at most [`LEFT_PLACES`].
fn places(rest: &[f64], zmap: &scallop_sim::ZMap) -> Vec<crate::RestPlaceReport> {
    scallop_sim::rest_places(rest, zmap)
        .into_iter()
        .take(LEFT_PLACES)
        .map(|p| crate::RestPlaceReport { at: [p.at.x, p.at.y], area_mm2: p.area, depth_mm: p.depth })
        .collect()
}
