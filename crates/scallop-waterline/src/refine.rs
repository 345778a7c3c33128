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
    /// Tip height of the exact drop-cutter at `p` minus z, floored at
    /// `-step` (a floor only prunes the search; it never changes the sign, so
    /// `height(p) > 0` is exactly "the cutter at z cuts into the part at p").
    pub(crate) fn height(&self, p: Point2) -> f64 {
        drop_cutter(self.cutter, self.index, p, self.z - self.step).tip.z - self.z
    }

    /// Exact: the cutter with its tip at z cuts into the part at `p`.
    pub(crate) fn is_inside(&self, p: Point2) -> bool {
        self.height(p) > 0.0
    }

    /// Shrinks the bracket from `inside` (height `h_in > 0`) to `outside`
    /// (height `h_out <= 0`) to the tolerance and returns its outside end.
    ///
    /// Every step keeps a true bracket (each new point is classified by the
    /// exact drop-cutter). Where the height is smooth, the secant guess
    /// `t = h_in / (h_in - h_out)` lands within the tolerance of the contour and
    /// two probes half a tolerance either side of it close the bracket; where it
    /// is not (vertical walls, creases), a step that did not halve the bracket
    /// is followed by a bisection, so the worst case is twice plain bisection.
    pub(crate) fn bisect_heights(
        &self,
        mut inside: Point2,
        mut h_in: f64,
        mut outside: Point2,
        mut h_out: f64,
    ) -> Point2 {
        let mut bisect_next = false;
        loop {
            let width = (outside - inside).norm();
            if width <= self.tolerance {
                return outside;
            }
            let secant = h_in - h_out;
            let use_secant = !bisect_next && secant.is_finite() && secant > 0.0;
            let (a, b) = (inside, outside);
            let steps: [Option<f64>; 2] = if use_secant {
                let t = (h_in / secant).clamp(0.0, 1.0);
                let half = SECANT_PROBE * self.tolerance / width;
                [Some((t - half).max(0.0)), Some((t + half).min(1.0))]
            } else {
                [Some(0.5), None]
            };
            for s in steps.into_iter().flatten() {
                let p = a + (b - a) * s;
                if p == inside || p == outside {
                    continue;
                }
                let h = self.height(p);
                if h > 0.0 {
                    (inside, h_in) = (p, h);
                } else {
                    (outside, h_out) = (p, h);
                    break;
                }
            }
            let after = (outside - inside).norm();
            if after >= width {
                // Down to adjacent floats (or a guess on an end): stop on the outside.
                return outside;
            }
            // A secant step that did not halve the bracket: the height is not
            // smooth here (a wall, a crease): plain bisection from now on.
            bisect_next |= use_secant && after > 0.5 * width;
        }
    }

    /// Where the contour crosses the line through `mid` along `normal` (unit,
    /// pointing inside): [`Near::Within`] if it does within `accept` of `mid`
    /// (one probe); otherwise probes at doubling distances up to `reach` and
    /// refines the first change of side found; [`Near::Missing`] if none.
    fn contour_near(&self, mid: Point2, normal: Vec2, accept: f64, reach: f64) -> Near {
        let h_mid = self.height(mid);
        let mid_in = h_mid > 0.0;
        let towards = if mid_in { -normal } else { normal };
        let mut r = accept;
        loop {
            let p = mid + towards * r;
            let h = self.height(p);
            if (h > 0.0) != mid_in {
                if r <= accept {
                    return Near::Within;
                }
                return Near::Found(if mid_in {
                    self.bisect_heights(mid, h_mid, p, h)
                } else {
                    self.bisect_heights(p, h, mid, h_mid)
                });
            }
            if r >= reach {
                return Near::Missing;
            }
            r = (PROBE_GROWTH * r).min(reach);
        }
    }
}

/// What [`Probe::contour_near`] found.
enum Near {
    /// The contour is within the accepted distance.
    Within,
    /// The contour point found (farther).
    Found(Point2),
    /// No change of side within reach.
    Missing,
}

/// Growth of the probe distance from one probe to the next.
const PROBE_GROWTH: f64 = 8.0;

/// Probe offset either side of a secant guess, in crossing tolerances: just
/// under a half, so that two probes that straddle the contour close the bracket.
const SECANT_PROBE: f64 = 0.45;

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
    let Near::Found(on) = probe.contour_near(mid, normal, chord_tolerance, length.max(probe.step)) else { return };
    if on == a || on == b {
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
