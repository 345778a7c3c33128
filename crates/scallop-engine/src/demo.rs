//! The demo job: the built-in Choi surface finished by a ball cutter with a
//! zigzag drop-cutter raster at a fixed stepover, written as plain G-code.
//! A first end-to-end run of the engine; the finishing issue replaces the
//! fixed stepover by the scallop-driven one and the naive time by the
//! jerk-limited model.

use rayon::prelude::*;
use scallop_cutter::{ClPoint, Contact, Cutter, CutterShape, drop_grid, drop_points};
use scallop_geom::{Point2, Point3, Tolerances};
use scallop_post::{Dialect, write_gcode};
use scallop_toolpath::{Move, MoveKind, Toolpath, simplify_above};
use serde::Serialize;

use crate::{EngineError, Part, PreparedPart, prepare_part};

/// Share of the path tolerance given to merging nearly collinear CL points
/// (the tessellation takes `Tolerances::TESSELLATION_SHARE`; the rest is left
/// for the sampling along the passes).
pub const SIMPLIFY_SHARE: f64 = 0.5;

/// Share of the path tolerance given to sampling along a pass: a straight
/// move between two CL points may deviate this far from the CL surface at its
/// middle (checked by refinement).
pub const SAMPLING_SHARE: f64 = 0.25;

/// Settings of the demo job (all in mm, mm/min).
#[derive(Debug, Clone, PartialEq)]
pub struct DemoSettings {
    /// Built-in part name.
    pub part: String,
    /// Ball cutter diameter.
    pub cutter_diameter: f64,
    /// Distance between passes.
    pub stepover: f64,
    /// Distance between drop-cutter samples along a pass.
    pub sample_step: f64,
    /// Cutting feed (mm/min).
    pub feed: f64,
    /// Rapid rate used for the time estimate (mm/min).
    pub rapid_rate: f64,
    /// Clearance height above the part's top (mm).
    pub clearance: f64,
    /// Cell size of the verifying stock simulation (mm).
    pub sim_resolution: f64,
    /// Path and gouge tolerances.
    pub tolerances: Tolerances,
}

impl DemoSettings {
    /// The standard demo: Choi surface, ball D6, stepover 0.6, samples every 0.25.
    #[must_use]
    pub fn standard() -> DemoSettings {
        DemoSettings {
            part: "choi".into(),
            cutter_diameter: 6.0,
            stepover: 0.6,
            sample_step: 0.25,
            feed: 2000.0,
            rapid_rate: 10_000.0,
            clearance: 5.0,
            sim_resolution: 0.1,
            tolerances: Tolerances { path: 0.01, gouge: 0.0 },
        }
    }
}

/// One-screen summary of the demo (serialisable for `--json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DemoSummary {
    /// Part name.
    pub part: String,
    /// Triangles of the tessellation the cutter was dropped on.
    pub triangles: usize,
    /// Proven distance between the surface and its tessellation (mm).
    pub chordal_error_mm: f64,
    /// Cutter description.
    pub cutter: String,
    /// Stepover (mm).
    pub stepover_mm: f64,
    /// Theoretical scallop height of the stepover on a horizontal plane (mm).
    pub flat_scallop_mm: f64,
    /// Passes (runs of contact along a raster line).
    pub passes: usize,
    /// Drop-cutter queries made.
    pub cl_points_dropped: usize,
    /// Moves in the program.
    pub moves: usize,
    /// Cutting length (mm).
    pub feed_length_mm: f64,
    /// Zigzag links on the CL surface (mm).
    pub link_length_mm: f64,
    /// Plunge length (mm).
    pub plunge_length_mm: f64,
    /// Rapid and retract length (mm).
    pub rapid_length_mm: f64,
    /// Lengths divided by feeds: a lower bound of the real time (no acceleration).
    pub naive_time_s: f64,
    /// Lowest and highest tool-tip z (mm).
    pub tip_z_range_mm: [f64; 2],
    /// Tolerance of collinear-point merging (mm).
    pub simplify_tolerance_mm: f64,
    /// Cell size of the stock simulation that verified the program (mm).
    pub sim_resolution_mm: f64,
    /// Largest material left above the part, measured on the simulated stock (mm).
    pub verified_max_scallop_mm: f64,
    /// Where the most material is left (XY, mm).
    pub verified_max_scallop_at: Option<[f64; 2]>,
    /// Smallest stock-minus-part deviation (mm); a gouge would make the run fail.
    pub verified_min_deviation_mm: f64,
    /// Share of feed moves that removed nothing.
    pub air_cut_share: f64,
}

/// The demo's results.
#[derive(Debug, Clone)]
pub struct DemoOutput {
    /// The toolpath.
    pub toolpath: Toolpath,
    /// The G-code text.
    pub gcode: String,
    /// The summary.
    pub summary: DemoSummary,
}

/// Runs the demo. `progress(done, total)` reports raster lines dropped.
///
/// # Errors
/// Bad settings (cutter, tolerance) or an unknown built-in part.
pub fn run_demo(settings: &DemoSettings, progress: &(dyn Fn(usize, usize) + Sync)) -> Result<DemoOutput, EngineError> {
    let s = settings;
    for (what, v) in [("stepover", s.stepover), ("sample step", s.sample_step), ("feed", s.feed)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(crate::GridError::Values(format!("{what} = {v}")).into());
        }
    }
    let part = Part::builtin(&s.part)
        .ok_or_else(|| crate::GridError::Syntax(format!("unknown built-in part '{}' (choi, rubio)", s.part)))?;
    let prepared = prepare_part(&part, &s.tolerances)?;
    let radius = 0.5 * s.cutter_diameter;
    // Long flutes: the Choi surface is 24 mm deep and the verifying stock reaches
    // 1 mm above its top (the shank check of the simulation would refuse shorter ones).
    let cutter = Cutter::new(CutterShape::Ball { radius }, 5.0 * s.cutter_diameter)?;
    let bounds = prepared.mesh.bounds();
    let floor = bounds.min.z - s.cutter_diameter;
    let axis = |lo: f64, hi: f64, step: f64| -> Vec<f64> {
        // INVARIANT: step > 0 checked above; the count is small for a demo.
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let n = ((hi - lo) / step).ceil().max(1.0) as usize;
        #[allow(clippy::cast_precision_loss)]
        (0..=n).map(|i| lo + (hi - lo) * i as f64 / n as f64).collect()
    };
    // The raster overruns the part by the cutter radius so that the cutter
    // finishes the edges (on a slope, a ball centred over a downhill edge rests
    // uphill and leaves the edge uncut); points where it touches nothing split
    // the passes.
    let xs = axis(bounds.min.x - radius, bounds.max.x + radius, s.sample_step);
    let ys = axis(bounds.min.y - radius, bounds.max.y + radius, s.stepover);
    let total = ys.len();
    let grid = drop_grid(&cutter, &prepared.index, &xs, &ys, floor, &|done| progress(done, total));
    let mut dropped = grid.len();

    let runs = zigzag_runs(&grid, xs.len());

    // Refine every run where the straight move between two samples would leave
    // the CL surface: below it at all (a gouge) or above it by more than the
    // sampling share of the path tolerance.
    let sampling_tol = SAMPLING_SHARE * s.tolerances.path;
    let runs: Vec<Vec<Point3>> =
        runs.par_iter().map(|run| refine(&cutter, &prepared.index, run, floor, sampling_tol, &mut 0)).collect();
    dropped += runs.iter().map(Vec::len).sum::<usize>();

    let clearance = bounds.max.z + s.clearance;
    let surface = Surface { cutter: &cutter, index: &prepared.index, floor, sampling_tol };
    let (path, linked) = link_runs(&surface, &runs, s, clearance);
    dropped += linked;

    // Verify the program on a simulated stock: the part's box from 1 mm below to
    // 1 mm above. A gouge beyond the gouge tolerance plus the tessellation's
    // chordal error (the program follows the mesh, which lies that close to the
    // surface) plus the sampling share (what remains between refined samples is
    // of second order, bounded here by the share) is an error.
    let stock = scallop_geom::Aabb3 {
        min: Point3::new(bounds.min.x, bounds.min.y, bounds.min.z - 1.0),
        max: Point3::new(bounds.max.x, bounds.max.y, bounds.max.z + 1.0),
    };
    let options = scallop_sim::VerifyOptions {
        gouge_tolerance: s.tolerances.gouge + prepared.chordal_error + sampling_tol,
        ..scallop_sim::VerifyOptions::default()
    };
    let sim = scallop_sim::simulate(stock, s.sim_resolution, &cutter, &path, &prepared.index, &options)?;

    let cutter_text = format!("ball D{} mm", s.cutter_diameter);
    let gcode = demo_gcode(&path, s, &cutter_text, prepared.chordal_error)?;
    let summary = summarise(&path, s, cutter_text, &prepared, (runs.len(), dropped), &sim);
    Ok(DemoOutput { toolpath: path, gcode, summary })
}

/// Runs of contact along each raster line of `grid` (rows of `width`
/// points), in zigzag order: points where the cutter touches nothing split
/// the passes, and runs of one point are dropped.
fn zigzag_runs(grid: &[ClPoint], width: usize) -> Vec<Vec<Point3>> {
    let mut runs: Vec<Vec<Point3>> = Vec::new();
    for (row, line) in grid.chunks(width).enumerate() {
        let ordered: Vec<&ClPoint> = if row % 2 == 0 { line.iter().collect() } else { line.iter().rev().collect() };
        let mut run: Vec<Point3> = Vec::new();
        for cl in ordered {
            if matches!(cl.contact, Contact::Floor) {
                if run.len() > 1 {
                    runs.push(std::mem::take(&mut run));
                }
                run.clear();
            } else {
                run.push(cl.tip);
            }
        }
        if run.len() > 1 {
            runs.push(run);
        }
    }
    runs
}

/// What the cutter is dropped on: the part's index above `floor`, refined to
/// `sampling_tol`.
struct Surface<'a> {
    cutter: &'a Cutter,
    index: &'a scallop_mesh::MeshIndex,
    floor: f64,
    sampling_tol: f64,
}

/// The program through the refined `runs`: each linked to the next on the CL
/// surface where a link stays on it, else by a retract to `clearance`, a rapid
/// and a plunge. Returns the path and the drop-cutter queries of the links.
fn link_runs(surface: &Surface, runs: &[Vec<Point3>], s: &DemoSettings, clearance: f64) -> (Toolpath, usize) {
    let Surface { cutter, index, floor, sampling_tol } = *surface;
    let simplify_tol = SIMPLIFY_SHARE * s.tolerances.path;
    let mut dropped = 0;
    let mut path = Toolpath::new(s.feed);
    let mut last: Option<Point3> = None;
    for run in runs {
        let start = run[0];
        let link = last.and_then(|p| {
            let cl = link_on_surface(cutter, index, p, start, s.sample_step, floor)
                .map(|points| refine(cutter, index, &points, floor, sampling_tol, &mut 0));
            dropped += cl.as_ref().map_or(0, Vec::len);
            cl
        });
        match link {
            Some(points) => {
                for i in simplify_above(&points, simplify_tol).into_iter().skip(1) {
                    path.push(Move::new(MoveKind::Link, points[i]));
                }
            }
            None => {
                if let Some(p) = last {
                    path.push(Move::new(MoveKind::Retract, Point3::new(p.x, p.y, clearance)));
                }
                path.push(Move::new(MoveKind::Rapid, Point3::new(start.x, start.y, clearance)));
                path.push(Move::new(MoveKind::Plunge, start));
            }
        }
        for i in simplify_above(run, simplify_tol).into_iter().skip(1) {
            path.push(Move::new(MoveKind::Feed, run[i]));
        }
        last = run.last().copied();
    }
    if let Some(p) = last {
        path.push(Move::new(MoveKind::Retract, Point3::new(p.x, p.y, clearance)));
    }
    (path, dropped)
}

/// The demo's program as plain G-code, with a header naming the part, the
/// cutter and the tolerances.
fn demo_gcode(path: &Toolpath, s: &DemoSettings, cutter_text: &str, chordal_error: f64) -> Result<String, EngineError> {
    let mut gcode = Vec::new();
    let comments = [
        format!("part: built-in {} surface, tessellated within {:.5} mm", s.part, chordal_error),
        format!("cutter: {cutter_text}; stepover {} mm; feed {} mm/min", s.stepover, s.feed),
        format!("path tolerance {} mm; gouge tolerance {} mm", s.tolerances.path, s.tolerances.gouge),
    ];
    let comment_refs: Vec<&str> = comments.iter().map(String::as_str).collect();
    // INVARIANT: writing into a Vec cannot fail.
    write_gcode(path, &Dialect::plain(), &comment_refs, &mut gcode).map_err(|_| EngineError::BadTolerance(f64::NAN))?;
    Ok(String::from_utf8_lossy(&gcode).into_owned())
}

/// The summary of the demo's `path` on `prepared`, from its `(passes,
/// drop-cutter queries)` and its simulation.
fn summarise(
    path: &Toolpath,
    s: &DemoSettings,
    cutter: String,
    prepared: &PreparedPart,
    (passes, dropped): (usize, usize),
    sim: &scallop_sim::Simulation,
) -> DemoSummary {
    let radius = 0.5 * s.cutter_diameter;
    let (zmin, zmax) = path
        .moves()
        .iter()
        .filter(|m| m.kind == MoveKind::Feed)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, m| (a.0.min(m.to.z), a.1.max(m.to.z)));
    let feed_len = path.length(MoveKind::Feed);
    let link_len = path.length(MoveKind::Link);
    let plunge_len = path.length(MoveKind::Plunge);
    let rapid_len = path.length(MoveKind::Rapid) + path.length(MoveKind::Retract);
    let half = 0.5 * s.stepover;
    DemoSummary {
        part: s.part.clone(),
        triangles: prepared.mesh.triangles().len(),
        chordal_error_mm: prepared.chordal_error,
        cutter,
        stepover_mm: s.stepover,
        flat_scallop_mm: radius - (radius * radius - half * half).max(0.0).sqrt(),
        passes,
        cl_points_dropped: dropped,
        moves: path.moves().len(),
        feed_length_mm: feed_len,
        link_length_mm: link_len,
        plunge_length_mm: plunge_len,
        rapid_length_mm: rapid_len,
        naive_time_s: 60.0
            * ((feed_len + link_len) / s.feed + plunge_len / path.plunge_feed + rapid_len / s.rapid_rate),
        tip_z_range_mm: [zmin, zmax],
        simplify_tolerance_mm: SIMPLIFY_SHARE * s.tolerances.path,
        sim_resolution_mm: s.sim_resolution,
        verified_max_scallop_mm: sim.verification.max_scallop,
        verified_max_scallop_at: sim.verification.max_scallop_at.map(|p| [p.x, p.y]),
        verified_min_deviation_mm: sim.verification.min_deviation,
        air_cut_share: sim.cut.air_cut_share(),
    }
}

/// Inserts drop-cutter points between consecutive CL points `run` until the
/// straight move between neighbours lies within `tol` of the CL point at its
/// middle (above or below: a dip below is a gouge of at most `tol`, which the
/// verification budgets); segments shorter than `MIN_REFINE_STEP` are left as
/// they are.
fn refine(
    cutter: &Cutter,
    index: &scallop_mesh::MeshIndex,
    run: &[Point3],
    floor: f64,
    tol: f64,
    count: &mut usize,
) -> Vec<Point3> {
    let mut out = Vec::with_capacity(run.len());
    for w in run.windows(2) {
        out.push(w[0]);
        let mut stack = vec![(w[0], w[1])];
        let mut inserted: Vec<Point3> = Vec::new();
        while let Some((p, q)) = stack.pop() {
            if (q.xy() - p.xy()).norm() < MIN_REFINE_STEP {
                continue;
            }
            let mid = Point2::from((p.xy().coords + q.xy().coords) * 0.5);
            let cl = scallop_cutter::drop_cutter(cutter, index, mid, floor);
            if matches!(cl.contact, Contact::Floor) {
                continue;
            }
            let chord = 0.5 * (p.z + q.z);
            if (cl.tip.z - chord).abs() > tol {
                *count += 1;
                inserted.push(cl.tip);
                // Depth first, left half last pushed so it is refined first.
                stack.push((cl.tip, q));
                stack.push((p, cl.tip));
            }
        }
        // Points come out in no particular order: sort them along the segment.
        let (a, b) = (w[0].xy(), w[1].xy());
        let dir = b - a;
        inserted.sort_by(|m, n| (m.xy() - a).dot(&dir).total_cmp(&(n.xy() - a).dot(&dir)));
        out.extend(inserted);
    }
    if let Some(last) = run.last() {
        out.push(*last);
    }
    out
}

/// Shortest segment that [`refine`] still splits (mm).
const MIN_REFINE_STEP: f64 = 1e-3;

/// CL points of a straight XY link from `a` to `b`, dropped on the part, or
/// `None` when the cutter would leave the part on the way (then retract).
fn link_on_surface(
    cutter: &Cutter,
    index: &scallop_mesh::MeshIndex,
    a: Point3,
    b: Point3,
    step: f64,
    floor: f64,
) -> Option<Vec<Point3>> {
    let d = (b.xy() - a.xy()).norm();
    // INVARIANT: step > 0; links are short.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let n = (d / step).ceil().max(1.0) as usize;
    #[allow(clippy::cast_precision_loss)]
    let xy: Vec<Point2> =
        (0..=n).map(|i| Point2::from(a.xy().coords.lerp(&b.xy().coords, i as f64 / n as f64))).collect();
    let cl = drop_points(cutter, index, &xy, floor);
    cl.iter().all(|c| !matches!(c.contact, Contact::Floor)).then(|| cl.iter().map(|c| c.tip).collect())
}

#[cfg(test)]
#[allow(
    clippy::unwrap_used,
    clippy::float_cmp,
    reason = "tests: a panic is the failure report; exact values are intended"
)]
mod tests {
    use super::*;

    #[test]
    fn demo_runs_and_never_cuts_below_the_cl_surface() {
        let out = run_demo(&DemoSettings::standard(), &|_, _| {}).unwrap();
        let s = &out.summary;
        assert!(s.passes >= 100, "{s:?}");
        assert!(s.feed_length_mm > 4000.0, "{s:?}");
        assert!(out.gcode.contains("M30"));
        // Every feed and link vertex is a drop-cutter point of the part: re-drop it.
        let part = Part::builtin("choi").unwrap();
        let prepared = prepare_part(&part, &DemoSettings::standard().tolerances).unwrap();
        let cutter = Cutter::new(CutterShape::Ball { radius: 3.0 }, 30.0).unwrap();
        for m in out.toolpath.moves().iter().filter(|m| matches!(m.kind, MoveKind::Feed | MoveKind::Link)) {
            let cl = scallop_cutter::drop_cutter(&cutter, &prepared.index, m.to.xy(), -1e3);
            assert!((cl.tip.z - m.to.z).abs() < 1e-9, "{m:?} vs {cl:?}");
        }
        // Deterministic on one and two threads.
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let again = one.install(|| run_demo(&DemoSettings::standard(), &|_, _| {}).unwrap());
        assert_eq!(again.gcode, out.gcode);
    }

    #[test]
    fn bad_settings_are_errors() {
        let mut s = DemoSettings::standard();
        s.stepover = 0.0;
        assert!(run_demo(&s, &|_, _| {}).is_err());
        let mut s = DemoSettings::standard();
        s.part = "nope".into();
        assert!(run_demo(&s, &|_, _| {}).is_err());
    }
}
