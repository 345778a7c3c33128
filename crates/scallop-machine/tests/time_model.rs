//! Acceptance tests T1-T7 of spec 7.4 (machine-aware time, section 8).

mod common;

use scallop_machine::time::{Limits, StopCase, TimeModel, block_time, path_time, stop_to_stop};
use scallop_machine::{Joints, Kinematics, Machine};

fn ucp(corner_tolerance: f64) -> Kinematics {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../machines/mikron-ucp710.toml"))
        .expect("file");
    let text = text.replace("corner_tolerance = 0.1 ", &format!("corner_tolerance = {corner_tolerance:?} "));
    Kinematics::new(&Machine::from_toml_str(&text).expect("valid"), 0.0)
}

fn xy(x: f64, y: f64) -> Joints {
    Joints::new(x, y, 50.0, 0.0, 0.0)
}

#[test]
fn t1_stop_to_stop() {
    let l = Limits { v: 5000.0 / 60.0, a: 6000.0, j: 40000.0 };
    assert_near!(l.a / l.j, 0.15, 1e-12);
    assert_near!((l.v / l.j).sqrt(), 0.0456435, 1e-7);
    assert_near!(2.0 * (l.v.powi(3) / l.j).sqrt(), 7.607258, 1e-6);
    let (t, case, _) = stop_to_stop(2.0, &l, TimeModel::SCurve);
    assert_eq!(case, StopCase::Neither);
    assert_near!(t, 0.116961, 1e-6);
    let (t, case, _) = stop_to_stop(50.0, &l, TimeModel::SCurve);
    assert_eq!(case, StopCase::VelocityOnly);
    assert_near!(t, 0.691287, 1e-6);
    // The general block time agrees with the closed forms.
    assert_near!(block_time(0.0, 0.0, 2.0, &l).0, 0.116961, 1e-6);
    assert_near!(block_time(0.0, 0.0, 50.0, &l).0, 0.691287, 1e-6);
}

#[test]
fn t2_t3_t4_ucp710_single_axis() {
    let x = Limits { v: 40.0, a: 2500.0, j: 5000.0 };
    let (t, case, _) = stop_to_stop(100.0, &x, TimeModel::SCurve);
    assert_eq!(case, StopCase::VelocityOnly);
    assert_near!(t, 2.678885, 1e-6);
    let x_rapid = Limits { v: 500.0, ..x };
    let (t, case, peak) = stop_to_stop(100.0, &x_rapid, TimeModel::SCurve);
    assert_eq!(case, StopCase::Neither);
    assert_near!(t, 0.861774, 1e-6);
    assert_near!(peak, 232.079, 1e-3);
    let z_rapid = Limits { v: 500.0, a: 2100.0, j: 50000.0 };
    let (t, case, peak) = stop_to_stop(100.0, &z_rapid, TimeModel::SCurve);
    assert_eq!(case, StopCase::AccelerationOnly);
    assert_near!(t, 0.480452, 1e-6);
    assert_near!(peak, 416.275, 1e-3);
    assert_near!(block_time(0.0, 0.0, 100.0, &z_rapid).0, 0.480452, 1e-6);
    let (t, case, _) = stop_to_stop(100.0, &z_rapid, TimeModel::Thesis);
    assert_eq!(case, StopCase::VelocityAndAcceleration);
    assert_near!(t, 0.480095, 1e-6);
    let m = Machine::builtin("ucp710").expect("shipped");
    assert_near!(
        scallop_machine::time::rapid_time(&m, &Joints::zeros(), &Joints::new(0.0, 0.0, 100.0, 0.0, 0.0)),
        0.480452,
        1e-6
    );
}

#[test]
fn t5_collinear_blocks() {
    let k = ucp(0.1);
    let r = path_time(&k, &[xy(0.0, 0.0), xy(50.0, 0.0), xy(100.0, 0.0)], &[2400.0, 2400.0]).expect("valid");
    assert_near!(r.total, 2.678885, 1e-6);
}

#[test]
fn t6_corner() {
    let q = [xy(0.0, 0.0), xy(50.0, 0.0), xy(50.0, 50.0)];
    let r = path_time(&ucp(0.0), &q, &[2400.0, 2400.0]).expect("valid");
    assert_near!(r.total, 2.857771, 1e-6);
    let r = path_time(&ucp(0.1), &q, &[2400.0, 2400.0]).expect("valid");
    assert_near!(r.junction_caps[0] * 60.0, 442.08, 0.01);
    assert_near!(r.total, 2.810696, 1e-6);
}

#[test]
fn t7_circle_jerk_cap() {
    let k = ucp(0.1);
    let q: Vec<Joints> = (0..=360)
        .map(|i| {
            let p = f64::from(i).to_radians();
            xy(4.0 * p.cos(), 4.0 * p.sin())
        })
        .collect();
    let r = path_time(&k, &q, &vec![6000.0; 360]).expect("valid");
    let cap = r.junction_caps.iter().copied().fold(f64::INFINITY, f64::min) * 60.0;
    assert!((cap - 2585.0).abs() <= 0.01 * 2585.0, "cap {cap}");
}

#[test]
fn time_lost_is_charged_to_the_axes_that_move() {
    // A straight X move: only X can cost time; Y, Z, A, C are never charged.
    let k = ucp(0.1);
    let r = path_time(&k, &[xy(0.0, 0.0), xy(100.0, 0.0)], &[2400.0]).expect("valid");
    assert!(r.axis_time_lost[0] > 0.0, "{r:?}");
    for lost in &r.axis_time_lost[1..] {
        assert_near!(*lost, 0.0, 1e-12);
    }
    // Lifting X's limits leaves the feed-only floor: the loss is total - floor, up to the
    // S-curve of the lifted (1e9 times larger, not infinite) limits, 2 sqrt(40 / 5e12) s.
    assert_near!(r.feed_time, 100.0 / 40.0, 1e-12);
    assert_near!(r.axis_time_lost[0], r.total - r.feed_time, 1e-5);
    // A small circle at a high feed is acceleration-limited on X and Y alike: both pay.
    let circle: Vec<Joints> = (0..=72)
        .map(|i| {
            let t = f64::from(i) * 5f64.to_radians();
            xy(4.0 * t.cos(), 4.0 * t.sin())
        })
        .collect();
    let r = path_time(&k, &circle, &vec![6000.0; 72]).expect("valid");
    assert!(r.axis_time_lost[0] > 0.0 && r.axis_time_lost[1] > 0.0, "{r:?}");
    assert!(r.total >= r.feed_time);
    assert_near!(r.axis_time_lost[2], 0.0, 1e-12);
}
