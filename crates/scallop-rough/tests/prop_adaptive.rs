//! Adaptive clearing of generated pockets (disc, rectangle, rectangle with
//! a round island, L), judged by the simulator's engagement evaluation
//! (`scallop_sim::pocket_engagement`): the tool never reaches beyond a wall,
//! no reachable material is left, and the plan is the same on one and two
//! threads. The simulator follows arc moves along chords within 1 um, as
//! `scallop engagement` reads G2/G3. The engagement bound (1.1 x the
//! stepover's angle outside the entry) holds on discs and on 99 % of the
//! path elsewhere, not yet at the sharp corners of straight walls
//! (docs/roughing.md, "Adaptive clearing").
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use proptest::prelude::*;
use scallop_contour::{Contour, Region};
use scallop_geom::Point2;
use scallop_rough::{ClearOptions, Direction, Motion, Pattern, RoughPlan, pocket_toolpath};
use scallop_sim::{EngagementOptions, EngagementReport, Pocket, engagement_angle, pocket_engagement};

const R: f64 = 1.5;
const AE: f64 = 0.4 * R;

fn circle(cx: f64, cy: f64, r: f64, n: usize, clockwise: bool) -> Vec<[f64; 2]> {
    #[allow(clippy::cast_precision_loss, reason = "small counts")]
    let mut v: Vec<[f64; 2]> = (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            [cx + r * a.cos(), cy + r * a.sin()]
        })
        .collect();
    if clockwise {
        v.reverse();
    }
    v
}

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<[f64; 2]> {
    vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
}

/// The pocket's rings (wall first, then islands) and its plan.
fn plan(rings: &[Vec<[f64; 2]>]) -> (Pocket, RoughPlan) {
    let mut it = rings.iter().map(|r| Contour::polygon(r, true).unwrap());
    let outer = it.next().unwrap();
    let wall = Region::with_holes(outer, it.collect()).unwrap();
    let region = wall.offset(R);
    let options = ClearOptions {
        tool_radius: R,
        stepover: AE,
        direction: Direction::Climb,
        chord_tolerance: 1e-3,
        pattern: Pattern::Adaptive,
    };
    let motion = Motion { clearance_z: 5.0, feed: 1000.0 };
    let plan = pocket_toolpath(&region, &options, -1.0, 0.0, &motion).unwrap();
    let pocket =
        Pocket::new(rings.iter().map(|r| r.iter().map(|p| Point2::new(p[0], p[1])).collect()).collect()).unwrap();
    (pocket, plan)
}

fn judge(pocket: &Pocket, plan: &RoughPlan) -> EngagementReport {
    let options = EngagementOptions { gouge_tolerance: 0.03, ..EngagementOptions::default() };
    // A reach beyond a wall fails here (`PocketGouge`).
    pocket_engagement(pocket, R, &plan.toolpath, engagement_angle(AE, R), &options).unwrap()
}

/// Nothing reachable left, no gouge (in `judge`).
fn check_cleared(report: &EngagementReport) {
    assert!(report.uncut_area <= 0.05, "uncut {} mm2", report.uncut_area);
}

fn shape(w: f64, h: f64, kind: usize) -> Vec<Vec<[f64; 2]>> {
    match kind {
        0 => vec![rect(0.0, 0.0, w, h)],
        1 => vec![rect(0.0, 0.0, w, h), circle(0.5 * w, 0.5 * h, 1.5, 48, true)],
        2 => vec![vec![[0.0, 0.0], [w, 0.0], [w, 0.5 * h], [0.5 * w, 0.5 * h], [0.5 * w, h], [0.0, h]]],
        _ => vec![circle(0.5 * w, 0.5 * h, 0.5 * h, 96, false)],
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4))]

    #[test]
    fn pockets_are_cleared_inside_their_walls(w in 12.0..18.0f64, h in 9.0..12.0f64, kind in 0..4usize) {
        // Rectangles, with an island, Ls, discs.
        let (pocket, plan) = plan(&shape(w, h, kind));
        check_cleared(&judge(&pocket, &plan));
    }
}

#[test]
fn ls_are_cleared_inside_their_walls() {
    // The L's inner corner is cut by an arc of radius R about the corner:
    // measured as its chord (before the simulator followed arcs) it read
    // 0.11 mm beyond the wall.
    let (pocket, plan) = plan(&shape(12.0, 9.0, 2));
    assert!(plan.toolpath.arc_count() > 0);
    check_cleared(&judge(&pocket, &plan));
}

#[test]
fn discs_stay_within_the_bound_and_no_pocket_has_a_slot() {
    // The bound (1.1 x the stepover's angle) holds on a disc; the straight-
    // walled pockets (rectangle, with an island, L) exceed it at their sharp
    // corners, which this pattern does not handle yet (issue 16,
    // docs/roughing.md "Adaptive clearing"), so their slots and their 99th
    // percentile are judged.
    let bound = 1.1 * engagement_angle(AE, R);
    for kind in 0..4 {
        let r = judge_shape(&shape(16.0, 12.0, kind));
        assert!(r.slot_length <= 0.0, "shape {kind}: slot {:.2} mm", r.slot_length);
        assert!(r.p99 <= bound, "shape {kind}: p99 {:.1} deg, bound {:.1} deg", r.p99.to_degrees(), bound.to_degrees());
        if kind == 3 {
            assert!(
                r.max <= bound,
                "disc: max {:.1} deg at {:?}, bound {:.1} deg",
                r.max.to_degrees(),
                r.max_at,
                bound.to_degrees()
            );
        }
    }
}

fn judge_shape(rings: &[Vec<[f64; 2]>]) -> EngagementReport {
    let (pocket, plan) = plan(rings);
    judge(&pocket, &plan)
}

#[test]
fn the_same_plan_on_one_and_two_threads() {
    let rings = vec![rect(0.0, 0.0, 14.0, 10.0), circle(7.0, 5.0, 1.5, 48, true)];
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            plan(&rings).1.toolpath.moves().iter().map(|m| (m.kind, m.to.x, m.to.y, m.to.z)).collect::<Vec<_>>()
        })
    };
    let one = run(1);
    assert!(!one.is_empty());
    assert_eq!(one, run(2));
    assert_eq!(one, run(1));
}

/// A "#" of bars `bar` wide over `side` x `side`, its middle square an island
/// (the bench's glyph, `bench/freecad/pockets.py`, at any scale).
fn hash(side: f64, bar: f64) -> Vec<Vec<[f64; 2]>> {
    let (a, b) = (0.25 * side, 0.25 * side + bar);
    let (c, d) = (0.75 * side - bar, 0.75 * side);
    let outer = vec![
        [a, 0.0],
        [b, 0.0],
        [b, a],
        [c, a],
        [c, 0.0],
        [d, 0.0],
        [d, a],
        [side, a],
        [side, b],
        [d, b],
        [d, c],
        [side, c],
        [side, d],
        [d, d],
        [d, side],
        [c, side],
        [c, d],
        [b, d],
        [b, side],
        [a, side],
        [a, d],
        [0.0, d],
        [0.0, c],
        [a, c],
        [a, b],
        [0.0, b],
        [0.0, a],
        [a, a],
    ];
    vec![outer, rect(b, b, c, c).into_iter().rev().collect()]
}

/// A channel along the bottom with fingers up from it (the bench's narrow
/// branching pocket, straight fingers only): widths `w` of the fingers.
fn comb(w: &[f64]) -> Vec<Vec<[f64; 2]>> {
    let width = 4.0 * R + 1.0;
    let mut pts = vec![[0.0, 0.0]];
    let mut x = 2.0 * R;
    let mut top = Vec::new();
    for &fw in w {
        top.push((x, fw));
        x += fw + 3.0 * R;
    }
    pts.push([x, 0.0]);
    pts.push([x, width]);
    for &(x0, fw) in top.iter().rev() {
        pts.extend([[x0 + fw, width], [x0 + fw, width + 6.0 * fw], [x0, width + 6.0 * fw], [x0, width]]);
    }
    pts.push([0.0, width]);
    vec![pts]
}

/// The moves of kind `Link` (tool down at cutting depth): a move ending
/// within 2 R of the link's end (the approach to a cut's start, which may
/// enter a front at a new point) or within R of its start (the arc turning
/// away from the last pass's end, which may engage as a pass does,
/// docs/roughing.md "Adaptive clearing", step 7: since the seventeenth
/// session the smallest arc that fits is tried first, 0.15 mm for this
/// tool, and it swings the tool's front past the material the pass stopped
/// beside) engages no more than the bound, every other
/// cuts nothing by the simulator's reading. "Nothing" is within the simulator's raster: older
/// cuts and the walls are cells of `resolution`, so a tool centre at R from
/// an older one or from a wall may read a sliver up to a cell deep (plus the
/// planner's 5 um slack), 2 arccos(1 - d / R) of periphery (31 degrees here;
/// a pass reads 53).
fn check_links(plan: &RoughPlan, report: &EngagementReport) {
    let depth = EngagementOptions::default().resolution + 0.005;
    let air = 2.0 * (1.0 - depth / R).acos();
    let bound = 1.1 * engagement_angle(AE, R);
    let moves = plan.toolpath.moves();
    for (i, m) in moves.iter().enumerate() {
        if m.kind != scallop_toolpath::MoveKind::Link || m.to.z > -0.5 {
            continue;
        }
        let end = moves[i..].iter().find(|n| n.kind != scallop_toolpath::MoveKind::Link).map_or(m.to, |_| {
            moves[i..].iter().take_while(|n| n.kind == scallop_toolpath::MoveKind::Link).last().map_or(m.to, |n| n.to)
        });
        let start = moves[..i].iter().rev().find(|n| n.kind != scallop_toolpath::MoveKind::Link).map_or(m.to, |n| n.to);
        let approach =
            (m.to.x - end.x).hypot(m.to.y - end.y) <= 2.0 * R || (m.to.x - start.x).hypot(m.to.y - start.y) <= R;
        let phi = report.move_phi[i];
        let limit = if approach { bound } else { air };
        assert!(phi <= limit, "link move {i} to {:?}: {:.1} deg", m.to, phi.to_degrees());
    }
}

#[test]
fn a_hash_is_cleared_with_its_pieces_joined_tool_down() {
    // The front splits at the "#"'s crossings: its pieces were joined by
    // hundreds of retracts on the bench's glyph; they are joined through
    // cleared area now, by links that cut nothing.
    let (pocket, plan) = plan(&hash(40.0, 4.0 * R + 1.0));
    let report = judge(&pocket, &plan);
    check_cleared(&report);
    assert!(report.slot_length <= 0.0, "slot {:.2} mm", report.slot_length);
    check_links(&plan, &report);
    // A join is a retract only where no cleared path is found (at most 3 %:
    // the links between corners, along walls whose slivers the rings cut
    // last, docs/roughing.md "Adaptive clearing", step 8).
    assert!(33 * plan.retracts <= plan.links, "{} retracts, {} links", plan.retracts, plan.links);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3))]

    #[test]
    fn combs_are_cleared_with_links_that_cut_nothing(
        w in proptest::collection::vec(2.0 * R + 0.5..4.0 * R, 2..4)
    ) {
        // Fingers a little wider than the tool: a finger the walk cannot
        // turn into gets an entry of its own (a retract), and the links
        // between the corners at its end may be retracts (docs/roughing.md,
        // "Adaptive clearing", step 8): at most three a finger.
        let (pocket, plan) = plan(&comb(&w));
        let report = judge(&pocket, &plan);
        check_cleared(&report);
        check_links(&plan, &report);
        prop_assert!(plan.retracts <= 3 * w.len() + 1, "{} retracts, {} links", plan.retracts, plan.links);
    }
}

/// The tool-centre region of one of the bench's pockets (its rings, the
/// outer first) and the bench's options (tool D 6, stepover 0.2 D).
fn bench_region(rings: &[Vec<[f64; 2]>]) -> (Region, ClearOptions) {
    let mut it = rings.iter().map(|q| Contour::polygon(q, true).unwrap());
    let outer = it.next().unwrap();
    let wall = Region::with_holes(outer, it.collect()).unwrap();
    let options = ClearOptions {
        tool_radius: 3.0,
        stepover: 1.2,
        direction: Direction::Climb,
        chord_tolerance: 1e-3,
        pattern: Pattern::Adaptive,
    };
    (wall.offset(options.tool_radius), options)
}

/// The plan of the bench's pockets (bench/freecad/pockets.py: tool D 6,
/// stepover 0.2 D, as `scallop pocket`), judged by the simulator.
fn bench_plan(rings: &[Vec<[f64; 2]>]) -> (RoughPlan, EngagementReport) {
    let (region, options) = bench_region(rings);
    let (r, ae) = (options.tool_radius, options.stepover);
    let motion = Motion { clearance_z: 5.0, feed: 5000.0 };
    let plan = pocket_toolpath(&region, &options, -1.0, 0.0, &motion).unwrap();
    let pocket =
        Pocket::new(rings.iter().map(|q| q.iter().map(|p| Point2::new(p[0], p[1])).collect()).collect()).unwrap();
    let report =
        pocket_engagement(&pocket, r, &plan.toolpath, engagement_angle(ae, r), &EngagementOptions::default()).unwrap();
    (plan, report)
}

#[test]
fn passes_that_end_against_a_wall_leave_it_turning_not_reversing() {
    // A channel 12 mm wide for a 6 mm tool (one of the bench's "#" bars):
    // every pass runs from wall to wall and ends against one. Its link
    // leaves along an arc tangent to the pass's last heading turned away
    // from the material by the least of a few angles that fits, not by a
    // reversal at the wall (a stop under a jerk-limited controller,
    // docs/benchmarks.md "Adaptive clearing: cycle time and links, sixth
    // session").
    let (plan, report) = bench_plan(&[rect(0.0, 0.0, 60.0, 12.0)]);
    check_cleared_by(&report);
    let moves = plan.toolpath.moves();
    let (mut ends, mut sharp) = (0, 0);
    for i in 2..moves.len() {
        let (a, b, c) = (moves[i - 2].to, moves[i - 1].to, moves[i].to);
        if moves[i - 1].kind != scallop_toolpath::MoveKind::Feed
            || moves[i].kind != scallop_toolpath::MoveKind::Link
            || a.z > -0.5
            || c.z > -0.5
        {
            continue;
        }
        let (u, v) = ([b.x - a.x, b.y - a.y], [c.x - b.x, c.y - b.y]);
        let (lu, lv) = (u[0].hypot(u[1]), v[0].hypot(v[1]));
        if lu < 1e-9 || lv < 1e-9 {
            continue;
        }
        let turn = ((u[0] * v[0] + u[1] * v[1]) / (lu * lv)).clamp(-1.0, 1.0).acos();
        ends += 1;
        if turn > 75f64.to_radians() {
            sharp += 1;
        }
    }
    // Without the turned arcs, three quarters of them turned by 75 to 180
    // degrees; now the ends right by the rings and the corners do.
    assert!(ends >= 20, "{ends} pass ends");
    assert!(3 * sharp <= ends, "{sharp} of {ends} pass ends turn by over 75 degrees");
}

fn check_cleared_by(report: &EngagementReport) {
    assert!(report.uncut_area <= 0.05, "uncut {} mm2", report.uncut_area);
    assert!(report.slot_length <= 0.0, "slot {:.2} mm", report.slot_length);
}

/// The bench's "#" glyph (bench/freecad/pockets.py): four bars 12 mm wide
/// over 80 x 80 mm, the central square an island.
fn bench_hash() -> Vec<Vec<[f64; 2]>> {
    let outer = vec![
        [20.0, 0.0],
        [32.0, 0.0],
        [32.0, 20.0],
        [48.0, 20.0],
        [48.0, 0.0],
        [60.0, 0.0],
        [60.0, 20.0],
        [80.0, 20.0],
        [80.0, 32.0],
        [60.0, 32.0],
        [60.0, 48.0],
        [80.0, 48.0],
        [80.0, 60.0],
        [60.0, 60.0],
        [60.0, 80.0],
        [48.0, 80.0],
        [48.0, 60.0],
        [32.0, 60.0],
        [32.0, 80.0],
        [20.0, 80.0],
        [20.0, 60.0],
        [0.0, 60.0],
        [0.0, 48.0],
        [20.0, 48.0],
        [20.0, 32.0],
        [0.0, 32.0],
        [0.0, 20.0],
        [20.0, 20.0],
    ];
    let mut island = rect(32.0, 32.0, 48.0, 48.0);
    island.reverse();
    vec![outer, island]
}

#[test]
fn the_bench_island_and_hash_stay_within_the_bound() {
    // The maximum read 65 degrees (1.22 x the target) on the bench's
    // rectangle with a round island, and 59 to 74 on the "#" with the
    // links of `passes_that_end_against_a_wall_leave_it_turning_not_reversing`:
    // a pass meeting the thin edge of the material left by earlier cuts
    // right after a turn towards it, or halfway along a step (the walk
    // measured at the step's end only), or along a line that replaces
    // several steps and heads a little off them. Each step is now measured
    // at its start, quarters and end, and a line replaces steps only when
    // it is measured within the bound too.
    let bound = 1.1 * engagement_angle(1.2, 3.0);
    let island: Vec<[f64; 2]> = circle(50.0, 30.0, 12.0, 128, true);
    for (name, rings) in
        [("rectangle with an island", vec![rect(0.0, 0.0, 100.0, 60.0), island]), ("hash", bench_hash())]
    {
        let (_, report) = bench_plan(&rings);
        check_cleared_by(&report);
        assert!(
            report.max <= bound,
            "{name}: max {:.1} deg at {:?}, bound {:.1} deg",
            report.max.to_degrees(),
            report.max_at,
            bound.to_degrees()
        );
    }
}

/// Every pass of the walk, as emitted (lines and arcs), keeps the tool
/// centre in the region (grown by `tol::LINK_GROW`, the hair links may use):
/// the arcs refitted over a pass's lines are kept only where they stay in.
/// On the bench's "#" and rectangle with an island, where passes slide along
/// straight and round walls.
#[test]
fn passes_as_arcs_stay_in_the_region() {
    let island: Vec<[f64; 2]> = circle(50.0, 30.0, 12.0, 128, true);
    for rings in [vec![rect(0.0, 0.0, 100.0, 60.0), island], bench_hash()] {
        let (region, options) = bench_region(&rings);
        let grown = region.offset(-scallop_rough::tol::LINK_GROW);
        let mut arcs = 0usize;
        for step in scallop_rough::plan_adaptive(&region, &options).unwrap() {
            if let scallop_rough::Step::Cut(c) = step {
                arcs += c.vertices().iter().filter(|v| v.bulge != 0.0).count();
                for p in c.to_points(1e-5) {
                    assert!(grown.contains(p), "{p:?} outside the region");
                }
            }
        }
        // The check is not vacuous: the passes are arcs in good part.
        assert!(arcs > 100, "{arcs} arcs");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3))]

    #[test]
    fn fingers_the_walk_cannot_turn_into_are_looped_not_slotted(
        w in proptest::collection::vec(2.0 * R + 0.25 * R..2.0 * R + 0.45 * R, 1..3)
    ) {
        // Fingers a few tenths of R wider than the tool (the bench's 7 mm
        // finger for a 6 mm tool): the walk's steps cannot turn in them, and
        // the region's ring used to cut each one as a slot from its mouth to
        // its end; it is cut with loops there now (docs/roughing.md,
        // "Adaptive clearing", the region's rings).
        let (pocket, plan) = plan(&comb(&w));
        let report = judge(&pocket, &plan);
        check_cleared(&report);
        // What is left: where the finger's end meets a loop's sliver, as in
        // the offset pattern's loops (`prop_loops.rs`).
        prop_assert!(report.slot_length <= 0.25, "slot {:.2} mm at {:?}", report.slot_length, report.max_at);
    }
}
