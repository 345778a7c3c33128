//! A roughing operation in a job: planned from the stock, cut on the one
//! stock and proven (a gouge or a rapid into stock fails `run_job`), the
//! allowance left, G2/G3 in the program, and a finishing operation after it
//! working on what the roughing left.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use scallop_cutter::{Cutter, CutterShape};
use scallop_engine::{FinishJob, Job, Operation, Part, StockShape, run_job};
use scallop_geom::{Aabb3, Point3};
use scallop_mesh::TriMesh;
use scallop_rough::{Direction, Pattern, RoughSettings};

mod common;
use common::boxes_mesh;

/// A block `[-6, 6] x [-5, 5] x [0, 6]` with a step on half of it up to 8,
/// on a plate at z = 0 that spans the stock.
fn part() -> TriMesh {
    boxes_mesh(&[
        ([-15.0, -15.0, -0.5], [15.0, 15.0, 0.0]),
        ([-6.0, -5.0, 0.0], [6.0, 5.0, 6.0]),
        ([-6.0, -5.0, 6.0], [6.0, 0.0, 8.0]),
    ])
}

fn rough_job(allowance: f64) -> Job {
    let mut finish = FinishJob::choi_demo();
    finish.part = Part::Mesh(part());
    finish.part_name = "stepped block".into();
    finish.cutter = Cutter::new(CutterShape::Flat { radius: 3.0 }, 30.0).unwrap();
    finish.sim_resolution = 0.2;
    let settings = RoughSettings {
        stepdown: 2.0,
        stepover: 0.2,
        radial_allowance: allowance,
        axial_allowance: allowance,
        pattern: Pattern::Offset,
        direction: Direction::Climb,
    };
    let stock = Aabb3 { min: Point3::new(-12.0, -11.0, -1.0), max: Point3::new(12.0, 11.0, 10.0) };
    Job {
        stock: Some(StockShape::Box(stock)),
        operations: vec![Operation { name: "rough".into(), finish, rough: Some(settings) }],
    }
}

/// The roughing removes the stock down to the part plus the allowance: no
/// gouge (run_job proves it), the deepest material left near the allowance
/// on the part's floors, and arcs written as G2/G3.
#[test]
fn roughing_leaves_the_allowance() {
    let allowance = 0.3;
    let out = run_job(&rough_job(allowance)).unwrap();
    let r = &out.report;
    let op = &r.operations[0];
    assert!(op.stock.removed_mm3 > 0.5 * op.stock.volume_before_mm3, "{:?}", op.stock);
    assert!(op.plan.passes > 0 && op.plan.planes >= 6, "{:?}", op.plan);
    // Nothing deeper than the allowance into it, beyond the path tolerance and the grid.
    assert!(r.sim_min_deviation_mm > allowance - 0.02, "{}", r.sim_min_deviation_mm);
    assert!(out.gcode.contains("G2") || out.gcode.contains("G3"), "no arcs");
    // Two floors (the step's top and the block's top outside it) and the plate get levels.
    assert!(op.plan.planes >= 7, "{:?}", op.plan);
}

/// A finishing operation after the roughing (the Choi surface, as
/// `examples/jobs/choi-rough.toml`) starts from the roughed stock: it removes
/// a small share of what the roughing removed, and the final stock holds
/// the finishing scallop.
#[test]
fn finishing_after_roughing() {
    let mut rough = FinishJob::choi_demo();
    rough.cutter = Cutter::new(CutterShape::Flat { radius: 3.0 }, 40.0).unwrap();
    let mut finish = FinishJob::choi_demo();
    finish.scallop_height = 0.05;
    finish.cutter = Cutter::new(CutterShape::Bull { radius: 5.0, corner: 2.0 }, 40.0).unwrap();
    let settings = RoughSettings {
        stepdown: 3.0,
        stepover: 0.3,
        radial_allowance: 0.5,
        axial_allowance: 0.5,
        pattern: Pattern::Offset,
        direction: Direction::Climb,
    };
    let job = Job {
        stock: Some(StockShape::AroundPart { margin: Some(5.0), top: 4.0, bottom: 1.0 }),
        operations: vec![
            Operation { name: "rough".into(), finish: rough, rough: Some(settings) },
            Operation { name: "finish".into(), finish, rough: None },
        ],
    };
    let out = run_job(&job).unwrap();
    let [a, b] = [&out.report.operations[0], &out.report.operations[1]];
    assert!(a.engagement.is_some() && b.engagement.is_none());
    assert!(b.stock.removed_mm3 < 0.2 * a.stock.removed_mm3, "{a:?} {b:?}");
    let r = &out.report;
    assert!(r.sim_max_scallop_mm <= 0.05 + r.sim_resolution_bound_mm, "{r:?}");
    assert!(out.gcode.contains("T2 M6"));
}

/// An L of two walls 8 mm high on a plate: the inside corner at
/// `(-6, -6)` keeps a fillet of the roughing tool's radius.
fn l_part() -> TriMesh {
    boxes_mesh(&[
        ([-15.0, -15.0, -0.5], [15.0, 15.0, 0.0]),
        ([-10.0, -10.0, 0.0], [10.0, -6.0, 8.0]),
        ([-10.0, -6.0, 0.0], [-6.0, 10.0, 8.0]),
    ])
}

/// An operation roughing the L part with a flat end mill of `radius`.
fn l_operation(name: &str, radius: f64) -> Operation {
    let mut finish = FinishJob::choi_demo();
    finish.part = Part::Mesh(l_part());
    finish.part_name = "L walls".into();
    finish.cutter = Cutter::new(CutterShape::Flat { radius }, 30.0).unwrap();
    finish.sim_resolution = 0.2;
    let settings = RoughSettings {
        stepdown: 2.0,
        stepover: 0.3,
        radial_allowance: 0.2,
        axial_allowance: 0.2,
        pattern: Pattern::Offset,
        direction: Direction::Climb,
    };
    Operation { name: name.into(), finish, rough: Some(settings) }
}

fn l_job(operations: Vec<Operation>) -> Job {
    let stock = Aabb3 { min: Point3::new(-12.0, -12.0, -1.0), max: Point3::new(12.0, 12.0, 9.0) };
    Job { stock: Some(StockShape::Box(stock)), operations }
}

/// Rest roughing: a 4 mm tool after a 12 mm one machines only what the large
/// one left (the inside corner's fillet), in a fraction of the feed length
/// the 4 mm tool needs from the box, and leaves no more material than that
/// 4 mm roughing alone (within the simulation's cells along the walls).
#[test]
fn rest_roughing_machines_only_what_the_larger_tool_left() {
    let both = run_job(&l_job(vec![l_operation("rough", 6.0), l_operation("rest", 2.0)])).unwrap();
    let alone = run_job(&l_job(vec![l_operation("rough small", 2.0)])).unwrap();
    let [big, rest] = [&both.report.operations[0], &both.report.operations[1]];
    let small = &alone.report.operations[0];
    // The corner fillet of radius 6 less the one of radius 2, 8 mm high: about 55 mm^3.
    assert!(rest.stock.removed_mm3 > 20.0, "{:?}", rest.stock);
    assert!(rest.stock.removed_mm3 < 0.1 * big.stock.removed_mm3, "{:?} {:?}", big.stock, rest.stock);
    assert!(rest.plan.feed_length_mm < 0.5 * small.plan.feed_length_mm, "{:?} {:?}", rest.plan, small.plan);
    let left_both = both.simulation.zmap.volume();
    let left_alone = alone.simulation.zmap.volume();
    assert!(
        left_both <= left_alone + 5.0,
        "left {left_both} mm^3 after rest, {left_alone} mm^3 by the small tool alone"
    );
}

/// A roughing operation reports the engagement the simulator read on the
/// stock it received: its target from the stepover (0.2 D: 53.13 degrees),
/// one figure per move of its toolpath (rapids and retracts cut nothing),
/// the offset pattern's passes at the target (the median within the
/// stock's reading, docs/simulation.md), and no slot: the levels are open on
/// the stock's sides and cut from the air inwards (docs/roughing.md, "Open
/// sides"; a finishing operation reports none: `finishing_after_roughing`).
/// The entries: one after each retract, and one at each descent reached by a
/// tool-down link.
#[test]
fn a_roughing_operation_reports_its_simulated_engagement() {
    let out = run_job(&rough_job(0.3)).unwrap();
    let e = out.report.operations[0].engagement.as_ref().unwrap();
    assert!((e.target_deg - 53.13).abs() < 0.01, "{}", e.target_deg);
    let path = &out.toolpaths[0];
    assert_eq!(e.move_deg.len(), path.moves().len());
    for (m, d) in path.moves().iter().zip(&e.move_deg) {
        if matches!(m.kind, scallop_toolpath::MoveKind::Rapid | scallop_toolpath::MoveKind::Retract) {
            assert_eq!(*d, 0.0);
        }
    }
    assert!(e.p50_deg <= e.p95_deg && e.p95_deg <= e.max_deg && e.max_deg <= 180.0, "{e:?}");
    assert!((e.p50_deg - e.target_deg).abs() < 6.0, "{e:?}");
    assert!(e.cutting_length_mm > 0.0 && e.slot_length_mm == 0.0, "{e:?}");
    // Each retract is followed by an entry; a descent after a tool-down link
    // (to the next level) is one too.
    let links = out.report.operations[0].plan.links;
    assert!(e.entries > 0 && e.entries >= e.retracts && e.entries <= e.retracts + links, "{e:?} {links}");
}

/// A wedge on a plate: a slope rising from z = 0 at x = -10 to z = 8 at
/// x = 0 (38.7 degrees), a flat top to x = 10, 12 mm wide.
fn wedge_part() -> TriMesh {
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    let plate = boxes_mesh(&[([-16.0, -12.0, -1.0], [16.0, 12.0, 0.0])]);
    let mut soup: Vec<[Point3; 3]> = (0..plate.triangles().len()).map(|i| plate.triangle(i)).collect();
    let (a, b, c, d) = (p(-10.0, -6.0, 0.0), p(10.0, -6.0, 0.0), p(10.0, 6.0, 0.0), p(-10.0, 6.0, 0.0));
    let (e, f, g, h) = (p(0.0, -6.0, 8.0), p(10.0, -6.0, 8.0), p(10.0, 6.0, 8.0), p(0.0, 6.0, 8.0));
    for [q0, q1, q2, q3] in [[a, d, c, b], [a, e, h, d], [e, f, g, h], [b, c, g, f]] {
        soup.push([q0, q1, q2]);
        soup.push([q0, q2, q3]);
    }
    soup.extend([[a, b, f], [a, f, e], [d, h, g], [d, g, c]]);
    TriMesh::from_soup(&soup).unwrap().0
}

/// An adaptive roughing operation on the wedge with a flat end mill of
/// `radius` at `stepdown` (0.25 D, 0.3 mm left).
fn wedge_operation(name: &str, radius: f64, stepdown: f64) -> Operation {
    let mut finish = FinishJob::choi_demo();
    finish.part = Part::Mesh(wedge_part());
    finish.part_name = "wedge".into();
    finish.cutter = Cutter::new(CutterShape::Flat { radius }, 30.0).unwrap();
    finish.sim_resolution = 0.2;
    let settings = RoughSettings {
        stepdown,
        stepover: 0.25,
        radial_allowance: 0.3,
        axial_allowance: 0.3,
        pattern: Pattern::Adaptive,
        direction: Direction::Climb,
    };
    Operation { name: name.into(), finish, rough: Some(settings) }
}

/// Adaptive rest roughing along a slope: a 6 mm end mill at 2 mm levels
/// leaves steps on the wedge's slope, which a 3 mm one takes at 0.5 mm
/// levels, its passes and rings sliding along the wall where the steps
/// are. The cells along the wall that hold more than the allowance but lie
/// in the margin `removable_material` leaves out are material the tool
/// meets: the walk counts them in its engagement (docs/roughing.md,
/// "Adaptive clearing", rest roughing), and the simulator reads the rest
/// operation within 1.1 x the target, with nothing over 1.2 x. Without them
/// the passes along the wall read 82.5 degrees for 60 (25.9 mm over 1.2 x).
#[test]
fn adaptive_rest_along_a_slope_holds_the_engagement() {
    let stock = Aabb3 { min: Point3::new(-20.0, -16.0, -1.0), max: Point3::new(20.0, 16.0, 11.0) };
    let job = Job {
        stock: Some(StockShape::Box(stock)),
        operations: vec![wedge_operation("rough", 3.0, 2.0), wedge_operation("rest", 1.5, 0.5)],
    };
    let out = run_job(&job).unwrap();
    let rest = out.report.operations[1].engagement.as_ref().unwrap();
    assert!(rest.cutting_length_mm > 100.0, "{rest:?}");
    assert!(rest.max_deg <= 1.1 * rest.target_deg, "{rest:?}");
    assert!(rest.over_length_mm < 1e-9 && rest.slot_length_mm < 1e-9, "{rest:?}");
}

/// The L walls standing alone, no plate: the inside corner at `(-6, -6)` is
/// a corner of the part's outline, with no part under the fillet the
/// roughing tool leaves in it.
fn l_alone() -> TriMesh {
    boxes_mesh(&[([-10.0, -10.0, 0.0], [10.0, -6.0, 8.0]), ([-10.0, -6.0, 0.0], [-6.0, 10.0, 8.0])])
}

/// The material left off the part's outline is measured down to the lowest
/// level (docs/roughing.md, "Material left above the allowance"): the
/// fillet a 6 mm end mill leaves in the outline's inside corner is reported
/// unreachable, at the corner, the fillet's volume beyond the band along the
/// walls that is not measured off the outline, and nothing else
/// off the outline is (the stock beside it is cut to the lowest level); a
/// 2 mm end mill's rest pass takes most of it and reports what it could not.
/// Before, cells with no part under their centre were not measured and both
/// operations read 0 mm^3.
#[test]
fn material_left_in_an_inside_corner_of_the_outline_is_reported() {
    const CELL: f64 = 0.1;
    let op = |name: &str, radius: f64| {
        let mut o = l_operation(name, radius);
        o.finish.part = Part::Mesh(l_alone());
        o.finish.sim_resolution = CELL;
        o
    };
    let stock = Aabb3 { min: Point3::new(-12.0, -12.0, 0.0), max: Point3::new(12.0, 12.0, 9.0) };
    let job = Job { stock: Some(StockShape::Box(stock)), operations: vec![op("rough", 3.0), op("rest", 1.0)] };
    let out = run_job(&job).unwrap();
    let [big, rest] = [&out.report.operations[0], &out.report.operations[1]];
    let (l0, l1) = (big.left.as_ref().unwrap(), rest.left.as_ref().unwrap());
    // The fillet the tool's disc (R = 3, its centre kept R + a = 3.2 from both
    // walls) leaves in the corner, less the band of a + 2 diagonals along the
    // walls that is not measured off the outline, from the lowest level (0.2)
    // to the walls' top level (8.2): integrated on a fine grid.
    let (r, band, n) = (3.0f64, 0.2 + 2.0 * CELL * std::f64::consts::SQRT_2, 800);
    let h = 3.2 / f64::from(n);
    let mut area = 0.0;
    for i in 0..n {
        for j in 0..n {
            let (x, y) = ((f64::from(i) + 0.5) * h, (f64::from(j) + 0.5) * h);
            if x > band && y > band && (x - 3.2).hypot(y - 3.2) > r {
                area += h * h;
            }
        }
    }
    let fillet = area * 8.0;
    // Within the cells along its edges (about 5 mm of edge, cells of 0.1 mm:
    // 0.5 mm^2 of 1 mm^2 on either side).
    assert!(
        l0.unreachable_volume_mm3 > 0.5 * fillet && l0.unreachable_volume_mm3 < 1.5 * fillet,
        "{l0:?}, fillet {fillet} mm^3"
    );
    assert!(l0.volume_mm3 < l0.unreachable_volume_mm3 + 1.0, "{l0:?}");
    let at = l0.places[0].at;
    assert!((at[0] + 6.0).hypot(at[1] + 6.0) < 3.2, "{l0:?}");
    assert!(l1.unreachable_volume_mm3 < 0.3 * l0.unreachable_volume_mm3, "{l0:?} {l1:?}");
    assert!(rest.stock.removed_mm3 > 0.5 * l0.unreachable_volume_mm3, "{:?}", rest.stock);
}

/// A frustum on a plate: a 20 x 16 mm base at z = 0 rising to a 8 x 4 mm top
/// at z = 8, its four sides sloping at 53 to 56 degrees.
fn frustum_part() -> TriMesh {
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    let plate = boxes_mesh(&[([-16.0, -12.0, -1.0], [16.0, 12.0, 0.0])]);
    let mut soup: Vec<[Point3; 3]> = (0..plate.triangles().len()).map(|i| plate.triangle(i)).collect();
    let (a, b, c, d) = (p(-10.0, -8.0, 0.0), p(10.0, -8.0, 0.0), p(10.0, 8.0, 0.0), p(-10.0, 8.0, 0.0));
    let (e, f, g, h) = (p(-4.0, -2.0, 8.0), p(4.0, -2.0, 8.0), p(4.0, 2.0, 8.0), p(-4.0, 2.0, 8.0));
    for [q0, q1, q2, q3] in [[a, d, c, b], [e, f, g, h], [a, b, f, e], [b, c, g, f], [c, d, h, g], [d, a, e, h]] {
        soup.push([q0, q1, q2]);
        soup.push([q0, q2, q3]);
    }
    TriMesh::from_soup(&soup).unwrap().0
}

/// Adaptive rest roughing of the steps a larger tool leaves on slopes all
/// round a part (docs/roughing.md, "Adaptive rest roughing: only the
/// stretches that meet material"): a 6 mm end mill at 2 mm levels, then a
/// 3 mm one at 0.5 mm. The rest levels' regions are bands along the walls;
/// their rings and corner arcs are cut only where the tool meets material,
/// not all round through the air. No gouge (run_job proves it), the
/// engagement within 1.1 x the target, no slot, no more material left.
#[test]
fn adaptive_rest_on_slopes_cuts_no_ring_in_the_air() {
    let stock = Aabb3 { min: Point3::new(-20.0, -16.0, -1.0), max: Point3::new(20.0, 16.0, 11.0) };
    let op = |name: &str, radius: f64, stepdown: f64| {
        let mut o = wedge_operation(name, radius, stepdown);
        o.finish.part = Part::Mesh(frustum_part());
        o.finish.part_name = "frustum".into();
        o
    };
    let job =
        Job { stock: Some(StockShape::Box(stock)), operations: vec![op("rough", 3.0, 2.0), op("rest", 1.5, 0.5)] };
    let out = run_job(&job).unwrap();
    let rest = &out.report.operations[1];
    let e = rest.engagement.as_ref().unwrap();
    // With every ring and corner arc cut whole: 62 % of the length at depth
    // in links, 119.6 s; with the stretches only 37 %, 100.3 s, the same
    // material left (0.633 mm reached, 45.86 mm3). Since the links turn on
    // the smallest arc that fits (docs/roughing.md, "Adaptive clearing",
    // step 7): 46 %, 85.9 s, 65 retracts for 81 (links found where there
    // were retracts).
    assert!(e.link_share < 0.5, "{e:?}");
    assert!(rest.plan.total_time_s < 110.0, "{:?}", rest.plan);
    assert!(e.max_deg <= 1.1 * e.target_deg && e.slot_length_mm < 1e-9, "{e:?}");
    let left = rest.left.as_ref().unwrap();
    assert!(left.reached_max_mm < 0.64 && left.volume_mm3 < 46.0, "{left:?}");
    assert!(rest.stock.removed_mm3 > 180.0, "{:?}", rest.stock);
}

/// A block 40 x 32 mm, 11 mm high, with a conical pit in its top (12 mm
/// radius at the top, walls at 40 degrees, 8 mm deep at most), as a height
/// field on a 1 mm grid closed by its sides and a bottom fan.
fn pit_part() -> TriMesh {
    let (nx, ny) = (41usize, 33usize);
    let z = |x: f64, y: f64| 10.0 - ((12.0 - x.hypot(y)) * 40f64.to_radians().tan()).clamp(0.0, 8.0);
    #[allow(clippy::cast_precision_loss)]
    let at = |i: usize, j: usize| {
        let (x, y) = (-20.0 + i as f64, -16.0 + j as f64);
        Point3::new(x, y, z(x, y))
    };
    let mut soup: Vec<[Point3; 3]> = Vec::new();
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            soup.push([a, b, c]);
            soup.push([a, c, d]);
        }
    }
    // The boundary loop counter-clockwise seen from above.
    let mut ring: Vec<(usize, usize)> = (0..nx - 1).map(|i| (i, 0)).collect();
    ring.extend((0..ny - 1).map(|j| (nx - 1, j)));
    ring.extend((1..nx).rev().map(|i| (i, ny - 1)));
    ring.extend((1..ny).rev().map(|j| (0, j)));
    let base = Point3::new(0.0, 0.0, -1.0);
    for k in 0..ring.len() {
        let (p, q) = (at(ring[k].0, ring[k].1), at(ring[(k + 1) % ring.len()].0, ring[(k + 1) % ring.len()].1));
        let (pb, qb) = (Point3::new(p.x, p.y, -1.0), Point3::new(q.x, q.y, -1.0));
        soup.push([p, pb, qb]);
        soup.push([p, qb, q]);
        soup.push([pb, base, qb]);
    }
    TriMesh::from_soup(&soup).unwrap().0
}

/// Adaptive rest roughing: links between the pieces of a rest level go
/// through the level's whole tool-centre region (cleared by the operation
/// before, where the material to remove is not), tool down, and the parts
/// of the rest region the walk cannot reach are entered from the air next
/// to them, not by a retract and a helix (docs/roughing.md, "Adaptive rest
/// roughing: links through the level's room"). A block with a conical pit
/// roughed by a 6 mm end mill at 2 mm levels, then rest-roughed by a 3 mm
/// one at 0.5 mm: the rest levels are bands along the pit's wall, and the
/// rest operation's retracts and time fall; the engagement stays within
/// 1.1 x the target with no slot, the material left is the same, no gouge
/// (run_job proves it).
#[test]
fn adaptive_rest_links_run_through_the_level_not_over_it() {
    let stock = Aabb3 { min: Point3::new(-20.0, -16.0, -1.0), max: Point3::new(20.0, 16.0, 12.0) };
    let op = |name: &str, radius: f64, stepdown: f64| {
        let mut o = wedge_operation(name, radius, stepdown);
        o.finish.part = Part::Mesh(pit_part());
        o.finish.part_name = "pit".into();
        o
    };
    let job =
        Job { stock: Some(StockShape::Box(stock)), operations: vec![op("rough", 3.0, 2.0), op("rest", 1.5, 0.5)] };
    let out = run_job(&job).unwrap();
    let rest = &out.report.operations[1];
    let e = rest.engagement.as_ref().unwrap();
    let left = rest.left.as_ref().unwrap();
    // Links only in the rest level's region: 17 retracts, 44.6 s; through
    // the level's room: 11, 40.6 s; the engagement (61 degrees at most for
    // 60) and the material left (0.426 mm reached, 43.42 mm3) the same.
    assert!(rest.plan.retracts <= 12, "{:?}", rest.plan);
    assert!(rest.plan.total_time_s < 42.5, "{:?}", rest.plan);
    assert!(e.max_deg <= 1.1 * e.target_deg && e.slot_length_mm < 1e-9, "{e:?}");
    assert!(left.reached_max_mm < 0.43 && left.volume_mm3 < 43.5, "{left:?}");
    assert!(rest.stock.removed_mm3 > 50.0, "{:?}", rest.stock);
}
