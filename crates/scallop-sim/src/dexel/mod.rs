//! The tri-dexel stock: three families of rays along X, Y and Z, each ray a
//! sorted list of material intervals, cut by cutters with any tool axis.
//!
//! See [`DexelStock`]. The swept solid of a cutter along a straight move with
//! a fixed axis is solved per ray exactly (closed forms per piece of the
//! cutter) or by a certified bracket ([`sweep`]); simultaneous 5-axis moves
//! are split into sub-steps with a fixed axis each ([`DexelOptions::axis_tolerance`]).

mod body;
mod sweep;
mod verify;

use std::fmt;
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;
use scallop_cutter::Cutter;
use scallop_geom::{Aabb3, Eps, Point2, Point3, Vec3};
use scallop_toolpath::{ArcXY, MoveKind, Toolpath};

use crate::envelope::SweptMove;
use crate::tol::ARC_SAGITTA;
use crate::{MoveId, RapidHit, SimError, ToolPart};
use body::Body;
use sweep::Sweep;

pub use verify::{DexelGouge, DexelPart, DexelVerification, verify_dexel};

/// The largest total number of rays of a [`DexelStock`].
pub const MAX_RAYS: usize = 32_000_000;

/// The largest number of fixed-axis sub-steps of one simultaneous 5-axis move.
pub const MAX_SUBSTEPS: usize = 100_000;

/// Rows of rays per band: the unit of parallel work (fixed, so results do not
/// depend on the thread count).
const BAND_ROWS: usize = 4;

/// One move of a multi-axis program: the tool tip goes in a straight line to
/// `tip` (or along `arc`) while the unit tool axis (from the tip towards the
/// spindle) turns from the previous move's axis to `axis` (on the great
/// circle, at a constant angular rate).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolMove {
    /// Kind of move.
    pub kind: MoveKind,
    /// End point of the tool tip (mm, part frame).
    pub tip: Point3,
    /// Unit tool axis at the end of the move.
    pub axis: Vec3,
    /// The XY circle of a circular (or helical) move, as in
    /// [`Toolpath::arc`]: cut as chords within [`crate::tol::ARC_SAGITTA`].
    pub arc: Option<ArcXY>,
}

impl ToolMove {
    /// A straight move.
    #[must_use]
    pub fn new(kind: MoveKind, tip: Point3, axis: Vec3) -> ToolMove {
        ToolMove { kind, tip, axis, arc: None }
    }

    /// The moves of a toolpath with their tool axes ([`Toolpath::axis`]: +Z for
    /// a 3-axis path), arcs kept.
    #[must_use]
    pub fn from_toolpath(path: &Toolpath) -> Vec<ToolMove> {
        path.moves()
            .iter()
            .enumerate()
            .map(|(i, m)| ToolMove { kind: m.kind, tip: m.to, axis: path.axis(i), arc: path.arc(i) })
            .collect()
    }
}

/// Algorithm knobs of [`DexelStock::cut`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DexelOptions {
    /// Largest distance (mm) between the simulated and the true swept solid
    /// of a simultaneous 5-axis move. Such a move is cut as `n` sub-steps,
    /// each a straight move with the axis fixed at its middle, where the axis
    /// turns by at most `2 axis_tolerance / l` per sub-step, `l` the largest
    /// distance from the tip to a point of the flutes; every point of the
    /// cutter then lies within `l dtheta / 2 <= axis_tolerance` of where it
    /// truly is at the same tip position (see `docs/simulation.md`). Moves
    /// with a fixed axis (3-axis, 3+2) are exact and never split.
    pub axis_tolerance: f64,
    /// Check the shank and the holder against the in-process stock.
    pub check_collisions: bool,
    /// Search the smallest stick-out (the tool's length out of the holder)
    /// up to this length (mm) at which neither the shank nor the holder meets
    /// the in-process stock along the whole cut, the tool otherwise the same
    /// ([`DexelReport::min_stick_out`]); `None`: no search.
    pub max_stick_out: Option<f64>,
}

impl Default for DexelOptions {
    /// 0.01 mm for 5-axis moves; collisions checked; no stick-out search.
    fn default() -> Self {
        DexelOptions { axis_tolerance: 0.01, check_collisions: true, max_stick_out: None }
    }
}

/// The smallest collision-free stick-out of a cut
/// ([`DexelOptions::max_stick_out`]).
///
/// The in-process stock at each fixed-axis sweep depends on the flutes only,
/// so one cut serves every stick-out: each sweep's shank and holder, held at
/// the smallest length found so far, are checked on the rays against the
/// stock left by the sweeps before it (as the collision check is, the same
/// epsilon); where they meet it the length is bisected up, for that sweep
/// and ray, to within [`crate::tol::STICK_OUT_TOL`]. The result is the
/// smallest length at which the collision check of the same cut would find
/// nothing, provided a longer stick-out never collides where a shorter one
/// did not: true when no segment of the holder is narrower than the shank or
/// than a segment below it, and no stock stands above the holder's top;
/// otherwise a length found by the same bisection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StickOut {
    /// The length (mm): the flute length when nothing above the flutes meets
    /// the stock; the largest length searched when even that one collides.
    pub length: f64,
    /// The move that asks for it and the middle of the stock piece the shank
    /// or holder meets just below it; `None` when the flutes alone suffice.
    pub limit: Option<(MoveId, Point3)>,
    /// Whether even the largest length searched meets the stock.
    pub exceeded: bool,
}

/// A move that drove the shank or holder into the in-process stock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DexelCollision {
    /// The move.
    pub id: MoveId,
    /// The part of the tool.
    pub part: ToolPart,
    /// Middle of the deepest stock piece inside the part of the tool.
    pub at: Point3,
    /// Length of that piece along its ray (mm).
    pub depth: f64,
}

impl fmt::Display for DexelCollision {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} drives the {} {:.4} mm into the stock at ({:.3}, {:.3}, {:.3})",
            self.id,
            self.part.name(),
            self.depth,
            self.at.x,
            self.at.y,
            self.at.z
        )
    }
}

/// What one [`DexelStock::cut`] did, move by move.
#[derive(Debug, Clone, PartialEq)]
pub struct DexelReport {
    /// The operation number given to this call's [`MoveId`]s.
    pub operation: u32,
    /// Volume removed by each move (mm^3, measured on the Z rays), in program order.
    pub removed_by_move: Vec<f64>,
    /// Total removed volume (mm^3): the sum of `removed_by_move`.
    pub removed_volume: f64,
    /// Number of [`MoveKind::Feed`] moves.
    pub feed_moves: usize,
    /// Feed moves that removed no more than the stock's rounding epsilon from any ray.
    pub air_feed_moves: usize,
    /// Number of fixed-axis sweeps the moves were cut as (equal to the
    /// number of moves for 3-axis and 3+2 programs).
    pub sweeps: usize,
    /// Rapid and retract moves that removed stock, in program order (errors).
    /// `at` is the XY of the deepest removal, `depth` its length along its ray.
    pub rapid_hits: Vec<RapidHit>,
    /// Shank and holder collisions with the in-process stock, in program order (errors).
    pub collisions: Vec<DexelCollision>,
    /// The smallest collision-free stick-out ([`DexelOptions::max_stick_out`]).
    pub min_stick_out: Option<StickOut>,
}

impl DexelReport {
    /// Share of feed moves that cut air, in [0, 1] (0 when there are none).
    #[must_use]
    pub fn air_cut_share(&self) -> f64 {
        crate::zmap::air_share(self.air_feed_moves, self.feed_moves)
    }

    /// The safety verdict of the cut: rapid hits first, then collisions.
    ///
    /// # Errors
    /// [`SimError::RapidIntoStock`], then [`SimError::DexelCollision`].
    pub fn check(&self) -> Result<(), SimError> {
        crate::zmap::safety_verdict(&self.rapid_hits, &self.collisions, |collisions| SimError::DexelCollision {
            collisions,
        })
    }
}

/// The material of one ray: untouched (the whole extent, no heap), or a
/// sorted list of disjoint intervals.
#[derive(Debug, Clone, PartialEq)]
enum Ray {
    Full,
    Cut(Vec<[f64; 2]>),
}

impl Ray {
    /// Whether any material lies in the open interval (a, b).
    fn has_material(&self, a: f64, b: f64, lo: f64, hi: f64) -> bool {
        match self {
            Ray::Full => a < hi && b > lo,
            Ray::Cut(v) => v.iter().any(|s| s[0] < b && s[1] > a),
        }
    }

    /// The hull of the material inside (a, b), if any.
    fn material_range(&self, a: f64, b: f64, lo: f64, hi: f64) -> Option<(f64, f64)> {
        match self {
            Ray::Full => (a < hi && b > lo).then(|| (a.max(lo), b.min(hi))),
            Ray::Cut(v) => {
                let first = v.iter().find(|s| s[1] > a && s[0] < b)?;
                let last = v.iter().rev().find(|s| s[1] > a && s[0] < b)?;
                Some((first[0].max(a), last[1].min(b)))
            }
        }
    }

    /// Material length inside [a, b].
    fn overlap(&self, a: f64, b: f64, lo: f64, hi: f64) -> (f64, f64) {
        let piece = |s: [f64; 2]| {
            let (x, y) = (s[0].max(a), s[1].min(b));
            if y > x { (y - x, 0.5 * (x + y)) } else { (0.0, 0.0) }
        };
        match self {
            Ray::Full => piece([lo, hi]),
            Ray::Cut(v) => v.iter().map(|&s| piece(s)).fold((0.0, 0.0), |best, p| if p.0 > best.0 { p } else { best }),
        }
    }

    /// Removes [a, b]; returns the removed length and the middle of the
    /// longest removed piece.
    fn subtract(&mut self, a: f64, b: f64, lo: f64, hi: f64) -> (f64, f64, f64) {
        if b <= a || a.is_nan() || b.is_nan() || !self.has_material(a, b, lo, hi) {
            return (0.0, 0.0, 0.0);
        }
        let old = match std::mem::replace(self, Ray::Cut(Vec::new())) {
            Ray::Full => vec![[lo, hi]],
            Ray::Cut(v) => v,
        };
        let mut out = Vec::with_capacity(old.len() + 1);
        let (mut removed, mut longest, mut mid) = (0.0, 0.0, 0.0);
        for s in old {
            if s[1] <= a || s[0] >= b {
                out.push(s);
                continue;
            }
            let (x, y) = (s[0].max(a), s[1].min(b));
            removed += y - x;
            if y - x > longest {
                longest = y - x;
                mid = 0.5 * (x + y);
            }
            if s[0] < a {
                out.push([s[0], a]);
            }
            if s[1] > b {
                out.push([b, s[1]]);
            }
        }
        *self = Ray::Cut(out);
        (removed, longest, mid)
    }

    fn intervals(&self, lo: f64, hi: f64) -> Vec<[f64; 2]> {
        match self {
            Ray::Full => vec![[lo, hi]],
            Ray::Cut(v) => v.clone(),
        }
    }

    fn length(&self, lo: f64, hi: f64) -> f64 {
        match self {
            Ray::Full => hi - lo,
            Ray::Cut(v) => v.iter().map(|s| s[1] - s[0]).sum(),
        }
    }
}

/// One fixed-axis sweep of a move (a whole move, or a sub-step of a 5-axis one).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Step {
    /// The move's index in its toolpath.
    index: u32,
    operation: u32,
    sweep: Sweep,
    rapid: bool,
    /// Box of the flutes' sweep.
    lo: Point3,
    hi: Point3,
}

/// Box of a body swept with a fixed axis between two tip positions: exact,
/// from the body's support function in the six axis directions, grown by `margin`.
fn swept_box(body: &Body, sweep: &Sweep, margin: f64) -> (Point3, Point3) {
    let mut lo = Point3::origin();
    let mut hi = Point3::origin();
    for i in 0..3 {
        let mut e = Vec3::zeros();
        e[i] = 1.0;
        let up = body.support(&sweep.a, &e).0;
        let down = body.support(&sweep.a, &(-e)).0;
        let (a, b) = (sweep.p0[i], sweep.p0[i] + sweep.v[i]);
        lo[i] = a.min(b) - down - margin;
        hi[i] = a.max(b) + up + margin;
    }
    (lo, hi)
}

/// Axis at fraction `t` of the great circle from `a` to `b` (unit vectors,
/// angle `theta` between them, below pi).
fn slerp(a: &Vec3, b: &Vec3, theta: f64, t: f64) -> Vec3 {
    if theta < 1e-9 {
        return (a + t * (b - a)).normalize();
    }
    let s = theta.sin();
    (((1.0 - t) * theta).sin() / s * a + (t * theta).sin() / s * b).normalize()
}

/// The tri-dexel stock: for each axis `k` (0 = X, 1 = Y, 2 = Z) a regular grid
/// of rays along `k` over the other two axes `u = (k + 1) % 3`,
/// `v = (k + 2) % 3`, at cell centres (cells of at most the resolution, tiling
/// the stock box exactly as in [`crate::ZMap`]), each ray holding its material
/// as sorted disjoint intervals of the coordinate along `k`. The Z rays sit on
/// the same XY cell centres as a `ZMap` of the same box and resolution.
///
/// ```
/// use scallop_geom::{Aabb3, Point3};
/// use scallop_sim::DexelStock;
/// let stock = Aabb3 { min: Point3::new(0.0, 0.0, -5.0), max: Point3::new(10.0, 4.0, 0.0) };
/// let dexels = DexelStock::new(stock, 0.5).unwrap();
/// assert_eq!(dexels.counts(), [20, 8, 10]);
/// assert_eq!(dexels.volume(), 200.0);
/// assert_eq!(dexels.intervals(2, 3, 4), vec![[-5.0, 0.0]]);
/// ```
#[derive(Debug, Clone)]
pub struct DexelStock {
    stock: Aabb3,
    n: [usize; 3],
    cell: [f64; 3],
    rays: [Vec<Ray>; 3],
    eps: f64,
    operations: u32,
    /// Every fixed-axis sweep cut so far, with its operation's flutes (for
    /// naming the move behind a gouge).
    history: Vec<Step>,
    bodies: Vec<Body>,
    /// Volume of the stock before any cut (mm^3), in the sum of [`DexelStock::volume`].
    initial: f64,
}

impl DexelStock {
    /// A full stock box with rays `resolution` (mm) apart or closer.
    ///
    /// # Errors
    /// [`SimError::BadResolution`], [`SimError::BadStock`],
    /// [`SimError::TooManyRays`] beyond [`MAX_RAYS`].
    pub fn new(stock: Aabb3, resolution: f64) -> Result<DexelStock, SimError> {
        crate::zmap::check_stock(&stock, resolution)?;
        let size = stock.size();
        let f = [size.x, size.y, size.z].map(|w| crate::zmap::cells_along(w, resolution));
        let total = f[0] * f[1] + f[1] * f[2] + f[2] * f[0];
        if total > MAX_RAYS as f64 {
            // Saturating conversion: only used in the message.
            return Err(SimError::TooManyRays { rays: total as usize, limit: MAX_RAYS });
        }
        // Below MAX_RAYS: exact conversions.
        let n = [f[0] as usize, f[1] as usize, f[2] as usize];
        let cell = [size.x / f[0], size.y / f[1], size.z / f[2]];
        let rays = [0, 1, 2].map(|k| vec![Ray::Full; n[(k + 1) % 3] * n[(k + 2) % 3]]);
        let mut dexels = DexelStock {
            stock,
            n,
            cell,
            rays,
            eps: Eps::for_bounds(&stock).0,
            operations: 0,
            history: Vec::new(),
            bodies: Vec::new(),
            initial: 0.0,
        };
        let area = cell[0] * cell[1];
        let column = stock.max.z - stock.min.z;
        dexels.initial = (0..n[1]).map(|_| (0..n[0]).map(|_| column).sum::<f64>() * area).sum();
        Ok(dexels)
    }

    /// A stock that is the material of a closed `solid` (a turned or cast
    /// blank) inside the box `stock`, with rays `resolution` (mm) apart or
    /// closer: each ray holds the solid's intervals along it, clipped to the
    /// box (exact crossings, see [`DexelPart`]).
    ///
    /// # Errors
    /// As [`DexelStock::new`], and [`SimError::OpenBlank`] when `solid` is not
    /// closed (a height field has no inside to start from).
    pub fn from_solid(stock: Aabb3, resolution: f64, solid: &DexelPart) -> Result<DexelStock, SimError> {
        if !solid.is_closed() {
            return Err(SimError::OpenBlank);
        }
        let mut dexels = DexelStock::new(stock, resolution)?;
        for axis in 0..3 {
            let material = solid.family_material(&dexels, axis);
            dexels.rays[axis] = material
                .into_iter()
                .map(|spans| {
                    let mut merged: Vec<[f64; 2]> = Vec::with_capacity(spans.len());
                    for s in spans {
                        match merged.last_mut() {
                            Some(last) if s[0] <= last[1] => last[1] = last[1].max(s[1]),
                            _ => merged.push(s),
                        }
                    }
                    Ray::Cut(merged)
                })
                .collect();
        }
        dexels.initial = dexels.volume();
        Ok(dexels)
    }

    /// Cells along X, Y and Z.
    #[must_use]
    pub fn counts(&self) -> [usize; 3] {
        self.n
    }

    /// Cell size along X, Y and Z (mm), each at most the resolution asked for.
    #[must_use]
    pub fn cell_size(&self) -> [f64; 3] {
        self.cell
    }

    /// The stock box.
    #[must_use]
    pub fn stock(&self) -> Aabb3 {
        self.stock
    }

    /// The rounding epsilon of the stock (mm): removals below it do not count as cuts.
    #[must_use]
    pub fn eps(&self) -> f64 {
        self.eps
    }

    /// Rays of family `axis` as (count along `u`, count along `v`).
    #[must_use]
    pub fn grid(&self, axis: usize) -> (usize, usize) {
        (self.n[(axis + 1) % 3], self.n[(axis + 2) % 3])
    }

    /// The point of ray `(iu, iv)` of family `axis` whose coordinate along
    /// `axis` is 0 (the ray is that point plus `s e_axis`).
    #[must_use]
    pub fn ray_origin(&self, axis: usize, iu: usize, iv: usize) -> Point3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let mut o = Point3::origin();
        // Indices far below 2^52: exact.
        o[u] = self.stock.min[u] + (iu as f64 + 0.5) * self.cell[u];
        o[v] = self.stock.min[v] + (iv as f64 + 0.5) * self.cell[v];
        o
    }

    /// The material intervals of ray `(iu, iv)` of family `axis` (coordinates
    /// along `axis`, sorted); empty outside the grid.
    #[must_use]
    pub fn intervals(&self, axis: usize, iu: usize, iv: usize) -> Vec<[f64; 2]> {
        let (nu, nv) = self.grid(axis);
        if axis > 2 || iu >= nu || iv >= nv {
            return Vec::new();
        }
        self.rays[axis][iv * nu + iu].intervals(self.stock.min[axis], self.stock.max[axis])
    }

    /// Whether ray `(iu, iv)` of family `axis` is still untouched (holds no heap memory).
    #[must_use]
    pub fn is_untouched(&self, axis: usize, iu: usize, iv: usize) -> bool {
        let (nu, _) = self.grid(axis);
        matches!(self.rays.get(axis).and_then(|r| r.get(iv * nu + iu)), Some(Ray::Full))
    }

    /// Highest material point of each Z ray, row-major with X fastest (the
    /// cells of a [`crate::ZMap`] of the same box and resolution); the stock
    /// bottom where a ray is empty.
    #[must_use]
    pub fn top_heights(&self) -> Vec<f64> {
        let (lo, hi) = (self.stock.min.z, self.stock.max.z);
        self.rays[2]
            .iter()
            .map(|r| match r {
                Ray::Full => hi,
                Ray::Cut(v) => v.last().map_or(lo, |s| s[1]),
            })
            .collect()
    }

    /// Volume of stock left (mm^3), summed over the rays of family `axis`
    /// (interval lengths times the cell area, in ray order).
    #[must_use]
    pub fn volume_along(&self, axis: usize) -> f64 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let area = self.cell[u] * self.cell[v];
        let (lo, hi) = (self.stock.min[axis], self.stock.max[axis]);
        let nu = self.n[u];
        self.rays[axis].chunks(nu).map(|row| row.iter().map(|r| r.length(lo, hi)).sum::<f64>() * area).sum()
    }

    /// Volume of stock left (mm^3), measured on the Z rays.
    #[must_use]
    pub fn volume(&self) -> f64 {
        self.volume_along(2)
    }

    /// Volume of the stock before any cut (mm^3; the full box, or the blank of
    /// [`DexelStock::from_solid`]), in the same sum as [`DexelStock::volume`].
    #[must_use]
    pub fn initial_volume(&self) -> f64 {
        self.initial
    }

    /// Splits the moves into fixed-axis sweeps.
    fn steps(
        &self,
        operation: u32,
        body: &Body,
        moves: &[ToolMove],
        options: &DexelOptions,
    ) -> Result<Vec<Step>, SimError> {
        let mut steps = Vec::with_capacity(moves.len());
        let mut prev: Option<(Point3, Vec3)> = None;
        let max_turn = 2.0 * options.axis_tolerance / body.reach();
        for (index, m) in moves.iter().enumerate() {
            let len = m.axis.norm();
            let finite = m.tip.coords.iter().chain(m.axis.iter()).all(|c| c.is_finite());
            if !(finite && len > 0.0) {
                return Err(SimError::BadAxis { index, axis: m.axis.into() });
            }
            let axis = m.axis / len;
            let (p0, a0) = prev.unwrap_or((m.tip, axis));
            let theta = a0.cross(&axis).norm().atan2(a0.dot(&axis));
            let mut n = if theta == 0.0 { 1.0 } else { (theta / max_turn).ceil().max(1.0) };
            // An arc: chords whose sagitta r (1 - cos(step / 2)) stays within ARC_SAGITTA.
            let arc = m.arc.filter(|a| a.sweep != 0.0 && prev.is_some()).map(|a| {
                let r = (p0.x - a.center.x).hypot(p0.y - a.center.y);
                let start = (p0.y - a.center.y).atan2(p0.x - a.center.x);
                (a, r, start)
            });
            if let Some((a, r, _)) = arc {
                let step = if r > ARC_SAGITTA { 2.0 * (1.0 - ARC_SAGITTA / r).acos() } else { a.sweep.abs() };
                n = n.max((a.sweep.abs() / step).ceil());
            }
            if theta > std::f64::consts::PI * (1.0 - 1e-6) || n > MAX_SUBSTEPS as f64 {
                return Err(SimError::AxisTurn { index, degrees: theta.to_degrees(), limit: MAX_SUBSTEPS });
            }
            // n <= MAX_SUBSTEPS: exact.
            let n_sub = n as usize;
            let rapid = matches!(m.kind, MoveKind::Rapid | MoveKind::Retract);
            let index32 = u32::try_from(index).map_err(|_| SimError::TooManyMoves { moves: moves.len() })?;
            let tip_at = |t: f64| match arc {
                _ if t >= 1.0 => m.tip,
                Some((a, r, start)) => {
                    let th = start + a.sweep * t;
                    Point3::new(a.center.x + r * th.cos(), a.center.y + r * th.sin(), p0.z + (m.tip.z - p0.z) * t)
                }
                None => p0 + t * (m.tip - p0),
            };
            for i in 0..n_sub {
                let (t0, t1) = (i as f64 / n, (i + 1) as f64 / n);
                let a = if theta == 0.0 { axis } else { slerp(&a0, &axis, theta, 0.5 * (t0 + t1)) };
                let q0 = tip_at(t0);
                let q1 = if i + 1 == n_sub { m.tip } else { tip_at(t1) };
                let sweep = Sweep { p0: q0, v: q1 - q0, a };
                let (lo, hi) = swept_box(body, &sweep, self.eps);
                steps.push(Step { index: index32, operation, sweep, rapid, lo, hi });
            }
            prev = Some((m.tip, axis));
        }
        Ok(steps)
    }

    /// Removes the material swept by the flutes of `cutter` along `moves`.
    /// The first move has no known start: the tool is placed at its end.
    /// Each fixed-axis sweep (see [`DexelOptions::axis_tolerance`]) is
    /// subtracted from every ray crossing its bounding box, exactly (see the
    /// module `sweep`); after each sweep the shank and the holder, swept
    /// the same way, are checked against the in-process stock (when
    /// [`DexelOptions::check_collisions`]): material inside them longer than
    /// the stock's epsilon along a ray goes into [`DexelReport::collisions`].
    /// Rapid and retract moves that remove stock go into
    /// [`DexelReport::rapid_hits`]. Neither stops the cut; use
    /// [`DexelReport::check`].
    ///
    /// Work is parallel over fixed bands of rays of each family; every ray
    /// applies the sweeps in program order, so the result does not depend on
    /// the number of threads.
    ///
    /// # Errors
    /// [`SimError::BadAxis`] (a zero or non-finite axis), [`SimError::AxisTurn`]
    /// (an axis reversal, or more than [`MAX_SUBSTEPS`] sub-steps),
    /// [`SimError::BadTolerance`], [`SimError::TooManyMoves`].
    ///
    /// ```
    /// use scallop_cutter::{Cutter, CutterShape};
    /// use scallop_geom::{Aabb3, Point3, Vec3};
    /// use scallop_sim::{DexelOptions, DexelStock, ToolMove};
    /// use scallop_toolpath::MoveKind;
    /// let stock = Aabb3 { min: Point3::new(0.0, 0.0, -5.0), max: Point3::new(20.0, 10.0, 0.0) };
    /// let mut dexels = DexelStock::new(stock, 0.25).unwrap();
    /// let flat = Cutter::new(CutterShape::Flat { radius: 2.0 }, 10.0).unwrap();
    /// let mv = |kind, x: f64, z: f64| ToolMove::new(kind, Point3::new(x, 5.0, z), Vec3::z());
    /// let path = [mv(MoveKind::Rapid, -3.0, 5.0), mv(MoveKind::Plunge, -3.0, -1.0), mv(MoveKind::Feed, 23.0, -1.0)];
    /// let report = dexels.cut(&flat, &path, &DexelOptions::default()).unwrap();
    /// report.check().unwrap();
    /// // A slot 4 mm wide and 1 mm deep through the 20 mm stock.
    /// assert!((report.removed_volume - 80.0).abs() < 1e-9);
    /// ```
    pub fn cut(
        &mut self,
        cutter: &Cutter,
        moves: &[ToolMove],
        options: &DexelOptions,
    ) -> Result<DexelReport, SimError> {
        self.cut_with_progress(cutter, moves, options, &|_, _| {})
    }

    /// [`DexelStock::cut`] that reports its progress: `progress(done, total)`
    /// is called from the worker threads (in any order) each time a band of
    /// rays has applied all its sweeps, `total` being the number of bands of
    /// the three families. The result does not depend on it.
    ///
    /// # Errors
    /// Those of [`DexelStock::cut`].
    pub fn cut_with_progress(
        &mut self,
        cutter: &Cutter,
        moves: &[ToolMove],
        options: &DexelOptions,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<DexelReport, SimError> {
        if !(options.axis_tolerance.is_finite() && options.axis_tolerance > 0.0) {
            return Err(SimError::BadTolerance { what: "axis tolerance", value: options.axis_tolerance });
        }
        if u32::try_from(moves.len()).is_err() {
            return Err(SimError::TooManyMoves { moves: moves.len() });
        }
        if let Some(max) = options.max_stick_out
            && !max.is_finite()
        {
            return Err(SimError::BadTolerance { what: "largest stick-out searched", value: max });
        }
        let operation = self.operations;
        let next = operation.checked_add(1).ok_or(SimError::TooManyMoves { moves: moves.len() })?;
        let flutes = Body::flutes(cutter);
        let guards = if options.check_collisions { guards(cutter) } else { Vec::new() };
        let steps = self.steps(operation, &flutes, moves, options)?;
        self.operations = next;
        let search = options.max_stick_out.map(|max| {
            let max = max.max(cutter.flute_length());
            let holder: f64 = cutter.holder().iter().map(|s| s.length).sum();
            (Search { cutter, max }, Body::guard_envelope(cutter, max + holder))
        });
        // Boxes of each step: flutes, then each guard, then the stick-out search's envelope.
        let boxes: Vec<Vec<(Point3, Point3)>> = steps
            .iter()
            .map(|s| {
                let mut b = vec![(s.lo, s.hi)];
                b.extend(guards.iter().map(|(g, _)| swept_box(g, &s.sweep, self.eps)));
                b.extend(search.iter().map(|(_, e)| swept_box(e, &s.sweep, self.eps)));
                b
            })
            .collect();
        let union = |bs: &[(Point3, Point3)]| bs.iter().fold(bs[0], |(lo, hi), (l, h)| (lo.inf(l), hi.sup(h)));
        let unions: Vec<(Point3, Point3)> = boxes.iter().map(|b| union(b)).collect();

        let count = moves.len();
        let mut removed_by_move = vec![0.0; count];
        let mut cut_any = vec![false; count];
        let mut rapid: Vec<Option<(f64, Point3)>> = vec![None; count];
        let mut collided: Vec<Vec<(ToolPart, f64, Point3)>> = vec![Vec::new(); count];
        // Sweeps with the axis +Z: their Z rays in closed form (the z-map's).
        let columns: Vec<Option<SweptMove>> = steps
            .iter()
            .map(|s| {
                let vertical = s.sweep.a.x == 0.0 && s.sweep.a.y == 0.0 && s.sweep.a.z > 0.0;
                vertical.then(|| SweptMove::new(cutter.shape(), &s.sweep.p0, &(s.sweep.p0 + s.sweep.v)))
            })
            .collect();
        let flutes_top = cutter.flute_length();
        let bands: usize = (0..3).map(|axis| self.grid(axis).1.div_ceil(BAND_ROWS)).sum();
        let done = AtomicUsize::new(0);
        let tick = || progress(done.fetch_add(1, Ordering::Relaxed) + 1, bands);
        let removal = FamilyCut::removal(&flutes, &guards, &steps, &boxes, &unions);
        let search = search.as_ref().map(|(s, _)| *s);
        // The longest stick-out any band needs.
        let mut need: Option<StickSearch> = None;
        for axis in 0..3 {
            let columns = if axis == 2 { Some((columns.as_slice(), flutes_top)) } else { None };
            let outputs = self.cut_family(axis, &FamilyCut { columns, search, ..removal }, &tick);
            for out in outputs {
                if let Some(band) = out.stick_out {
                    // The longest; between equal lengths the earliest step (a fixed order).
                    let step = |n: &StickSearch| n.limit.map_or(u32::MAX, |l| l.0);
                    let longer = |n: &StickSearch| match band.length.total_cmp(&n.length) {
                        std::cmp::Ordering::Greater => true,
                        std::cmp::Ordering::Equal => step(&band) < step(n),
                        std::cmp::Ordering::Less => false,
                    };
                    if need.as_ref().is_none_or(longer) {
                        need = Some(band);
                    }
                }
                for (k, volume, longest, at) in out.removed {
                    let step = &steps[k as usize];
                    let m = step.index as usize;
                    if axis == 2 {
                        removed_by_move[m] += volume;
                    }
                    if longest > self.eps {
                        cut_any[m] = true;
                        if step.rapid && rapid[m].is_none_or(|(d, _)| longest > d) {
                            rapid[m] = Some((longest, at));
                        }
                    }
                }
                merge_collisions(&mut collided, &steps, out.collisions);
            }
        }
        let id = |k: usize| MoveId { operation, index: k as u32 };
        let feed_moves = moves.iter().filter(|m| m.kind == MoveKind::Feed).count();
        let air_feed_moves = moves.iter().zip(&cut_any).filter(|(m, c)| m.kind == MoveKind::Feed && !**c).count();
        let rapid_hits = rapid
            .iter()
            .enumerate()
            .filter_map(|(k, r)| r.map(|(depth, at)| RapidHit { id: id(k), at: Point2::new(at.x, at.y), depth }))
            .collect();
        let collisions = collision_list(operation, &collided);
        let min_stick_out = search.map(|s| {
            let n = need.unwrap_or(StickSearch { length: s.cutter.flute_length(), exceeded: false, limit: None });
            StickOut {
                length: n.length,
                limit: n.limit.map(|(k, at)| (steps[k as usize].id(), at)),
                exceeded: n.exceeded,
            }
        });
        let removed_volume = removed_by_move.iter().sum();
        let sweeps = steps.len();
        self.bodies.push(flutes);
        self.history.extend(steps);
        Ok(DexelReport {
            operation,
            removed_by_move,
            removed_volume,
            feed_moves,
            air_feed_moves,
            sweeps,
            rapid_hits,
            collisions,
            min_stick_out,
        })
    }

    /// Checks the shank and holder of `cutter` along `moves` against the
    /// design part itself (not the in-process stock), as
    /// [`crate::ZMap::part_collisions`] does on a z-map: the part is laid on
    /// rays of its own (along X, Y and Z, at this stock's cell size, over the
    /// part's box within the reach of the shank and holder sweeps, so part
    /// features outside the stock box count too), and each fixed-axis sweep
    /// of the shank and of each holder segment is checked against them as in
    /// [`DexelStock::cut`]: part material inside them longer than the stock's
    /// epsilon along a ray is a collision, the deepest per move and part of
    /// the tool, in program order. The stock is not changed; `operation`
    /// names the moves (the [`DexelReport::operation`] of the cut of the same
    /// moves). A part wall reached by the flutes is a gouge, not a collision
    /// (see [`verify_dexel`]).
    ///
    /// # Errors
    /// Those of [`DexelStock::cut`] on the moves, and
    /// [`SimError::TooManyRays`] when the part's rays would exceed [`MAX_RAYS`].
    ///
    /// ```
    /// use scallop_cutter::{Cutter, CutterShape};
    /// use scallop_geom::{Aabb3, Point3, Vec3};
    /// use scallop_mesh::TriMesh;
    /// use scallop_sim::{DexelOptions, DexelPart, DexelStock, ToolMove, ToolPart};
    /// use scallop_toolpath::MoveKind;
    /// let p = |x, y, z| Point3::new(x, y, z);
    /// // An open part: a plane at z = 0, with a step up to z = 8 at x >= 14
    /// // (outside the stock box, which ends at x = 10).
    /// let soup = [
    ///     [p(-5., -5., 0.), p(14., -5., 0.), p(14., 15., 0.)],
    ///     [p(-5., -5., 0.), p(14., 15., 0.), p(-5., 15., 0.)],
    ///     [p(14., -5., 8.), p(30., -5., 8.), p(30., 15., 8.)],
    ///     [p(14., -5., 8.), p(30., 15., 8.), p(14., 15., 8.)],
    /// ];
    /// let part = DexelPart::new(&TriMesh::from_soup(&soup).unwrap().0);
    /// let stock = Aabb3 { min: p(0., 0., -1.), max: p(10., 10., 1.) };
    /// let dexels = DexelStock::new(stock, 0.25).unwrap();
    /// // A ball R 1 with 4 mm of flutes, shank R 1 to 30 mm, tilted 45 degrees
    /// // towards +X: at x = 6 the shank reaches over the step.
    /// let ball = Cutter::new(CutterShape::Ball { radius: 1.0 }, 4.0).unwrap().with_shank(1.0, 26.0).unwrap();
    /// let axis = Vec3::new(1.0, 0.0, 1.0).normalize();
    /// let mv = |kind, x: f64| ToolMove::new(kind, p(x, 5., 0.), axis);
    /// let path = [mv(MoveKind::Rapid, 0.), mv(MoveKind::Feed, 6.)];
    /// let hits = dexels.part_collisions(&part, &ball, &path, &DexelOptions::default(), 0).unwrap();
    /// assert_eq!((hits.len(), hits[0].id.index, hits[0].part), (1, 1, ToolPart::Shank));
    /// assert!(hits[0].at.x >= 14.0 && hits[0].at.z <= 8.0);
    /// ```
    pub fn part_collisions(
        &self,
        part: &DexelPart,
        cutter: &Cutter,
        moves: &[ToolMove],
        options: &DexelOptions,
        operation: u32,
    ) -> Result<Vec<DexelCollision>, SimError> {
        if !(options.axis_tolerance.is_finite() && options.axis_tolerance > 0.0) {
            return Err(SimError::BadTolerance { what: "axis tolerance", value: options.axis_tolerance });
        }
        let flutes = Body::flutes(cutter);
        let guards = guards(cutter);
        let steps = self.steps(operation, &flutes, moves, options)?;
        let boxes: Vec<Vec<(Point3, Point3)>> = steps
            .iter()
            .map(|s| {
                // No flutes box: nothing is removed.
                let mut b = vec![(Point3::new(1.0, 1.0, 1.0), Point3::origin())];
                b.extend(guards.iter().map(|(g, _)| swept_box(g, &s.sweep, self.eps)));
                b
            })
            .collect();
        let unions: Vec<(Point3, Point3)> =
            boxes.iter().map(|b| b[1..].iter().fold(b[1], |(lo, hi), (l, h)| (lo.inf(l), hi.sup(h)))).collect();
        // The part's rays: over the part's box within the reach of the sweeps.
        let Some(&first) = unions.first() else { return Ok(Vec::new()) };
        let (reach_lo, reach_hi) = unions.iter().fold(first, |(lo, hi), (l, h)| (lo.inf(l), hi.sup(h)));
        let material = part.material_box();
        let (lo, hi) = (reach_lo.sup(&material.min), reach_hi.inf(&material.max));
        if (0..3).any(|i| hi[i].partial_cmp(&lo[i]) != Some(std::cmp::Ordering::Greater)) {
            return Ok(Vec::new());
        }
        let resolution = self.cell.iter().fold(0.0f64, |a, &b| a.max(b));
        let mut solid = DexelStock::new(Aabb3 { min: lo, max: hi }, resolution)?;
        let mut collided: Vec<Vec<(ToolPart, f64, Point3)>> = vec![Vec::new(); moves.len()];
        // Only the guards are checked: nothing is removed.
        let check = FamilyCut { remove: false, ..FamilyCut::removal(&flutes, &guards, &steps, &boxes, &unions) };
        for axis in 0..3 {
            solid.rays[axis] = part.family_material(&solid, axis).into_iter().map(Ray::Cut).collect();
            // The part's epsilon is the stock's: the same penetrations count.
            solid.eps = self.eps;
            let outputs = solid.cut_family(axis, &check, &|| {});
            for out in outputs {
                merge_collisions(&mut collided, &steps, out.collisions);
            }
            // Each family's rays are only needed for its own pass.
            solid.rays[axis] = Vec::new();
        }
        Ok(collision_list(operation, &collided))
    }

    /// Which of `moves` would meet the stock as it stands: for each move,
    /// the longest piece of material along a ray inside the sweep of the
    /// flutes of `cutter` (0 when none is longer than the stock's epsilon),
    /// each move swept alone against the present stock (nothing is removed,
    /// so a move does not see what the ones before it in `moves` would cut).
    /// The first move has no known start: the tool placed at its end. Moves
    /// are split as in [`DexelStock::cut`].
    ///
    /// # Errors
    /// Those of [`DexelStock::cut`].
    ///
    /// ```
    /// use scallop_cutter::{Cutter, CutterShape};
    /// use scallop_geom::{Aabb3, Point3, Vec3};
    /// use scallop_sim::{DexelOptions, DexelStock, ToolMove};
    /// use scallop_toolpath::MoveKind;
    /// let stock = Aabb3 { min: Point3::new(0.0, 0.0, -5.0), max: Point3::new(20.0, 10.0, 0.0) };
    /// let mut dexels = DexelStock::new(stock, 0.25).unwrap();
    /// let flat = Cutter::new(CutterShape::Flat { radius: 2.0 }, 10.0).unwrap();
    /// let mv = |x: f64, z: f64| ToolMove::new(MoveKind::Feed, Point3::new(x, 5.0, z), Vec3::z());
    /// // Over the stock, down beside it, then 1 mm into it twice along the same line.
    /// let path = [mv(-3.0, 1.0), mv(23.0, 1.0), mv(23.0, -1.0), mv(-3.0, -1.0), mv(23.0, -1.0)];
    /// let depth = dexels.probe(&flat, &path, &DexelOptions::default()).unwrap();
    /// assert_eq!(depth[..3], [0.0, 0.0, 0.0]);
    /// assert!(depth[3] > 0.9 && depth[4] > 0.9);
    /// assert_eq!(dexels.volume(), 1000.0);
    /// ```
    pub fn probe(&mut self, cutter: &Cutter, moves: &[ToolMove], options: &DexelOptions) -> Result<Vec<f64>, SimError> {
        if !(options.axis_tolerance.is_finite() && options.axis_tolerance > 0.0) {
            return Err(SimError::BadTolerance { what: "axis tolerance", value: options.axis_tolerance });
        }
        if u32::try_from(moves.len()).is_err() {
            return Err(SimError::TooManyMoves { moves: moves.len() });
        }
        let flutes = Body::flutes(cutter);
        // The flutes checked as a guard: material inside them is measured, nothing removed.
        let guards = vec![(Body::flutes(cutter), ToolPart::Shank)];
        let steps = self.steps(self.operations, &flutes, moves, options)?;
        let boxes: Vec<Vec<(Point3, Point3)>> = steps
            .iter()
            .map(|s| vec![(Point3::new(1.0, 1.0, 1.0), Point3::origin()), swept_box(&guards[0].0, &s.sweep, self.eps)])
            .collect();
        let unions: Vec<(Point3, Point3)> = boxes.iter().map(|b| b[1]).collect();
        let check = FamilyCut { remove: false, ..FamilyCut::removal(&flutes, &guards, &steps, &boxes, &unions) };
        let mut collided: Vec<Vec<(ToolPart, f64, Point3)>> = vec![Vec::new(); moves.len()];
        for axis in 0..3 {
            for out in self.cut_family(axis, &check, &|| {}) {
                merge_collisions(&mut collided, &steps, out.collisions);
            }
        }
        Ok(collided.iter().map(|list| list.iter().map(|c| c.1).fold(0.0, f64::max)).collect())
    }

    /// One family: bands of rays in parallel, each applying its steps in
    /// order; `remove == false` only checks the guards (nothing is cut).
    fn cut_family(&mut self, axis: usize, cut: &FamilyCut<'_>, tick: &(dyn Fn() + Sync)) -> Vec<BandOutput> {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let (nu, nv) = (self.n[u], self.n[v]);
        let geo = Family {
            axis,
            u,
            v,
            nu,
            nv,
            min: self.stock.min,
            cell: self.cell,
            lo: self.stock.min[axis],
            hi: self.stock.max[axis],
            area: self.cell[u] * self.cell[v],
            eps: self.eps,
        };
        // Steps per band, in program order.
        let bands = nv.div_ceil(BAND_ROWS);
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); bands];
        for (k, (lo, hi)) in cut.unions.iter().enumerate() {
            if let Some((a, b)) = geo.index_range(v, lo[v], hi[v]) {
                for m in &mut members[a / BAND_ROWS..=b / BAND_ROWS] {
                    // k < moves <= u32::MAX (checked by the caller).
                    m.push(k as u32);
                }
            }
        }
        self.rays[axis]
            .par_chunks_mut(BAND_ROWS * nu)
            .zip(members.par_iter())
            .enumerate()
            .map(|(band, (rays, ids))| {
                let out = geo.cut_band(band, rays, ids, cut);
                tick();
                out
            })
            .collect()
    }

    /// The fixed-axis sweeps cut so far, with the flutes of their operation.
    pub(crate) fn history(&self) -> impl Iterator<Item = (&Step, &Body)> {
        self.history.iter().map(|s| (s, &self.bodies[s.operation as usize]))
    }

    pub(crate) fn ray(&self, axis: usize, index: usize) -> &[[f64; 2]] {
        match &self.rays[axis][index] {
            Ray::Full => &[],
            Ray::Cut(v) => v,
        }
    }

    pub(crate) fn ray_is_full(&self, axis: usize, index: usize) -> bool {
        matches!(self.rays[axis][index], Ray::Full)
    }
}

impl Step {
    /// The move this sweep belongs to.
    pub(crate) fn id(&self) -> MoveId {
        MoveId { operation: self.operation, index: self.index }
    }

    /// The interval of the ray along `axis` through `o` inside this sweep of `body`.
    pub(crate) fn interval(&self, body: &Body, o: &Point3, axis: usize) -> Option<(f64, f64)> {
        let mut d = Vec3::zeros();
        d[axis] = 1.0;
        self.sweep.interval(body, o, &d)
    }

    /// Whether the box of the sweep contains the ray.
    pub(crate) fn crosses(&self, o: &Point3, axis: usize) -> bool {
        (0..3).filter(|&i| i != axis).all(|i| o[i] >= self.lo[i] && o[i] <= self.hi[i])
    }
}

/// Adds a band's collisions `(step, part, depth, place)` to the deepest
/// per move and part of the tool (`collided[move]`, in order of first finding).
fn merge_collisions(
    collided: &mut [Vec<(ToolPart, f64, Point3)>],
    steps: &[Step],
    found: Vec<(u32, ToolPart, f64, Point3)>,
) {
    for (k, part, depth, at) in found {
        let list = &mut collided[steps[k as usize].index as usize];
        match list.iter_mut().find(|(p, _, _)| *p == part) {
            Some(entry) if depth > entry.1 => *entry = (part, depth, at),
            Some(_) => {}
            None => list.push((part, depth, at)),
        }
    }
}

/// The merged collisions in program order.
fn collision_list(operation: u32, collided: &[Vec<(ToolPart, f64, Point3)>]) -> Vec<DexelCollision> {
    collided
        .iter()
        .enumerate()
        .flat_map(|(k, list)| list.iter().map(move |&(part, depth, at)| (k, part, depth, at)))
        // k < moves <= u32::MAX (checked by the callers).
        .map(|(k, part, depth, at)| DexelCollision { id: MoveId { operation, index: k as u32 }, part, at, depth })
        .collect()
}

/// The closed-form Z rays of a cut: per step, the flutes' sweep when the
/// axis is +Z, and the flute length.
type Columns<'a> = (&'a [Option<SweptMove>], f64);

/// The stick-out search of a cut ([`DexelOptions::max_stick_out`]): the
/// tool and the largest length searched (at least the flute length).
#[derive(Clone, Copy)]
struct Search<'a> {
    cutter: &'a Cutter,
    max: f64,
}

/// What one family's bands apply, step by step: the flutes and the guarded
/// parts of the tool (shank, holder), the fixed-axis steps with their boxes
/// (flutes first, then one per guard, then the search's envelope) and the
/// union of those boxes; `remove == false` only checks the guards; `columns`:
/// the Z rays of vertical steps in closed form, with the flutes' top;
/// `search`: the stick-out search.
#[derive(Clone, Copy)]
struct FamilyCut<'a> {
    flutes: &'a Body,
    guards: &'a [(Body, ToolPart)],
    steps: &'a [Step],
    boxes: &'a [Vec<(Point3, Point3)>],
    unions: &'a [(Point3, Point3)],
    remove: bool,
    columns: Option<Columns<'a>>,
    search: Option<Search<'a>>,
}

impl<'a> FamilyCut<'a> {
    /// Removal by the flutes and the guards' check, every ray by the general sweep.
    fn removal(
        flutes: &'a Body,
        guards: &'a [(Body, ToolPart)],
        steps: &'a [Step],
        boxes: &'a [Vec<(Point3, Point3)>],
        unions: &'a [(Point3, Point3)],
    ) -> FamilyCut<'a> {
        FamilyCut { flutes, guards, steps, boxes, unions, remove: true, columns: None, search: None }
    }
}

/// The parts of the tool checked for collisions: the shank, then each holder piece.
fn guards(cutter: &Cutter) -> Vec<(Body, ToolPart)> {
    let mut guards = vec![(Body::shank(cutter), ToolPart::Shank)];
    let mut i = 0;
    while let Some(b) = Body::holder(cutter, i) {
        guards.push((b, ToolPart::Holder(i)));
        i += 1;
    }
    guards
}

/// What a band found, sparse per step.
#[derive(Default)]
struct BandOutput {
    /// (step, removed volume, longest removed piece, its middle).
    removed: Vec<(u32, f64, f64, Point3)>,
    /// (step, part, depth, place).
    collisions: Vec<(u32, ToolPart, f64, Point3)>,
    /// The band's smallest collision-free stick-out.
    stick_out: Option<StickSearch>,
}

/// The geometry of one family of rays.
#[derive(Clone, Copy)]
struct Family {
    axis: usize,
    u: usize,
    v: usize,
    nu: usize,
    nv: usize,
    min: Point3,
    cell: [f64; 3],
    lo: f64,
    hi: f64,
    area: f64,
    eps: f64,
}

impl Family {
    /// Ray indices along `c` (u or v) whose centres may lie in [lo, hi].
    fn index_range(&self, c: usize, lo: f64, hi: f64) -> Option<(usize, usize)> {
        let n = if c == self.u { self.nu } else { self.nv };
        crate::zmap::index_range(lo, hi, self.min[c], self.cell[c], n)
    }

    fn origin(&self, iu: usize, iv: usize) -> Point3 {
        let mut o = Point3::origin();
        o[self.u] = self.min[self.u] + (iu as f64 + 0.5) * self.cell[self.u];
        o[self.v] = self.min[self.v] + (iv as f64 + 0.5) * self.cell[self.v];
        o
    }

    fn cut_band(&self, band: usize, rays: &mut [Ray], ids: &[u32], cut: &FamilyCut<'_>) -> BandOutput {
        let FamilyCut { flutes, guards, steps, boxes, unions, remove, columns, search } = *cut;
        let row0 = band * BAND_ROWS;
        let rows = rays.len() / self.nu;
        let mut out = BandOutput::default();
        // The stick-out search: the length so far and its shank and holder.
        let mut need = search.map(|s| {
            let length = s.cutter.flute_length();
            (StickSearch { length, exceeded: false, limit: None }, Body::guards_at(s.cutter, length))
        });
        let mut d = Vec3::zeros();
        d[self.axis] = 1.0;
        let (lo, hi) = (self.lo, self.hi);
        for &k in ids {
            let step = &steps[k as usize];
            let (ulo, uhi) = unions[k as usize];
            let Some((v0, v1)) = self.index_range(self.v, ulo[self.v], uhi[self.v]) else { continue };
            let Some((u0, u1)) = self.index_range(self.u, ulo[self.u], uhi[self.u]) else { continue };
            let (v0, v1) = (v0.max(row0), v1.min(row0 + rows - 1));
            let (mut removed, mut longest, mut at) = (0.0, 0.0, Point3::origin());
            let mut worst: Vec<Option<(f64, Point3)>> = vec![None; guards.len()];
            for iv in v0..=v1 {
                for iu in u0..=u1 {
                    let o = self.origin(iu, iv);
                    let ray = &mut rays[(iv - row0) * self.nu + iu];
                    let inside = |b: &(Point3, Point3)| {
                        o[self.u] >= b.0[self.u]
                            && o[self.u] <= b.1[self.u]
                            && o[self.v] >= b.0[self.v]
                            && o[self.v] <= b.1[self.v]
                    };
                    let bx = &boxes[k as usize];
                    if remove
                        && inside(&bx[0])
                        && let Some((m_lo, m_hi)) = ray.material_range(bx[0].0[self.axis], bx[0].1[self.axis], lo, hi)
                        && let Some((a, b)) = match columns.and_then(|(c, top)| c[k as usize].map(|m| (m, top))) {
                            // The Z ray of a vertical tool: the z-map's closed forms.
                            Some((m, top)) => m.column(o.x, o.y, top),
                            None => step.sweep.interval_within(flutes, &o, &d, m_lo, m_hi),
                        }
                    {
                        let (r, l, mid) = ray.subtract(a.max(lo), b.min(hi), lo, hi);
                        removed += r;
                        if l > longest {
                            longest = l;
                            at = o;
                            at[self.axis] = mid;
                        }
                    }
                    for (g, (body, _)) in guards.iter().enumerate() {
                        let b = &bx[g + 1];
                        if !inside(b) {
                            continue;
                        }
                        let Some((m_lo, m_hi)) = ray.material_range(b.0[self.axis], b.1[self.axis], lo, hi) else {
                            continue;
                        };
                        if let Some((a, b)) = step.sweep.interval_within(body, &o, &d, m_lo, m_hi) {
                            let (depth, mid) = ray.overlap(a, b, lo, hi);
                            if depth > self.eps && worst[g].is_none_or(|(w, _)| depth > w) {
                                let mut p = o;
                                p[self.axis] = mid;
                                worst[g] = Some((depth, p));
                            }
                        }
                    }
                    if let (Some(s), Some((state, bodies))) = (search, need.as_mut())
                        && !state.exceeded
                    {
                        let b = &bx[guards.len() + 1];
                        if inside(b)
                            && let Some(range) = ray.material_range(b.0[self.axis], b.1[self.axis], lo, hi)
                        {
                            let meets = |bodies: &[Body]| self.meets(ray, step, bodies, &o, range);
                            if let Some(at) = meets(bodies) {
                                state.raise(s, k, at, &meets);
                                *bodies = Body::guards_at(s.cutter, state.length);
                            }
                        }
                    }
                }
            }
            if removed > 0.0 {
                out.removed.push((k, removed * self.area, longest, at));
            }
            for (g, w) in worst.iter().enumerate() {
                if let Some((depth, p)) = *w {
                    out.collisions.push((k, guards[g].1, depth, p));
                }
            }
        }
        out.stick_out = need.map(|(s, _)| s);
        out
    }

    /// The middle of the stock piece of `ray` (material within `range` along
    /// it, through `o`) inside one of `bodies` swept by `step`, if any piece is
    /// longer than the stock's epsilon (as the collision check counts).
    fn meets(&self, ray: &Ray, step: &Step, bodies: &[Body], o: &Point3, range: (f64, f64)) -> Option<Point3> {
        let mut d = Vec3::zeros();
        d[self.axis] = 1.0;
        bodies.iter().find_map(|body| {
            let (a, b) = step.sweep.interval_within(body, o, &d, range.0, range.1)?;
            let (depth, mid) = ray.overlap(a, b, self.lo, self.hi);
            (depth > self.eps).then(|| {
                let mut p = *o;
                p[self.axis] = mid;
                p
            })
        })
    }
}

/// A band's stick-out search so far: the length, whether even the largest
/// searched meets the stock, the step and place that set it.
#[derive(Clone, Copy)]
struct StickSearch {
    length: f64,
    exceeded: bool,
    limit: Option<(u32, Point3)>,
}

impl StickSearch {
    /// Step `k` meets the stock at `at` with the shank and holder at
    /// `self.length`: the length goes up to the smallest, within
    /// [`crate::tol::STICK_OUT_TOL`], at which `meets` finds nothing (a
    /// bisection), or to the largest searched when that one meets it too.
    fn raise(&mut self, search: Search<'_>, k: u32, at: Point3, meets: &dyn Fn(&[Body]) -> Option<Point3>) {
        let at_length = |l: f64| meets(&Body::guards_at(search.cutter, l));
        if let Some(p) = at_length(search.max) {
            *self = StickSearch { length: search.max, exceeded: true, limit: Some((k, p)) };
            return;
        }
        let (mut short, mut long, mut place) = (self.length, search.max, at);
        while long - short > crate::tol::STICK_OUT_TOL {
            let mid = 0.5 * (short + long);
            match at_length(mid) {
                Some(p) => (short, place) = (mid, p),
                None => long = mid,
            }
        }
        *self = StickSearch { length: long, exceeded: false, limit: Some((k, place)) };
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
mod tests {
    use scallop_cutter::Cutter;

    use super::*;

    /// The closed-form Z rays of a vertical tool ([`SweptMove::column`], used
    /// by the cut) agree with the general certified sweep of the flutes
    /// ([`Sweep::interval`]) on scattered moves and rays: entry and exit
    /// within the sweep's tolerance, and the same misses.
    #[test]
    fn vertical_columns_match_the_general_sweep() {
        let shapes = crate::test_support::shapes(2.0, 0.6, 0.7);
        let mut rng = crate::test_support::Lcg(7);
        let mut next = || rng.unit();
        let mut both = 0;
        for shape in shapes {
            let cutter = Cutter::new(shape, 7.0).unwrap();
            let flutes = Body::flutes(&cutter);
            for case in 0..300 {
                let p0 = Point3::new(10.0 * next(), 10.0 * next(), 4.0 * next() - 2.0);
                // Every tenth move vertical, every tenth horizontal.
                let (dx, dy) = if case % 10 == 0 { (0.0, 0.0) } else { (8.0 * next() - 4.0, 8.0 * next() - 4.0) };
                let dz = if case % 10 == 1 { 0.0 } else { 6.0 * next() - 3.0 };
                let v = Vec3::new(dx, dy, dz);
                let sweep = Sweep { p0, v, a: Vec3::z() };
                let m = SweptMove::new(cutter.shape(), &p0, &(p0 + v));
                for _ in 0..20 {
                    let o = Point3::new(
                        p0.x + dx * next() + 5.0 * next() - 2.5,
                        p0.y + dy * next() + 5.0 * next() - 2.5,
                        0.0,
                    );
                    let general = sweep.interval(&flutes, &o, &Vec3::z());
                    let closed = m.column(o.x, o.y, cutter.flute_length());
                    match (general, closed) {
                        (Some(g), Some(c)) => {
                            both += 1;
                            assert!((g.0 - c.0).abs() <= 1e-7 && (g.1 - c.1).abs() <= 1e-7, "{shape:?} {g:?} {c:?}");
                        }
                        (None, None) => {}
                        // A ray grazing the swept solid's side: a vanishing piece.
                        (Some(g), None) => assert!(g.1 - g.0 <= 1e-6, "{shape:?} {g:?}"),
                        (None, Some(c)) => assert!(c.1 - c.0 <= 1e-6, "{shape:?} {c:?}"),
                    }
                }
            }
        }
        assert!(both > 10_000, "{both}");
    }
}
