//! 3+2 (issue 3): a part turned by the inverse of the setup rotation plans exactly like
//! the untouched part, and the indexed program replays through the machine's forward
//! kinematics onto the part-frame CL path.

use scallop_engine::{FinishJob, FinishOutput, Part, Setup, prepare_part, run_finishing};
use scallop_geom::nalgebra::{Matrix3, Rotation3};
use scallop_geom::{Point3, Vec3};
use scallop_machine::program::{ProgramOptions, records_from_toolpath};
use scallop_machine::{Kinematics, Machine};
use scallop_mesh::TriMesh;
use scallop_post::{check_replay, replay};
use scallop_toolpath::{Move, Toolpath};

fn turned(mesh: &TriMesh, r: &Rotation3<f64>) -> TriMesh {
    let v: Vec<Point3> = mesh.vertices().iter().map(|p| r * p).collect();
    let t: Vec<[usize; 3]> = mesh.triangles().iter().map(|t| t.map(|i| i as usize)).collect();
    TriMesh::from_indexed(&v, &t).expect("a rigid motion keeps the mesh valid").0
}

fn job(mesh: TriMesh) -> FinishJob {
    let mut job = FinishJob::choi_demo();
    job.part = Part::Mesh(mesh);
    job.direction_deg = Some(30.0);
    job.cutter = scallop_cutter::Cutter::new(scallop_cutter::CutterShape::Bull { radius: 5.0, corner: 2.0 }, 80.0)
        .expect("valid");
    job
}

fn choi_mesh() -> TriMesh {
    let base = FinishJob::choi_demo();
    prepare_part(&base.part, &base.tolerances).expect("tessellates").mesh
}

/// Plans the untouched mesh and the mesh turned by `rotation^-1` with the setup `rotation`.
fn plan_both(rotation: Rotation3<f64>) -> (FinishOutput, FinishOutput, FinishJob) {
    let mesh = choi_mesh();
    let plain = job(mesh.clone());
    let mut tilted = job(turned(&mesh, &rotation.inverse()));
    let machine = Machine::builtin("linuxcnc-xyzac-trt").expect("shipped");
    tilted.setup = Some(Setup { rotation, machine, tool_length: 0.0 });
    (run_finishing(&plain).expect("plans"), run_finishing(&tilted).expect("plans the tilted part"), tilted)
}

#[test]
fn a_part_turned_by_the_inverse_quarter_turn_plans_bit_for_bit_like_the_untouched_part() {
    // A quarter turn about Z is exact in floating point: R (R^-1 v) == v, so the two
    // plans must agree exactly; a frame convention error (R instead of R^-1) would turn
    // the part by a half turn against the 30-degree feed and change everything.
    let quarter = Rotation3::from_matrix_unchecked(Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0));
    let (a, b, tilted) = plan_both(quarter);
    assert_eq!(a.toolpath, b.toolpath);
    assert!(b.gcode.contains(" C"), "the C table turns");
    check_indexed(&b, &tilted);
}

#[test]
fn a_part_tilted_by_the_inverse_setup_plans_like_the_untilted_part() {
    let rotation = Rotation3::from_euler_angles(12f64.to_radians(), -8f64.to_radians(), 25f64.to_radians());
    let (a, b, tilted) = plan_both(rotation);
    // The turned mesh differs from the original by rounding (1e-14 mm). The planner's
    // accept/retry decisions on measured scallops are not continuous in the input, so
    // the plane offsets may drift by a fraction of a step-over (the quarter-turn test
    // above is the exact check): the same planes and passes, the same guarantee, and
    // the same length within 1 %.
    let (pa, pb) = (&a.report.plan, &b.report.plan);
    assert_eq!((pa.planes, pa.passes, pa.links, pa.retracts), (pb.planes, pb.passes, pb.links, pb.retracts));
    assert!(pa.max_scallop_mm <= 0.01 && pb.max_scallop_mm <= 0.01);
    assert!((pa.feed_length_mm - pb.feed_length_mm).abs() <= 0.01 * pa.feed_length_mm, "{pa:?}\n{pb:?}");
    check_indexed(&b, &tilted);
}

/// The indexed program positions the rotaries once and replays through the machine's
/// forward kinematics onto the part-frame CL path.
fn check_indexed(b: &FinishOutput, tilted: &FinishJob) {
    let setup = tilted.setup.as_ref().expect("3+2");
    assert!(b.gcode.contains(" A") || b.gcode.contains(" C"), "no rotary words");
    let kin = Kinematics::new(&setup.machine, 0.0);
    let back = setup.rotation.inverse();
    let mut part_frame = Toolpath::new(b.toolpath.feed);
    part_frame.plunge_feed = b.toolpath.plunge_feed;
    for m in b.toolpath.moves() {
        part_frame.push(Move::new(m.kind, back * m.to));
    }
    let records = records_from_toolpath(&part_frame, &(back * Vec3::z()));
    let blocks = replay(&b.gcode, &tilted.output.dialect, &kin).expect("reads back");
    let opts = ProgramOptions::default();
    check_replay(&blocks, &records, &kin, &tilted.output.dialect, opts.tol_pos, opts.tol_ang)
        .expect("the indexed program follows the part-frame path");
}
