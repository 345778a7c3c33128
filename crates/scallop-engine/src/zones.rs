//! Zone finishing (issue 8): the drop-cutter planner run zone by zone over a
//! labelled parametric patch, the zones joined into one program, the program
//! proven on a simulated stock.
//!
//! # Method
//! - **Labelled machining mesh.** The patch is tessellated on a `(u, v)` grid
//!   (the grid of `Patch::tessellate` within the tessellation share of the path
//!   tolerance: same cell counts per knot span), so each triangle's parameter
//!   centroid is known; the triangle gets the label of the clustering cell
//!   containing that centroid (`CellLabels::label_at`).
//! - **Zones.** Each zone is planned by [`scallop_strategy::plan_zone_finishing`]
//!   in its own feed direction: a cutter location belongs to the zone when its
//!   contact lies in the zone dilated by a margin ([`ZoneRegion`]). The margin
//!   starts at the first of [`ZONE_MARGIN_PER_RADIUS`] times the cutter radius
//!   (the next ones when the proof below fails) and is raised
//!   to [`ZONE_MARGIN_PER_SPACING`] times the largest plane spacing of the zone's
//!   plan, replanning until it holds (at most [`ZONE_MARGIN_ROUNDS`] plans). The
//!   cutter locations that shape a point have their contacts within about one
//!   step-over of it, but near a pass end the envelope also lacks the locations
//!   beyond the end (up to the cutter radius along the feed), so the planner does
//!   not measure there; the margin moves those ends off the zone, the border
//!   strips are machined twice, and the stock simulation proves the result.
//! - **Joining.** Zones in the order given (the optimiser's: increasing
//!   label), each ending with a retract to the clearance height above the part's
//!   top and the next starting with a rapid and a plunge: the transition model
//!   of the optimiser (retract, traverse, approach), with the job's clearance
//!   height (safe over any stock) instead of `c` above the higher end.
//! - **3+2.** A tilted zone is planned in its own frame (the mesh turned so that
//!   its tool axis is vertical, same triangles, so the labels carry over), turned
//!   back to the part frame with its tool axis, and the zones are written as
//!   indexed setups through the machine's inverse kinematics (tilted planes, a
//!   new one on the rapid that starts each zone).
//! - **Proof.** 3-axis: the whole program is cut on a z-map of the stock box; a
//!   gouge, a rapid into stock or a collision is an error, and so is a simulated
//!   scallop above `sh` plus the simulation's resolution bound. 3+2: each zone's
//!   program alone in its frame, with the same errors, the scallop measured on
//!   the zone's own triangles (they tile the surface). The rotary repositioning
//!   between setups is not checked.

use scallop_analysis::MachineLimits;
use scallop_geom::{Point3, Tolerances, Vec3};
use scallop_machine::Kinematics;
use scallop_machine::program::{ProgramOptions, records_from_toolpath, to_program};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_network::{CellLabels, Orientation, Transitions};
use scallop_strategy::{FinishingParams, StrategyError, ZoneRegion, plan_zone_finishing};
use scallop_surface::{Direction, Patch};
use scallop_toolpath::{FittedPath, MoveKind, Toolpath, fit_arcs};
use serde::Serialize;

use crate::finish::{cutter_text, finishing_params};
use crate::{ARC_SHARE, EngineError, FinishJob, Part, PreparedPart, Strategy, run_finishing};

/// The margin of every zone starts at the first of these shares of the cutter
/// radius (3 mm for R = 5 mm; chosen from the border experiment of
/// docs/validation.md: on a two-zone Choi plan the borders exceed the limit below
/// 2 mm and keep 4 % of room at 3 mm); when the proof finds a scallop over the
/// limit, the whole plan is made again with the next share (more zones meet at
/// more borders), and the job fails after the last.
pub const ZONE_MARGIN_PER_RADIUS: [f64; 3] = [0.6, 1.0, 1.5];

/// The margin of a zone is raised to this many times its largest plane spacing.
pub const ZONE_MARGIN_PER_SPACING: f64 = 2.0;

/// Plans per zone at most while the margin grows.
pub const ZONE_MARGIN_ROUNDS: usize = 3;

/// A triangle is the part's top at a stock cell when its height there is within
/// this of the highest part height the simulation computes (mm; both are
/// interpolations of the same triangle when it is the top).
const FACE_MATCH_MM: f64 = 1e-6;

/// One zone to machine.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ZoneSpec {
    /// Its label in the cell labelling.
    pub label: u32,
    /// Feed direction (degrees from +X, in the zone's frame).
    pub direction_deg: f64,
    /// 3+2: angle between the tool axis and Z (degrees; 0: 3-axis).
    pub tilt_deg: f64,
    /// 3+2: azimuth of the tool axis from X (degrees).
    pub azimuth_deg: f64,
    /// The network model's predicted time of the zone (s), if known.
    pub predicted_time_s: Option<f64>,
}

/// A zone plan: the labels of the clustering cells, the zones in machining
/// order, and what the optimiser predicted.
#[derive(Debug, Clone, PartialEq)]
pub struct ZonePlanSpec {
    /// Zone label of each clustering cell over the patch's parameter square.
    pub labels: CellLabels,
    /// The zones, in machining order.
    pub zones: Vec<ZoneSpec>,
    /// The optimiser's inter-zone transition model (for the predicted transition time).
    pub transitions: Transitions,
    /// The network model's predicted total time (s), if known.
    pub predicted_time_s: Option<f64>,
    /// `None`: the adaptive margin (see the module docs); `Some(d)`: every zone
    /// dilated by exactly `d` mm (for experiments: with `d = 0` the borders are
    /// left to the pass ends, and the stock simulation shows what that leaves).
    pub fixed_margin_mm: Option<f64>,
    /// The machine whose kinematics write 3+2 zones as indexed setups (needed
    /// when a zone is tilted).
    pub machine: Option<scallop_machine::Machine>,
}

/// One program for [`finish_candidates`] to plan and prove.
#[derive(Debug, Clone, PartialEq)]
pub enum ProgramCandidate {
    /// A zone plan, planned by [`finish_zones`].
    Zones(ZonePlanSpec),
    /// The whole part in one feed direction, planned by [`run_finishing`]: the
    /// program of `scallop run` with `direction = direction_deg` (the single zone a
    /// zone plan has to beat).
    SingleZone {
        /// Feed direction (degrees from +X).
        direction_deg: f64,
        /// The network model's time of it (s), if known.
        predicted_time_s: Option<f64>,
    },
}

/// Plans and proves every candidate on the part of `job` (no `[setup]`), in
/// parallel (rayon; each result depends on its candidate only, so the results are
/// the same on any number of threads), results in the order of `candidates`. A
/// single-zone program whose simulated scallop exceeds `sh` plus the resolution
/// bound is an [`EngineError::ScallopExceeded`], as a zone program's is.
#[must_use]
pub fn finish_candidates(
    job: &FinishJob,
    candidates: &[ProgramCandidate],
) -> Vec<Result<ZoneFinishOutput, EngineError>> {
    use rayon::prelude::*;
    candidates
        .par_iter()
        .map(|c| match c {
            ProgramCandidate::Zones(spec) => finish_zones(job, spec),
            ProgramCandidate::SingleZone { direction_deg, predicted_time_s } => {
                single_zone(job, *direction_deg, *predicted_time_s)
            }
        })
        .collect()
}

/// The program of `scallop run` along `direction_deg`, proven and reported as a
/// one-zone program (label 0).
fn single_zone(job: &FinishJob, direction_deg: f64, predicted: Option<f64>) -> Result<ZoneFinishOutput, EngineError> {
    let job = FinishJob { direction_deg: Some(direction_deg), ..job.clone() };
    let out = run_finishing(&job)?;
    let r = out.report;
    let limit = job.scallop_height + r.sim_resolution_bound_mm;
    let v = &out.details.simulation.verification;
    if r.sim_max_scallop_mm > limit {
        let at = v.max_thickness_at.map_or([f64::NAN; 2], |p| [p.x, p.y]);
        return Err(EngineError::ScallopExceeded { height: r.sim_max_scallop_mm, limit, x: at[0], y: at[1] });
    }
    let triangles = out.details.prepared.mesh.triangles().len();
    let figure = ZoneFigures {
        label: 0,
        direction_deg: r.direction_deg,
        tilt_deg: 0.0,
        azimuth_deg: 0.0,
        sim_zone_scallop_mm: None,
        triangles,
        region_triangles: triangles,
        margin_mm: 0.0,
        max_spacing_mm: 0.0,
        passes: r.plan.passes,
        max_scallop_mm: r.plan.max_scallop_mm,
        machining_time_s: r.plan.machining_time_s,
        machining_time_lookahead_s: r.plan.machining_time_lookahead_s,
        predicted_time_s: predicted,
        skipped: None,
    };
    let total = r.plan.total_time_s;
    let report = ZoneFinishReport {
        part: r.part,
        cutter: r.cutter,
        scallop_height_mm: r.scallop_height_mm,
        chordal_error_mm: r.chordal_error_mm,
        margin_per_radius: 0.0,
        zones: vec![figure],
        plan: r.plan,
        transitions: 0,
        transition_time_s: 0.0,
        transition_time_model_s: 0.0,
        predicted_time_s: predicted,
        time_ratio: predicted.filter(|&p| p > 0.0).map(|p| total / p),
        sim_resolution_mm: r.sim_resolution_mm,
        indexed: false,
        sim_resolution_bound_mm: r.sim_resolution_bound_mm,
        sim_max_scallop_mm: r.sim_max_scallop_mm,
        sim_max_scallop_at: v.max_thickness_at.map(|p| [p.x, p.y]),
        sim_edge_max_scallop_mm: r.sim_edge_max_scallop_mm,
        sim_scallop_limit_mm: limit,
        sim_min_deviation_mm: r.sim_min_deviation_mm,
        sim_gouge_tolerance_mm: r.sim_gouge_tolerance_mm,
    };
    let zone_of_move = vec![0; out.toolpath.moves().len()];
    Ok(ZoneFinishOutput {
        toolpath: out.toolpath,
        zone_of_move,
        gcode: out.gcode,
        report,
        prepared: out.details.prepared,
        simulation: Some(out.details.simulation),
    })
}

/// What one zone came to.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ZoneFigures {
    /// Its label.
    pub label: u32,
    /// Feed direction (degrees from +X, in the zone's frame).
    pub direction_deg: f64,
    /// Tool-axis tilt (degrees; 0: 3-axis).
    pub tilt_deg: f64,
    /// Tool-axis azimuth (degrees).
    pub azimuth_deg: f64,
    /// 3+2: the largest material thickness along the normal that the zone's own
    /// program leaves on its own triangles, simulated in its frame (mm).
    pub sim_zone_scallop_mm: Option<f64>,
    /// Triangles of the machining mesh carrying the label.
    pub triangles: usize,
    /// Triangles of the zone dilated by the margin.
    pub region_triangles: usize,
    /// The dilation margin (mm, XY).
    pub margin_mm: f64,
    /// Largest plane spacing of the zone's plan (mm).
    pub max_spacing_mm: f64,
    /// Passes (0: no cutter location touches the zone, see `skipped`).
    pub passes: usize,
    /// Largest scallop the planner measured between the zone's passes (mm).
    pub max_scallop_mm: f64,
    /// Stop-to-stop time of the zone's cutting moves (passes and links) (s).
    pub machining_time_s: f64,
    /// Look-ahead time of the zone's cutting moves (s).
    pub machining_time_lookahead_s: f64,
    /// The network model's predicted time of the zone (s), if given.
    pub predicted_time_s: Option<f64>,
    /// Why the zone has no pass, if it has none.
    pub skipped: Option<String>,
}

/// The report of a zone program (part of `report.json` of `scallop optimize`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ZoneFinishReport {
    /// Part.
    pub part: String,
    /// Cutter.
    pub cutter: String,
    /// Scallop height asked (mm).
    pub scallop_height_mm: f64,
    /// Distance between the surface and the machining mesh (mm).
    pub chordal_error_mm: f64,
    /// The start margin of the zones as a share of the cutter radius (the first of
    /// [`ZONE_MARGIN_PER_RADIUS`] whose plan passed the proof).
    pub margin_per_radius: f64,
    /// Per zone, in machining order.
    pub zones: Vec<ZoneFigures>,
    /// The joined program's figures (times of the whole program; `max_scallop_mm`
    /// the largest over the zones' planner measurements).
    pub plan: scallop_strategy::Report,
    /// Zone-to-zone transitions in the program.
    pub transitions: usize,
    /// Stop-to-stop time of the program's transitions (retract, rapid, plunge) (s);
    /// 3+2: straight moves in the part frame, without the rotaries' repositioning.
    pub transition_time_s: f64,
    /// The same transitions under the optimiser's model (s).
    pub transition_time_model_s: f64,
    /// The network model's predicted total (s), if given.
    pub predicted_time_s: Option<f64>,
    /// `total / predicted_time_s`.
    pub time_ratio: Option<f64>,
    /// Cell size of the stock simulation (mm).
    pub sim_resolution_mm: f64,
    /// 3+2: zones tilted, written as indexed setups and proven one by one in
    /// their frames (gouges, collisions, and the scallop on the zone's own
    /// triangles); otherwise one 3-axis program proven as a whole.
    pub indexed: bool,
    /// The simulation's resolution bound for this cutter and cell size (mm).
    pub sim_resolution_bound_mm: f64,
    /// Largest material thickness along the part normal on the simulated stock,
    /// farther than the cutter radius from the part's edge (mm); 3+2: the largest
    /// over the zones of what each leaves on its own triangles.
    pub sim_max_scallop_mm: f64,
    /// Where (mm, XY).
    pub sim_max_scallop_at: Option<[f64; 2]>,
    /// The same within the cutter radius of the part's edge (mm; not held to `sh`;
    /// 0 in 3+2).
    pub sim_edge_max_scallop_mm: f64,
    /// `sh + sim_resolution_bound_mm`: the simulated scallop must not exceed it.
    pub sim_scallop_limit_mm: f64,
    /// Deepest stock-minus-part deviation (mm).
    pub sim_min_deviation_mm: f64,
    /// Gouge tolerance the simulation enforced (mm).
    pub sim_gouge_tolerance_mm: f64,
}

/// The outputs of [`finish_zones`].
#[derive(Debug, Clone)]
pub struct ZoneFinishOutput {
    /// The joined toolpath (part frame; 3+2 zones turned back from their frames).
    pub toolpath: Toolpath,
    /// Zone label of each move of `toolpath`.
    pub zone_of_move: Vec<u32>,
    /// The G-code text.
    pub gcode: String,
    /// The figures.
    pub report: ZoneFinishReport,
    /// The labelled machining mesh and its index.
    pub prepared: PreparedPart,
    /// The simulated stock of the whole 3-axis program (`None` in 3+2).
    pub simulation: Option<scallop_sim::Simulation>,
}

/// Plans, joins, times, proves and posts the zones of `spec` (3-axis: each
/// zone in its own feed direction) on the part of `job`: its cutter, scallop
/// height, pattern, machine, tolerances, sampling step, simulation resolution
/// and output; its direction is replaced by the zones' (zone programs have no
/// leads: `job.leads` is not applied).
///
/// # Errors
/// - [`EngineError::Output`]: the part is not one parametric patch, or the job
///   has a 3+2 setup or isoparametric strategy;
/// - [`EngineError::Zone`]: the planner refused a zone (e.g. its direction
///   cannot hold the scallop height there);
/// - [`EngineError::Verification`]: the simulation found a gouge, a rapid into
///   stock or a collision;
/// - [`EngineError::ScallopExceeded`]: the simulated scallop exceeds `sh` plus
///   the resolution bound.
pub fn finish_zones(job: &FinishJob, spec: &ZonePlanSpec) -> Result<ZoneFinishOutput, EngineError> {
    let mut result = Err(EngineError::BadTolerance(f64::NAN));
    for &share in &ZONE_MARGIN_PER_RADIUS {
        result = finish_zones_with(job, spec, share);
        match &result {
            Err(EngineError::ScallopExceeded { .. }) if spec.fixed_margin_mm.is_none() => {}
            _ => break,
        }
    }
    result
}

/// [`finish_zones`] with the start margin `share` times the cutter radius.
fn finish_zones_with(job: &FinishJob, spec: &ZonePlanSpec, share: f64) -> Result<ZoneFinishOutput, EngineError> {
    let patch = zone_patch(job)?;
    let tolerances = crate::Budget::new(job.tolerances, job.output.arc_fitting)?.planning();
    let (prepared, uv) = labelled_mesh(patch, &tolerances)?;
    let labels: Vec<u32> = uv.iter().map(|&[u, v]| spec.labels.label_at(u, v)).collect();
    let base = finishing_params(job, 0.0);
    let machine = base.machine;
    let start_margin = share * job.cutter.radius();
    let cap = 2.0 * job.cutter.radius();

    let tilted = spec.zones.iter().any(|z| z.tilt_deg != 0.0);
    let radius = job.cutter.radius();
    let gouge_tolerance = job.tolerances.gouge + prepared.chordal_error + job.tolerances.path;
    let options =
        scallop_sim::VerifyOptions { gouge_tolerance, scallop_margin: radius, ..scallop_sim::VerifyOptions::default() };
    let open_edge = open_edge_vertices(&prepared.mesh);

    let ctx = ZoneContext {
        job,
        spec,
        prepared: &prepared,
        labels: &labels,
        base,
        tolerances,
        start_margin,
        cap,
        options: &options,
        open_edge: &open_edge,
        tilted,
    };
    let JoinedZones { toolpath, zone_of_move, records, zone_sims, figures, ends } = join_zones(&ctx)?;

    // Times and lengths of the joined program.
    let transitions = ends.len().saturating_sub(1);
    let transition_time_model_s: f64 =
        ends.windows(2).map(|w| spec.transitions.time(&w[0].1, &w[1].0, &machine).0).sum();
    let transition_time_s = transition_time(&toolpath, &zone_of_move, &base);
    let plan = scallop_strategy::Report {
        passes: figures.iter().map(|f| f.passes).sum(),
        max_scallop_mm: figures.iter().map(|f| f.max_scallop_mm).fold(0.0, f64::max),
        ..scallop_strategy::Report::timed(&toolpath, &base)
    };
    let total = plan.total_time_s;

    // The proof: the whole 3-axis program on a stock box (as `run_finishing`); 3+2
    // zones were proven one by one above, each in its own frame.
    let (sim, bound, max_scallop, max_at, edge, min_deviation) =
        if tilted { proof_of_zones(&zone_sims) } else { prove_three_axis(job, &prepared, &toolpath, &options)? };
    let limit = job.scallop_height + bound;
    if max_scallop > limit {
        let at = max_at.unwrap_or([f64::NAN; 2]);
        return Err(EngineError::ScallopExceeded { height: max_scallop, limit, x: at[0], y: at[1] });
    }

    let cutter = cutter_text(job.cutter.shape());
    let comments = [
        format!("part: {}, tessellated within {:.5} mm", job.part_name, prepared.chordal_error),
        format!("tool: {cutter}; scallop height {} mm", job.scallop_height),
        format!("zones: {}, feed directions {}", figures.iter().filter(|f| f.passes > 0).count(), directions(&figures)),
        format!(
            "predicted machining time {:.1} s (stop-to-stop), {:.1} s (look-ahead), rapids {:.1} s",
            plan.machining_time_s, plan.machining_time_lookahead_s, plan.rapid_time_s
        ),
        format!("simulated scallop {max_scallop:.4} mm, limit {limit:.4} mm"),
    ];
    let text = if tilted {
        indexed_zones(job, spec, &records, plan.machining_time_s)?
    } else {
        let fitted = if job.output.arc_fitting {
            fit_arcs(&toolpath, ARC_SHARE * job.tolerances.path)
        } else {
            FittedPath::lines(&toolpath)
        };
        crate::finish::three_axis_program(job, &fitted, &comments)?
    };

    let report = ZoneFinishReport {
        part: job.part_name.clone(),
        cutter,
        scallop_height_mm: job.scallop_height,
        chordal_error_mm: prepared.chordal_error,
        margin_per_radius: share,
        zones: figures,
        plan,
        transitions,
        transition_time_s,
        transition_time_model_s,
        predicted_time_s: spec.predicted_time_s,
        time_ratio: spec.predicted_time_s.filter(|&p| p > 0.0).map(|p| total / p),
        sim_resolution_mm: job.sim_resolution,
        sim_resolution_bound_mm: bound,
        indexed: tilted,
        sim_max_scallop_mm: max_scallop,
        sim_max_scallop_at: max_at,
        sim_edge_max_scallop_mm: edge,
        sim_scallop_limit_mm: limit,
        sim_min_deviation_mm: min_deviation,
        sim_gouge_tolerance_mm: gouge_tolerance,
    };
    Ok(ZoneFinishOutput { toolpath, zone_of_move, gcode: text, report, prepared, simulation: sim })
}

/// The one parametric patch a zone finish runs on, or why the job cannot be
/// zone-finished (a mesh part, several patches, a [setup] or isoparametric
/// passes).
fn zone_patch(job: &FinishJob) -> Result<&Patch, EngineError> {
    let Part::Surfaces(set) = &job.part else {
        return Err(EngineError::Output {
            what: "zone finishing of a mesh part".into(),
            fix: "give one parametric patch (builtin or a surface file)".into(),
        });
    };
    let [patch] = set.patches() else {
        return Err(EngineError::Output {
            what: format!("zone finishing of {} patches", set.patches().len()),
            fix: "give one parametric patch".into(),
        });
    };
    if job.setup.is_some() || job.strategy != Strategy::ParallelPlanes {
        return Err(EngineError::Output {
            what: "zone finishing with a [setup] or isoparametric passes".into(),
            fix: "remove [setup] and use finishing.strategy = \"parallel\"".into(),
        });
    }
    Ok(patch)
}

/// The zones' paths joined in the order of the spec.
struct JoinedZones {
    toolpath: Toolpath,
    /// The zone label of every move of `toolpath`.
    zone_of_move: Vec<u32>,
    /// The joined program's records (with each zone's tool axis).
    records: Vec<scallop_machine::program::ClRecord>,
    /// (scallop, min deviation, bound) of every tilted zone's own proof.
    zone_sims: Vec<(f64, f64, f64)>,
    figures: Vec<ZoneFigures>,
    /// First plunge and last cutting point of every zone with passes.
    ends: Vec<(Point3, Point3)>,
}

/// Plans every zone of `ctx` and joins their paths, in the spec's order.
fn join_zones(ctx: &ZoneContext<'_>) -> Result<JoinedZones, EngineError> {
    let (spec, base) = (ctx.spec, &ctx.base);
    let mut toolpath = Toolpath::new(base.machine.feed * 60.0);
    toolpath.plunge_feed = base.plunge_feed * 60.0;
    let mut zone_of_move = Vec::new();
    let mut records = Vec::new();
    let mut zone_sims: Vec<(f64, f64, f64)> = Vec::new();
    let mut figures = Vec::with_capacity(spec.zones.len());
    let mut ends: Vec<(Point3, Point3)> = Vec::new();
    for zone in &spec.zones {
        let planned = plan_zone_of(ctx, zone)?;
        if let Some((zone_path, axis, sim)) = planned.path {
            zone_sims.extend(sim);
            records.extend(records_from_toolpath(&zone_path, &axis));
            let first = zone_path.moves().iter().find(|m| m.kind == MoveKind::Plunge).map(|m| m.to);
            let last = zone_path.moves().iter().rev().find(|m| m.kind != MoveKind::Retract).map(|m| m.to);
            if let (Some(a), Some(b)) = (first, last) {
                ends.push((a, b));
            }
            for m in zone_path.moves() {
                toolpath.push_with_axis(*m, axis);
                zone_of_move.push(zone.label);
            }
        }
        figures.push(planned.figure);
    }
    if toolpath.moves().is_empty() {
        return Err(StrategyError::EmptyRegion { direction_deg: 0.0 }.into());
    }
    Ok(JoinedZones { toolpath, zone_of_move, records, zone_sims, figures, ends })
}

/// What the proof of a zone finish found: the simulation (3-axis only), the
/// resolution bound, the largest scallop and where, the largest at the open
/// edges, the smallest deviation.
type ZoneProof = (Option<scallop_sim::Simulation>, f64, f64, Option<[f64; 2]>, f64, f64);

/// The proof of 3+2 zones from each zone's own proof: the largest bound and
/// scallop, the smallest deviation.
fn proof_of_zones(zone_sims: &[(f64, f64, f64)]) -> ZoneProof {
    let bound = zone_sims.iter().map(|z| z.2).fold(0.0, f64::max);
    let height = zone_sims.iter().map(|z| z.0).fold(0.0, f64::max);
    let deepest = zone_sims.iter().map(|z| z.1).fold(f64::INFINITY, f64::min);
    (None, bound, height, None, 0.0, deepest)
}

/// The proof of a 3-axis zone program: the whole program on a stock box (as
/// `run_finishing`).
fn prove_three_axis(
    job: &FinishJob,
    prepared: &PreparedPart,
    toolpath: &Toolpath,
    options: &scallop_sim::VerifyOptions,
) -> Result<ZoneProof, EngineError> {
    let stock = crate::stock_box(&prepared.mesh, job.cutter.radius());
    let sim = scallop_sim::simulate(stock, job.sim_resolution, &job.cutter, toolpath, &prepared.index, options)?;
    let bound = sim.zmap.resolution_bound(job.cutter.shape());
    let v = &sim.verification;
    let (height, at, edge, deepest) =
        (v.max_thickness, v.max_thickness_at.map(|p| [p.x, p.y]), v.margin_max_thickness, v.min_deviation);
    Ok((Some(sim), bound, height, at, edge, deepest))
}

/// What every zone of one [`finish_zones_with`] run shares.
struct ZoneContext<'a> {
    job: &'a FinishJob,
    spec: &'a ZonePlanSpec,
    prepared: &'a PreparedPart,
    labels: &'a [u32],
    base: FinishingParams,
    tolerances: Tolerances,
    start_margin: f64,
    cap: f64,
    options: &'a scallop_sim::VerifyOptions,
    open_edge: &'a [bool],
    tilted: bool,
}

/// One zone planned: its figures and, unless skipped, its toolpath (part
/// frame), its tool axis and, for a 3+2 zone, its own proof (scallop, deepest
/// deviation, resolution bound).
struct PlannedZone {
    figure: ZoneFigures,
    path: Option<(Toolpath, Vec3, Option<(f64, f64, f64)>)>,
}

/// Plans one zone: its region grown until the margin covers its spacing, its
/// passes by drop-cutter, and for a 3+2 zone its proof in its own frame.
fn plan_zone_of(ctx: &ZoneContext<'_>, zone: &ZoneSpec) -> Result<PlannedZone, EngineError> {
    let ZoneContext { job, spec, prepared, labels, base, tolerances, start_margin, cap, options, open_edge, tilted } =
        *ctx;
    let radius = job.cutter.radius();
    let mut zone_sim = None;
    let params = FinishingParams { direction: zone.direction_deg.to_radians(), ..base };
    let orientation = (zone.tilt_deg != 0.0)
        .then(|| Orientation::new(zone.tilt_deg.to_radians(), zone.azimuth_deg.to_radians(), Point3::origin()));
    let turned = match &orientation {
        Some(o) => Some(turn(&prepared, o)?),
        None => None,
    };
    let part = turned.as_ref().unwrap_or(prepared);
    let mut figure = ZoneFigures {
        label: zone.label,
        direction_deg: zone.direction_deg,
        tilt_deg: zone.tilt_deg,
        azimuth_deg: zone.azimuth_deg,
        sim_zone_scallop_mm: None,
        triangles: labels.iter().filter(|&&l| l == zone.label).count(),
        region_triangles: 0,
        margin_mm: 0.0,
        max_spacing_mm: 0.0,
        passes: 0,
        max_scallop_mm: 0.0,
        machining_time_s: 0.0,
        machining_time_lookahead_s: 0.0,
        predicted_time_s: zone.predicted_time_s,
        skipped: None,
    };
    if figure.triangles == 0 {
        figure.skipped = Some("no triangle of the machining mesh carries this label".into());
        return Ok(PlannedZone { figure, path: None });
    }
    let mut margin = spec.fixed_margin_mm.unwrap_or(start_margin);
    let mut planned = None;
    for _ in 0..ZONE_MARGIN_ROUNDS {
        let region = ZoneRegion::new(&part.mesh, &labels, zone.label, margin)?;
        figure.region_triangles = region.accepted_triangles();
        let p = match plan_zone_finishing(&part.index, &job.cutter, &params, &tolerances, &region) {
            Ok(p) => p,
            Err(StrategyError::EmptyRegion { .. }) => break,
            Err(source) => {
                return Err(EngineError::Zone { zone: zone.label, direction_deg: zone.direction_deg, source });
            }
        };
        let spacing = largest_spacing(&p.planes, cap);
        figure.margin_mm = margin;
        figure.max_spacing_mm = spacing;
        let done = spec.fixed_margin_mm.is_some() || ZONE_MARGIN_PER_SPACING * spacing <= margin;
        planned = Some(p);
        if done {
            break;
        }
        margin = ZONE_MARGIN_PER_SPACING * spacing;
    }
    let Some(p) = planned else {
        figure.skipped = Some("no cutter location has its contact in the zone".into());
        return Ok(PlannedZone { figure, path: None });
    };
    figure.passes = p.report.passes;
    figure.max_scallop_mm = p.scallop.max_mm;
    figure.machining_time_s = p.report.machining_time_s;
    figure.machining_time_lookahead_s = p.report.machining_time_lookahead_s;
    let mut zone_path = p.toolpath;
    if tilted {
        // Prove the zone in its own frame: no gouge or collision anywhere, and its
        // own triangles finished within the scallop height.
        let stock = crate::stock_box(&part.mesh, radius);
        let sim = scallop_sim::simulate(stock, job.sim_resolution, &job.cutter, &zone_path, &part.index, &options)?;
        let bound = sim.zmap.resolution_bound(job.cutter.shape());
        let (height, at) = zone_scallop(&sim.zmap, part, &labels, zone.label, &open_edge, radius);
        if height > job.scallop_height + bound {
            let at = orientation.map_or(Point3::new(at[0], at[1], 0.0), |o| o.to_part(&Point3::new(at[0], at[1], 0.0)));
            return Err(EngineError::ScallopExceeded { height, limit: job.scallop_height + bound, x: at.x, y: at.y });
        }
        figure.sim_zone_scallop_mm = Some(height);
        zone_sim = Some((height, sim.verification.min_deviation, bound));
        if let Some(o) = &orientation {
            let mut back = Toolpath::new(zone_path.feed);
            back.plunge_feed = zone_path.plunge_feed;
            for m in zone_path.moves() {
                back.push(scallop_toolpath::Move::new(m.kind, o.to_part(&m.to)));
            }
            zone_path = back;
        }
    }
    let axis = orientation.as_ref().map_or_else(Vec3::z, Orientation::tool_axis);
    Ok(PlannedZone { figure, path: Some((zone_path, axis, zone_sim)) })
}

fn directions(figures: &[ZoneFigures]) -> String {
    let list: Vec<String> =
        figures.iter().filter(|f| f.passes > 0).map(|f| format!("{:.1}", f.direction_deg)).collect();
    format!("{} deg", list.join(", "))
}

/// The largest gap between consecutive planes not wider than `cap` (wider gaps
/// separate ranges of planes, not passes).
fn largest_spacing(planes: &[scallop_strategy::Plane], cap: f64) -> f64 {
    planes
        .windows(2)
        .filter(|w| !w[0].passes.is_empty() && !w[1].passes.is_empty())
        .map(|w| (w[1].offset - w[0].offset).abs())
        .filter(|&g| g <= cap)
        .fold(0.0, f64::max)
}

/// Stop-to-stop time of the moves between zones (s): at each change of zone,
/// the previous zone's final retract and the next zone's rapid and plunge,
/// each a straight move from rest to rest (rapids and retracts at the rapid
/// rate, plunges at the plunge feed), as `stop_to_stop_time` times them.
fn transition_time(path: &Toolpath, zone_of_move: &[u32], params: &FinishingParams) -> f64 {
    let moves = path.moves();
    let rapid = MachineLimits { feed: params.rapid_rate, ..params.machine };
    let plunge = MachineLimits { feed: params.plunge_feed, ..params.machine };
    let time = |k: usize| -> f64 {
        let Some(m) = moves.get(k) else { return 0.0 };
        let Some(previous) = k.checked_sub(1).and_then(|j| moves.get(j)) else { return 0.0 };
        let length = (m.to - previous.to).norm();
        match m.kind {
            MoveKind::Rapid | MoveKind::Retract => rapid.segment_time(length),
            MoveKind::Plunge => plunge.segment_time(length),
            MoveKind::Feed | MoveKind::Link => 0.0,
        }
    };
    let mut total = 0.0;
    for i in 1..moves.len().min(zone_of_move.len()) {
        if zone_of_move[i] != zone_of_move[i - 1] {
            total += time(i - 1) + time(i) + time(i + 1);
        }
    }
    total
}

/// The machining mesh turned into the frame of a 3+2 orientation (about the
/// origin): same vertices and triangles in the same order, so labels carry over.
fn turn(prepared: &PreparedPart, o: &Orientation) -> Result<PreparedPart, EngineError> {
    let vertices: Vec<Point3> = prepared.mesh.vertices().iter().map(|v| o.to_machine(v)).collect();
    let triangles: Vec<[usize; 3]> = prepared.mesh.triangles().iter().map(|t| t.map(|i| i as usize)).collect();
    let (mesh, _) = TriMesh::from_indexed(&vertices, &triangles).map_err(|e| EngineError::Output {
        what: format!("the machining mesh turned to tilt {:.2} deg: {e}", o.tilt.to_degrees()),
        fix: "check the zone orientations".into(),
    })?;
    if mesh.triangles().len() != triangles.len() {
        return Err(EngineError::Output {
            what: "the turned machining mesh lost triangles (welding)".into(),
            fix: "use a finer path tolerance".into(),
        });
    }
    let index = MeshIndex::build(&mesh);
    Ok(PreparedPart { mesh, index, ..prepared.clone() })
}

/// Vertices on the open boundary of the mesh (edges used by one triangle).
fn open_edge_vertices(mesh: &TriMesh) -> Vec<bool> {
    let mut count: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
    for t in mesh.triangles() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry(if a < b { (a, b) } else { (b, a) }).or_insert(0) += 1;
        }
    }
    let mut open = vec![false; mesh.vertices().len()];
    for ((a, b), n) in count {
        if n == 1 {
            open[a as usize] = true;
            open[b as usize] = true;
        }
    }
    open
}

/// The largest material thickness along the normal, `(stock - part) n_z`, that
/// the simulated stock leaves over the zone's own triangles (cells whose centre
/// lies in such a triangle, where that triangle is the part's top there), leaving
/// out triangles within `edge` (XY) of the part's open boundary, as the whole
/// program's verification does; with the place (XY, zone frame).
fn zone_scallop(
    zmap: &scallop_sim::ZMap,
    part: &PreparedPart,
    labels: &[u32],
    zone: u32,
    open_edge: &[bool],
    edge: f64,
) -> (f64, [f64; 2]) {
    let top = scallop_sim::part_heights(zmap, &part.index);
    let vertices = part.mesh.vertices();
    let edge_points: Vec<Point3> = vertices.iter().zip(open_edge).filter(|(_, o)| **o).map(|(v, _)| *v).collect();
    let near_edge = |p: &Point3| edge_points.iter().any(|q| (q.x - p.x).hypot(q.y - p.y) < edge);
    let (cell_x, cell_y) = zmap.cell_size();
    let min = zmap.stock().min;
    let (nx, ny) = (zmap.nx(), zmap.ny());
    let mut worst = (0.0, [f64::NAN; 2]);
    for (t, tri) in part.mesh.triangles().iter().enumerate() {
        if labels[t] != zone {
            continue;
        }
        let c = tri.map(|v| vertices[v as usize]);
        let n = (c[1] - c[0]).cross(&(c[2] - c[0]));
        let area = n.z; // twice the signed XY area
        if area.abs() <= f64::MIN_POSITIVE || c.iter().any(&near_edge) {
            continue;
        }
        let nz = (n.z / n.norm()).abs();
        let (x0, x1) = (c[0].x.min(c[1].x).min(c[2].x), c[0].x.max(c[1].x).max(c[2].x));
        let (y0, y1) = (c[0].y.min(c[1].y).min(c[2].y), c[0].y.max(c[1].y).max(c[2].y));
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "clamped cell indices")]
        let range = |lo: f64, hi: f64, origin: f64, size: f64, n: usize| {
            let a = ((lo - origin) / size - 0.5).ceil().max(0.0) as usize;
            let b = (((hi - origin) / size - 0.5).floor().max(-1.0) + 1.0) as usize;
            a..b.min(n)
        };
        for j in range(y0, y1, min.y, cell_y, ny) {
            for i in range(x0, x1, min.x, cell_x, nx) {
                let p = zmap.cell_center(i, j);
                // Barycentric weights (XY).
                let w = |a: &Point3, b: &Point3| ((b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)) / area;
                let (w0, w1, w2) = (w(&c[1], &c[2]), w(&c[2], &c[0]), w(&c[0], &c[1]));
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let z = w0 * c[0].z + w1 * c[1].z + w2 * c[2].z;
                let cell = j * nx + i;
                if (top[cell] - z).abs() > FACE_MATCH_MM {
                    continue; // another part of the surface is above: not this zone's face here
                }
                let Some(stock) = zmap.height(i, j) else { continue };
                let thickness = (stock - z) * nz;
                if thickness > worst.0 {
                    worst = (thickness, [p.x, p.y]);
                }
            }
        }
    }
    worst
}

/// 3+2 output: the zones' records (part frame, each with its tool axis) through the
/// machine's inverse kinematics, written as tilted work planes (a new plane on the
/// rapid that starts each zone), or joint space with the rotaries held where the
/// dialect has no plane code.
fn indexed_zones(
    job: &FinishJob,
    spec: &ZonePlanSpec,
    records: &[scallop_machine::program::ClRecord],
    time: f64,
) -> Result<String, EngineError> {
    let Some(machine) = &spec.machine else {
        return Err(EngineError::Output {
            what: "3+2 zones without a machine".into(),
            fix: "give [setup] machine = a 5-axis machine (e.g. linuxcnc-xyzac-trt)".into(),
        });
    };
    let kin = Kinematics::new(machine, 0.0);
    let options = ProgramOptions::default();
    let program = to_program(&kin, records, None, &options).map_err(|e| EngineError::Output {
        what: format!("the zones' tool axes on machine `{}`: {e}", machine.name()),
        fix: "choose a machine whose rotaries reach every zone's orientation".into(),
    })?;
    crate::finish::tilted_plane_text(job, &program, (&kin, 0.0), &options, time)
}

/// The part's patch tessellated on the grid `Patch::tessellate` picks within
/// `tol.tessellation()`, with the parameter centroid of each kept triangle as
/// fractions of the domain.
fn labelled_mesh(patch: &Patch, tol: &Tolerances) -> Result<(PreparedPart, Vec<[f64; 2]>), EngineError> {
    let tolerance = tol.tessellation();
    let planned = patch.tessellate(tolerance)?;
    let [nu, nv] = planned.cells.first().copied().unwrap_or([1, 1]);
    let domain = patch.domain();
    let widths = [domain.u[1] - domain.u[0], domain.v[1] - domain.v[0]];
    let grid = |direction: Direction, n: usize, width: f64| -> Vec<f64> {
        let breaks = patch.span_breaks(direction);
        let mut out = Vec::new();
        for w in breaks.windows(2) {
            #[allow(clippy::cast_precision_loss, clippy::cast_possible_truncation, clippy::cast_sign_loss)]
            let cells = (((w[1] - w[0]) / width * n as f64).ceil() as usize).max(1);
            for k in 0..cells {
                #[allow(clippy::cast_precision_loss)]
                out.push(w[0] + (w[1] - w[0]) * (k as f64 / cells as f64));
            }
        }
        out.push(*breaks.last().unwrap_or(&width));
        out
    };
    let us = grid(Direction::U, nu, widths[0]);
    let vs = grid(Direction::V, nv, widths[1]);
    let mut vertices = Vec::with_capacity(us.len() * vs.len());
    for &u in &us {
        for &v in &vs {
            vertices.push(patch.point(u, v));
        }
    }
    let stride = vs.len();
    let mut triangles = Vec::with_capacity(2 * (us.len() - 1) * (stride - 1));
    let mut centroids = Vec::with_capacity(triangles.capacity());
    let frac = |u: f64, v: f64| [(u - domain.u[0]) / widths[0], (v - domain.v[0]) / widths[1]];
    for i in 0..us.len() - 1 {
        for j in 0..stride - 1 {
            let a = i * stride + j;
            let (b, c, d) = (a + stride, a + stride + 1, a + 1);
            triangles.push([a, b, c]);
            centroids.push(frac((2.0 * us[i + 1] + us[i]) / 3.0, (vs[j] + vs[j + 1] + vs[j]) / 3.0));
            triangles.push([a, c, d]);
            centroids.push(frac((us[i] + us[i + 1] + us[i]) / 3.0, (vs[j] + 2.0 * vs[j + 1]) / 3.0));
        }
    }
    let (mesh, diagnostics) = TriMesh::from_indexed(&vertices, &triangles).map_err(|e| EngineError::Output {
        what: format!("the labelled machining mesh: {e}"),
        fix: "check the surface (it collapses to a curve or a point)".into(),
    })?;
    // Kept triangles are in input order: match each to its input triangle.
    let uv = if diagnostics.degenerate_dropped == 0 {
        centroids
    } else {
        let close = 2.0 * diagnostics.weld_distance;
        let mut kept = Vec::with_capacity(mesh.triangles().len());
        let mut j = 0;
        for t in 0..mesh.triangles().len() {
            let corners = mesh.triangle(t);
            while j < triangles.len() && !(0..3).all(|k| (corners[k] - vertices[triangles[j][k]]).norm() <= close) {
                j += 1;
            }
            kept.push(centroids.get(j).copied().unwrap_or([0.5, 0.5]));
            j += 1;
        }
        kept
    };
    let largest = |values: &[f64]| values.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
    let bounds = patch.second_derivative_bounds();
    let chordal_error = bounds.chordal_bound(largest(&us), largest(&vs));
    let index = MeshIndex::build(&mesh);
    Ok((PreparedPart { mesh, index, chordal_error, chordal_error_guaranteed: bounds.guaranteed }, uv))
}

#[cfg(test)]
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
mod tests {
    use super::*;

    /// The labelled mesh's centroids lie in their triangles (mapped back through the patch).
    #[test]
    fn labelled_mesh_centroids_map_into_their_triangles() {
        let set = scallop_surface::builtin("choi").unwrap();
        let patch = &set.patches()[0];
        let (prepared, uv) = labelled_mesh(patch, &Tolerances { path: 0.04, gouge: 0.0 }).unwrap();
        assert_eq!(uv.len(), prepared.mesh.triangles().len());
        assert!(prepared.chordal_error <= 0.01 * (1.0 + 1e-9));
        let d = patch.domain();
        for (t, &[s, r]) in uv.iter().enumerate().step_by(97) {
            let (u, v) = d.lerp(s, r);
            let p = patch.point(u, v);
            let c = prepared.mesh.triangle(t);
            let centroid = (c[0].coords + c[1].coords + c[2].coords) / 3.0;
            assert!((p.coords - centroid).norm() <= 0.01 + 1e-9, "{t}");
        }
    }
}
