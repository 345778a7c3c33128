//! Contour-parallel offset clearing of one tool-centre region.
//!
//! The region (where the tool centre may go) is eroded by the stepover ae
//! again and again: `levels[k]` is the region eroded by `k ae` (erosion by
//! discs composes, so each is the previous one eroded by ae). The rings of
//! each level are cut from the deepest level out (inside-out), so every pass
//! but the first of a branch has uncut material on one side only, about ae
//! wide, and the last pass (`k = 0`) is the contour of the region at the
//! allowance.
//!
//! Cleared area. When every ring of the levels above k has been cut, the
//! tool has swept every point within R of `levels[k + 1]` (a point of it is
//! within ae <= R of the deepest ring around it). A tool centre at distance
//! t from `levels[k + 1]` then meets uncut material at most `t - ae` deep,
//! so a link inside `levels[k + 1]` grown by `2 ae` engages no more than a
//! pass does: such links stay down at the cutting depth; any other is a
//! retract.

use scallop_contour::{Contour, P2, Region, Vertex};

use crate::{ClearOptions, Direction, RoughError, tol};

pub(crate) mod loops;

/// One step of a clearing plan in the plane.
#[derive(Debug, Clone)]
pub enum Step {
    /// A pass along the contour from its first vertex (a closed one back to
    /// it; adaptive clearing's open runs end at their last vertex).
    Cut(Contour),
    /// The move to the next cut's start: at the cutting depth through
    /// cleared area when `tool_down`, else by a retract.
    Link {
        /// Stays at the cutting depth.
        tool_down: bool,
        /// A tool-down link's points between the last cut's end and the next
        /// cut's start (empty: a straight move).
        via: Vec<P2>,
        /// The next cut starts where the tool cuts nothing: after a retract,
        /// a straight plunge there is enough (no helix).
        cleared: bool,
        /// Where the link was planned to end, when that is not the next
        /// cut's start: a run of adaptive clearing split at two moves in a
        /// row gives two links with no cut between them, the first ending
        /// where the second was planned from. `None`: the next cut's start.
        to: Option<P2>,
    },
}

/// The offset clearing of `region` (a tool-centre region): passes and links
/// (see the module documentation).
///
/// # Errors
/// [`RoughError::TooMuchWork`] beyond [`tol::MAX_PASSES`] levels.
pub fn plan_offset(region: &Region, options: &ClearOptions) -> Result<Vec<Step>, RoughError> {
    plan_offset_in(region, None, None, options)
}

/// As [`plan_offset`], the material of the level being `material`: a ring
/// along which the tool never comes within R of it (less than
/// [`tol::AIR_RING_CHIP`] deep) cuts nothing and is left out. The ring of a
/// level's region around the stock's sides (the section grown by R) is one.
/// Leaving rings out keeps the links safe: the area the module documentation
/// counts as cleared by a ring left out holds no material. A ring that meets
/// the material along part of its length is cut along those stretches
/// only. Tool-down links may also cross the air (the centres of `room`, else
/// of `region`, farther than R from the material): the tool cuts nothing
/// there.
///
/// # Errors
/// As [`plan_offset`].
pub fn plan_offset_in(
    region: &Region,
    material: Option<&Region>,
    room: Option<&Region>,
    options: &ClearOptions,
) -> Result<Vec<Step>, RoughError> {
    let ae = options.stepover;
    let mut levels = vec![region.clone()];
    loop {
        let next = erode(region, &levels, ae)?;
        if next.is_empty() {
            break;
        }
        if levels.len() >= tol::MAX_PASSES {
            return Err(RoughError::TooMuchWork { what: "offset passes", limit: tol::MAX_PASSES });
        }
        levels.push(next);
    }
    let grow = 2.0 * ae + tol::LINK_MARGIN_SHARE * ae;
    // The passes of level 0 lie on the region's contour: grown a hair, the
    // region holds them.
    let holder = region.offset(-tol::LINK_GROW);
    let tol_c = options.chord_tolerance;
    // The level's material and room as far as this region's tool reaches
    // (a level's many regions share them): its bounds grown by 2 R hold
    // every point within R of a centre and every straight link between two.
    let clip = region.bounds().map(|(lo, hi)| {
        let g = 2.0 * options.tool_radius + tol::LINK_GROW;
        let (lo, hi) = ([lo[0] - g, lo[1] - g], [hi[0] + g, hi[1] + g]);
        Region::from_polygons(&[vec![lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]]], false)
    });
    let clipped = |m: &Region| clip.as_ref().map_or_else(|| m.clone(), |c| m.intersection(c, tol_c));
    let material = material.map(clipped);
    let material = material.as_ref();
    let room = room.map(clipped);
    let room = room.as_ref();
    let reach = material.map(|m| Reach::new(m, options.tool_radius, tol_c));
    // Where the tool cuts nothing (beyond R of the material): a tool-down
    // link may cross it as well as the cleared bands.
    let room = room.map_or_else(|| holder.clone(), |r| r.offset(-tol::LINK_GROW).union(&holder, tol_c));
    let air = reach.as_ref().map(|m| room.difference(&m.grown, tol_c));
    let r = options.tool_radius;
    // The region with the air around it: where a ring's nearest boundary is
    // open (air), not a wall, its points lie deeper in this than their
    // level's depth. Without air every ring lies at its level's depth from
    // a wall: none is open.
    let open_region = air.as_ref().filter(|air| !air.is_empty()).map(|air| region.union(air, tol_c));
    let mut open_pieces: Vec<Vec<Piece>> = Vec::with_capacity(levels.len());
    let mut wall_pieces: Vec<Vec<Piece>> = Vec::with_capacity(levels.len());
    let mut has_open: Vec<bool> = Vec::with_capacity(levels.len());
    for k in 0..levels.len() {
        #[allow(clippy::cast_precision_loss, reason = "a small level count")]
        let depth = ae * k as f64 + tol::OPEN_SIDE_SHARE * ae;
        let deep_test = open_region.as_ref().map(|e| Banded::new(&e.offset(depth), tol_c));
        let step = reach.as_ref().map_or(tol::AIR_RING_STEP, |m| m.step);
        // A ring whose every point lies nearer the air than a wall is cut
        // from the air inwards: it meets the material as it is. Another is
        // cut inside-out: it meets what the deeper rings left.
        let rings: Vec<(Contour, bool)> = levels[k]
            .rings()
            .iter()
            .map(|ring| {
                let ring = refit(&orient(ring, options.direction), true, tol_c);
                let is_open = deep_test.as_ref().is_some_and(|deep| all_inside(&ring, deep, step, tol_c));
                (ring, is_open)
            })
            .collect();
        // The material left when the rings of the deeper levels are cut:
        // they swept every point within R of `levels[k + 1]` (the module
        // documentation; a sliver under the chip at that reach's edge is
        // counted as swept). Computed for the rings cut inside-out only.
        let left = match (material, levels.get(k + 1)) {
            (Some(m), Some(inner)) if rings.iter().any(|(_, o)| !o) => {
                Some(Reach::new(&m.difference(&inner.offset(-(r + tol::AIR_RING_CHIP)), tol_c), r, tol_c))
            }
            _ => None,
        };
        let left = left.as_ref().or(reach.as_ref());
        let (mut open, mut wall) = (Vec::new(), Vec::new());
        for (ring, is_open) in rings {
            let by = if is_open { reach.as_ref() } else { left };
            let pieces = match by {
                None => vec![Piece { contour: ring, closed: true, from_air: false, to_air: false }],
                Some(m) => m.pieces(&ring, r),
            };
            if is_open {
                open.extend(pieces.into_iter().map(Piece::reversed));
            } else {
                wall.extend(pieces);
            }
        }
        // Links of the open side: through the air, or along the band a
        // stepover wide inside the level's ring on the open side (swept by
        // it: a link there engages no more than a pass). Computed for the
        // levels with such rings only.
        has_open.push(!open.is_empty());
        open_pieces.push(open);
        wall_pieces.push(wall);
    }
    let mut steps = Vec::new();
    let mut pos: Option<P2> = None;
    // Outside-in from the air first (each pass then has its uncut material
    // on the inner side only, ae wide: no slot), then inside-out to the walls.
    // The open side, outside-in: a piece is cut once the pieces a stepover
    // outside it (its parents) are, the nearest such piece first, so a
    // corner is cleared level after level before the tool moves on.
    let mut open: Vec<(usize, Piece, Vec<P2>)> = Vec::new();
    for (k, pieces) in open_pieces.into_iter().enumerate() {
        for piece in pieces {
            let points = piece.contour.to_points(tol_c);
            open.push((k, piece, points));
        }
    }
    let near = |q: P2, points: &[P2]| {
        points.windows(2).any(|w| segment_distance(q, w[0], w[1]) <= ae * (1.0 + 2.0 * tol::LINK_MARGIN_SHARE))
    };
    let parents: Vec<Vec<usize>> = open
        .iter()
        .map(|(k, _, points)| {
            let probes: Vec<P2> =
                [0, points.len() / 4, points.len() / 2, 3 * points.len() / 4, points.len().saturating_sub(1)]
                    .iter()
                    .filter_map(|&i| points.get(i).copied())
                    .collect();
            (0..open.len()).filter(|&j| open[j].0 + 1 == *k && probes.iter().any(|&q| near(q, &open[j].2))).collect()
        })
        .collect();
    // Links of the open side: through the air, or along the band a
    // stepover wide inside the level's ring on the open side (swept by it: a
    // link there engages no more than a pass). Computed for the levels with
    // such rings only, when a link first needs it.
    let strips: Vec<std::cell::OnceCell<Option<Region>>> =
        (0..levels.len()).map(|_| std::cell::OnceCell::new()).collect();
    let strip = |k: usize| -> Option<&Region> {
        let cell = strips.get(k)?;
        cell.get_or_init(|| {
            open_region.as_ref().filter(|_| has_open[k]).map(|e| {
                #[allow(clippy::cast_precision_loss, reason = "a small level count")]
                let open_side = e.offset(ae * k as f64);
                let inner = levels[k].offset(ae * (1.0 + tol::LINK_MARGIN_SHARE));
                levels[k].offset(-tol::LINK_GROW).difference(&inner, tol_c).intersection(&open_side, tol_c)
            })
        })
        .as_ref()
    };
    let mut done = vec![false; open.len()];
    let mut last: Option<usize> = None;
    loop {
        let ready: Vec<usize> = (0..open.len()).filter(|&i| !done[i] && parents[i].iter().all(|&j| done[j])).collect();
        if ready.is_empty() {
            break;
        }
        let candidates: Vec<Piece> = ready.iter().map(|&i| open[i].1.clone()).collect();
        let (c, cut) = nearest(&candidates, pos);
        let i = ready[c];
        done[i] = true;
        let (k, piece) = (open[i].0, &open[i].1);
        let Some(start) = cut.start() else { continue };
        // Cleared for links: the air, and the band inside the level of the
        // piece just cut when this one is its child (a stepover inside it).
        let child = last.is_some_and(|l| parents[i].contains(&l));
        let lead = || k.checked_sub(1).and_then(strip);
        match pos {
            Some(p) => {
                let length = (start[0] - p[0]).hypot(start[1] - p[1]);
                let short = || length <= ae && holder.contains_segment(p, start, tol_c);
                let in_air = || air.as_ref().is_some_and(|air| air.contains_segment(p, start, tol_c));
                let along =
                    || child && length <= 4.0 * r && lead().is_some_and(|band| band.contains_segment(p, start, tol_c));
                if short() || in_air() || along() {
                    steps.push(Step::Link { tool_down: true, via: Vec::new(), cleared: false, to: None });
                } else {
                    push_entry(&mut steps, start, piece.from_air, air.as_ref(), lead, &holder, ae, tol_c);
                }
            }
            None => push_entry(&mut steps, start, piece.from_air, air.as_ref(), lead, &holder, ae, tol_c),
        }
        last = Some(i);
        pos = cut.end().or(Some(start));
        steps.push(Step::Cut(cut));
    }
    // The walls, inside-out. Where a ring's inner side meets material the
    // deeper rings did not sweep (a slot), it is cut with loops.
    let target = (1.0 - (ae / r).min(2.0)).acos();
    let climb = matches!(options.direction.rings(), Direction::Climb);
    let with_loops = matches!(options.pattern, crate::Pattern::OffsetLoops);
    let mut looper = with_loops.then(|| loops::Looper::new(region, None, r, climb, target, tol_c));
    // The last wall ring cut, when closed (a transition leaves it).
    let mut last_ring: Option<Contour> = None;
    for k in (0..levels.len()).rev() {
        let mut pieces = std::mem::take(&mut wall_pieces[k]);
        if let Some(looper) = looper.as_mut().filter(|_| !pieces.is_empty()) {
            looper.set_deeper(levels.get(k + 1));
        }
        // A band may reach past the region: it is kept inside. It holds
        // when every deeper ring is cut (the open side's are).
        // Computed when a link that is not short first needs it.
        let safe = std::cell::OnceCell::new();
        let safe = || {
            safe.get_or_init(|| {
                let band = levels.get(k + 1).map(|inner| inner.offset(-grow).intersection(&holder, tol_c));
                match (band, &air) {
                    (Some(band), Some(air)) => Some(band.union(air, tol_c)),
                    (Some(band), None) => Some(band),
                    (None, Some(air)) => Some(air.clone()),
                    (None, None) => None,
                }
            })
        };
        while !pieces.is_empty() {
            let (i, cut) = nearest(&pieces, pos);
            let piece = pieces.swap_remove(i);
            let cut = match looper.as_mut() {
                Some(looper) => looper.looped(&cut),
                None => cut,
            };
            // From the ring just cut into this one, ae out, without a stop:
            // a transition that leaves the last ring along it and reaches
            // this one tangentially (docs/roughing.md, "Offset clearing",
            // transitions).
            let (cut, ring) = match (&last_ring, pos) {
                (Some(prev), Some(p)) if cut.is_closed() => {
                    match transition(prev, &cut, p, ae, r, target, climb, tol_c, &holder) {
                        Some((way, ring)) => (way, Some(ring)),
                        None => (cut.clone(), Some(cut)),
                    }
                }
                _ => (cut.clone(), Some(cut).filter(Contour::is_closed)),
            };
            last_ring = ring;
            let Some(start) = cut.start() else { continue };
            match pos {
                Some(p) => {
                    // A link no longer than ae from where the tool cut
                    // engages no more than a pass does.
                    let short =
                        (start[0] - p[0]).hypot(start[1] - p[1]) <= ae && holder.contains_segment(p, start, tol_c);
                    let down = short || safe().as_ref().is_some_and(|safe| safe.contains_segment(p, start, tol_c));
                    steps.push(Step::Link { tool_down: down, via: Vec::new(), cleared: piece.from_air, to: None });
                }
                None if piece.from_air => {
                    // The first cut starts where the tool cuts nothing: a
                    // straight plunge there, no helix.
                    steps.push(Step::Link { tool_down: false, via: Vec::new(), cleared: true, to: None });
                }
                None => {}
            }
            pos = cut.end().or(Some(start));
            steps.push(Step::Cut(cut));
        }
    }
    Ok(steps)
}

/// The transition from the closed ring `prev`, cut last and starting (and
/// ending) at `p`, into the closed ring `next` lying `ae` outside it: the
/// tool goes on along `prev` and moves out, its heading turning away from
/// the ring by at most a radian per R of path (no corner where it leaves
/// `prev`) and by no more than the engagement allows, to `next` at `s = L`
/// (met at the angle the bound allows there, a degree or two), then around
/// `next` back to that point. The result is the cut from `p`
/// (the transition's points, then `next` from where it was reached) and
/// `next` starting there.
///
/// The way keeps the engagement within [`tol::TRANSITION_ENGAGEMENT`] x
/// `target`, or [`tol::TRANSITION_OVER`] x `target` above the ring's own
/// where its curvature takes that higher: moving out at an angle `beta` to
/// the band, `d` deep of its `ae`, the front half of the periphery meets the
/// band over `beta` more than moving along it (`arccos(1 - d / R)` on a
/// straight band), so `beta` may be at most `phi - engagement(d)` (less
/// [`tol::TRANSITION_MARGIN`] of it).
///
/// `None` (a straight link instead) where either ring turns by more than [`tol::TRANSITION_TURN`]
/// between chords along the way, where `next` is not `ae` outside `prev`
/// there (a ring of another branch), or where the way leaves `holder`.
#[allow(clippy::too_many_arguments, reason = "the rings and the cut's figures")]
fn transition(
    prev: &Contour,
    next: &Contour,
    p: P2,
    ae: f64,
    r: f64,
    target: f64,
    climb: bool,
    tol_c: f64,
    holder: &Region,
) -> Option<(Contour, Contour)> {
    let pts = prev.to_points(tol_c);
    let side = if climb { 1.0 } else { -1.0 };
    // The ring's curvature towards its inner side along the way (a ring
    // turning that way meets more of its band: `engaged`), 0 where it turns
    // the other way (less: the straight band's figure holds).
    let bend = {
        let (mut turn, mut run) = (0.0, 0.0);
        for w in pts.windows(3) {
            let (u, v) = ([w[1][0] - w[0][0], w[1][1] - w[0][1]], [w[2][0] - w[1][0], w[2][1] - w[1][1]]);
            turn += (u[0] * v[1] - u[1] * v[0]).atan2(u[0] * v[0] + u[1] * v[1]);
            run += u[0].hypot(u[1]);
            if run > tol::TRANSITION_BEND_SHARE * r {
                break;
            }
        }
        if run > 0.0 { (side * turn / run).max(0.0) } else { 0.0 }
    };
    // The engagement `d` deep into the band moving along it: the arc of the
    // front half beyond the last ring's swept boundary (a circle of radius
    // `rho + R` about the ring's centre of curvature, the tool `rho + d`
    // from it; straight, `arccos(1 - d / R)`).
    let engaged = |d: f64| -> f64 {
        let c = if bend > 0.0 {
            let rho = 1.0 / bend;
            let t = rho + d;
            ((rho + r).powi(2) - t * t - r * r) / (2.0 * t * r)
        } else {
            1.0 - d / r
        };
        c.clamp(-1.0, 1.0).acos()
    };
    // The bound: the target's share, or a little above the ring's own
    // engagement where its curvature takes it higher.
    let phi = (tol::TRANSITION_ENGAGEMENT * target).max(engaged(ae) + tol::TRANSITION_OVER * target);
    // The depth along the way: the heading's angle to the ring turns out at
    // most one radian per R of path and stays within the bound less the
    // margin (moving out at `beta`, the band meets the front half over
    // `beta` more than along it).
    let ds = tol::TRANSITION_STEP_SHARE * r / 4.0;
    let (mut along, mut d, mut beta) = (0.0f64, 0.0f64, 0.0f64);
    let mut profile: Vec<(f64, f64)> = vec![(0.0, 0.0)];
    while d < ae {
        let bound = (phi - engaged(d)) * (1.0 - tol::TRANSITION_MARGIN);
        if bound <= 0.0 || profile.len() > tol::TRANSITION_MAX_STEPS {
            return None;
        }
        beta = (beta + ds / r).min(bound);
        d = (d + ds * beta.sin()).min(ae);
        along += ds * beta.cos();
        profile.push((along, d));
    }
    let l = along;
    let depth = |s: f64| -> f64 {
        let k = profile.partition_point(|q| q.0 < s).clamp(1, profile.len() - 1);
        let ((s0, d0), (s1, d1)) = (profile[k - 1], profile[k]);
        if s1 > s0 { d0 + (d1 - d0) * ((s - s0) / (s1 - s0)).clamp(0.0, 1.0) } else { d1 }
    };
    if pts.len() < 3 || prev.start().is_none_or(|s| (s[0] - p[0]).hypot(s[1] - p[1]) > tol_c) {
        return None;
    }
    if prev.length() < 4.0 * l || next.length() < 4.0 * l {
        return None;
    }
    let smooth = |q: &[P2], upto: f64| -> bool {
        let mut run = 0.0;
        for w in q.windows(3) {
            let (u, v) = ([w[1][0] - w[0][0], w[1][1] - w[0][1]], [w[2][0] - w[1][0], w[2][1] - w[1][1]]);
            let turn = (u[0] * v[1] - u[1] * v[0]).atan2(u[0] * v[0] + u[1] * v[1]).abs();
            if turn > tol::TRANSITION_TURN {
                return false;
            }
            run += u[0].hypot(u[1]);
            if run > upto {
                break;
            }
        }
        true
    };
    let reach = l + 2.0 * ae;
    if !smooth(&pts, reach) || !smooth(&next.to_points(tol_c), reach) {
        return None;
    }
    // Points every share of R along `prev`, with their unit tangents.
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small positive count")]
    let m = ((l / (tol::TRANSITION_STEP_SHARE * r)).ceil() as usize).max(8);
    let mut out: Vec<P2> = vec![p];
    let (mut k, mut done) = (0usize, 0.0f64);
    let next_pts = next.to_points(tol_c);
    let on_next = |q: P2| -> f64 {
        next_pts
            .windows(2)
            .map(|w| {
                let (a, b) = (w[0], w[1]);
                let ab = [b[0] - a[0], b[1] - a[1]];
                let len2 = ab[0] * ab[0] + ab[1] * ab[1];
                let t = if len2 > 0.0 {
                    (((q[0] - a[0]) * ab[0] + (q[1] - a[1]) * ab[1]) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (q[0] - a[0] - t * ab[0]).hypot(q[1] - a[1] - t * ab[1])
            })
            .fold(f64::INFINITY, f64::min)
    };
    for j in 1..=m {
        #[allow(clippy::cast_precision_loss, reason = "a small count")]
        let s = l * j as f64 / m as f64;
        while k + 1 < pts.len() && done + (pts[k + 1][0] - pts[k][0]).hypot(pts[k + 1][1] - pts[k][1]) < s {
            done += (pts[k + 1][0] - pts[k][0]).hypot(pts[k + 1][1] - pts[k][1]);
            k += 1;
        }
        if k + 1 >= pts.len() {
            return None;
        }
        let (a, b) = (pts[k], pts[k + 1]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        if len <= 0.0 {
            return None;
        }
        let t = [(b[0] - a[0]) / len, (b[1] - a[1]) / len];
        let f = (s - done) / len;
        let at = [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])];
        let n = [side * t[1], -side * t[0]];
        let d = if j == m { ae } else { depth(s) };
        let q = [at[0] + d * n[0], at[1] + d * n[1]];
        if j == m && on_next(q) > tol::TRANSITION_FIT_SHARE * ae + 2.0 * tol_c {
            // `next` is not `ae` outside `prev` here.
            return None;
        }
        out.push(q);
    }
    let ring = next.starting_near(*out.last()?);
    let start = ring.start()?;
    *out.last_mut()? = start;
    if !out.windows(2).all(|w| holder.contains_segment(w[0], w[1], tol_c)) {
        return None;
    }
    let mut v: Vec<Vertex> = out[..out.len() - 1].iter().map(|q| Vertex { x: q[0], y: q[1], bulge: 0.0 }).collect();
    v.extend(ring.vertices());
    v.push(Vertex { x: start[0], y: start[1], bulge: 0.0 });
    Some((Contour::new(&v, false).ok()?, ring))
}

/// The entry of an open side's piece from above at `start`: a straight
/// plunge where the tool cuts nothing there (`from_air`), else a plunge in
/// the air or the cleared band `lead` beside it and a move in (a retract
/// with a helix when there is neither).
#[allow(clippy::too_many_arguments, reason = "the entry's context")]
fn push_entry<'a>(
    steps: &mut Vec<Step>,
    start: P2,
    from_air: bool,
    air: Option<&Region>,
    lead: impl FnOnce() -> Option<&'a Region>,
    holder: &Region,
    ae: f64,
    tol_c: f64,
) {
    if from_air {
        steps.push(Step::Link { tool_down: false, via: Vec::new(), cleared: true, to: None });
        return;
    }
    let clear = match (air, lead()) {
        (Some(a), Some(l)) => Some(a.union(l, tol_c)),
        (Some(a), None) => Some(a.clone()),
        (None, Some(l)) => Some(l.clone()),
        (None, None) => None,
    };
    match clear.as_ref().and_then(|c| lead_in(start, c, holder, ae, tol_c)) {
        Some(a) => {
            steps.push(Step::Link { tool_down: false, via: Vec::new(), cleared: true, to: Some(a) });
            steps.push(Step::Link { tool_down: true, via: Vec::new(), cleared: false, to: None });
        }
        None => steps.push(Step::Link { tool_down: false, via: Vec::new(), cleared: false, to: None }),
    }
}

/// Distance from `q` to the segment `a b`.
fn segment_distance(q: P2, a: P2, b: P2) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 { (((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (q[0] - a[0] - t * dx).hypot(q[1] - a[1] - t * dy)
}

/// A point of `air` within a few stepovers of `s` from which a straight
/// move to `s` stays in the air or the region (`holder`): the nearest of 16
/// directions at 1 to 4 ae.
fn lead_in(s: P2, air: &Region, holder: &Region, ae: f64, tol_c: f64) -> Option<P2> {
    let both = std::cell::OnceCell::new();
    (1..=4).find_map(|m| {
        (0..16).find_map(|i| {
            let a = std::f64::consts::PI * f64::from(i) / 8.0;
            let d = ae * f64::from(m);
            let q = [s[0] + d * a.cos(), s[1] + d * a.sin()];
            let inside = |r: &Region| r.contains_segment(q, s, tol_c);
            (air.contains(q)
                && (inside(air) || inside(holder) || inside(both.get_or_init(|| air.union(holder, tol_c)))))
            .then_some(q)
        })
    })
}

/// Point tests against a region whose rings are cut into horizontal bands:
/// the winding number of a point sums the edges of its band that cross its
/// height to its right (arcs as chords within the given tolerance).
struct Banded {
    /// Per band: the edges `(a, b)` that meet its height range.
    bands: Vec<Vec<(P2, P2)>>,
    y0: f64,
    dy: f64,
}

impl Banded {
    fn new(region: &Region, chord: f64) -> Banded {
        let rings: Vec<Vec<P2>> = region.rings().iter().map(|r| r.to_points(chord)).collect();
        let edges: Vec<(P2, P2)> = rings
            .iter()
            .flat_map(|r| (0..r.len()).map(move |i| (r[i], r[(i + 1) % r.len()])))
            .filter(|(a, b)| a[1] != b[1])
            .collect();
        let (y0, y1) = edges.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (a, b)| {
            (lo.min(a[1]).min(b[1]), hi.max(a[1]).max(b[1]))
        });
        #[allow(clippy::cast_precision_loss, reason = "an edge count")]
        let count = ((edges.len() as f64).sqrt().ceil()).clamp(1.0, 4096.0);
        let dy = if y1 > y0 { (y1 - y0) / count } else { 1.0 };
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "at most 4096 bands")]
        let mut bands = vec![Vec::new(); count as usize];
        let last = bands.len() - 1;
        let band = |y: f64| -> usize {
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "clamped to the bands")]
            let k = ((y - y0) / dy).floor().max(0.0) as usize;
            k.min(last)
        };
        for &(a, b) in &edges {
            for k in band(a[1].min(b[1]))..=band(a[1].max(b[1])) {
                bands[k].push((a, b));
            }
        }
        Banded { bands, y0, dy }
    }

    /// `p` is inside (winding number above 0), as `Region::contains`.
    fn contains(&self, p: P2) -> bool {
        if !(p[1] >= self.y0) {
            return false;
        }
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a band index")]
        let k = ((p[1] - self.y0) / self.dy).floor() as usize;
        let Some(edges) = self.bands.get(k) else { return false };
        let mut winding = 0i32;
        for &(a, b) in edges {
            let up = a[1] <= p[1] && b[1] > p[1];
            let down = b[1] <= p[1] && a[1] > p[1];
            if up || down {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if x > p[0] {
                    winding += if up { 1 } else { -1 };
                }
            }
        }
        winding > 0
    }
}
/// Every point of the closed `ring`, sampled every `step` (arcs as chords
/// within `chord`), lies in `deep`.
fn all_inside(ring: &Contour, deep: &Banded, step: f64, chord: f64) -> bool {
    let vertices = ring.to_points(chord);
    (0..vertices.len()).all(|i| {
        let (p, q) = (vertices[i], vertices[(i + 1) % vertices.len()]);
        let d = (q[0] - p[0]).hypot(q[1] - p[1]);
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a ring's samples")]
        let n = (d / step).ceil().max(1.0) as usize;
        (0..n).all(|j| {
            #[allow(clippy::cast_precision_loss, reason = "small counts")]
            let f = j as f64 / n as f64;
            deep.contains([p[0] + f * (q[0] - p[0]), p[1] + f * (q[1] - p[1])])
        })
    })
}

/// A ring to cut, or the stretch of one that reaches the material.
#[derive(Clone)]
struct Piece {
    /// Oriented for the milling direction.
    contour: Contour,
    /// A closed ring, which may be started anywhere; else an open stretch,
    /// cut from its first point.
    closed: bool,
    /// The open stretch starts where the tool cuts nothing.
    from_air: bool,
    /// The open stretch ends where the tool cuts nothing.
    to_air: bool,
}

impl Piece {
    /// The piece run the other way.
    fn reversed(self) -> Piece {
        Piece { contour: self.contour.reversed(), closed: self.closed, from_air: self.to_air, to_air: self.from_air }
    }
}

/// Where a tool centre meets material: the material grown by R less
/// [`tol::AIR_RING_CHIP`].
struct Reach {
    grown: Region,
    /// `grown` for point tests.
    tester: Banded,
    bounds: Option<(P2, P2)>,
    /// Arcs are sampled as chords within this (mm).
    chord: f64,
    /// Samples along a ring at most this far apart (mm).
    step: f64,
}

impl Reach {
    /// Between two samples `s` apart a straight stretch dips at most
    /// `s^2 / 8 rho` into a boundary of curvature radius rho (the material's
    /// corners grown by R less the chip): the samples lie close enough for
    /// half the chip.
    fn new(material: &Region, radius: f64, chord: f64) -> Reach {
        let rho = (radius - tol::AIR_RING_CHIP).max(0.0);
        let grown = material.offset(-rho);
        let bounds = grown.bounds();
        let step = (4.0 * rho * tol::AIR_RING_CHIP).sqrt().clamp(tol::AIR_RING_STEP, radius.max(tol::AIR_RING_STEP));
        let tester = Banded::new(&grown, chord);
        Reach { grown, tester, bounds, chord, step }
    }

    fn inside(&self, p: P2) -> bool {
        self.bounds.is_some_and(|(lo, hi)| {
            p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && self.tester.contains(p)
        })
    }

    /// The stretches of the closed `ring` to cut: the whole ring when the
    /// tool meets material all along it, none when nowhere, else the open
    /// stretches that reach it, each one sample longer at both ends, joined
    /// across gaps of air shorter than [`tol::AIR_RUN_GAP_SHARE`] R (cutting
    /// through such a gap costs less than a link).
    fn pieces(&self, ring: &Contour, radius: f64) -> Vec<Piece> {
        let mut samples: Vec<P2> = Vec::new();
        let vertices = ring.to_points(self.chord);
        for (i, &p) in vertices.iter().enumerate() {
            let q = vertices[(i + 1) % vertices.len()];
            let d = (q[0] - p[0]).hypot(q[1] - p[1]);
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a ring's samples")]
            let n = (d / self.step).ceil().max(1.0) as usize;
            for j in 0..n {
                #[allow(clippy::cast_precision_loss, reason = "small counts")]
                let f = j as f64 / n as f64;
                samples.push([p[0] + f * (q[0] - p[0]), p[1] + f * (q[1] - p[1])]);
            }
        }
        let n = samples.len();
        let touch: Vec<bool> = samples.iter().map(|&p| self.inside(p)).collect();
        let (first_air, joined) = match ring_runs(&samples, &touch, tol::AIR_RUN_GAP_SHARE * radius) {
            RingRuns::Whole => {
                return vec![Piece { contour: ring.clone(), closed: true, from_air: false, to_air: false }];
            }
            RingRuns::Nowhere => return Vec::new(),
            RingRuns::Runs { first_air, runs } => (first_air, runs),
        };
        let at = |i: usize| samples[(first_air + i) % n];
        let hit = |i: usize| touch[(first_air + i) % n];
        joined
            .into_iter()
            .filter_map(|(a, b)| {
                // One sample into the air at each end.
                let points: Vec<P2> = (a.saturating_sub(1)..=b + 1).map(at).collect();
                let contour = Contour::from_points(&points, false, tol::RING_ARC_FIT_SHARE * self.chord).ok()?;
                Some(Piece { contour, closed: false, from_air: !hit(a.saturating_sub(1)), to_air: !hit(b + 1) })
            })
            .collect()
    }
}

/// Where a closed ring's samples `hit` (the tool meets material or the
/// region there, `samples` their points, equally spaced).
pub(crate) enum RingRuns {
    /// All round, or but for gaps of air shorter than the gap: the whole ring.
    Whole,
    /// Nowhere: no piece of it.
    Nowhere,
    /// Runs `(a, b)` of sample indices counted from the air sample
    /// `first_air` (`b` may pass the sample count where the last run joins
    /// the first across the ring's start), joined across gaps shorter than
    /// the gap.
    Runs { first_air: usize, runs: Vec<(usize, usize)> },
}

/// The stretches of a closed ring whose samples `hit`, joined across gaps of
/// air shorter than `gap` (mm, along the samples).
pub(crate) fn ring_runs(samples: &[P2], hit: &[bool], gap: f64) -> RingRuns {
    let n = samples.len();
    let Some(first_air) = hit.iter().position(|h| !h) else { return RingRuns::Whole };
    if !hit.iter().any(|&h| h) {
        return RingRuns::Nowhere;
    }
    let at = |i: usize| samples[(first_air + i) % n];
    let on = |i: usize| hit[(first_air + i) % n];
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < n {
        if !on(i) {
            i += 1;
            continue;
        }
        let a = i;
        while i < n && on(i) {
            i += 1;
        }
        runs.push((a, i - 1));
    }
    // Join runs across short gaps (the last one to the first across the
    // ring's start, when the ring closes through air shorter than the gap).
    let length = |a: usize, b: usize| -> f64 {
        (a..b)
            .map(|j| {
                let (p, q) = (at(j), at(j + 1));
                (q[0] - p[0]).hypot(q[1] - p[1])
            })
            .sum()
    };
    let mut joined: Vec<(usize, usize)> = Vec::new();
    for run in runs {
        match joined.last_mut() {
            Some(last) if length(last.1, run.0) < gap => last.1 = run.1,
            _ => joined.push(run),
        }
    }
    if joined.len() > 1 {
        let (first, last) = (joined[0], joined[joined.len() - 1]);
        if length(last.1, first.0 + n) < gap {
            joined[0] = (last.0, first.1 + n);
            joined.pop();
        }
    }
    if joined.len() == 1 && length(joined[0].1, joined[0].0 + n) < gap {
        return RingRuns::Whole;
    }
    RingRuns::Runs { first_air, runs: joined }
}

/// The last of `levels` (the erosions of `region` by 0, ae, 2 ae, ...)
/// eroded by `ae` once more. The offset kernel now and then loses rings (the
/// fitting pocket's z = 22 level eroded to nothing after one pass, and its
/// inside went uncut under a rapid, docs/rough5.md "Baselines"), so the result is
/// checked: erosion by `d` removes some area and at most `P d + pi d^2 h` of a region of
/// perimeter P with h holes (the inner parallel curves of a ring are no
/// longer than it, each hole's by at most `2 pi d`). A result that lost more
/// is computed again from `region` by the whole depth, then by a distance
/// [`tol::OFFSET_RETRY`] shorter or longer.
///
/// # Errors
/// [`RoughError::Offset`] when every attempt lost too much.
fn erode(region: &Region, levels: &[Region], ae: f64) -> Result<Region, RoughError> {
    let last = &levels[levels.len() - 1];
    let perimeter: f64 = last.rings().iter().map(Contour::length).sum();
    let holes = last.rings().iter().filter(|r| !r.is_ccw()).count();
    #[allow(clippy::cast_precision_loss, reason = "small counts")]
    let (depth, holes) = (ae * levels.len() as f64, holes as f64);
    let most = perimeter * ae + std::f64::consts::PI * ae * ae * holes + tol::OFFSET_AREA_SLACK * last.area();
    (0..4)
        .map(|attempt| match attempt {
            0 => last.offset(ae),
            1 => region.offset(depth),
            2 => last.offset(ae * (1.0 - tol::OFFSET_RETRY)),
            _ => last.offset(ae * (1.0 + tol::OFFSET_RETRY)),
        })
        .find(|next| (0.0..=most).contains(&(last.area() - next.area())))
        .ok_or(RoughError::Offset { distance: depth })
}

/// `c` oriented for `direction`. Climb milling with a clockwise spindle
/// keeps the uncut material on the tool's right: inside-out, that is the
/// region's own orientation (the material lies outside each ring's filled
/// side).
fn orient(c: &Contour, direction: Direction) -> Contour {
    match direction.rings() {
        Direction::Conventional => c.reversed(),
        Direction::Climb | Direction::Both => c.clone(),
    }
}

/// `c` as the fewest lines and arcs within [`tol::RING_ARC_FIT_SHARE`] of
/// the chord tolerance `chord` (its arcs read as chords within a tenth of
/// that first): the offsets of a level's region keep its boundary's dense
/// polygon, whose short moves a jerk-limited controller cannot run at the
/// feed (docs/roughing.md, "Offset clearing"). `c` itself when no fit is
/// found.
fn refit(c: &Contour, closed: bool, chord: f64) -> Contour {
    let fit = tol::RING_ARC_FIT_SHARE * chord;
    Contour::from_points(&c.to_points(0.1 * fit), closed, fit).unwrap_or_else(|_| c.clone())
}

/// The piece whose start is nearest `pos` (a closed ring started at its
/// point nearest `pos`; an open stretch at its first point).
fn nearest(pieces: &[Piece], pos: Option<P2>) -> (usize, Contour) {
    let Some(p) = pos else { return (0, pieces[0].contour.clone()) };
    let mut best: Option<(f64, usize, Contour)> = None;
    for (i, piece) in pieces.iter().enumerate() {
        let c = if piece.closed { piece.contour.starting_near(p) } else { piece.contour.clone() };
        let s = c.start().unwrap_or(p);
        let d = (s[0] - p[0]).hypot(s[1] - p[1]);
        if best.as_ref().is_none_or(|b| d < b.0) {
            best = Some((d, i, c));
        }
    }
    best.map_or_else(|| (0, pieces[0].contour.clone()), |(_, i, c)| (i, c))
}
