//! 3-axis roughing (docs/roughing.md): z-level tool-centre regions of a part
//! in a stock box, cleared level by level with contour-parallel offset
//! passes, joined depth-first so the tool stays low.
//!
//! A level's tool-centre region is the stock's XY box grown by the tool
//! radius (the tool may leave the stock on open sides) minus the inside of
//! the part's waterline loops at the level, computed with the cutter grown
//! radially by the radial allowance and at the level lowered by the axial
//! allowance (`scallop-waterline`). Levels fall every stepdown from the stock
//! top to the part's bottom, plus one on each horizontal facet of the part
//! (floors are cut at their height, not left as terraces). Regions shrink
//! going down, so each connected part of a level lies in one part of the
//! level above: the parts form a tree, cut depth-first.

use rayon::prelude::*;
use scallop_contour::{Contour, P2, Region, Segment};
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::{Aabb3, Point2, Point3};
use scallop_mesh::MeshIndex;
use scallop_toolpath::{ArcXY, Move, MoveKind, Toolpath};
use scallop_waterline::{WaterlineGrid, WaterlineOptions};

mod adaptive;
mod grid;
mod material;
mod offset;
pub use scallop_geom::tol::rough as tol;
mod walls;

pub use adaptive::{plan_adaptive, plan_adaptive_in, plan_adaptive_rest, plan_adaptive_touching};
pub use material::{MaterialMap, limit_to_material, material_met, removable_material};
pub use offset::{Step, plan_offset, plan_offset_in};

/// Why a roughing plan could not be made; each variant names the setting and the fix.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RoughError {
    /// A setting out of range.
    #[error("roughing.{key} = {value}: {fix}")]
    BadSetting {
        /// The job key.
        key: &'static str,
        /// Its value.
        value: f64,
        /// What to give instead.
        fix: &'static str,
    },
    /// The cutter cannot be grown by the radial allowance (cone cutters).
    #[error("roughing with a {0} cutter is not supported; use a flat, ball or bull-nose cutter")]
    Cutter(&'static str),
    /// The waterline kernel refused.
    #[error("waterline of the part: {0}")]
    Waterline(#[from] scallop_waterline::WaterlineError),
    /// The offset kernel lost part of a region at every attempt.
    #[error("the offset of a roughing region by {distance} mm failed; give a slightly different stepover")]
    Offset {
        /// The offset distance from the region's contour (mm).
        distance: f64,
    },
    /// More work than the planner's bounds allow.
    #[error("more than {limit} {what}; give a larger stepover or stepdown")]
    TooMuchWork {
        /// What grew too large.
        what: &'static str,
        /// The bound.
        limit: usize,
    },
}

/// Milling direction, for a spindle turning clockwise (M3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Direction {
    /// Climb (down) milling: the uncut material on the tool's right.
    #[default]
    Climb,
    /// Conventional (up) milling.
    Conventional,
    /// Both ways (adaptive pattern): a pass that ends where the next one
    /// can start back along the frontier it left is followed by one the
    /// other way, climb and conventional in turn, where climb only would
    /// link back to the frontier's upstream end (docs/roughing.md,
    /// "Adaptive clearing", both ways). The offset patterns, the region's
    /// rings and corners climb.
    Both,
}

impl Direction {
    /// The direction of closed rings and of the offset patterns: climb but
    /// for [`Direction::Conventional`].
    #[must_use]
    pub fn rings(self) -> Self {
        match self {
            Self::Conventional => Self::Conventional,
            Self::Climb | Self::Both => Self::Climb,
        }
    }
}

/// How a region is cleared.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Pattern {
    /// Contour-parallel offsets at the stepover, inside-out, then the region's contour.
    #[default]
    Offset,
    /// As `Offset`, with loops (trochoidal milling) where a ring would cut a
    /// slot: no pass has material on both sides (docs/roughing.md, "Offset
    /// clearing", "Slots").
    OffsetLoops,
    /// A front grown from the deepest point with the engagement held at the
    /// stepover's angle, then the region's contour (docs/roughing.md).
    Adaptive,
}

/// The clearing of one connected tool-centre region by `options.pattern`.
///
/// # Errors
/// [`RoughError::TooMuchWork`] beyond the planners' bounds.
pub fn plan_region(region: &Region, options: &ClearOptions) -> Result<Vec<Step>, RoughError> {
    plan_region_in(region, None, None, options)
}

/// As [`plan_region`], the material of the level being `material` (the
/// adaptive pattern's [`plan_adaptive_in`]: no engagement counted, passes
/// started and rings left out where the tool cuts air; the offset pattern's
/// [`plan_offset_in`]: rings left out where the tool cuts air, and links
/// through that air inside `room`, where the tool centre may go at the
/// level beyond `region`).
///
/// # Errors
/// As [`plan_region`].
pub fn plan_region_in(
    region: &Region,
    material: Option<&Region>,
    room: Option<&Region>,
    options: &ClearOptions,
) -> Result<Vec<Step>, RoughError> {
    match options.pattern {
        Pattern::Offset | Pattern::OffsetLoops => plan_offset_in(region, material, room, options),
        Pattern::Adaptive => plan_adaptive_in(region, material, options),
    }
}

/// Settings of the clearing of one region in the plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClearOptions {
    /// Tool radius R (mm): sizes the helical entries.
    pub tool_radius: f64,
    /// Radial depth of cut ae between passes (mm), `0 < ae <= R`.
    pub stepover: f64,
    /// Milling direction.
    pub direction: Direction,
    /// Chords stand for arcs within this in link checks (mm).
    pub chord_tolerance: f64,
    /// Clearing pattern.
    pub pattern: Pattern,
}

/// The settings of a roughing operation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoughSettings {
    /// Depth between levels (mm), > 0.
    pub stepdown: f64,
    /// Radial depth of cut as a fraction of the tool diameter, in (0, 0.5].
    pub stepover: f64,
    /// Material left on the part's walls (mm, >= 0).
    pub radial_allowance: f64,
    /// Material left on the part's floors (mm, >= 0).
    pub axial_allowance: f64,
    /// Clearing pattern.
    pub pattern: Pattern,
    /// Milling direction.
    pub direction: Direction,
}

impl RoughSettings {
    /// Checks the ranges.
    ///
    /// # Errors
    /// [`RoughError::BadSetting`] naming the key.
    pub fn validate(&self) -> Result<(), RoughError> {
        let bad = |key, value, fix| Err(RoughError::BadSetting { key, value, fix });
        if !(self.stepdown.is_finite() && self.stepdown > 0.0) {
            return bad("stepdown", self.stepdown, "give a depth per level > 0 mm");
        }
        if !(self.stepover.is_finite() && self.stepover > 0.0 && self.stepover <= 0.5) {
            return bad("stepover", self.stepover, "give a fraction of the tool diameter in (0, 0.5]");
        }
        if !(self.radial_allowance.is_finite() && self.radial_allowance >= 0.0) {
            return bad("stock_to_leave", self.radial_allowance, "give an allowance >= 0 mm");
        }
        if !(self.axial_allowance.is_finite() && self.axial_allowance >= 0.0) {
            return bad("stock_to_leave_axial", self.axial_allowance, "give an allowance >= 0 mm");
        }
        Ok(())
    }
}

/// Heights and feeds of the moves between passes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// Height of rapids (mm, part frame), above all material.
    pub clearance_z: f64,
    /// Cutting feed (mm/min).
    pub feed: f64,
}

/// One level of a plan.
#[derive(Debug, Clone)]
pub struct Level {
    /// Tool tip height (mm).
    pub z: f64,
    /// The tool-centre region.
    pub region: Region,
}

/// A roughing plan.
#[derive(Debug, Clone)]
pub struct RoughPlan {
    /// The toolpath (tool tip, part frame), XY arcs attached as `ArcXY`.
    pub toolpath: Toolpath,
    /// The levels, top down.
    pub levels: Vec<Level>,
    /// Closed passes cut.
    pub passes: usize,
    /// Links at the cutting depth.
    pub links: usize,
    /// Retract-rapid-plunge connections.
    pub retracts: usize,
    /// Helical entries (the other entries are straight plunges).
    pub helices: usize,
}

/// The lowest level's tool-tip height: the part's bottom plus the axial
/// allowance (and [`tol::FLAT_LIFT`]), not below the stock's bottom. Off the
/// part's outline the roughing takes the stock down to this height.
#[must_use]
pub fn level_bottom(part: &Aabb3, stock: &Aabb3, settings: &RoughSettings) -> f64 {
    (part.min.z + settings.axial_allowance + tol::FLAT_LIFT).max(stock.min.z)
}

/// The tool-tip heights of the levels, top down: every `stepdown` below the
/// stock top down to the part's bottom plus the axial allowance, and each
/// horizontal facet's height plus the axial allowance.
#[must_use]
pub fn level_heights(index: &MeshIndex, stock: &Aabb3, settings: &RoughSettings) -> Vec<f64> {
    let top = stock.max.z;
    let bottom = level_bottom(&index.bounds(), stock, settings);
    let mut zs = Vec::new();
    let mut k = 1.0;
    while top - k * settings.stepdown > bottom + tol::LEVEL_MERGE && zs.len() < tol::MAX_LEVELS {
        zs.push(top - k * settings.stepdown);
        k += 1.0;
    }
    if bottom < top {
        zs.push(bottom);
    }
    let mut flats: Vec<f64> = (0..index.len())
        .filter(|&s| index.normal(s).z.abs() > tol::FLAT_NORMAL_Z)
        .map(|s| index.corners(s).iter().map(|c| c.z).sum::<f64>() / 3.0)
        .collect();
    flats.sort_by(f64::total_cmp);
    flats.dedup_by(|a, b| (*a - *b).abs() <= tol::FLAT_MERGE);
    for f in flats {
        let z = f + settings.axial_allowance + tol::FLAT_LIFT;
        if z > bottom && z < top {
            zs.push(z);
        }
    }
    zs.sort_by(|a, b| b.total_cmp(a));
    zs.dedup_by(|a, b| (*a - *b).abs() <= tol::LEVEL_MERGE);
    zs
}

/// The cutter grown radially by `allowance` (the envelope the part must keep
/// clear of to hold the allowance on its walls).
///
/// # Errors
/// [`RoughError::Cutter`] for a cone; the cutter's own errors as a bad setting.
pub fn grown_cutter(cutter: &Cutter, allowance: f64) -> Result<Cutter, RoughError> {
    let shape = match *cutter.shape() {
        CutterShape::Flat { radius } => CutterShape::Flat { radius: radius + allowance },
        CutterShape::Ball { radius } if allowance > 0.0 => {
            CutterShape::Bull { radius: radius + allowance, corner: radius }
        }
        CutterShape::Ball { radius } => CutterShape::Ball { radius },
        CutterShape::Bull { radius, corner } => CutterShape::Bull { radius: radius + allowance, corner },
        _ => return Err(RoughError::Cutter("cone")),
    };
    Cutter::new(shape, cutter.flute_length()).map_err(|_| RoughError::BadSetting {
        key: "stock_to_leave",
        value: allowance,
        fix: "give an allowance that keeps the tool a valid cutter",
    })
}

/// The tool-centre regions of the levels `zs` (see the crate documentation).
///
/// # Errors
/// [`RoughError::Waterline`], [`RoughError::Cutter`].
pub fn level_regions(
    index: &MeshIndex,
    cutter: &Cutter,
    stock: &Aabb3,
    settings: &RoughSettings,
    zs: &[f64],
    tolerance: f64,
) -> Result<Vec<Level>, RoughError> {
    let grown = grown_cutter(cutter, settings.radial_allowance)?;
    let grid = WaterlineGrid::new(&grown, index, &WaterlineOptions::default())?;
    let (zmin, zmax) = grid.z_range();
    let r = cutter.radius();
    let (lo, hi) = ([stock.min.x - r, stock.min.y - r], [stock.max.x + r, stock.max.y + r]);
    let rect = Region::from_polygons(&[vec![lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]]], false);
    zs.par_iter()
        .map(|&z| {
            let contact = z - settings.axial_allowance;
            if contact >= zmax {
                return Ok(Level { z, region: rect.clone() });
            }
            let loops = grid.loops(contact.max(zmin))?;
            let rings: Vec<Vec<P2>> = loops.iter().map(|l| l.points.iter().map(|p| [p.x, p.y]).collect()).collect();
            let inside = Region::from_polygons_simplified(&rings, true, tol::SIMPLIFY);
            Ok(Level { z, region: rect.difference(&inside, tolerance) })
        })
        .collect()
}

/// One connected part of one level, with its clearing plan.
struct Node {
    z: f64,
    /// The top of the material above the node before it is cut: its
    /// parent's level, else the stock's top (or the material's, see
    /// [`plan_rough_from`]).
    top: f64,
    region: Region,
    parent: Option<usize>,
    steps: Vec<Step>,
}

/// Plans the roughing of the part in `index` from the stock box `stock`
/// (see the crate documentation). `tolerance` is the chord tolerance of the
/// region booleans and link checks (mm).
///
/// # Errors
/// [`RoughError`]: bad settings, the waterline kernel's errors, too much work.
pub fn plan_rough(
    index: &MeshIndex,
    cutter: &Cutter,
    stock: &Aabb3,
    settings: &RoughSettings,
    motion: &Motion,
    tolerance: f64,
) -> Result<RoughPlan, RoughError> {
    plan_rough_from(index, cutter, stock, None, settings, motion, tolerance)
}

/// As [`plan_rough`], from the in-process stock `material` when given (the
/// stock the earlier operations left, inside the box `stock`): each level's
/// region is cut down to the centres that reach material to remove
/// ([`limit_to_material`]), so a smaller tool after a larger one machines
/// only what the larger one left (rest roughing), and entries start from
/// the material's top rather than the box's.
///
/// # Errors
/// As [`plan_rough`].
pub fn plan_rough_from(
    index: &MeshIndex,
    cutter: &Cutter,
    stock: &Aabb3,
    material: Option<&MaterialMap>,
    settings: &RoughSettings,
    motion: &Motion,
    tolerance: f64,
) -> Result<RoughPlan, RoughError> {
    settings.validate()?;
    let zs = level_heights(index, stock, settings);
    let levels = level_regions(index, cutter, stock, settings, &zs, tolerance)?;
    plan_levels(levels, cutter, stock, material, settings, motion, tolerance)
}

/// The second half of [`plan_rough_from`]: clears the given `levels` (top
/// down, each a tool-tip height and its tool-centre region), from the
/// in-process stock `material` when given. A caller that restricts the
/// regions of [`level_regions`] further (5-axis roughing's 3-axis baselines
/// in a tilted setup, `scallop-rough5`) plans them here.
///
/// # Errors
/// As [`plan_rough`].
pub fn plan_levels(
    levels: Vec<Level>,
    cutter: &Cutter,
    stock: &Aabb3,
    material: Option<&MaterialMap>,
    settings: &RoughSettings,
    motion: &Motion,
    tolerance: f64,
) -> Result<RoughPlan, RoughError> {
    settings.validate()?;
    // Where each level holds material: the stock's section, and with an
    // in-process stock the material the tool would remove at the level
    // (its region then cut down to the centres that reach it). The level's
    // whole region stays the room for links through air. The adaptive
    // pattern is also told the material the tool meets there beyond that
    // (within R of the level's whole region: the cells along the walls that
    // `removable_material` leaves out), which it counts in the engagement.
    let (lo, hi) = ([stock.min.x, stock.min.y], [stock.max.x, stock.max.y]);
    let section = Region::from_polygons(&[vec![lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]]], false);
    let r = cutter.radius();
    let spaces: Vec<(Level, Region, Option<Region>, Option<Region>)> = match material {
        Some(m) => levels
            .into_par_iter()
            .map(|l| {
                let adaptive = settings.pattern == Pattern::Adaptive;
                let (removable, met) = material_met(&l.region, m, l.z, r, tolerance, adaptive);
                let region = if removable.is_empty() {
                    Region::empty()
                } else {
                    l.region.intersection(&removable.offset(-r), tolerance)
                };
                let touched = (adaptive && !region.is_empty()).then(|| met.intersection(&section, tolerance));
                (Level { region, z: l.z }, removable.intersection(&section, tolerance), Some(l.region), touched)
            })
            .filter(|(l, _, _, _)| !l.region.is_empty())
            .collect(),
        None => {
            // Beyond the stock's section grown by R the tool meets neither
            // stock nor part: room for links and the open sides.
            let rect = section.offset(-r);
            let outer = section.offset(-3.0 * r);
            levels
                .into_par_iter()
                .map(|l| {
                    let room = outer.difference(&rect.difference(&l.region, tolerance), tolerance);
                    (l, section.clone(), Some(room), None)
                })
                .collect()
        }
    };
    let mut levels = Vec::with_capacity(spaces.len());
    let mut materials = Vec::with_capacity(spaces.len());
    let mut rooms = Vec::with_capacity(spaces.len());
    let mut touched = Vec::with_capacity(spaces.len());
    for (l, m, room, t) in spaces {
        levels.push(l);
        materials.push(m);
        rooms.push(room);
        touched.push(t);
    }
    let options = ClearOptions {
        tool_radius: r,
        stepover: settings.stepover * 2.0 * r,
        direction: settings.direction,
        chord_tolerance: tolerance,
        pattern: settings.pattern,
    };
    let mut nodes = build_tree(&levels, &materials, &rooms, &touched, &options)?;
    if let Some(m) = material {
        // A node with no parent is entered from the material's top over its
        // region grown by the tool radius (not the box's top).
        let r = cutter.radius();
        for n in nodes.iter_mut().filter(|n| n.parent.is_none()) {
            if let Some((lo, hi)) = n.region.bounds() {
                n.top = m
                    .top_in([lo[0] - r, lo[1] - r], [hi[0] + r, hi[1] + r])
                    .map_or(n.z, |t| t.max(n.z))
                    .min(stock.max.z);
            }
        }
    }
    let mut out = Emitter::new(motion, stock.max.z, &options);
    out.material = material;
    let roots: Vec<usize> = (0..nodes.len()).filter(|&k| nodes[k].parent.is_none()).collect();
    visit_all(&nodes, &roots, &mut out);
    out.finish();
    Ok(RoughPlan {
        toolpath: out.path,
        levels,
        passes: out.passes,
        links: out.links,
        retracts: out.retracts,
        helices: out.helices,
    })
}

/// The nodes of all levels with their parents and plans (planned in parallel).
fn build_tree(
    levels: &[Level],
    materials: &[Region],
    rooms: &[Option<Region>],
    touched: &[Option<Region>],
    options: &ClearOptions,
) -> Result<Vec<Node>, RoughError> {
    let mut shells: Vec<(usize, Region)> = Vec::new();
    for (k, level) in levels.iter().enumerate() {
        shells.extend(level.region.components().into_iter().map(|c| (k, c)));
    }
    let first_of_level: Vec<usize> =
        (0..=levels.len()).map(|k| shells.iter().position(|s| s.0 >= k).unwrap_or(shells.len())).collect();
    let planned: Result<Vec<Vec<Step>>, RoughError> = shells
        .par_iter()
        .map(|(k, region)| match (&touched[*k], options.pattern) {
            (Some(t), Pattern::Adaptive) => {
                plan_adaptive_rest(region, Some(&materials[*k]), Some(t), rooms[*k].as_ref(), options)
            }
            _ => plan_region_in(region, Some(&materials[*k]), rooms[*k].as_ref(), options),
        })
        .collect();
    let planned = planned?;
    // Parents are found among the previous level's nodes by containment.
    let mut out: Vec<Node> = Vec::with_capacity(shells.len());
    for ((k, region), steps) in shells.into_iter().zip(planned) {
        let parent = if k == 0 {
            None
        } else {
            (first_of_level[k - 1]..first_of_level[k]).find(|&p| contains_part(&out[p].region, &region))
        };
        let top = parent.map_or(f64::INFINITY, |p| out[p].z);
        out.push(Node { z: levels[k].z, top, region, parent, steps });
    }
    Ok(out)
}

/// Whether `child` lies in `parent`, tested at a point strictly inside the
/// child (its outer ring may run on the parent's boundary: the stock box).
fn contains_part(parent: &Region, child: &Region) -> bool {
    interior_point(child).is_some_and(|p| parent.contains(p))
}

/// A point inside `region`: a chord midpoint of its first outer ring moved a
/// little to the ring's left (the filled side), the first such point inside.
fn interior_point(region: &Region) -> Option<P2> {
    let ring = region.outers().next()?.to_points(tol::INTERIOR_NUDGE / 4.0);
    (0..ring.len()).find_map(|i| {
        let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = dx.hypot(dy);
        let d = tol::INTERIOR_NUDGE / len;
        let p = [0.5 * (a[0] + b[0]) - dy * d, 0.5 * (a[1] + b[1]) + dx * d];
        (len > 4.0 * tol::INTERIOR_NUDGE && region.contains(p)).then_some(p)
    })
}

/// Cuts the trees from `roots` depth-first, each time going on with the
/// nearest uncut node among the children of the last one cut.
fn visit_all(nodes: &[Node], roots: &[usize], out: &mut Emitter) {
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); nodes.len()];
    for (k, n) in nodes.iter().enumerate() {
        if let Some(p) = n.parent {
            children[p].push(k);
        }
    }
    let mut pending: Vec<usize> = roots.to_vec();
    visit_siblings(nodes, &children, &mut pending, out);
}

fn visit_siblings(nodes: &[Node], children: &[Vec<usize>], pending: &mut Vec<usize>, out: &mut Emitter) {
    while !pending.is_empty() {
        let here = out.position();
        let i = (0..pending.len())
            .min_by(|&a, &b| distance_to(&nodes[pending[a]], here).total_cmp(&distance_to(&nodes[pending[b]], here)))
            .unwrap_or(0);
        let k = pending.remove(i);
        out.node(nodes, k);
        let mut next = children[k].clone();
        visit_siblings(nodes, children, &mut next, out);
    }
}

fn distance_to(node: &Node, here: Option<P2>) -> f64 {
    let start = node.steps.iter().find_map(|s| match s {
        Step::Cut(c) => c.start(),
        Step::Link { .. } => None,
    });
    match (start, here) {
        (Some(s), Some(h)) => (s[0] - h[0]).hypot(s[1] - h[1]),
        _ => 0.0,
    }
}

/// Writes nodes as moves.
struct Emitter<'m> {
    path: Toolpath,
    /// The in-process stock the operation starts from, when known: an entry
    /// descends at the feed only through the material over its own disc.
    material: Option<&'m MaterialMap>,
    /// The tool's radius (mm).
    tool_radius: f64,
    clearance: f64,
    stock_top: f64,
    /// Chord tolerance of the link checks (mm).
    chord: f64,
    /// Radius of the tool centre's circle on helical entries (mm).
    helix_radius: f64,
    /// Helical entries made.
    helices: usize,
    /// The node last cut.
    last: Option<usize>,
    passes: usize,
    links: usize,
    retracts: usize,
}

impl Emitter<'_> {
    fn new(motion: &Motion, stock_top: f64, options: &ClearOptions) -> Self {
        Emitter {
            path: Toolpath::new(motion.feed),
            material: None,
            tool_radius: options.tool_radius,
            clearance: motion.clearance_z,
            stock_top,
            chord: options.chord_tolerance,
            helix_radius: tol::HELIX_RADIUS_SHARE * options.tool_radius,
            helices: 0,
            last: None,
            passes: 0,
            links: 0,
            retracts: 0,
        }
    }

    fn position(&self) -> Option<P2> {
        self.path.moves().last().map(|m| [m.to.x, m.to.y])
    }

    fn at(&self) -> Option<Point3> {
        self.path.moves().last().map(|m| m.to)
    }

    /// The moves of node `k`: the way there, then its passes and links.
    fn node(&mut self, nodes: &[Node], k: usize) {
        let node = &nodes[k];
        let mut first = true;
        for step in &node.steps {
            match step {
                Step::Cut(c) => {
                    let Some(s) = c.start() else { continue };
                    if first {
                        self.enter(nodes, k, s, false);
                        first = false;
                    }
                    self.cut(c, node.z);
                }
                Step::Link { tool_down, via, cleared, to } => {
                    let next = to.or_else(|| next_start(&node.steps, step));
                    if let Some(s) = next {
                        if first {
                            // The node's entry: a straight plunge where the
                            // tool cuts nothing there (`cleared`).
                            self.enter(nodes, k, s, *cleared);
                            first = false;
                        } else if *tool_down {
                            for p in via {
                                self.path.push(Move::new(MoveKind::Link, Point3::new(p[0], p[1], node.z)));
                            }
                            self.path.push(Move::new(MoveKind::Link, Point3::new(s[0], s[1], node.z)));
                            self.links += 1;
                        } else {
                            let above = self.cleared_top(nodes, k, s);
                            self.retract_to(s, above, node.z, &node.region, *cleared);
                        }
                    }
                }
            }
        }
        self.last = Some(k);
    }

    /// From the last node to the start `s` of node `k`: up to the deepest
    /// level both lie in, across it when the straight move stays in its
    /// region, else over the clearance height; then down through the cleared
    /// levels above `k` and a plunge.
    fn enter(&mut self, nodes: &[Node], k: usize, s: P2, straight: bool) {
        let node = &nodes[k];
        let above = self.cleared_top(nodes, k, s);
        let (Some(here), Some(last)) = (self.at(), self.last) else {
            self.path.push(Move::new(MoveKind::Rapid, Point3::new(s[0], s[1], self.clearance)));
            self.plunge(s, above, node.z, &node.region, straight);
            return;
        };
        let ancestors = chain(nodes, k);
        let mut common = Some(last);
        while let Some(c) = common {
            if ancestors.contains(&c) {
                break;
            }
            common = nodes[c].parent;
        }
        // The last pass ends on its region's contour: grown a hair, the
        // region holds it.
        let across = common
            .filter(|&c| nodes[c].region.offset(-tol::LINK_GROW).contains_segment([here.x, here.y], s, self.chord));
        match across {
            Some(c) => {
                let zc = nodes[c].z;
                if here.z < zc {
                    self.path.push(Move::new(MoveKind::Rapid, Point3::new(here.x, here.y, zc)));
                }
                self.path.push(Move::new(MoveKind::Link, Point3::new(s[0], s[1], zc)));
                self.links += 1;
                self.plunge(s, above.min(zc), node.z, &node.region, straight);
            }
            None => {
                self.retracts += 1;
                self.path.push(Move::new(MoveKind::Retract, Point3::new(here.x, here.y, self.clearance)));
                self.path.push(Move::new(MoveKind::Rapid, Point3::new(s[0], s[1], self.clearance)));
                self.plunge(s, above, node.z, &node.region, straight);
            }
        }
    }

    /// The height down to which the material over the tool centre `s` of node
    /// `k` and over the start of a helix about it is cleared: the level of its
    /// parent when both lie [`tol::ENTRY_MARGIN`] inside the parent's region
    /// (the parent's passes swept every point within R of it), else the same
    /// for the parent, up to a root's top; never above the stock's top.
    fn cleared_top(&self, nodes: &[Node], k: usize, s: P2) -> f64 {
        let points = [s, [s[0] + self.helix_radius, s[1]]];
        let mut c = k;
        while let Some(p) = nodes[c].parent {
            if points.iter().all(|&q| inside_by(&nodes[p].region, q, tol::ENTRY_MARGIN)) {
                break;
            }
            c = p;
        }
        nodes[c].top.min(self.stock_top)
    }

    /// Down from the cleared height `above` to `z` at `s`: a rapid to
    /// `APPROACH` above it (when higher), then a helix about `s` when its
    /// circle fits in `region` (the tool centre's circle of
    /// [`tol::HELIX_RADIUS_SHARE`] R, descending at [`tol::HELIX_SLOPE`], one
    /// full turn at `z`, counter-clockwise: climb in the bore), else a
    /// straight plunge (always when `straight`: the tool cuts nothing at `s`).
    fn plunge(&mut self, s: P2, above: f64, z: f64, region: &Region, straight: bool) {
        let current = self.at().map_or(self.clearance, |p| p.z);
        let rh = self.helix_radius;
        let (above, straight) = match self.material_over(s, above, z) {
            Some(top) => (top, straight),
            None => (z, true),
        };
        let approach = above + tol::APPROACH;
        let depth = above - z;
        let fits = !straight && rh > 0.0 && depth > 0.0 && region.holds_disc(s, rh);
        let start = if fits { [s[0] + rh, s[1]] } else { s };
        if current > approach {
            self.path.push(Move::new(MoveKind::Rapid, Point3::new(start[0], start[1], approach)));
        } else if fits {
            self.path.push(Move::new(MoveKind::Link, Point3::new(start[0], start[1], current)));
        }
        if !fits {
            self.path.push(Move::new(MoveKind::Plunge, Point3::new(s[0], s[1], z)));
            return;
        }
        self.path.push(Move::new(MoveKind::Plunge, Point3::new(start[0], start[1], above.min(current))));
        let per_turn = std::f64::consts::TAU * rh * tol::HELIX_SLOPE;
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small positive count")]
        let quarters = 4 * ((above.min(current) - z) / per_turn).ceil().max(1.0) as usize + 4;
        let top = above.min(current);
        #[allow(clippy::cast_precision_loss, reason = "a small count")]
        let descent = quarters as f64 - 4.0;
        for i in 1..=quarters {
            #[allow(clippy::cast_precision_loss, reason = "a small count")]
            let a = std::f64::consts::FRAC_PI_2 * i as f64;
            #[allow(clippy::cast_precision_loss, reason = "a small count")]
            let zi = if (i as f64) < descent { top - (top - z) * i as f64 / descent } else { z };
            let arc = ArcXY { center: Point2::new(s[0], s[1]), sweep: std::f64::consts::FRAC_PI_2 };
            self.path
                .push_arc(Move::new(MoveKind::Feed, Point3::new(s[0] + rh * a.cos(), s[1] + rh * a.sin(), zi)), arc);
        }
        self.path.push(Move::new(MoveKind::Feed, Point3::new(s[0], s[1], z)));
        self.helices += 1;
    }

    /// How high material may stand over an entry at `s` down to `z`, given
    /// that nothing stands above `above` there: with the in-process stock
    /// known, at most its highest top over the box around the disc the tool
    /// and its helix sweep (a cell's top bounds the stock over the cell).
    /// `None` when nothing stands more than [`tol::MIN_CHIP`] above `z`.
    fn material_over(&self, s: P2, above: f64, z: f64) -> Option<f64> {
        let Some(m) = self.material else { return Some(above) };
        let reach = self.tool_radius + self.helix_radius;
        let top = m.top_in([s[0] - reach, s[1] - reach], [s[0] + reach, s[1] + reach])?;
        (top > z + tol::MIN_CHIP).then_some(above.min(top))
    }

    /// A retract within a level: up to the clearance, over, and down (a
    /// straight plunge when the tool cuts nothing at `s`: `cleared`).
    fn retract_to(&mut self, s: P2, above: f64, z: f64, region: &Region, cleared: bool) {
        let Some(here) = self.at() else { return };
        self.retracts += 1;
        self.path.push(Move::new(MoveKind::Retract, Point3::new(here.x, here.y, self.clearance)));
        self.path.push(Move::new(MoveKind::Rapid, Point3::new(s[0], s[1], self.clearance)));
        if cleared {
            let above = self.material_over(s, above, z).unwrap_or(z);
            self.path.push(Move::new(MoveKind::Rapid, Point3::new(s[0], s[1], above + tol::APPROACH)));
            self.path.push(Move::new(MoveKind::Plunge, Point3::new(s[0], s[1], z)));
        } else {
            self.plunge(s, above, z, region, false);
        }
    }

    /// The last retract to the clearance height.
    fn finish(&mut self) {
        if let Some(p) = self.at() {
            self.path.push(Move::new(MoveKind::Retract, Point3::new(p.x, p.y, self.clearance)));
        }
    }

    fn cut(&mut self, c: &Contour, z: f64) {
        push_contour(&mut self.path, c, z);
        self.passes += 1;
    }
}

/// Whether `p` and the points at distance `d` from it in 16 directions lie in
/// `region`.
fn inside_by(region: &Region, p: P2, d: f64) -> bool {
    region.contains(p)
        && (0..16).all(|i| {
            let a = std::f64::consts::PI * f64::from(i) / 8.0;
            region.contains([p[0] + d * a.cos(), p[1] + d * a.sin()])
        })
}

/// The node and its ancestors.
fn chain(nodes: &[Node], k: usize) -> Vec<usize> {
    let mut out = vec![k];
    let mut c = nodes[k].parent;
    while let Some(p) = c {
        out.push(p);
        c = nodes[p].parent;
    }
    out
}

/// The start of the cut after `step` in `steps`.
fn next_start(steps: &[Step], step: &Step) -> Option<P2> {
    let i = steps.iter().position(|s| std::ptr::eq(s, step))?;
    steps[i + 1..].iter().find_map(|s| match s {
        Step::Cut(c) => c.start(),
        Step::Link { .. } => None,
    })
}

/// Appends the closed contour `c` at height `z` as feed moves from its start
/// (the tool is there): lines, and arcs split to at most
/// [`tol::MAX_ARC_SWEEP`] each.
pub fn push_contour(path: &mut Toolpath, c: &Contour, z: f64) {
    for seg in c.segments() {
        match seg {
            Segment::Line { to, .. } => path.push(Move::new(MoveKind::Feed, Point3::new(to[0], to[1], z))),
            Segment::Arc { from, to, center, sweep } => {
                #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "a small positive count")]
                let pieces = (sweep.abs() / tol::MAX_ARC_SWEEP).ceil().max(1.0) as usize;
                let r = (from[0] - center[0]).hypot(from[1] - center[1]);
                let a0 = (from[1] - center[1]).atan2(from[0] - center[0]);
                #[allow(clippy::cast_precision_loss, reason = "a small count")]
                let step = sweep / pieces as f64;
                for i in 1..=pieces {
                    #[allow(clippy::cast_precision_loss, reason = "a small count")]
                    let a = a0 + step * i as f64;
                    let p = if i == pieces { to } else { [center[0] + r * a.cos(), center[1] + r * a.sin()] };
                    let arc = ArcXY { center: Point2::new(center[0], center[1]), sweep: step };
                    path.push_arc(Move::new(MoveKind::Feed, Point3::new(p[0], p[1], z)), arc);
                }
            }
        }
    }
}

/// The clearing of one 2D pocket at height `z` from the height
/// `top` (the material's top): a plunge at the first pass, links and
/// retracts as planned (see [`plan_region`]).
///
/// # Errors
/// As [`plan_region`].
pub fn pocket_toolpath(
    region: &Region,
    options: &ClearOptions,
    z: f64,
    top: f64,
    motion: &Motion,
) -> Result<RoughPlan, RoughError> {
    let mut out = Emitter::new(motion, top, options);
    let mut nodes = Vec::new();
    for part in region.components() {
        let steps = plan_region(&part, options)?;
        nodes.push(Node { z, top, region: part, parent: None, steps });
    }
    let roots: Vec<usize> = (0..nodes.len()).collect();
    visit_all(&nodes, &roots, &mut out);
    out.finish();
    let level = Level { z, region: region.clone() };
    Ok(RoughPlan {
        toolpath: out.path,
        levels: vec![level],
        passes: out.passes,
        links: out.links,
        retracts: out.retracts,
        helices: out.helices,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two links in a row (an adaptive run split at two moves in a row, no
    /// cut between them): the first ends where it was planned to end, where
    /// the second was planned from, not at the next cut's start (a move
    /// never checked, which cut into a wall of mount_rush).
    #[test]
    fn a_link_ends_where_it_was_planned_to_end() {
        let square = |x0: f64, y0: f64, s: f64| {
            Contour::polygon(&[[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]], true).unwrap()
        };
        let options = ClearOptions {
            tool_radius: 1.0,
            stepover: 0.4,
            direction: Direction::Climb,
            chord_tolerance: 0.01,
            pattern: Pattern::Adaptive,
        };
        let (q, r) = ([5.0, 1.0], [9.0, 9.0]);
        let steps = vec![
            Step::Cut(square(1.0, 1.0, 2.0)),
            Step::Link { tool_down: true, via: vec![[4.0, 1.0]], cleared: true, to: Some(q) },
            Step::Link { tool_down: true, via: vec![[9.0, 1.0]], cleared: true, to: Some(r) },
            Step::Cut(square(9.0, 9.0, 0.5)),
        ];
        let region = Region::from_polygons(&[vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]], false);
        let nodes = vec![Node { z: -1.0, top: 0.0, region, parent: None, steps }];
        let mut out = Emitter::new(&Motion { clearance_z: 5.0, feed: 1000.0 }, 0.0, &options);
        visit_all(&nodes, &[0], &mut out);
        let links: Vec<[f64; 2]> =
            out.path.moves().iter().filter(|m| m.kind == MoveKind::Link).map(|m| [m.to.x, m.to.y]).collect();
        assert_eq!(links, vec![[4.0, 1.0], q, [9.0, 1.0], r]);
    }
}
