//! Path curves: iterated inward offsets of a curve on a support by Marching
//! Facets (Jousselin 2020, Ch. 2 §3.2.1, the scalar method). Each curve is
//! the iso-line at `a_e` of the signed distance to the previous one (one field
//! per curve: iso-levels of one field would drift apart by more than `a_e` on
//! curved supports), until no facet is crossed. Several loops at a step mean
//! the offset split (Ch. 2 §3.3, Fig. 2.39b).

use rayon::prelude::*;
use scallop_geom::Point3;

use crate::facets::{Isolines, march};
use crate::field::CurveField;
use crate::support::{Curve, Support, check_curve};
use crate::{GuideError, tol};

/// One offset step.
#[derive(Clone, Debug, PartialEq)]
pub struct OffsetStep {
    /// The loops (or open chains) of this offset, inside on their left.
    pub curves: Vec<Curve>,
    /// Whether this step has more loops than the one before (a split).
    pub split: bool,
    /// Facets flagged as crossed by the medial axis.
    pub flagged: usize,
    /// Flagged facets whose segment got a repair point.
    pub repaired: usize,
}

/// The successive inward offsets of `limit` (inside on the left of each
/// curve, see [`Curve::inside_left`]) on `support`, `step` (the radial
/// engagement a_e, mm) apart, until they vanish. The first entry is the first
/// offset (C_n itself is not repeated). A loop narrower than
/// [`tol::SLIVER_WIDTH_FACETS`] facets (mean width `2 area / length`) counts
/// as vanished: it is the iso-line of a distance whose maximum barely passes
/// the step, below the mesh's resolution, and where the region is a strip of
/// about twice the step it breaks into a row of such slivers.
///
/// # Errors
/// [`GuideError::BadLength`] for a non-positive step, [`GuideError::BadCurve`]
/// for an unusable curve, [`GuideError::NotVanishing`] if the offsets do not
/// vanish within `diagonal / step + 2` steps.
pub fn offset_curves(support: &Support, limit: &[Curve], step: f64) -> Result<Vec<OffsetStep>, GuideError> {
    check_step(step)?;
    for (i, c) in limit.iter().enumerate() {
        check_curve(c, i)?;
    }
    let guard = (support.mesh().bounds().diagonal() / step).ceil() as usize + tol::EXTRA_STEPS;
    let mut current: Vec<Curve> = limit.to_vec();
    let mut band: Option<Band> = None;
    let mut steps: Vec<OffsetStep> = Vec::new();
    while !current.is_empty() {
        if steps.len() >= guard {
            return Err(GuideError::NotVanishing { steps: steps.len() });
        }
        let (mut iso, next) = offset_once(support, &current, step, band.as_ref());
        let sliver = tol::SLIVER_WIDTH_FACETS * support.facet_size();
        iso.curves.retain(|c| !c.line.closed || 2.0 * c.signed_area().abs() >= sliver * c.line.length());
        if iso.curves.is_empty() {
            break;
        }
        band = Some(next);
        let split = iso.curves.len() > current.len() && !steps.is_empty();
        current = iso.curves.clone();
        steps.push(OffsetStep { curves: iso.curves, split, flagged: iso.flagged, repaired: iso.repaired });
    }
    Ok(steps)
}

/// The single iso-line at `distance` inside `curves` (one Marching Facets
/// extraction over the whole support).
///
/// # Errors
/// [`GuideError::BadLength`] for a non-positive distance,
/// [`GuideError::BadCurve`] for an unusable curve.
pub fn offset_curve(support: &Support, curves: &[Curve], distance: f64) -> Result<Isolines, GuideError> {
    check_step(distance)?;
    for (i, c) in curves.iter().enumerate() {
        check_curve(c, i)?;
    }
    Ok(offset_once(support, curves, distance, None).0)
}

/// What one step leaves to the next: per vertex, the field value (distance
/// minus the offset; `+inf` where only a bound is known, `-inf` outside) and a
/// lower bound of the distance to the curves.
struct Band {
    values: Vec<f64>,
    lower: Vec<f64>,
}

/// Gives the vertices farther than the reach from the curves (value NaN) the
/// side of their measured neighbours: a connected set of far vertices never
/// crosses the curves, so it lies on one side. A far set with no measured
/// neighbour gets its side from one exact query. Sequential, in vertex order:
/// deterministic.
fn flood_far_sides(support: &Support, field: &CurveField, sampled: &mut [(f64, f64, Option<Point3>)]) {
    let far_value = |side_positive: bool| if side_positive { f64::INFINITY } else { f64::NEG_INFINITY };
    let mut queue: std::collections::VecDeque<u32> =
        (0..sampled.len()).filter(|&v| !sampled[v].0.is_nan()).map(|v| v as u32).collect();
    let mut seed = 0usize;
    loop {
        while let Some(u) = queue.pop_front() {
            let positive = sampled[u as usize].0 > 0.0;
            for &w in support.neighbours(u as usize) {
                if sampled[w as usize].0.is_nan() {
                    sampled[w as usize].0 = far_value(positive);
                    queue.push_back(w);
                }
            }
        }
        let Some(v) = (seed..sampled.len()).find(|&v| sampled[v].0.is_nan()) else { break };
        seed = v;
        sampled[v].0 = far_value(field.signed(&support.mesh().vertices()[v]) > 0.0);
        queue.push_back(v as u32);
    }
}

/// One Marching Facets extraction. On the first step only the vertices
/// within the reach (`distance` plus two facets) of the curves are measured;
/// the others take their side by a flood ([`flood_far_sides`]). After the first step (`prev` given) every
/// vertex still inside lies inside `curves`, and by the triangle inequality its
/// distance to them is at least its distance to the previous curves minus
/// `distance`: a vertex whose bound passes `distance` plus two facets is far
/// inside and is not measured (`+inf`); only the band around the new iso-line
/// is, so a step costs about the curve's length, not the area left.
fn offset_once(support: &Support, curves: &[Curve], distance: f64, prev: Option<&Band>) -> (Isolines, Band) {
    let field = CurveField::new(curves);
    let verts = support.mesh().vertices();
    let reach = distance + 2.0 * support.facet_size();
    // Chunks of consecutive vertices (neighbours in space on most meshes)
    // search from the last foot found: the same feet, fewer nodes visited.
    let chunks: Vec<Vec<(f64, f64, Option<Point3>)>> = (0..verts.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut hint = None;
            (c * CHUNK..((c + 1) * CHUNK).min(verts.len()))
                .map(|v| {
                    if let Some(prev) = prev {
                        if prev.values[v] <= 0.0 {
                            return (f64::NEG_INFINITY, 0.0, None);
                        }
                        let bound = prev.lower[v] - distance;
                        if bound > reach {
                            return (f64::INFINITY, bound, None);
                        }
                    }
                    match field.foot_near(&verts[v], reach, hint.as_ref()) {
                        Some(f) => {
                            hint = Some(f);
                            (field.signed_at(&verts[v], &f) - distance, f.distance, Some(f.point))
                        }
                        // Far: inside after the first step; decided by the flood below on the first.
                        None => (if prev.is_some() { f64::INFINITY } else { f64::NAN }, reach, None),
                    }
                })
                .collect()
        })
        .collect();
    let mut sampled: Vec<(f64, f64, Option<Point3>)> = chunks.into_iter().flatten().collect();
    if prev.is_none() {
        flood_far_sides(support, &field, &mut sampled);
    }
    let values: Vec<f64> = sampled.iter().map(|s| s.0).collect();
    let exact = |p: &Point3| field.signed(p) - distance;
    let mesh = support.mesh();
    let medial = |f: usize| {
        let t = mesh.triangles()[f];
        let feet = t.map(|v| sampled[v as usize].2);
        let [Some(a), Some(b), Some(c)] = feet else { return false };
        let spread = (a - b).norm().max((b - c).norm()).max((c - a).norm());
        let tri = mesh.triangle(f);
        let size = (tri[1] - tri[0]).norm().max((tri[2] - tri[1]).norm()).max((tri[0] - tri[2]).norm());
        spread > tol::MEDIAL_FOOT_FACTOR * size
    };
    let iso = march(support, &values, &exact, &medial);
    (iso, Band { lower: sampled.iter().map(|s| s.1).collect(), values })
}

/// Vertices per parallel work item of the field evaluation.
const CHUNK: usize = 256;

pub(crate) fn check_step(step: f64) -> Result<(), GuideError> {
    if step.is_finite() && step > 0.0 { Ok(()) } else { Err(GuideError::BadLength { name: "a_e", value: step }) }
}
