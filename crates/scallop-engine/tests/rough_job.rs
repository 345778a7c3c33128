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

/// A block `[-6, 6] x [-5, 5] x [0, 6]` with a step on half of it up to 8,
/// on a plate at z = 0 that spans the stock.
fn part() -> TriMesh {
    let p = |x, y, z| Point3::new(x, y, z);
    let mut soup = Vec::new();
    let mut quad = |a: Point3, b: Point3, c: Point3, d: Point3| {
        soup.push([a, b, c]);
        soup.push([a, c, d]);
    };
    quad(p(-15.0, -15.0, 0.0), p(15.0, -15.0, 0.0), p(15.0, 15.0, 0.0), p(-15.0, 15.0, 0.0));
    let mut block = |x0: f64, x1: f64, y0: f64, y1: f64, z0: f64, z1: f64| {
        quad(p(x0, y0, z1), p(x1, y0, z1), p(x1, y1, z1), p(x0, y1, z1));
        quad(p(x0, y0, z0), p(x1, y0, z0), p(x1, y0, z1), p(x0, y0, z1));
        quad(p(x1, y0, z0), p(x1, y1, z0), p(x1, y1, z1), p(x1, y0, z1));
        quad(p(x1, y1, z0), p(x0, y1, z0), p(x0, y1, z1), p(x1, y1, z1));
        quad(p(x0, y1, z0), p(x0, y0, z0), p(x0, y0, z1), p(x0, y1, z1));
    };
    block(-6.0, 6.0, -5.0, 5.0, 0.0, 6.0);
    block(-6.0, 6.0, -5.0, 0.0, 6.0, 8.0);
    TriMesh::from_soup(&soup).unwrap().0
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
    // Material left above the floors and walls stays near the allowance where
    // the flat tool reaches (away from the part's edges the tool cannot reach).
    assert!(r.sim_max_scallop_mm < allowance + 3.5, "{}", r.sim_max_scallop_mm);
}

/// A finishing operation after the roughing starts from the roughed stock.
#[test]
fn finishing_after_roughing() {
    let mut job = rough_job(0.3);
    let mut finish = job.operations[0].finish.clone();
    finish.cutter = Cutter::new(CutterShape::Ball { radius: 2.0 }, 30.0).unwrap();
    finish.scallop_height = 0.05;
    job.operations.push(Operation { name: "finish".into(), finish, rough: None });
    let out = run_job(&job).unwrap();
    let [a, b] = [&out.report.operations[0], &out.report.operations[1]];
    assert!(b.stock.removed_mm3 < 0.2 * a.stock.removed_mm3, "{a:?} {b:?}");
    assert!(out.gcode.contains("T2 M6"));
}
