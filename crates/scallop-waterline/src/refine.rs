//! Bisection on the exact drop-cutter, and the adaptive splitting of chords.

use rayon::prelude::*;
use scallop_cutter::{Cutter, drop_cutter};
use scallop_geom::{Point2, Vec2};
use scallop_mesh::MeshIndex;

use crate::{Loop, tol};

/// The side test at one height: is the cutter with its tip at `z` cutting
/// into the part at (x, y)?
pub(crate) struct Probe<'a> {
    pub(crate) cutter: &'a Cutter,
    pub(crate) index: &'a MeshIndex,
    pub(crate) z: f64,
    /// Width of the final bisection bracket.
    pub(crate) tolerance: f64,
    /// The grid step.
    pub(crate) step: f64,
}

impl Probe<'_> {
    /// Exact: the drop-cutter (floored at z, which only prunes more) rises above z.
    pub(crate) fn is_inside(&self, p: Point2) -> bool {
        drop_cutter(self.cutter, self.index, p, self.z).tip.z > self.z
    }

    /// Bisection between an inside and an outside point down to the tolerance;
    /// returns the outside end of the final bracket.
    pub(crate) fn bisect(&self, mut inside: Point2, mut outside: Point2) -> Point2 {
        while (outside - inside).norm() > self.tolerance {
            let mid = Point2::new(0.5 * (inside.x + outside.x), 0.5 * (inside.y + outside.y));
            if mid == inside || mid == outside {
                break; // the bracket is down to adjacent floats
            }
            if self.is_inside(mid) {
                inside = mid;
            } else {
                outside = mid;
            }
        }
        outside
    }

    /// The contour near `mid` along `normal` (unit, pointing inside), found
    /// by bisection within `reach` of `mid`; `None` if no change of side there.
    /// Probes at a quarter of `reach`, then at doubling distances up to
    /// `reach` (the first change of side found is bisected).
    fn contour_near(&self, mid: Point2, normal: Vec2, reach: f64) -> Option<Point2> {
        let mid_in = self.is_inside(mid);
        let towards = if mid_in { -normal } else { normal };
        let mut r = reach * QUARTER;
        loop {
            let p = mid + towards * r;
            if self.is_inside(p) != mid_in {
                return Some(if mid_in { self.bisect(mid, p) } else { self.bisect(p, mid) });
            }
            if r >= reach {
                return None;
            }
            r = (2.0 * r).min(reach);
        }
    }
}

/// The first probe distance, as a fraction of the reach.
const QUARTER: f64 = 0.25;

/// Points strictly between `a` and `b` that bring every chord within
/// `chord_tolerance` of the contour at its midpoint (as far as the probe
/// along the chord's normal finds the contour), in order from `a` to `b`.
fn refine_chord(probe: &Probe<'_>, a: Point2, b: Point2, chord_tolerance: f64, depth: u32, out: &mut Vec<Point2>) {
    let d = b - a;
    let length = d.norm();
    if depth >= tol::MAX_REFINE_DEPTH || length <= tol::MIN_CHORD_PER_CROSSING * probe.tolerance {
        return;
    }
    let normal = Vec2::new(-d.y, d.x) / length; // left of a -> b: the inside
    let mid = Point2::new(0.5 * (a.x + b.x), 0.5 * (a.y + b.y));
    // Within a grid cell the contour may bulge up to about a cell away from the
    // chord joining its two crossings (a ridge along the diagonal): reach that far.
    let Some(on) = probe.contour_near(mid, normal, length.max(probe.step)) else { return };
    if (on - mid).norm() <= chord_tolerance || on == a || on == b {
        return;
    }
    refine_chord(probe, a, on, chord_tolerance, depth + 1, out);
    out.push(on);
    refine_chord(probe, on, b, chord_tolerance, depth + 1, out);
}

/// Closed loops from the grid chains, every chord refined (in parallel over
/// chords; the result does not depend on the number of threads).
pub(crate) fn refine_loops(probe: &Probe<'_>, chains: &[Vec<Point2>], chord_tolerance: f64, z: f64) -> Vec<Loop> {
    let chords: Vec<(Point2, Point2)> =
        chains.iter().flat_map(|c| (0..c.len()).map(move |i| (c[i], c[(i + 1) % c.len()]))).collect();
    let inserted: Vec<Vec<Point2>> = chords
        .par_iter()
        .with_min_len(4)
        .map(|&(a, b)| {
            let mut out = Vec::new();
            refine_chord(probe, a, b, chord_tolerance, 0, &mut out);
            out
        })
        .collect();
    let mut loops = Vec::with_capacity(chains.len());
    let mut at = 0;
    for chain in chains {
        let mut points = Vec::with_capacity(chain.len());
        for (p, extra) in chain.iter().zip(&inserted[at..at + chain.len()]) {
            points.push(*p);
            points.extend_from_slice(extra);
        }
        at += chain.len();
        loops.push(Loop { z, points });
    }
    loops
}
