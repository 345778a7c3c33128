//! The main job (`scallop demo`): the Choi surface finished with a bull-nose
//! cutter R = 5, r = 2 mm at a guaranteed scallop height of 0.01 mm, along the
//! steepest-slope direction of the surface's PCA plane (what the tool-choice
//! rule of the finishing spec picks for this surface), with the machining time
//! of the spec's machine (V = 5 m/min, A = 6 m/s², J = 40 m/s³), plain
//! G-code, and a stock simulation that proves the program before it is
//! written.

use scallop_analysis::{
    GridOptions, MachineLimits, Recommendation, ToolOptions, analyze, sample_mesh, sample_surface_set,
};
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::nalgebra::Rotation3;
use scallop_geom::{Aabb3, Point3, Tolerances, Vec3};
use scallop_machine::frame::SetupFrame;
use scallop_machine::program::{MachineProgram, ProgramOptions, records_from_toolpath, to_program};
use scallop_machine::{Kinematics, Machine};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_post::{Dialect, OutputMode, PostParams, ProgramInfo, program_text, write_fitted};
use scallop_strategy::{
    Boundary, FinishingParams, IsoDirection, IsoSurface, LeadKind, LeadReport, Pattern, Refinement, SteepShallow,
    apply_leads, lookahead_time, plan_finishing_refined, plan_isoparametric, plan_steep_shallow, stop_to_stop_time,
};
use scallop_toolpath::{FittedPath, Move, MoveKind, Toolpath, fit_arcs};
use serde::Serialize;

use crate::refine::{Layout, MAX_ROUNDS, merged, refinement_for};
use crate::{ARC_SHARE, EngineError, Part, PreparedPart, prepare_part};

/// How the program is written.
#[derive(Debug, Clone)]
pub struct OutputOptions {
    /// Controller dialect (3-axis ISO: `plain`, `linuxcnc`, `fanuc`, `grbl`, ...).
    pub dialect: Dialect,
    /// Replace runs of cutting moves by `G2`/`G3` arcs within `ARC_SHARE * path`.
    pub arc_fitting: bool,
    /// Program name or number.
    pub program: String,
    /// Tool number (0: no tool change).
    pub tool: u32,
    /// Spindle speed (1/min; 0: no spindle word).
    pub spindle: f64,
}

impl OutputOptions {
    /// LinuxCNC (4 decimals: the program replays within 1e-4 mm), no arcs, no tool
    /// change.
    ///
    /// # Panics
    /// Never: the shipped dialect parses (tested in `scallop-post`).
    #[must_use]
    pub fn linuxcnc() -> OutputOptions {
        // INVARIANT: the shipped dialect files parse.
        #[allow(clippy::unwrap_used, clippy::missing_panics_doc)]
        let dialect = Dialect::builtin("linuxcnc").unwrap();
        OutputOptions { dialect, arc_fitting: false, program: "1".into(), tool: 0, spindle: 0.0 }
    }
}

/// 3+2 setup: the part is turned by `rotation` (part frame -> planning frame, where the
/// tool is vertical), planned there as a 3-axis job, and written as indexed 5-axis
/// output for `machine` (the tool axis `rotation^-1 z` held constant, rotaries moved on
/// the first rapid only).
#[derive(Debug, Clone)]
pub struct Setup {
    /// Part frame -> planning frame.
    pub rotation: Rotation3<f64>,
    /// The machine description (`scallop_machine::Machine::builtin` name) whose
    /// kinematics turn the indexed tool axis into rotary words.
    pub machine: Machine,
    /// Tool length the kinematics use (mm; 0 when the controller applies it).
    pub tool_length: f64,
}

/// A finishing job (mm, seconds; machine limits in the spec's units).
#[derive(Debug, Clone)]
pub struct FinishJob {
    /// The part.
    pub part: Part,
    /// How to call it in reports.
    pub part_name: String,
    /// The cutter (ball, flat or bull-nose).
    pub cutter: Cutter,
    /// Scallop height sh (mm).
    pub scallop_height: f64,
    /// Feed direction from +X (degrees); `None`: from the PCA of the part (the
    /// steepest slope for bull-nose and flat cutters, the principal direction
    /// for a ball).
    pub direction_deg: Option<f64>,
    /// Zigzag or one-way.
    pub pattern: Pattern,
    /// Feed V (m/min), acceleration A (m/s²), jerk J (m/s³).
    pub machine: [f64; 3],
    /// Rapid rate (mm/s).
    pub rapid_rate: f64,
    /// Clearance above the part's top (mm).
    pub clearance: f64,
    /// Path and gouge tolerances (mm).
    pub tolerances: Tolerances,
    /// Longest forward step between drop-cutter samples (mm).
    pub max_step: f64,
    /// Cell size of the verifying stock simulation (mm).
    pub sim_resolution: f64,
    /// How the program is written.
    pub output: OutputOptions,
    /// 3+2 setup; `None` for 3-axis work in the part frame.
    pub setup: Option<Setup>,
    /// Lead-in/lead-out at plunges and retracts.
    pub leads: LeadKind,
    /// Parallel planes or isoparametric passes.
    pub strategy: Strategy,
}

impl FinishJob {
    /// The machine and feed parameters the planners time this job's moves
    /// with (the feed direction left at 0: timing does not use it).
    #[must_use]
    pub fn timing_params(&self) -> FinishingParams {
        finishing_params(self, 0.0)
    }

    /// The spec's main job: the Choi surface, bull-nose R 5 r 2, sh 0.01 mm,
    /// V 5 m/min, A 6 m/s², J 40 m/s³, along the PCA steepest slope.
    ///
    /// # Panics
    /// Never: the built-in part and cutter are valid (checked by tests).
    #[must_use]
    pub fn choi_demo() -> FinishJob {
        // INVARIANT: the built-in surface exists and the cutter sizes are valid.
        #[allow(clippy::unwrap_used, clippy::missing_panics_doc)]
        let (part, cutter) = (
            Part::builtin("choi").unwrap(),
            Cutter::new(CutterShape::Bull { radius: 5.0, corner: 2.0 }, 30.0).unwrap(),
        );
        FinishJob {
            part,
            part_name: "built-in choi surface".into(),
            cutter,
            scallop_height: 0.01,
            direction_deg: None,
            pattern: Pattern::Zigzag,
            machine: [5.0, 6.0, 40.0],
            rapid_rate: RAPID_RATE,
            clearance: 5.0,
            tolerances: Tolerances { path: 0.01, gouge: 0.0 },
            max_step: 0.5,
            sim_resolution: 0.1,
            output: OutputOptions::linuxcnc(),
            setup: None,
            leads: LeadKind::None,
            strategy: Strategy::ParallelPlanes,
        }
    }
}

/// What the job produced (serialisable as `report.json`).
#[derive(Debug, Clone, Serialize)]
pub struct FinishReport {
    /// Part.
    pub part: String,
    /// Cutter.
    pub cutter: String,
    /// Scallop height asked (mm).
    pub scallop_height_mm: f64,
    /// Feed direction from +X (degrees).
    pub direction_deg: f64,
    /// What the tool-choice analysis recommends for this part.
    pub recommendation: Recommendation,
    /// PCA slope of the part (degrees) and its critical slope (degrees).
    pub slope_deg: f64,
    /// Critical slope s_c(mu) (degrees).
    pub critical_slope_deg: f64,
    /// Distance between the surface and the mesh the cutter was dropped on (mm).
    pub chordal_error_mm: f64,
    /// The planner's figures (times, lengths, passes, verified scallop).
    pub plan: scallop_strategy::Report,
    /// Cell size of the stock simulation (mm).
    pub sim_resolution_mm: f64,
    /// Largest material left on the simulated stock (mm; includes the simulation's resolution effects).
    pub sim_max_material_mm: f64,
    /// Largest material thickness along the part normal on the simulated stock
    /// farther than the cutter radius from the part's edge (mm): the scallop
    /// height the plan guarantees, as the simulation measures it.
    pub sim_max_scallop_mm: f64,
    /// The same within the cutter radius of the part's edge (mm; shaped by pass
    /// ends and the outer planes, not held to the scallop height).
    pub sim_edge_max_scallop_mm: f64,
    /// The simulation's resolution bound for this cutter and cell size (mm),
    /// see `scallop_sim::ZMap::resolution_bound`.
    pub sim_resolution_bound_mm: f64,
    /// Deepest stock-minus-part deviation on the simulated stock (mm).
    pub sim_min_deviation_mm: f64,
    /// Gouge tolerance the simulation enforced (mm).
    pub sim_gouge_tolerance_mm: f64,
    /// Leads applied, and those replaced by straight plunges (with where and why).
    pub leads: LeadReport,
    /// Material the cutter cannot reach (none when the area is 0): reported
    /// apart from the scallop, which it never counts in.
    pub rest: RestReport,
}

/// The job's outputs.
#[derive(Debug, Clone)]
pub struct FinishOutput {
    /// The toolpath.
    pub toolpath: Toolpath,
    /// The G-code text.
    pub gcode: String,
    /// The report.
    pub report: FinishReport,
    /// What the 3-axis program was written from (lines and arcs, planning frame);
    /// lines only for 3+2 output.
    pub fitted: FittedPath,
    /// What the pictures and the HTML report show (`scallop-report`).
    pub details: FinishDetails,
}

/// The intermediate results behind a [`FinishReport`], kept for reports and
/// pictures: the part as cut, the stock, the planner's settings, the measured
/// scallop and the simulated stock.
#[derive(Debug, Clone)]
pub struct FinishDetails {
    /// The mesh the cutter was dropped on, and its index.
    pub prepared: PreparedPart,
    /// The stock box of the simulation.
    pub stock: Aabb3,
    /// The settings the planner ran with (for the look-ahead feed profile).
    pub params: FinishingParams,
    /// The verified scallop of parallel planes (histogram, pairs); isoparametric
    /// passes are checked by `iso_scallop`, which keeps no histogram.
    pub scallop: Option<scallop_strategy::ScallopReport>,
    /// The simulated stock and its verification.
    pub simulation: scallop_sim::Simulation,
}

/// Runs the finishing job. `planning_seconds` is measured by the caller and
/// written into the report (the library reads no clock).
///
/// # Errors
/// Bad settings, an unknown part, a plan that cannot hold the scallop height,
/// or a safety problem found by the stock simulation.
pub fn run_finishing(job: &FinishJob) -> Result<FinishOutput, EngineError> {
    run_finishing_with_progress(job, &|_| {})
}

/// What [`run_finishing_with_progress`] is doing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FinishStep {
    /// Planning the toolpath with this strategy.
    Planning(Strategy),
    /// Cutting the simulated stock: `done` of `total` bands of rows
    /// ([`scallop_sim::ZMap::cut_with_progress`]).
    Cutting {
        /// Bands cut.
        done: usize,
        /// All bands.
        total: usize,
    },
    /// Measuring the scallop and the material left, writing the program.
    Verifying,
    /// Planning again with planes or levels added where the simulation found
    /// the scallop over sh (round 1, 2, ...; see docs/simulation.md, "Refinement").
    Refining {
        /// The refinement round.
        round: usize,
    },
}

/// [`run_finishing`], calling `progress` as it goes (planning, then the cut
/// with its count of bands, then the proof).
///
/// # Errors
/// As [`run_finishing`].
pub fn run_finishing_with_progress(
    job: &FinishJob,
    progress: &(dyn Fn(FinishStep) + Sync),
) -> Result<FinishOutput, EngineError> {
    let tolerances = planning_tolerances(job)?;
    let prepared = prepare_part(&job.part, &tolerances)?;
    let prepared = match &job.setup {
        Some(setup) => rotate_prepared(&prepared, &setup.rotation)?,
        None => prepared,
    };
    let stock = stock_box(&prepared.mesh, job.cutter.radius());
    let (gouge_tolerance, options) = verify_options(job, &prepared);
    let mut refine = Refinement::default();
    let (mut round, mut first) = (0, (0, 0));
    let (mut op, sim, rest) = loop {
        progress(if round == 0 { FinishStep::Planning(job.strategy) } else { FinishStep::Refining { round } });
        let mut op = plan_operation(job, &prepared, &tolerances, None, &refine)?;
        if round == 0 {
            first = (op.plan.layout.planes.len(), op.plan.layout.levels.len());
        }
        let sim = scallop_sim::simulate_with_progress(
            stock,
            job.sim_resolution,
            &job.cutter,
            &op.plan.toolpath,
            &prepared.index,
            &options,
            &|done, total| progress(FinishStep::Cutting { done, total }),
        )?;
        progress(FinishStep::Verifying);
        if !job.strategy.simulation_verifies_scallop() {
            break (op, sim, RestReport::default());
        }
        let split = scallop_split(&sim, job, &prepared, &options);
        let more =
            if split.holds() || round == MAX_ROUNDS || op.plan.layout.planes.len() + op.plan.layout.levels.len() == 0 {
                Refinement::default()
            } else {
                refinement_for(&op.plan.layout, &split.over, &job.cutter, &prepared.index)
            };
        let all = merged(&refine, &more);
        if more.is_empty() || all == refine {
            let rest = accept_scallop(split, &sim, job, &mut op.plan.report)?;
            break (op, sim, rest);
        }
        refine = all;
        round += 1;
    };
    op.plan.report.refinement = (round > 0).then_some(scallop_strategy::RefinementReport {
        rounds: round,
        planes_added: op.plan.layout.planes.len().saturating_sub(first.0),
        levels_added: op.plan.layout.levels.len().saturating_sub(first.1),
    });
    let (fitted, comments) = fit_and_comment(job, &op, &prepared, &tolerances);
    let text = match &job.setup {
        None => three_axis_program(job, &fitted, &comments)?,
        Some(setup) => indexed_program(job, setup, &op.plan.toolpath, op.plan.report.machining_time_s)?,
    };
    let report = finish_report(job, &op, &prepared, &sim, gouge_tolerance, rest);
    let details = FinishDetails { prepared, stock, params: op.params, scallop: op.plan.scallop, simulation: sim };
    Ok(FinishOutput { toolpath: op.plan.toolpath, gcode: text, report, fitted, details })
}

/// The stock box of a part when the job gives none: the part's box grown by
/// the cutter radius in X and Y, from 1 mm below to 1 mm above the part (the
/// one rule of the engine, also used by the CLI's `simulate`).
#[must_use]
pub fn stock_box(mesh: &TriMesh, radius: f64) -> Aabb3 {
    let b = mesh.bounds();
    Aabb3 {
        min: Point3::new(b.min.x - radius, b.min.y - radius, b.min.z - 1.0),
        max: Point3::new(b.max.x + radius, b.max.y + radius, b.max.z + 1.0),
    }
}

/// The job's checks on its output settings and the tolerances its planning
/// runs with: with arcs on, planning gets `1 - ARC_SHARE` of the path tolerance.
pub(crate) fn planning_tolerances(job: &FinishJob) -> Result<Tolerances, EngineError> {
    if job.setup.is_none() && job.output.dialect.syntax != scallop_post::Syntax::Iso {
        return Err(EngineError::Output {
            what: format!("3-axis output in the plain-language dialect `{}`", job.output.dialect.name),
            fix: "use an ISO dialect (linuxcnc, fanuc, grbl, siemens840d, heidenhain-iso)".into(),
        });
    }
    if job.output.arc_fitting && job.setup.is_some() {
        return Err(EngineError::Output {
            what: "arc fitting in 3+2 output".into(),
            fix: "set output.arc_fitting = false for a job with a [setup]".into(),
        });
    }
    Ok(crate::Budget::new(job.tolerances, job.output.arc_fitting)?.planning())
}

/// The simulation's allowance and options: the program follows the
/// tessellation (within the chordal error of the surface), and between samples
/// the planner keeps moves within the path tolerance of the CL surface; the
/// scallop is held beyond the cutter radius from the part's edge (see
/// `VerifyOptions::scallop_margin`), the edge strip's figure reported too.
pub(crate) fn verify_options(job: &FinishJob, prepared: &PreparedPart) -> (f64, scallop_sim::VerifyOptions) {
    let gouge_tolerance =
        crate::Budget { tolerances: job.tolerances, arc_fitting: false }.gouge_allowance(prepared.chordal_error);
    let options = scallop_sim::VerifyOptions {
        gouge_tolerance,
        scallop_margin: job.cutter.radius(),
        ..scallop_sim::VerifyOptions::default()
    };
    (gouge_tolerance, options)
}

/// What the planning of one finishing operation produced, before the
/// simulation and the program text.
pub(crate) struct PlannedOperation {
    pub(crate) plan: Plan,
    pub(crate) params: FinishingParams,
    pub(crate) direction_deg: f64,
    pub(crate) analysis: scallop_analysis::AnalysisReport,
    pub(crate) leads: LeadReport,
}

/// Plans one finishing operation on a prepared part: the analysis, the
/// direction, the passes and the leads. `clearance` overrides the job's
/// clearance above the part's top (a stock above it, see `run_job`).
pub(crate) fn plan_operation(
    job: &FinishJob,
    prepared: &PreparedPart,
    tolerances: &Tolerances,
    clearance: Option<f64>,
    refine: &Refinement,
) -> Result<PlannedOperation, EngineError> {
    let samples = match (&job.part, &job.setup) {
        (Part::Surfaces(set), None) => {
            sample_surface_set(set, &GridOptions::default()).map_err(EngineError::Analysis)?
        }
        (Part::Mesh(mesh), None) => sample_mesh(mesh),
        // 3+2: analyse the part as the cutter sees it, in the planning frame.
        (_, Some(_)) => sample_mesh(&prepared.mesh),
    };
    let (analysis, direction_deg) = analyse(job, &samples)?;
    let mut params = finishing_params(job, direction_deg.to_radians());
    if let Some(c) = clearance {
        params.clearance = c;
    }
    let mut planned = match job.strategy {
        Strategy::ParallelPlanes => {
            let p = plan_finishing_refined(&prepared.index, &job.cutter, &params, tolerances, refine)?;
            let layout = Layout {
                direction: params.direction,
                planes: p.planes.iter().map(|q| q.offset).collect(),
                ..Layout::default()
            };
            Plan { toolpath: p.toolpath, report: p.report, scallop: Some(p.scallop), layout }
        }
        Strategy::NetworkPlanes => {
            let set = parametric_only(job, "the network planner (finishing.strategy = \"network\")")?;
            network_planes(set, prepared, job, &params, tolerances)?
        }
        Strategy::Isoparametric(direction) => {
            let set = parametric_only(job, "isoparametric passes (finishing.strategy = \"isoparametric\")")?;
            isoparametric(set, prepared, job, &params, tolerances, direction)?
        }
        Strategy::SteepShallow { threshold_deg } => {
            let mut split = SteepShallow::default_for(&job.cutter, job.scallop_height);
            if let Some(t) = threshold_deg {
                split.threshold = t.to_radians();
            }
            let p =
                plan_steep_shallow(&prepared.mesh, &prepared.index, &job.cutter, &params, tolerances, &split, refine)?;
            let layout = Layout {
                direction: params.direction,
                planes: p.shallow.as_ref().map(|q| q.planes.iter().map(|q| q.offset).collect()).unwrap_or_default(),
                levels: p.level_heights,
                steep_min: split.threshold - split.overlap,
                shallow_max: split.threshold + split.overlap,
            };
            Plan { toolpath: p.toolpath, report: p.report, scallop: None, layout }
        }
    };
    let (led, leads) =
        apply_leads(&planned.toolpath, &prepared.index, &job.cutter, job.leads, tolerances.path, job.tolerances.gouge)?;
    if leads.applied > 0 {
        // The leads change the plunges and retracts: times and lengths again.
        let (a, b) = (stop_to_stop_time(&led, &params), lookahead_time(&led, &params));
        let r = &mut planned.report;
        r.machining_time_s = a.cutting;
        r.machining_time_lookahead_s = b.cutting;
        r.rapid_time_s = a.rapid;
        r.plunge_time_s = a.plunge;
        r.total_time_s = a.total();
        r.rapid_length_mm = led.length(MoveKind::Rapid) + led.length(MoveKind::Retract);
        r.plunge_length_mm = led.length(MoveKind::Plunge);
        r.points = led.moves().len();
        planned.toolpath = led;
    }
    Ok(PlannedOperation { plan: planned, params, direction_deg, analysis, leads })
}

/// The part's analysis for the job's cutter, and the feed direction `scallop run`
/// takes when the job gives none (degrees from +X): the principal direction for a
/// ball, the steepest slope of the PCA plane otherwise.
fn analysis_of(
    job: &FinishJob,
    samples: &scallop_analysis::Samples,
    machine: &MachineLimits,
) -> Result<(scallop_analysis::AnalysisReport, f64), EngineError> {
    let radius = job.cutter.radius();
    let (corner, is_ball) = match *job.cutter.shape() {
        CutterShape::Bull { corner, .. } => (corner, false),
        CutterShape::Ball { .. } => (radius / 2.0, true),
        _ => (radius / 2.0, false),
    };
    let tools = ToolOptions { ball_radius: radius, toroidal_radius: radius, corner_radius: corner };
    let analysis = analyze(samples, &tools, machine, job.scallop_height).map_err(EngineError::Analysis)?;
    let direction = if is_ball { analysis.principal_direction_deg } else { analysis.slope_direction_deg };
    Ok((analysis, direction))
}

/// The feed direction `scallop run` takes for a parametric part without a
/// `[setup]` when the job gives none (degrees from +X; see [`FinishJob::direction_deg`]).
///
/// # Errors
/// [`EngineError::Output`] for a mesh part or a job with a setup;
/// [`EngineError::Analysis`] when the surface cannot be sampled.
pub fn auto_direction_deg(job: &FinishJob) -> Result<f64, EngineError> {
    let (Part::Surfaces(set), None) = (&job.part, &job.setup) else {
        return Err(EngineError::Output {
            what: "the automatic direction of a mesh part or a 3+2 setup".into(),
            fix: "give a parametric part without [setup]".into(),
        });
    };
    let machine = MachineLimits::from_thesis_units(job.machine[0], job.machine[1], job.machine[2]);
    let samples = sample_surface_set(set, &GridOptions::default()).map_err(EngineError::Analysis)?;
    Ok(analysis_of(job, &samples, &machine)?.1)
}

/// The analysis of a part's samples with the job's cutter (finishing.md 4) and
/// the feed direction: the job's, else the one [`analysis_of`] takes.
pub(crate) fn analyse(
    job: &FinishJob,
    samples: &scallop_analysis::Samples,
) -> Result<(scallop_analysis::AnalysisReport, f64), EngineError> {
    let machine = MachineLimits::from_thesis_units(job.machine[0], job.machine[1], job.machine[2]);
    let (analysis, auto_deg) = analysis_of(job, samples, &machine)?;
    Ok((analysis, job.direction_deg.unwrap_or(auto_deg)))
}

/// The surfaces of a parametric part, for a strategy that needs them, or the
/// error that names the key selecting it.
fn parametric_only<'j>(job: &'j FinishJob, what: &str) -> Result<&'j scallop_surface::SurfaceSet, EngineError> {
    let Part::Surfaces(set) = &job.part else {
        return Err(EngineError::Output {
            what: format!("{what} on a mesh part"),
            fix: "use a parametric part (builtin or a surface file) or finishing.strategy = \"parallel\"".into(),
        });
    };
    if job.setup.is_some() {
        return Err(EngineError::Output {
            what: format!("{what} in a 3+2 setup"),
            fix: "remove [setup] or use finishing.strategy = \"parallel\"".into(),
        });
    }
    Ok(set)
}

/// The strategies the simulation verifies (the network planner measures no
/// scallop, steep-and-shallow's levels none): a scallop over sh beyond the
/// grid's bound fails the job, once the material no program of this cutter
/// can remove is told apart (`scallop_sim::split_rest`) and reported.
pub(crate) fn network_scallop_from(
    sim: &scallop_sim::Simulation,
    job: &FinishJob,
    prepared: &PreparedPart,
    options: &scallop_sim::VerifyOptions,
    report: &mut scallop_strategy::Report,
) -> Result<RestReport, EngineError> {
    accept_scallop(scallop_split(sim, job, prepared, options), sim, job, report)
}

/// The scallop on the machined surface of a simulated program, told apart
/// from the material the cutter cannot reach.
pub(crate) struct ScallopSplit {
    max: f64,
    at: Option<scallop_geom::Point2>,
    rest: RestReport,
    /// The machined cells over the limit ([`scallop_sim::RestSplit::machined_over`]).
    pub(crate) over: Vec<scallop_sim::OverCell>,
    limit: f64,
    bound: f64,
}

impl ScallopSplit {
    /// Whether the scallop on the machined surface holds the limit.
    pub(crate) fn holds(&self) -> bool {
        self.max <= self.limit
    }
}

/// Splits what the program left (see [`ScallopSplit`]); the split by reach
/// runs only when the simulation's largest thickness exceeds the limit.
pub(crate) fn scallop_split(
    sim: &scallop_sim::Simulation,
    job: &FinishJob,
    prepared: &PreparedPart,
    options: &scallop_sim::VerifyOptions,
) -> ScallopSplit {
    let bound = sim.zmap.resolution_bound(job.cutter.shape());
    let limit = job.scallop_height + bound;
    let v = &sim.verification;
    if v.max_thickness > limit {
        let field = scallop_sim::PartField::new(&sim.zmap, &prepared.index);
        let split = scallop_sim::split_rest(&sim.zmap, &field, &prepared.index, &job.cutter, options, limit);
        let rest = RestReport::from_split(&split);
        ScallopSplit { max: split.machined_max, at: split.machined_at, rest, over: split.machined_over, limit, bound }
    } else {
        let (max, at) = (v.max_thickness, v.max_thickness_at);
        ScallopSplit { max, at, rest: RestReport::default(), over: Vec::new(), limit, bound }
    }
}

/// The rest report of a split that holds the limit, with the report's scallop
/// figures filled; else [`EngineError::ScallopNotHeld`].
pub(crate) fn accept_scallop(
    split: ScallopSplit,
    sim: &scallop_sim::Simulation,
    job: &FinishJob,
    report: &mut scallop_strategy::Report,
) -> Result<RestReport, EngineError> {
    let ScallopSplit { max, at, rest, limit, bound, .. } = split;
    let v = &sim.verification;
    if max > limit {
        let at = at.unwrap_or_else(|| scallop_geom::Point2::new(f64::NAN, f64::NAN));
        return Err(EngineError::ScallopNotHeld { measured: max, x: at.x, y: at.y, limit: job.scallop_height, bound });
    }
    report.max_scallop_mm = max;
    // The mean: material left above the part per unit of its area (vertical).
    #[allow(clippy::cast_precision_loss, reason = "cell counts")]
    let cells = v.part_cells.max(1) as f64;
    report.mean_scallop_mm = v.excess_volume / (cells * job.sim_resolution * job.sim_resolution);
    Ok(rest)
}

/// Material the cutter cannot reach (a corner sharper than it, a slot
/// narrower than it), found by the simulation: reported, never counted as
/// scallop (`scallop_sim::split_rest`).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct RestReport {
    /// Area with rest material thicker than sh plus the resolution bound (mm^2).
    pub area_mm2: f64,
    /// Its largest thickness along the part normal (mm).
    pub depth_mm: f64,
    /// The scallop on the machined surface above the cutter's reach (mm); 0
    /// when the simulation's scallop needed no split (then that is the figure).
    pub machined_scallop_mm: f64,
    /// The places, largest first: `[x, y]` of the deepest cell, area (mm^2), depth (mm).
    pub places: Vec<RestPlaceReport>,
}

/// One place of [`RestReport`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RestPlaceReport {
    /// The deepest cell's centre, `[x, y]` (mm, planning frame).
    pub at: [f64; 2],
    /// Area (mm^2).
    pub area_mm2: f64,
    /// Largest thickness (mm).
    pub depth_mm: f64,
}

impl RestReport {
    pub(crate) fn from_split(split: &scallop_sim::RestSplit) -> RestReport {
        RestReport {
            area_mm2: split.unreachable_area,
            depth_mm: split.unreachable_depth,
            machined_scallop_mm: split.machined_max,
            places: split
                .places
                .iter()
                .map(|p| RestPlaceReport { at: [p.at.x, p.at.y], area_mm2: p.area, depth_mm: p.depth })
                .collect(),
        }
    }
}

/// The program's path (arcs fitted when asked) and its header comments.
pub(crate) fn fit_and_comment(
    job: &FinishJob,
    op: &PlannedOperation,
    prepared: &PreparedPart,
    tolerances: &Tolerances,
) -> (FittedPath, Vec<String>) {
    let r = &op.plan.report;
    let mut comments = vec![
        format!("part: {}, {}", job.part_name, chordal_text(prepared)),
        format!("tool: {}; scallop height {} mm", cutter_text(job.cutter.shape()), job.scallop_height),
        format!(
            "path tolerance {} mm; gouge tolerance {} mm; feed direction {:.2} deg",
            job.tolerances.path, job.tolerances.gouge, op.direction_deg
        ),
        format!(
            "predicted machining time {:.1} s (stop-to-stop), {:.1} s (look-ahead), rapids {:.1} s",
            r.machining_time_s, r.machining_time_lookahead_s, r.rapid_time_s
        ),
    ];
    let fitted = if job.output.arc_fitting {
        let f = fit_arcs(&op.plan.toolpath, ARC_SHARE * job.tolerances.path);
        comments.push(format!(
            "arcs: {} G2/G3 within {} mm of the planned path; planning within {} mm",
            f.arcs(),
            ARC_SHARE * job.tolerances.path,
            tolerances.path
        ));
        f
    } else {
        FittedPath::lines(&op.plan.toolpath)
    };
    (fitted, comments)
}

/// How the part's approximation reads in a program's header: the chordal bound
/// of a tessellated surface, or a mesh taken as it is.
fn chordal_text(prepared: &PreparedPart) -> String {
    if prepared.chordal_error > 0.0 {
        format!("tessellated within {:.5} mm", prepared.chordal_error)
    } else {
        "a mesh, machined as given".into()
    }
}

/// The report of one finishing operation proven by `sim`.
pub(crate) fn finish_report(
    job: &FinishJob,
    op: &PlannedOperation,
    prepared: &PreparedPart,
    sim: &scallop_sim::Simulation,
    gouge_tolerance: f64,
    rest: RestReport,
) -> FinishReport {
    FinishReport {
        part: job.part_name.clone(),
        cutter: cutter_text(job.cutter.shape()),
        scallop_height_mm: job.scallop_height,
        direction_deg: op.direction_deg,
        recommendation: op.analysis.recommendation,
        slope_deg: op.analysis.slope_deg,
        critical_slope_deg: op.analysis.critical_slope_deg,
        chordal_error_mm: prepared.chordal_error,
        plan: op.plan.report.clone(),
        sim_resolution_mm: job.sim_resolution,
        sim_max_material_mm: sim.verification.max_scallop,
        sim_max_scallop_mm: if rest.machined_scallop_mm > 0.0 {
            rest.machined_scallop_mm
        } else {
            sim.verification.max_thickness
        },
        sim_edge_max_scallop_mm: sim.verification.margin_max_thickness,
        sim_resolution_bound_mm: sim.zmap.resolution_bound(job.cutter.shape()),
        sim_min_deviation_mm: sim.verification.min_deviation,
        sim_gouge_tolerance_mm: gouge_tolerance,
        leads: op.leads.clone(),
        rest,
    }
}

/// A 3-axis program of `fitted` in the job's dialect with `comments` in its header.
/// The planner's settings of a finishing job along `direction` (rad from +X):
/// the job's pattern, scallop height, steps and tolerances, its machine
/// (plunges at a quarter of the feed), boundary contacts inside the part.
pub(crate) fn finishing_params(job: &FinishJob, direction: f64) -> FinishingParams {
    let machine = MachineLimits::from_thesis_units(job.machine[0], job.machine[1], job.machine[2]);
    FinishingParams {
        direction,
        pattern: job.pattern,
        scallop_height: job.scallop_height,
        boundary: Boundary::ContactInside,
        max_step: job.max_step,
        clearance: job.clearance,
        machine,
        plunge_feed: machine.feed / 4.0,
        rapid_rate: job.rapid_rate,
        sharp_corner: SHARP_CORNER_DEG.to_radians(),
        blend_tolerance: job.tolerances.path,
    }
}

pub(crate) fn three_axis_program(
    job: &FinishJob,
    fitted: &FittedPath,
    comments: &[String],
) -> Result<String, EngineError> {
    let refs: Vec<&str> = comments.iter().map(String::as_str).collect();
    let info = ProgramInfo {
        program: job.output.program.clone(),
        tool: job.output.tool,
        spindle: job.output.spindle,
        indexed_rotaries: Vec::new(),
    };
    let mut text = Vec::new();
    write_fitted(fitted, &job.output.dialect, &info, &refs, &mut text)
        .map_err(|e| EngineError::Output { what: format!("writing the program: {e}"), fix: String::new() })?;
    Ok(String::from_utf8_lossy(&text).into_owned())
}

/// Which finishing strategy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Strategy {
    /// Parallel vertical planes (`scallop_strategy::plan_finishing`).
    ParallelPlanes,
    /// Isoparametric passes on every patch of a parametric part.
    Isoparametric(IsoDirection),
    /// Parallel vertical planes placed by the fast network planner
    /// (`scallop_network`, finishing.md 6.3 to 6.5) on every patch of a
    /// parametric part, cutter locations by drop-cutter
    /// (`scallop_network::network_toolpath`); the scallop is verified by
    /// the stock simulation only.
    NetworkPlanes,
    /// Parallel planes on the shallow triangles of a mesh and waterline levels
    /// on the steep ones (`scallop_strategy::plan_steep_shallow`), split at
    /// `threshold_deg` (default from the cutter and sh); the scallop is
    /// verified by the stock simulation.
    SteepShallow {
        /// Slope (degrees from the horizontal) of the split.
        threshold_deg: Option<f64>,
    },
}

impl Strategy {
    /// Whether the stock simulation is the scallop's verification (the
    /// planner measures none, or not everywhere).
    #[must_use]
    pub fn simulation_verifies_scallop(&self) -> bool {
        matches!(self, Strategy::NetworkPlanes | Strategy::SteepShallow { .. })
    }
}

/// The machining-mesh step of the network planner (mm): the specification's
/// 0.5 mm machining mesh (finishing.md 6.3).
pub const NETWORK_STEP_MM: f64 = 0.5;

/// Parallel planes by the network planner, patch after patch (see
/// [`Strategy::NetworkPlanes`]); the scallop figures are filled in from the
/// simulation by the caller.
fn network_planes(
    set: &scallop_surface::SurfaceSet,
    prepared: &PreparedPart,
    job: &FinishJob,
    params: &FinishingParams,
    tolerances: &Tolerances,
) -> Result<Plan, EngineError> {
    use scallop_network::{Margins, Network, ZoneParams, network_toolpath, plan_zone};
    let tool = match *job.cutter.shape() {
        CutterShape::Ball { radius } => scallop_analysis::Cutter::Ball { radius },
        CutterShape::Bull { radius, corner } => scallop_analysis::Cutter::Toroidal { radius, corner },
        CutterShape::Flat { radius } => scallop_analysis::Cutter::Toroidal { radius, corner: 0.0 },
        CutterShape::Cone { .. } => return Err(scallop_strategy::StrategyError::Unsupported { shape: "cone" }.into()),
    };
    let zone = ZoneParams {
        direction: params.direction,
        tool,
        scallop_height: params.scallop_height,
        margins: Margins::HalfStep,
        sharp_corner: params.sharp_corner,
        machine: params.machine,
    };
    let mut toolpath = Toolpath::new(params.machine.feed * 60.0);
    toolpath.plunge_feed = params.plunge_feed * 60.0;
    let (mut passes, mut planes, mut links, mut drops) = (0, 0, 0, 0);
    for patch in set.patches() {
        let network = Network::new(patch, NETWORK_STEP_MM)?;
        let plan = plan_zone(&network, None, 0, &zone)?;
        planes += plan.planes.len();
        let made =
            network_toolpath(&network, std::slice::from_ref(&plan), &prepared.index, &job.cutter, params, tolerances)?;
        passes += made.passes;
        links += made.links;
        drops += made.drops;
        for m in made.toolpath.moves() {
            toolpath.push(*m);
        }
    }
    // The scallop figures are filled in from the simulation (the planner measures none).
    let report = scallop_strategy::Report {
        passes,
        planes,
        links,
        cl_points_dropped: drops,
        ..scallop_strategy::Report::timed(&toolpath, params)
    };
    Ok(Plan { toolpath, report, scallop: None, layout: Layout::default() })
}

/// A toolpath and its figures, whatever the strategy.
pub(crate) struct Plan {
    pub(crate) toolpath: Toolpath,
    pub(crate) report: scallop_strategy::Report,
    pub(crate) scallop: Option<scallop_strategy::ScallopReport>,
    /// Where the planes and levels are, for a refinement (empty for the
    /// strategies that are not refined).
    pub(crate) layout: Layout,
}

/// Isoparametric passes patch after patch; the report's times and lengths are those
/// of the joined toolpath, its scallop the largest measured over all patches.
fn isoparametric(
    set: &scallop_surface::SurfaceSet,
    prepared: &PreparedPart,
    job: &FinishJob,
    params: &FinishingParams,
    tolerances: &Tolerances,
    direction: IsoDirection,
) -> Result<Plan, EngineError> {
    let mut toolpath = Toolpath::new(params.machine.feed * 60.0);
    toolpath.plunge_feed = params.plunge_feed * 60.0;
    let (mut passes, mut max_h, mut mean_sum) = (0, 0.0f64, 0.0);
    for patch in set.patches() {
        let surface = IsoSurface { patch, index: &prepared.index, chordal_error: prepared.chordal_error };
        let p = plan_isoparametric(&surface, &job.cutter, params, direction, tolerances)?;
        passes += p.passes.len();
        max_h = max_h.max(p.max_scallop_mm);
        mean_sum += p.mean_scallop_mm;
        toolpath.plunge_feed = p.toolpath.plunge_feed;
        for m in p.toolpath.moves() {
            toolpath.push(*m);
        }
    }
    let feed = toolpath.length(MoveKind::Feed);
    #[allow(clippy::cast_precision_loss, reason = "patch counts")]
    let mean = mean_sum / set.patches().len().max(1) as f64;
    // Isoparametric passes are joined without links: the path is the feed moves.
    let report = scallop_strategy::Report {
        path_length_mm: feed,
        link_length_mm: 0.0,
        passes,
        planes: passes,
        max_scallop_mm: max_h,
        mean_scallop_mm: mean,
        ..scallop_strategy::Report::timed(&toolpath, params)
    };
    Ok(Plan { toolpath, report, scallop: None, layout: Layout::default() })
}

/// The prepared part turned into the planning frame of a 3+2 setup.
fn rotate_prepared(prepared: &PreparedPart, rotation: &Rotation3<f64>) -> Result<PreparedPart, EngineError> {
    let vertices: Vec<Point3> = prepared.mesh.vertices().iter().map(|v| rotation * v).collect();
    let triangles: Vec<[usize; 3]> = prepared.mesh.triangles().iter().map(|t| t.map(|i| i as usize)).collect();
    let (mesh, _) = TriMesh::from_indexed(&vertices, &triangles).map_err(|e| EngineError::Output {
        what: format!("the turned part: {e}"),
        fix: "check the setup rotation".into(),
    })?;
    let index = MeshIndex::build(&mesh);
    Ok(PreparedPart { mesh, index, ..prepared.clone() })
}

/// 3+2 output: the planning-frame toolpath back in the part frame with the tool axis
/// `rotation^-1 z`, through the machine's inverse kinematics, written in tilted work
/// planes (joint space with the rotaries held where the dialect has no plane code).
fn indexed_program(job: &FinishJob, setup: &Setup, path: &Toolpath, time: f64) -> Result<String, EngineError> {
    let frame = SetupFrame::about_origin(setup.rotation);
    let mut part_frame = Toolpath::new(path.feed);
    part_frame.plunge_feed = path.plunge_feed;
    for m in path.moves() {
        part_frame.push(Move::new(m.kind, frame.to_part(&m.to)));
    }
    let axis: Vec3 = frame.tool_axis();
    let kin = Kinematics::new(&setup.machine, setup.tool_length);
    let options = ProgramOptions::default();
    let records = records_from_toolpath(&part_frame, &axis);
    let program = to_program(&kin, &records, None, &options).map_err(|e| EngineError::Output {
        what: format!("the indexed tool axis on machine `{}`: {e}", setup.machine.name()),
        fix: "choose a setup rotation the machine can reach, or another machine".into(),
    })?;
    tilted_plane_text(job, &program, (&kin, setup.tool_length), &options, time)
}

/// A 3+2 machine program written in tilted work planes (joint space with the
/// rotaries held where the dialect has no plane code), for the kinematics `kin`
/// with its tool length, predicted to take `time` seconds.
pub(crate) fn tilted_plane_text(
    job: &FinishJob,
    program: &MachineProgram,
    (kin, tool_length): (&Kinematics, f64),
    options: &ProgramOptions,
    time: f64,
) -> Result<String, EngineError> {
    let params = PostParams {
        program: job.output.program.clone(),
        mode: OutputMode::TiltedPlane,
        tool: job.output.tool.max(1),
        tool_length,
        spindle: job.output.spindle,
        tol_pos: options.tol_pos,
        tol_ang: options.tol_ang,
        predicted_time: Some(time),
    };
    program_text(program, kin, &job.output.dialect, &params).map_err(|e| EngineError::Output {
        what: e.to_string(),
        fix: "use a 5-axis dialect (linuxcnc, fanuc, siemens840d, heidenhain)".into(),
    })
}

/// A cutter as reports name it.
pub(crate) fn cutter_text(shape: &CutterShape) -> String {
    match *shape {
        CutterShape::Bull { radius, corner } => format!("bull-nose R{radius} r{corner} mm"),
        CutterShape::Ball { radius } => format!("ball R{radius} mm"),
        CutterShape::Flat { radius } => format!("flat R{radius} mm"),
        CutterShape::Cone { radius, .. } => format!("cone R{radius} mm"),
    }
}

/// Rapid rate of the demo machine (mm/s).
const RAPID_RATE: f64 = 500.0;
/// Direction change above which the stop-to-stop model stops (degrees).
pub(crate) const SHARP_CORNER_DEG: f64 = 30.0;

#[cfg(test)]
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
mod tests {
    use super::*;

    #[test]
    fn choi_finishing_holds_the_scallop_and_proves_itself() {
        let out = run_finishing(&FinishJob::choi_demo()).unwrap();
        let r = &out.report;
        assert_eq!(r.recommendation, Recommendation::ToroidalAlongSlope);
        assert!(r.plan.max_scallop_mm <= 0.01, "{r:?}");
        assert!(r.plan.machining_time_s > 0.0 && r.plan.machining_time_lookahead_s > 0.0);
        assert!(r.sim_min_deviation_mm >= -r.sim_gouge_tolerance_mm);
        assert!(r.sim_max_scallop_mm <= r.scallop_height_mm + r.sim_resolution_bound_mm, "{r:?}");
        assert!(out.gcode.contains("predicted machining time"));
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        assert_eq!(one.install(|| run_finishing(&FinishJob::choi_demo()).unwrap()).gcode, out.gcode);
    }

    #[test]
    fn one_way_finishing_with_leads_enters_tangentially_and_proves_itself() {
        for leads in [LeadKind::Arc { radius: 2.0 }, LeadKind::Ramp { length: 3.0, angle: 15f64.to_radians() }] {
            let mut job = FinishJob::choi_demo();
            job.pattern = Pattern::OneWay;
            job.scallop_height = 0.03;
            job.leads = leads;
            // run_finishing fails if the stock simulation finds a gouge or a rapid into stock.
            let out = run_finishing(&job).unwrap();
            let r = &out.report;
            assert!(r.plan.retracts > 10);
            assert_eq!(r.leads.applied + r.leads.fallbacks.len(), 2 * (r.plan.retracts + 1), "{:?}", r.leads);
            assert!(r.leads.applied > r.plan.retracts, "{:?}", r.leads);
        }
    }

    #[test]
    fn isoparametric_finishing_of_choi_holds_the_scallop_and_proves_itself() {
        let mut job = FinishJob::choi_demo();
        job.cutter = Cutter::new(CutterShape::Ball { radius: 3.0 }, 40.0).unwrap();
        job.scallop_height = 0.05;
        job.strategy = Strategy::Isoparametric(IsoDirection::U);
        // run_finishing fails if the stock simulation finds a gouge or a rapid into stock.
        let out = run_finishing(&job).unwrap();
        let r = &out.report.plan;
        assert!(r.passes > 10 && r.max_scallop_mm <= 0.05, "{r:?}");
        // A mesh part has no isolines.
        let mut mesh_job = job.clone();
        let mesh = prepare_part(&job.part, &job.tolerances).unwrap().mesh;
        mesh_job.part = Part::Mesh(mesh);
        assert!(matches!(run_finishing(&mesh_job), Err(EngineError::Output { .. })));
    }

    /// The demo job with the network planner: no gouge (the simulation would
    /// fail the job), the simulated scallop within sh plus the grid's bound, and
    /// a pass count near the drop-cutter planner's.
    #[test]
    fn network_finishing_of_choi_holds_the_scallop_in_the_simulation() {
        let mut job = FinishJob::choi_demo();
        job.sim_resolution = 0.1;
        let reference = run_finishing(&job).unwrap();
        job.strategy = Strategy::NetworkPlanes;
        let out = run_finishing(&job).unwrap();
        let (r, sim) = (&out.report, &out.details.simulation);
        assert!(sim.verification.max_thickness <= r.scallop_height_mm + r.sim_resolution_bound_mm, "{r:?}");
        assert_eq!(r.plan.max_scallop_mm.to_bits(), sim.verification.max_thickness.to_bits());
        let (a, b) = (r.plan.passes as f64, reference.report.plan.passes as f64);
        assert!((a - b).abs() <= 0.2 * b, "network {a} passes, drop-cutter planner {b}");
        // A mesh part has no network; nor has a 3+2 setup.
        let mut mesh_job = job.clone();
        mesh_job.part = Part::Mesh(prepare_part(&job.part, &job.tolerances).unwrap().mesh);
        assert!(matches!(run_finishing(&mesh_job), Err(EngineError::Output { .. })));
    }
}
