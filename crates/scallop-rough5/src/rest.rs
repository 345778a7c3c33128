//! A rest pass along the bottom's limit curves (docs/rough5.md, "Impeller
//! hub and roots"): where a flank overhangs the bottom (an impeller blade
//! leaning over its channel), the bottom level's limit curve keeps the
//! vertical tool off the overhang, so its passes stay several millimetres
//! from the flank's root and a band of the bottom's height is left along it.
//! The rest pass moves each pair of the bottom's limit pass across the pass,
//! along the bottom, and tilts its axis across the pass, as far towards the
//! nearest flank as the whole tool keeps the flank allowance (the flutes and
//! the corner, checked by a [`BodyCheck`] with the allowance as its
//! clearance) and the shank and holder their radius; it keeps a pair only
//! where that tool covers enough of the pair's cross-section that the
//! bottom level's tools left.

use rayon::prelude::*;
use scallop_geom::{Point3, Vec3};
use scallop_mesh::MeshQuery;

use crate::collide::BodyCheck;
use crate::place::{Placement, Placer};
use crate::sync::SyncPoint;

/// Farthest move of a pair towards the flank (mm).
pub const ROOT_REST_REACH_MAX: f64 = 6.0;
/// Farthest move of a pair away from the flank (mm): a tool leaning away
/// from an overhang stands farther out at the bottom.
pub const ROOT_REST_BACK_MAX: f64 = 3.0;
/// The tilts tried across the pass from the bottom's normal (degrees,
/// positive towards the flank): from 50 degrees away from the flank to 20
/// degrees towards it.
pub const ROOT_REST_TILTS: [f64; 8] = [-50.0, -40.0, -30.0, -20.0, -10.0, 0.0, 10.0, 20.0];
/// Bisection steps of the move towards the flank.
pub const ROOT_REST_BISECTIONS: usize = 7;
/// The cross-section sampled at each pair: points every [`ROOT_REST_CELL`]
/// mm from [`ROOT_REST_BACK_MAX`] behind the pair to [`ROOT_REST_SPAN`] mm
/// towards the flank, across the pass along the bottom, at heights from
/// [`ROOT_REST_LOW`] to [`ROOT_REST_HIGH`] mm over the bottom's tangent
/// plane: the band the bottom level's passes leave under an overhang.
pub const ROOT_REST_SPAN: f64 = 10.0;
/// See [`ROOT_REST_SPAN`] (mm).
pub const ROOT_REST_CELL: f64 = 0.5;
/// See [`ROOT_REST_SPAN`] (mm).
pub const ROOT_REST_LOW: f64 = 0.75;
/// See [`ROOT_REST_SPAN`] (mm).
pub const ROOT_REST_HIGH: f64 = 4.0;
/// A pair is kept where its tool covers at least this much of its
/// cross-section (mm^2) that no tool of the bottom level covered.
pub const ROOT_REST_MIN_AREA: f64 = 1.0;
/// Pairs whose nearest flank point lies along the pass (the cosine of its
/// direction with the tangent above this) are not moved: a corner or an open
/// end.
pub const ROOT_REST_ALONG: f64 = 0.7;
/// Runs of the rest pass shorter than this (mm) are left out: a retract and
/// an entry cost more than they cut.
pub const ROOT_REST_MIN_RUN: f64 = 5.0;
/// The bottom level's tools are taken every this many mm along their runs
/// (their CL points interpolated) when the rest pass measures what they
/// covered.
pub const ROOT_REST_SWEEP_STEP: f64 = 1.0;

/// Whether `q` lies inside the torus (R, r, flute length) placed at `p`.
#[must_use]
pub fn inside(p: &Placement, (radius, corner, flutes): (f64, f64, f64), q: &Point3) -> bool {
    let d = q - p.tip;
    let a = d.dot(&p.axis);
    if !(0.0..=flutes).contains(&a) {
        return false;
    }
    let rho = (d - p.axis * a).norm();
    if a >= corner {
        rho <= radius
    } else {
        let c = corner - a;
        rho <= radius - corner + (corner * corner - c * c).max(0.0).sqrt()
    }
}

/// The horizontal unit from `p` to the flank point nearest to it within
/// `within`, when that point lies across the pass (tangent `t`).
fn towards_flank(flanks: &MeshQuery, p: &Point3, t: &Vec3, within: f64) -> Option<Vec3> {
    let c = flanks.closest_within(p, within)?;
    let d = c.point - p;
    let h = Vec3::new(d.x, d.y, 0.0);
    let len = h.norm();
    if len < 1e-6 {
        return None;
    }
    let f = h / len;
    let th = Vec3::new(t.x, t.y, 0.0);
    let tl = th.norm();
    (tl < 1e-9 || (f.dot(&th) / tl).abs() < ROOT_REST_ALONG).then_some(f)
}

/// The tools that cut the bottom level so far, every
/// [`ROOT_REST_SWEEP_STEP`] along each run (tips and axes interpolated).
#[must_use]
pub fn swept(runs: &[Vec<Placement>]) -> Vec<Placement> {
    let mut out = Vec::new();
    for run in runs {
        for w in run.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            let n = ((b.tip - a.tip).norm() / ROOT_REST_SWEEP_STEP).ceil().max(1.0) as usize;
            for k in 0..n {
                let t = k as f64 / n as f64;
                let axis = (a.axis * (1.0 - t) + b.axis * t).try_normalize(1e-9).unwrap_or(a.axis);
                out.push(Placement { tip: a.tip + (b.tip - a.tip) * t, axis, ..*a });
            }
        }
        if let Some(last) = run.last() {
            out.push(*last);
        }
    }
    out
}

/// The rest pairs of a bottom limit pass `pairs` (as synchronised, every
/// `--step`), in runs of consecutive kept pairs. Each pair is moved across
/// the pass along the bottom, towards its nearest flank or back from it, and
/// its axis turned from the bottom's normal across the pass
/// ([`ROOT_REST_TILTS`]): for each tilt the move
/// nearest the flank at which `rest` (the tool with the flank allowance as
/// the flutes' clearance) is clear, the tool placed on the bottom; the tilt
/// whose tool covers the most of the pair's cross-section that the tools
/// `cut` did not cover, short of the flanks by the flank `allowance` (the
/// smallest tilt within a tenth of the best), is kept when that is at least
/// [`ROOT_REST_MIN_AREA`]. `tool` is (R, r, flute length).
#[must_use]
pub fn root_rest_pairs(
    placer: &Placer,
    rest: &BodyCheck,
    flanks: &MeshQuery,
    (pairs, cut): (&[SyncPoint], &[Placement]),
    tool: (f64, f64, f64),
    allowance: f64,
) -> Vec<Vec<SyncPoint>> {
    let (radius, _, flutes) = tool;
    let within = radius + ROOT_REST_SPAN;
    let columns = ((ROOT_REST_SPAN + ROOT_REST_BACK_MAX) / ROOT_REST_CELL).round() as usize;
    let rows = ((ROOT_REST_HIGH - ROOT_REST_LOW) / ROOT_REST_CELL).round() as usize;
    let cell_area = ROOT_REST_CELL * ROOT_REST_CELL;
    let moved: Vec<Option<SyncPoint>> = pairs
        .par_iter()
        .map(|s| {
            let f = towards_flank(flanks, &s.path, &s.tangent, within)?;
            // Across the pass, along the bottom.
            let along = (f - s.normal * f.dot(&s.normal)).try_normalize(1e-9)?;
            // The cross-section's points no tool of the bottom level covered.
            let reach = within + ROOT_REST_BACK_MAX + flutes.min(2.0 * radius);
            let near: Vec<&Placement> = cut.iter().filter(|p| (p.tip - s.path).norm() < reach).collect();
            // Columns from behind the pair towards the flank, up to the first
            // point within the allowance of a flank (beyond it lies the flank).
            let mut open: Vec<Point3> = Vec::new();
            'columns: for i in 0..=columns {
                let x = -ROOT_REST_BACK_MAX + ROOT_REST_CELL * i as f64;
                let column: Vec<Point3> = (0..=rows)
                    .map(|k| s.path + along * x + s.normal * (ROOT_REST_LOW + ROOT_REST_CELL * k as f64))
                    .collect();
                if column.iter().any(|q| flanks.closest_within(q, allowance).is_some()) {
                    break 'columns;
                }
                open.extend(column.into_iter().filter(|q| !near.iter().any(|p| inside(p, tool, q))));
            }
            if (open.len() as f64) * cell_area < ROOT_REST_MIN_AREA {
                return None;
            }
            let mut best: Option<(usize, f64, SyncPoint)> = None;
            for deg in ROOT_REST_TILTS {
                let a = deg.to_radians();
                let axis = s.normal * a.cos() + along * a.sin();
                let at =
                    |d: f64| placer.place(&(s.path + along * d), &axis).filter(|p| !rest.collides(&p.tip, &p.axis));
                let Some(mut good) = at(-ROOT_REST_BACK_MAX) else { continue };
                let (mut lo, mut hi) = (-ROOT_REST_BACK_MAX, ROOT_REST_REACH_MAX);
                let mut moved_by = lo;
                if let Some(p) = at(hi) {
                    good = p;
                    moved_by = hi;
                } else {
                    for _ in 0..ROOT_REST_BISECTIONS {
                        let mid = 0.5 * (lo + hi);
                        match at(mid) {
                            Some(p) => {
                                lo = mid;
                                good = p;
                                moved_by = mid;
                            }
                            None => hi = mid,
                        }
                    }
                }
                let covered = open.iter().filter(|q| inside(&good, tool, q)).count();
                let better = best
                    .as_ref()
                    .is_none_or(|b| 10 * covered > 11 * b.0 || (10 * covered >= 9 * b.0 && a.abs() < b.1.abs()));
                if better {
                    let pair = SyncPoint { path: s.path + along * moved_by, tilt: None, axis, ..*s };
                    best = Some((covered, a, pair));
                }
            }
            best.filter(|b| (b.0 as f64) * cell_area >= ROOT_REST_MIN_AREA).map(|b| b.2)
        })
        .collect();
    let mut runs: Vec<Vec<SyncPoint>> = Vec::new();
    let mut current: Vec<SyncPoint> = Vec::new();
    for m in moved {
        match m {
            Some(s) => current.push(s),
            None if current.len() >= 2 => runs.push(std::mem::take(&mut current)),
            None => current.clear(),
        }
    }
    if current.len() >= 2 {
        runs.push(current);
    }
    runs
}
