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
use scallop_geom::{Aabb3, Point3, Tolerances};
use scallop_post::{Dialect, write_gcode};
use scallop_strategy::{Boundary, FinishingParams, Pattern, plan_finishing};
use scallop_toolpath::{MoveKind, Toolpath};
use serde::Serialize;

use crate::{EngineError, Part, prepare_part};

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
}

impl FinishJob {
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
}

/// Runs the finishing job. `planning_seconds` is measured by the caller and
/// written into the report (the library reads no clock).
///
/// # Errors
/// Bad settings, an unknown part, a plan that cannot hold the scallop height,
/// or a safety problem found by the stock simulation.
pub fn run_finishing(job: &FinishJob) -> Result<FinishOutput, EngineError> {
    let prepared = prepare_part(&job.part, &job.tolerances)?;
    let machine = MachineLimits::from_thesis_units(job.machine[0], job.machine[1], job.machine[2]);
    let samples = match &job.part {
        Part::Surfaces(set) => sample_surface_set(set, &GridOptions::default()).map_err(EngineError::Analysis)?,
        Part::Mesh(mesh) => sample_mesh(mesh),
    };
    let radius = job.cutter.radius();
    let (corner, is_ball) = match *job.cutter.shape() {
        CutterShape::Bull { corner, .. } => (corner, false),
        CutterShape::Ball { .. } => (radius / 2.0, true),
        _ => (radius / 2.0, false),
    };
    let tools = ToolOptions { ball_radius: radius, toroidal_radius: radius, corner_radius: corner };
    let analysis = analyze(&samples, &tools, &machine, job.scallop_height).map_err(EngineError::Analysis)?;
    let direction_deg = job.direction_deg.unwrap_or(if is_ball {
        analysis.principal_direction_deg
    } else {
        analysis.slope_direction_deg
    });
    let params = FinishingParams {
        direction: direction_deg.to_radians(),
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
    };
    let planned = plan_finishing(&prepared.index, &job.cutter, &params, &job.tolerances)?;

    // Prove the program on a simulated stock before anyone runs it: the part's
    // box grown by the cutter radius, from 1 mm below to 1 mm above the part.
    let b = prepared.mesh.bounds();
    let stock = Aabb3 {
        min: Point3::new(b.min.x - radius, b.min.y - radius, b.min.z - 1.0),
        max: Point3::new(b.max.x + radius, b.max.y + radius, b.max.z + 1.0),
    };
    // The program follows the tessellation (within the chordal error of the
    // surface); between samples the planner keeps moves within the path
    // tolerance of the CL surface.
    let gouge_tolerance = job.tolerances.gouge + prepared.chordal_error + job.tolerances.path;
    // The scallop is held where neighbouring passes shape the surface: beyond
    // the cutter radius from the part's edge (see `VerifyOptions::scallop_margin`);
    // the edge strip's figure is reported too.
    let options =
        scallop_sim::VerifyOptions { gouge_tolerance, scallop_margin: radius, ..scallop_sim::VerifyOptions::default() };
    let sim =
        scallop_sim::simulate(stock, job.sim_resolution, &job.cutter, &planned.toolpath, &prepared.index, &options)?;

    let cutter_text = match *job.cutter.shape() {
        CutterShape::Bull { radius, corner } => format!("bull-nose R{radius} r{corner} mm"),
        CutterShape::Ball { radius } => format!("ball R{radius} mm"),
        CutterShape::Flat { radius } => format!("flat R{radius} mm"),
        CutterShape::Cone { radius, .. } => format!("cone R{radius} mm"),
    };
    let r = &planned.report;
    let comments = [
        format!("part: {}, tessellated within {:.5} mm", job.part_name, prepared.chordal_error),
        format!("tool: {cutter_text}; scallop height {} mm", job.scallop_height),
        format!(
            "path tolerance {} mm; gouge tolerance {} mm; feed direction {:.2} deg",
            job.tolerances.path, job.tolerances.gouge, direction_deg
        ),
        format!(
            "predicted machining time {:.1} s (stop-to-stop), {:.1} s (look-ahead), rapids {:.1} s",
            r.machining_time_s, r.machining_time_lookahead_s, r.rapid_time_s
        ),
    ];
    let refs: Vec<&str> = comments.iter().map(String::as_str).collect();
    let mut text = Vec::new();
    write_gcode(&planned.toolpath, &Dialect::plain(), &refs, &mut text)
        .map_err(|_| EngineError::BadTolerance(f64::NAN))?;
    let report = FinishReport {
        part: job.part_name.clone(),
        cutter: cutter_text,
        scallop_height_mm: job.scallop_height,
        direction_deg,
        recommendation: analysis.recommendation,
        slope_deg: analysis.slope_deg,
        critical_slope_deg: analysis.critical_slope_deg,
        chordal_error_mm: prepared.chordal_error,
        plan: planned.report.clone(),
        sim_resolution_mm: job.sim_resolution,
        sim_max_material_mm: sim.verification.max_scallop,
        sim_max_scallop_mm: sim.verification.max_thickness,
        sim_edge_max_scallop_mm: sim.verification.margin_max_thickness,
        sim_resolution_bound_mm: sim.zmap.resolution_bound(job.cutter.shape()),
        sim_min_deviation_mm: sim.verification.min_deviation,
        sim_gouge_tolerance_mm: gouge_tolerance,
    };
    Ok(FinishOutput { toolpath: planned.toolpath, gcode: String::from_utf8_lossy(&text).into_owned(), report })
}

/// Rapid rate of the demo machine (mm/s).
const RAPID_RATE: f64 = 500.0;
/// Direction change above which the stop-to-stop model stops (degrees).
const SHARP_CORNER_DEG: f64 = 30.0;

/// The toolpath as CSV: `kind,x,y,z` per move.
#[must_use]
pub fn toolpath_csv(path: &Toolpath) -> String {
    let mut out = String::from("kind,x,y,z\n");
    for m in path.moves() {
        let kind = match m.kind {
            MoveKind::Rapid => "rapid",
            MoveKind::Plunge => "plunge",
            MoveKind::Feed => "feed",
            MoveKind::Link => "link",
            MoveKind::Retract => "retract",
        };
        out.push_str(&format!("{kind},{},{},{}\n", m.to.x, m.to.y, m.to.z));
    }
    out
}

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
}
