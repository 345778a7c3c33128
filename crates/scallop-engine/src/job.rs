//! Jobs as a sequence of operations on one stock ([`run_job`]): each operation
//! is planned on the part, cut from the one simulated stock that the
//! operations before it left (it reads that stock through
//! [`scallop_sim::StockView`]), and the proof (gouges, collisions, material
//! left) runs on the stock they all left. One program with a tool change per
//! operation.

use scallop_geom::{Aabb3, Tolerances};
use scallop_mesh::TriMesh;
use scallop_post::{ProgramInfo, Section, write_sections};
use scallop_sim::{PartField, StockView, ZMap, verify_in};
use scallop_toolpath::{FittedPath, Toolpath};
use serde::Serialize;

use crate::finish::{
    PlannedOperation, cutter_text, fit_and_comment, network_scallop_from, plan_operation, planning_tolerances,
    verify_options,
};
use crate::rough::{PlannedRough, plan_rough_operation};
use crate::{EngineError, FinishJob, PreparedPart, prepare_part, stock_box};

/// Height kept between the highest material of the in-process stock and the
/// rapids of an operation (mm): an operation's clearance plane is at least
/// this far above what the operations before it left.
pub const STOCK_CLEARANCE_MM: f64 = 2.0;

/// One operation of a [`Job`].
#[derive(Debug, Clone)]
pub struct Operation {
    /// How the program and the report name it.
    pub name: String,
    /// What it does: a finishing operation (its part, tolerances, machine,
    /// verification and output settings must be those of the job's other
    /// operations; its tool and spindle are its own).
    pub finish: FinishJob,
    /// `Some`: a roughing operation with these settings instead (its cutter,
    /// tool, spindle, feeds and clearance are those of `finish`, whose
    /// finishing settings are not used).
    pub rough: Option<scallop_rough::RoughSettings>,
}

/// What planning one operation produced.
enum Planned {
    Finish(Box<PlannedOperation>),
    Rough(Box<PlannedRough>),
}

impl Planned {
    fn toolpath(&self) -> &Toolpath {
        match self {
            Planned::Finish(p) => &p.plan.toolpath,
            Planned::Rough(r) => &r.toolpath,
        }
    }

    fn report(&self) -> &scallop_strategy::Report {
        match self {
            Planned::Finish(p) => &p.plan.report,
            Planned::Rough(r) => &r.report,
        }
    }

    fn direction_deg(&self) -> f64 {
        match self {
            Planned::Finish(p) => p.direction_deg,
            Planned::Rough(_) => 0.0,
        }
    }
}

/// The stock of a [`Job`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StockShape {
    /// A box (mm, part frame).
    Box(Aabb3),
    /// The part's box grown by `margin` in X and Y (default: the largest
    /// cutter radius of the operations), `top` above and `bottom` below (mm).
    AroundPart {
        /// Margin in X and Y; `None`: the largest cutter radius.
        margin: Option<f64>,
        /// Stock above the part's top.
        top: f64,
        /// Stock below the part's bottom.
        bottom: f64,
    },
}

/// A job: operations in order on one stock.
#[derive(Debug, Clone)]
pub struct Job {
    /// The stock; `None`: [`stock_box`] of the part with the largest cutter
    /// of the operations.
    pub stock: Option<StockShape>,
    /// The operations, in machining order (at least one).
    pub operations: Vec<Operation>,
}

/// What one operation met on the stock and what it removed.
#[derive(Debug, Clone, Serialize)]
pub struct StockFigures {
    /// Highest material of the stock the operation received (mm).
    pub top_before_mm: f64,
    /// Volume of that stock (mm^3).
    pub volume_before_mm3: f64,
    /// Volume this operation removed (mm^3).
    pub removed_mm3: f64,
    /// Share of its feed moves that removed nothing (air), in [0, 1].
    pub air_cut_share: f64,
    /// Share of its feed length that removed nothing (air), in [0, 1].
    pub air_length_share: f64,
    /// The clearance above the part's top its rapids ran at (mm): the job's,
    /// raised to clear the stock by [`STOCK_CLEARANCE_MM`].
    pub clearance_mm: f64,
}

/// The engagement of a roughing operation, read by the simulator on the stock
/// the operation received, cut move by move (`scallop_sim::stock_engagement`;
/// docs/simulation.md, "Engagement on the in-process stock"). Angles in
/// degrees, lengths in mm; entries (within 2 R of where the tool reached
/// cutting depth) are reported apart and not counted in the percentiles.
#[derive(Debug, Clone, Serialize)]
pub struct EngagementFigures {
    /// The target, `arccos(1 - stepover D / R)`.
    pub target_deg: f64,
    /// Median engagement of the samples that cut.
    pub p50_deg: f64,
    /// 95th percentile.
    pub p95_deg: f64,
    /// 99th percentile.
    pub p99_deg: f64,
    /// Largest engagement outside entries.
    pub max_deg: f64,
    /// Where it is: tool centre x, y (mm) and the move's index in the
    /// operation's toolpath.
    pub max_at: Option<([f64; 2], usize)>,
    /// Largest engagement inside entries.
    pub entry_max_deg: f64,
    /// Length above 1.2 x the target.
    pub over_length_mm: f64,
    /// Length at or above 170 degrees (a full slot).
    pub slot_length_mm: f64,
    /// Length of the moves that cut.
    pub cutting_length_mm: f64,
    /// Share of the cutting moves' length below 2 degrees.
    pub air_share: f64,
    /// Share of the feed length at cutting depth in moves that cut nothing.
    pub link_share: f64,
    /// Times the tool reached cutting depth, and left it.
    pub entries: usize,
    /// Times it left.
    pub retracts: usize,
    /// The largest engagement of each move of the operation (degrees; 0 where
    /// it cuts nothing): the report's colouring.
    #[serde(skip)]
    pub move_deg: Vec<f64>,
}

impl EngagementFigures {
    fn of(r: &scallop_sim::EngagementReport) -> EngagementFigures {
        EngagementFigures {
            target_deg: r.target.to_degrees(),
            p50_deg: r.p50.to_degrees(),
            p95_deg: r.p95.to_degrees(),
            p99_deg: r.p99.to_degrees(),
            max_deg: r.max.to_degrees(),
            max_at: r.max_at.map(|(p, i)| ([p.x, p.y], i)),
            entry_max_deg: r.entry_max.to_degrees(),
            over_length_mm: r.over_length,
            slot_length_mm: r.slot_length,
            cutting_length_mm: r.cutting_length,
            air_share: r.air_share(),
            link_share: r.link_share(),
            entries: r.entries,
            retracts: r.retracts,
            move_deg: r.move_phi.iter().map(|p| p.to_degrees()).collect(),
        }
    }
}

/// What a roughing operation left above its allowance, read on the stock it
/// left (docs/roughing.md, "Material left above the allowance"): the material
/// above the part grown by the allowances, split into the steps the levels
/// leave where the cutter reaches and the places it cannot reach (a corner
/// sharper than it, a slot narrower than it), which a smaller tool or the
/// finishing must take.
#[derive(Debug, Clone, Serialize)]
pub struct LeftFigures {
    /// Material thinner than this above the part grown by the allowances is
    /// not counted (mm): the minimum chip of rest roughing
    /// (`scallop_geom::tol::rough::MIN_CHIP`) and the stock's rounding.
    pub limit_mm: f64,
    /// Volume above the part grown by the allowances (mm^3), reachable or not.
    pub volume_mm3: f64,
    /// Largest height of material above the part grown by the allowances
    /// where the cutter reaches (mm): the steps between levels on slopes.
    pub reached_max_mm: f64,
    /// Where it is, `[x, y]` (mm).
    pub reached_at: Option<[f64; 2]>,
    /// Area where the cutter cannot take the stock down to the part grown by
    /// the allowances (mm^2).
    pub unreachable_area_mm2: f64,
    /// The part of `volume_mm3` there (mm^3).
    pub unreachable_volume_mm3: f64,
    /// Largest height of material there above the part grown by the allowances (mm).
    pub unreachable_depth_mm: f64,
    /// The unreachable places, largest first (at most ten).
    pub places: Vec<crate::RestPlaceReport>,
}

/// The report of one operation.
#[derive(Debug, Clone, Serialize)]
pub struct OperationReport {
    /// Its name.
    pub name: String,
    /// Its cutter.
    pub cutter: String,
    /// Tool number in the program.
    pub tool: u32,
    /// Scallop height asked (mm).
    pub scallop_height_mm: f64,
    /// Feed direction from +X (degrees).
    pub direction_deg: f64,
    /// The planner's figures (times, lengths, passes, measured scallop).
    pub plan: scallop_strategy::Report,
    /// What it met on the stock.
    pub stock: StockFigures,
    /// A roughing operation's engagement as the simulator read it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub engagement: Option<EngagementFigures>,
    /// What a roughing operation left above its allowance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub left: Option<LeftFigures>,
}

/// The report of a job (`report.json`).
#[derive(Debug, Clone, Serialize)]
pub struct JobReport {
    /// Part.
    pub part: String,
    /// The stock box (mm): min and max corners.
    pub stock_mm: [[f64; 3]; 2],
    /// One entry per operation, in order.
    pub operations: Vec<OperationReport>,
    /// Predicted time of the whole program (s, stop-to-stop model, rapids included).
    pub total_time_s: f64,
    /// Cell size of the stock simulation (mm).
    pub sim_resolution_mm: f64,
    /// Largest material thickness along the part normal on the final stock,
    /// beyond the last cutter's radius from the part's edge (mm).
    pub sim_max_scallop_mm: f64,
    /// The simulation's resolution bound for the last cutter (mm).
    pub sim_resolution_bound_mm: f64,
    /// Deepest stock-minus-part deviation on the final stock (mm).
    pub sim_min_deviation_mm: f64,
    /// Gouge tolerance the simulation enforced (mm).
    pub sim_gouge_tolerance_mm: f64,
    /// Material the last operation's cutter cannot reach (none when the area is 0).
    pub rest: crate::RestReport,
}

/// The outputs of [`run_job`].
#[derive(Debug, Clone)]
pub struct JobOutput {
    /// Each operation's toolpath (part frame), in order.
    pub toolpaths: Vec<Toolpath>,
    /// All toolpaths joined (the program's moves), each operation's moves in order.
    pub toolpath: Toolpath,
    /// The G-code text: one program, a tool change per operation.
    pub gcode: String,
    /// The figures.
    pub report: JobReport,
    /// The mesh the cutters were dropped on.
    pub prepared: PreparedPart,
    /// The final stock and its verification.
    pub simulation: scallop_sim::Simulation,
}

/// The stock box of `job` around its (prepared) part `mesh`.
pub(crate) fn job_stock(job: &Job, mesh: &TriMesh) -> Aabb3 {
    let radius = job.operations.iter().map(|o| o.finish.cutter.radius()).fold(0.0, f64::max);
    match job.stock {
        None => stock_box(mesh, radius),
        Some(StockShape::Box(b)) => b,
        Some(StockShape::AroundPart { margin, top, bottom }) => {
            let mut b = stock_box(mesh, margin.unwrap_or(radius));
            b.max.z += top - 1.0;
            b.min.z -= bottom - 1.0;
            b
        }
    }
}

/// Runs the operations of `job` in order on one simulated stock and proves
/// the result (see the module documentation).
///
/// # Errors
/// No operation; operations that disagree on the shared settings; a 3+2
/// setup in a job of several operations (not supported yet); every error of
/// [`crate::run_finishing`] (planning, safety problems found by the
/// simulation of each operation on the stock the others left).
pub fn run_job(job: &Job) -> Result<JobOutput, EngineError> {
    run_job_with_progress(job, &|_| {})
}

/// Where [`run_job_with_progress`] is: operation `index` (0-based) of
/// `count` enters `phase`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct JobStep {
    /// The operation (0-based); `count` for the final proof and the program.
    pub index: usize,
    /// Number of operations.
    pub count: usize,
    /// What starts now.
    pub phase: JobPhase,
}

/// The phases of a job that [`run_job_with_progress`] announces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JobPhase {
    /// Planning an operation's toolpath.
    Planning,
    /// Cutting the operation from the simulated stock and checking it.
    Cutting,
    /// Proving the stock all operations left, and writing the program.
    Proving,
}

/// [`run_job`], calling `progress` as each operation enters a phase (in
/// order: planning then cutting per operation, then proving once). The
/// caller may time the phases: the planning time of operation `k` is the
/// time between its `Planning` and `Cutting` steps.
///
/// # Errors
/// As [`run_job`].
pub fn run_job_with_progress(job: &Job, progress: &dyn Fn(JobStep)) -> Result<JobOutput, EngineError> {
    let count = job.operations.len();
    let first = &check_operations(job)?.finish;
    let tolerances = planning_tolerances(first)?;
    let prepared = prepare_part(&first.part, &tolerances)?;
    let stock = job_stock(job, &prepared.mesh);
    let mut zmap = ZMap::new(stock, first.sim_resolution)?;
    let field = PartField::new(&zmap, &prepared.index);
    let part_top = prepared.mesh.bounds().max.z;
    let mut planned: Vec<(Planned, StockFigures, Option<EngagementFigures>)> = Vec::with_capacity(job.operations.len());
    let mut lefts: Vec<Option<LeftFigures>> = Vec::with_capacity(job.operations.len());
    for (index, op) in job.operations.iter().enumerate() {
        progress(JobStep { index, count, phase: JobPhase::Planning });
        let f = &op.finish;
        let top_before = zmap.max_top().unwrap_or(stock.min.z);
        let clearance = f.clearance.max(top_before + STOCK_CLEARANCE_MM - part_top);
        let p = match &op.rough {
            Some(r) => {
                let material = crate::rough::material_of(&zmap)?;
                Planned::Rough(Box::new(plan_rough_operation(
                    f,
                    r,
                    &prepared,
                    &stock,
                    material.as_ref(),
                    clearance,
                    &tolerances,
                )?))
            }
            None => Planned::Finish(Box::new(plan_operation(
                f,
                &prepared,
                &tolerances,
                Some(clearance),
                &scallop_strategy::Refinement::default(),
            )?)),
        };
        progress(JobStep { index, count, phase: JobPhase::Cutting });
        let engagement = match &op.rough {
            Some(r) => {
                let radius = f.cutter.shape().radius();
                let target = scallop_sim::engagement_angle(2.0 * radius * r.stepover, radius);
                let options = scallop_sim::EngagementOptions::default();
                let read = scallop_sim::stock_engagement(&zmap, &f.cutter, p.toolpath(), target, &options)?;
                Some(EngagementFigures::of(&read))
            }
            None => None,
        };
        let volume_before = zmap.volume();
        let cut = zmap.cut(&f.cutter, p.toolpath())?;
        if !cut.rapid_hits.is_empty() {
            cut.check()?;
        }
        let collisions = zmap.part_collisions_in(&field, &f.cutter, p.toolpath(), cut.operation)?;
        if !collisions.is_empty() {
            return Err(scallop_sim::SimError::PartCollision { collisions }.into());
        }
        cut.check()?;
        let figures = StockFigures {
            top_before_mm: top_before,
            volume_before_mm3: volume_before,
            removed_mm3: cut.removed_volume,
            air_cut_share: cut.air_cut_share(),
            air_length_share: cut.air_length_share(),
            clearance_mm: clearance,
        };
        planned.push((p, figures, engagement));
        lefts.push(match &op.rough {
            Some(r) => Some(crate::rough::left_above_allowance(&zmap, &field, &prepared, &f.cutter, r)?),
            None => None,
        });
    }
    let Some(last) = job.operations.last().map(|o| &o.finish) else {
        return Err(no_operation());
    };
    progress(JobStep { index: count, count, phase: JobPhase::Proving });
    let (gouge_tolerance, options) = verify_options(last, &prepared);
    let verification = verify_in(&zmap, &field, &options)?;
    let simulation = scallop_sim::Simulation { zmap, cut: empty_cut(), verification };
    let mut rest = crate::RestReport::default();
    if last.strategy.simulation_verifies_scallop()
        && let Some((Planned::Finish(p), _, _)) = planned.last_mut()
    {
        rest = network_scallop_from(&simulation, last, &prepared, &options, &mut p.plan.report)?;
    }
    let gcode = program(job, &planned, &prepared, &tolerances)?;
    let mut toolpath = Toolpath::new(first.machine[0] * 1000.0);
    let mut reports = Vec::with_capacity(planned.len());
    let mut total_time = 0.0;
    for (((p, figures, engagement), left), (k, op)) in planned.iter().zip(lefts).zip(job.operations.iter().enumerate())
    {
        toolpath.extend_from(p.toolpath());
        total_time += p.report().total_time_s;
        reports.push(OperationReport {
            name: op.name.clone(),
            cutter: cutter_text(op.finish.cutter.shape()),
            tool: tool_number(&op.finish, k),
            scallop_height_mm: if op.rough.is_some() { 0.0 } else { op.finish.scallop_height },
            direction_deg: p.direction_deg(),
            plan: p.report().clone(),
            stock: figures.clone(),
            engagement: engagement.clone(),
            left,
        });
    }
    let v = &simulation.verification;
    let report = JobReport {
        part: first.part_name.clone(),
        stock_mm: [stock.min.coords.into(), stock.max.coords.into()],
        operations: reports,
        total_time_s: total_time,
        sim_resolution_mm: first.sim_resolution,
        sim_max_scallop_mm: if rest.machined_scallop_mm > 0.0 { rest.machined_scallop_mm } else { v.max_thickness },
        sim_resolution_bound_mm: simulation.zmap.resolution_bound(last.cutter.shape()),
        sim_min_deviation_mm: v.min_deviation,
        sim_gouge_tolerance_mm: gouge_tolerance,
        rest,
    };
    let toolpaths = planned.iter().map(|(p, _, _)| p.toolpath().clone()).collect();
    Ok(JobOutput { toolpaths, toolpath, gcode, report, prepared, simulation })
}

fn no_operation() -> EngineError {
    EngineError::Output { what: "a job without operations".into(), fix: "give at least one [[operation]]".into() }
}

/// The first operation, once the operations agree on what they share.
fn check_operations(job: &Job) -> Result<&Operation, EngineError> {
    let first = job.operations.first().ok_or_else(no_operation)?;
    let f = &first.finish;
    for (k, op) in job.operations.iter().enumerate() {
        let o = &op.finish;
        if o.setup.is_some() && job.operations.len() > 1 {
            return Err(EngineError::Output {
                what: format!("operation {} (`{}`) has a 3+2 [setup] in a job of several operations", k + 1, op.name),
                fix: "run 3+2 operations as jobs of their own (one stock per setup is not supported yet)".into(),
            });
        }
        let same = o.tolerances == f.tolerances
            && o.sim_resolution.to_bits() == f.sim_resolution.to_bits()
            && o.output.dialect.name == f.output.dialect.name
            && o.output.arc_fitting == f.output.arc_fitting
            && o.part_name == f.part_name;
        if !same {
            return Err(EngineError::Output {
                what: format!(
                    "operation {} (`{}`) differs from the first in its part, tolerances, verify resolution or output",
                    k + 1,
                    op.name
                ),
                fix: "give the operations of one job the same part and the job-level settings".into(),
            });
        }
    }
    Ok(first)
}

/// The tool number of operation `k`: its own, else `k + 1`.
fn tool_number(job: &FinishJob, k: usize) -> u32 {
    if job.output.tool > 0 { job.output.tool } else { u32::try_from(k + 1).unwrap_or(u32::MAX) }
}

fn empty_cut() -> scallop_sim::CutReport {
    scallop_sim::CutReport {
        operation: 0,
        removed_by_move: Vec::new(),
        removed_volume: 0.0,
        feed_moves: 0,
        air_feed_moves: 0,
        feed_length_mm: 0.0,
        air_feed_length_mm: 0.0,
        rapid_hits: Vec::new(),
        collisions: Vec::new(),
    }
}

/// One program: the job's header comments, then each operation's section.
fn program(
    job: &Job,
    planned: &[(Planned, StockFigures, Option<EngagementFigures>)],
    prepared: &PreparedPart,
    tolerances: &Tolerances,
) -> Result<String, EngineError> {
    let mut fitted: Vec<(FittedPath, Vec<String>)> = Vec::with_capacity(planned.len());
    let mut header: Vec<String> = Vec::new();
    for (k, ((p, _, _), op)) in planned.iter().zip(&job.operations).enumerate() {
        let (f, comments) = match p {
            Planned::Finish(p) => fit_and_comment(&op.finish, p, prepared, tolerances),
            Planned::Rough(r) => crate::rough::fit_and_comment(&op.finish, r),
        };
        if k == 0 {
            header.push(comments[0].clone());
        }
        fitted.push((f, comments));
    }
    let sections: Vec<Section<'_>> = fitted
        .iter()
        .zip(&job.operations)
        .enumerate()
        .map(|(k, ((f, comments), op))| Section {
            path: f,
            info: ProgramInfo {
                program: String::new(),
                tool: tool_number(&op.finish, k),
                spindle: op.finish.output.spindle,
                indexed_rotaries: Vec::new(),
            },
            title: format!("operation {} `{}`: {}", k + 1, op.name, comments[1..].join("; ")),
        })
        .collect();
    let first = &job.operations[0].finish;
    let refs: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut text = Vec::new();
    write_sections(&sections, &first.output.dialect, &first.output.program, &refs, &mut text)
        .map_err(|e| EngineError::Output { what: format!("writing the program: {e}"), fix: String::new() })?;
    Ok(String::from_utf8_lossy(&text).into_owned())
}

#[cfg(test)]
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
mod tests {
    use super::*;
    use scallop_cutter::{Cutter, CutterShape};

    fn coarse_then_fine() -> Job {
        let mut coarse = FinishJob::choi_demo();
        coarse.cutter = Cutter::new(CutterShape::Ball { radius: 4.0 }, 40.0).unwrap();
        coarse.scallop_height = 0.2;
        let mut fine = FinishJob::choi_demo();
        fine.scallop_height = 0.03;
        // Flutes long enough to cut the whole stock alone (the comparison below).
        fine.cutter = Cutter::new(CutterShape::Bull { radius: 5.0, corner: 2.0 }, 60.0).unwrap();
        let mut stock = stock_box(&prepare_part(&fine.part, &fine.tolerances).unwrap().mesh, 5.0);
        stock.max.z += 9.0;
        Job {
            stock: Some(StockShape::Box(stock)),
            operations: vec![
                Operation { name: "coarse ball".into(), finish: coarse, rough: None },
                Operation { name: "fine bull-nose".into(), finish: fine, rough: None },
            ],
        }
    }

    /// The second operation sees the stock the first one left: it receives
    /// the volume the first left and removes far less than it would from the
    /// fresh stock; the rapids of both clear the tall stock's untouched
    /// corners (a rapid into stock would fail the job); the program changes
    /// tools between them and the final stock holds the fine scallop.
    #[test]
    fn the_second_operation_sees_the_stock_the_first_left() {
        let job = coarse_then_fine();
        let out = run_job(&job).unwrap();
        let [a, b] = [&out.report.operations[0], &out.report.operations[1]];
        let part_top = out.prepared.mesh.bounds().max.z;
        let Some(StockShape::Box(stock)) = job.stock else { panic!("a box stock") };
        let stock_top = stock.max.z;
        assert_eq!(a.stock.top_before_mm, stock_top);
        assert!((a.stock.clearance_mm - (stock_top + STOCK_CLEARANCE_MM - part_top)).abs() < 1e-9, "{:?}", a.stock);
        assert!(a.stock.clearance_mm > job.operations[0].finish.clearance, "{:?}", a.stock);
        let after_first = a.stock.volume_before_mm3 - a.stock.removed_mm3;
        assert!((b.stock.volume_before_mm3 - after_first).abs() < 1e-9 * a.stock.volume_before_mm3, "{a:?} {b:?}");
        let alone = Job { stock: job.stock, operations: vec![job.operations[1].clone()] };
        let alone = run_job(&alone).unwrap();
        let fresh = &alone.report.operations[0].stock;
        assert!(b.stock.removed_mm3 < 0.05 * fresh.removed_mm3, "{:?} vs {fresh:?}", b.stock);
        assert!((fresh.volume_before_mm3 - a.stock.volume_before_mm3).abs() < 1e-9 * fresh.volume_before_mm3);
        // One program, two tools, the spindle stopped before the second change.
        let text = &out.gcode;
        let (t1, t2) = (text.find("T1 M6").unwrap(), text.find("T2 M6").unwrap());
        assert!(t1 < t2 && text[t1..t2].contains("M5"), "{text}");
        assert_eq!(text.matches("M2").count(), 1);
        // The final stock: no gouge (run_job would fail) and the fine scallop.
        let r = &out.report;
        assert!(r.sim_max_scallop_mm <= 0.03 + r.sim_resolution_bound_mm, "{r:?}");
        assert_eq!(out.toolpath.moves().len(), out.toolpaths.iter().map(|t| t.moves().len()).sum::<usize>());
    }

    #[test]
    fn operations_must_share_the_job_settings() {
        let mut job = coarse_then_fine();
        job.operations[1].finish.sim_resolution = 0.2;
        assert!(matches!(run_job(&job), Err(EngineError::Output { .. })));
        job.operations.clear();
        assert!(matches!(run_job(&job), Err(EngineError::Output { .. })));
    }
}
