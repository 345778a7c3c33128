//! The engagement of a 3-axis program measured on the in-process stock (a
//! [`ZMap`]): the stock a roughing operation receives from the operations
//! before it, cut move by move as the program runs (docs/simulation.md,
//! "Engagement on the in-process stock").
//!
//! At each sample (every [`EngagementOptions::sample_step`] along the moves
//! that cut), the front half of the periphery is probed on a circle of radius
//! `rho = R - d` about the tool axis, at the height where the profile reaches
//! its full radius (the tip for a flat end mill, `r` above it for a bull-nose),
//! against the stock as the moves before the current one left it. `d` is half
//! a cell's diagonal, so a probed cell's centre lies within `R` of the tool
//! axis: the cells read are cells the current position cuts, never the
//! allowance beyond a wall the tool runs along. A probe is in material when
//! its cell's height is above the probe height by more than
//! [`ENGAGEMENT_FLOOR`].
//!
//! The front half of the true periphery lies beyond `R` from every earlier
//! position of a straight move, so it is exact to probe it before the move is
//! cut; the circle of radius `rho` is within `d` of it, and the z-map's cell
//! edges are within `d` of their centres: a straight cut at radial depth `ae`
//! reads `arccos(1 - ae / R)` within the angle `2 d` moves across the arc's
//! ends at its slope (about 2 degrees at `d = 0.07 mm`, `R = 3 mm`, 0.2 D), on
//! top of [`EngagementOptions::angle_bound`].

use rayon::prelude::*;
use scallop_cutter::Cutter;
use scallop_geom::{Point2, Vec2};
use scallop_toolpath::Toolpath;

use super::{EngagementOptions, EngagementReport, summarise, track};
use crate::tol::ENGAGEMENT_FLOOR;
use crate::{SimError, ZMap};

/// Measures the engagement of `path` (3-axis moves of `cutter`) on `stock`,
/// the material it starts from, against the `target` angle: the figures of
/// [`super::pocket_engagement`] but for the pocket's areas (left at 0; the
/// job's rest report measures the material left). `stock` is not changed:
/// the moves are cut into a copy as the measure goes.
///
/// # Errors
/// [`SimError::BadEngagement`] for a bad option or a cutter whose profile
/// never reaches its radius (none does), and the errors of [`ZMap::cut`].
///
/// ```
/// use scallop_cutter::{Cutter, CutterShape};
/// use scallop_geom::{Aabb3, Point3};
/// use scallop_sim::{EngagementOptions, ZMap, engagement_angle, stock_engagement};
/// use scallop_toolpath::{Move, MoveKind, Toolpath};
/// let p = |x, y, z| Point3::new(x, y, z);
/// let stock = ZMap::new(Aabb3 { min: p(0., 0., -5.), max: p(60., 40., 0.) }, 0.05).unwrap();
/// let flat = Cutter::new(CutterShape::Flat { radius: 3.0 }, 20.0).unwrap();
/// // A slot along y = 20, then a pass 1.2 mm beside it (0.2 D), both 2 mm deep.
/// let mut path = Toolpath::new(1000.0);
/// for (y, x1) in [(20.0, 50.0), (21.2, 44.0)] {
///     path.push(Move::new(MoveKind::Rapid, p(10.0, y, 5.0)));
///     path.push(Move::new(MoveKind::Plunge, p(10.0, y, -2.0)));
///     path.push(Move::new(MoveKind::Feed, p(x1, y, -2.0)));
///     path.push(Move::new(MoveKind::Retract, p(x1, y, 5.0)));
/// }
/// let target = engagement_angle(1.2, 3.0);
/// let r = stock_engagement(&stock, &flat, &path, target, &EngagementOptions::default()).unwrap();
/// assert!((r.move_phi[2] - std::f64::consts::PI).abs() < 0.01); // the slot
/// assert!((r.move_phi[6] - target).abs() < 2f64.to_radians()); // the side cut
/// ```
pub fn stock_engagement(
    stock: &ZMap,
    cutter: &Cutter,
    path: &Toolpath,
    target: f64,
    options: &EngagementOptions,
) -> Result<EngagementReport, SimError> {
    let shape = cutter.shape();
    let radius = shape.radius();
    options.check(radius)?;
    let lift = shape.profile_height();
    if !lift.is_finite() {
        return Err(SimError::BadEngagement { what: "cutter profile height", value: lift });
    }
    let (cx, cy) = stock.cell_size();
    let inset = 0.5 * cx.hypot(cy) * (1.0 + 1e-9);
    if inset >= radius {
        return Err(SimError::BadEngagement {
            what: "stock cell diagonal against the tool diameter",
            value: 2.0 * inset,
        });
    }
    let rho = radius - inset;
    // Its arcs as chord moves: a straight move's front half lies beyond R
    // of every earlier position of it (exact to probe before the move is
    // cut), an arc's does not where it turns.
    let (chorded, origin) = chord_moves(path);
    let path = &chorded;
    let track = track(path, radius, options);
    let mut zmap = stock.clone();
    let moves = path.moves();
    let half = options.angle_samples / 2;
    let step = std::f64::consts::PI / half as f64;
    let mut phi = Vec::with_capacity(track.samples.len());
    // Moves before `cut` are cut into `zmap`.
    let mut cut = 0usize;
    let mut k = 0;
    while k < track.samples.len() {
        let index = track.segments[track.samples[k].segment].index;
        let end = k + track.samples[k..].partition_point(|s| track.segments[s.segment].index == index);
        if cut < index {
            zmap.cut(cutter, &moves_between(path, cut, index))?;
            cut = index;
        }
        let view = &zmap;
        let angles: Vec<f64> = track.samples[k..end]
            .par_iter()
            .map(|s| {
                let from = track.segments[s.segment].a;
                let floor = s.z + lift + ENGAGEMENT_FLOOR;
                let probe = |theta: f64| material_above(view, s.at + Vec2::new(theta.cos(), theta.sin()) * rho, floor);
                if from == s.at {
                    // A vertical plunge: the half of the periphery with most material.
                    let probes: Vec<bool> = (0..2 * half).map(|j| probe((j as f64 + 0.5) * step)).collect();
                    return super::half_window_max(&probes) as f64 * step;
                }
                let heading = (s.at.y - from.y).atan2(s.at.x - from.x);
                let count = (0..half)
                    .filter(|&j| probe(heading - std::f64::consts::FRAC_PI_2 + (j as f64 + 0.5) * step))
                    .count();
                count as f64 * step
            })
            .collect();
        phi.extend(angles);
        k = end;
    }
    let mut report = summarise(path, &track, &phi, target, options);
    report.max_penetration = 0.0;
    debug_assert_eq!(report.move_phi.len(), moves.len());
    // Figures per move of the program as given.
    let mut move_phi = vec![0.0f64; origin.last().map_or(0, |&k| k + 1)];
    for (&k, &p) in origin.iter().zip(&report.move_phi) {
        move_phi[k] = move_phi[k].max(p);
    }
    report.move_phi = move_phi;
    report.max_at = report.max_at.map(|(at, k)| (at, origin[k]));
    Ok(report)
}

/// `path` with each XY arc move replaced by its chords within
/// [`crate::tol::ENGAGEMENT_ARC_SAGITTA`] (moves of the same kind), and for
/// each move of the result the index of the move of `path` it comes from.
fn chord_moves(path: &Toolpath) -> (Toolpath, Vec<usize>) {
    let moves = path.moves();
    let mut out = Toolpath::new(1000.0);
    let mut origin = Vec::with_capacity(moves.len());
    for (i, m) in moves.iter().enumerate() {
        match (i.checked_sub(1).map(|j| moves[j].to), path.arc(i)) {
            (Some(from), Some(arc)) => {
                for p in arc.chords(&from, &m.to, crate::tol::ENGAGEMENT_ARC_SAGITTA) {
                    out.push(scallop_toolpath::Move::new(m.kind, p));
                    origin.push(i);
                }
            }
            _ => {
                out.push(*m);
                origin.push(i);
            }
        }
    }
    (out, origin)
}

/// The moves `from..to` of `path` (arcs kept) as a toolpath that starts with a
/// rapid to where move `from - 1` ended (it sweeps only what that move swept).
fn moves_between(path: &Toolpath, from: usize, to: usize) -> Toolpath {
    let moves = path.moves();
    let mut part = Toolpath::new(1000.0);
    if from > 0 {
        part.push(scallop_toolpath::Move::new(scallop_toolpath::MoveKind::Rapid, moves[from - 1].to));
    }
    for (i, m) in moves.iter().enumerate().take(to).skip(from) {
        match path.arc(i) {
            Some(arc) => part.push_arc(*m, arc),
            None => part.push(*m),
        }
    }
    part
}

/// Whether the stock at `q` rises above `floor` (outside the grid: no stock).
fn material_above(zmap: &ZMap, q: Point2, floor: f64) -> bool {
    let box_ = zmap.stock();
    let (cx, cy) = zmap.cell_size();
    let (u, v) = ((q.x - box_.min.x) / cx, (q.y - box_.min.y) / cy);
    if !(u >= 0.0 && v >= 0.0) {
        return false;
    }
    // Non-negative and finite (checked above); cells far below 2^52.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let (i, j) = (u as usize, v as usize);
    zmap.height(i, j).is_some_and(|h| h > floor)
}
