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

use scallop_contour::{Contour, P2, Region};

use crate::{ClearOptions, Direction, RoughError, tol};

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
    plan_offset_in(region, None, options)
}

/// As [`plan_offset`], the material of the level being `material`: a ring
/// along which the tool never comes within R of it (less than
/// [`tol::AIR_RING_CHIP`] deep) cuts nothing and is left out. The ring of a
/// level's region around the stock's sides (the section grown by R) is one.
/// Leaving rings out keeps the links safe: the area the module documentation
/// counts as cleared by a ring left out holds no material.
///
/// # Errors
/// As [`plan_offset`].
pub fn plan_offset_in(
    region: &Region,
    material: Option<&Region>,
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
    let bands: Vec<Option<Region>> =
        (0..levels.len()).map(|k| levels.get(k + 1).map(|inner| inner.offset(-grow))).collect();
    // The passes of level 0 lie on the region's contour: grown a hair, the
    // region holds them.
    let holder = region.offset(-tol::LINK_GROW);
    let reach = material.map(|m| Reach::new(m, options.tool_radius, options.chord_tolerance));
    let mut steps = Vec::new();
    let mut pos: Option<P2> = None;
    for k in (0..levels.len()).rev() {
        let mut rings: Vec<&Contour> =
            levels[k].rings().iter().filter(|c| reach.as_ref().is_none_or(|m| m.touches(c))).collect();
        while !rings.is_empty() {
            let (i, ring) = nearest(&rings, pos, options.direction);
            rings.swap_remove(i);
            let Some(start) = ring.start() else { continue };
            if let Some(p) = pos {
                let down = bands[k].as_ref().is_some_and(|band| {
                    band.contains_segment(p, start, options.chord_tolerance)
                        && holder.contains_segment(p, start, options.chord_tolerance)
                });
                steps.push(Step::Link { tool_down: down, via: Vec::new(), cleared: false, to: None });
            }
            pos = Some(start);
            steps.push(Step::Cut(ring));
        }
    }
    Ok(steps)
}

/// Where a tool centre meets material: the material grown by R less
/// [`tol::AIR_RING_CHIP`].
struct Reach {
    grown: Region,
    bounds: Option<(P2, P2)>,
    /// Arcs are sampled as chords within this (mm).
    chord: f64,
}

impl Reach {
    fn new(material: &Region, radius: f64, chord: f64) -> Reach {
        let grown = material.offset(-(radius - tol::AIR_RING_CHIP).max(0.0));
        let bounds = grown.bounds();
        Reach { grown, bounds, chord }
    }

    /// Some point of `ring`, sampled every [`tol::AIR_RING_STEP`], lies in
    /// the grown material. Between two samples a straight stretch dips at
    /// most `s^2 / 8 rho` into a boundary of curvature radius rho (the
    /// material's corners grown by about R): under a micrometre at the step.
    fn touches(&self, ring: &Contour) -> bool {
        let Some((lo, hi)) = self.bounds else { return false };
        let points = ring.to_points(self.chord);
        let inside = |p: P2| p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1] && self.grown.contains(p);
        let mut prev: Option<P2> = points.last().copied().filter(|_| ring.is_closed());
        for &p in &points {
            if let Some(q) = prev {
                let d = (p[0] - q[0]).hypot(p[1] - q[1]);
                #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a short ring's samples")]
                let n = (d / tol::AIR_RING_STEP).ceil().max(1.0) as usize;
                #[allow(clippy::cast_precision_loss, reason = "small counts")]
                if (1..=n).any(|i| {
                    let f = i as f64 / n as f64;
                    inside([q[0] + f * (p[0] - q[0]), q[1] + f * (p[1] - q[1])])
                }) {
                    return true;
                }
            } else if inside(p) {
                return true;
            }
            prev = Some(p);
        }
        false
    }
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

/// The ring nearest `pos`, oriented for `direction` and started at its point
/// nearest `pos`. Climb milling with a clockwise spindle keeps the uncut
/// material on the tool's right: inside-out, that is the region's own
/// orientation (the material lies outside each ring's filled side).
fn nearest(rings: &[&Contour], pos: Option<P2>, direction: Direction) -> (usize, Contour) {
    let orient = |c: &Contour| match direction {
        Direction::Climb => c.clone(),
        Direction::Conventional => c.reversed(),
    };
    let Some(p) = pos else { return (0, orient(rings[0])) };
    let mut best: Option<(f64, usize, Contour)> = None;
    for (i, r) in rings.iter().enumerate() {
        let c = orient(r).starting_near(p);
        let s = c.start().unwrap_or(p);
        let d = (s[0] - p[0]).hypot(s[1] - p[1]);
        if best.as_ref().is_none_or(|b| d < b.0) {
            best = Some((d, i, c));
        }
    }
    best.map_or_else(|| (0, orient(rings[0])), |(_, i, c)| (i, c))
}
