//! Joint-space programs: planning, subdivision, G93 and FK replay (spec 1.2, 3.9, 3.10,
//! K16 before formatting).

mod common;

use common::deg;
use scallop_geom::{Point3, Vec3};
use scallop_machine::plan::Event;
use scallop_machine::program::{ClRecord, Motion, ProgramOptions, to_program, verify};
use scallop_machine::{Kinematics, Machine, MachineError, Pose};

fn rec(pose: Pose, motion: Motion) -> ClRecord {
    ClRecord { pose, motion, feed: 2000.0 }
}

#[test]
fn five_axis_swarf_like_path_on_every_shipped_machine() {
    for name in Machine::builtin_names() {
        let m = Machine::builtin(name).expect("shipped");
        let k = Kinematics::new(&m, if name == "mx330" { 100.0 } else { 0.0 });
        let z = if name == "mx330" { 20.0 } else { 60.0 };
        let mut records = vec![rec(Pose::new(Point3::new(-20.0, 0.0, z + 30.0), Vec3::z()), Motion::Rapid)];
        for i in 0..=40 {
            let t = f64::from(i) / 40.0;
            let tilt = deg(25.0) * (std::f64::consts::PI * t).sin();
            let axis = Vec3::new(tilt.sin() * (2.0 * t).cos(), tilt.sin() * (2.0 * t).sin(), tilt.cos());
            records.push(rec(Pose::new(Point3::new(-20.0 + 40.0 * t, 10.0 * (3.0 * t).sin(), z), axis), Motion::Feed));
        }
        let opts = ProgramOptions::default();
        let prog = to_program(&k, &records, None, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(prog.blocks.len() >= records.len(), "{name}");
        let v = verify(&k, &prog, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(v.max_tip_deviation <= opts.tol_pos, "{name}: {v:?}");
        assert!(v.max_rate_ratio <= 1.0 + 1e-12, "{name}: {v:?}");
        assert!(
            prog.blocks
                .iter()
                .skip(1)
                .all(|b| b.motion == Motion::Rapid || b.inverse_time.is_some() == m.nc().inverse_time)
        );
    }
}

#[test]
fn pole_crossing_program_keeps_rotary_speeds_within_limits() {
    let k = Kinematics::new(&Machine::builtin("mx330").expect("shipped"), 100.0);
    let poses: Vec<Pose> = (-30..=30)
        .map(|i| {
            Pose::new(Point3::new(0.0, 0.0, 20.0), Vec3::new(0.0, deg(f64::from(i)).sin(), deg(f64::from(i)).cos()))
        })
        .collect();
    let records: Vec<ClRecord> = poses.iter().map(|p| rec(*p, Motion::Feed)).collect();
    let opts = ProgramOptions::default();
    let prog = to_program(&k, &records, None, &opts).expect("flip at the pole");
    assert_eq!(prog.events.iter().filter(|e| matches!(e, Event::PoleFlip { .. })).count(), 1);
    let v = verify(&k, &prog, &opts).expect("replays");
    assert!(v.max_rate_ratio <= 1.0 + 1e-12, "{v:?}");
    // The flip block is an in-place C rotation timed by the C speed limit.
    let flip = prog.blocks.windows(2).find(|w| (w[1].words[4] - w[0].words[4]).abs() > 170.0).expect("flip block");
    assert!((flip[1].pose.tip - flip[0].pose.tip).norm() < 1e-9);
    let f_inv = flip[1].inverse_time.expect("G93");
    assert!(180.0 * f_inv / 60.0 <= 198.0 + 1e-9);
}

#[test]
fn program_leaving_a_stroke_names_block_axis_and_value() {
    let k = Kinematics::new(&Machine::builtin("ucp710").expect("shipped"), 0.0);
    let records = [
        rec(Pose::new(Point3::new(0.0, 0.0, 50.0), Vec3::z()), Motion::Rapid),
        rec(Pose::new(Point3::new(100.0, 0.0, 50.0), Vec3::z()), Motion::Feed),
        rec(Pose::new(Point3::new(400.0, 0.0, 50.0), Vec3::z()), Motion::Feed),
    ];
    let err = to_program(&k, &records, None, &ProgramOptions::default()).expect_err("X leaves [-355, 355]");
    match &err {
        MachineError::LimitViolation { block, axis, value, .. } => {
            assert_eq!((*block, axis.as_str()), (Some(2), "X"));
            assert!((value - 400.0).abs() < 1e-9);
        }
        other => panic!("{other}"),
    }
    assert!(err.to_string().contains("block 2: axis X = 400.0000 mm"), "{err}");
}

#[test]
fn pole_flip_off_the_c_axis_is_subdivided_and_replays() {
    // Tip 15 mm from the C axis: the in-place C rotation needs X/Y along an arc.
    let k = Kinematics::new(&Machine::builtin("mx330").expect("shipped"), 100.0);
    let records: Vec<ClRecord> = (-30..=30)
        .map(|i| {
            rec(
                Pose::new(
                    Point3::new(15.0, 0.0, 20.0),
                    Vec3::new(0.0, deg(f64::from(i)).sin(), deg(f64::from(i)).cos()),
                ),
                Motion::Feed,
            )
        })
        .collect();
    let opts = ProgramOptions::default();
    let prog = to_program(&k, &records, None, &opts).expect("flip at the pole");
    assert!(prog.blocks.len() > records.len() + 10, "the flip is subdivided: {}", prog.blocks.len());
    let v = verify(&k, &prog, &opts).expect("replays");
    assert!(v.max_tip_deviation <= opts.tol_pos && v.max_rate_ratio <= 1.0 + 1e-12, "{v:?}");
}

#[test]
fn three_axis_toolpath_becomes_a_program() {
    use scallop_toolpath::{Move, MoveKind, Toolpath};
    let k = Kinematics::new(&Machine::builtin("linuxcnc-xyzac-trt").expect("shipped"), 0.0);
    let mut tp = Toolpath::new(600.0);
    tp.push(Move::new(MoveKind::Rapid, Point3::new(0.0, 0.0, 20.0)));
    tp.push(Move::new(MoveKind::Plunge, Point3::new(0.0, 0.0, 0.0)));
    tp.push(Move::new(MoveKind::Feed, Point3::new(30.0, 0.0, 0.0)));
    tp.push(Move::new(MoveKind::Feed, Point3::new(30.0, 20.0, 0.0)));
    tp.push(Move::new(MoveKind::Retract, Point3::new(30.0, 20.0, 20.0)));
    let records = scallop_machine::program::records_from_toolpath(&tp, &Vec3::z());
    let opts = ProgramOptions::default();
    let prog = to_program(&k, &records, None, &opts).expect("3-axis");
    assert_eq!(prog.blocks.len(), 5, "no subdivision without rotary motion");
    for (b, m) in prog.blocks.iter().zip(tp.moves()) {
        assert!(
            (b.words[0] - m.to.x).abs() < 1e-12
                && (b.words[1] - m.to.y).abs() < 1e-12
                && (b.words[2] - m.to.z).abs() < 1e-12
        );
        assert!(b.words[3].abs() < 1e-12 && b.words[4].abs() < 1e-12);
    }
    // G93: 30 mm at 600 mm/min is 20 per minute.
    assert_eq!(prog.blocks[2].inverse_time, Some(20.0));
    verify(&k, &prog, &opts).expect("replays");
}
