//! The stock simulation's acceptance on the finishing issue's test parts
//! (issue 6): the Choi (bull-nose) and Rubio (ball) finishing programs
//! simulate at a 0.05 mm grid with no gouge and a scallop (material thickness
//! along the part normal, beyond the cutter radius from the part's edge) of at
//! most sh plus the simulator's resolution bound; the Choi program with a
//! run of moves lowered by 0.05 mm is reported as gouges cut by those moves.

#![allow(clippy::unwrap_used, reason = "tests fail loudly by design")]

use scallop_cutter::{Cutter, CutterShape};
use scallop_engine::{FinishJob, Part, prepare_part, run_finishing};
use scallop_geom::{Aabb3, Point3};
use scallop_sim::{SimError, VerifyOptions, simulate};
use scallop_toolpath::{Move, MoveKind, Toolpath};

const GRID: f64 = 0.05;

fn check(job: &FinishJob) -> Toolpath {
    let out = run_finishing(job).unwrap();
    let r = &out.report;
    assert!(r.sim_resolution_bound_mm > 0.0 && r.sim_resolution_bound_mm < 1e-3, "{r:?}");
    assert!(r.sim_max_scallop_mm <= r.scallop_height_mm + r.sim_resolution_bound_mm, "{r:?}");
    // The passes really hold the scallop: not a stock left untouched.
    assert!(r.sim_max_scallop_mm > 0.5 * r.scallop_height_mm, "{r:?}");
    assert!(r.sim_min_deviation_mm >= -r.sim_gouge_tolerance_mm, "{r:?}");
    out.toolpath
}

#[test]
fn choi_program_holds_the_scallop_and_a_lowered_run_gouges() {
    let job = FinishJob { sim_resolution: GRID, ..FinishJob::choi_demo() };
    let path = check(&job);

    // Lower a run of feed moves in the middle of the program by 0.05 mm.
    let n = path.moves().len();
    let run = n / 2..n / 2 + 40;
    let mut lowered = Toolpath::new(path.feed);
    for (k, m) in path.moves().iter().enumerate() {
        let mut m: Move = *m;
        if run.contains(&k) && m.kind == MoveKind::Feed {
            m.to.z -= 0.05;
        }
        lowered.push(m);
    }
    let prepared = prepare_part(&job.part, &job.tolerances).unwrap();
    let b = prepared.mesh.bounds();
    let radius = job.cutter.radius();
    let stock = Aabb3 {
        min: Point3::new(b.min.x - radius, b.min.y - radius, b.min.z - 1.0),
        max: Point3::new(b.max.x + radius, b.max.y + radius, b.max.z + 1.0),
    };
    let tolerance = job.tolerances.gouge + prepared.chordal_error + job.tolerances.path;
    let options = VerifyOptions { gouge_tolerance: tolerance, worst_reported: 10_000, scallop_margin: radius };
    match simulate(stock, GRID, &job.cutter, &lowered, &prepared.index, &options) {
        Err(SimError::Gouge { count, worst, .. }) => {
            assert!(count > 100, "{count}");
            assert!(worst[0].depth > 0.04 && worst[0].depth <= 0.05 + tolerance, "{:?}", worst[0]);
            for g in &worst {
                let index = g.cut_by.unwrap().index as usize;
                // Cut by a lowered move, or by the first move after the run
                // (it starts at the last lowered point).
                assert!(run.start <= index && index <= run.end, "{g:?} outside {run:?}");
            }
        }
        other => panic!("expected gouges, got {other:?}"),
    }
}

#[test]
fn rubio_program_holds_the_scallop() {
    // A ball along the principal direction (what the analysis recommends for
    // Rubio), with flutes longer than the part's height range: the finishing
    // check runs on an unroughed stock box, which the shank must clear.
    let job = FinishJob {
        part: Part::builtin("rubio").unwrap(),
        part_name: "built-in rubio surface".into(),
        cutter: Cutter::new(CutterShape::Ball { radius: 5.0 }, 80.0).unwrap(),
        sim_resolution: GRID,
        ..FinishJob::choi_demo()
    };
    check(&job);
}
