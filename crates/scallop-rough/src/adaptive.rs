//! Adaptive (engagement-controlled) clearing of one tool-centre region.
//!
//! The tool enters at the region's deepest point (largest inscribed circle,
//! found by fast marching from the walls) by the emitter's helix, which
//! bores a disc. The cleared tool-centre set then grows as a front: the set
//! `F(t)` of points whose distance from the entry measured inside the region
//! is at most `t` (fast marching from the bore). Each pass is the part of the
//! boundary of `F(t + a)` not cut before: arcs inside the region and the
//! newly reached pieces of its walls, run with `F` on the left (climb with a
//! clockwise spindle: the material on the tool's right). Every point of
//! `F(t + a)` lies within `a` of `F(t)`, whose boundary was swept, so the
//! material within R of `F(t)` is cut and a pass meets at most a band about
//! `a` wide.
//!
//! The front is slowed near the walls (fast marching with a speed of
//! [`tol::WALL_SPEED`] on a wall, rising to 1 at [`tol::WALL_BAND`] R from
//! it): it bends to meet a wall nearly parallel, with passes closer together
//! there. A pass's points on a wall are moved onto the wall itself and the
//! wall's vertices between them put back (`walls.rs`), so a pass along a wall
//! follows it exactly and reaches into its corners.
//!
//! The step `a` is chosen per pass from the engagement itself: a grid keeps
//! the distance from every point to the tool centres swept so far (the
//! cleared material is where it is at most R), the candidate pass is swept
//! on it and its engagement (the arc of the periphery in material, probed
//! all round) measured every cell side; a pass over
//! [`tol::ENGAGE_ACCEPT`] times the target `arccos(1 - ae / R)` is undone and
//! tried with a smaller step scaled by the ratio of `1 - cos` of the angles
//! (the straight-cut relation), a pass under it lets the next one grow by at
//! most [`tol::STEP_GROW`] up to the stepover. Tight curves (the first rings
//! about the bore, fronts wrapping round islands and inner corners, narrow
//! channels) get small steps, straight fronts the stepover. This is the
//! engagement control of the adaptive-clearing literature (for instance
//! Elber, Cohen and Drake 2005, "MATHSM: medial axis transform toward high
//! speed machining of pockets", CAD 37(2): a bounded engagement from the
//! medial axis outwards), done by measurement instead of a closed form.
//!
//! A closed front (not touching a wall) is entered by a spiral turn from
//! the current point; a pass that starts on a wall starts where the wall
//! was reached before (cleared). Once every pass is planned, the cuts are
//! put in an order that clears a branch before moving on, and joined by
//! tool-down links through cleared area, retracts only when none is found
//! (`links.rs`). Last, the region's own rings are cut (the contour at the
//! allowance, exact and with arcs): the grid's iso-lines stay within a cell
//! side of the walls.

use scallop_contour::{Contour, P2, Region};

use crate::grid::{BIG, Grid, IsoPoint, iso_lines};
use crate::offset::Step;
use crate::walls::Walls;
use crate::{ClearOptions, Direction, RoughError, tol};

mod links;
use links::Planned;

/// One piece of a front's boundary to cut.
enum Piece {
    /// An open run from a point cut before to another, and how many of its
    /// first points lie on a wall (the tool goes along the wall into the
    /// corner the front makes with it: see [`Planner::sweep`]).
    Open(Vec<P2>, usize),
    /// A closed front, every point new.
    Ring(Vec<P2>),
}

/// What one pass starts from.
#[derive(Clone, Copy)]
struct Level<'g> {
    /// The distance field of the front.
    g: &'g [f64],
    /// The step from the last front (mm).
    a: f64,
    /// Where the tool is.
    pos: P2,
    /// The ring the last pass's spiral turn left open.
    pending: Option<&'g Vec<P2>>,
}

/// A pass planned: its largest engagement (rad), cuts, end, and the ring
/// its spiral turn leaves open.
struct Cut {
    phi: f64,
    items: Vec<Planned>,
    end: P2,
    open: Option<Vec<P2>>,
}

/// The state of the planner of one region.
struct Planner<'a> {
    grid: Grid,
    /// Distance from the region (0 inside).
    reach: Vec<f64>,
    /// Distance from the tool centres swept so far.
    swept: Vec<f64>,
    /// The region grown a hair: links must stay in it.
    holder: Region,
    /// The region's walls, onto which the passes' wall points are moved.
    walls: Walls,
    options: &'a ClearOptions,
    /// The largest accepted engagement (rad).
    accept: f64,
    /// Cells whose centre lies in the region.
    inside: Vec<bool>,
    /// The link search's cache per cell (`links.rs`).
    lattice: Vec<u32>,
    /// Chains cut so far (the cache's clock).
    epoch: u32,
}

/// The adaptive clearing of `region` (one connected tool-centre region):
/// open and closed cuts and links (see the module documentation). The first
/// cut starts at the entry point, where the emitter's helix bores.
///
/// # Errors
/// [`RoughError::TooMuchWork`] beyond [`tol::MAX_PASSES`] passes.
pub fn plan_adaptive(region: &Region, options: &ClearOptions) -> Result<Vec<Step>, RoughError> {
    let r = options.tool_radius;
    let Some((lo, hi)) = region.bounds() else { return Ok(Vec::new()) };
    let grid = Grid::new(lo, hi, r + 4.0 * r * tol::GRID_SHARE, r * tol::GRID_SHARE)?;
    let h = grid.h;
    let inside = grid.fill(region, (0.25 * h).min(options.chord_tolerance.max(1e-4)));
    let mut reach: Vec<f64> = inside.iter().map(|&i| if i { 0.0 } else { BIG }).collect();
    for ring in region.rings() {
        let pts = ring.to_points(0.25 * h);
        for (k, a) in pts.iter().enumerate() {
            grid.stamp_segment(&mut reach, *a, pts[(k + 1) % pts.len()], r + 2.0 * h, None);
        }
    }
    let walls: Vec<(usize, f64)> = (0..grid.len())
        .filter(|&k| inside[k] && [k - 1, k + 1, k - grid.nx, k + grid.nx].iter().any(|&n| !inside[n]))
        .map(|k| (k, 0.5 * h))
        .collect();
    let depth = grid.march(&inside, &walls, None);
    let Some(seed) = (0..grid.len())
        .filter(|&k| depth[k] < 0.5 * BIG)
        .max_by(|&a, &b| depth[a].total_cmp(&depth[b]).then(b.cmp(&a)))
    else {
        return Ok(rings_only(region, options));
    };
    let s = grid.centre(seed);
    let rh = tol::HELIX_RADIUS_SHARE * r;
    let r0 = if rh > 0.0 && region.offset(rh).contains(s) { rh } else { 0.0 };
    let mut planner = Planner {
        swept: vec![BIG; grid.len()],
        reach,
        holder: region.offset(-tol::LINK_GROW),
        walls: Walls::new(region, 2.0 * h),
        options,
        accept: tol::ENGAGE_ACCEPT * (1.0 - (options.stepover / r).min(1.0)).acos(),
        lattice: vec![0; grid.len()],
        epoch: 1,
        inside: inside.clone(),
        grid,
    };
    planner.bore(s, r0);
    let bored = planner.swept.clone();
    let near = r0 + 2.0 * h;
    let sources: Vec<(usize, f64)> = (0..planner.grid.len())
        .map(|k| (k, dist(planner.grid.centre(k), s)))
        .filter(|&(k, d)| d <= near && inside[k])
        .collect();
    // The front slows down near the walls: it meets them nearly parallel,
    // with passes closer together there (see the module documentation).
    let slow: Vec<f64> = depth.iter().map(|&d| 1.0 / wall_speed(d, r)).collect();
    let g = planner.grid.march(&inside, &sources, Some(&slow));
    let cuts = planner.fronts(&g, s, r0)?;
    // The cuts again in their own order (`links.rs`), from the bore.
    planner.swept = bored;
    let (mut steps, pos) = planner.schedule(cuts, s);
    let mut rest = planner.finish(region, pos);
    steps.append(&mut rest);
    Ok(steps)
}

/// The front's speed at `depth` mm from the region's walls (tool radius
/// `r`): [`tol::WALL_SPEED`] on the wall, rising linearly to 1 at
/// [`tol::WALL_BAND`] x `r` from it.
fn wall_speed(depth: f64, r: f64) -> f64 {
    let f = (depth / (tol::WALL_BAND * r)).clamp(0.0, 1.0);
    tol::WALL_SPEED + (1.0 - tol::WALL_SPEED) * f
}

fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Only the region's rings, when no grid cell lies inside it.
fn rings_only(region: &Region, options: &ClearOptions) -> Vec<Step> {
    let mut steps = Vec::new();
    for ring in region.rings() {
        if !steps.is_empty() {
            steps.push(Step::Link { tool_down: false, via: Vec::new(), cleared: false, to: None });
        }
        steps.push(Step::Cut(orient(ring, options.direction)));
    }
    steps
}

fn orient(c: &Contour, direction: Direction) -> Contour {
    match direction {
        Direction::Climb => c.clone(),
        Direction::Conventional => c.reversed(),
    }
}

impl Planner<'_> {
    /// The helix's bore about `s` (tool centre circle of radius `r0`), or a
    /// plunge at `s`.
    fn bore(&mut self, s: P2, r0: f64) {
        let w = self.options.tool_radius + 2.0 * self.grid.h;
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small positive count")]
        let n = ((std::f64::consts::TAU * r0 / self.grid.h).ceil() as usize).max(1);
        let on = |i: usize| {
            #[allow(clippy::cast_precision_loss, reason = "a small count")]
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            [s[0] + r0 * a.cos(), s[1] + r0 * a.sin()]
        };
        for i in 0..n {
            self.grid.stamp_segment(&mut self.swept, on(i), on(i + 1), w, None);
        }
        self.grid.stamp_segment(&mut self.swept, s, s, w, None);
    }

    /// The engagement (rad) of the tool centred at `p`: the share of its
    /// periphery in material (inside the reach of the region, farther than R
    /// from every swept centre).
    fn engagement(&self, p: P2) -> f64 {
        let r = self.options.tool_radius;
        let n = tol::ENGAGE_PROBES;
        let mut count = 0usize;
        for i in 0..n {
            #[allow(clippy::cast_precision_loss, reason = "a small count")]
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            let q = [p[0] + r * a.cos(), p[1] + r * a.sin()];
            if self.grid.sample(&self.reach, q) < r && self.grid.sample(&self.swept, q) > r {
                count += 1;
            }
        }
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let phi = std::f64::consts::TAU * count as f64 / n as f64;
        phi
    }

    /// Sweeps the polyline `run` (the tool at its first point), a sample
    /// every cell side: the largest engagement met after its first `skip`
    /// points and within R of the last of them; the swept field's old values
    /// go to `undo`. A run's first points on a wall go along the wall into
    /// the corner between the wall and the last front, whose angle, not the
    /// step, sets the engagement there: they are not counted
    /// (docs/roughing.md).
    fn sweep(&mut self, run: &[P2], skip: usize, undo: &mut Vec<(usize, f64)>) -> f64 {
        let w = self.options.tool_radius + 2.0 * self.grid.h;
        let mut phi = 0.0f64;
        let Some(&first) = run.first() else { return phi };
        if skip == 0 {
            phi = phi.max(self.engagement(first));
        }
        self.grid.stamp_segment(&mut self.swept, first, first, w, Some(undo));
        for (k, pair) in run.windows(2).enumerate() {
            let (a, b) = (pair[0], pair[1]);
            let corner = run[skip.saturating_sub(1).min(run.len() - 1)];
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small positive count")]
            let n = ((dist(a, b) / self.grid.h).ceil() as usize).max(1);
            let mut prev = a;
            for i in 1..=n {
                #[allow(clippy::cast_precision_loss, reason = "a small count")]
                let f = i as f64 / n as f64;
                let p = [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])];
                let counted = skip == 0 || (k >= skip && dist(p, corner) > self.options.tool_radius);
                let e = if counted { self.engagement(p) } else { 0.0 };
                phi = phi.max(e);
                self.grid.stamp_segment(&mut self.swept, prev, p, w, Some(undo));
                prev = p;
            }
        }
        phi
    }

    fn revert(&mut self, undo: &mut Vec<(usize, f64)>, mark: usize) {
        while undo.len() > mark {
            if let Some((k, v)) = undo.pop() {
                self.swept[k] = v;
            }
        }
    }

    /// The passes of the growing front from the bore of radius `r0` about `s`
    /// until the front has reached every point of the distance field `g`.
    fn fronts(&mut self, g: &[f64], s: P2, r0: f64) -> Result<Vec<Planned>, RoughError> {
        let gmax = g.iter().copied().filter(|&v| v < 0.5 * BIG).fold(0.0f64, f64::max);
        let ae = self.options.stepover;
        let target = self.accept / tol::ENGAGE_ACCEPT;
        let a_min = tol::STEP_MIN_SHARE * self.grid.h;
        let (mut t, mut a, mut pos) = (r0, ae, s);
        let mut steps: Vec<Planned> = Vec::new();
        let mut undo = Vec::new();
        let mut passes = 0usize;
        let mut pending: Option<Vec<P2>> = None;
        while t < gmax {
            passes += 1;
            if passes > tol::MAX_PASSES {
                return Err(RoughError::TooMuchWork { what: "adaptive passes", limit: tol::MAX_PASSES });
            }
            let mut trial = 0;
            let mut last: Option<(f64, f64)> = None;
            let mut force = false;
            loop {
                trial += 1;
                let level = t + a;
                let loops = iso_lines(&self.grid, g, level, t).iter().map(|lp| self.walls.snap(lp)).collect();
                let pieces = pieces(loops, self.options.direction, 2.0 * self.options.tool_radius);
                undo.clear();
                let from = Level { g, a, pos, pending: pending.as_ref() };
                let Cut { phi, items, end, open } = self.cut_level(pieces, from, &mut undo);
                let ratio = (1.0 - target.cos()) / (1.0 - phi.cos()).max(1e-12);
                if phi <= self.accept || a <= a_min || trial >= tol::STEP_TRIALS || force {
                    steps.extend(items);
                    pending = open;
                    pos = end;
                    t = level;
                    a = (a * ratio.clamp(1.0, tol::STEP_GROW)).min(ae);
                    break;
                }
                self.revert(&mut undo, 0);
                // A smaller step that did not lower the engagement: the
                // geometry sets it (a front meeting a wall at a small
                // angle); the larger step is kept.
                if let Some((a_last, _)) = last.filter(|l| phi > l.1 - tol::STEP_STALL) {
                    a = a_last;
                    force = true;
                    continue;
                }
                last = Some((a, phi));
                a = (a * 0.9 * ratio).min(0.9 * a).max(a_min);
            }
        }
        if let Some(ring) = pending {
            self.stamp(&ring);
            steps.push((true, ring));
        }
        Ok(steps)
    }

    /// Cuts the pieces of one pass nearest first from `pos`: the largest
    /// engagement of the cuts, the cuts, where the tool ends, and the ring
    /// left open by a spiral turn (see [`Planner::spiral`]). `pending` is the
    /// ring the last pass left open: it is closed first unless this pass is
    /// one closed front again.
    fn cut_level(&mut self, mut pieces: Vec<Piece>, level: Level<'_>, undo: &mut Vec<(usize, f64)>) -> Cut {
        let r = self.options.tool_radius;
        let mut pos = level.pos;
        let mut phi = 0.0f64;
        let mut items = Vec::new();
        let mut open = None;
        let single_ring = pieces.len() == 1 && matches!(pieces[0], Piece::Ring(_));
        if let Some(ring) = level.pending.filter(|_| !single_ring) {
            phi = phi.max(self.sweep(ring, 0, undo));
            pos = *ring.last().unwrap_or(&pos);
            items.push((true, ring.clone()));
        }
        while !pieces.is_empty() {
            let near = |p: &Piece| match p {
                Piece::Open(v, _) => (dist(v[0], pos), 0),
                Piece::Ring(v) => nearest_vertex(v, pos),
            };
            let i = (0..pieces.len()).min_by(|&x, &y| near(&pieces[x]).0.total_cmp(&near(&pieces[y]).0)).unwrap_or(0);
            let (d, j0) = near(&pieces[i]);
            let mut skip = 0;
            // Links are planned later (`links.rs`) and cut nothing but
            // their approach, which no cut of this plan relies on.
            let (glued, run) = match pieces.remove(i) {
                Piece::Open(v, lead) => {
                    skip = lead;
                    (false, v)
                }
                Piece::Ring(v) if d <= r && single_ring && self.spiral_fits(&v, j0, pos, level) => {
                    let (run, closing) = self.spiral(&v, j0, pos, level);
                    open = Some(closing);
                    (true, run)
                }
                Piece::Ring(v) => {
                    let run: Vec<P2> = v[j0..].iter().chain(v[..=j0].iter()).copied().collect();
                    (false, run)
                }
            };
            phi = phi.max(self.sweep(&run, skip, undo));
            pos = *run.last().unwrap_or(&pos);
            items.push((glued, run));
        }
        Cut { phi, items, end: pos, open }
    }

    /// Whether the spiral's first move, from `pos`, stays in the region.
    fn spiral_fits(&self, v: &[P2], j: usize, pos: P2, level: Level<'_>) -> bool {
        let (run, _) = self.spiral(v, j, pos, level);
        run.get(1).is_some_and(|&p| self.holder.contains_segment(pos, p, self.options.chord_tolerance))
    }

    /// One turn of a spiral from the last front (level `t`) to the ring `v`
    /// (level `t + a`), from its vertex `j` nearest `pos` round to it: each
    /// point of the ring moved back along the distance field's gradient by
    /// the share of `a` still to climb there. The second polyline is the
    /// ring from `j` round to it, which the spiral leaves open behind it.
    fn spiral(&self, v: &[P2], j: usize, pos: P2, level: Level<'_>) -> (Vec<P2>, Vec<P2>) {
        let ring: Vec<P2> = v[j..].iter().chain(v[..=j].iter()).copied().collect();
        let mut len = vec![0.0];
        for w in ring.windows(2) {
            len.push(len[len.len() - 1] + dist(w[0], w[1]));
        }
        let total = len[len.len() - 1].max(f64::MIN_POSITIVE);
        let h = self.grid.h;
        let mut run = vec![pos];
        for (q, l) in ring.iter().zip(&len) {
            let gx = self.grid.sample(level.g, [q[0] + h, q[1]]) - self.grid.sample(level.g, [q[0] - h, q[1]]);
            let gy = self.grid.sample(level.g, [q[0], q[1] + h]) - self.grid.sample(level.g, [q[0], q[1] - h]);
            let norm = gx.hypot(gy);
            let back = (1.0 - l / total) * level.a;
            let p = if norm > 0.0 && norm < h * 8.0 { [q[0] - back * gx / norm, q[1] - back * gy / norm] } else { *q };
            run.push(p);
        }
        (run, ring)
    }

    /// The region's rings from `pos`, nearest first, with their links.
    fn finish(&mut self, region: &Region, mut pos: P2) -> Vec<Step> {
        let mut rings: Vec<Contour> = region.rings().iter().map(|c| orient(c, self.options.direction)).collect();
        let mut steps = Vec::new();
        while !rings.is_empty() {
            let started: Vec<Contour> = rings.iter().map(|c| c.starting_near(pos)).collect();
            let d = |c: &Contour| c.start().map_or(f64::INFINITY, |p| dist(p, pos));
            let i = (0..started.len()).min_by(|&x, &y| d(&started[x]).total_cmp(&d(&started[y]))).unwrap_or(0);
            let ring = started[i].clone();
            rings.remove(i);
            let Some(start) = ring.start() else { continue };
            let link = self.link_step(pos, start);
            steps.push(link);
            let mut pts = ring.to_points(0.25 * self.grid.h);
            pts.push(start);
            self.stamp(&pts);
            pos = start;
            steps.push(Step::Cut(ring));
        }
        steps
    }
}

/// The vertex of `v` nearest `p`: (distance, index).
fn nearest_vertex(v: &[P2], p: P2) -> (f64, usize) {
    v.iter().enumerate().map(|(k, q)| (dist(*q, p), k)).fold((f64::INFINITY, 0), |b, x| if x.0 < b.0 { x } else { b })
}

/// The new parts of the iso-lines: closed rings where every point is new,
/// else runs of new points with the old point before and after each.
fn pieces(loops: Vec<Vec<IsoPoint>>, direction: Direction, gap: f64) -> Vec<Piece> {
    let mut out = Vec::new();
    for lp in loops {
        let n = lp.len();
        // A stretch of old points shorter than `gap` joins the runs beside it.
        let mut keep: Vec<bool> = lp.iter().map(|p| p.1).collect();
        let Some(first_old) = lp.iter().position(|p| !p.1) else {
            let mut v: Vec<P2> = lp.iter().map(|p| p.0).collect();
            if direction == Direction::Conventional {
                v.reverse();
            }
            out.push(Piece::Ring(v));
            continue;
        };
        let Some(start) = (0..n).map(|i| (first_old + i) % n).find(|&i| lp[i].1 && !lp[(i + n - 1) % n].1) else {
            continue;
        };
        let mut i = 0;
        while i < n {
            let k = (start + i) % n;
            if lp[k].1 {
                i += 1;
                continue;
            }
            let (mut len, mut m) = (0.0, i);
            while m < n && !lp[(start + m) % n].1 {
                len += dist(lp[(start + m) % n].0, lp[(start + m + 1) % n].0);
                m += 1;
            }
            if len < gap && m < n {
                for q in i..m {
                    keep[(start + q) % n] = true;
                }
            }
            i = m;
        }
        let Some(old) = (0..n).find(|&i| !keep[i]) else {
            let mut v: Vec<P2> = lp.iter().map(|p| p.0).collect();
            if direction == Direction::Conventional {
                v.reverse();
            }
            out.push(Piece::Ring(v));
            continue;
        };
        let mut run: Vec<P2> = Vec::new();
        let mut walls: Vec<bool> = Vec::new();
        for i in 1..=n {
            let p = lp[(old + i) % n].0;
            let prev = lp[(old + i - 1) % n].0;
            if keep[(old + i) % n] {
                if run.is_empty() {
                    run.push(prev);
                    walls.push(lp[(old + i - 1) % n].2);
                }
                run.push(p);
                walls.push(lp[(old + i) % n].2);
            } else if !run.is_empty() {
                run.push(p);
                walls.push(lp[(old + i) % n].2);
                let mut v = std::mem::take(&mut run);
                let mut w = std::mem::take(&mut walls);
                if direction == Direction::Conventional {
                    v.reverse();
                    w.reverse();
                }
                let lead = w.iter().take_while(|&&x| x).count();
                out.push(Piece::Open(v, lead));
            }
        }
    }
    out
}

/// `c` with its arcs of radius over [`tol::MAX_ARC_RADIUS`] made lines (the
/// fit of nearly collinear points along a wall: a G-code reader refuses their
/// far centres).
fn flat_arcs(c: &Contour) -> Result<Contour, scallop_contour::ContourError> {
    let mut v = c.vertices();
    for k in 0..v.len().saturating_sub(1) {
        let chord = (v[k + 1].x - v[k].x).hypot(v[k + 1].y - v[k].y);
        let b = v[k].bulge.abs();
        if b > 0.0 && chord * (1.0 + b * b) / (4.0 * b) > tol::MAX_ARC_RADIUS {
            v[k].bulge = 0.0;
        }
    }
    Contour::new(&v, false)
}

/// The points as lines and arcs within [`tol::ARC_FIT`], far arcs made lines.
fn fit(points: &[P2]) -> Option<Contour> {
    Contour::from_points(points, false, tol::ARC_FIT).and_then(|c| flat_arcs(&c)).ok()
}
