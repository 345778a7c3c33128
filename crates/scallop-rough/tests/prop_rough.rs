//! Roughing: regions inside the stock and outside the part grown by the
//! allowances (brute-force drop-cutter), pockets cleared (a brute-force
//! coverage oracle), climb orientation, tool-down links inside the cleared
//! area, and the same plan on one and two threads.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use proptest::prelude::*;
use scallop_contour::{Contour, Region};
use scallop_cutter::{Cutter, CutterShape, drop_cutter};
use scallop_geom::{Aabb3, Point2, Point3};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_rough::{
    ClearOptions, Direction, MaterialMap, Motion, Pattern, RoughPlan, RoughSettings, Step, grown_cutter, plan_offset,
    plan_rough, plan_rough_from, pocket_toolpath,
};
use scallop_sim::{EngagementOptions, ZMap, engagement_angle, stock_engagement};
use scallop_toolpath::{MoveKind, Toolpath};

/// A box `[x0, x1] x [y0, y1] x [0, h]` on a plate `[-p, p]^2` at z = 0 and a
/// step `[x0, x1] x [y0, mid] x [h, h + s]`: two floors and walls.
fn stepped_part(x0: f64, x1: f64, y0: f64, y1: f64, h: f64, s: f64) -> TriMesh {
    let p = |x, y, z| Point3::new(x, y, z);
    let mut soup = Vec::new();
    let mut quad = |a: Point3, b: Point3, c: Point3, d: Point3| {
        soup.push([a, b, c]);
        soup.push([a, c, d]);
    };
    let plate = 40.0;
    quad(p(-plate, -plate, 0.0), p(plate, -plate, 0.0), p(plate, plate, 0.0), p(-plate, plate, 0.0));
    let mut block = |x0: f64, x1: f64, y0: f64, y1: f64, z0: f64, z1: f64| {
        quad(p(x0, y0, z1), p(x1, y0, z1), p(x1, y1, z1), p(x0, y1, z1));
        quad(p(x0, y0, z0), p(x1, y0, z0), p(x1, y0, z1), p(x0, y0, z1));
        quad(p(x1, y0, z0), p(x1, y1, z0), p(x1, y1, z1), p(x1, y0, z1));
        quad(p(x1, y1, z0), p(x0, y1, z0), p(x0, y1, z1), p(x1, y1, z1));
        quad(p(x0, y1, z0), p(x0, y0, z0), p(x0, y0, z1), p(x0, y1, z1));
    };
    block(x0, x1, y0, y1, 0.0, h);
    block(x0, x1, y0, 0.5 * (y0 + y1), h, h + s);
    TriMesh::from_soup(&soup).unwrap().0
}

fn settings(stepdown: f64, radial: f64, axial: f64) -> RoughSettings {
    RoughSettings {
        stepdown,
        stepover: 0.2,
        radial_allowance: radial,
        axial_allowance: axial,
        pattern: Pattern::Offset,
        direction: Direction::Climb,
    }
}

/// Points along the cutting moves (feeds, links; arcs as chords) every `step` mm.
fn samples(path: &Toolpath, step: f64) -> Vec<Point3> {
    let mut out = Vec::new();
    let moves = path.moves();
    for k in 1..moves.len() {
        let m = moves[k];
        if !matches!(m.kind, MoveKind::Feed | MoveKind::Link | MoveKind::Plunge) {
            continue;
        }
        let a = moves[k - 1].to;
        let pts: Vec<Point3> = match path.arc(k) {
            Some(arc) => {
                let c = arc.center;
                let r = (a.x - c.x).hypot(a.y - c.y);
                let a0 = (a.y - c.y).atan2(a.x - c.x);
                let n = ((arc.sweep.abs() * r / step).ceil() as usize).max(1);
                (0..=n)
                    .map(|i| {
                        let t = a0 + arc.sweep * i as f64 / n as f64;
                        Point3::new(c.x + r * t.cos(), c.y + r * t.sin(), m.to.z)
                    })
                    .collect()
            }
            None => {
                let n = (((m.to - a).norm() / step).ceil() as usize).max(1);
                (0..=n).map(|i| a + (m.to - a) * (i as f64 / n as f64)).collect()
            }
        };
        out.extend(pts);
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]

    /// Every level's region lies in the stock box grown by R and outside the
    /// part grown by the allowances: the grown cutter dropped at its ring
    /// points stays below the level less the axial allowance; every cutting
    /// sample of the path is as safe with the real cutter.
    #[test]
    fn regions_inside_stock_and_outside_the_grown_part(
        w in 8.0..20.0_f64, d in 8.0..20.0_f64, h in 3.0..9.0_f64, s in 1.0..4.0_f64,
        radial in 0.0..0.8_f64, axial in 0.0..0.5_f64, stepdown in 1.0..3.0_f64,
    ) {
        let mesh = stepped_part(-w / 2.0, w / 2.0, -d / 2.0, d / 2.0, h, s);
        let index = MeshIndex::build(&mesh);
        let cutter = Cutter::new(CutterShape::Flat { radius: 3.0 }, 40.0).unwrap();
        let stock = Aabb3 { min: Point3::new(-w / 2.0 - 5.0, -d / 2.0 - 5.0, 0.0), max: Point3::new(w / 2.0 + 5.0, d / 2.0 + 5.0, h + s + 2.0) };
        let set = settings(stepdown, radial, axial);
        let motion = Motion { clearance_z: h + s + 10.0, feed: 1000.0 };
        let plan = plan_rough(&index, &cutter, &stock, &set, &motion, 1e-3).unwrap();
        // Both floors get a level: the step's top and the plate.
        for floor in [h, h + s] {
            prop_assert!(plan.levels.iter().any(|l| (l.z - floor - axial).abs() < 1e-3), "{:?}", plan.levels.iter().map(|l| l.z).collect::<Vec<_>>());
        }
        let grown = grown_cutter(&cutter, radial).unwrap();
        for level in &plan.levels {
            for ring in level.region.rings() {
                for p in ring.to_points(1e-3) {
                    prop_assert!(p[0] >= stock.min.x - 3.0 - 1e-6 && p[0] <= stock.max.x + 3.0 + 1e-6);
                    prop_assert!(p[1] >= stock.min.y - 3.0 - 1e-6 && p[1] <= stock.max.y + 3.0 + 1e-6);
                    let cl = drop_cutter(&grown, &index, Point2::new(p[0], p[1]), f64::NEG_INFINITY);
                    // The loops and booleans are within 1e-3 mm of the exact contour.
                    let ok = cl.tip.z <= level.z - axial + 1e-9
                        || drop_cutter(&grown, &index, Point2::new(p[0], p[1]), f64::NEG_INFINITY).tip.z <= level.z - axial + 1e-9;
                    let near = [[1e-3, 0.0], [-1e-3, 0.0], [0.0, 1e-3], [0.0, -1e-3]].iter().any(|o| {
                        drop_cutter(&grown, &index, Point2::new(p[0] + o[0], p[1] + o[1]), f64::NEG_INFINITY).tip.z <= level.z - axial + 1e-9
                    });
                    prop_assert!(ok || near, "ring point {p:?} at level {} is in the grown part ({})", level.z, cl.tip.z);
                }
            }
        }
        // The thinned loops (tol::SIMPLIFY) and the links' slack (tol::LINK_GROW)
        // may bring a tool centre that close to the exact contour, no closer.
        let slack = scallop_rough::tol::SIMPLIFY + scallop_rough::tol::LINK_GROW;
        let safe = |x: f64, y: f64, z: f64| drop_cutter(&cutter, &index, Point2::new(x, y), f64::NEG_INFINITY).tip.z <= z - axial + 1e-9;
        for q in samples(&plan.toolpath, 0.25) {
            let near = (0..16).any(|i| {
                let a = std::f64::consts::PI * f64::from(i) / 8.0;
                safe(q.x + slack * a.cos(), q.y + slack * a.sin(), q.z)
            });
            prop_assert!(safe(q.x, q.y, q.z) || near, "{q:?} below the part + allowance");
        }
    }

    /// A rectangular pocket with a round island, cleared: every point of the
    /// area the tool can reach (the tool-centre region grown by R) lies within
    /// R of the cutting path (brute force), every pass is in the region, and
    /// the outer rings run counter-clockwise (climb).
    #[test]
    fn pockets_are_cleared(w in 20.0..60.0_f64, h in 20.0..50.0_f64, isl in 2.0..6.0_f64, f in 0.1..0.5_f64) {
        let r = 3.0;
        let wall = Region::with_holes(
            Contour::polygon(&[[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]], true).unwrap(),
            vec![Contour::circle([w / 2.0, h / 2.0], isl).unwrap()],
        ).unwrap();
        let region = wall.offset(r);
        let options = ClearOptions { tool_radius: r, stepover: f * 2.0 * r, direction: Direction::Climb, chord_tolerance: 1e-3, pattern: Pattern::Offset };
        // Climb: the last (largest) pass runs counter-clockwise along the wall,
        // the passes around the island clockwise; conventional: the reverse.
        for (direction, sign) in [(Direction::Climb, 1.0), (Direction::Conventional, -1.0)] {
            let steps = plan_offset(&region, &ClearOptions { direction, ..options }).unwrap();
            // A cut that starts with a transition from the ring before it is
            // open (it ends where its ring began, ae from its start): its
            // points closed by that short segment have the ring's orientation.
            let area = |q: &[[f64; 2]]| -> f64 {
                0.5 * (0..q.len()).map(|i| {
                    let (a, b) = (q[i], q[(i + 1) % q.len()]);
                    a[0] * b[1] - a[1] * b[0]
                }).sum::<f64>()
            };
            let areas: Vec<f64> = steps.iter().filter_map(|s| match s {
                Step::Cut(c) => Some(sign * area(&c.to_points(1e-3))),
                Step::Link { .. } => None,
            }).collect();
            let largest = areas.iter().copied().fold(0.0_f64, |m, a| if a.abs() > m.abs() { a } else { m });
            prop_assert!(largest > 0.0, "{direction:?}: {areas:?}");
            // (The island's ring may merge with the wall's for large islands.)
            let has_hole = region.rings().iter().any(|r| !r.is_ccw());
            prop_assert!(!has_hole || areas.iter().any(|&a| a < 0.0), "{direction:?}: no pass around the island");
        }
        let motion = Motion { clearance_z: 5.0, feed: 1000.0 };
        let plan = pocket_toolpath(&region, &options, -1.0, 0.0, &motion).unwrap();
        let pts = samples(&plan.toolpath, 0.1);
        let holder = region.offset(-1e-3);
        for q in &pts {
            if q.z < -0.5 {
                prop_assert!(holder.contains([q.x, q.y]), "{q:?} leaves the tool-centre region");
            }
        }
        let reach = region.offset(-(r - 0.02));
        let mut grid = Vec::new();
        for i in 0..60 { for j in 0..60 {
            let p = [w * (i as f64 + 0.5) / 60.0, h * (j as f64 + 0.5) / 60.0];
            if reach.contains(p) { grid.push(p); }
        }}
        for p in grid {
            let covered = pts.iter().any(|q| q.z < -0.5 && (q.x - p[0]).hypot(q.y - p[1]) <= r);
            prop_assert!(covered, "{p:?} left uncut");
        }
    }
}

/// The tool-down links of a pocket stay where the material is cut: the link
/// never crosses the island, and the plan is the same on one and two threads.
#[test]
fn links_and_threads() {
    let mesh = stepped_part(-6.0, 6.0, -5.0, 5.0, 6.0, 2.0);
    let index = MeshIndex::build(&mesh);
    let cutter = Cutter::new(CutterShape::Flat { radius: 3.0 }, 40.0).unwrap();
    let stock = Aabb3 { min: Point3::new(-11.0, -10.0, 0.0), max: Point3::new(11.0, 10.0, 10.0) };
    let motion = Motion { clearance_z: 20.0, feed: 1000.0 };
    let set = settings(2.0, 0.3, 0.1);
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| plan_rough(&index, &cutter, &stock, &set, &motion, 1e-3).unwrap())
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.toolpath, b.toolpath);
    assert!(a.passes > 0 && a.links > 0, "{} passes {} links", a.passes, a.links);
    let moves = a.toolpath.moves();
    // Links are horizontal.
    for k in 1..moves.len() {
        if moves[k].kind == MoveKind::Link {
            assert!((moves[k].to.z - moves[k - 1].to.z).abs() < 1e-12);
        }
    }
}

/// A material map of 0.5 mm cells over `stock` holding the stock's top in
/// `blocks` (`[x0, y0, x1, y1, top]`, material from the stock's bottom up to
/// `top`) and nothing elsewhere: what earlier operations might have left.
fn material(stock: &Aabb3, blocks: &[[f64; 5]]) -> MaterialMap {
    let cell = 0.5;
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss, reason = "small positive counts")]
    let (nx, ny) =
        (((stock.max.x - stock.min.x) / cell).ceil() as usize, ((stock.max.y - stock.min.y) / cell).ceil() as usize);
    let mut tops = vec![f64::NEG_INFINITY; nx * ny];
    for j in 0..ny {
        for i in 0..nx {
            let (x, y) = (stock.min.x + (i as f64 + 0.5) * cell, stock.min.y + (j as f64 + 0.5) * cell);
            for b in blocks {
                if x >= b[0] && x <= b[2] && y >= b[1] && y <= b[3] {
                    tops[j * nx + i] = tops[j * nx + i].max(b[4]);
                }
            }
        }
    }
    MaterialMap::new([stock.min.x, stock.min.y], [cell, cell], nx, ny, tops).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]

    /// Roughing from an in-process stock (rest roughing): every level's
    /// region lies in the region of the same level planned from the box
    /// (so outside the part grown by the allowances), every centre of it is
    /// within R of material above the level, and every centre of the box's
    /// region within `R - margin` of such material is kept (brute force over
    /// the material's cells, not the planner's outlines).
    #[test]
    fn rest_regions_reach_the_material_and_only_it(
        w in 8.0..16.0_f64, d in 8.0..16.0_f64, h in 3.0..7.0_f64,
        bx in -10.0..6.0_f64, by in -10.0..6.0_f64, bw in 1.0..6.0_f64, top in 1.0..9.0_f64,
    ) {
        let mesh = stepped_part(-w / 2.0, w / 2.0, -d / 2.0, d / 2.0, h, 1.5);
        let index = MeshIndex::build(&mesh);
        let r = 2.0;
        let cutter = Cutter::new(CutterShape::Flat { radius: r }, 40.0).unwrap();
        let stock = Aabb3 { min: Point3::new(-w / 2.0 - 5.0, -d / 2.0 - 5.0, 0.0), max: Point3::new(w / 2.0 + 5.0, d / 2.0 + 5.0, h + 3.0) };
        // Two blocks of material left: one placed at random, one in a corner of the stock.
        let blocks = [[bx, by, bx + bw, by + bw, top], [stock.min.x, stock.min.y, stock.min.x + 3.0, stock.min.y + 2.0, h + 2.0]];
        let map = material(&stock, &blocks);
        let set = settings(1.0, 0.3, 0.2);
        let motion = Motion { clearance_z: h + 10.0, feed: 1000.0 };
        let from_box = plan_rough(&index, &cutter, &stock, &set, &motion, 1e-3).unwrap();
        let rest = plan_rough_from(&index, &cutter, &stock, Some(&map), &set, &motion, 1e-3).unwrap();
        let cell = 0.5;
        // Cells with material more than the minimum chip above z, as squares.
        let above = |z: f64| -> Vec<[f64; 2]> {
            let mut out = Vec::new();
            let (nx, ny) = (((stock.max.x - stock.min.x) / cell).ceil() as usize, ((stock.max.y - stock.min.y) / cell).ceil() as usize);
            for j in 0..ny { for i in 0..nx {
                let c = [stock.min.x + (i as f64 + 0.5) * cell, stock.min.y + (j as f64 + 0.5) * cell];
                if blocks.iter().any(|b| c[0] >= b[0] && c[0] <= b[2] && c[1] >= b[1] && c[1] <= b[3] && b[4] > z + scallop_rough::tol::MIN_CHIP) {
                    out.push(c);
                }
            }}
            out
        };
        // Distance from p to a cell's square.
        let to_cell = |p: [f64; 2], c: [f64; 2]| ((p[0] - c[0]).abs() - cell / 2.0).max(0.0).hypot(((p[1] - c[1]).abs() - cell / 2.0).max(0.0));
        let margin = cell * 2f64.sqrt() + scallop_rough::tol::MIN_CHIP;
        let mut kept = 0;
        for level in &from_box.levels {
            let cells = above(level.z);
            let limited = rest.levels.iter().find(|l| (l.z - level.z).abs() < 1e-9);
            // Sample the box's region on a 0.25 mm grid.
            let (lo, hi) = (level.region.bounds().unwrap().0, level.region.bounds().unwrap().1);
            let mut y = lo[1];
            while y <= hi[1] {
                let mut x = lo[0];
                while x <= hi[0] {
                    let p = [x, y];
                    let near = cells.iter().map(|&c| to_cell(p, c)).fold(f64::INFINITY, f64::min);
                    let inside_rest = limited.is_some_and(|l| l.region.contains(p));
                    if inside_rest {
                        kept += 1;
                        // Within the region planned from the box (away from its boundary by the chords).
                        let boundary = [[1e-2, 0.0], [-1e-2, 0.0], [0.0, 1e-2], [0.0, -1e-2]].iter().any(|o| !level.region.contains([x + o[0], y + o[1]]));
                        prop_assert!(level.region.contains(p) || boundary, "{p:?} at {} outside the box's region", level.z);
                        prop_assert!(near <= r + 0.3, "{p:?} at {} is {near} mm from material", level.z);
                    } else if level.region.contains(p) && near < r - margin - 0.35 {
                        // Near the rest region's boundary the booleans' chords decide.
                        let edge = limited.is_some_and(|l| [[0.1, 0.0], [-0.1, 0.0], [0.0, 0.1], [0.0, -0.1]].iter().any(|o| l.region.contains([x + o[0], y + o[1]])));
                        prop_assert!(edge, "{p:?} at {} reaches material {near} mm away but is not kept", level.z);
                    }
                    x += 0.25;
                }
                y += 0.25;
            }
        }
        prop_assert!(kept > 0, "no centre kept");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]

    /// Rest roughing enters each piece of material it finds where the tool
    /// last left the material above it: every descent at a feed (a plunge or
    /// a helix) starts at most the approach height above the highest
    /// material the earlier operations left within reach of it (the tool and
    /// its helix, brute force over the blocks), or above the level when there
    /// is none; no helix turns where nothing is left to cut. The material:
    /// a tall narrow block and a low wide one, each placed at random.
    #[test]
    fn rest_entries_descend_at_the_feed_only_through_material(
        tx in -12.0..4.0_f64, ty in -10.0..4.0_f64, lx in -12.0..2.0_f64, ly in -10.0..2.0_f64,
        lw in 4.0..10.0_f64, low in 0.6..2.5_f64,
    ) {
        let (w, d, h) = (10.0, 8.0, 4.0);
        let mesh = stepped_part(-w / 2.0, w / 2.0, -d / 2.0, d / 2.0, h, 1.5);
        let index = MeshIndex::build(&mesh);
        let r = 1.5;
        let cutter = Cutter::new(CutterShape::Flat { radius: r }, 40.0).unwrap();
        let stock = Aabb3 { min: Point3::new(-w / 2.0 - 8.0, -d / 2.0 - 8.0, 0.0), max: Point3::new(w / 2.0 + 8.0, d / 2.0 + 8.0, h + 4.0) };
        let blocks = [[tx, ty, tx + 2.0, ty + 2.0, h + 3.0], [lx, ly, lx + lw, ly + lw, low]];
        let map = material(&stock, &blocks);
        let set = settings(1.0, 0.3, 0.2);
        let motion = Motion { clearance_z: h + 10.0, feed: 1000.0 };
        let rest = plan_rough_from(&index, &cutter, &stock, Some(&map), &set, &motion, 1e-3).unwrap();
        prop_assert!(rest.passes > 0);
        // The highest block top whose square meets the box of half-side
        // `reach` around `p`.
        let top_near = |p: Point3, reach: f64| {
            blocks
                .iter()
                .filter(|b| p.x + reach >= b[0] && p.x - reach <= b[2] && p.y + reach >= b[1] && p.y - reach <= b[3])
                .map(|b| b[4])
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let rh = scallop_rough::tol::HELIX_RADIUS_SHARE * r;
        // A helix point lies rh from its centre; a cell (0.5 mm) decides a top.
        let reach = r + 2.0 * rh + 0.5;
        let moves = rest.toolpath.moves();
        let mut descents = 0;
        for k in 1..moves.len() {
            let (a, b) = (moves[k - 1].to, moves[k].to);
            if !matches!(moves[k].kind, MoveKind::Plunge | MoveKind::Feed) || b.z > a.z - 1e-9 {
                continue;
            }
            descents += 1;
            // The level this descent ends on: the next move at a constant height.
            let level = moves[k..].iter().find(|m| m.kind != MoveKind::Plunge && (m.to.z - b.z).abs() < 1e-9).map_or(b.z, |m| m.to.z);
            let top = top_near(a, reach);
            prop_assert!(
                a.z <= top.max(level) + scallop_rough::tol::APPROACH + 1e-9,
                "move {k}: a descent at the feed from z {:.3} at ({:.2}, {:.2}); material within reach up to {top:.3}",
                a.z, a.x, a.y
            );
            if moves[k].kind == MoveKind::Feed {
                prop_assert!(top > b.z, "move {k}: a helix at ({:.2}, {:.2}) z {:.3} with nothing to cut", b.x, b.y, b.z);
            }
        }
        prop_assert!(descents > 0);
    }
}

/// Adaptive clearing of a box on a plate in a larger stock: every level's
/// region runs R past the stock's sides, which are open (air). The levels
/// are entered from there by straight plunges (no helix), the feed moves
/// keep out of the air beyond the stock (no ring around it, no pass along
/// it), every tool centre of the regions inside the stock is reached by the
/// tool (no reachable stock left), and the plan is the same on one and two
/// threads.
#[test]
fn adaptive_levels_are_entered_from_the_open_sides() {
    let (plan, stock, cutter, _) = open_sides_plan(Pattern::Adaptive);
    let r = cutter.radius();
    assert_eq!(plan.helices, 0, "a level with an open side is entered from the air");
    assert_open_sides_kept(&plan, &stock, r);
}

/// The offset pattern, told each level's material (the stock's section),
/// leaves out the ring of the region around the stock's sides (the section
/// grown by R), along which the tool cuts nothing: at most 3 % of the feed
/// in the air around the stock, every tool centre inside the stock still
/// reached, links inside their levels, and the same plan on one and two
/// threads; its rings nearer the open sides than the part are cut from the
/// air inwards, so no pass is a slot.
#[test]
fn offset_levels_cut_no_ring_around_the_stock() {
    let (plan, stock, cutter, set) = open_sides_plan(Pattern::Offset);
    let r = cutter.radius();
    assert_open_sides_kept(&plan, &stock, r);
    // Every level has open sides: cut from them inwards, no pass is a slot
    // (the simulator's reading on the stock box; the part is never cut).
    let map = ZMap::new(stock, 0.1).unwrap();
    let target = engagement_angle(set.stepover * 2.0 * r, r);
    let report = stock_engagement(&map, &cutter, &plan.toolpath, target, &EngagementOptions::default()).unwrap();
    assert!(report.slot_length < 1e-9, "{:.1} mm of slot", report.slot_length);
}

/// A box on a plate in a larger stock (every level's region runs R past the
/// stock's open sides) planned by `pattern` with a 6 mm flat end mill, 2 mm
/// levels, 0.3 D: the same plan on one and two threads, with passes.
fn open_sides_plan(pattern: Pattern) -> (RoughPlan, Aabb3, Cutter, RoughSettings) {
    let mesh = stepped_part(-6.0, 6.0, -5.0, 5.0, 6.0, 2.0);
    let index = MeshIndex::build(&mesh);
    let cutter = Cutter::new(CutterShape::Flat { radius: 3.0 }, 40.0).unwrap();
    let stock = Aabb3 { min: Point3::new(-16.0, -14.0, 0.0), max: Point3::new(16.0, 14.0, 10.0) };
    let motion = Motion { clearance_z: 20.0, feed: 1000.0 };
    let set = RoughSettings { pattern, ..settings(2.0, 0.3, 0.1) };
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| plan_rough(&index, &cutter, &stock, &set, &motion, 1e-3).unwrap())
    };
    let (plan, again) = (run(1), run(2));
    assert_eq!(plan.toolpath, again.toolpath);
    assert!(plan.passes > 0);
    (plan, stock, cutter, set)
}

/// Checks of a plan of levels on a part in a box of stock: at most 3 % of
/// the feed beyond R - 0.05 mm outside the stock's section, every tool-down
/// link inside its level's region, every region point inside the stock
/// within R of the cutting samples of its level.
fn assert_open_sides_kept(plan: &RoughPlan, stock: &Aabb3, r: f64) {
    // Distance of a tool centre outside the stock's section (0 inside).
    let outside = |x: f64, y: f64| {
        let dx = (stock.min.x - x).max(x - stock.max.x).max(0.0);
        let dy = (stock.min.y - y).max(y - stock.max.y).max(0.0);
        dx.hypot(dy)
    };
    let moves = plan.toolpath.moves();
    let (mut feed, mut air) = (0.0, 0.0);
    for k in 1..moves.len() {
        if moves[k].kind != MoveKind::Feed || moves[k].to.z >= stock.max.z {
            continue;
        }
        let (a, b) = (moves[k - 1].to, moves[k].to);
        let n = 20;
        for i in 0..n {
            let t = (f64::from(i) + 0.5) / f64::from(n);
            let len = (b - a).norm() / f64::from(n);
            feed += len;
            // The tool cuts nothing beyond R outside the stock.
            if outside(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)) >= r - 0.05 {
                air += len;
            }
        }
    }
    assert!(air <= 0.03 * feed, "{air:.1} of {feed:.1} mm of feed in the air around the stock");
    // Every tool-down link stays in the tool-centre region of its level.
    for k in 1..moves.len() {
        let (a, b) = (moves[k - 1].to, moves[k].to);
        if moves[k].kind == MoveKind::Link && (a.z - b.z).abs() < 1e-12 {
            let level = plan.levels.iter().find(|l| (l.z - b.z).abs() < 1e-9).unwrap();
            assert!(
                level.region.offset(-1e-3).contains_segment([a.x, a.y], [b.x, b.y], 1e-3),
                "link {a:?} -> {b:?} leaves its level"
            );
        }
    }
    // Every region point inside the stock is within R of the cutting samples of its level.
    let pts = samples(&plan.toolpath, 0.1);
    for level in &plan.levels {
        let inner = level.region.offset(-0.05);
        let at: Vec<&Point3> = pts.iter().filter(|q| (q.z - level.z).abs() < 1e-9).collect();
        let (ni, nj) = ((stock.max.x - stock.min.x) / 0.5, (stock.max.y - stock.min.y) / 0.5);
        for i in 0..ni.ceil() as i32 {
            for j in 0..nj.ceil() as i32 {
                let p = [stock.min.x + 0.5 * (f64::from(i) + 0.5), stock.min.y + 0.5 * (f64::from(j) + 0.5)];
                if p[0] < stock.max.x && p[1] < stock.max.y && inner.contains(p) {
                    let covered = at.iter().any(|q| (q.x - p[0]).hypot(q.y - p[1]) <= r);
                    assert!(covered, "{p:?} at z {} left uncut", level.z);
                }
            }
        }
    }
}
