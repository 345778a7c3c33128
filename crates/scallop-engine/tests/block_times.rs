//! The machine time block by block (`block_times`, `time_breakdown`;
//! docs/rough5.md, "Where the machine time goes"): the blocks' times add up
//! to the program's time, and each block says what sets it.

use scallop_engine::{block_times, on_machine, time_breakdown};
use scallop_geom::{Point3, Vec3};
use scallop_machine::{Kinematics, Machine};
use scallop_toolpath::{Move, MoveKind, Toolpath};

fn tilted(deg: f64) -> Vec3 {
    let t = deg.to_radians();
    Vec3::new(t.sin(), 0.0, t.cos())
}

/// A rapid, a straight feed with the axis +Z, a turn of the axis by 20 deg
/// on the spot, a tilted straight feed and a rapid away: on the UCP 710.
fn program() -> Toolpath {
    let p = Point3::new;
    let mut path = Toolpath::new(2400.0);
    path.push_with_axis(Move::new(MoveKind::Rapid, p(0.0, 0.0, 60.0)), Vec3::z());
    path.push_with_axis(Move::new(MoveKind::Plunge, p(0.0, 0.0, 50.0)), Vec3::z());
    path.push_with_axis(Move::new(MoveKind::Feed, p(50.0, 0.0, 50.0)), Vec3::z());
    path.push_with_axis(Move::new(MoveKind::Feed, p(50.0, 0.0, 50.0)), tilted(20.0));
    path.push_with_axis(Move::new(MoveKind::Feed, p(80.0, 0.0, 50.0)), tilted(20.0));
    path.push_with_axis(Move::new(MoveKind::Rapid, p(80.0, 0.0, 80.0)), tilted(20.0));
    path
}

#[test]
fn the_blocks_add_up_to_the_program_time_and_name_what_sets_them() {
    let kin = Kinematics::new(&Machine::builtin("ucp710").unwrap(), 100.0);
    let path = program();
    let run = on_machine(&kin, &path).unwrap();
    let blocks = block_times(&kin, &run.program).unwrap();
    assert_eq!(blocks.len(), run.program.blocks.len() - 1);
    let total: f64 = blocks.iter().map(|b| b.time_s).sum();
    assert!((total - run.time.total).abs() < 1e-9 * run.time.total.max(1.0), "{total} against {}", run.time.total);
    for b in &blocks {
        // The velocity-limited time is at least the feed's, the block's at least that.
        assert!(b.at_velocity_s >= b.at_feed_s - 1e-12, "{b:?}");
        assert!(b.time_s >= b.at_velocity_s - 1e-9, "{b:?}");
        assert!(b.rotary_only_s > 0.0 && b.linear_only_s > 0.0, "{b:?}");
    }
    // The straight feed with the axis +Z: the feed sets its velocity-limited time.
    let straight: Vec<_> = blocks.iter().filter(|b| b.cl_index == 2 && b.length_mm > 1.0).collect();
    assert!(
        straight.len() == 1
            && straight[0].bound == "feed"
            && (straight[0].at_velocity_s - straight[0].at_feed_s).abs() < 1e-12
    );
    // The turn on the spot (the C table turned on the pole, then the A tilt;
    // the machine layer's blocks of one CL record): the tip does not move, a
    // rotary axis or the orientation feed sets its velocity-limited time; the
    // tip 50 mm from the C axis is carried round by the table, so the linear
    // axes' limits hold the turn (lifting them saves time).
    let turn: Vec<_> = blocks.iter().filter(|b| !b.rapid && b.length_mm < 1e-9).collect();
    assert!(turn.len() > 1);
    assert!(turn.iter().all(|b| b.at_feed_s < 1e-9 && b.bound != "feed"), "{turn:?}");
    assert!(turn.iter().map(|b| b.time_s - b.rotary_only_s).sum::<f64>() > 0.0);
    // The rapids: their slowest axis.
    assert!(blocks.iter().filter(|b| b.rapid).all(|b| ["X", "Y", "Z", "A", "C"].contains(&b.bound.as_str())));
    // The breakdown by move kind keeps every block and every second.
    let shares = time_breakdown(&blocks, &|i| format!("{:?}", path.moves()[i].kind));
    assert_eq!(shares.iter().map(|s| s.blocks).sum::<usize>(), blocks.len());
    let share_total: f64 = shares.iter().map(|s| s.time_s).sum();
    assert!((share_total - total).abs() < 1e-9);
    for s in &shares {
        let velocity: f64 = s.velocity_s.iter().map(|v| v.1).sum();
        assert!((s.at_feed_s + velocity + s.dynamics_s - s.time_s).abs() < 1e-9, "{s:?}");
    }
}
