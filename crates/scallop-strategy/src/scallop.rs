//! Scallop height between adjacent passes, measured from the cutter geometry
//! and the part, independently of the planner's step-over model.
//!
//! # Method
//! Passes lie in vertical planes `d = m . p` and are polylines `z(t)` of the
//! feed coordinate `t = f . p`. At a feed coordinate `t`, cut everything with
//! the vertical plane normal to `f` (lateral coordinate `w`). The material left
//! by one pass there is bounded by its **envelope**
//!
//! ```text
//! E(w) = min over tool positions tau on the pass, |tau - t| <= sqrt(R^2 - y^2), y = w - d,
//!        of  z(tau) + h( sqrt((tau - t)^2 + y^2) )
//! ```
//!
//! with `h(rho)` the cutter profile's height above the tip. Along one linear
//! segment `z(tau)` is linear and `h(sqrt(.))` convex (ball, bull-nose and flat
//! profiles are convex), so the minimum per segment is a 1-D convex problem:
//! closed form for the ball (`delta = -p q / sqrt(1 + p^2)`, `q^2 = R^2 - y^2`),
//! an end point for the flat cutter, golden section for the bull-nose. The cusp
//! between passes A and B is where `E_A(w) = E_B(w)` (Illinois false position);
//! its scallop height is the vertical distance to the part there times the part
//! normal's `n_z`, i.e. the distance along the normal to the local tangent plane.
//! Other passes can only lower the material further, so two passes bound it.
//!
//! The planner places each plane by this same measurement (shrinking the gap
//! until it holds), so the verification of the final passes re-measures exactly
//! what the planner accepted; it shares no step-over model with the planner.

use rayon::prelude::*;
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::num::golden_section;
use scallop_geom::{Point2, Point3};
use scallop_mesh::MeshIndex;
use serde::{Deserialize, Serialize};

use crate::geometry::{Frame, surface_at};
use crate::{Plane, StrategyError, tol};

/// A pass as a function `z(t)` in its plane `d`.
#[derive(Debug, Clone)]
pub(crate) struct Curve {
    ts: Vec<f64>,
    zs: Vec<f64>,
    d: f64,
}

impl Curve {
    /// From CL points in increasing `t`.
    pub(crate) fn new(frame: &Frame, points: &[Point3]) -> Curve {
        let ts = points.iter().map(|p| frame.t(p)).collect();
        let zs = points.iter().map(|p| p.z).collect();
        let d = points.first().map_or(0.0, |p| frame.d(p));
        Curve { ts, zs, d }
    }

    /// Whether `t` lies on the curve at least `margin` from both ends.
    pub(crate) fn covers_inside(&self, t: f64, margin: f64) -> bool {
        match (self.ts.first(), self.ts.last()) {
            (Some(&a), Some(&b)) => a + margin <= t && t <= b - margin,
            _ => false,
        }
    }

    /// `E(w)`: the lowest cutter surface of this pass over `(t, w)`; `+inf` out of reach.
    fn envelope(&self, shape: &CutterShape, t: f64, w: f64) -> f64 {
        self.envelope_at(shape, t, w).0
    }

    /// `E(w)` and whether its minimum comes from an end of the pass (where the
    /// envelope is the cutter standing at the end, an edge effect, not a scallop).
    fn envelope_at(&self, shape: &CutterShape, t: f64, w: f64) -> (f64, bool) {
        let radius = shape.radius();
        let y = w - self.d;
        if y.abs() > radius || self.ts.is_empty() {
            return (f64::INFINITY, true);
        }
        let reach = (radius * radius - y * y).max(0.0).sqrt();
        let (lo, hi) = (t - reach, t + reach);
        let n = self.ts.len();
        if n == 1 {
            let delta = self.ts[0] - t;
            let z = if delta.abs() <= reach { self.zs[0] + shape.height_at(delta.hypot(y)) } else { f64::INFINITY };
            return (z, true);
        }
        let end_slack = tol::PASS_END_REL * radius;
        let (t_first, t_last) = (self.ts[0], self.ts[n - 1]);
        let first = self.ts.partition_point(|&x| x < lo).saturating_sub(1);
        let last = self.ts.partition_point(|&x| x <= hi).min(n - 1);
        let mut best = f64::INFINITY;
        let mut best_tau = t;
        // Segments nearest to t first (the best bound early), then outwards.
        let home =
            self.ts.partition_point(|&x| x <= t).saturating_sub(1).clamp(first, last.saturating_sub(1).max(first));
        let order = (first..=home).rev().chain(home + 1..last);
        for i in order {
            if i + 1 >= n {
                continue;
            }
            let (t0, t1, z0, z1) = (self.ts[i], self.ts[i + 1], self.zs[i], self.zs[i + 1]);
            let (a, b) = (t0.max(lo), t1.min(hi));
            if a > b {
                continue;
            }
            // Lower bound on the segment: lowest tip on [a, b] plus the profile at
            // the smallest distance from (t, y) to the segment's positions.
            let z_at = |tau: f64| if t1 > t0 { z0 + (z1 - z0) * (tau - t0) / (t1 - t0) } else { z0 };
            let gap = if t < a {
                a - t
            } else if t > b {
                t - b
            } else {
                0.0
            };
            if z_at(a).min(z_at(b)) + shape.height_at(gap.hypot(y)) >= best {
                continue;
            }
            let slope = if t1 > t0 { (z1 - z0) / (t1 - t0) } else { 0.0 };
            let g = |tau: f64| z0 + slope * (tau - t0) + shape.height_at(((tau - t) * (tau - t) + y * y).sqrt());
            let (tau, value) = match *shape {
                CutterShape::Ball { .. } => {
                    // d/d(delta) [p delta - sqrt(q^2 - delta^2)] = 0  =>  delta = -p q / sqrt(1 + p^2)
                    let delta = -slope * reach / slope.hypot(1.0);
                    let tau = (t + delta).clamp(a, b);
                    (tau, g(tau))
                }
                CutterShape::Flat { .. } => {
                    let (ga, gb) = (g(a), g(b));
                    if ga <= gb { (a, ga) } else { (b, gb) }
                }
                CutterShape::Bull { radius, corner } => {
                    // g is convex: find the zero of g'(tau) = p + h'(rho) (tau - t) / rho,
                    // h'(rho) = s / sqrt(r^2 - s^2), s = rho - (R - r) (0 on the flat bottom).
                    let flat = radius - corner;
                    let dg = |tau: f64| {
                        let delta = tau - t;
                        let rho = (delta * delta + y * y).sqrt();
                        let s = rho - flat;
                        if s <= 0.0 || rho <= 0.0 {
                            slope
                        } else {
                            let q = (corner * corner - s * s).max(corner * corner * tol::GOLDEN_REL_TOL).sqrt();
                            slope + s / q * delta / rho
                        }
                    };
                    let (da, db) = (dg(a), dg(b));
                    let tau = if da >= 0.0 {
                        a
                    } else if db <= 0.0 {
                        b
                    } else {
                        crossing(&dg, a, b, da, db, tol::GOLDEN_REL_TOL * radius / tol::CUSP_REL_TOL)
                    };
                    (tau, g(tau))
                }
                CutterShape::Cone { .. } => golden_min(&g, a, b, radius),
            };
            if value < best {
                best = value;
                best_tau = tau;
            }
        }
        let at_end = best_tau <= t_first + end_slack || best_tau >= t_last - end_slack;
        (best, at_end)
    }
}

/// Minimum of a convex function on `[a, b]` by golden section: `(argmin, min)`.
fn golden_min(g: &impl Fn(f64) -> f64, a: f64, b: f64, scale: f64) -> (f64, f64) {
    let stop = Some(tol::GOLDEN_REL_TOL * scale);
    let end = golden_section(g, (a, b), tol::GOLDEN_ITERATIONS, stop, |g1, g2| g1 <= g2);
    let (a, b) = (end.lo, end.hi);
    [end.inner[0], end.inner[1], (a, g(a)), (b, g(b))]
        .into_iter()
        .fold((a, f64::INFINITY), |m, c| if c.1 < m.1 { c } else { m })
}

/// One measured cusp.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cusp {
    pub(crate) height: f64,
    /// Rest material under the cusp that no denser pass spacing would remove (mm).
    pub(crate) rest: f64,
    pub(crate) at: Point2,
}

/// What a scallop measurement needs.
pub(crate) struct Measure<'a> {
    pub(crate) index: &'a MeshIndex,
    pub(crate) cutter: &'a Cutter,
    pub(crate) shape: CutterShape,
    pub(crate) frame: Frame,
    /// Heights above this are re-measured against the dense-pass reference.
    pub(crate) limit: f64,
    /// Whether heights above the limit are re-measured (costly: dense virtual passes).
    pub(crate) refine: bool,
    pub(crate) floor: f64,
    /// Sections closer than this to an end of a pass (along the feed) are not
    /// measured (0: every section both passes cover). Zone planning sets the
    /// cutter radius: there a pass may end inside the part, and the envelope of
    /// a section within R of such an end lacks the cutter locations beyond it.
    pub(crate) end_margin: f64,
}

impl<'a> Measure<'a> {
    pub(crate) fn new(index: &'a MeshIndex, cutter: &'a Cutter, direction: f64, limit: f64) -> Measure<'a> {
        let b = index.bounds();
        Measure {
            index,
            cutter,
            shape: *cutter.shape(),
            frame: Frame::new(direction),
            limit,
            refine: true,
            floor: b.min.z - b.diagonal() - 1.0,
            end_margin: 0.0,
        }
    }

    /// The lowest surface the cutter can machine at `(t, w)` with passes in
    /// every plane between `d0` and `d1` (a dense family of virtual passes,
    /// dropped on a fine grid): the reference of the scallop where the cutter
    /// cannot reach the part itself (concavities tighter than the cutter, the
    /// flat bottom of a bull-nose over a hollow). Linear interpolation between
    /// the virtual CL samples can only lower it (conservative).
    fn dense_reference(&self, d0: f64, d1: f64, t: f64, w: f64) -> f64 {
        let radius = self.shape.radius();
        let planes = tol::REFERENCE_PLANES;
        let step = radius * tol::REFERENCE_STEP_FRACTION;
        let mut best = f64::INFINITY;
        for i in 0..=planes {
            let d = d0 + (d1 - d0) * (i as f64 / planes as f64);
            let y = w - d;
            if y.abs() > radius {
                continue;
            }
            let reach = (radius * radius - y * y).max(0.0).sqrt();
            let n = (2.0 * reach / step).ceil().max(2.0);
            let ts: Vec<f64> = (0..=n as usize).map(|j| t - reach + 2.0 * reach * (j as f64 / n)).collect();
            let zs = ts
                .iter()
                .map(|&tau| {
                    scallop_cutter::drop_cutter(self.cutter, self.index, self.frame.xy(tau, d), self.floor).tip.z
                })
                .collect();
            let curve = Curve { ts, zs, d };
            best = best.min(curve.envelope(&self.shape, t, w));
        }
        best
    }
}

/// The scallop height between passes `a` and `b` at feed coordinate `t`, or
/// `None` when there is no part under the cusp (a hole between the passes) or
/// when an envelope there is made by a pass end (the end strips of a pass are
/// left as the cutter standing at its end leaves them: an edge effect of the
/// region's boundary, not a scallop between passes).
pub(crate) fn cusp(measure: &Measure<'_>, a: &Curve, b: &Curve, t: f64, scratch: &mut Vec<u32>) -> Option<Cusp> {
    let (index, shape, frame) = (measure.index, &measure.shape, &measure.frame);
    let (a, b) = if a.d <= b.d { (a, b) } else { (b, a) };
    let radius = shape.radius();
    // Both envelopes are finite on [b.d - R, a.d + R]; there E_A - E_B is
    // non-decreasing (a convex profile minus its own translate), and its zero is
    // the cusp. On a cross slope the contacts, hence the cusp, lie beside the
    // pass planes, not between them.
    let (lo, hi) = (b.d - radius, a.d + radius);
    if lo > hi {
        // The envelopes do not meet: a strip between the passes is never cut.
        let at = frame.xy(t, 0.5 * (a.d + b.d));
        return surface_at(index, at, scratch).map(|_| Cusp { height: f64::INFINITY, rest: 0.0, at });
    }
    let g = |w: f64| a.envelope(shape, t, w) - b.envelope(shape, t, w);
    let (g_lo, g_hi) = (g(lo), g(hi));
    let mut candidates = Vec::new();
    if g_lo < 0.0 && g_hi > 0.0 {
        candidates.push(crossing(&g, lo, hi, g_lo, g_hi, (b.d - a.d).max(radius)));
    } else if b.d - a.d < tol::MIN_SPACING {
        return None; // coincident planes
    }
    if matches!(shape, CutterShape::Flat { .. }) || candidates.is_empty() {
        // A flat end leaves a saw tooth whose top need not be the crossing, and
        // without a crossing one envelope lies below the other: sample the span.
        let n = tol::CUSP_SPAN_SAMPLES;
        candidates.extend((0..=n).map(|k| lo + (hi - lo) * (k as f64 / n as f64)));
    }
    let mut worst: Option<(f64, f64, f64, f64)> = None; // (vertical residual, w, top, normal z)
    for w in candidates {
        let at = frame.xy(t, w);
        let ((top_a, end_a), (top_b, end_b)) = (a.envelope_at(shape, t, w), b.envelope_at(shape, t, w));
        let top = top_a.min(top_b);
        if (end_a && top_a <= top_b) || (end_b && top_b <= top_a) || !top.is_finite() {
            continue;
        }
        let Some((z_part, normal)) = surface_at(index, at, scratch) else { continue };
        let residual = (top - z_part).max(0.0);
        if worst.is_none_or(|(r, _, _, nz)| residual * normal.z > r * nz) {
            worst = Some((residual, w, z_part, normal.z));
        }
    }
    let (residual, w_star, z_part, n_z) = worst?;
    let at = frame.xy(t, w_star);
    let height = residual * n_z;
    if height <= measure.limit || !measure.refine {
        return Some(Cusp { height, rest: 0.0, at });
    }
    // Above the limit: measure against what any pass spacing could achieve.
    // The virtual family leaves its own scallops, about (1/planes)^2 of this one
    // (scallop ~ gap^2); twice that is not counted as rest material.
    let planes = tol::REFERENCE_PLANES as f64;
    let own = 2.0 * residual / (planes * planes);
    let rest = (measure.dense_reference(a.d, b.d, t, w_star) - z_part - own).max(0.0);
    Some(Cusp { height: (residual - rest).max(0.0) * n_z, rest: rest * n_z, at })
}

/// The zero of the non-decreasing `g` on `[lo, hi]` (`g(lo) < 0 < g(hi)`) by
/// Illinois false position.
fn crossing(g: &impl Fn(f64) -> f64, mut lo: f64, mut hi: f64, mut g_lo: f64, mut g_hi: f64, scale: f64) -> f64 {
    let stop = tol::CUSP_REL_TOL * scale;
    let mut side = 0i8;
    let mut w = 0.5 * (lo + hi);
    for _ in 0..tol::CUSP_ITERATIONS {
        if hi - lo <= stop {
            break;
        }
        w = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
        if !(w > lo && w < hi) {
            w = 0.5 * (lo + hi);
        }
        let gw = g(w);
        if gw == 0.0 {
            break;
        }
        if gw < 0.0 {
            lo = w;
            g_lo = gw;
            if side == -1 {
                g_hi *= 0.5;
            }
            side = -1;
        } else {
            hi = w;
            g_hi = gw;
            if side == 1 {
                g_lo *= 0.5;
            }
            side = 1;
        }
    }
    w
}

/// Scallop statistics of one pair of adjacent planes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PairScallop {
    /// Index of the first plane.
    pub plane: usize,
    /// Index of the second plane (`plane + 1`).
    pub next: usize,
    /// Largest measured scallop (mm).
    pub max_mm: f64,
    /// Mean measured scallop (mm).
    pub mean_mm: f64,
    /// Samples measured.
    pub samples: usize,
    /// XY place of the largest scallop (mm).
    pub worst_xy: [f64; 2],
    /// Largest rest material found under a cusp: thickness the cutter cannot
    /// remove at any pass spacing (concavities tighter than the cutter), not
    /// counted as scallop (mm).
    pub rest_material_mm: f64,
}

/// The verified scallop heights of a plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScallopReport {
    /// Largest scallop over all samples (mm); 0 without samples.
    pub max_mm: f64,
    /// Mean scallop (mm).
    pub mean_mm: f64,
    /// Number of measured samples.
    pub samples: usize,
    /// Width of a histogram bin (mm): `sh / HISTOGRAM_BINS`.
    pub bin_width_mm: f64,
    /// Counts of samples per bin over `[0, sh]`; the last entry counts heights above `sh`.
    pub histogram: Vec<usize>,
    /// Largest rest material (see [`PairScallop::rest_material_mm`]) (mm).
    pub rest_material_mm: f64,
    /// Per pair of adjacent planes with common samples.
    pub pairs: Vec<PairScallop>,
}

/// Measures the scallop between every pair of adjacent planes at the feed
/// coordinates `feed_samples` (`t = f . p`, `f` the feed direction of angle
/// `direction`), wherever both planes have a pass covering `t` and the part
/// lies under the cusp. Passes are CL polylines of the tool tip, in increasing `t`.
///
/// Pairs are measured in parallel and collected in order: the result does not
/// depend on the number of threads.
///
/// # Errors
/// [`StrategyError::ScallopExceeded`] for the first pair (in plane order) whose
/// largest scallop exceeds `scallop_height` (plus a relative measurement slack
/// of [`tol::SCALLOP_REL_SLACK`]).
///
/// ```
/// # use scallop_strategy::{verify_scallop, Plane};
/// # use scallop_cutter::{Cutter, CutterShape};
/// # use scallop_geom::Point3;
/// # use scallop_mesh::{MeshIndex, TriMesh};
/// let p = |x, y, z| Point3::new(x, y, z);
/// let (mesh, _) = TriMesh::from_soup(&[[p(0., 0., 0.), p(10., 0., 0.), p(0., 10., 0.)],
///                                      [p(10., 0., 0.), p(10., 10., 0.), p(0., 10., 0.)]]).unwrap();
/// let index = MeshIndex::build(&mesh);
/// let ball = Cutter::new(CutterShape::Ball { radius: 5.0 }, 20.0).unwrap();
/// // Two passes along X, 1 mm apart: scallop 5 - sqrt(25 - 0.25) = 0.02506 mm.
/// let plane = |y: f64| Plane { offset: y, passes: vec![vec![p(0., y, 0.), p(10., y, 0.)]] };
/// let planes = [plane(4.5), plane(5.5)];
/// let report = verify_scallop(&index, &ball, &planes, 0.0, &[2.0, 5.0, 8.0], 0.03).unwrap();
/// assert!((report.max_mm - 0.025_062_814).abs() < 1e-8);
/// assert!(verify_scallop(&index, &ball, &planes, 0.0, &[5.0], 0.02).is_err());
/// ```
pub fn verify_scallop(
    index: &MeshIndex,
    cutter: &Cutter,
    planes: &[Plane],
    direction: f64,
    feed_samples: &[f64],
    scallop_height: f64,
) -> Result<ScallopReport, StrategyError> {
    verify_measured(&Measure::new(index, cutter, direction, scallop_height), planes, feed_samples, true)
}

/// [`verify_scallop`] with `measure` (its limit the scallop height, its end
/// margin left out); `strict: false` reports a scallop over the limit instead
/// of refusing it.
pub(crate) fn verify_measured(
    measure: &Measure<'_>,
    planes: &[Plane],
    feed_samples: &[f64],
    strict: bool,
) -> Result<ScallopReport, StrategyError> {
    let scallop_height = measure.limit;
    let frame = measure.frame;
    let curves: Vec<Vec<Curve>> =
        planes.iter().map(|pl| pl.passes.iter().map(|p| Curve::new(&frame, p)).collect()).collect();
    let pairs: Vec<(PairScallop, Vec<f64>)> = (0..planes.len().saturating_sub(1))
        .into_par_iter()
        .map(|k| {
            let heights: Vec<Cusp> = pair_heights(measure, &curves[k], &curves[k + 1], feed_samples);
            let mut pair = PairScallop {
                plane: k,
                next: k + 1,
                max_mm: 0.0,
                mean_mm: 0.0,
                samples: heights.len(),
                worst_xy: [0.0; 2],
                rest_material_mm: 0.0,
            };
            let mut sum = 0.0;
            for c in &heights {
                sum += c.height;
                pair.rest_material_mm = pair.rest_material_mm.max(c.rest);
                if c.height > pair.max_mm {
                    pair.max_mm = c.height;
                    pair.worst_xy = [c.at.x, c.at.y];
                }
            }
            if !heights.is_empty() {
                pair.mean_mm = sum / heights.len() as f64;
            }
            (pair, heights.into_iter().map(|c| c.height).collect())
        })
        .collect();
    let limit = scallop_height * (1.0 + tol::SCALLOP_REL_SLACK);
    let bin = scallop_height / tol::HISTOGRAM_BINS as f64;
    let mut report = ScallopReport {
        max_mm: 0.0,
        mean_mm: 0.0,
        samples: 0,
        bin_width_mm: bin,
        histogram: vec![0; tol::HISTOGRAM_BINS + 1],
        rest_material_mm: 0.0,
        pairs: Vec::with_capacity(pairs.len()),
    };
    let mut sum = 0.0;
    for (pair, heights) in pairs {
        if strict && pair.max_mm > limit {
            return Err(StrategyError::ScallopExceeded {
                plane: pair.plane,
                next: pair.next,
                x: pair.worst_xy[0],
                y: pair.worst_xy[1],
                height: pair.max_mm,
                limit: scallop_height,
            });
        }
        for h in heights {
            sum += h;
            report.samples += 1;
            report.max_mm = report.max_mm.max(h);
            let slot = if h > scallop_height {
                tol::HISTOGRAM_BINS
            } else {
                ((h / bin) as usize).min(tol::HISTOGRAM_BINS - 1)
            };
            report.histogram[slot] += 1;
        }
        report.rest_material_mm = report.rest_material_mm.max(pair.rest_material_mm);
        if pair.samples > 0 {
            report.pairs.push(pair);
        }
    }
    if report.samples > 0 {
        report.mean_mm = sum / report.samples as f64;
    }
    Ok(report)
}

/// Cusps between the passes of two planes at every covered feed sample.
pub(crate) fn pair_heights(
    measure: &Measure<'_>,
    first: &[Curve],
    second: &[Curve],
    feed_samples: &[f64],
) -> Vec<Cusp> {
    let mut scratch = Vec::new();
    let mut out = Vec::new();
    for &t in feed_samples {
        let m = measure.end_margin;
        for a in first.iter().filter(|c| c.covers_inside(t, m)) {
            for b in second.iter().filter(|c| c.covers_inside(t, m)) {
                if let Some(c) = cusp(measure, a, b, t, &mut scratch) {
                    out.push(c);
                }
            }
        }
    }
    out
}
