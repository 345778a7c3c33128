//! The trochoidal slot of kinematics.md section 5 through the machine layer: posted for
//! the Mikron UCP 710 in every 5-axis-capable dialect and replayed, and its feed bounded
//! by the axes' jerk exactly where the spec's derived values say.

use scallop_geom::{Point3, Vec3};
use scallop_machine::program::{ProgramOptions, records_from_toolpath, to_program};
use scallop_machine::time::path_time;
use scallop_machine::{Kinematics, Machine};
use scallop_post::{Dialect, OutputMode, PostParams, check_replay, program_text, replay};
use scallop_strategy::trochoid::{TrochoidParams, trochoid_slot};

fn slot() -> scallop_toolpath::Toolpath {
    let params = TrochoidParams {
        diameter: 20.0,
        width: 28.0,
        step: 1.5,
        tolerance: 0.002,
        depth: 30.0,
        clearance: 10.0,
        feed: 2400.0,
        clockwise: false,
    };
    trochoid_slot(&[Point3::new(-60.0, 0.0, 0.0), Point3::new(60.0, 0.0, 0.0)], &params).expect("valid slot")
}

#[test]
fn the_slot_posts_and_replays_in_every_dialect() {
    let kin = Kinematics::new(&Machine::builtin("ucp710").expect("shipped"), 0.0);
    let records = records_from_toolpath(&slot(), &Vec3::z());
    let options = ProgramOptions::default();
    let program = to_program(&kin, &records, None, &options).expect("reachable");
    for name in ["linuxcnc", "fanuc", "siemens840d", "heidenhain"] {
        let dialect = Dialect::builtin(name).expect("shipped");
        let params = PostParams::new("2000", OutputMode::Joint, 1, 0.0, 12000.0, &options);
        let text = program_text(&program, &kin, &dialect, &params).expect("post");
        let trip = check_replay(&replay(&text, &dialect, &kin).expect("replay"), &records, &kin, &dialect, 0.01, 1e-3)
            .expect("round trip");
        assert!(trip.max_tip_deviation <= 0.01, "{name}: {trip:?}");
    }
}

#[test]
fn the_loops_are_jerk_limited_below_the_programmed_feed() {
    // UCP 710: J_x = J_y = 5 m/s^3. Constant speed on the trochoid's tightest radius,
    // 3.536783 mm, is capped at (J rho^2)^(1/3) = 2381.66 mm/min: below the 2400 mm/min
    // programmed, so every loop slows down at its tight part (spec 5, derived values).
    let machine = Machine::builtin("ucp710").expect("shipped");
    let kin = Kinematics::new(&machine, 0.0);
    let records = records_from_toolpath(&slot(), &Vec3::z());
    let program = to_program(&kin, &records, None, &ProgramOptions::default()).expect("reachable");
    // The cutting run: from the plunge's end to the last feed block.
    let blocks: Vec<_> = program.blocks.iter().skip(2).take_while(|b| b.motion.is_cutting()).collect();
    let joints: Vec<_> = blocks.iter().map(|b| b.joints).collect();
    let feeds: Vec<f64> = blocks[1..].iter().map(|b| b.feed).collect();
    let report = path_time(&kin, &joints, &feeds).expect("time");
    let n = report.blocks.len();
    let steady = &report.blocks[n / 4..3 * n / 4];
    let fastest = steady.iter().map(|b| b.peak).fold(0.0, f64::max) * 60.0;
    let slowest = steady.iter().map(|b| b.peak).fold(f64::MAX, f64::min) * 60.0;
    // The wide part of each loop (radius up to 4.49 mm, cap 2581 mm/min) runs at the feed.
    assert!((fastest - 2400.0).abs() < 1e-6, "the programmed feed is never exceeded: {fastest}");
    // Per-axis jerk on a circle of radius rho at speed v: v^3 / rho^2 on the axis at its
    // extreme; the tightest point of the loop sets the slowest speed.
    let rho_min: f64 = 3.536783;
    let cap = (5000.0 * rho_min * rho_min).cbrt() * 60.0;
    assert!((cap - 2381.66).abs() < 0.01, "{cap}");
    assert!(slowest <= cap * 1.02 && slowest >= cap * 0.8, "slowest {slowest} against the cap {cap}");
    assert!(report.axis_time_lost[0] > 0.0 && report.axis_time_lost[1] > 0.0);
}
