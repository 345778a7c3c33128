//! Isoparametric finishing of one parametric patch (issue 3): passes along the
//! isolines of `u` (or `v`), the iso spacing adapted pass by pass so that the
//! scallop between adjacent passes stays `<= sh`.
//!
//! - **Passes.** Pass `k` follows the isoline `cross = c_k` (`cross = v` for
//!   passes along `u`). Its cutter locations are drop-cutter points (exact, on the
//!   part's mesh) at the XY of the tip that touches each isoline point along the
//!   surface normal (so the contact stays on the isoline where the cutter can
//!   reach it), sampled every `max_step` mm and
//!   bisected while the CL midpoint deviates from the chord by more than
//!   `SAMPLING_SHARE * path`, then merged by `simplify_above` within
//!   `SIMPLIFY_SHARE * path`. Passes run in zigzag order, joined by retract, rapid
//!   and plunge (always safe).
//! - **Spacing rule.** At every sample of pass `k`: the surface normal `n`, the
//!   feed direction `f = S_along` and the cross direction `S_cross`; tilt
//!   `s = acos |n_z|`, horizontal angle `alpha` between `f` and the steepest
//!   slope, `R_eff(s, alpha)` of the cutter ([`scallop_analysis::Cutter`]: ball
//!   `R`, bull-nose Eq. 1.5, flat as a torus with `r = 0`), step-over
//!   `sod = min(2 sqrt(2 sh R_eff - sh^2), 1.8 R)` on the surface, and the
//!   parameter step `sod / |S_cross x n-free part|` (`sod` over the length of
//!   `S_cross` across the feed). The candidate is the minimum over the pass.
//! - **Guarantee: measured.** The candidate next pass is planned and the scallop
//!   between the two is measured by [`iso_scallop`] (below); the step is scaled by
//!   `sqrt(sh / h)` (the scallop grows as the square of the spacing) up to
//!   [`tol::ISO_FIT_ITERATIONS`] times, keeping the largest step measured `<= sh`
//!   (a step measured within [`tol::ISO_FIT_ACCEPT`] of `sh` is taken at once).
//!   A pair over `sh` after that is an `Err`.
//! - **Independent check.** [`iso_scallop`] uses no effective radius: the cutter
//!   body (ball, flat or bull-nose) is convex, the Minkowski sum of a horizontal
//!   disc of radius `R - r` and a ball of radius `r`, so the distance from a point
//!   to the cutter moving along a straight CL segment is convex in the segment
//!   parameter and found exactly by golden section. The scallop at a surface point
//!   between two passes is its distance to the nearest cutter position of either
//!   pass (0 where a cutter touches it), evaluated at [`tol::ISO_LATERAL_SAMPLES`]
//!   points across the gap at every sample of the pass, on the true surface, less
//!   the rest material there (what the cutter placed to touch the point along its
//!   normal, then dropped, still leaves: hollows tighter than the cutter, edges).
//!   The end strips (within the cutter radius of a pass end, where the envelope
//!   comes from the end position: the cutter never goes beyond the patch) are not
//!   measured, as for parallel planes.
//!   Heights include the tessellation's chordal error of the mesh the cutter was
//!   dropped on, so the planner aims at `sh - chordal_error`.

use scallop_analysis::Cutter as Model;
use scallop_cutter::{Cutter, CutterShape, drop_cutter};
use scallop_geom::num::golden_section;
use scallop_geom::{Point2, Point3, Tolerances, Vec3};
use scallop_mesh::MeshIndex;
use scallop_surface::Patch;
use scallop_toolpath::{Move, MoveKind, Toolpath, simplify_above};
use serde::{Deserialize, Serialize};

use crate::{FinishingParams, StrategyError, tol};

/// Which parameter runs along the passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IsoDirection {
    /// Passes along `u` (isolines `v = const`).
    U,
    /// Passes along `v` (isolines `u = const`).
    V,
}

/// A patch as the isoparametric planner machines it: the patch, the index of
/// its tessellation (what the cutter is dropped on) and that tessellation's
/// chordal error (mm; the planner aims at `sh - chordal_error`).
#[derive(Debug, Clone, Copy)]
pub struct IsoSurface<'a> {
    /// The patch.
    pub patch: &'a Patch,
    /// Its tessellation, indexed.
    pub index: &'a MeshIndex,
    /// Largest distance between the tessellation and the patch (mm).
    pub chordal_error: f64,
}

/// One isoparametric pass.
#[derive(Debug, Clone, PartialEq)]
pub struct IsoPass {
    /// The constant parameter of the isoline.
    pub iso: f64,
    /// Cutter locations (tool tip, mm) in increasing running parameter.
    pub cl: Vec<Point3>,
    /// Running parameter of each point of `cl`.
    pub cl_params: Vec<f64>,
    /// Running parameters of all samples before merging (where the scallop is measured).
    pub samples: Vec<f64>,
}

/// The result of [`plan_isoparametric`].
#[derive(Debug, Clone, PartialEq)]
pub struct IsoPlanned {
    /// The moves (zigzag; retract, rapid and plunge between passes).
    pub toolpath: Toolpath,
    /// The passes in order.
    pub passes: Vec<IsoPass>,
    /// Largest measured scallop between adjacent passes (mm).
    pub max_scallop_mm: f64,
    /// Mean of the per-sample measured scallops (mm).
    pub mean_scallop_mm: f64,
}

/// Plans isoparametric passes over `surface` with `cutter`. From `params` it uses
/// `scallop_height`, `max_step` and `clearance`; the feed is `params.machine.feed`.
///
/// # Errors
/// A bad parameter, a cone cutter, `sh` not below the cutter (corner) radius, a
/// spacing below [`tol::MIN_SPACING`] (in mm on the surface), or a measured scallop
/// over `sh` (a bug).
pub fn plan_isoparametric(
    surface: &IsoSurface<'_>,
    cutter: &Cutter,
    params: &FinishingParams,
    direction: IsoDirection,
    tolerances: &Tolerances,
) -> Result<IsoPlanned, StrategyError> {
    let chordal_error = surface.chordal_error;
    let (model, target) = checked_target(cutter, params, tolerances, chordal_error)?;
    let (ctx, across) = Ctx::new(surface, cutter, direction, tolerances, params);
    let mut passes = vec![ctx.pass(across[0])];
    let mut heights: Vec<f64> = Vec::new();
    let mut max_h = 0.0f64;
    while passes.last().is_some_and(|p| p.iso < across[1]) {
        let current = &passes[passes.len() - 1];
        let (next, h, worst) = ctx.fit_next(current, &model, target, across[1])?;
        max_h = max_h.max(worst);
        heights.extend(h);
        passes.push(next);
    }
    #[allow(clippy::cast_precision_loss, reason = "sample counts")]
    let mean = if heights.is_empty() { 0.0 } else { heights.iter().sum::<f64>() / heights.len() as f64 };
    let toolpath = ctx.toolpath(&passes);
    Ok(IsoPlanned { toolpath, passes, max_scallop_mm: max_h + chordal_error.max(0.0), mean_scallop_mm: mean })
}

impl<'a> Ctx<'a> {
    /// The planner's context on `surface` and the cross range of its isolines.
    fn new(
        surface: &IsoSurface<'a>,
        cutter: &'a Cutter,
        direction: IsoDirection,
        tolerances: &'a Tolerances,
        params: &'a FinishingParams,
    ) -> (Ctx<'a>, [f64; 2]) {
        let (patch, index) = (surface.patch, surface.index);
        let domain = patch.domain();
        let (along, across) = match direction {
            IsoDirection::U => (domain.u, domain.v),
            IsoDirection::V => (domain.v, domain.u),
        };
        let floor = index.bounds().min.z - 1.0;
        (Ctx { patch, index, cutter, direction, along, floor, tolerances, params }, across)
    }

    /// The pass after `current` as the planner places it: the rule's step for
    /// `target`, then measured ([`iso_scallop`]) and corrected until the
    /// worst scallop is within [`tol::ISO_FIT_ACCEPT`] of `target` (or the
    /// isoline `end` is reached); the farthest measured pass that holds
    /// `target`, with its scallop samples and their worst.
    fn fit_next(
        &self,
        current: &IsoPass,
        model: &Model,
        target: f64,
        end: f64,
    ) -> Result<(IsoPass, Vec<f64>, f64), StrategyError> {
        let (patch, index, cutter, direction) = (self.patch, self.index, self.cutter, self.direction);
        let last = current.iso;
        let mut step = self.rule_step(current, model, target);
        let mut best: Option<(IsoPass, Vec<f64>, f64)> = None;
        for _ in 0..tol::ISO_FIT_ITERATIONS {
            let iso = (last + step).min(end);
            let next = self.pass(iso);
            let h = iso_scallop(patch, index, cutter, direction, current, &next);
            let worst = h.iter().copied().fold(0.0, f64::max);
            let reached_end = iso >= end;
            if worst <= target {
                let better = best.as_ref().is_none_or(|b| iso > b.0.iso);
                if better {
                    best = Some((next, h, worst));
                }
                if reached_end || worst >= tol::ISO_FIT_ACCEPT * target {
                    break;
                }
            }
            let factor = if worst > 0.0 { (target / worst).sqrt() * tol::SPACING_SAFETY } else { 2.0 };
            let grown = step * factor.clamp(0.25, 2.0);
            if worst <= target && grown <= step {
                break;
            }
            step = if worst > target { step * factor.clamp(0.25, 0.95) } else { grown };
            if step * self.cross_speed(current) < tol::MIN_SPACING {
                break;
            }
        }
        best.ok_or_else(|| {
            let p = current.cl.first().copied().unwrap_or_else(Point3::origin);
            StrategyError::Unreachable { x: p.x, y: p.y, spacing: step, scallop_height: self.params.scallop_height }
        })
    }
}

/// The planner's checks and its cutter model and target scallop: `sh` less
/// the tessellation's `chordal_error`.
fn checked_target(
    cutter: &Cutter,
    params: &FinishingParams,
    tolerances: &Tolerances,
    chordal_error: f64,
) -> Result<(Model, f64), StrategyError> {
    params.validate()?;
    let model = model(cutter)?;
    let sh = params.scallop_height;
    let limit = match *cutter.shape() {
        CutterShape::Bull { corner, .. } => corner,
        _ => cutter.radius(),
    };
    if sh >= limit {
        return Err(StrategyError::ScallopTooLarge { scallop_height: sh, what: "radius", radius: limit });
    }
    let target = sh - chordal_error.max(0.0);
    if target <= 0.0 {
        return Err(StrategyError::BadParameter {
            name: "tolerances.path",
            value: tolerances.path,
            fix: "the tessellation error exceeds the scallop height: use a smaller path tolerance",
        });
    }
    Ok((model, target))
}

/// The number of passes [`plan_isoparametric`] makes on `surface`, estimated
/// from the planner's own step fit (the rule's step, measured by
/// [`iso_scallop`] and corrected, as the planner does) at `samples` isolines
/// spread evenly across the patch: the cross range is walked with the fitted
/// steps, linear between the sampled isolines. It costs about `samples` of
/// the planner's passes; `scallop run --plan-only` estimates with it.
///
/// # Errors
/// As [`plan_isoparametric`].
pub fn iso_fitted_passes(
    surface: &IsoSurface<'_>,
    cutter: &Cutter,
    params: &FinishingParams,
    direction: IsoDirection,
    tolerances: &Tolerances,
    samples: usize,
) -> Result<usize, StrategyError> {
    use rayon::prelude::*;
    let (model, target) = checked_target(cutter, params, tolerances, surface.chordal_error)?;
    let (ctx, across) = Ctx::new(surface, cutter, direction, tolerances, params);
    let n = samples.max(2);
    #[allow(clippy::cast_precision_loss, reason = "small counts")]
    let fitted = (0..n)
        .into_par_iter()
        .map(|k| {
            let c = across[0] + (across[1] - across[0]) * (k as f64 + 0.5) / n as f64;
            let (next, _, _) = ctx.fit_next(&ctx.pass(c), &model, target, across[1])?;
            Ok((c, next.iso - c))
        })
        .collect::<Result<Vec<(f64, f64)>, StrategyError>>()?;
    let step_at = |c: f64| {
        let k = fitted.partition_point(|&(ck, _)| ck <= c);
        match k {
            0 => fitted[0].1,
            k if k == fitted.len() => fitted[k - 1].1,
            k => {
                let ((c0, s0), (c1, s1)) = (fitted[k - 1], fitted[k]);
                s0 + (s1 - s0) * (c - c0) / (c1 - c0)
            }
        }
    };
    let (mut iso, mut passes) = (across[0], 1);
    while iso < across[1] && passes <= tol::ISO_MAX_SAMPLES {
        let step = step_at(iso);
        if !(step.is_finite() && step > 0.0) {
            break;
        }
        iso = (iso + step).min(across[1]);
        passes += 1;
    }
    Ok(passes)
}

fn model(cutter: &Cutter) -> Result<Model, StrategyError> {
    match *cutter.shape() {
        CutterShape::Ball { radius } => Ok(Model::Ball { radius }),
        CutterShape::Bull { radius, corner } => Ok(Model::Toroidal { radius, corner }),
        CutterShape::Flat { radius } => Ok(Model::Toroidal { radius, corner: 0.0 }),
        CutterShape::Cone { .. } => Err(StrategyError::Unsupported { shape: "cone" }),
    }
}

struct Ctx<'a> {
    patch: &'a Patch,
    index: &'a MeshIndex,
    cutter: &'a Cutter,
    direction: IsoDirection,
    along: [f64; 2],
    floor: f64,
    tolerances: &'a Tolerances,
    params: &'a FinishingParams,
}

fn uv(direction: IsoDirection, a: f64, c: f64) -> (f64, f64) {
    match direction {
        IsoDirection::U => (a, c),
        IsoDirection::V => (c, a),
    }
}

impl Ctx<'_> {
    fn surface(&self, a: f64, c: f64) -> Point3 {
        let (u, v) = uv(self.direction, a, c);
        self.patch.point(u, v)
    }

    /// The cutter location whose contact is `S(a, c)` (the tip offset along the
    /// normal), dropped onto the part: the contact stays on the isoline wherever the
    /// cutter can reach it.
    fn drop(&self, a: f64, c: f64) -> Point3 {
        let (u, v) = uv(self.direction, a, c);
        let ideal = touching_tip(self.patch, self.cutter, u, v);
        drop_cutter(self.cutter, self.index, Point2::new(ideal.x, ideal.y), self.floor).tip
    }

    /// The pass on isoline `c`: uniform samples at about `max_step`, bisected to the
    /// sampling share of the path tolerance, merged within the simplify share.
    fn pass(&self, c: f64) -> IsoPass {
        let [a0, a1] = self.along;
        let coarse = 64;
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let length: f64 = (0..coarse)
            .map(|i| {
                let (s, t) = (i as f64 / coarse as f64, (i + 1) as f64 / coarse as f64);
                (self.surface(a0 + (a1 - a0) * t, c) - self.surface(a0 + (a1 - a0) * s, c)).norm()
            })
            .sum();
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small positive count")]
        let n = ((length / self.params.max_step).ceil() as usize).clamp(2, tol::ISO_MAX_SAMPLES);
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let mut samples: Vec<(f64, Point3)> = (0..=n)
            .map(|i| {
                let a = a0 + (a1 - a0) * i as f64 / n as f64;
                (a, self.drop(a, c))
            })
            .collect();
        let sample_tol = tol::SAMPLING_SHARE * self.tolerances.path;
        let min_da = (a1 - a0) * tol::MIN_STEP_FRACTION / n as f64;
        let mut k = 0;
        while k + 1 < samples.len() && samples.len() < tol::ISO_MAX_SAMPLES {
            let ((sa, pa), (sb, pb)) = (samples[k], samples[k + 1]);
            let m = 0.5 * (sa + sb);
            let pm = self.drop(m, c);
            let chord = Point3::from((pa.coords + pb.coords) * 0.5);
            if (pm - chord).norm() > sample_tol && sb - sa > min_da {
                samples.insert(k + 1, (m, pm));
            } else {
                k += 1;
            }
        }
        let points: Vec<Point3> = samples.iter().map(|s| s.1).collect();
        let kept = simplify_above(&points, tol::SIMPLIFY_SHARE * self.tolerances.path);
        IsoPass {
            iso: c,
            cl: kept.iter().map(|&i| points[i]).collect(),
            cl_params: kept.iter().map(|&i| samples[i].0).collect(),
            samples: samples.iter().map(|s| s.0).collect(),
        }
    }

    /// Length (mm) of the cross derivative, the smallest over the pass's samples.
    fn cross_speed(&self, pass: &IsoPass) -> f64 {
        pass.samples.iter().map(|&a| self.derivs(a, pass.iso).1.norm()).fold(f64::INFINITY, f64::min)
    }

    /// `(S_along, S_cross, normal)` at `(a, c)`.
    fn derivs(&self, a: f64, c: f64) -> (Vec3, Vec3, Vec3) {
        let (u, v) = uv(self.direction, a, c);
        let d = self.patch.derivatives(u, v);
        let n = self.patch.normal(u, v);
        match self.direction {
            IsoDirection::U => (d.du, d.dv, n),
            IsoDirection::V => (d.dv, d.du, n),
        }
    }

    /// The spacing rule: the smallest parameter step over the pass.
    fn rule_step(&self, pass: &IsoPass, model: &Model, target: f64) -> f64 {
        rule_step(self.patch, self.direction, model, (pass.iso, &pass.samples), target)
    }

    fn toolpath(&self, passes: &[IsoPass]) -> Toolpath {
        let top = self.index.bounds().max.z + self.params.clearance;
        let feed = self.params.machine.feed * 60.0;
        let mut path = Toolpath::new(feed);
        path.plunge_feed = self.params.plunge_feed * 60.0;
        for (k, pass) in passes.iter().enumerate() {
            let pts: Vec<Point3> = if k % 2 == 0 { pass.cl.clone() } else { pass.cl.iter().rev().copied().collect() };
            let (Some(first), Some(last)) = (pts.first(), pts.last()) else { continue };
            path.push(Move::new(MoveKind::Rapid, Point3::new(first.x, first.y, top)));
            path.push(Move::new(MoveKind::Plunge, *first));
            for p in &pts[1..] {
                path.push(Move::new(MoveKind::Feed, *p));
            }
            path.push(Move::new(MoveKind::Retract, Point3::new(last.x, last.y, top)));
        }
        path
    }
}

/// The spacing rule of [`plan_isoparametric`] on the isoline `iso` at the
/// running parameters `samples`: the smallest parameter step over them.
fn rule_step(patch: &Patch, direction: IsoDirection, model: &Model, (iso, samples): (f64, &[f64]), target: f64) -> f64 {
    let mut step = f64::INFINITY;
    for &a in samples {
        let (u, v) = uv(direction, a, iso);
        let d = patch.derivatives(u, v);
        let (f, x) = match direction {
            IsoDirection::U => (d.du, d.dv),
            IsoDirection::V => (d.dv, d.du),
        };
        let n = patch.normal(u, v);
        let n = if n.z < 0.0 { -n } else { n };
        let slope = n.z.clamp(-1.0, 1.0).acos();
        let (nx, ny) = (n.x, n.y);
        let alpha = if nx.hypot(ny) > tol::HORIZONTAL_XY && f.xy().norm() > tol::HORIZONTAL_XY {
            (f.x * ny - f.y * nx).atan2(f.x * nx + f.y * ny)
        } else {
            0.0
        };
        let r_eff = model.effective_radius(slope, alpha);
        // The part of S_cross across the feed direction on the surface.
        let fu = f.try_normalize(1e-300).unwrap_or_else(Vec3::x);
        let across = (x - fu * fu.dot(&x)).norm();
        let sod = scallop_analysis::step_over(target, r_eff).min(tol::ISO_MAX_STEP_OVER * model.radius());
        if across > 0.0 {
            step = step.min(sod / across);
        }
    }
    step
}

/// `(R, r)` of the cutter body: ball `r = R`, flat `r = 0`.
fn radii(cutter: &Cutter) -> (f64, f64) {
    match *cutter.shape() {
        CutterShape::Ball { radius } => (radius, radius),
        CutterShape::Bull { radius, corner } => (radius, corner),
        CutterShape::Flat { radius } | CutterShape::Cone { radius, .. } => (radius, 0.0),
    }
}

/// The tip of the cutter touching `S(u, v)` with the surface normal there (upward).
fn touching_tip(patch: &Patch, cutter: &Cutter, u: f64, v: f64) -> Point3 {
    let n = patch.normal(u, v);
    let n = if n.z < 0.0 { -n } else { n };
    patch.point(u, v) + crate::geometry::contact_to_tip(cutter.shape(), &n)
}

/// Distance (mm) from `p` to the cutter body with its tip at `tip` (0 inside):
/// the body is a horizontal disc of radius `R - r` at height `r` above the tip,
/// grown by a ball of radius `r` (ball: `r = R`; flat: `r = 0`).
fn body_distance(p: &Point3, tip: &Point3, radius: f64, corner: f64) -> f64 {
    let h = (p.xy() - tip.xy()).norm();
    let dz = p.z - (tip.z + corner);
    ((h - (radius - corner)).max(0.0).hypot(dz) - corner).max(0.0)
}

/// Smallest distance from `p` to the cutter moving along the pass (golden section
/// per segment: the distance is convex along a straight move). Segments are visited
/// outwards from the one at running parameter `s` and the walk stops on each side
/// after [`tol::ISO_WINDOW_MISSES`] segments in a row that cannot come closer; a
/// segment left out can only make the result larger (the check stays conservative).
fn swept_distance(p: &Point3, pass: &IsoPass, s: f64, radius: f64, corner: f64) -> f64 {
    let cl = &pass.cl;
    if cl.len() < 2 {
        return cl.first().map_or(f64::INFINITY, |t| body_distance(p, t, radius, corner));
    }
    let start = pass.cl_params.partition_point(|&x| x < s).clamp(1, cl.len() - 1) - 1;
    let mut best = f64::INFINITY;
    let visit = |k: usize, best: &mut f64| -> bool {
        let (a, b) = (cl[k], cl[k + 1]);
        let ab = b.xy() - a.xy();
        let t = if ab.norm_squared() > 0.0 {
            ((p.xy() - a.xy()).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        // The body reaches at most `radius` sideways from its axis.
        let lower = (a.xy() + ab * t - p.xy()).norm() - radius;
        if lower > *best {
            return false;
        }
        let f = |s: f64| body_distance(p, &(a + (b - a) * s), radius, corner);
        let end = golden_section(f, (0.0, 1.0), tol::GOLDEN_ITERATIONS, None, |f1, f2| f1 <= f2);
        let [(_, f1), (_, f2)] = end.inner;
        *best = best.min(f1.min(f2)).min(f(0.0)).min(f(1.0));
        true
    };
    visit(start, &mut best);
    let mut misses = 0;
    for k in (0..start).rev() {
        misses = if visit(k, &mut best) { 0 } else { misses + 1 };
        if misses >= tol::ISO_WINDOW_MISSES {
            break;
        }
    }
    misses = 0;
    for k in start + 1..cl.len() - 1 {
        misses = if visit(k, &mut best) { 0 } else { misses + 1 };
        if misses >= tol::ISO_WINDOW_MISSES {
            break;
        }
    }
    best
}

/// Measured scallop (mm) between two adjacent isoparametric passes `a` and `b`, at
/// every running sample of `a` (and `b`), the largest of
/// [`tol::ISO_LATERAL_SAMPLES`] surface points across the gap: each point's distance to
/// the nearest cutter position of either pass, less what the cutter leaves there
/// anyway (rest material: the cutter placed to touch the point with its own normal,
/// then dropped, is held up elsewhere). Independent of the spacing rule.
#[must_use]
pub fn iso_scallop(
    patch: &Patch,
    index: &MeshIndex,
    cutter: &Cutter,
    direction: IsoDirection,
    a: &IsoPass,
    b: &IsoPass,
) -> Vec<f64> {
    let (radius, corner) = radii(cutter);
    let floor = index.bounds().min.z - 1.0;
    let ends = [a.samples.first().copied(), a.samples.last().copied()];
    let mut out = Vec::new();
    let mut running: Vec<f64> = a.samples.iter().chain(&b.samples).copied().collect();
    running.sort_by(f64::total_cmp);
    running.dedup();
    for &s in &running {
        let mut worst = 0.0f64;
        for k in 1..tol::ISO_LATERAL_SAMPLES {
            #[allow(clippy::cast_precision_loss, reason = "small counts")]
            let c = a.iso + (b.iso - a.iso) * k as f64 / tol::ISO_LATERAL_SAMPLES as f64;
            let (u, v) = uv(direction, s, c);
            let p = patch.point(u, v);
            // End strips: within the cutter radius of a pass end the envelope comes from
            // the end position (the cutter never goes beyond the patch): not a scallop.
            let near_end = ends.iter().flatten().any(|&e| {
                let (eu, ev) = uv(direction, e, c);
                (patch.point(eu, ev) - p).norm() < radius
            });
            if near_end {
                continue;
            }
            let d = swept_distance(&p, a, s, radius, corner).min(swept_distance(&p, b, s, radius, corner));
            if d <= worst {
                continue;
            }
            // The tip that touches p with the surface normal there, dropped.
            let ideal = touching_tip(patch, cutter, u, v);
            let held = drop_cutter(cutter, index, Point2::new(ideal.x, ideal.y), floor).tip;
            let rest = if held.z > ideal.z { body_distance(&p, &held, radius, corner) } else { 0.0 };
            worst = worst.max(d - rest);
        }
        out.push(worst);
    }
    out
}

#[cfg(test)]
mod touching_tests {
    use super::*;
    use scallop_cutter::{Contact, drop_cutter};
    use scallop_mesh::{MeshIndex, TriMesh};

    /// The drop-cutter location at the XY of `touching_tip` touches an inclined
    /// plane exactly at the isoline point.
    #[test]
    fn touching_tip_touches_the_surface_point() {
        let s = 30f64.to_radians();
        let p = |x: f64, y: f64| Point3::new(x, y, s.tan() * x);
        let control = vec![vec![p(-40., -40.), p(-40., 40.)], vec![p(40., -40.), p(40., 40.)]];
        let patch = Patch::bezier("incline", [1, 1], &control, None).unwrap_or_else(|e| panic!("{e}"));
        let (mesh, _) = TriMesh::from_soup(&[
            [p(-40., -40.), p(40., -40.), p(40., 40.)],
            [p(-40., -40.), p(40., 40.), p(-40., 40.)],
        ])
        .unwrap_or_else(|e| panic!("{e}"));
        let index = MeshIndex::build(&mesh);
        for shape in [
            CutterShape::Bull { radius: 5.0, corner: 2.0 },
            CutterShape::Flat { radius: 3.0 },
            CutterShape::Ball { radius: 4.0 },
        ] {
            let cutter = Cutter::new(shape, 20.0).unwrap_or_else(|e| panic!("{e}"));
            let (u, v) = (0.55, 0.4);
            let tip = touching_tip(&patch, &cutter, u, v);
            let cl = drop_cutter(&cutter, &index, scallop_geom::Point2::new(tip.x, tip.y), -100.0);
            let Contact::Facet { point, .. } = cl.contact else { panic!("{:?}", cl.contact) };
            assert!((point - patch.point(u, v)).norm() < 1e-9, "{shape:?}: {point:?} vs {:?}", patch.point(u, v));
            assert!((cl.tip - tip).norm() < 1e-9, "{shape:?}");
        }
    }
}
