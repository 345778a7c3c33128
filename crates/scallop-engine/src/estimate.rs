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

use scallop_analysis::{GridOptions, sample_mesh, sample_surface_set};
use scallop_geom::{Point3, Vec3};
use scallop_strategy::rule_spacing;
use serde::Serialize;

use crate::finish::analyse;
use crate::{EngineError, FinishJob, Part, Strategy};

/// Bands across the feed of the estimate.
const BANDS: usize = 400;

/// The estimate of one finishing operation.
#[derive(Debug, Clone, Serialize)]
pub struct Estimate {
    /// The strategy's job word (`parallel`, `network`, `isoparametric`).
    pub strategy: &'static str,
    /// Feed direction from +X (degrees).
    pub direction_deg: f64,
    /// Whether the job gave it (else the analysis chose it).
    pub direction_given: bool,
    /// Expected planes (parallel and network strategies: one pass each where
    /// the part is convex across the feed).
    pub planes: usize,
    /// Smallest and largest band spacing (mm).
    pub spacing_mm: [f64; 2],
    /// Expected feed length (mm): the part's area over the local spacing.
    pub feed_length_mm: f64,
    /// Expected cutting time at the programmed feed (s): a lower bound of the
    /// planned time (acceleration limits add to it).
    pub time_at_feed_s: f64,
}

/// Estimates a finishing operation of `job` (see the module documentation).
///
/// # Errors
/// The analysis' errors, and a 3+2 `[setup]` (its planning frame is the
/// planner's; not estimated).
pub fn estimate_operation(job: &FinishJob) -> Result<Estimate, EngineError> {
    if job.setup.is_some() {
        return Err(EngineError::Output {
            what: "an estimate of a 3+2 setup".into(),
            fix: "run the job without --plan-only".into(),
        });
    }
    let samples = match &job.part {
        Part::Surfaces(set) => sample_surface_set(set, &GridOptions::default()).map_err(EngineError::Analysis)?,
        Part::Mesh(mesh) => sample_mesh(mesh),
    };
    let (_, direction_deg) = analyse(job, &samples)?;
    let direction = direction_deg.to_radians();
    let m = Vec3::new(-direction.sin(), direction.cos(), 0.0);
    let sh = job.scallop_height;
    // Faces as (offset range across the feed, normal, area).
    let faces: Vec<([f64; 2], Vec3, f64)> = match &job.part {
        Part::Mesh(mesh) => mesh
            .triangles()
            .iter()
            .map(|t| {
                let p = t.map(|i| mesh.vertices()[i as usize]);
                let d = p.map(|q: Point3| q.coords.dot(&m));
                let n = (p[1] - p[0]).cross(&(p[2] - p[0]));
                let area = 0.5 * n.norm();
                let n = if n.z < 0.0 { -n } else { n };
                ([d[0].min(d[1]).min(d[2]), d[0].max(d[1]).max(d[2])], n.normalize(), area)
            })
            .filter(|(_, n, area)| *area > 0.0 && n.iter().all(|c| c.is_finite()))
            .collect(),
        Part::Surfaces(_) => samples
            .samples()
            .iter()
            .map(|s| {
                let d = s.point.coords.dot(&m);
                let n = if s.normal.z < 0.0 { -s.normal } else { s.normal };
                ([d, d], n, s.weight)
            })
            .collect(),
    };
    Ok(bands(job, &faces, sh, direction, direction_deg))
}

/// The planes, spacings, length and time from faces binned across the feed.
fn bands(job: &FinishJob, faces: &[([f64; 2], Vec3, f64)], sh: f64, direction: f64, direction_deg: f64) -> Estimate {
    let lo = faces.iter().map(|f| f.0[0]).fold(f64::INFINITY, f64::min);
    let hi = faces.iter().map(|f| f.0[1]).fold(f64::NEG_INFINITY, f64::max);
    let width = (hi - lo).max(1e-9) / BANDS as f64;
    let mut band = vec![f64::INFINITY; BANDS];
    let mut feed_length = 0.0;
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "clamped band indices")]
    let index = |d: f64| (((d - lo) / width).floor().max(0.0) as usize).min(BANDS - 1);
    for (range, n, area) in faces {
        let spacing = rule_spacing(job.cutter.shape(), sh, n, direction);
        feed_length += area / spacing;
        for b in &mut band[index(range[0])..=index(range[1])] {
            *b = b.min(spacing);
        }
    }
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
    let floor = rule_spacing(job.cutter.shape(), sh, &Vec3::z(), direction);
    let planes: f64 = band.iter().map(|s| width / s).sum::<f64>() + 2.0 * job.cutter.radius() / floor;
    let [min, max] = band.iter().fold([f64::INFINITY, 0.0f64], |[a, b], &s| [a.min(s), b.max(s)]);
    let feed = job.machine[0] * 1000.0 / 60.0; // m/min -> mm/s
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a plane count")]
    let planes = planes.round().max(1.0) as usize;
    Estimate {
        strategy: match job.strategy {
            Strategy::ParallelPlanes => "parallel",
            Strategy::NetworkPlanes => "network",
            Strategy::Isoparametric(_) => "isoparametric",
            // The estimate counts the shallow planes' rule over the whole part.
            Strategy::SteepShallow { .. } => "steep-shallow",
        },
        direction_deg: direction_deg + 0.0,
        direction_given: job.direction_deg.is_some(),
        planes,
        spacing_mm: [min, max],
        feed_length_mm: feed_length,
        time_at_feed_s: feed_length / feed,
    }
}
