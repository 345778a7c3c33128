//! Rest roughing on generated parts with inside corners, judged on the
//! simulated stock against an independent, analytic computation of what a
//! flat end mill can reach over boxes (issue 16, "rest roughing removes the
//! steps the first tool left in corners"; "results identical on 1 and 2
//! threads").
//!
//! Over a part made of axis-aligned boxes, a flat end mill of radius `g`
//! whose centre is at `c` rests on the highest box top whose rectangle lies
//! within `g` of `c` (the drop-cutter of a flat end is the highest point under
//! its disc). A roughing tool of radius R with a radial allowance s is planned
//! as a flat end of radius `g = R + s` kept off the part, with its tip the
//! axial allowance a above it; it cuts the stock within R of its centre. The
//! lowest the stock can be taken at a point p by such a tool is therefore
//! `reach(p) = min over |c - p| <= R of top_g(c) + a`. Material more than a
//! tolerance above the part grown by the allowances may be left only where
//! `reach(p)` stands above it too: where the tool cannot reach.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use proptest::prelude::*;
use scallop_cutter::{Cutter, CutterShape};
use scallop_engine::{FinishJob, Job, JobOutput, Operation, Part, StockShape, run_job};
use scallop_geom::{Aabb3, Point3};
use scallop_rough::{Direction, Pattern, RoughSettings};

mod common;
use common::boxes_mesh;

/// An axis-aligned box: (min, max) corners.
type Boxed = ([f64; 3], [f64; 3]);

/// A U of walls `t` thick and `h` high around a channel `w` wide, open at
/// +y, on a plate at z = 0 that spans the stock: two inside corners of 90
/// degrees at the channel's bottom.
fn u_part(w: f64, t: f64, h: f64) -> Vec<Boxed> {
    let (x0, x1) = (-0.5 * w, 0.5 * w);
    vec![
        ([-20.0, -20.0, -0.5], [20.0, 20.0, 0.0]),
        ([x0 - t, -10.0, 0.0], [x1 + t, -10.0 + t, h]),
        ([x0 - t, -10.0 + t, 0.0], [x0, 10.0, h]),
        ([x1, -10.0 + t, 0.0], [x1 + t, 10.0, h]),
    ]
}

/// XY distance from `p` to a box's rectangle.
fn distance(p: [f64; 2], b: &Boxed) -> f64 {
    let dx = (b.0[0] - p[0]).max(p[0] - b.1[0]).max(0.0);
    let dy = (b.0[1] - p[1]).max(p[1] - b.1[1]).max(0.0);
    dx.hypot(dy)
}

/// The highest box top within `g` of `p` (XY): the part grown by `g`
/// sideways; the tip height of a flat end mill of radius `g` at `p`.
fn top_within(boxes: &[Boxed], p: [f64; 2], g: f64) -> f64 {
    boxes.iter().filter(|b| distance(p, b) <= g).map(|b| b.1[2]).fold(f64::NEG_INFINITY, f64::max)
}

/// `reach(p)` of the module docs for a tool of radius `r` (centres sampled
/// every `step` over the disc) kept `s` off the part sideways and `a` above it.
fn reach(boxes: &[Boxed], p: [f64; 2], r: f64, s: f64, a: f64, step: f64) -> f64 {
    #[allow(clippy::cast_possible_truncation, reason = "a small count")]
    let n = (r / step).ceil() as i32;
    let mut best = f64::INFINITY;
    for i in -n..=n {
        for j in -n..=n {
            let (dx, dy) = (f64::from(i) * step, f64::from(j) * step);
            if dx.hypot(dy) <= r {
                best = best.min(top_within(boxes, [p[0] + dx, p[1] + dy], r + s) + a);
            }
        }
    }
    best
}

fn operation(name: &str, boxes: &[Boxed], radius: f64, allowance: f64) -> Operation {
    let mut finish = FinishJob::choi_demo();
    finish.part = Part::Mesh(boxes_mesh(boxes));
    finish.part_name = "U walls".into();
    finish.cutter = Cutter::new(CutterShape::Flat { radius }, 30.0).unwrap();
    finish.sim_resolution = 0.2;
    let settings = RoughSettings {
        stepdown: 2.0,
        stepover: 0.3,
        radial_allowance: allowance,
        axial_allowance: allowance,
        pattern: Pattern::Offset,
        direction: Direction::Climb,
    };
    Operation { name: name.into(), finish, rough: Some(settings) }
}

fn job(operations: Vec<Operation>, h: f64) -> Job {
    let stock = Aabb3 { min: Point3::new(-14.0, -12.0, -1.0), max: Point3::new(14.0, 12.0, h + 1.0) };
    Job { stock: Some(StockShape::Box(stock)), operations }
}

/// What a stock holds above the part grown by the allowance `s` (sideways
/// and up), more than `tol` thick: the cells `(x, y, excess)`, the part
/// grown by `s + slack` sideways (the cells' and the planner's margins).
fn above_allowance(out: &JobOutput, boxes: &[Boxed], s: f64, slack: f64, tol: f64) -> Vec<(f64, f64, f64)> {
    let z = &out.simulation.zmap;
    let mut cells = Vec::new();
    for j in 0..z.ny() {
        for i in 0..z.nx() {
            let c = z.cell_center(i, j);
            let floor = top_within(boxes, [c.x, c.y], s + slack) + s;
            let h = z.height(i, j).unwrap();
            if h > floor + tol {
                cells.push((c.x, c.y, h - floor));
            }
        }
    }
    cells
}

/// The cells of `left` that a flat end mill of radius `r` with allowance `s`
/// could take lower than the part grown by `s + slack` plus `tol`: material
/// left where the tool reaches.
fn reachable(left: &[(f64, f64, f64)], boxes: &[Boxed], r: f64, s: f64, slack: f64, tol: f64) -> Vec<(f64, f64, f64)> {
    left.iter()
        .copied()
        .filter(|&(x, y, _)| {
            let floor = top_within(boxes, [x, y], s + slack) + s;
            // The centres within r - slack: a cell's width and the planner's margin.
            reach(boxes, [x, y], r - slack, s, s, 0.1) <= floor + tol
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3))]

    /// A 12 mm end mill roughs a U channel, a 4 mm one rest-roughs it: the
    /// stock left holds material above the allowance only where the 4 mm
    /// tool cannot reach (checked by `reach` above, not by the planner's
    /// regions); the 12 mm tool alone leaves material there that the 4 mm
    /// tool reaches (the corners' steps: the check can fail), and the rest
    /// pass leaves less of it.
    #[test]
    fn rest_roughing_leaves_material_only_where_the_small_tool_cannot_reach(
        w in 12.5..17.0_f64, t in 2.5..4.0_f64, h in 4.0..8.0_f64, s in 0.1..0.4_f64,
    ) {
        let boxes = u_part(w, t, h);
        let (big, small) = (6.0, 2.0);
        let first = run_job(&job(vec![operation("rough", &boxes, big, s)], h)).unwrap();
        let both = run_job(&job(vec![operation("rough", &boxes, big, s), operation("rest", &boxes, small, s)], h)).unwrap();
        // Slack: a cell's diagonal (0.28 mm) and the rest planner's margin
        // (a cell's diagonal plus the minimum chip, docs/roughing.md);
        // tolerance: the minimum chip and the simulation's rounding.
        let (slack, tol) = (0.6, 0.1);
        let left_first = above_allowance(&first, &boxes, s, slack, tol);
        let left_both = above_allowance(&both, &boxes, s, slack, tol);
        let missed = reachable(&left_both, &boxes, small, s, slack, tol);
        prop_assert!(missed.is_empty(), "{} cells left where the 4 mm tool reaches, e.g. {:?}", missed.len(), &missed[..missed.len().min(5)]);
        let steps = reachable(&left_first, &boxes, small, s, slack, tol);
        prop_assert!(steps.len() > 20, "the 12 mm tool left only {} cells the 4 mm one reaches", steps.len());
        let volume = |cells: &[(f64, f64, f64)]| cells.iter().map(|c| c.2).sum::<f64>() * 0.04;
        prop_assert!(volume(&left_both) < 0.5 * volume(&left_first), "{} mm3 after rest, {} mm3 before", volume(&left_both), volume(&left_first));
        // The engine's own report of what each roughing left (docs/roughing.md,
        // "Material left above the allowance"): the 12 mm tool leaves material it
        // cannot reach, the rest pass takes most of it, and on a part of boxes
        // (no slopes, so no steps) nothing thicker than a chip is left where
        // the 4 mm tool reaches.
        let l0 = first.report.operations[0].left.as_ref().unwrap();
        let l1 = both.report.operations[1].left.as_ref().unwrap();
        prop_assert!(l0.unreachable_volume_mm3 > 0.0 && !l0.places.is_empty(), "{l0:?}");
        prop_assert!(l1.unreachable_volume_mm3 < 0.5 * l0.unreachable_volume_mm3, "{l0:?} {l1:?}");
        prop_assert!(l1.reached_max_mm < 0.2, "{l1:?}");
        // Each of the two corners is worked by the rest pass.
        for x in [-0.5 * w, 0.5 * w] {
            let corner = |cells: &[(f64, f64, f64)]| cells.iter().filter(|c| (c.0 - x).abs() < 6.0 && (c.1 + 10.0 - t).abs() < 6.0).count();
            prop_assert!(corner(&left_both) < corner(&left_first), "corner at x = {x}: {} cells, {} before", corner(&left_both), corner(&left_first));
        }
    }
}

/// A job of roughing and rest roughing gives the same program, toolpaths and
/// final stock on one and on two threads.
#[test]
fn rough_and_rest_are_the_same_on_one_and_two_threads() {
    let boxes = u_part(14.0, 3.0, 6.0);
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            run_job(&job(vec![operation("rough", &boxes, 6.0, 0.3), operation("rest", &boxes, 2.0, 0.3)], 6.0)).unwrap()
        })
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.toolpaths, b.toolpaths);
    assert_eq!(a.gcode, b.gcode);
    assert_eq!(a.simulation.zmap.heights(), b.simulation.zmap.heights());
    for (x, y) in a.report.operations.iter().zip(&b.report.operations) {
        assert_eq!(x.stock.removed_mm3.to_bits(), y.stock.removed_mm3.to_bits());
        let (ex, ey) = (x.engagement.as_ref().unwrap(), y.engagement.as_ref().unwrap());
        assert_eq!((ex.max_deg.to_bits(), ex.p95_deg.to_bits()), (ey.max_deg.to_bits(), ey.p95_deg.to_bits()));
    }
    assert!(a.report.operations[1].stock.removed_mm3 > 0.0);
}
