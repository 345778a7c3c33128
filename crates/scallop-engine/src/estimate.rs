//! Look before computing (`scallop run --plan-only`, docs/job.md): what a
//! finishing operation will do, from the analysis (the feed direction) and the
//! planner's own spacing rule (`scallop_strategy::rule_spacing`) over the part's
//! extent across the feed, without a drop-cutter query or a simulation.
//!
//! The parallel-planes planner places each plane one spacing from the last,
//! the spacing being the smallest the rule gives on that plane. Here the extent
//! across the feed is cut into bands; each band takes the smallest rule spacing
//! of the part's faces (mesh triangles) or samples (surface grid points) that
//! reach it, and the planes are the sum of band width over band spacing, plus
//! the two strips of one cutter radius beyond the part where the cutter still
//! touches its rim, at the rule's spacing on a floor.
//!
//! Steep and shallow (`scallop_strategy::plan_steep_shallow`): the bands count
//! only the shallow triangles, and each plane makes as many passes as the
//! runs of shallow triangles along the band's centre line; the waterline
//! levels are stepped down the steep triangles' height range as the planner
//! steps them (`SteepShallow::level_spacing` at the smallest steep slope at
//! each height, a level just above each flat area), and each level makes as
//! many passes as the steep triangles' cross-section at that height has
//! connected pieces (counted on at most [`SECTION_SAMPLES`] levels).
//!
//! A 3+2 `[setup]` is estimated on the part turned into its planning frame
//! (surfaces tessellated as the planner tessellates them).

use std::collections::HashMap;

use rayon::prelude::*;
use scallop_analysis::{GridOptions, sample_mesh, sample_surface_set};
use scallop_cutter::CutterShape;
use scallop_geom::{Aabb3, Point3, Vec3};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_strategy::{
    IsoDirection, IsoSurface, SteepShallow, convex_factor, iso_fitted_passes, rule_spacing, tol as stol,
};
use serde::Serialize;

use crate::finish::{analyse, planning_tolerances};
use crate::job::job_stock;
use crate::rough_estimate::RoughModel;
use crate::{EngineError, FinishJob, Job, Part, Strategy};

/// Profile samples per cutter radius of the rest test of steep and shallow.
const REST_SAMPLES: f64 = 8.0;

/// Profile samples of one run of the rest test, at most.
const MAX_REST_POINTS: usize = 4_000;

/// Isolines of each patch where the isoparametric estimate runs the
/// planner's step fit (`scallop_strategy::iso_fitted_passes`).
const ISO_SAMPLES: usize = 8;

/// Bands across the feed of the estimate.
const BANDS: usize = 400;

/// Height bins of the steep triangles' smallest slope (steep and shallow).
const Z_BINS: usize = 2_000;

/// Levels on which the steep cross-section's pieces are counted; the passes
/// of the others are their mean (keeps a large mesh's estimate under a second).
pub const SECTION_SAMPLES: usize = 32;

/// The estimate of one finishing operation.
#[derive(Debug, Clone, Serialize)]
pub struct Estimate {
    /// The strategy's job word (`parallel`, `network`, `isoparametric`, `steep-shallow`).
    pub strategy: &'static str,
    /// Feed direction from +X (degrees).
    pub direction_deg: f64,
    /// Whether the job gave it (else the analysis chose it).
    pub direction_given: bool,
    /// Expected planes (parallel and network strategies: one pass each where
    /// the part is convex across the feed; steep and shallow: the planes of
    /// the shallow triangles).
    pub planes: usize,
    /// Expected waterline levels with a pass (steep and shallow; else 0).
    pub levels: usize,
    /// Expected passes: the planes' (steep and shallow: their runs over the
    /// shallow triangles) plus the levels'. The planner's report counts the same.
    pub passes: usize,
    /// Smallest and largest band spacing (mm).
    pub spacing_mm: [f64; 2],
    /// Expected feed length (mm): the part's area over the local spacing.
    pub feed_length_mm: f64,
    /// Expected cutting time at the programmed feed (s): a lower bound of the
    /// planned time (acceleration limits add to it).
    pub time_at_feed_s: f64,
}

/// A face of the part for the estimate: a mesh triangle or a surface sample.
struct Face {
    /// Offset range across the feed (mm).
    across: [f64; 2],
    /// Unit normal, facing up.
    normal: Vec3,
    /// Area (mm²).
    area: f64,
    /// The mesh triangle (index), `None` for a surface sample.
    triangle: Option<usize>,
}

impl Face {
    /// Slope from the horizontal (rad).
    fn slope(&self) -> f64 {
        self.normal.z.abs().min(1.0).acos()
    }
}

/// Estimates a finishing operation of `job` (see the module documentation).
///
/// # Errors
/// The analysis' errors; a surface that cannot be tessellated (3+2 setups and
/// steep and shallow on surfaces, which plan on the tessellation).
pub fn estimate_operation(job: &FinishJob) -> Result<Estimate, EngineError> {
    let steep = matches!(job.strategy, Strategy::SteepShallow { .. });
    let turned = planning_mesh(job, steep)?;
    let mesh = match (&turned, &job.part) {
        (Some(m), _) | (None, Part::Mesh(m)) => Some(m),
        (None, Part::Surfaces(_)) => None,
    };
    let samples = match (mesh, &job.part) {
        (Some(m), _) => sample_mesh(m),
        (None, Part::Surfaces(set)) => {
            sample_surface_set(set, &GridOptions::default()).map_err(EngineError::Analysis)?
        }
        (None, Part::Mesh(m)) => sample_mesh(m),
    };
    let (_, direction_deg) = analyse(job, &samples)?;
    let direction = direction_deg.to_radians();
    let m = Vec3::new(-direction.sin(), direction.cos(), 0.0);
    let up = |n: Vec3| if n.z < 0.0 { -n } else { n };
    let faces: Vec<Face> = match mesh {
        Some(mesh) => (0..mesh.triangles().len())
            .map(|t| {
                let p = mesh.triangle(t);
                let d = p.map(|q: Point3| q.coords.dot(&m));
                let n = (p[1] - p[0]).cross(&(p[2] - p[0]));
                let across = [d[0].min(d[1]).min(d[2]), d[0].max(d[1]).max(d[2])];
                Face { across, normal: up(n.normalize()), area: 0.5 * n.norm(), triangle: Some(t) }
            })
            .filter(|f| f.area > 0.0 && f.normal.iter().all(|c| c.is_finite()))
            .collect(),
        None => samples
            .samples()
            .iter()
            .map(|s| {
                let d = s.point.coords.dot(&m);
                Face { across: [d, d], normal: up(s.normal), area: s.weight, triangle: None }
            })
            .collect(),
    };
    let estimate = Estimate {
        strategy: strategy_word(job.strategy),
        direction_deg: direction_deg + 0.0,
        direction_given: job.direction_deg.is_some(),
        planes: 0,
        levels: 0,
        passes: 0,
        spacing_mm: [0.0; 2],
        feed_length_mm: 0.0,
        time_at_feed_s: 0.0,
    };
    let feed = job.machine[0] * 1000.0 / 60.0; // m/min -> mm/s
    let mut e = match (job.strategy, mesh) {
        (Strategy::SteepShallow { threshold_deg }, Some(mesh)) => {
            let mut split = SteepShallow::default_for(&job.cutter, job.scallop_height);
            if let Some(t) = threshold_deg {
                split.threshold = t.to_radians();
            }
            steep_shallow(job, mesh, &faces, &split, direction, estimate)
        }
        (Strategy::Isoparametric(iso), _) => isoparametric(job, iso, parallel(job, &faces, direction, estimate))?,
        _ => parallel(job, &faces, direction, estimate),
    };
    e.time_at_feed_s = e.feed_length_mm / feed;
    Ok(e)
}

/// Isoparametric passes on a parametric part: the planner's own step fit
/// (the rule's step measured on the tessellation and corrected) at
/// [`ISO_SAMPLES`] isolines of each patch, the cross range walked with those
/// steps (`scallop_strategy::iso_fitted_passes`); `e` keeps the parallel
/// estimate's spacings and feed length.
#[allow(clippy::result_large_err, reason = "the engine's one error type, as estimate_operation")]
fn isoparametric(job: &FinishJob, direction: IsoDirection, mut e: Estimate) -> Result<Estimate, EngineError> {
    let Part::Surfaces(set) = &job.part else { return Ok(e) };
    let tolerances = planning_tolerances(job)?;
    let prepared = crate::prepare_part(&job.part, &tolerances)?;
    let params = job.timing_params();
    let mut passes = 0;
    for patch in set.patches() {
        let surface = IsoSurface { patch, index: &prepared.index, chordal_error: prepared.chordal_error };
        passes += iso_fitted_passes(&surface, &job.cutter, &params, direction, &tolerances, ISO_SAMPLES)
            .map_err(EngineError::Strategy)?;
    }
    e.planes = passes;
    e.passes = passes;
    Ok(e)
}

/// The job word of a strategy.
fn strategy_word(strategy: Strategy) -> &'static str {
    match strategy {
        Strategy::ParallelPlanes => "parallel",
        Strategy::NetworkPlanes => "network",
        Strategy::Isoparametric(_) => "isoparametric",
        Strategy::SteepShallow { .. } => "steep-shallow",
    }
}

/// Estimates every operation of `job`: finishing with [`estimate_operation`],
/// roughing with one [`RoughModel`] of the job's stock (the part tessellated
/// once for all roughing operations), each roughing operation on the
/// material the earlier ones left in the model.
#[must_use]
pub fn estimate_job(job: &Job) -> Vec<Result<Estimate, EngineError>> {
    let mut model: Option<(RoughModel, MeshIndex, Aabb3)> = None;
    let mut out = Vec::with_capacity(job.operations.len());
    for (k, op) in job.operations.iter().enumerate() {
        let Some(settings) = &op.rough else {
            out.push(estimate_operation(&op.finish));
            continue;
        };
        let later = job.operations[k + 1..].iter().any(|o| o.rough.is_some());
        if model.is_none() {
            match part_mesh(&op.finish) {
                Ok(m) => model = Some(rough_model(job, &m)),
                Err(e) => {
                    out.push(Err(e));
                    continue;
                }
            }
        }
        if let Some((model, index, stock)) = &mut model {
            out.push(Ok(model.estimate(&op.finish, (settings, later), stock, index)));
        }
    }
    out
}

/// The roughing model of `job` on its part `mesh` (`rough_estimate` module
/// docs: cells of half the smallest stepover, or of the simulation's
/// resolution when a roughing operation follows another operation), the
/// part's index and the stock box.
fn rough_model(job: &Job, mesh: &TriMesh) -> (RoughModel, MeshIndex, Aabb3) {
    let stock = job_stock(job, mesh);
    let radius = job.operations.iter().map(|o| o.finish.cutter.radius()).fold(0.0, f64::max);
    let rest = job.operations.iter().skip(1).any(|o| o.rough.is_some());
    let sim = job.operations.first().map_or(0.1, |o| o.finish.sim_resolution);
    let cells = if rest {
        (sim, crate::rough_estimate::MAX_REST_CELLS)
    } else {
        let half = job
            .operations
            .iter()
            .filter_map(|o| o.rough.map(|s| s.stepover * o.finish.cutter.radius()))
            .fold(f64::INFINITY, f64::min);
        (half, crate::rough_estimate::MAX_CELLS)
    };
    (RoughModel::new(mesh, &stock, radius, cells, sim), MeshIndex::build(mesh), stock)
}

/// The part as the planner meshes it: the mesh, or the surfaces' tessellation.
fn part_mesh(job: &FinishJob) -> Result<TriMesh, EngineError> {
    Ok(match &job.part {
        Part::Mesh(m) => m.clone(),
        Part::Surfaces(set) => set.tessellate(planning_tolerances(job)?.tessellation())?.mesh,
    })
}

/// The mesh the planner works on when it is not the job's part: a 3+2
/// setup's turned part, the tessellation of surfaces under steep and shallow.
fn planning_mesh(job: &FinishJob, steep: bool) -> Result<Option<TriMesh>, EngineError> {
    if job.setup.is_none() && !(steep && matches!(job.part, Part::Surfaces(_))) {
        return Ok(None);
    }
    let mesh = part_mesh(job)?;
    let Some(setup) = &job.setup else { return Ok(Some(mesh)) };
    let vertices: Vec<Point3> = mesh.vertices().iter().map(|v| setup.rotation * v).collect();
    let triangles: Vec<[usize; 3]> = mesh.triangles().iter().map(|t| t.map(|i| i as usize)).collect();
    let (turned, _) = TriMesh::from_indexed(&vertices, &triangles).map_err(|e| EngineError::Output {
        what: format!("the turned part: {e}"),
        fix: "check the setup rotation".into(),
    })?;
    Ok(Some(turned))
}

/// Bands across the feed from `lo`, `width` wide: the smallest rule spacing
/// of the faces reaching each (infinite where none does), and the feed length
/// (area over spacing).
fn band_spacings<'a>(
    job: &FinishJob,
    faces: impl Iterator<Item = &'a Face>,
    (lo, width): (f64, f64),
    direction: f64,
) -> (Vec<f64>, f64) {
    let mut band = vec![f64::INFINITY; BANDS];
    let mut feed_length = 0.0;
    for f in faces {
        let spacing = rule_spacing(job.cutter.shape(), job.scallop_height, &f.normal, direction);
        feed_length += f.area / spacing;
        for b in &mut band[band_index(f.across[0], lo, width)..=band_index(f.across[1], lo, width)] {
            *b = b.min(spacing);
        }
    }
    (band, feed_length)
}

#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "clamped band indices")]
fn band_index(d: f64, lo: f64, width: f64) -> usize {
    (((d - lo) / width).floor().max(0.0) as usize).min(BANDS - 1)
}

/// The range across the feed of `faces` and the width of a band.
fn band_range<'a>(faces: impl Iterator<Item = &'a Face> + Clone) -> (f64, f64) {
    let lo = faces.clone().map(|f| f.across[0]).fold(f64::INFINITY, f64::min);
    let hi = faces.map(|f| f.across[1]).fold(f64::NEG_INFINITY, f64::max);
    #[allow(clippy::cast_precision_loss, reason = "a small constant")]
    let width = (hi - lo).max(1e-9) / BANDS as f64;
    (lo, width)
}

/// Smallest and largest finite spacing.
fn spacing_range(band: &[f64]) -> [f64; 2] {
    let [a, b] = band.iter().filter(|s| s.is_finite()).fold([f64::INFINITY, 0.0f64], |[a, b], &s| [a.min(s), b.max(s)]);
    if a.is_finite() { [a, b] } else { [0.0, 0.0] }
}

#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a count")]
fn count(x: f64) -> usize {
    x.round().max(0.0) as usize
}

/// Parallel planes over the whole part (also the network and isoparametric
/// strategies' nearest cheap figure).
fn parallel(job: &FinishJob, faces: &[Face], direction: f64, mut e: Estimate) -> Estimate {
    let (lo, width) = band_range(faces.iter());
    let (mut band, feed_length) = band_spacings(job, faces.iter(), (lo, width), direction);
    // Bands no face reaches (between surface samples) take their neighbour's spacing.
    for k in 1..BANDS {
        if band[k].is_infinite() {
            band[k] = band[k - 1];
        }
    }
    for k in (0..BANDS - 1).rev() {
        if band[k].is_infinite() {
            band[k] = band[k + 1];
        }
    }
    // Beyond the part's extent the cutter still touches its rim for one radius on each
    // side: those strips are planed at the floor spacing of the rule.
    let floor = rule_spacing(job.cutter.shape(), job.scallop_height, &Vec3::z(), direction);
    let planes: f64 = band.iter().map(|s| width / s).sum::<f64>() + 2.0 * job.cutter.radius() / floor;
    e.planes = count(planes).max(1);
    e.passes = e.planes;
    e.spacing_mm = spacing_range(&band);
    e.feed_length_mm = feed_length;
    e
}

/// Steep and shallow (module docs): the shallow triangles' planes and runs,
/// then the steep triangles' levels and pieces.
fn steep_shallow(
    job: &FinishJob,
    mesh: &TriMesh,
    faces: &[Face],
    split: &SteepShallow,
    direction: f64,
    mut e: Estimate,
) -> Estimate {
    let shallow: Vec<&Face> = faces.iter().filter(|f| f.slope() < split.threshold + split.overlap).collect();
    if !shallow.is_empty() {
        let (lo, width) = band_range(shallow.iter().copied());
        let (band, length) = band_spacings(job, shallow.iter().copied(), (lo, width), direction);
        let is_shallow = |f: &Face| f.slope() < split.threshold + split.overlap;
        let sections = band_sections(mesh, faces, is_shallow, (lo, width), direction);
        let shape = job.cutter.shape();
        let band_runs: Vec<Vec<[f64; 2]>> = sections.iter().map(|s| runs(s, job.tolerances.path)).collect();
        let shallow_nz = (split.threshold + split.overlap).cos();
        let across = across_rest(&sections, &band_runs, (width, shallow_nz), shape, job.scallop_height);
        let (runs, rest): (Vec<usize>, Vec<bool>) = sections
            .par_iter()
            .zip(&band_runs)
            .zip(&across)
            .map(|((section, runs), &across)| {
                (runs.len(), across || band_has_rest(section, runs, shape, job.scallop_height))
            })
            .unzip();
        // Where a band meets rest material the planes go a share of the largest
        // step-over (the rule's spacing on a horizontal face) apart.
        let rest_gap = stol::REST_SPACING_SHARE * rule_spacing(shape, job.scallop_height, &Vec3::z(), direction);
        let (mut planes, mut passes) = (0.0, 0.0);
        for ((s, &r), &rest) in band.iter().zip(&runs).zip(&rest) {
            if s.is_finite() && r > 0 {
                let s = if rest { s.min(rest_gap) } else { *s };
                planes += width / s;
                #[allow(clippy::cast_precision_loss, reason = "a small count")]
                let r = r as f64;
                passes += width / s * r;
            }
        }
        e.planes = count(planes);
        e.passes = count(passes);
        e.spacing_mm = spacing_range(&band);
        e.feed_length_mm = length;
    }
    let steep: Vec<&Face> = faces.iter().filter(|f| f.slope() >= split.threshold - split.overlap).collect();
    let (levels, passes, length) = waterline_levels(job, mesh, &steep, split);
    e.levels = levels;
    e.passes += passes;
    e.feed_length_mm += length;
    e
}

/// A face's piece on a band's centre line: feed abscissae, heights, the
/// face's normal z and whether it is shallow.
struct Piece {
    u: [f64; 2],
    z: [f64; 2],
    nz: f64,
    shallow: bool,
}

/// Per band, the pieces of `faces` (mesh triangles) on the band's centre
/// line, `shallow` telling which of them the planes finish.
fn band_sections(
    mesh: &TriMesh,
    faces: &[Face],
    shallow: impl Fn(&Face) -> bool,
    (lo, width): (f64, f64),
    direction: f64,
) -> Vec<Vec<Piece>> {
    let (f, m) = (Vec3::new(direction.cos(), direction.sin(), 0.0), Vec3::new(-direction.sin(), direction.cos(), 0.0));
    let mut sections: Vec<Vec<Piece>> = (0..BANDS).map(|_| Vec::new()).collect();
    for face in faces {
        let Some(t) = face.triangle else { continue };
        let p = mesh.triangle(t);
        for (k, band) in sections
            .iter_mut()
            .enumerate()
            .take(band_index(face.across[1], lo, width) + 1)
            .skip(band_index(face.across[0], lo, width))
        {
            #[allow(clippy::cast_precision_loss, reason = "a band index")]
            let d = lo + (k as f64 + 0.5) * width;
            let mut ends: Vec<(f64, f64)> = Vec::with_capacity(2);
            for (a, b) in [(p[0], p[1]), (p[1], p[2]), (p[2], p[0])] {
                let (da, db) = (a.coords.dot(&m) - d, b.coords.dot(&m) - d);
                if da * db > 0.0 || (da - db).abs() < f64::MIN_POSITIVE {
                    continue;
                }
                let q = a + (b - a) * (da / (da - db));
                ends.push((q.coords.dot(&f), q.z));
            }
            ends.sort_by(|x, y| x.0.total_cmp(&y.0));
            if let (Some(&(u0, z0)), Some(&(u1, z1))) = (ends.first(), ends.last()) {
                band.push(Piece { u: [u0, u1], z: [z0, z1], nz: face.normal.z, shallow: shallow(face) });
            }
        }
    }
    sections
}

/// The runs of the shallow pieces of a band: their intervals along the feed
/// merged where they touch (within `gap`).
fn runs(section: &[Piece], gap: f64) -> Vec<[f64; 2]> {
    let mut list: Vec<[f64; 2]> = section.iter().filter(|p| p.shallow).map(|p| p.u).collect();
    list.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let mut out: Vec<[f64; 2]> = Vec::new();
    for [a, b] in list {
        match out.last_mut() {
            Some(last) if a <= last[1] + gap => last[1] = last[1].max(b),
            _ => out.push([a, b]),
        }
    }
    out
}

/// Whether the planes of a band meet rest material (the steep-and-shallow
/// planner's rest rule, `Planner::sweep` in `scallop_strategy`): in the
/// band's section, the cutter's profile run along each run of shallow pieces
/// (tip heights by the 2-D drop of the profile on the section, at
/// [`REST_SAMPLES`] a cutter radius) leaves a residual, along the normal,
/// over sh somewhere at least a cutter radius from the run's ends (where the
/// planner measures: its zone end margin). No plane spacing lowers that
/// residual, so the planner takes it for rest: at once when it is over
/// `REST_RESIDUAL_FACTOR` sh, else when it keeps over half its height as
/// the gap is more than halved. A vertical wall inside a run (the pass steps
/// down it) leaves the corner at its foot, so does a concave edge tighter
/// than the cutter.
fn band_has_rest(section: &[Piece], runs: &[[f64; 2]], shape: &CutterShape, sh: f64) -> bool {
    let radius = shape.radius();
    runs.iter().filter(|r| r[1] - r[0] > 2.0 * radius).any(|&[a, b]| {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a bounded count")]
        let n = (((b - a) * REST_SAMPLES / radius).ceil() as usize).clamp(1, MAX_REST_POINTS);
        #[allow(clippy::cast_precision_loss, reason = "a bounded count")]
        let us: Vec<f64> = (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect();
        let zs: Vec<(f64, f64)> = us.iter().map(|&u| profile(section, u)).collect();
        let left = residuals(&zs, (b - a) / us.len().saturating_sub(1).max(1) as f64, shape);
        (0..=n).any(|i| us[i] >= a + radius && us[i] <= b - radius && left[i] > sh)
    })
}

/// The part's height (and normal z) on a band's centre line at feed
/// abscissa `u`: the highest piece over it (`-inf` where none).
fn profile(section: &[Piece], u: f64) -> (f64, f64) {
    section
        .iter()
        .filter(|p| p.u[0] <= u && u <= p.u[1])
        .map(|p| {
            let w = if p.u[1] > p.u[0] { (u - p.u[0]) / (p.u[1] - p.u[0]) } else { 0.5 };
            (p.z[0] + w * (p.z[1] - p.z[0]), p.nz)
        })
        .fold((f64::NEG_INFINITY, 1.0), |a, b| if b.0 > a.0 { b } else { a })
}

/// The residual, along the normal, that the cutter's profile run along a
/// section sampled every `step` mm (heights and normal z `zs`) leaves at
/// each sample: tip heights by the 2-D drop of the profile, then the lowest
/// surface of the profile over each sample.
fn residuals(zs: &[(f64, f64)], step: f64, shape: &CutterShape) -> Vec<f64> {
    let n = zs.len();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a bounded count")]
    let w = ((shape.radius() / step).floor() as usize).min(n);
    let near = |i: usize| i.saturating_sub(w)..(i + w + 1).min(n);
    #[allow(clippy::cast_precision_loss, reason = "sample offsets")]
    let h = |i: usize, j: usize| shape.height_at(step * i.abs_diff(j) as f64);
    let tips: Vec<f64> = (0..n).map(|i| near(i).map(|j| zs[j].0 - h(i, j)).fold(f64::NEG_INFINITY, f64::max)).collect();
    (0..n)
        .map(|i| {
            let left = near(i).map(|j| tips[j] + h(i, j)).fold(f64::INFINITY, f64::min);
            (left - zs[i].0) * zs[i].1.abs()
        })
        .collect()
}

/// The bands whose planes meet rest material across the feed: the
/// residual (as [`band_has_rest`]) of the cutter's profile run across the
/// bands, on sections at every [`REST_SAMPLES`]-th of a cutter radius along
/// the feed, over sh at a band's point on a shallow piece (normal z at
/// least `shallow_nz`) that lies at least a cutter radius inside one of its
/// runs and a cutter radius from the first and last band (the cutter beyond
/// them is not sampled).
fn across_rest(
    sections: &[Vec<Piece>],
    runs: &[Vec<[f64; 2]>],
    (width, shallow_nz): (f64, f64),
    shape: &CutterShape,
    sh: f64,
) -> Vec<bool> {
    let radius = shape.radius();
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a bounded count")]
    let margin = ((radius / width).ceil() as usize).min(sections.len());
    let inside = |b: usize, u: f64| runs[b].iter().any(|r| u >= r[0] + radius && u <= r[1] - radius);
    let lo = runs.iter().flatten().map(|r| r[0]).fold(f64::INFINITY, f64::min);
    let hi = runs.iter().flatten().map(|r| r[1]).fold(f64::NEG_INFINITY, f64::max);
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return vec![false; sections.len()];
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a bounded count")]
    let n = (((hi - lo) * REST_SAMPLES / radius).ceil() as usize).clamp(1, MAX_REST_POINTS);
    #[allow(clippy::cast_precision_loss, reason = "a bounded count")]
    let us: Vec<f64> = (0..=n).map(|i| lo + (hi - lo) * i as f64 / n as f64).collect();
    let hits: Vec<Vec<usize>> = us
        .par_iter()
        .map(|&u| {
            let zs: Vec<(f64, f64)> = sections.iter().map(|s| profile(s, u)).collect();
            let left = residuals(&zs, width, shape);
            // A point of a shallow piece, with the bands a cutter radius around it.
            (margin..sections.len().saturating_sub(margin))
                .filter(|&b| left[b] > sh && zs[b].1 >= shallow_nz && inside(b, u))
                .collect()
        })
        .collect();
    let mut rest = vec![false; sections.len()];
    for b in hits.into_iter().flatten() {
        rest[b] = true;
    }
    rest
}

/// The waterline levels of the `steep` triangles stepped down as the planner
/// steps them: (levels with a pass, passes, feed length in mm).
fn waterline_levels(job: &FinishJob, mesh: &TriMesh, steep: &[&Face], split: &SteepShallow) -> (usize, usize, f64) {
    let path = job.tolerances.path;
    let spacing = |s: f64| split.level_spacing(&job.cutter, job.scallop_height, path, s);
    let z_of = |f: &Face| f.triangle.map(|t| mesh.triangle(t).map(|p| p.z));
    let zs: Vec<[f64; 3]> = steep.iter().filter_map(|f| z_of(f)).collect();
    let lo = zs.iter().flatten().copied().fold(f64::INFINITY, f64::min);
    let hi = zs.iter().flatten().copied().fold(f64::NEG_INFINITY, f64::max);
    let bin_lo = lo - job.cutter.radius();
    if zs.is_empty() {
        return (0, 0, 0.0);
    }
    // The smallest steep slope at each height.
    #[allow(clippy::cast_precision_loss, reason = "a small constant")]
    let bin = (hi - bin_lo).max(1e-9) / Z_BINS as f64;
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "clamped bin indices")]
    let index = |z: f64| (((z - bin_lo) / bin).floor().max(0.0) as usize).min(Z_BINS - 1);
    // A profile circle of radius rho touches a face of slope s at rho (1 - cos s) above
    // the tip: the faces are binned by the tip heights that touch them.
    let rho = match *job.cutter.shape() {
        CutterShape::Bull { corner, .. } => corner,
        CutterShape::Flat { .. } => 0.0,
        ref shape => shape.radius(),
    };
    let lift = |s: f64| rho * (1.0 - s.cos());
    let mut slopes = vec![f64::INFINITY; Z_BINS];
    let mut length = 0.0;
    for (f, z) in steep.iter().zip(&zs) {
        let (a, b) = (z[0].min(z[1]).min(z[2]), z[0].max(z[1]).max(z[2]));
        for s in &mut slopes[index(a - lift(f.slope()))..=index(b - lift(f.slope()))] {
            *s = s.min(f.slope());
        }
        length += f.area * f.slope().sin() / spacing(f.slope());
    }
    fill_gaps(&mut slopes, rho / bin);
    let slope_at = |z: f64| if z < bin_lo || z > hi { f64::INFINITY } else { slopes[index(z)] };
    // Heights of the flat areas (a level runs just above each), as the planner finds them.
    let mut flats: Vec<f64> = (0..mesh.triangles().len())
        .map(|t| mesh.triangle(t))
        .filter(|p| {
            let n = (p[1] - p[0]).cross(&(p[2] - p[0]));
            n.norm() > 0.0 && (n.z.abs() / n.norm()).min(1.0).acos() < stol::FLAT_SLOPE
        })
        .map(|p| p.iter().map(|q| q.z).fold(f64::NEG_INFINITY, f64::max))
        .collect();
    flats.sort_by(|a, b| b.total_cmp(a));
    flats.dedup_by(|a, b| (*a - *b).abs() <= path);
    let bounds = mesh.bounds();
    let margin = stol::LEVEL_EDGE_SHARE * path;
    let bottom = (lo + margin).max(bounds.min.z + margin);
    let top = (hi - margin).min(bounds.max.z - margin).max(bottom);
    let next_z = |z: f64, dz: f64| {
        let below = (z - dz).max(bottom);
        flats.iter().map(|f| f + stol::FLAT_LIFT_SHARE * path).find(|&f| f < z && f > below).unwrap_or(below)
    };
    let mut levels = Vec::new();
    let mut z = top;
    while levels.len() <= stol::MAX_LEVELS {
        let s = slope_at(z);
        if s.is_finite() {
            levels.push(z + lift(s));
        }
        if z <= bottom {
            break;
        }
        let mut dz = spacing(s);
        let mut next = next_z(z, dz);
        if slope_at(next) < s {
            next = next_z(z, spacing(slope_at(next)));
        } else if let Some(factor) = convex_factor(job.cutter.shape(), (z, s), (next, slope_at(next))) {
            dz *= factor;
            next = next_z(z, dz);
        }
        z = next;
    }
    (levels.len(), level_passes(mesh, steep, &levels), length)
}

/// Fills the runs of empty bins shorter than `bins` between two filled ones
/// with the smaller neighbour: the faces' shifts by their own contact lift
/// leave such gaps between adjacent faces of different slopes, where the
/// cutter touches their common edge.
fn fill_gaps(slopes: &mut [f64], bins: f64) {
    let mut last: Option<usize> = None;
    for k in 0..slopes.len() {
        if slopes[k].is_infinite() {
            continue;
        }
        if let Some(j) = last
            && k > j + 1
        {
            #[allow(clippy::cast_precision_loss, reason = "bin counts")]
            let short = ((k - j - 1) as f64) < bins;
            if short {
                let s = slopes[j].min(slopes[k]);
                slopes[j + 1..k].iter_mut().for_each(|v| *v = s);
            }
        }
        last = Some(k);
    }
}

/// Passes on `levels`: the connected pieces of the steep triangles' cross
/// section, counted on at most [`SECTION_SAMPLES`] levels spread evenly.
fn level_passes(mesh: &TriMesh, steep: &[&Face], levels: &[f64]) -> usize {
    if levels.is_empty() {
        return 0;
    }
    let step = levels.len().div_ceil(SECTION_SAMPLES);
    let sampled: Vec<usize> = levels.iter().step_by(step).map(|&z| section_pieces(mesh, steep, z)).collect();
    #[allow(clippy::cast_precision_loss, reason = "small counts")]
    let mean = sampled.iter().sum::<usize>() as f64 / sampled.len() as f64;
    #[allow(clippy::cast_precision_loss, reason = "small counts")]
    count(mean * levels.len() as f64)
}

/// The connected pieces of the section of the `steep` triangles at height `z`
/// (triangles joined through the edges that cross `z`).
fn section_pieces(mesh: &TriMesh, steep: &[&Face], z: f64) -> usize {
    let above = |i: u32| mesh.vertices()[i as usize].z >= z;
    let mut parent: Vec<usize> = Vec::new();
    let mut owner: HashMap<(u32, u32), usize> = HashMap::new();
    fn root(parent: &mut [usize], mut k: usize) -> usize {
        while parent[k] != k {
            parent[k] = parent[parent[k]];
            k = parent[k];
        }
        k
    }
    for f in steep {
        let Some(t) = f.triangle else { continue };
        let tri = mesh.triangles()[t];
        let crossing: Vec<(u32, u32)> = [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])]
            .into_iter()
            .filter(|&(a, b)| above(a) != above(b))
            .map(|(a, b)| (a.min(b), a.max(b)))
            .collect();
        if crossing.is_empty() {
            continue;
        }
        let me = parent.len();
        parent.push(me);
        for edge in crossing {
            if let Some(other) = owner.insert(edge, me) {
                let (a, b) = (root(&mut parent, other), root(&mut parent, me));
                parent[a] = b;
            }
        }
    }
    (0..parent.len()).filter(|&k| root(&mut parent, k) == k).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_gaps_are_filled_with_the_smaller_neighbour_long_ones_kept() {
        let inf = f64::INFINITY;
        let mut s = vec![inf, 1.0, inf, inf, 0.5, inf, inf, inf, inf, 0.7, inf];
        fill_gaps(&mut s, 3.0);
        assert_eq!(s[..5], [inf, 1.0, 0.5, 0.5, 0.5]);
        assert!(s[5..9].iter().all(|v| v.is_infinite()) && s[9].to_bits() == 0.7f64.to_bits() && s[10].is_infinite());
    }

    /// Two separate vertical walls (two quads, each two triangles) cut at
    /// mid-height are two pieces; joined at a corner, one.
    #[test]
    fn section_pieces_count_separate_walls() {
        let p = |x, y, z| Point3::new(x, y, z);
        let quad = |a: Point3, b: Point3| {
            let (a1, b1) = (p(a.x, a.y, 10.0), p(b.x, b.y, 10.0));
            vec![[a, b, b1], [a, b1, a1]]
        };
        let count = |walls: Vec<[Point3; 3]>| {
            let (mesh, _) = TriMesh::from_soup(&walls).unwrap();
            let faces: Vec<Face> = (0..mesh.triangles().len())
                .map(|t| Face { across: [0.0, 0.0], normal: Vec3::x(), area: 1.0, triangle: Some(t) })
                .collect();
            let refs: Vec<&Face> = faces.iter().collect();
            section_pieces(&mesh, &refs, 5.0)
        };
        let apart = [quad(p(0., 0., 0.), p(10., 0., 0.)), quad(p(0., 20., 0.), p(10., 20., 0.))].concat();
        assert_eq!(count(apart), 2);
        let corner = [quad(p(0., 0., 0.), p(10., 0., 0.)), quad(p(10., 0., 0.), p(10., 10., 0.))].concat();
        assert_eq!(count(corner), 1);
    }

    /// The rest test on band sections: a floor, and a convex arc of radius
    /// larger than the ball, leave no residual; a vertical step inside the
    /// run leaves the corner at its foot (about the ball's radius high),
    /// also when the run ends more than a radius from the step.
    #[test]
    fn a_step_leaves_rest_a_floor_and_a_convex_arc_none() {
        let ball = CutterShape::Ball { radius: 2.0 };
        let piece = |u0: f64, u1: f64, z0: f64, z1: f64| Piece { u: [u0, u1], z: [z0, z1], nz: 1.0, shallow: true };
        let rest = |section: Vec<Piece>| {
            let runs = runs(&section, 0.01);
            band_has_rest(&section, &runs, &ball, 0.02)
        };
        assert!(!rest(vec![piece(0.0, 30.0, 5.0, 5.0)]));
        // A circle of radius 20 through points 0.25 mm apart (chords sag 0.4 um).
        let arc: Vec<Piece> = (0..80)
            .map(|k| {
                let (a, b) = (-1.0 + f64::from(k) / 40.0, -1.0 + f64::from(k + 1) / 40.0);
                let z = |x: f64| (400.0 - 100.0 * x * x).sqrt();
                piece(10.0 * a, 10.0 * b, z(a), z(b))
            })
            .collect();
        assert!(!rest(arc));
        assert!(rest(vec![piece(0.0, 10.0, 0.0, 0.0), piece(10.0, 20.0, 5.0, 5.0)]));
        assert!(!rest(vec![piece(0.0, 3.0, 0.0, 0.0)]), "a run under two radii is not measured");
    }
}
