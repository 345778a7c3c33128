//! Adaptive (engagement-controlled) clearing of one tool-centre region by a
//! walking tool.
//!
//! The tool enters at the region's deepest point (largest inscribed circle,
//! found by fast marching from the walls) by the emitter's helix, which
//! bores a disc. From there the path is made one step at a time, as the
//! adaptive-clearing literature does (for instance Stori and Wright 2000,
//! "Constant engagement tool path generation for convex geometries", J.
//! Manuf. Systems 19(3): the direction of each step chosen so that the
//! engagement stays at its target): a grid keeps the distance from every
//! point to the tool centres swept so far (the cut material is where it is
//! at most R), and each step of [`tol::WALK_STEP_SHARE`] R goes in the
//! direction whose engagement (the arc of the front half of the periphery in
//! material, the half the tool moves into) is the target `arccos(1 - ae /
//! R)`, found by bisection on the turn from the last heading: turning
//! towards the material (right when climbing with an M3 spindle) raises it,
//! turning away lowers it. A step that would leave the region turns further
//! away from the material until it stays in (exactly, against the region's
//! chords): the tool slides along a wall with no more than the target
//! engagement.
//!
//! A pass ends when it has cut nothing for [`tol::WALK_AIR_SHARE`] R (it is
//! cut back to its last cutting step) or when no step stays in the region.
//! The next pass starts at a tool centre of an earlier pass (or of the bore)
//! next to material, nearest the tool first, heading where the engagement is
//! at the target with the material on the cutting side; the way there is a
//! tool-down link through cleared area, a retract only when none is found
//! (`links.rs`). The region is done when no earlier centre has material
//! within reach. Last, the region's own rings are cut (the contour at the
//! allowance, exact and with arcs), linked the same way.
//!
//! Each pass is cut where it was planned, in the order it was planned, on
//! the field as it was then: the engagement measured while planning is the
//! engagement of the program (docs/roughing.md, "Adaptive clearing").

use std::collections::BinaryHeap;

use scallop_contour::{Contour, P2, Region, Vertex};

use crate::grid::{BIG, Blocks, Grid};
use crate::offset::Step;
use crate::{ClearOptions, Direction, RoughError, tol};

mod links;
mod squares;
use crate::walls::Edges;
use squares::{CORE, Fields, NOTHING, RIM, Squares};

/// The state of the planner of one region.
struct Planner<'a> {
    grid: Grid,
    /// Distance from the region (0 inside).
    reach: Vec<f64>,
    /// Distance from the tool centres swept so far.
    swept: Vec<f64>,
    /// What a probe reads in each square of the grid, where it is one
    /// answer ([`Squares`]): forgotten wherever `swept` changes.
    squares: Squares,
    /// Bounds of the swept field and of `reach` per block of squares, for
    /// [`Grid::quiet`]: kept as `squares` is.
    blocks: Blocks,
    /// The region grown a hair: links must stay in it.
    holder: Region,
    /// The holder's rings as chords, for its segment test
    /// ([`Planner::in_holder`]).
    fence: Edges,
    /// The region's boundary as chords, for the walk's exact wall test.
    edges: Edges,
    options: &'a ClearOptions,
    /// The largest accepted engagement (rad).
    accept: f64,
    /// The target engagement (rad).
    target: f64,
    /// Cells whose centre lies in the region.
    inside: Vec<bool>,
    /// The link search's cache per cell (`links.rs`).
    lattice: Vec<u32>,
    /// Chains cut so far (the cache's clock).
    epoch: u32,
    /// The moves the last pass left stamped on the swept field, until its
    /// lines are emitted (`links.rs`, `emit_runs`).
    stamped: Vec<(P2, P2)>,
    /// Tool centres of earlier passes, where a pass may start: the point,
    /// whether material may still lie next to it, its pass (0: the bore),
    /// that pass's [`Planner::away`] (a bore's or an air start's: that of
    /// the direction) and whether its run is peeled from its tail (both
    /// ways, [`Planner::next_start`]).
    starts: Vec<Start>,
    /// The sign of a turn away from the material on the pass being planned
    /// ([`Planner::away`]).
    hand: f64,
    /// Unit directions of the front half's probes about the heading +x,
    /// from the right.
    probes: Vec<P2>,
    /// The same from the left.
    probes_left: Vec<P2>,
    /// Unit directions of [`tol::ENGAGE_PROBES`] probes all round, from +x
    /// ([`Planner::engagement`]).
    round: Vec<P2>,
    /// Unit directions of [`tol::LINK_PROBES`] probes all round, from +x
    /// ([`Planner::clear_at`]).
    link_round: Vec<P2>,
    /// The tolerance of the lines a pass is emitted as (mm,
    /// [`tol::WALK_FIT_SHARE`]).
    fit: f64,
    /// The strip along the walls left to the rings (mm,
    /// [`tol::WALK_WALL_STRIP_SHARE`]).
    strip: f64,
    /// Signed distance to the boundary of the level's material (negative in
    /// it), when known ([`plan_adaptive_in`]): a probe where it is positive
    /// is in air.
    open: Option<Vec<f64>>,
    /// Signed distance to the boundary of the material the tool meets at
    /// the level beyond `open`'s (the material along the walls that the
    /// level's material leaves out, [`plan_adaptive_touching`]): it counts in
    /// the engagement ([`Planner::front`]) and nothing else, as the strip
    /// along the walls does; with `reach` raised past R outside it.
    touch: Option<(Vec<f64>, Vec<f64>)>,
    /// Where links may run besides the region ([`plan_adaptive_rest`]).
    room: Option<Room>,
}

/// The room of the links ([`plan_adaptive_rest`]): its cells, and as the
/// region's `holder` and `fence` are.
struct Room {
    inside: Vec<bool>,
    holder: Region,
    fence: Edges,
}

/// A place where a pass may start ([`Planner::starts`]).
type Start = (P2, bool, u32, f64, bool);

/// The walk's steps so far, its passes and its remaining steps.
struct Walk {
    steps: Vec<Step>,
    passes: usize,
    budget: usize,
}

/// One step of a walk: where the tool goes, its heading (rad) and engagement (rad).
#[derive(Clone, Copy)]
struct Stride {
    to: P2,
    heading: f64,
    phi: f64,
    /// The engagement (rad) leaving out the strip along the walls that the
    /// rings cut ([`tol::WALK_WALL_STRIP_SHARE`]): what tells cutting from air.
    core: f64,
    /// Whether the wall turned the step further away from the material than
    /// the engagement asked ([`Planner::turn_by`]): the tool slides along it.
    wall: bool,
}

/// The adaptive clearing of `region` (one connected tool-centre region):
/// passes, links and the region's rings (see the module documentation). The
/// first pass starts at the entry point, where the emitter's helix bores.
///
/// # Errors
/// [`RoughError::TooMuchWork`] beyond [`tol::MAX_PASSES`] passes or
/// [`tol::MAX_WALK_STEPS`] steps.
pub fn plan_adaptive(region: &Region, options: &ClearOptions) -> Result<Vec<Step>, RoughError> {
    plan_adaptive_in(region, None, options)
}

/// As [`plan_adaptive`], knowing where the material is: `material` is the
/// part of the plane that holds material at the level (the stock's section,
/// or the in-process stock's cells above the level); `None`, material
/// everywhere within R of the region (a closed pocket). Outside `material`
/// the tool cuts air: the walk counts no engagement there, a pass may start
/// from a tool centre clear of the material (entered by a straight plunge,
/// no helix: the stock's open sides of a level), and a ring of the region
/// that never comes within R of the material is not cut.
///
/// # Errors
/// As [`plan_adaptive`].
pub fn plan_adaptive_in(
    region: &Region,
    material: Option<&Region>,
    options: &ClearOptions,
) -> Result<Vec<Step>, RoughError> {
    plan_adaptive_touching(region, material, None, options)
}

/// As [`plan_adaptive_in`], `touched` being more material that the tool
/// meets at the level (a superset of `material`): in rest roughing, the
/// in-process stock within R of the level's whole region, where `material`
/// is the part of it the operation is to remove (the cells along the walls
/// that hold the allowance left out, [`crate::removable_material`]). The
/// walk counts `touched` in the engagement it holds at the target, and
/// `material` alone in what keeps a pass going or a start alive, in links
/// and in what the rings must cut: the tool slides along the walls with the
/// engagement the simulator measures there (docs/roughing.md, "Adaptive
/// clearing", "Rest roughing").
///
/// # Errors
/// As [`plan_adaptive`].
pub fn plan_adaptive_touching(
    region: &Region,
    material: Option<&Region>,
    touched: Option<&Region>,
    options: &ClearOptions,
) -> Result<Vec<Step>, RoughError> {
    plan_adaptive_rest(region, material, touched, None, options)
}

/// As [`plan_adaptive_touching`], `room` being where links may run besides
/// `region` (a superset of it): in rest roughing, the level's whole
/// tool-centre region, cleared by the operations before except where
/// `material` lies. A link between two pieces of the rest level's region
/// then goes round the material through it, within
/// [`tol::REST_LINK_ROOM_SHARE`] R of the region, tool down, where it had to
/// retract (docs/roughing.md, "Adaptive rest roughing: links through the
/// level's room").
///
/// # Errors
/// As [`plan_adaptive`].
pub fn plan_adaptive_rest(
    region: &Region,
    material: Option<&Region>,
    touched: Option<&Region>,
    room: Option<&Region>,
    options: &ClearOptions,
) -> Result<Vec<Step>, RoughError> {
    let r = options.tool_radius;
    let Some((mut lo, mut hi)) = region.bounds() else { return Ok(Vec::new()) };
    // The room near the region (links go no farther).
    let room = room.filter(|_| material.is_some()).map(|room| {
        let m = tol::REST_LINK_ROOM_SHARE * r;
        (lo, hi) = ([lo[0] - m, lo[1] - m], [hi[0] + m, hi[1] + m]);
        let rect = Region::from_polygons(&[vec![lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]]], false);
        room.intersection(&rect, options.chord_tolerance).union(region, options.chord_tolerance)
    });
    let grid = Grid::new(lo, hi, r + 4.0 * r * tol::GRID_SHARE, r * tol::GRID_SHARE)?;
    let h = grid.h;
    let fill_tolerance = (0.25 * h).min(options.chord_tolerance.max(1e-4));
    let inside = grid.fill(region, fill_tolerance);
    let room = room.map(|room| {
        let holder = room.offset(-tol::LINK_GROW);
        Room {
            inside: grid.fill(&room, fill_tolerance),
            fence: Edges::new(&holder, options.chord_tolerance, 8.0 * h),
            holder,
        }
    });
    let mut reach: Vec<f64> = inside.iter().map(|&i| if i { 0.0 } else { BIG }).collect();
    for ring in region.rings() {
        let pts = ring.to_points(0.25 * h);
        for (k, a) in pts.iter().enumerate() {
            grid.stamp_segment(&mut reach, *a, pts[(k + 1) % pts.len()], r + 2.0 * h, None);
        }
    }
    // Signed distance of each cell centre to the material's boundary: a
    // cell outside it is no material (its `reach` raised past R by that
    // much), and the probes read the field itself (`Planner::open_at`).
    let outside = material.map(|m| signed_distance(&grid, m, 2.0 * r + 4.0 * h, fill_tolerance));
    // The same for the material touched beyond it: its own field, and the
    // distance from the region raised past R outside it.
    let touch = touched.filter(|_| material.is_some()).map(|t| {
        let field = signed_distance(&grid, t, 2.0 * r + 4.0 * h, fill_tolerance);
        let raised = reach.iter().zip(&field).map(|(&v, &d)| if d > 0.0 { v.max(r + d) } else { v }).collect();
        (field, raised)
    });
    if let Some(out) = &outside {
        for (v, d) in reach.iter_mut().zip(out) {
            if *d > 0.0 {
                *v = v.max(r + d);
            }
        }
    }
    let walls: Vec<(usize, f64)> = (0..grid.len())
        .filter(|&k| inside[k] && [k - 1, k + 1, k - grid.nx, k + grid.nx].iter().any(|&n| !inside[n]))
        .map(|k| (k, 0.5 * h))
        .collect();
    let depth = grid.march(&inside, &walls);
    let Some(seed) = (0..grid.len())
        .filter(|&k| depth[k] < 0.5 * BIG)
        .max_by(|&a, &b| depth[a].total_cmp(&depth[b]).then(b.cmp(&a)))
    else {
        return Ok(rings_only(region, options));
    };
    let s = grid.centre(seed);
    let rh = tol::HELIX_RADIUS_SHARE * r;
    let r0 = if rh > 0.0 && region.holds_disc(s, rh) { rh } else { 0.0 };
    let target = (1.0 - (options.stepover / r).min(1.0)).acos();
    let chord = options.chord_tolerance.clamp(1e-5, tol::WALK_CHORD);
    let holder = region.offset(-tol::LINK_GROW);
    let fence = Edges::new(&holder, options.chord_tolerance, 8.0 * h);
    let mut planner = Planner {
        swept: vec![BIG; grid.len()],
        squares: Squares::new(grid.len(), grid.nx),
        blocks: Blocks::new(&grid, &reach),
        reach,
        holder,
        fence,
        edges: Edges::new(region, chord, 8.0 * h),
        options,
        accept: tol::ENGAGE_ACCEPT * target,
        target,
        lattice: vec![0; grid.len()],
        stamped: Vec::new(),
        epoch: 1,
        inside,
        grid,
        starts: Vec::new(),
        hand: if options.direction == Direction::Conventional { -1.0 } else { 1.0 },
        probes: front_probes(tol::ENGAGE_PROBES / 2),
        probes_left: front_probes(tol::ENGAGE_PROBES / 2).into_iter().rev().collect(),
        round: round_probes(tol::ENGAGE_PROBES),
        link_round: round_probes(tol::LINK_PROBES),
        fit: tol::WALK_FIT_SHARE * r,
        strip: tol::WALK_WALL_STRIP_SHARE * r,
        open: outside,
        touch,
        room,
    };
    if !planner.edges.contains(s) {
        return Ok(rings_only(region, options));
    }
    // Tool centres of the region just clear of the material (a band a cell
    // wide, R to R + h outside it, which one step of the walk brings into
    // it): starts from the air, entered by a straight plunge. The deepest
    // point is bored only when there are none.
    let air_starts: Vec<P2> = planner.open.as_ref().map_or_else(Vec::new, |out| {
        (0..planner.grid.len())
            .filter(|&k| planner.inside[k] && out[k] >= r && out[k] < r + h)
            .map(|k| planner.grid.centre(k))
            .filter(|&p| planner.edges.contains(p))
            .collect()
    });
    let mut walk = Walk { steps: Vec::new(), passes: 0, budget: tol::MAX_WALK_STEPS };
    let mut end = if air_starts.is_empty() {
        planner.bore(s, r0, 0);
        planner.walk_all(Some(s), &mut walk)?
    } else {
        let hand = planner.base_hand();
        planner.starts.extend(air_starts.iter().map(|&p| (p, true, 0, hand, false)));
        planner.walk_all(None, &mut walk)?
    };
    // Parts of the region the walk could not reach (joined to the rest by a
    // neck narrower than its steps, or a tooth gap it could not turn into):
    // a new entry at the deepest centre far from every cut, each.
    let far = r + 2.0 * h;
    // Entries tried from which nothing could be cut: no entry is tried again
    // within `far` of one. Their bores stay out of the swept field (nothing
    // was cut there: the region's rings meet that material, and cut it with
    // loops, `Planner::finish`).
    let mut tried = vec![false; planner.grid.len()];
    for _ in 0..tol::MAX_ENTRIES {
        let Some(k) = (0..planner.grid.len())
            .filter(|&k| !tried[k] && planner.inside[k] && depth[k] < 0.5 * BIG && planner.swept[k] > far)
            .filter(|&k| planner.open.as_ref().is_none_or(|out| out[k] < r))
            .max_by(|&a, &b| depth[a].total_cmp(&depth[b]).then(b.cmp(&a)))
        else {
            break;
        };
        let e = planner.grid.centre(k);
        tried[k] = true;
        if !planner.edges.contains(e) {
            continue;
        }
        let r0 = if rh > 0.0 && region.holds_disc(e, rh) { rh } else { 0.0 };
        let saved = (planner.swept.clone(), planner.lattice.clone(), planner.starts.len());
        walk.steps.push(Step::Link { tool_down: false, via: Vec::new(), cleared: false, to: None });
        #[allow(clippy::cast_possible_truncation, reason = "passes are bounded by MAX_PASSES")]
        planner.bore(e, r0, walk.passes as u32);
        let before = walk.steps.len();
        let reached = planner.walk_all(Some(e), &mut walk)?;
        if walk.steps.len() == before {
            // Nothing cut from there: the entry alone, a plunge or a helix;
            // the tool is still where the last walk left it.
            walk.steps.pop();
            planner.starts.truncate(saved.2);
            (planner.swept, planner.lattice) = (saved.0, saved.1);
            planner.squares.reset();
            planner.blocks.reset();
            let g = &planner.grid;
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "clamped to the grid")]
            let span = |c: f64, o: f64, n: usize| {
                let lo = ((c - far - o) / g.h).floor().max(0.0) as usize;
                let hi = (((c + far - o) / g.h).ceil().max(0.0) as usize).min(n - 1);
                lo..=hi
            };
            for j in span(e[1], g.y0, g.ny) {
                for i in span(e[0], g.x0, g.nx) {
                    let m = j * g.nx + i;
                    if dist(g.centre(m), e) <= far {
                        tried[m] = true;
                    }
                }
            }
        } else {
            end = reached;
        }
    }
    // The passes as lines and arcs within half the lines' own tolerance of
    // their vertices (the walk turns through many short lines), each kept
    // as lines unless its arcs stay in the region (exactly, against the
    // region's chords, the arcs as chords within `tol::WALK_CHORD`).
    let arc_fit = 0.5 * tol::WALK_FIT_SHARE * r;
    let mut steps: Vec<Step> = walk
        .steps
        .into_iter()
        .map(|step| match step {
            Step::Cut(c) => Step::Cut(fit_in(&planner.edges, &c, arc_fit).unwrap_or(c)),
            link @ Step::Link { .. } => link,
        })
        .collect();
    let mut rest = planner.finish(region, end);
    steps.append(&mut rest);
    Ok(steps)
}

/// The pass `c` as lines and arcs within `tolerance` of its points every
/// tenth of `tolerance` ([`Contour::from_points`]), each arc kept only where
/// it stays in the region (as chords within [`tol::WALK_CHORD`], exactly
/// against `edges`), else the points it stood for, as lines. `None` when
/// the fit fails.
fn fit_in(edges: &Edges, c: &Contour, tolerance: f64) -> Option<Contour> {
    let points = c.to_points(0.1 * tolerance);
    let fitted = Contour::from_points(&points, c.is_closed(), tolerance).ok()?.vertices();
    let n = fitted.len();
    let mut out = Vec::with_capacity(n);
    // The fit's vertices are some of `points`, in order: `at` is where the
    // last one was found.
    let mut at = 0usize;
    #[allow(clippy::float_cmp, reason = "the fit's vertices are copies of the points")]
    let find = |from: usize, v: &Vertex| (from..points.len()).find(|&k| points[k] == [v.x, v.y]);
    for k in 0..n {
        let v = fitted[k];
        let i = find(at, &v)?;
        at = i;
        let next = if k + 1 < n {
            Some(fitted[k + 1])
        } else if c.is_closed() {
            Some(fitted[0])
        } else {
            None
        };
        let Some(w) = next.filter(|_| v.bulge != 0.0) else {
            out.push(v);
            continue;
        };
        let arc = Contour::new(&[v, Vertex { bulge: 0.0, ..w }], false).ok()?;
        let chords = arc.to_points(tol::WALK_CHORD);
        if chords.windows(2).all(|m| edges.contains_segment(m[0], m[1])) {
            out.push(v);
            continue;
        }
        // The points the arc stood for, as lines.
        let j = if k + 1 < n { find(i + 1, &w)? } else { points.len() };
        out.push(Vertex { bulge: 0.0, ..v });
        out.extend(points[i + 1..j].iter().map(|p| Vertex { x: p[0], y: p[1], bulge: 0.0 }));
    }
    Contour::new(&out, c.is_closed()).ok()
}

/// A convex corner of a region's ring between two lines: its point, the
/// unit directions in and out (the region on the left), the turn (rad) and
/// the radius of the largest arc tangent to both within half of each line.
struct Corner {
    at: P2,
    u: P2,
    turn: f64,
    largest: f64,
}

/// The corners of the closed ring `c` that [`fillet_corners`] rounds.
fn corners(c: &Contour) -> Vec<Corner> {
    let v = c.vertices();
    let n = v.len();
    if !c.is_closed() || n < 3 {
        return Vec::new();
    }
    let mut out = Vec::new();
    for i in 0..n {
        let (a, b, d) = (&v[(i + n - 1) % n], &v[i], &v[(i + 1) % n]);
        let (l1, l2) = ((b.x - a.x).hypot(b.y - a.y), (d.x - b.x).hypot(d.y - b.y));
        if !(a.bulge == 0.0 && b.bulge == 0.0 && l1 > 0.0 && l2 > 0.0) {
            continue;
        }
        let (u, w) = ([(b.x - a.x) / l1, (b.y - a.y) / l1], [(d.x - b.x) / l2, (d.y - b.y) / l2]);
        let turn = (u[0] * w[1] - u[1] * w[0]).atan2(u[0] * w[0] + u[1] * w[1]);
        let largest = 0.5 * l1.min(l2) / (0.5 * turn).tan();
        if turn > 0.0 && turn <= tol::RING_FILLET_TURN && largest >= tol::RING_FILLET {
            out.push(Corner { at: [b.x, b.y], u, turn, largest });
        }
    }
    out
}

/// The closed ring `c` (the region on its left) with each left turn between
/// two lines of at most [`tol::RING_FILLET_TURN`] replaced by an arc of
/// radius [`tol::RING_FILLET`] tangent to both, where the lines are long
/// enough to hold it; `c` itself when nothing changes or the result is not
/// a valid contour.
fn fillet_corners(c: &Contour) -> Contour {
    let v = c.vertices();
    let n = v.len();
    if !c.is_closed() || n < 3 {
        return c.clone();
    }
    let rho = tol::RING_FILLET;
    let mut out = Vec::with_capacity(2 * n);
    let mut changed = false;
    for i in 0..n {
        let (a, b, d) = (&v[(i + n - 1) % n], &v[i], &v[(i + 1) % n]);
        let (l1, l2) = ((b.x - a.x).hypot(b.y - a.y), (d.x - b.x).hypot(d.y - b.y));
        let lines = a.bulge == 0.0 && b.bulge == 0.0 && l1 > 0.0 && l2 > 0.0;
        if lines {
            let (u, w) = ([(b.x - a.x) / l1, (b.y - a.y) / l1], [(d.x - b.x) / l2, (d.y - b.y) / l2]);
            let turn = (u[0] * w[1] - u[1] * w[0]).atan2(u[0] * w[0] + u[1] * w[1]);
            let t = rho * (0.5 * turn).tan();
            if turn > 0.0 && turn <= tol::RING_FILLET_TURN && t <= 0.5 * l1 && t <= 0.5 * l2 {
                let p1 = scallop_contour::Vertex { x: b.x - t * u[0], y: b.y - t * u[1], bulge: (0.25 * turn).tan() };
                let p2 = scallop_contour::Vertex { x: b.x + t * w[0], y: b.y + t * w[1], bulge: 0.0 };
                out.push(p1);
                out.push(p2);
                changed = true;
                continue;
            }
        }
        out.push(*b);
    }
    if !changed {
        return c.clone();
    }
    Contour::new(&out, true).unwrap_or_else(|_| c.clone())
}

/// `n` unit directions evenly over the front half about +x (from -90 to
/// +90 degrees, at the middles of `n` equal arcs).
fn front_probes(n: usize) -> Vec<P2> {
    (0..n)
        .map(|i| {
            #[allow(clippy::cast_precision_loss, reason = "a small count")]
            let a = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * (i as f64 + 0.5) / n as f64;
            [a.cos(), a.sin()]
        })
        .collect()
}

/// `n` unit directions evenly all round from +x (the `i`th at `TAU i / n`).
fn round_probes(n: usize) -> Vec<P2> {
    (0..n)
        .map(|i| {
            #[allow(clippy::cast_precision_loss, reason = "a small count")]
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            [a.cos(), a.sin()]
        })
        .collect()
}

fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// A measure of a step by its turn and the bound its engagement is
/// compared with ([`Planner::stride_within`]).
type Measure<'a> = &'a dyn Fn(f64, f64) -> Option<Stride>;

/// The turn at lattice point `k` of `n` (a power of two) between `lo` and
/// `hi`, as bisection from `lo` and `hi` reaches it: each midpoint
/// `0.5 * (lo + hi)` of the bracket holding `k`, so that a search on the
/// lattice tests the very turns a bisection would.
fn bisection_turn(lo: f64, hi: f64, k: usize, n: usize) -> f64 {
    let (mut lo, mut hi, mut klo, mut khi) = (lo, hi, 0usize, n);
    loop {
        if k <= klo {
            return lo;
        }
        if k >= khi {
            return hi;
        }
        let (mid, kmid) = (0.5 * (lo + hi), klo + (khi - klo) / 2);
        if k < kmid {
            (hi, khi) = (mid, kmid);
        } else {
            (lo, klo) = (mid, kmid);
        }
    }
}

/// The largest count `k` of `n` probes whose share of a half turn, `PI k
/// / n` as [`Planner::front_within`] computes it, is at most `limit` (0
/// when none is; `n` when `limit` is not a number).
fn most_within(n: usize, limit: f64) -> usize {
    #[allow(clippy::cast_precision_loss, reason = "small counts")]
    let share = |k: usize| std::f64::consts::PI * k as f64 / n as f64;
    if n == 0 || share(n) <= limit || limit.is_nan() {
        return n;
    }
    if share(1) > limit {
        return 0;
    }
    // From the estimate, to the last count within (share(1) is within,
    // share(n) is not).
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, clippy::cast_precision_loss)]
    let mut k = ((limit / std::f64::consts::PI * n as f64) as usize).clamp(1, n - 1);
    while share(k) > limit {
        k -= 1;
    }
    while share(k + 1) <= limit {
        k += 1;
    }
    k
}

fn ahead(p: P2, heading: f64, len: f64) -> P2 {
    [p[0] + len * heading.cos(), p[1] + len * heading.sin()]
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
    match direction.rings() {
        Direction::Conventional => c.reversed(),
        Direction::Climb | Direction::Both => c.clone(),
    }
}

impl Planner<'_> {
    /// The helix's bore about `s` (tool centre circle of radius `r0`), or a
    /// plunge at `s`; its centres are where the first pass may start.
    fn bore(&mut self, s: P2, r0: f64, pass: u32) {
        let w = self.options.tool_radius + 2.0 * self.grid.h;
        let hand = self.base_hand();
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small positive count")]
        let n = ((std::f64::consts::TAU * r0 / self.grid.h).ceil() as usize).max(1);
        let on = |i: usize| {
            #[allow(clippy::cast_precision_loss, reason = "a small count")]
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            [s[0] + r0 * a.cos(), s[1] + r0 * a.sin()]
        };
        for i in 0..n {
            self.stamp_full(on(i), on(i + 1), w);
            if self.edges.contains(on(i)) {
                self.starts.push((on(i), true, pass, hand, false));
            }
        }
        self.stamp_full(s, s, w);
        self.starts.push((s, true, pass, hand, false));
    }

    /// Whether the segment `a`-`b` stays in the holder (as
    /// `Region::contains_segment` at the chord tolerance): at once when `a`
    /// lies inside the holder's chords and the segment keeps farther than
    /// twice the tolerance (and a micrometre) from every chord (then the
    /// exact rings, within the tolerance of the chords, hold it too, and
    /// clipping by the chords leaves nothing outside); else by that test's
    /// rule on the chords near the segment ([`Edges::keeps_inside`]).
    fn in_holder(&self, a: P2, b: P2) -> bool {
        self.holds(&self.holder, &self.fence, a, b)
    }

    /// As [`Planner::in_holder`], in the links' room when there is one
    /// ([`plan_adaptive_rest`]).
    fn in_room(&self, a: P2, b: P2) -> bool {
        match &self.room {
            Some(room) => self.holds(&room.holder, &room.fence, a, b),
            None => self.in_holder(a, b),
        }
    }

    /// The test of [`Planner::in_holder`] against `holder` and its chords
    /// `fence`.
    fn holds(&self, holder: &Region, fence: &Edges, a: P2, b: P2) -> bool {
        let margin = 2.0 * self.options.chord_tolerance + 1e-3;
        if fence.contains(a) && fence.clear_of(a, b, margin) {
            return true;
        }
        holder.contains(a) && holder.contains(b) && fence.keeps_inside(a, b, scallop_contour::tol::LINK_SLACK)
    }

    /// Whether a link may pass through cell `k` (in the region, or in the
    /// links' room when there is one).
    fn link_cell(&self, k: usize) -> bool {
        self.room.as_ref().map_or(self.inside[k], |room| room.inside[k])
    }

    /// Stamps the move `a`-`b` on the swept field (R and two cells about
    /// it, old values to `undo`), leaving cells at least
    /// two cells and [`tol::AIR_RING_CHIP`] inside the cut as they are
    /// ([`Grid::stamp_segment_over`]): the field is read only against
    /// thresholds of R less [`tol::AIR_RING_CHIP`] or more, which such a
    /// cell's squares answer alike either way.
    fn stamp_swept(&mut self, a: P2, b: P2, mut undo: Option<&mut Vec<(usize, f64)>>) {
        let (r, h) = (self.options.tool_radius, self.grid.h);
        let floor = self.grid.settled(r - tol::AIR_RING_CHIP);
        let (squares, blocks) = (&self.squares, &self.blocks);
        self.grid.stamp_segment_with(&mut self.swept, a, b, r + 2.0 * h, floor, |k, old| {
            if let Some(u) = undo.as_deref_mut() {
                u.push((k, old));
            }
            squares.lowered(k, old, r);
            blocks.lowered(k, old, r - tol::AIR_RING_CHIP);
        });
    }

    /// Stamps the move `a`-`b` on the swept field within `w` of it, every
    /// cell (the bore's).
    fn stamp_full(&mut self, a: P2, b: P2, w: f64) {
        let r = self.options.tool_radius;
        let (squares, blocks) = (&self.squares, &self.blocks);
        self.grid.stamp_segment_with(&mut self.swept, a, b, w, f64::NEG_INFINITY, |k, old| {
            squares.lowered(k, old, r);
            blocks.lowered(k, old, r - tol::AIR_RING_CHIP);
        });
    }

    /// Sets cell `k` of the swept field back to `v` (undoing a stamp).
    fn restore_swept(&mut self, k: usize, v: f64) {
        self.swept[k] = v;
        self.squares.changed(k);
        self.blocks.changed(k);
    }

    /// The fields a probe reads ([`squares::probe`]).
    fn fields(&self) -> Fields<'_> {
        let r = self.options.tool_radius;
        Fields {
            swept: &self.swept,
            reach: &self.reach,
            open: self.open.as_deref(),
            touch: self.touch.as_ref().map(|(f, near)| (&f[..], &near[..])),
            nx: self.grid.nx,
            r,
            strip: r - self.strip,
        }
    }

    /// Whether the point `q` is material: within R of the region (inside the
    /// pocket) and farther than R from every swept centre.
    fn material(&self, q: P2) -> bool {
        let r = self.options.tool_radius;
        // The square's answer where it has one (its material is this).
        match self.grid.locate(q).map(|at| self.squares.get(at.0, &self.fields())) {
            None | Some(NOTHING) => return false,
            Some(CORE | RIM) => return true,
            _ => {}
        }
        self.grid.sample(&self.swept, q) > r
            && self.grid.sample(&self.reach, q) < r
            && !self.grid.locate(q).is_some_and(|at| self.open_at(at))
    }

    /// Whether the grid point `at` lies outside the level's material (in
    /// air), when that is known.
    fn open_at(&self, at: (usize, f64, f64)) -> bool {
        self.open.as_ref().is_some_and(|f| Grid::interpolate(f, self.grid.nx, at) > 0.0)
    }

    /// The engagement (rad) of the tool centred at `p`: the share of its
    /// periphery in material, all round.
    fn engagement(&self, p: P2) -> f64 {
        let r = self.options.tool_radius;
        let n = self.round.len();
        let mut count = 0usize;
        for &[c, s] in &self.round {
            if self.material([p[0] + r * c, p[1] + r * s]) {
                count += 1;
            }
        }
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let phi = std::f64::consts::TAU * count as f64 / n as f64;
        phi
    }

    /// The engagement (rad) of the tool centred at `p` moving along
    /// `heading`: the arc of the front half of its periphery in material (the
    /// back half lies in what the tool has just cut); and that arc without
    /// the strip along the walls ([`Stride::core`]).
    fn front(&self, p: P2, heading: f64) -> (f64, f64) {
        self.front_within(p, heading, f64::INFINITY).unwrap_or((0.0, 0.0))
    }

    /// [`Planner::front`], or `None` as soon as the engagement is found over
    /// `limit` (the probes on the material's side come first: from the
    /// right when climbing, from the left when not, [`Planner::away`]; the
    /// counts do not depend on the order).
    fn front_within(&self, p: P2, heading: f64, limit: f64) -> Option<(f64, f64)> {
        let r = self.options.tool_radius;
        let n = self.probes.len();
        let (s, c) = heading.sin_cos();
        #[allow(clippy::cast_precision_loss, reason = "small counts")]
        let share = |k: usize| std::f64::consts::PI * k as f64 / n as f64;
        // `share(count) > limit` as a count (`share` only grows with it).
        let most = most_within(n, limit);
        let (mut count, mut core) = (0usize, 0usize);
        let probes = if self.away() < 0.0 { &self.probes_left } else { &self.probes };
        let fields = self.fields();
        for &[u, v] in probes {
            // The probe's direction (u, v) about the heading, rotated onto it.
            let q = [p[0] + r * (u * c - v * s), p[1] + r * (u * s + v * c)];
            // Off the grid both fields are far: no material.
            let Some(at) = self.grid.locate(q) else { continue };
            // The square's answer where it has one, else the probe's own.
            let (counted, in_core) = match self.squares.get(at.0, &fields) {
                NOTHING => continue,
                CORE => (true, true),
                RIM => (true, false),
                _ => squares::probe(&fields, at),
            };
            if counted {
                count += 1;
                if count > most {
                    return None;
                }
                core += usize::from(in_core);
            }
        }
        Some((share(count), share(core)))
    }

    /// The sign of a turn away from the material on the pass being planned:
    /// left (counter-clockwise, 1) when climbing, the material on the tool's
    /// right; right (-1) when milling conventionally. Both ways, it changes
    /// from pass to pass ([`Planner::next_start`]).
    fn away(&self) -> f64 {
        self.hand
    }

    /// The sign of [`Planner::away`] of the passes that start from a bore or
    /// from the air.
    fn base_hand(&self) -> f64 {
        if self.options.direction == Direction::Conventional { -1.0 } else { 1.0 }
    }

    fn stride(&self, p: P2, heading: f64) -> Stride {
        self.stride_by(p, heading, tol::WALK_STEP_SHARE * self.options.tool_radius)
    }

    fn stride_by(&self, p: P2, heading: f64, len: f64) -> Stride {
        let to = ahead(p, heading, len);
        let (phi, core) = self.front(to, heading);
        Stride { to, heading, phi, core, wall: false }
    }

    /// The step from `p` along `heading` of length `len`, its engagement
    /// the largest at the points `along` it (shares of `len`), or `None`
    /// when one is over `limit`.
    fn stride_within(&self, p: P2, heading: f64, len: f64, limit: f64, along: &[f64]) -> Option<Stride> {
        let (mut phi, mut core) = (0.0f64, 0.0f64);
        for &f in along {
            let (a, b) = self.front_within(ahead(p, heading, f * len), heading, limit)?;
            phi = phi.max(a);
            core = core.max(b);
        }
        Some(Stride { to: ahead(p, heading, len), heading, phi, core, wall: false })
    }

    /// The next step from `p` after a step along `heading` (see
    /// [`Planner::next_by`]).
    fn next(&self, p: P2, heading: f64) -> Option<Stride> {
        self.next_by(p, heading, tol::WALK_STEP_SHARE * self.options.tool_radius)
    }

    /// The next step from `p` after a step along `heading`: the turn of
    /// [`Planner::turn_by`], its engagement measured at the points
    /// [`tol::WALK_STEP_SAMPLES`] along it. Right after a turn towards the material,
    /// or halfway along a step, the front half can lie along the thin edge
    /// of what earlier cuts left where it does not at the step's end
    /// (docs/roughing.md, "Adaptive clearing", step 3).
    fn next_by(&self, p: P2, heading: f64, len: f64) -> Option<Stride> {
        self.turn_by(p, heading, len, &tol::WALK_STEP_SAMPLES)
    }

    /// The step whose engagement is the target: its turn (rad, away from
    /// the material) between `toward` (the sharpest turn towards the
    /// material) and `back` (the sharpest away). That towards the material
    /// when its step keeps within the target (its engagement at every
    /// point along it); else, when the sharpest away is over the accepted
    /// bound, `None`, and when it is over the target, that one; else the
    /// bisection's turn between them (`tol::WALK_BISECTIONS` halvings, the
    /// least turn found to keep within the target).
    ///
    /// Each test measures the step's end first (`end_within`) and the other
    /// points (`rest`) only when the end keeps within the bound: a step is
    /// over the bound when any point is, so the answers are those of
    /// measuring the points in order, found sooner when the step is over
    /// (docs/roughing.md, "Adaptive clearing", step 3).
    fn turn_bisect(
        &self,
        (toward, back): (f64, f64),
        (end_within, rest): (Measure<'_>, Measure<'_>),
    ) -> Option<Stride> {
        let n = 1usize << tol::WALK_BISECTIONS;
        let at = |k: usize| bisection_turn(toward, back, k, n);
        // The step turned by `d`, its engagement at every point within
        // `limit`: the end's, then the others'.
        let measure = |d: f64, limit: f64| {
            end_within(d, limit).and_then(|end| {
                rest(d, limit).map(|m| Stride { phi: m.phi.max(end.phi), core: m.core.max(end.core), ..end })
            })
        };
        let full = |k: usize| measure(at(k), self.target);
        if let Some(m) = full(0) {
            return Some(m);
        }
        let hard = measure(back, self.accept)?;
        if hard.phi > self.target {
            return Some(hard);
        }
        let (mut lo, mut hi, mut best) = (0, n, hard);
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            match full(mid) {
                None => lo = mid,
                Some(m) => (hi, best) = (mid, m),
            }
        }
        Some(best)
    }

    /// The step from `p` after a step along `heading`, its engagement
    /// measured at the points `along` it: the turn whose
    /// engagement is the target (bisection between the sharpest turn towards
    /// the material and the sharpest away), then, when that step leaves the
    /// region, the least further turn away that stays in it with the
    /// engagement within the accepted bound. `None` when there is none.
    fn turn_by(&self, p: P2, heading: f64, len: f64, along: &[f64]) -> Option<Stride> {
        let away = self.away();
        // The step turned by `d`: its end alone, or its stride unless its
        // engagement is over `limit` (`None`, found early: where only that
        // comparison matters).
        let end = |d: f64| ahead(p, heading + away * d, len);
        let within = |d: f64, limit: f64| self.stride_within(p, heading + away * d, len, limit, along);
        let (toward, back) = (-tol::WALK_TURN, tol::WALK_TURN_HARD);
        let last = along.len().saturating_sub(1);
        let end_within = |d: f64, limit: f64| self.stride_within(p, heading + away * d, len, limit, &along[last..]);
        let rest = |d: f64, limit: f64| self.stride_within(p, heading + away * d, len, limit, &along[..last]);
        let best = self.turn_bisect((toward, back), (&end_within, &rest))?;
        if self.edges.contains_segment(p, best.to) {
            return Some(best);
        }
        // Turn further away until the step stays in: the first turn that
        // does, then bisection back towards the wall.
        let d0 = (best.heading - heading) * away;
        let mut prev = d0;
        let mut d = d0;
        loop {
            d += tol::WALK_WALL_TURN;
            if d > tol::WALK_TURN_HARD + 1e-12 {
                return None;
            }
            if self.edges.contains_segment(p, end(d)) {
                let (mut lo, mut hi) = (prev, d);
                for _ in 0..tol::WALK_BISECTIONS {
                    let mid = 0.5 * (lo + hi);
                    if self.edges.contains_segment(p, end(mid)) {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                if let Some(ok) = within(hi, self.accept) {
                    return Some(Stride { wall: true, ..ok });
                }
                // Along the wall the engagement is over the bound: further
                // away, the first step in the region under it, if any.
                let mut e = hi;
                while e <= tol::WALK_TURN_HARD {
                    e += tol::WALK_WALL_TURN;
                    if self.edges.contains_segment(p, end(e))
                        && let Some(m) = within(e, self.accept)
                    {
                        return Some(Stride { wall: true, ..m });
                    }
                }
                return None;
            }
            prev = d;
        }
    }

    /// The first step of a pass starting at `p`: from the heading of the
    /// largest engagement all round, turned away from the material until the
    /// engagement is the target (and further at a wall), as along a pass.
    /// `None` when no step from `p` meets material (or none that stays in
    /// the region does).
    fn start_heading(&self, p: P2) -> Option<Stride> {
        if self.nothing_near(p) {
            return None;
        }
        let n = tol::WALK_START_HEADINGS;
        #[allow(clippy::cast_precision_loss, reason = "a small count")]
        let heading = |i: usize| std::f64::consts::TAU * i as f64 / n as f64;
        let (mut best, mut phi) = (0.0, -1.0);
        for i in 0..n {
            let s = self.stride(p, heading(i));
            if s.core > phi {
                (best, phi) = (heading(i), s.core);
            }
        }
        if phi < tol::WALK_AIR * self.target {
            return None;
        }
        // From the heading into the material, the turn away to the target
        // and, at a wall, further away, as along a pass.
        self.next(p, best).filter(|s| s.core >= tol::WALK_AIR * self.target)
    }

    /// Whether no material lies within reach of any probe of any heading's
    /// stride from `p` (the probes lie R beyond a step of `len` from `p`):
    /// then no heading meets material, decided on the squares about that
    /// ring.
    fn nothing_near(&self, p: P2) -> bool {
        let (r, h) = (self.options.tool_radius, self.grid.h);
        let len = tol::WALK_STEP_SHARE * r;
        let (inner, outer) = (r - len - h, r + len + h);
        let ring = |m: P2| {
            let d = dist(m, p);
            d >= inner && d <= outer
        };
        let bounds = ([p[0] - outer, p[1] - outer], [p[0] + outer, p[1] + outer]);
        self.grid.quiet(&self.swept, &self.reach, bounds, ring, r, r, Some(&self.blocks))
    }

    /// The direction (rad) from `p` towards the level's material when the
    /// tool centred at `p` is clear of it (an air start, R or more outside
    /// it): against the gradient of the signed distance. `None` elsewhere.
    fn air_inward(&self, p: P2) -> Option<f64> {
        let out = self.open.as_ref()?;
        let r = self.options.tool_radius;
        if self.grid.sample(out, p) < r - tol::LINK_SLACK {
            return None;
        }
        let e = 0.5 * self.grid.h;
        let f = |q: P2| self.grid.sample(out, q);
        let (gx, gy) = (f([p[0] + e, p[1]]) - f([p[0] - e, p[1]]), f([p[0], p[1] + e]) - f([p[0], p[1] - e]));
        (gx.hypot(gy) > 0.0 && gx.is_finite() && gy.is_finite()).then(|| (-gy).atan2(-gx))
    }

    /// The first step of a pass from the air start `p`: along the material's
    /// edge with the material on the side the walk turns towards (right when
    /// climbing), turned towards it until the engagement is the target (as
    /// along a pass): a lead-in that meets the material gradually. The
    /// material lies `inward` ([`Planner::air_inward`]).
    fn air_heading(&self, p: P2, inward: f64) -> Option<Stride> {
        if self.nothing_near(p) {
            return None;
        }
        let along = inward + self.away() * std::f64::consts::FRAC_PI_2;
        self.next(p, along)
    }

    /// Whether the pass `run` (its steps' points, cut back to the last that
    /// cut) is short and ends across a narrow channel: shorter than
    /// [`tol::WALK_BOTH_WAYS_SHARE`] R, and the region narrower than that
    /// across its last step, both ways from its end (the lines square to the
    /// step leave the region within that length on both sides).
    fn across_narrow(&self, run: &[P2]) -> bool {
        let width = tol::WALK_BOTH_WAYS_SHARE * self.options.tool_radius;
        let step = tol::WALK_STEP_SHARE * self.options.tool_radius;
        #[allow(clippy::cast_precision_loss, reason = "a step count")]
        let short = (run.len() - 1) as f64 * step < width;
        short && self.narrow_at(run, width)
    }

    /// Whether the region across the last step of `run`, from its end, is
    /// narrower than `width` (the lines square to the step leave the region
    /// within `width` on both sides); `false` for a run of one point.
    fn narrow_at(&self, run: &[P2], width: f64) -> bool {
        let [.., a, b] = run[..] else { return false };
        let heading = (b[1] - a[1]).atan2(b[0] - a[0]);
        let side = |turn: f64| !self.edges.contains_segment(b, ahead(b, heading + turn, width));
        side(std::f64::consts::FRAC_PI_2) && side(-std::f64::consts::FRAC_PI_2)
    }

    /// A pass from `p` along `heading`: its points (the first is `p`), cut
    /// back to its last step that cut, as lines ([`simplify`]), and
    /// the area it cleared (mm^2, on the grid's cells) and its steps' points;
    /// the swept field holds the lines.
    fn pass(&mut self, p: P2, first: Stride, budget: &mut usize) -> Result<(Vec<P2>, f64, Vec<P2>), RoughError> {
        let air_len = tol::WALK_AIR_SHARE * self.options.tool_radius;
        let step = tol::WALK_STEP_SHARE * self.options.tool_radius;
        let mut run = vec![p];
        let mut undo: Vec<(usize, f64)> = Vec::new();
        // Per point of `run`: the undo log's length before its move.
        let mut marks = vec![0usize];
        let mut last_cut = 0usize;
        // Per point of `run` after the first: whether its step slid along a
        // wall.
        let mut slid: Vec<bool> = Vec::new();
        let mut at = p;
        let mut next = Some(first);
        while let Some(s) = next {
            if *budget == 0 {
                return Err(RoughError::TooMuchWork { what: "adaptive steps", limit: tol::MAX_WALK_STEPS });
            }
            *budget -= 1;
            marks.push(undo.len());
            self.stamp_swept(at, s.to, Some(&mut undo));
            run.push(s.to);
            slid.push(s.wall);
            if s.core >= tol::WALK_AIR * self.target {
                last_cut = run.len() - 1;
            }
            #[allow(clippy::cast_precision_loss, reason = "a step count")]
            let idle = (run.len() - 1 - last_cut) as f64 * step;
            if idle > air_len {
                break;
            }
            at = s.to;
            next = self.next(at, s.heading);
        }
        // Back to the last step that cut: the air after it is not cut.
        let mut keep = last_cut + 1;
        // A short pass across a narrow channel (wall to wall, the channel
        // narrower than the length that makes a pass long) ends with its last
        // step slid along the far wall: a tight turn the tool crawls through,
        // then a reversal or a link back. That step is not cut: the pass ends
        // where the wall turned it, and the next pass, planned on the field
        // without the step, takes what it would have cut (docs/roughing.md,
        // "Adaptive clearing", narrow channels).
        if keep > 2 && slid[keep - 2] && self.across_narrow(&run[..keep]) {
            keep -= 1;
        }
        if keep < run.len() {
            let mark = marks[keep];
            while undo.len() > mark {
                if let Some((k, v)) = undo.pop() {
                    self.restore_swept(k, v);
                }
            }
            run.truncate(keep);
        }
        // The pass as it is emitted: the fewest lines within `fit` of its
        // steps, in the region; the swept field then holds those lines, not
        // the steps, so that later passes are planned on what the program
        // cuts.
        let kept = simplify(&self.edges, &run, self.fit);
        while let Some((k, v)) = undo.pop() {
            self.restore_swept(k, v);
        }
        // A line that replaces several steps heads a little off each of
        // them, and the front half it cuts turns with it: where its
        // engagement (at the points `WALK_STEP_SAMPLES` along it, on the
        // field the lines before it leave) is over the accepted bound, the
        // steps are cut instead.
        let mut lines = vec![run[0]];
        for pair in kept.windows(2) {
            let (i, j) = (pair[0], pair[1]);
            let merged = j > i + 1 && {
                let (a, b) = (run[i], run[j]);
                let heading = (b[1] - a[1]).atan2(b[0] - a[0]);
                self.stride_within(a, heading, dist(a, b), self.accept, &tol::WALK_STEP_SAMPLES).is_some()
            };
            let span: &[P2] = if merged || j == i + 1 { &run[j..=j] } else { &run[i + 1..=j] };
            for &q in span {
                let from = lines[lines.len() - 1];
                self.stamp_swept(from, q, Some(&mut undo));
                lines.push(q);
            }
        }
        self.stamped = lines.windows(2).map(|m| (m[0], m[1])).collect();
        let r = self.options.tool_radius;
        let cleared =
            undo.iter().filter(|&&(k, old)| old > r && self.swept[k] <= r && self.reach[k] < r - self.strip).count();
        #[allow(clippy::cast_precision_loss, reason = "a cell count")]
        let area = cleared as f64 * self.grid.h * self.grid.h;
        Ok((lines, area, run))
    }

    /// Every pass from the bore about `s` until no earlier centre has
    /// material next to it, its steps and links appended to `walk`: where
    /// the tool ends.
    /// The passes from the bore at `s`, or, with `None`, from the starts
    /// already listed (tool centres in air: the first pass is entered by a
    /// straight plunge at its start).
    fn walk_all(&mut self, s: Option<P2>, walk: &mut Walk) -> Result<P2, RoughError> {
        let air = s.is_none();
        let s = s.or_else(|| self.starts.first().map(|t| t.0)).unwrap_or([0.0, 0.0]);
        let mut pos = s;
        // The heading of the last pass's last move.
        let mut out: Option<f64> = None;
        // The last pass's `away`: its end turns that way into the link.
        let mut last_hand = self.hand;
        let mut fresh = true;
        let spacing = tol::WALK_START_SPACING * self.options.tool_radius;
        let step = tol::WALK_STEP_SHARE * self.options.tool_radius;
        while let Some((i, first)) = self.next_start() {
            let start = self.starts[i].0;
            walk.passes += 1;
            let passes = walk.passes;
            if passes > tol::MAX_PASSES {
                return Err(RoughError::TooMuchWork { what: "adaptive passes", limit: tol::MAX_PASSES });
            }
            // The link there first: it runs on the field as the tool finds it
            // (the pass would clear what the link's approach meets).
            let link = (!fresh).then(|| self.turning_link(pos, out, (last_hand, self.hand), start, first.heading));
            let (run, area, walked) = self.pass(start, first, &mut walk.budget)?;
            let hand = self.hand;
            let steps = walked.len() - 1;
            // A start serves once: a pass from it that could not go on (the
            // engagement would rise over the target along a wall) would
            // only be tried again; its neighbours serve instead.
            self.starts[i].1 = false;
            if run.len() < 2 {
                continue;
            }
            // The pass's own start heads its run of starts: the next pass
            // peels the new frontier from the same upstream end (from a
            // point further along, the frontier would creep towards the
            // pass's end, leaving a growing wedge at its start). Only after
            // progress: a pass that cleared little (slivers in a corner the
            // tool cannot quite reach) would be made again and again.
            #[allow(clippy::cast_precision_loss, reason = "a step count")]
            let progress = area >= tol::WALK_RESTART_SHARE * steps as f64 * step * self.options.stepover;
            // Both ways, the run a pass leaves is peeled from its tail, back
            // along it ([`Planner::next_start`]), but that of a pass that
            // made no progress (from their tails, two such passes could undo
            // each other's turn for ever) or of a short one (the link back
            // to its head is short, and the reversal at its end would stop
            // the tool as often, where a U-turn rarely fits).
            #[allow(clippy::cast_precision_loss, reason = "a step count")]
            let long = steps as f64 * step >= tol::WALK_BOTH_WAYS_SHARE * self.options.tool_radius;
            // Nor that of a crossing (its ends closer than
            // [`tol::WALK_BOTH_WAYS_SHARE`] R) that ends in a channel
            // narrower than [`tol::WALK_NARROW_END_SHARE`] R (a crossing of a
            // narrow bar that slid along its far wall): the pass back would
            // start with a reversal there, a stop, where no U-turn fits; the
            // link back to the run's head turns (docs/roughing.md, "Adaptive
            // clearing", "Both ways"). A pass along a narrow band (a rest
            // level's) is still followed back.
            let crossing = walked.len() >= 2
                && dist(walked[0], walked[walked.len() - 1]) < tol::WALK_BOTH_WAYS_SHARE * self.options.tool_radius;
            let tail = self.options.direction == Direction::Both
                && progress
                && long
                && !(crossing && self.narrow_at(&walked, tol::WALK_NARROW_END_SHARE * self.options.tool_radius));
            #[allow(clippy::cast_possible_truncation, reason = "passes are bounded by MAX_PASSES")]
            let pass_no = passes as u32;
            if steps >= tol::WALK_RESTART_STEPS && progress {
                self.starts.push((start, true, pass_no, hand, tail));
            }
            // The steps' points, every `spacing` or more: within `fit` of
            // the lines the tool cuts.
            let mut last = start;
            for &p in &walked[1..] {
                if dist(p, last) >= spacing {
                    self.starts.push((p, true, pass_no, hand, tail));
                    last = p;
                }
            }
            // Peeled from its tail, the next pass starts right where this one
            // ended.
            if let Some(&end) = walked.last()
                && tail
                && dist(end, last) > tol::WALK_END_START_SHARE * spacing
            {
                self.starts.push((end, true, pass_no, hand, tail));
            }
            if fresh && air {
                // A tool centre in air: plunged straight, no helix.
                walk.steps.push(Step::Link { tool_down: false, via: Vec::new(), cleared: true, to: None });
                self.emit_runs(&mut walk.steps, vec![run.clone()]);
            } else if fresh && dist(start, s) > 0.0 {
                // From the helix's end (its centre) to the pass: inside the bore.
                let mut first = vec![s];
                first.extend_from_slice(&run);
                self.emit_runs(&mut walk.steps, vec![first]);
            } else {
                if let Some(link) = link {
                    walk.steps.push(link);
                }
                self.emit_runs(&mut walk.steps, vec![run.clone()]);
            }
            fresh = false;
            last_hand = hand;
            pos = *run.last().unwrap_or(&pos);
            if let [.., a, b] = run[..] {
                out = Some((b[1] - a[1]).atan2(b[0] - a[0]));
            }
        }
        Ok(pos)
    }

    /// The start of the next pass: the head of a run of earlier centres
    /// next to material (the one before it in its pass has none), on the
    /// latest pass that has one, and its heading. A pass from a head goes
    /// along the whole run, the material on the same side, so the frontier
    /// that the last pass made is peeled from its upstream end, and a branch
    /// is cleared before the tool moves on. Centres found with no material
    /// are dropped for good (material only goes away), which makes the next
    /// one a head.
    ///
    /// Both ways ([`Direction::Both`]), a pass's run is peeled from its tail
    /// instead (the one after it has none), the other way round: the tool
    /// goes back along the frontier from where the last pass ended, with the
    /// material on its other side. A bore's and the air's starts are heads.
    /// Sets [`Planner::hand`] for the pass.
    fn next_start(&mut self) -> Option<(usize, Stride)> {
        let gap = 2.0 * tol::WALK_START_SPACING * self.options.tool_radius;
        let both = self.options.direction == Direction::Both;
        let n = self.starts.len();
        let tails = |starts: &[Start], i: usize| both && starts[i].4;
        let near = |starts: &[Start], i: usize, j: usize| {
            starts[j].1 && starts[j].2 == starts[i].2 && dist(starts[j].0, starts[i].0) <= gap
        };
        let head = |starts: &[Start], i: usize| starts[i].1 && !tails(starts, i) && (i == 0 || !near(starts, i, i - 1));
        let tail = |starts: &[Start], i: usize| {
            starts[i].1 && tails(starts, i) && (i + 1 == starts.len() || !near(starts, i, i + 1))
        };
        #[allow(clippy::cast_possible_wrap, reason = "starts are bounded by the walk's steps")]
        let key = |starts: &[Start], i: usize| {
            let order = if tails(starts, i) { i as i64 } else { -(i as i64) };
            (starts[i].2, order, i)
        };
        let mut heap: BinaryHeap<(u32, i64, usize)> =
            (0..n).filter(|&i| head(&self.starts, i) || tail(&self.starts, i)).map(|i| key(&self.starts, i)).collect();
        while let Some((_, _, i)) = heap.pop() {
            if !self.starts[i].1 {
                continue;
            }
            let p = self.starts[i].0;
            let from_tail = tails(&self.starts, i);
            self.hand = if from_tail { -self.starts[i].3 } else { self.starts[i].3 };
            // An air start's first pass leads in along the material's edge;
            // a start listed again after a pass heads into its frontier.
            let inward = if self.starts[i].2 == 0 { self.air_inward(p) } else { None };
            let heading = match inward {
                Some(inward) => self.air_heading(p, inward),
                None => self.start_heading(p),
            };
            if let Some(h) = heading {
                return Some((i, h));
            }
            self.starts[i].1 = false;
            if from_tail {
                if i > 0 && tail(&self.starts, i - 1) {
                    heap.push(key(&self.starts, i - 1));
                }
            } else if i + 1 < n && head(&self.starts, i + 1) {
                heap.push(key(&self.starts, i + 1));
            }
        }
        None
    }

    /// The largest engagement (rad) along the polyline `run` (the tool at
    /// its first point), measured at every point on the field as the run
    /// leaves it, the run stamped (old values to `undo`).
    fn sweep_run(&mut self, run: &[P2], undo: &mut Vec<(usize, f64)>) -> f64 {
        let mut phi = 0.0f64;
        let step = 0.5 * self.grid.h;
        for pair in run.windows(2) {
            let heading = (pair[1][1] - pair[0][1]).atan2(pair[1][0] - pair[0][0]);
            // Every half cell along the move, the move cut up to there.
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small positive count")]
            let n = ((dist(pair[0], pair[1]) / step).ceil() as usize).max(1);
            let mut from = pair[0];
            for i in 1..=n {
                #[allow(clippy::cast_precision_loss, reason = "a small count")]
                let f = i as f64 / n as f64;
                let q = [pair[0][0] + f * (pair[1][0] - pair[0][0]), pair[0][1] + f * (pair[1][1] - pair[0][1])];
                phi = phi.max(self.front(q, heading).0);
                self.stamp_swept(from, q, Some(undo));
                from = q;
            }
        }
        phi
    }

    fn revert(&mut self, undo: &mut Vec<(usize, f64)>) {
        while let Some((k, v)) = undo.pop() {
            self.restore_swept(k, v);
        }
    }

    /// Clears what the passes left in a convex corner of the region before
    /// its rings are cut: arcs tangent to both walls, from the largest that
    /// fits down to [`tol::RING_FILLET`], each the smallest whose engagement
    /// stays within the accepted bound (bisection on the radius), in the
    /// cutting direction, joined by links (docs/roughing.md, "Corners").
    fn clear_corner(&mut self, corner: &Corner, pos: &mut P2, steps: &mut Vec<Step>) {
        let mut rho = corner.largest.min(tol::CORNER_START_SHARE * self.options.tool_radius);
        let smallest = tol::RING_FILLET;
        let mut undo = Vec::new();
        for _ in 0..tol::CORNER_ARCS {
            if rho <= smallest * (1.0 + 1e-9) {
                break;
            }
            let mut fits = |me: &mut Self, r: f64| {
                let run = me.corner_arc(corner, r);
                let ok = me.sweep_run(&run, &mut undo) <= me.accept;
                me.revert(&mut undo);
                ok
            };
            if !fits(self, rho) {
                return;
            }
            let next = if fits(self, smallest) {
                smallest
            } else {
                let (mut bad, mut good) = (smallest, rho);
                for _ in 0..tol::WALK_BISECTIONS {
                    let mid = 0.5 * (bad + good);
                    if fits(self, mid) {
                        good = mid;
                    } else {
                        bad = mid;
                    }
                }
                good
            };
            if next >= rho * (1.0 - tol::CORNER_MIN_SHRINK) {
                return;
            }
            rho = next;
            let run = self.corner_arc(corner, rho);
            let Some(&start) = run.first() else { return };
            // Rest roughing: an arc that meets no material is not cut
            // (docs/roughing.md, "Adaptive rest roughing: only the stretches
            // that meet material").
            if self.touch.is_some() && !run.iter().any(|&p| self.meets(p)) {
                continue;
            }
            let link = self.link_step(*pos, start);
            steps.push(link);
            *pos = *run.last().unwrap_or(&start);
            self.emit_runs(steps, vec![run]);
        }
    }

    /// The arc of radius `r` tangent to both walls of `corner`, as the
    /// points of its chords in the cutting direction.
    fn corner_arc(&self, c: &Corner, r: f64) -> Vec<P2> {
        let t = r * (0.5 * c.turn).tan();
        let p1 = [c.at[0] - t * c.u[0], c.at[1] - t * c.u[1]];
        let centre = [p1[0] - r * c.u[1], p1[1] + r * c.u[0]];
        let a0 = (p1[1] - centre[1]).atan2(p1[0] - centre[0]);
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small positive count")]
        // Chords within `fit` of the arc (inside it: towards its centre,
        // away from the corner's material).
        let sweep = 2.0 * (1.0 - (self.fit / r).min(1.0)).acos();
        let n = ((c.turn / sweep.max(1e-3)).ceil() as usize).max(1);
        let mut run: Vec<P2> = (0..=n)
            .map(|i| {
                #[allow(clippy::cast_precision_loss, reason = "a small count")]
                let a = a0 + c.turn * i as f64 / n as f64;
                [centre[0] + r * a.cos(), centre[1] + r * a.sin()]
            })
            .collect();
        if self.options.direction == Direction::Conventional {
            run.reverse();
        }
        run
    }

    /// Whether the tool centred at `p` meets material: a probe all round,
    /// [`tol::AIR_RING_CHIP`] inside its periphery, in the material to
    /// remove or in the material touched beyond it (rest roughing: the
    /// cells along the walls; the offset pattern's test of a ring against
    /// the air, docs/roughing.md, "Air"), not swept.
    fn meets(&self, p: P2) -> bool {
        let r = self.options.tool_radius;
        let d = r - tol::AIR_RING_CHIP;
        let nx = self.grid.nx;
        let touched = |q: P2| {
            self.touch.as_ref().is_some_and(|(f, near)| {
                self.grid.locate(q).is_some_and(|at| {
                    Grid::interpolate(&self.swept, nx, at) > r
                        && Grid::interpolate(near, nx, at) < r
                        && Grid::interpolate(f, nx, at) <= 0.0
                })
            })
        };
        self.link_round.iter().any(|&[c, s]| {
            let q = [p[0] + d * c, p[1] + d * s];
            self.material(q) || touched(q)
        })
    }

    /// The closed ring `c` (oriented for the milling direction) as points
    /// on it at most half a cell apart: its chords within
    /// [`tol::WALK_CHORD`], cut up.
    fn ring_samples(&self, c: &Contour) -> (Vec<P2>, Vec<bool>) {
        let step = 0.5 * self.grid.h;
        let vertices = c.to_points(tol::WALK_CHORD);
        let n = vertices.len();
        let mut out = Vec::with_capacity(n);
        let mut corner = Vec::with_capacity(n);
        for (i, &p) in vertices.iter().enumerate() {
            let q = vertices[(i + 1) % n];
            #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a ring's samples")]
            let k = (dist(p, q) / step).ceil().max(1.0) as usize;
            for j in 0..k {
                #[allow(clippy::cast_precision_loss, reason = "small counts")]
                let f = j as f64 / k as f64;
                out.push([p[0] + f * (q[0] - p[0]), p[1] + f * (q[1] - p[1])]);
                corner.push(j == 0);
            }
        }
        (out, corner)
    }

    /// The points of `run` (samples of a ring, [`Planner::ring_samples`])
    /// that are its chords' ends, `corner` telling which, and its first and
    /// last: the ring's own lines (a line between two samples of a wall
    /// that is not one of its chords may cross the wall).
    fn chords_of(run: &[P2], corner: &[bool]) -> Vec<P2> {
        let n = run.len();
        (0..n).filter(|&k| k == 0 || k + 1 == n || corner[k]).map(|k| run[k]).collect()
    }

    /// The region's rings from `pos`, nearest first, with their links.
    /// A ring (or a corner) where the tool never comes within R of the
    /// material is left out ([`plan_adaptive_in`]).
    fn finish(&mut self, region: &Region, mut pos: P2) -> Vec<Step> {
        // The region's convex corners between two lines, up to a right
        // angle and a little more, rounded by [`tol::RING_FILLET`]: a tool
        // centre reaching a sharp corner meets the quarter of its periphery
        // facing the corner in material however close the passes came
        // (docs/roughing.md, "Corners"); rounded, the corner keeps a sliver
        // at most 0.42 x the radius thick. Sharper corners (a gear's tooth
        // gap) keep their tip: rounded, they would leave their bottom uncut.
        let rounded: Vec<Contour> = region.rings().iter().map(fillet_corners).collect();
        let r = self.options.tool_radius;
        let away = |p: P2| self.open.as_ref().is_some_and(|out| self.grid.sample(out, p) >= r);
        let in_air = |c: &Contour| self.open.is_some() && c.to_points(0.25 * self.grid.h).iter().all(|&p| away(p));
        let mut rings: Vec<Contour> =
            rounded.iter().filter(|c| !in_air(c)).map(|c| orient(c, self.options.direction)).collect();
        let mut steps = Vec::new();
        let corners: Vec<Corner> = region.rings().iter().flat_map(corners).filter(|c| !away(c.at)).collect();
        for corner in &corners {
            self.clear_corner(corner, &mut pos, &mut steps);
        }
        let rest = self.touch.is_some();
        let climb = matches!(self.options.direction.rings(), Direction::Climb);
        let mut looper =
            crate::offset::loops::Looper::after(region, r, climb, self.target, self.options.chord_tolerance);
        while !rings.is_empty() {
            let started: Vec<Contour> = rings.iter().map(|c| c.starting_near(pos)).collect();
            let d = |c: &Contour| c.start().map_or(f64::INFINITY, |p| dist(p, pos));
            let i = (0..started.len()).min_by(|&x, &y| d(&started[x]).total_cmp(&d(&started[y]))).unwrap_or(0);
            let ring = started[i].clone();
            rings.remove(i);
            // Rest roughing: only the stretches of the ring along which the
            // tool still meets material (the rest is air, or what the walk
            // cleared), as the offset pattern's rings (docs/roughing.md,
            // "Adaptive rest roughing: only the stretches that meet
            // material").
            let pieces = if rest { self.stretches(&ring) } else { vec![ring] };
            for piece in pieces {
                // Where the ring meets material the walk did not reach on its
                // inner side too (a channel narrower than a pass could turn in,
                // a tooth gap), it would slot: loops there, as the offset
                // pattern's (docs/roughing.md, "Slots: loops").
                let piece = {
                    let chip = tol::AIR_RING_CHIP;
                    let cleared = |y: P2| {
                        self.grid.sample(&self.swept, y) <= r - chip
                            || self.grid.locate(y).is_some_and(|at| self.open_at(at))
                    };
                    looper.looped_after(&piece, &cleared)
                };
                let Some(start) = piece.start() else { continue };
                let link = self.link_step(pos, start);
                steps.push(link);
                let mut pts = piece.to_points(0.25 * self.grid.h);
                if piece.is_closed() {
                    pts.push(start);
                }
                self.stamp(&pts);
                pos = piece.end().unwrap_or(start);
                steps.push(Step::Cut(piece));
            }
        }
        steps
    }

    /// The stretches of the closed `ring` along which the tool meets
    /// material ([`Planner::meets`]): the whole ring when it does all along
    /// or but for gaps shorter than [`tol::AIR_RUN_GAP_SHARE`] R, none when
    /// nowhere, else open stretches, each one sample into the air at both
    /// ends, as the ring's own lines, then lines and arcs where they stay in
    /// the region ([`fit_in`]).
    fn stretches(&self, ring: &Contour) -> Vec<Contour> {
        let (samples, corner) = self.ring_samples(ring);
        let n = samples.len();
        let hit: Vec<bool> = samples.iter().map(|&p| self.meets(p)).collect();
        let gap = tol::AIR_RUN_GAP_SHARE * self.options.tool_radius;
        let (first_air, joined) = match crate::offset::ring_runs(&samples, &hit, gap) {
            crate::offset::RingRuns::Whole => return vec![ring.clone()],
            crate::offset::RingRuns::Nowhere => return Vec::new(),
            crate::offset::RingRuns::Runs { first_air, runs } => (first_air, runs),
        };
        let at = |i: usize| samples[(first_air + i) % n];
        let arc_fit = 0.5 * tol::WALK_FIT_SHARE * self.options.tool_radius;
        joined
            .into_iter()
            .filter_map(|(a, b)| {
                let range = a.saturating_sub(1)..=b + 1;
                let points: Vec<P2> = range.clone().map(at).collect();
                let flags: Vec<bool> = range.map(|i| corner[(first_air + i) % n]).collect();
                let c = lines(&Self::chords_of(&points, &flags))?;
                Some(fit_in(&self.edges, &c, arc_fit).unwrap_or(c))
            })
            .collect()
    }
}
/// Each cell centre's signed distance to the boundary of `material`
/// (negative in it), exact up to `cap` from its rings (chords within
/// `tolerance`), -[`BIG`] or [`BIG`] beyond.
fn signed_distance(grid: &Grid, material: &Region, cap: f64, tolerance: f64) -> Vec<f64> {
    // Only the rings whose boxes come within `cap` of the grid's: a closed
    // ring wholly beside the grid crosses each row of cells an even number
    // of times on one side of them (no winding there) and stamps no distance
    // under `cap` (a level's material holds the rings of the whole level).
    #[allow(clippy::cast_precision_loss, reason = "cell counts")]
    let (lo, hi) = (
        [grid.x0 - cap, grid.y0 - cap],
        [grid.x0 + grid.nx as f64 * grid.h + cap, grid.y0 + grid.ny as f64 * grid.h + cap],
    );
    let near = |pts: &Vec<P2>| {
        let (mut a, mut b) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in pts {
            a = [a[0].min(p[0]), a[1].min(p[1])];
            b = [b[0].max(p[0]), b[1].max(p[1])];
        }
        a[0] <= hi[0] && b[0] >= lo[0] && a[1] <= hi[1] && b[1] >= lo[1]
    };
    let rings: Vec<Vec<P2>> = material.rings().iter().map(|c| c.to_points(tolerance)).filter(near).collect();
    let inside = grid.fill_rings(&rings);
    let mut d = vec![BIG; grid.len()];
    for pts in &rings {
        for (k, a) in pts.iter().enumerate() {
            grid.stamp_segment(&mut d, *a, pts[(k + 1) % pts.len()], cap, None);
        }
    }
    for (v, &i) in d.iter_mut().zip(&inside) {
        if i {
            *v = -*v;
        }
    }
    d
}

/// The distance from `p` to the segment `a`-`b`.
fn segment_distance(p: P2, a: P2, b: P2) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 { (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0) } else { 0.0 };
    dist(p, [a[0] + t * dx, a[1] + t * dy])
}

/// The points as lines.
fn lines(points: &[P2]) -> Option<Contour> {
    Contour::polygon(points, false).ok()
}

/// The fewest of the points of `run` (its ends kept) whose lines stay
/// within `tolerance` of it and in the region (Douglas and Peucker
/// 1973, "Algorithms for the reduction of the number of points required
/// to represent a digitized line", Cartographica 10(2); a line that
/// leaves the region is split like one too far from the points).
fn simplify(edges: &Edges, run: &[P2], tolerance: f64) -> Vec<usize> {
    let n = run.len();
    if n <= 2 {
        return (0..n).collect();
    }
    let mut keep = vec![false; n];
    (keep[0], keep[n - 1]) = (true, true);
    let mut stack = vec![(0, n - 1)];
    while let Some((i, j)) = stack.pop() {
        if j <= i + 1 {
            continue;
        }
        let (mut worst, mut at) = (-1.0, (i + j) / 2);
        for k in i + 1..j {
            let d = segment_distance(run[k], run[i], run[j]);
            if d > worst {
                (worst, at) = (d, k);
            }
        }
        if worst > tolerance || !edges.contains_segment(run[i], run[j]) {
            keep[at] = true;
            stack.push((i, at));
            stack.push((at, j));
        }
    }
    (0..n).filter(|&k| keep[k]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lattice_turns_are_the_bisections_midpoints_bit_for_bit() {
        // Bisections between the walk's bounds and others, every sequence
        // of answers of 8 halvings of a few: each midpoint tried is the
        // lattice turn of its index, and so are the ends.
        let n = 1usize << tol::WALK_BISECTIONS;
        for (lo0, hi0) in [(-tol::WALK_TURN, tol::WALK_TURN_HARD), (-0.3, 0.7), (0.1, 3.0), (-2.0, -1.9)] {
            assert_eq!(bisection_turn(lo0, hi0, 0, n).to_bits(), lo0.to_bits());
            assert_eq!(bisection_turn(lo0, hi0, n, n).to_bits(), hi0.to_bits());
            for answers in 0..n {
                let (mut lo, mut hi, mut klo, mut khi) = (lo0, hi0, 0usize, n);
                for bit in 0..tol::WALK_BISECTIONS {
                    let (mid, kmid) = (0.5 * (lo + hi), (klo + khi) / 2);
                    assert_eq!(bisection_turn(lo0, hi0, kmid, n).to_bits(), mid.to_bits(), "{lo0} {hi0} {kmid}");
                    if answers >> bit & 1 == 1 {
                        (hi, khi) = (mid, kmid);
                    } else {
                        (lo, klo) = (mid, kmid);
                    }
                }
            }
        }
    }

    #[test]
    fn most_within_is_the_last_count_whose_share_keeps_within() {
        // Against the linear scan, at the walk's probe counts, at limits on
        // and around every share, and at the ends.
        for n in [1usize, 2, 7, 90, 180] {
            #[allow(clippy::cast_precision_loss, reason = "small counts")]
            let share = |k: usize| std::f64::consts::PI * k as f64 / n as f64;
            let mut limits = vec![-1.0, 0.0, f64::INFINITY, f64::NAN, 10.0, tol::ENGAGE_ACCEPT * 0.927];
            for k in 0..=n {
                let v = share(k);
                limits.extend([v, v.next_up(), v.next_down(), v + 1e-3, v - 1e-3]);
            }
            for limit in limits {
                let want = (0..=n).filter(|&k| share(k) <= limit || limit.is_nan()).max().unwrap_or(0);
                assert_eq!(most_within(n, limit), want, "n {n}, limit {limit}");
            }
        }
    }

    #[test]
    fn right_angled_corners_get_fillets_and_sharp_ones_keep_their_tips() {
        let square = Contour::polygon(&[[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]], true).unwrap();
        let f = fillet_corners(&square);
        assert_eq!(f.vertices().len(), 8);
        let rho = tol::RING_FILLET;
        let want = 16.0 - (4.0 - std::f64::consts::PI) * rho * rho;
        assert!((f.signed_area() - want).abs() < 1e-9, "{} vs {want}", f.signed_area());
        // A spike of 20 degrees keeps its tip.
        let spike = Contour::polygon(&[[0.0, 0.0], [10.0, 1.76], [0.0, 3.53]], true).unwrap();
        let g = fillet_corners(&spike);
        assert!(g.vertices().iter().any(|v| (v.x - 10.0).abs() < 1e-12 && (v.y - 1.76).abs() < 1e-12));
    }

    #[test]
    fn a_walk_becomes_few_lines_near_it_and_inside_the_region() {
        // A square with a round hole; walks of steps of 0.375 that turn a
        // little at each, some sliding round the hole (the region's wall
        // bends into them there: the chords of the hole leave the region).
        let outer = vec![[0.0, 0.0], [40.0, 0.0], [40.0, 40.0], [0.0, 40.0]];
        let hole: Vec<P2> = (0..64)
            .map(|k| {
                let a = -std::f64::consts::TAU * f64::from(k) / 64.0;
                [20.0 + 5.0 * a.cos(), 20.0 + 5.0 * a.sin()]
            })
            .collect();
        let region = Region::from_polygons(&[outer, hole], false);
        let edges = Edges::new(&region, 1e-4, 1.0);
        let tolerance = 0.02;
        for case in 0..24u32 {
            let f = f64::from(case);
            let (mut p, mut heading) = ([2.0 + 0.5 * f, 2.0 + 0.3 * f], 0.1 * f);
            let mut run = vec![p];
            for k in 0..300u32 {
                let turn = 0.02 * (0.05 * f64::from(k) + f).sin();
                let next = [p[0] + 0.375 * (heading + turn).cos(), p[1] + 0.375 * (heading + turn).sin()];
                if !edges.contains_segment(p, next) {
                    // Round the hole (or turn back at the square's wall).
                    heading += 0.3;
                    continue;
                }
                heading += turn;
                p = next;
                run.push(p);
            }
            if case == 0 {
                // Sliding round the hole, 0.01 mm off its wall: chords of the hole's
                // circle within the tolerance would cut into it.
                let r = 5.0 + 1e-2;
                run = (0..=40)
                    .map(|k| {
                        let a = 0.075 * f64::from(k);
                        [20.0 + r * a.cos(), 20.0 + r * a.sin()]
                    })
                    .collect();
            }
            let lines: Vec<P2> = simplify(&edges, &run, tolerance).into_iter().map(|k| run[k]).collect();
            assert_eq!((lines.first(), lines.last()), (run.first(), run.last()));
            assert!(
                case == 0 || lines.len() * 3 < run.len(),
                "case {case}: {} lines of {} points",
                lines.len(),
                run.len()
            );
            for q in &run {
                let d = lines.windows(2).map(|w| segment_distance(*q, w[0], w[1])).fold(f64::INFINITY, f64::min);
                assert!(d <= tolerance + 1e-12, "case {case}: a step {d} mm from the lines");
            }
            for w in lines.windows(2) {
                assert!(edges.contains_segment(w[0], w[1]), "case {case}: a line leaves the region");
            }
        }
    }
}
