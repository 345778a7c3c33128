//! Steep-and-shallow finishing of a mesh (issue 15, items 2 and 3): the part
//! split by the slope of its triangles; shallow triangles finished by parallel
//! planes restricted to them ([`crate::plan_zone_finishing`]), steep ones by
//! waterline levels ([`scallop_waterline`]) kept where the cutter's contact is
//! steep. The two slope ranges overlap by a band (`2 * overlap`), so the pass
//! ends of each lie where the other holds the scallop.
//!
//! **Level spacing.** A wall of slope `s` (from the horizontal) finished by
//! levels `dz` apart is crossed by the cutter's profile circles `dz / sin s`
//! apart along the wall: the profile radius `rho` (the ball radius, the
//! corner radius of a bull-nose) leaves the scallop `sh` when that distance is
//! `2 sqrt(2 rho sh - sh^2)` (finishing.md Eq. 1.4 with the effective radius
//! `rho`), so `dz = 2 sqrt(2 rho sh - sh^2) sin s`; a flat end leaves steps of
//! normal height `dz cos s`, so `dz = sh / cos s`. Each level takes the
//! smallest contact slope of its own kept points and of the next level's,
//! and never more than the cutter radius. The stock simulation of the program
//! proves the result (`scallop_engine`).

use std::collections::HashMap;

use rayon::prelude::*;

use scallop_cutter::{ClPoint, Cutter, CutterShape, drop_cutter};
use scallop_geom::{Point2, Point3, Tolerances, Vec2};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_toolpath::{Move, MoveKind, Toolpath};
use scallop_waterline::{Loop, WaterlineGrid, WaterlineOptions};

use crate::geometry::{contact_normal, slots_by_original};
use crate::{FinishingParams, Planned, Refinement, Report, StrategyError, ZoneRegion, tol};

/// How the part is split by slope.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteepShallow {
    /// Slope (rad from the horizontal) at which parallel planes give way to
    /// waterline levels.
    pub threshold: f64,
    /// Half-width of the band both finish (rad): planes run up to
    /// `threshold + overlap`, levels down to `threshold - overlap`.
    pub overlap: f64,
    /// Climb milling on the levels (material on the tool's right, spindle
    /// clockwise); `false`: conventional.
    pub climb: bool,
}

impl SteepShallow {
    /// The split for `cutter` and scallop height `sh`: the slope at which the
    /// horizontal spacing of parallel planes across a wall (the analysis
    /// model's step-over times `cos s`) equals the level spacing (`dz` of the
    /// module docs), between 30 and 70 degrees (45 for a ball); `tol::STEEP_OVERLAP_DEG` of
    /// overlap; climb.
    ///
    /// ```
    /// use scallop_cutter::{Cutter, CutterShape};
    /// let ball = Cutter::new(CutterShape::Ball { radius: 3.0 }, 30.0).unwrap();
    /// let s = scallop_strategy::SteepShallow::default_for(&ball, 0.01);
    /// assert!((s.threshold.to_degrees() - 45.0).abs() < 0.1);
    /// ```
    #[must_use]
    pub fn default_for(cutter: &Cutter, sh: f64) -> SteepShallow {
        let (lo, hi) = (30f64.to_radians(), 70f64.to_radians());
        let plane_width = |s: f64| plane_step(cutter.shape(), sh, s) * s.cos();
        let level_width = |s: f64| level_dz(cutter.shape(), sh, s);
        // The planes' spacing shrinks with the slope, the levels' grows: bisect
        // where they cross (or take the end of the range).
        let (mut a, mut b) = (lo, hi);
        for _ in 0..60 {
            let m = 0.5 * (a + b);
            if plane_width(m) > level_width(m) {
                a = m;
            } else {
                b = m;
            }
        }
        SteepShallow { threshold: 0.5 * (a + b), overlap: tol::STEEP_OVERLAP_DEG.to_radians(), climb: true }
    }

    /// The spacing (mm) of two waterline levels on a wall of `slope` (rad;
    /// not finite: the steep range's lowest slope) for `cutter`, scallop
    /// height `sh` and path tolerance `path` (module docs; before the
    /// convexity factor of a wall that grows steeper downwards). The planner
    /// spaces its levels so; `scallop run --plan-only` estimates with it.
    #[must_use]
    pub fn level_spacing(&self, cutter: &Cutter, sh: f64, path: f64, slope: f64) -> f64 {
        let s = if slope.is_finite() { slope } else { self.threshold - self.overlap };
        // The push-out adds its width to the material left on the wall.
        let sh = sh - tol::LEVEL_PUSH_CHORDS * (tol::LEVEL_CHORD_SHARE * path);
        (tol::LEVEL_SPACING_SAFETY * level_dz(cutter.shape(), sh, s)).max(tol::MIN_SPACING)
    }

    fn check(&self) -> Result<(), StrategyError> {
        let ok = self.threshold.is_finite()
            && self.overlap.is_finite()
            && self.overlap >= 0.0
            && self.threshold - self.overlap > 0.0
            && self.threshold + self.overlap < std::f64::consts::FRAC_PI_2;
        if ok {
            Ok(())
        } else {
            Err(StrategyError::BadParameter {
                name: "steep_threshold",
                value: self.threshold.to_degrees(),
                fix: "give a slope threshold in degrees with threshold +- overlap inside (0, 90), e.g. 45",
            })
        }
    }
}

/// On a wall that grows steeper downwards (convex in its vertical section,
/// curvature `k` from the slopes `s0` at the upper level `z0` and `s1` at the
/// lower `z1`), the profile circles leave a higher cusp than on a plane:
/// `d^2 (1 / rho + k) / 8` instead of `d^2 / (8 rho)`, so the level spacing
/// shrinks by `1 / sqrt(1 + rho k)`; `None` when it would change by less than
/// 1 % (or for a flat end or a cone). The planner applies it between two
/// levels; `scallop run --plan-only` estimates with it.
#[must_use]
pub fn convex_factor(shape: &CutterShape, (z0, s0): (f64, f64), (z1, s1): (f64, f64)) -> Option<f64> {
    let rho = match *shape {
        CutterShape::Ball { radius } => radius,
        CutterShape::Bull { corner, .. } => corner,
        CutterShape::Flat { .. } | CutterShape::Cone { .. } => return None,
    };
    if !(s0.is_finite() && s1.is_finite() && s1 > s0) {
        return None;
    }
    let along = (z0 - z1) / (0.5 * (s0 + s1)).sin().max(1e-9);
    let factor = 1.0 / (1.0 + rho * (s1 - s0) / along).sqrt();
    (factor < 0.99).then_some(factor)
}

/// The largest residual (mm, from the lowest surface the cutter can reach)
/// that two levels `dz` apart leave across a concave crease where a wall of
/// slope `upper` (rad, above the crease) meets one of slope `lower` (below;
/// `lower < upper`): in the vertical section across a horizontal crease, the
/// profile circles' centres (radius `rho`: the ball radius, the corner radius
/// of a bull-nose) run on two lines meeting at the centre `C` of the circle
/// that touches both walls; the reach there is that circle, and the cusp of
/// the two levels' circles (one on each line, `dz` apart in height, at every
/// split of `dz` between the lines) stands `rho - dist(cusp, centre lines)`
/// above it. On a straight wall (`upper == lower`) this is the scallop of the
/// circles `dz / sin s` apart; a crease adds about `dz sin(deflection / 2)`,
/// linear in `dz`, where the spacing rule assumes the quadratic law.
/// 0 for a flat end or a cone (no profile circle), `f64::INFINITY` where the
/// circles do not meet.
#[must_use]
pub fn crease_residual(shape: &CutterShape, upper: f64, lower: f64, dz: f64) -> f64 {
    let rho = match *shape {
        CutterShape::Ball { radius } => radius,
        CutterShape::Bull { corner, .. } => corner,
        CutterShape::Flat { .. } | CutterShape::Cone { .. } => return 0.0,
    };
    if !(dz > 0.0 && upper > lower && lower > 0.0) {
        return 0.0;
    }
    let (u1, u2) = (Vec2::new(-upper.cos(), upper.sin()), Vec2::new(lower.cos(), -lower.sin()));
    // The part lies on the side away from the walls' mean normal.
    let normal = Vec2::new(upper.sin() + lower.sin(), upper.cos() + lower.cos());
    let to_lines = |x: Vec2| {
        [u1, u2]
            .iter()
            .map(|u| if x.dot(u) <= 0.0 { x.norm() } else { (x - u * x.dot(u)).norm() })
            .fold(f64::INFINITY, f64::min)
    };
    let top = dz / upper.sin();
    let mut worst = 0.0_f64;
    for k in 0..=tol::CREASE_SPLITS {
        #[allow(clippy::cast_precision_loss, reason = "a small count")]
        let a = top * (k as f64 / tol::CREASE_SPLITS as f64);
        let b = (dz - a * upper.sin()) / lower.sin();
        let (c1, c2) = (u1 * a, u2 * b);
        let chord = c2 - c1;
        let half = 0.5 * chord.norm();
        if half >= rho {
            return f64::INFINITY;
        }
        let across = Vec2::new(-chord.y, chord.x) / (2.0 * half).max(f64::MIN_POSITIVE);
        let side = if across.dot(&normal) > 0.0 { -1.0 } else { 1.0 };
        let cusp = (c1 + c2) * 0.5 + across * (side * (rho * rho - half * half).sqrt());
        worst = worst.max(rho - to_lines(cusp));
    }
    worst
}

/// The plane step-over (along the wall's horizontal projection) of parallel
/// planes across a slope `s`, from the analysis model.
fn plane_step(shape: &CutterShape, sh: f64, s: f64) -> f64 {
    let model = match *shape {
        CutterShape::Ball { radius } => scallop_analysis::Cutter::Ball { radius },
        CutterShape::Bull { radius, corner } => scallop_analysis::Cutter::Toroidal { radius, corner },
        CutterShape::Flat { radius } | CutterShape::Cone { radius, .. } => {
            scallop_analysis::Cutter::Toroidal { radius, corner: 0.0 }
        }
    };
    model.step_over(sh, s, std::f64::consts::FRAC_PI_2)
}

/// The level spacing (mm) that holds `sh` on a wall of slope `s` (module docs).
fn level_dz(shape: &CutterShape, sh: f64, s: f64) -> f64 {
    let rho = match *shape {
        CutterShape::Ball { radius } => radius,
        CutterShape::Bull { corner, .. } => corner,
        CutterShape::Flat { radius } | CutterShape::Cone { radius, .. } => {
            return (sh / s.cos().max(1e-9)).min(radius);
        }
    };
    let along = 2.0 * (2.0 * rho * sh - sh * sh).max(0.0).sqrt();
    (along * s.sin()).min(shape.radius())
}

/// The result of [`plan_steep_shallow`].
#[derive(Debug, Clone, PartialEq)]
pub struct SteepPlanned {
    /// Shallow passes, then the levels.
    pub toolpath: Toolpath,
    /// The parallel planes of the shallow triangles (`None`: no shallow triangle).
    pub shallow: Option<Planned>,
    /// Waterline levels with at least one pass.
    pub levels: usize,
    /// Tip heights of the levels with a pass, from the top down (mm).
    pub level_heights: Vec<f64>,
    /// Passes on the levels (runs of steep contact).
    pub steep_passes: usize,
    /// Times, lengths and counts of the whole toolpath; the scallop is the
    /// shallow planner's (the levels are proven by the stock simulation).
    pub report: Report,
}

/// Plans steep-and-shallow finishing of `mesh` (indexed by `index`): see the
/// module docs. The planes and levels of `refine` are added to those the
/// planner places (see [`Refinement`]; `Refinement::default()` adds none).
///
/// # Errors
/// As [`crate::plan_finishing`] for the shallow planes; a bad split
/// ([`StrategyError::BadParameter`]); a waterline failure
/// ([`StrategyError::Waterline`]).
pub fn plan_steep_shallow(
    mesh: &TriMesh,
    index: &MeshIndex,
    cutter: &Cutter,
    params: &FinishingParams,
    tol_: &Tolerances,
    split: &SteepShallow,
    refine: &Refinement,
) -> Result<SteepPlanned, StrategyError> {
    params.validate()?;
    split.check()?;
    if matches!(cutter.shape(), CutterShape::Cone { .. }) {
        return Err(StrategyError::Unsupported { shape: "cone" });
    }
    let slopes: Vec<f64> = (0..mesh.triangles().len()).map(|t| triangle_slope(&mesh.triangle(t))).collect();
    let labels: Vec<u32> = slopes.iter().map(|&s| u32::from(s >= split.threshold + split.overlap)).collect();
    let shallow = if labels.contains(&0) {
        let region = ZoneRegion::new(mesh, &labels, 0, 0.0)?;
        match crate::plan(index, cutter, params, tol_, Some(&region), true, &refine.planes) {
            Ok(p) => Some(p),
            Err(StrategyError::EmptyRegion { .. }) => None,
            Err(e) => return Err(e),
        }
    } else {
        None
    };
    let steep_min = split.threshold - split.overlap;
    let mut toolpath = Toolpath::new(params.machine.feed * 60.0);
    toolpath.plunge_feed = params.plunge_feed * 60.0;
    if let Some(p) = &shallow {
        toolpath.extend_from(&p.toolpath);
    }
    let steep_z = steep_range(mesh, &slopes, steep_min);
    let (levels, steep_passes, level_heights) = match steep_z {
        Some(range) => {
            let mut levels = Levels::new(index, cutter, params, tol_, split, range)?;
            levels.flats = flat_heights(mesh, &slopes, tol_.path);
            levels.extra.clone_from(&refine.levels);
            levels.append_to(&mut toolpath)?
        }
        None => (0, 0, Vec::new()),
    };
    if shallow.is_none() && steep_passes == 0 {
        return Err(StrategyError::EmptyRegion { direction_deg: params.direction.to_degrees() });
    }
    let mut report = Report::timed(&toolpath, params);
    if let Some(p) = &shallow {
        report.passes = p.report.passes;
        report.planes = p.report.planes;
        report.links = p.report.links;
        report.max_scallop_mm = p.report.max_scallop_mm;
        report.mean_scallop_mm = p.report.mean_scallop_mm;
        report.cl_points_dropped = p.report.cl_points_dropped;
    }
    report.passes += steep_passes;
    report.planes += levels;
    Ok(SteepPlanned { toolpath, shallow, levels, level_heights, steep_passes, report })
}

/// Slope of a triangle from the horizontal (rad, 0 to pi/2; facing down
/// counts as steep as facing up).
fn triangle_slope(t: &[Point3; 3]) -> f64 {
    let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
    let len = n.norm();
    if len > 0.0 { (n.z.abs() / len).min(1.0).acos() } else { 0.0 }
}

/// The z range of the triangles at least `steep_min` steep, `None` without any.
fn steep_range(mesh: &TriMesh, slopes: &[f64], steep_min: f64) -> Option<(f64, f64)> {
    let mut range: Option<(f64, f64)> = None;
    for (t, &s) in slopes.iter().enumerate() {
        if s < steep_min {
            continue;
        }
        for p in mesh.triangle(t) {
            range = Some(range.map_or((p.z, p.z), |(lo, hi)| (lo.min(p.z), hi.max(p.z))));
        }
    }
    range
}

/// Distinct heights of the part's horizontal triangles (within `resolution`),
/// highest first.
fn flat_heights(mesh: &TriMesh, slopes: &[f64], resolution: f64) -> Vec<f64> {
    let mut zs: Vec<f64> = slopes
        .iter()
        .enumerate()
        .filter(|&(_, &s)| s < tol::FLAT_SLOPE)
        .map(|(t, _)| mesh.triangle(t).iter().map(|p| p.z).fold(f64::NEG_INFINITY, f64::max))
        .collect();
    zs.sort_by(|a, b| b.total_cmp(a));
    zs.dedup_by(|a, b| (*a - *b).abs() <= resolution);
    zs
}

/// The waterline levels of the steep triangles.
struct Levels<'a> {
    index: &'a MeshIndex,
    cutter: &'a Cutter,
    params: &'a FinishingParams,
    split: &'a SteepShallow,
    grid: WaterlineGrid<'a>,
    /// The loops' chord tolerance, and how far their points are pushed out
    /// (mm): a chord of a convex contour lies inside it by up to this much,
    /// and on a steep wall any inward step is a deep vertical gouge.
    chord: f64,
    /// The path tolerance (mm).
    path: f64,
    slots: Vec<u32>,
    floor: f64,
    /// Lowest and highest level (tip heights, mm).
    z_range: (f64, f64),
    /// Heights of the part's flat areas, highest first: a level runs just
    /// above each, so the foot of a wall standing on a floor is finished, and
    /// looks for the floor's wells its grid misses ([`Levels::wells`]).
    flats: Vec<f64>,
    /// How far above a flat area its level runs (mm, `FLAT_LIFT_SHARE * path`).
    lift: f64,
    /// Levels added to those the spacing rule places ([`Refinement::levels`]).
    extra: Vec<f64>,
}

/// One level's passes and its smallest steep contact slope.
struct Level {
    z: f64,
    passes: Vec<Vec<Point2>>,
    /// The contact slope at each point of `passes` (rad).
    slopes: Vec<Vec<f64>>,
    min_slope: f64,
}

impl<'a> Levels<'a> {
    fn new(
        index: &'a MeshIndex,
        cutter: &'a Cutter,
        params: &'a FinishingParams,
        tol_: &Tolerances,
        split: &'a SteepShallow,
        (lo, hi): (f64, f64),
    ) -> Result<Levels<'a>, StrategyError> {
        let chord = tol::LEVEL_CHORD_SHARE * tol_.path;
        let options = WaterlineOptions { chord_tolerance: chord, ..WaterlineOptions::default() };
        let grid = WaterlineGrid::new(cutter, index, &options).map_err(|e| StrategyError::Waterline(e.to_string()))?;
        let bounds = index.bounds();
        // Tip heights inside the part's range, where the waterline exists.
        let margin = tol::LEVEL_EDGE_SHARE * tol_.path;
        let top = (hi - margin).min(bounds.max.z - margin);
        let bottom = (lo + margin).max(bounds.min.z + margin);
        Ok(Levels {
            index,
            cutter,
            params,
            split,
            grid,
            chord,
            path: tol_.path,
            slots: slots_by_original(index),
            floor: bounds.min.z - bounds.diagonal() - 1.0,
            z_range: (bottom, top.max(bottom)),
            flats: Vec::new(),
            lift: tol::FLAT_LIFT_SHARE * tol_.path,
            extra: Vec::new(),
        })
    }

    /// The passes of the level at tip height `z`: runs of loop points whose
    /// contact is at least `threshold - overlap` steep, in cutting order.
    fn level(&self, z: f64) -> Result<Level, StrategyError> {
        let mut loops = self.grid.loops(z).map_err(|e| StrategyError::Waterline(e.to_string()))?;
        if self.above_flat(z) {
            let wells = self.wells(z, &loops);
            loops.extend(wells);
        }
        let steep_min = self.split.threshold - self.split.overlap;
        let (mut passes, mut pass_slopes) = (Vec::new(), Vec::new());
        let mut min_slope = f64::INFINITY;
        for l in loops {
            let contour = self.tightened(z, &l.points);
            let mut points = pushed_out(&contour, tol::LEVEL_PUSH_CHORDS * self.chord);
            // The contact that lifts the cutter above z: a little inside the
            // loop (its points are where the cutter just clears the part, on a
            // floor level the floor itself).
            let mut slopes: Vec<f64> = pushed_out(&contour, -tol::LEVEL_PROBE_CHORDS * self.chord)
                .iter()
                .map(|p| self.contact_slope(*p))
                .collect();
            if self.split.climb {
                // Loops have their inside (material) on the left: climb puts it right.
                points.reverse();
                slopes.reverse();
            }
            for &s in slopes.iter().filter(|&&s| s >= steep_min) {
                min_slope = min_slope.min(s);
            }
            for run in steep_runs(&slopes, steep_min) {
                passes.push(run.iter().map(|&i| points[i]).collect());
                pass_slopes.push(run.iter().map(|&i| slopes[i]).collect());
            }
        }
        Ok(Level { z, passes, slopes: pass_slopes, min_slope })
    }

    /// Whether `z` runs just above a flat area (within the levels' edge margin,
    /// and the lift for rounding): a floor's level, or the lowest level on the
    /// lowest floor.
    fn above_flat(&self, z: f64) -> bool {
        let margin = tol::LEVEL_EDGE_SHARE * self.path + self.lift;
        self.flats.iter().any(|&f| z > f && z - f <= margin)
    }

    /// The wells of a floor's level at `z` that the waterline grid misses, as
    /// loops (inside on the left) to add to `loops`. In a pocket just wider
    /// than the cutter (a triangle whose inscribed circle is a little larger
    /// than the cutter's), the cutter reaches the floor only in a small region
    /// (the pocket offset inwards by the cutter), which may lie between the
    /// grid's samples: the kernel sees no contour there, and the floor around
    /// it, which a flat bottom reaches from there alone, is left uncut (issue
    /// 15, octagonal_pocket: docs/validation.md). Such a well lies at the
    /// bottom of a valley of the drop-cutter surface, where the cutter hangs
    /// between the pocket's walls: from every sample of the grid above `z`
    /// none of whose eight neighbours is lower (and one higher), a descent
    /// (steps halved down to the chord tolerance) looks for a point where the
    /// cutter at `z` clears the part; one that `loops` count inside the part
    /// is a missed well, whose contour is traced by rays from it.
    fn wells(&self, z: f64, loops: &[Loop]) -> Vec<Loop> {
        let (nx, ny) = self.grid.shape();
        let mut seeds = Vec::new();
        for j in 1..ny.saturating_sub(1) {
            for i in 1..nx.saturating_sub(1) {
                let h = self.grid.height(i, j);
                let around = (j - 1..=j + 1)
                    .flat_map(|jj| (i - 1..=i + 1).map(move |ii| (ii, jj)))
                    .filter(|&at| at != (i, j))
                    .map(|(ii, jj)| self.grid.height(ii, jj));
                let (lowest, higher) = around.fold((true, false), |(l, m), n| (l && n >= h, m || n > h));
                if h > z && lowest && higher {
                    #[allow(clippy::cast_precision_loss, reason = "grid indices")]
                    let at = self.grid.origin() + Vec2::new(i as f64, j as f64) * self.grid.step();
                    seeds.push(at);
                }
            }
        }
        let found: Vec<Option<Point2>> = seeds.par_iter().map(|&at| self.descend(z, at)).collect();
        let mut out: Vec<Loop> = Vec::new();
        for p in found.into_iter().flatten() {
            if loops.iter().chain(&out).map(|l| l.winding_number(p)).sum::<i32>() == 0 {
                continue; // outside already: a contour the grid found
            }
            if let Some(well) = self.well_contour(z, p) {
                out.push(well);
            }
        }
        out
    }

    /// From `start` (where the cutter at `z` cuts into the part), the pattern
    /// search down the drop-cutter surface (eight directions, the step halved
    /// where none is lower) to a point where the cutter at `z` clears the part,
    /// within [`tol::WELL_REACH_STEPS`] grid steps; `None` if there is none.
    fn descend(&self, z: f64, start: Point2) -> Option<Point2> {
        let reach = tol::WELL_REACH_STEPS * self.grid.step();
        let diagonal = std::f64::consts::FRAC_1_SQRT_2;
        let directions = [
            Vec2::new(1.0, 0.0),
            Vec2::new(diagonal, diagonal),
            Vec2::new(0.0, 1.0),
            Vec2::new(-diagonal, diagonal),
            Vec2::new(-1.0, 0.0),
            Vec2::new(-diagonal, -diagonal),
            Vec2::new(0.0, -1.0),
            Vec2::new(diagonal, -diagonal),
        ];
        let (mut p, mut h) = (start, self.above(z, start));
        let mut step = 0.5 * self.grid.step();
        for _ in 0..tol::WELL_DESCENT_MOVES {
            if h <= 0.0 {
                return Some(p);
            }
            if step < self.chord {
                return None;
            }
            let lower = directions
                .iter()
                .map(|d| p + d * step)
                .filter(|q| (q - start).norm() <= reach)
                .map(|q| (self.above(z, q), q))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            match lower {
                Some((hq, q)) if hq < h => (p, h) = (q, hq),
                _ => step *= 0.5,
            }
        }
        None
    }

    /// The contour at `z` of the well around `inside` (where the cutter at `z`
    /// clears the part), inside (the part) on the left: along rays from
    /// `inside`, the first place where the cutter cuts into the part, bisected
    /// to `tol::LEVEL_CHORD_BRACKET` chord tolerances and kept at its clear
    /// end; rays are added between two whose chord leaves the contour by more
    /// than the chord tolerance. `None` when a ray finds no contour within
    /// [`tol::WELL_REACH_STEPS`] grid steps (no small well).
    fn well_contour(&self, z: f64, inside: Point2) -> Option<Loop> {
        let reach = tol::WELL_REACH_STEPS * self.grid.step();
        let ray = |angle: f64| -> Option<Point2> {
            let u = Vec2::new(angle.cos(), angle.sin());
            let (mut clear, mut r) = (0.0, self.chord);
            let mut cut = loop {
                if self.above(z, inside + u * r) > 0.0 {
                    break r;
                }
                if r >= reach {
                    return None;
                }
                clear = r;
                r = (2.0 * r).min(reach);
            };
            let bracket = tol::LEVEL_CHORD_BRACKET * self.chord;
            while cut - clear > bracket {
                let m = 0.5 * (clear + cut);
                if self.above(z, inside + u * m) > 0.0 {
                    cut = m;
                } else {
                    clear = m;
                }
            }
            Some(inside + u * clear)
        };
        let tau = std::f64::consts::TAU;
        #[allow(clippy::cast_precision_loss, reason = "a small count")]
        let first: Vec<f64> = (0..=tol::WELL_RAYS).map(|k| tau * k as f64 / tol::WELL_RAYS as f64).collect();
        let mut points: Vec<(f64, Point2)> = Vec::new();
        for w in first.windows(2) {
            let (a, b) = ((w[0], ray(w[0])?), (w[1], ray(w[1])?));
            self.well_arc(&ray, a, b, 0, &mut points)?;
        }
        // Counter-clockwise around the well: reversed, the part is on the left.
        let mut loop_points: Vec<Point2> = points.into_iter().map(|(_, p)| p).collect();
        loop_points.reverse();
        (loop_points.len() >= 3).then_some(Loop { z, points: loop_points })
    }

    /// The contour points from ray `a` (included) towards ray `b` (excluded),
    /// rays added half-way while the middle one leaves the chord by more than
    /// the chord tolerance (see [`Self::well_contour`]).
    fn well_arc(
        &self,
        ray: &dyn Fn(f64) -> Option<Point2>,
        a: (f64, Point2),
        b: (f64, Point2),
        depth: u32,
        out: &mut Vec<(f64, Point2)>,
    ) -> Option<()> {
        if depth < tol::WELL_RAY_DEPTH {
            let angle = 0.5 * (a.0 + b.0);
            let m = ray(angle)?;
            let chord = b.1 - a.1;
            let off = if chord.norm() > 0.0 {
                (chord.x * (m.y - a.1.y) - chord.y * (m.x - a.1.x)).abs() / chord.norm()
            } else {
                (m - a.1).norm()
            };
            if off > self.chord {
                self.well_arc(ray, a, (angle, m), depth + 1, out)?;
                return self.well_arc(ray, (angle, m), b, depth + 1, out);
            }
        }
        out.push(a);
        Some(())
    }

    /// The closed contour `points` (tip height `z`, inside on the left) with
    /// a contour point added wherever a chord, moved out by the push-out,
    /// has a sample (`tol::LEVEL_CHORD_SAMPLES`) where the cutter at `z`
    /// cuts into the part: the kernel checks a chord at its midpoint only.
    /// Chords in parallel; the result does not depend on the thread count.
    fn tightened(&self, z: f64, points: &[Point2]) -> Vec<Point2> {
        let n = points.len();
        let inserted: Vec<Vec<Point2>> = (0..n)
            .into_par_iter()
            .with_min_len(16)
            .map(|i| {
                let mut out = Vec::new();
                self.tighten_chord(z, points[i], points[(i + 1) % n], 0, &mut out);
                out
            })
            .collect();
        let mut out = Vec::with_capacity(n + inserted.iter().map(Vec::len).sum::<usize>());
        for (p, extra) in points.iter().zip(inserted) {
            out.push(*p);
            out.extend(extra);
        }
        out
    }

    /// Tip height of the drop-cutter at `p` above `z` (0 where nothing
    /// reaches above `z`).
    fn above(&self, z: f64, p: Point2) -> f64 {
        drop_cutter(self.cutter, self.index, p, z).tip.z - z
    }

    /// The contour points to add strictly between `a` and `b` (see
    /// [`Self::tightened`]), in order from `a` to `b`, appended to `out`;
    /// `false` (and nothing added) when the chord cuts into the part and no
    /// polyline within reach clears it: the chord is then kept as the kernel
    /// gave it, never replaced by a detour the samples have not cleared.
    fn tighten_chord(&self, z: f64, a: Point2, b: Point2, depth: u32, out: &mut Vec<Point2>) -> bool {
        let push = tol::LEVEL_PUSH_CHORDS * self.chord;
        let d = b - a;
        let length = d.norm();
        if length <= push {
            return true;
        }
        let outward = Vec2::new(d.y, -d.x) / length; // right of a -> b: away from the material
        // The deepest sample that cuts into the part, if any.
        let mut worst: Option<(f64, Point2)> = None;
        for k in 1..tol::LEVEL_CHORD_SAMPLES {
            #[allow(clippy::cast_precision_loss, reason = "a small count")]
            let t = k as f64 / tol::LEVEL_CHORD_SAMPLES as f64;
            let p = a + d * t + outward * push;
            let h = self.above(z, p);
            if h > 0.0 && worst.is_none_or(|(w, _)| h > w) {
                worst = Some((h, p));
            }
        }
        let Some((_, p)) = worst else { return true };
        if depth >= tol::LEVEL_CHORD_DEPTH {
            return false;
        }
        // The bend of this chord lies within about its length of it.
        let Some(on) = self.contour_outward(z, p, outward, length) else { return false };
        let at = out.len();
        let ok = self.tighten_chord(z, a, on, depth + 1, out) && {
            out.push(on);
            self.tighten_chord(z, on, b, depth + 1, out)
        };
        if !ok {
            out.truncate(at);
        }
        ok
    }

    /// The contour point on the ray from `start` (where the cutter at `z`
    /// cuts into the part) along `outward`: probes at doubling distances up
    /// to `reach`, then bisects to `tol::LEVEL_CHORD_BRACKET` chord
    /// tolerances and returns the outside end (the cutter there clears the
    /// part); `None` if no probe is clear.
    fn contour_outward(&self, z: f64, start: Point2, outward: Vec2, reach: f64) -> Option<Point2> {
        let mut inside = start;
        let mut r = tol::LEVEL_PUSH_CHORDS * self.chord;
        let mut outside = loop {
            let q = start + outward * r;
            if self.above(z, q) <= 0.0 {
                break q;
            }
            if r >= reach {
                return None;
            }
            inside = q;
            r = (2.0 * r).min(reach);
        };
        let bracket = tol::LEVEL_CHORD_BRACKET * self.chord;
        while (outside - inside).norm() > bracket {
            let m = Point2::new(0.5 * (inside.x + outside.x), 0.5 * (inside.y + outside.y));
            if m == inside || m == outside {
                break;
            }
            if self.above(z, m) > 0.0 {
                inside = m;
            } else {
                outside = m;
            }
        }
        Some(outside)
    }

    fn contact_slope(&self, p: Point2) -> f64 {
        let cl: ClPoint = drop_cutter(self.cutter, self.index, p, self.floor);
        let n = contact_normal(self.cutter.shape(), self.index, &self.slots, &cl);
        n.z.abs().min(1.0).acos()
    }

    fn dz(&self, slope: f64) -> f64 {
        self.split.level_spacing(self.cutter, self.params.scallop_height, self.path, slope)
    }

    fn convex_factor(&self, upper: &Level, lower: &Level) -> Option<f64> {
        convex_factor(self.cutter.shape(), (upper.z, upper.min_slope), (lower.z, lower.min_slope))
    }

    /// The scallop height the levels hold: `sh` less the push-out (see
    /// [`SteepShallow::level_spacing`]).
    fn level_sh(&self) -> f64 {
        self.params.scallop_height - tol::LEVEL_PUSH_CHORDS * self.chord
    }

    /// The largest [`crease_residual`] between two levels: each point of
    /// `lower` is paired with the nearest point of `upper` within
    /// `CREASE_REACH` times `dz / tan(threshold - overlap)` in XY (two levels
    /// on walls steeper than that lie closer); where the upper contact is
    /// steeper, a concave crease may lie between them.
    fn crease(&self, upper: &Level, lower: &Level) -> f64 {
        let dz = upper.z - lower.z;
        let steep_min = self.split.threshold - self.split.overlap;
        let radius = (tol::CREASE_REACH * dz / steep_min.tan()).max(tol::MIN_SPACING);
        #[allow(clippy::cast_possible_truncation, reason = "cell indices of a bounded part")]
        let key = |p: &Point2| ((p.x / radius).floor() as i64, (p.y / radius).floor() as i64);
        let mut cells: HashMap<(i64, i64), Vec<(Point2, f64)>> = HashMap::new();
        for (pass, slopes) in upper.passes.iter().zip(&upper.slopes) {
            for (p, &s) in pass.iter().zip(slopes) {
                cells.entry(key(p)).or_default().push((*p, s));
            }
        }
        let mut worst = 0.0_f64;
        for (pass, slopes) in lower.passes.iter().zip(&lower.slopes) {
            for (q, &s_lo) in pass.iter().zip(slopes) {
                let (i, j) = key(q);
                let mut nearest: Option<(f64, f64)> = None;
                for di in -1..=1 {
                    for dj in -1..=1 {
                        for (p, s) in cells.get(&(i + di, j + dj)).into_iter().flatten() {
                            let d = (p - q).norm();
                            if d <= radius && nearest.is_none_or(|(best, _)| d < best) {
                                nearest = Some((d, *s));
                            }
                        }
                    }
                }
                if let Some((_, s_up)) = nearest.filter(|&(_, s_up)| s_up > s_lo) {
                    worst = worst.max(crease_residual(self.cutter.shape(), s_up, s_lo, dz));
                }
            }
        }
        worst
    }

    /// The levels from the top down (module docs), each spaced by the smaller
    /// slope of itself and the next.
    fn all(&self) -> Result<Vec<Level>, StrategyError> {
        let (bottom, top) = self.z_range;
        let mut out = Vec::new();
        let mut current = self.level(top)?;
        loop {
            if current.z <= bottom {
                out.push(current);
                break;
            }
            let mut dz = self.dz(current.min_slope);
            let mut next = self.level(self.next_z(current.z, dz))?;
            if next.min_slope < current.min_slope {
                dz = self.dz(next.min_slope);
                next = self.level(self.next_z(current.z, dz))?;
            } else if let Some(factor) = self.convex_factor(&current, &next) {
                dz *= factor;
                next = self.level(self.next_z(current.z, dz))?;
            }
            for _ in 0..tol::CREASE_RETRIES {
                let residual = self.crease(&current, &next);
                if residual <= self.level_sh() || dz <= tol::MIN_SPACING {
                    break;
                }
                // The crease's residual grows about linearly with dz.
                let ratio = if residual.is_finite() { self.level_sh() / residual } else { 0.5 };
                dz = (dz * ratio * tol::LEVEL_SPACING_SAFETY).max(tol::MIN_SPACING);
                next = self.level(self.next_z(current.z, dz))?;
            }
            out.push(current);
            if out.len() > tol::MAX_LEVELS {
                return Err(StrategyError::TooManyLevels { levels: out.len(), dz, max: tol::MAX_LEVELS });
            }
            current = next;
        }
        self.with_extra(out)
    }

    /// `levels` (from the top down) with a level at each height of
    /// [`Self::extra`] inside the levels' range and not within
    /// [`tol::MIN_SPACING`] of one.
    fn with_extra(&self, mut levels: Vec<Level>) -> Result<Vec<Level>, StrategyError> {
        let (bottom, top) = self.z_range;
        for &z in &self.extra {
            if !(bottom..=top).contains(&z) || levels.iter().any(|l| (l.z - z).abs() <= tol::MIN_SPACING) {
                continue;
            }
            let level = self.level(z)?;
            let at = levels.partition_point(|l| l.z > z);
            levels.insert(at, level);
        }
        Ok(levels)
    }

    /// The level `dz` below `z`, or the level just above a flat area between
    /// them, never below the lowest level.
    fn next_z(&self, z: f64, dz: f64) -> f64 {
        let (bottom, _) = self.z_range;
        let below = (z - dz).max(bottom);
        self.flats.iter().map(|f| f + self.lift).find(|&f| f < z && f > below).unwrap_or(below)
    }

    /// Appends the levels to `path` (after what it holds), each pass entered
    /// from the clearance height or linked from the previous pass's end when the
    /// straight move between them stays above the CL surface; returns (levels
    /// with a pass, passes, the heights of those levels).
    fn append_to(&self, path: &mut Toolpath) -> Result<(usize, usize, Vec<f64>), StrategyError> {
        let clear = self.index.bounds().max.z + self.params.clearance;
        let mut last: Option<Point3> = None;
        let (mut levels, mut count, mut heights) = (0, 0, Vec::new());
        for level in self.all()? {
            if level.passes.is_empty() {
                continue;
            }
            levels += 1;
            heights.push(level.z);
            for pass in order_from(level.passes, last.map(|p| p.xy())) {
                let points: Vec<Point3> = pass.iter().map(|p| Point3::new(p.x, p.y, level.z)).collect();
                let (Some(&start), Some(&end)) = (points.first(), points.last()) else { continue };
                count += 1;
                match last {
                    Some(from) if self.safe_link(&from, &start) => path.push(Move::new(MoveKind::Link, start)),
                    Some(from) => {
                        path.push(Move::new(MoveKind::Retract, Point3::new(from.x, from.y, clear)));
                        path.push(Move::new(MoveKind::Rapid, Point3::new(start.x, start.y, clear)));
                        path.push(Move::new(MoveKind::Plunge, start));
                    }
                    None => {
                        path.push(Move::new(MoveKind::Rapid, Point3::new(start.x, start.y, clear)));
                        path.push(Move::new(MoveKind::Plunge, start));
                    }
                }
                for p in &points[1..] {
                    path.push(Move::new(MoveKind::Feed, *p));
                }
                last = Some(end);
            }
        }
        if let Some(end) = last {
            path.push(Move::new(MoveKind::Retract, Point3::new(end.x, end.y, clear)));
        }
        Ok((levels, count, heights))
    }

    /// Whether the straight move from `a` to `b` stays on or above the
    /// drop-cutter surface at samples `LEVEL_LINK_SAMPLE_CHORDS` chord tolerances apart
    /// (and is short: at most a few step-overs, so it cuts no fresh wall).
    fn safe_link(&self, a: &Point3, b: &Point3) -> bool {
        let radius = self.cutter.radius();
        let length = (b - a).norm();
        if length > tol::LEVEL_LINK_RADII * radius {
            return false;
        }
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small positive count")]
        let n = (length / (tol::LEVEL_LINK_SAMPLE_CHORDS * self.chord)).ceil().max(1.0) as usize;
        (0..=n).all(|k| {
            #[allow(clippy::cast_precision_loss, reason = "a small count")]
            let t = k as f64 / n as f64;
            let p = a + (b - a) * t;
            drop_cutter(self.cutter, self.index, p.xy(), self.floor).tip.z <= p.z
        })
    }
}

/// The closed loop `points` (inside on the left) with every point moved
/// `by` mm to the right, along the bisector of its two edges' right normals.
fn pushed_out(points: &[Point2], by: f64) -> Vec<Point2> {
    let n = points.len();
    let right = |a: &Point2, b: &Point2| {
        let d = b - a;
        let len = d.norm();
        if len > 0.0 { scallop_geom::Vec2::new(d.y, -d.x) / len } else { scallop_geom::Vec2::zeros() }
    };
    (0..n)
        .map(|i| {
            let (prev, next) = (&points[(i + n - 1) % n], &points[(i + 1) % n]);
            let m = right(prev, &points[i]) + right(&points[i], next);
            let len = m.norm();
            if len > 0.0 { points[i] + m / len * by } else { points[i] }
        })
        .collect()
}

/// Maximal runs of `points` (a closed loop) whose `slopes` reach `steep_min`;
/// a loop steep all around comes back closed (its first point again at the end).
fn steep_runs(slopes: &[f64], steep_min: f64) -> Vec<Vec<usize>> {
    let n = slopes.len();
    let keep: Vec<bool> = slopes.iter().map(|&s| s >= steep_min).collect();
    if n < 2 || !keep.contains(&true) {
        return Vec::new();
    }
    if keep.iter().all(|&k| k) {
        let mut closed: Vec<usize> = (0..n).collect();
        closed.push(0);
        return vec![closed];
    }
    // Start right after a dropped point so no run wraps around the start.
    let start = (0..n).find(|&i| !keep[i]).map_or(0, |i| (i + 1) % n);
    let mut runs = Vec::new();
    let mut run: Vec<usize> = Vec::new();
    for k in 0..n {
        let i = (start + k) % n;
        if keep[i] {
            run.push(i);
        } else if !run.is_empty() {
            let done = std::mem::take(&mut run);
            if done.len() >= 2 {
                runs.push(done);
            }
        }
    }
    if run.len() >= 2 {
        runs.push(run);
    }
    runs
}

/// The passes of a level in a near-neighbour order from `from`; a closed pass
/// (first point == last) is turned to start at its point nearest to where the
/// tool is.
fn order_from(mut passes: Vec<Vec<Point2>>, from: Option<Point2>) -> Vec<Vec<Point2>> {
    let mut out = Vec::with_capacity(passes.len());
    let mut at = from;
    while !passes.is_empty() {
        let pick = match at {
            None => 0,
            Some(p) => {
                let d = |pass: &Vec<Point2>| pass.iter().map(|q| (q - p).norm_squared()).fold(f64::INFINITY, f64::min);
                (0..passes.len()).min_by(|&i, &j| d(&passes[i]).total_cmp(&d(&passes[j]))).unwrap_or(0)
            }
        };
        let mut pass = passes.swap_remove(pick);
        if let (Some(p), true) = (at, pass.len() > 2 && pass.first() == pass.last()) {
            pass.pop();
            let k =
                (0..pass.len()).min_by(|&i, &j| (pass[i] - p).norm_squared().total_cmp(&(pass[j] - p).norm_squared()));
            pass.rotate_left(k.unwrap_or(0));
            pass.push(pass[0]);
        }
        at = pass.last().copied();
        out.push(pass);
    }
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Finishing settings of the crate's unit tests: direction 0, sh 0.05 mm.
    pub(crate) fn test_params() -> FinishingParams {
        FinishingParams {
            direction: 0.0,
            pattern: crate::Pattern::Zigzag,
            scallop_height: 0.05,
            boundary: crate::Boundary::ContactInside,
            max_step: 0.5,
            clearance: 5.0,
            machine: scallop_analysis::MachineLimits::default(),
            plunge_feed: 20.0,
            rapid_rate: 500.0,
            sharp_corner: 30f64.to_radians(),
            blend_tolerance: 0.01,
        }
    }

    #[test]
    fn runs_split_a_loop_at_shallow_points_without_wrapping() {
        let slopes = [1.0, 1.0, 0.0, 1.0, 1.0, 1.0];
        let runs = steep_runs(&slopes, 0.5);
        // After the dropped point 2: 3, 4, 5, then 0, 1 (one run across the loop's start).
        assert_eq!(runs, vec![vec![3, 4, 5, 0, 1]]);
        let all = steep_runs(&[1.0; 6], 0.5);
        assert_eq!(all[0].len(), 7);
        assert_eq!(all[0].first(), all[0].last());
    }

    #[test]
    fn crease_residual_is_the_straight_scallop_without_a_crease_and_grows_with_it() {
        let ball = CutterShape::Ball { radius: 1.5 };
        let (s, dz) = (50f64.to_radians(), 0.4);
        // Nearly equal slopes: the circles dz / sin s apart on a straight line.
        let half = 0.5 * dz / s.sin();
        let straight = 1.5 - (1.5 * 1.5 - half * half).sqrt();
        let nearly = crease_residual(&ball, s + 1e-9, s, dz);
        assert!((nearly - straight).abs() < 1e-6, "{nearly} {straight}");
        // A sharper crease leaves more; halving dz leaves much more than a
        // quarter (the linear term of the crease).
        let sharp = crease_residual(&ball, 80f64.to_radians(), 40f64.to_radians(), dz);
        let milder = crease_residual(&ball, 60f64.to_radians(), 40f64.to_radians(), dz);
        assert!(sharp > milder && milder > crease_residual(&ball, 41f64.to_radians(), 40f64.to_radians(), dz));
        let half_dz = crease_residual(&ball, 80f64.to_radians(), 40f64.to_radians(), 0.5 * dz);
        assert!(half_dz > 0.4 * sharp, "{half_dz} {sharp}");
        // No crease (convex or equal slopes) and no profile circle: nothing to add.
        assert!(crease_residual(&ball, s, s, dz).abs() < f64::EPSILON);
        assert!(crease_residual(&CutterShape::Flat { radius: 1.5 }, 1.2, 0.7, dz).abs() < f64::EPSILON);
    }

    /// Brute force in the section: the cusp of the two levels' circles,
    /// measured to the lowest circle over a dense family of centres on the two
    /// centre lines (the reach), agrees with `crease_residual`.
    #[test]
    fn crease_residual_matches_a_dense_family_of_circles() {
        let rho = 1.0;
        let ball = CutterShape::Ball { radius: rho };
        let (upper, lower, dz) = (75f64.to_radians(), 38f64.to_radians(), 0.3);
        let (u1, u2) = (Vec2::new(-upper.cos(), upper.sin()), Vec2::new(lower.cos(), -lower.sin()));
        let mut worst = 0.0_f64;
        for k in 0..=400 {
            let a = dz / upper.sin() * (f64::from(k) / 400.0);
            let b = (dz - a * upper.sin()) / lower.sin();
            let (c1, c2) = (u1 * a, u2 * b);
            // The lower intersection of the two circles, by bisection on the
            // bisector of the chord, below the chord.
            let mid = (c1 + c2) * 0.5;
            let chord = c2 - c1;
            let across = Vec2::new(chord.y, -chord.x) / chord.norm();
            let across = if across.y < 0.0 { across } else { -across };
            let cusp = mid + across * (rho * rho - 0.25 * chord.norm_squared()).sqrt();
            // Distance to the family of centres (both lines, densely).
            let mut nearest = f64::INFINITY;
            for j in 0..=4000 {
                let t = 3.0 * f64::from(j) / 4000.0;
                nearest = nearest.min((cusp - u1 * t).norm()).min((cusp - u2 * t).norm());
            }
            worst = worst.max(rho - nearest);
        }
        let r = crease_residual(&ball, upper, lower, dz);
        assert!((r - worst).abs() < 2e-3 * worst.max(1e-3) + 1e-6, "{r} {worst}");
    }

    /// Two boxes with vertical walls, the second's front wall `stagger` mm
    /// in front of the first's and `gap` mm beyond its end: at mid-height the
    /// waterline runs along the first wall, arcs into a notch and runs along
    /// the second, so a chord from one wall to the other has the contour on
    /// its outside near one end and inside near the other (an S bend, as on
    /// mount_rush at z = -13.525, bull R3 r1: docs/validation.md). The
    /// kernel checks a chord at its midpoint only.
    fn staggered_boxes(shift: f64, stagger: f64, gap: f64) -> TriMesh {
        let mut soup = Vec::new();
        let mut cuboid = |lo: Point3, hi: Point3| {
            let c = |i: usize| {
                Point3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                )
            };
            for [a, b, cc, d] in [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]] {
                soup.push([c(a), c(b), c(cc)]);
                soup.push([c(a), c(cc), c(d)]);
            }
        };
        cuboid(Point3::new(0.0, 0.0, 0.0), Point3::new(10.0 + shift, 10.0, 10.0));
        cuboid(Point3::new(10.0 + shift + gap, -stagger, 0.0), Point3::new(20.0, 10.0, 10.0));
        TriMesh::from_soup(&soup).expect("two boxes").0
    }

    /// The largest height (mm) by which the cutter at a level's height cuts
    /// into the part along the level's passes, sampled every `step` mm.
    fn deepest_cut(levels: &Levels<'_>, level: &Level, step: f64) -> f64 {
        let mut worst = 0.0_f64;
        for pass in &level.passes {
            for w in pass.windows(2) {
                let d = w[1] - w[0];
                #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small count")]
                let n = (d.norm() / step).ceil().max(1.0) as usize;
                for k in 0..=n {
                    #[allow(clippy::cast_precision_loss, reason = "a small count")]
                    let p = w[0] + d * (k as f64 / n as f64);
                    worst = worst.max(levels.above(level.z, p));
                }
            }
        }
        worst
    }

    /// Regression (mount_rush bull R3 r1 sh 0.05 gouged 0.045 mm): whatever
    /// the notch's place on the waterline grid, the level's passes never cut
    /// into the part between their points, with a ball and a bull-nose.
    #[test]
    fn level_chords_never_cut_into_the_part_across_an_s_bend() {
        let params = test_params();
        let tolerances = Tolerances { path: 0.01, gouge: 0.0 };
        let mut cuts = Vec::new();
        for shape in [CutterShape::Ball { radius: 3.0 }, CutterShape::Bull { radius: 3.0, corner: 1.0 }] {
            let cutter = Cutter::new(shape, 30.0).expect("cutter");
            let split = SteepShallow::default_for(&cutter, params.scallop_height);
            for k in 0..64 {
                let mesh = staggered_boxes(f64::from(k) * 0.75 / 64.0, 0.05, 0.15);
                let index = MeshIndex::build(&mesh);
                let levels = Levels::new(&index, &cutter, &params, &tolerances, &split, (0.0, 10.0)).expect("levels");
                let level = levels.level(5.0).expect("level");
                assert!(!level.passes.is_empty());
                cuts.push(deepest_cut(&levels, &level, 1e-3));
            }
        }
        let worst = cuts.iter().copied().fold(0.0, f64::max);
        assert!(worst <= tolerances.path * tol::LEVEL_CHORD_SHARE, "{worst} {cuts:?}");
    }

    /// A triangular plate (circumradius 30 mm, 5 mm thick) with an
    /// equilateral triangular pocket 4 mm deep whose inscribed circle has the
    /// radius `inradius`, its centre at `centre`.
    fn triangle_pocket(centre: Point2, inradius: f64) -> TriMesh {
        let corner = |k: usize, size: f64, at: Point2, z: f64| {
            #[allow(clippy::cast_precision_loss, reason = "a small count")]
            let a = std::f64::consts::FRAC_PI_2 + std::f64::consts::TAU * k as f64 / 3.0;
            Point3::new(at.x + size * a.cos(), at.y + size * a.sin(), z)
        };
        let origin = Point2::origin();
        let (o, t) =
            (|k: usize, z| corner(k % 3, 30.0, origin, z), |k: usize, z| corner(k % 3, 2.0 * inradius, centre, z));
        let mut soup = Vec::new();
        let mut quad = |a: Point3, b: Point3, c: Point3, d: Point3| {
            soup.push([a, b, c]);
            soup.push([a, c, d]);
        };
        for k in 0..3 {
            quad(o(k, 5.0), o(k + 1, 5.0), t(k + 1, 5.0), t(k, 5.0)); // the top around the pocket
            quad(t(k, 1.0), t(k, 5.0), t(k + 1, 5.0), t(k + 1, 1.0)); // the pocket's walls
            quad(o(k, 0.0), o(k + 1, 0.0), o(k + 1, 5.0), o(k, 5.0)); // the outer walls
        }
        soup.push([t(0, 1.0), t(1, 1.0), t(2, 1.0)]);
        soup.push([o(0, 0.0), o(2, 0.0), o(1, 0.0)]);
        TriMesh::from_soup(&soup).expect("a triangular pocket").0
    }

    /// Regression (octagonal_pocket, bull-nose R8 r3 at sh 0.05, 0.0534 mm
    /// over sh: docs/validation.md): in a pocket whose inscribed circle is
    /// 0.1 mm larger than a bull-nose R3 r1, the cutter reaches the floor
    /// only in a triangle 0.35 mm wide, here in the middle of a cell of the
    /// waterline grid (step 0.75 mm), where no sample sees it. The floor's
    /// level runs around that well, with the cutter clear of the part at
    /// every point, wherever in the cell the well lies.
    #[test]
    fn the_floor_level_runs_around_a_well_narrower_than_the_waterline_grid() {
        let params = test_params();
        let tolerances = Tolerances { path: 0.01, gouge: 0.0 };
        let cutter = Cutter::new(CutterShape::Bull { radius: 3.0, corner: 1.0 }, 30.0).expect("cutter");
        let split = SteepShallow::default_for(&cutter, params.scallop_height);
        // The grid's origin depends on the plate only: place the well in its cells.
        let plate = MeshIndex::build(&triangle_pocket(Point2::origin(), 3.1));
        let grid = Levels::new(&plate, &cutter, &params, &tolerances, &split, (0.0, 5.0)).expect("levels");
        let (origin, step) = (grid.grid.origin(), grid.grid.step());
        let mut missing = Vec::new();
        for (fx, fy) in [(0.5, 0.5), (0.3, 0.6), (0.7, 0.35)] {
            let cell = Vec2::new((-origin.x / step).floor() + fx, (-origin.y / step).floor() + fy);
            let centre = origin + cell * step;
            let mesh = triangle_pocket(centre, 3.1);
            let index = MeshIndex::build(&mesh);
            let mut levels = Levels::new(&index, &cutter, &params, &tolerances, &split, (0.0, 5.0)).expect("levels");
            levels.flats = flat_heights(
                &mesh,
                &mesh
                    .triangles()
                    .iter()
                    .enumerate()
                    .map(|(t, _)| triangle_slope(&mesh.triangle(t)))
                    .collect::<Vec<_>>(),
                tolerances.path,
            );
            let z = 1.0 + levels.lift;
            assert!(levels.above(z, centre) <= 0.0, "the cutter reaches the floor at the pocket's centre");
            let level = levels.level(z).expect("level");
            let around = level.passes.iter().any(|pass| {
                let closed = Loop { z, points: pass.clone() };
                closed.winding_number(centre) != 0
                    && pass.iter().all(|p| (p - centre).norm() < 0.5 && levels.above(z, *p) <= 0.0)
            });
            if !around {
                missing.push((fx, fy));
            }
        }
        assert!(missing.is_empty(), "no pass around the well at {missing:?}");
    }

    /// The shallow planes' measure is a report where rest is tolerated: raw
    /// heights, no dense-pass reference (so no rest material subtracted).
    #[test]
    fn the_shallow_report_of_steep_and_shallow_is_the_raw_measure() {
        let params = test_params();
        let tolerances = Tolerances { path: 0.01, gouge: 0.0 };
        let mesh = staggered_boxes(0.0, 0.05, 4.0);
        let index = MeshIndex::build(&mesh);
        let cutter = Cutter::new(CutterShape::Bull { radius: 3.0, corner: 1.0 }, 30.0).expect("cutter");
        let split = SteepShallow::default_for(&cutter, params.scallop_height);
        let p = plan_steep_shallow(&mesh, &index, &cutter, &params, &tolerances, &split, &Refinement::default())
            .expect("plan");
        let shallow = p.shallow.expect("the boxes' tops are shallow");
        assert!(shallow.scallop.samples > 0);
        assert_eq!(shallow.scallop.rest_material_mm, 0.0);
        assert!(shallow.scallop.max_mm.is_finite());
    }

    #[test]
    fn level_spacing_matches_the_profile_circle_on_a_vertical_wall() {
        let ball = CutterShape::Ball { radius: 3.0 };
        let sh: f64 = 0.01;
        let dz = level_dz(&ball, sh, std::f64::consts::FRAC_PI_2);
        // Two circles of radius 3 dz apart on a vertical line leave sh between them.
        let left = 3.0 - (9.0 - (dz / 2.0).powi(2)).sqrt();
        assert!((left - sh).abs() < 1e-12, "{left}");
        let flat = CutterShape::Flat { radius: 3.0 };
        let s = 60f64.to_radians();
        assert!((level_dz(&flat, sh, s) * s.cos() - sh).abs() < 1e-15);
    }
}
