//! Entries against the machine's dynamics (docs/rough5.md, "Entries against
//! the machine's dynamics"): `path_time_estimate` follows the machine time
//! model of `scallop_machine::time` on paths of the linear axes (circles,
//! helices, back-and-forth ramps); with `Rough5Settings::entry_dynamics` the
//! closed pocket's entries take less time by that estimate than the largest
//! helices, none descends more steeply than theirs, and the program proves
//! itself on the tri-dexel stock.

#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;

use proptest::prelude::*;
use scallop_geom::Point3;
use scallop_machine::time::path_time;
use scallop_machine::{Joints, Kinematics, Machine};
use scallop_parts::closed_pocket;
use scallop_rough5::{MoveRole, PathDynamics, ProofSettings, Rough5Settings, path_time_estimate, plan_rough5, prove};

/// The Mikron UCP 710's linear axes (machines/mikron-ucp710.toml): the
/// smallest acceleration (Z, 2100 mm/s²) and jerk (X and Y, 5000 mm/s³), and
/// its corner tolerance.
const UCP710: PathDynamics = PathDynamics { acceleration: 2100.0, jerk: 5000.0, corner_tolerance: 0.1 };

/// The UCP 710's model time (s) of the tool tips `tips` with the axis +Z
/// (A = C = 0: the tip moves with X, Y and Z alone) at `feed` mm/min.
fn model_time(tips: &[Point3], feed: f64) -> f64 {
    let machine = Machine::builtin("ucp710").unwrap();
    let kin = Kinematics::new(&machine, 0.0);
    let joints: Vec<Joints> = tips.iter().map(|p| Joints::new(p.x, p.y, p.z, 0.0, 0.0)).collect();
    let feeds = vec![feed; tips.len() - 1];
    path_time(&kin, &joints, &feeds).unwrap().total
}

/// A helix of radius `r` descending `drop` mm over `turns` turns about
/// (50, 20, 30), in chords turning by `turn` rad.
fn helix(r: f64, turns: f64, drop: f64, turn: f64) -> Vec<Point3> {
    let n = (turns * std::f64::consts::TAU / turn).ceil() as usize;
    (0..=n)
        .map(|k| {
            let w = k as f64 / n as f64;
            let a = turns * std::f64::consts::TAU * w;
            Point3::new(50.0 + r * a.cos(), 20.0 + r * a.sin(), 30.0 - drop * w)
        })
        .collect()
}

/// A ramp back and forth along x in `legs` legs of `leg` mm, descending
/// `drop` mm, points every `step` mm.
fn shuttle(leg: f64, legs: usize, drop: f64, step: f64) -> Vec<Point3> {
    let per = (leg / step).ceil() as usize;
    let total = (per * legs) as f64;
    let mut out = Vec::new();
    for l in 0..legs {
        for k in 0..per {
            let along = k as f64 * leg / per as f64;
            let x = if l.is_multiple_of(2) { along } else { leg - along };
            let done = (l * per + k) as f64 / total;
            out.push(Point3::new(10.0 + x, -15.0, 25.0 - drop * done));
        }
    }
    let x = if legs.is_multiple_of(2) { 0.0 } else { leg };
    out.push(Point3::new(10.0 + x, -15.0, 25.0 - drop));
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// On a helix of the linear axes, the estimate is the machine time
    /// model's within 15 % (it takes every axis at the slowest one's limits,
    /// so it is rarely below), and a larger circle never takes longer per
    /// mm than a smaller one.
    #[test]
    fn helices_follow_the_machine_model(
        r in 1.0f64..6.0,
        turns in 1.5f64..5.0,
        drop in 1.0f64..6.0,
        turn_deg in 3.0f64..9.0,
        feed in 1200.0f64..4800.0,
    ) {
        let tips = helix(r, turns, drop, turn_deg.to_radians());
        let estimate = path_time_estimate(&tips, feed, &UCP710);
        let model = model_time(&tips, feed);
        prop_assert!(estimate > 0.97 * model && estimate < 1.15 * model, "estimate {estimate} model {model}");
        let length: f64 = tips.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        let bigger = helix(1.5 * r, turns / 1.5, drop, turn_deg.to_radians());
        let big_length: f64 = bigger.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        let per_mm = |t: f64, l: f64| t / l;
        prop_assert!(
            per_mm(path_time_estimate(&bigger, feed, &UCP710), big_length) <= per_mm(estimate, length) * 1.001
        );
    }

    /// On a ramp back and forth (a stop at every turn), the estimate is the
    /// model's within 15 %.
    #[test]
    fn shuttles_follow_the_machine_model(
        leg in 5.0f64..40.0,
        legs in 1usize..6,
        drop in 1.0f64..6.0,
        step in 0.5f64..2.0,
        feed in 1200.0f64..4800.0,
    ) {
        let tips = shuttle(leg, legs, drop, step);
        let estimate = path_time_estimate(&tips, feed, &UCP710);
        let model = model_time(&tips, feed);
        prop_assert!(estimate > 0.97 * model && estimate < 1.15 * model, "estimate {estimate} model {model}");
    }
}

/// A helix on a circle of 1.25 mm (a quarter of the tool's radius, the only
/// one that fits a narrow loop) takes longer than straight legs back and
/// forth of the same length and descent: the linear axes' jerk holds the
/// circle to (j ρ²)^(1/3) = 19.8 mm/s at a 40 mm/s feed, by the model and by
/// the estimate alike.
#[test]
fn a_small_helix_is_slower_than_straight_legs() {
    let h = helix(1.25, 57.3 / (std::f64::consts::TAU * 1.25), 5.0, 9f64.to_radians());
    let s = shuttle(57.3 / 3.0, 3, 5.0, 1.0);
    let (mh, ms) = (model_time(&h, 2400.0), model_time(&s, 2400.0));
    assert!(ms < 0.8 * mh, "model: helix {mh} s, legs {ms} s");
    let (eh, es) = (path_time_estimate(&h, 2400.0, &UCP710), path_time_estimate(&s, 2400.0, &UCP710));
    assert!(es < 0.8 * eh, "estimate: helix {eh} s, legs {es} s");
}

/// The entries' estimated time (s), each from the approach's end (its last
/// move) to the end of its last entry move, and the steepest descent of an
/// entry move (rise over length).
fn entry_times(plan: &scallop_rough5::Rough5Plan) -> (f64, f64) {
    let moves = plan.toolpath.moves();
    let (mut total, mut steepest) = (0.0, 0.0f64);
    let mut k = 0;
    while k < moves.len() {
        if plan.roles[k] != MoveRole::Entry || k == 0 {
            k += 1;
            continue;
        }
        let mut tips = vec![moves[k - 1].to];
        while k < moves.len() && plan.roles[k] == MoveRole::Entry {
            let (a, b) = (tips[tips.len() - 1], moves[k].to);
            let length = (b - a).norm();
            if length > 1e-9 && moves[k].kind == scallop_toolpath::MoveKind::Feed {
                steepest = steepest.max((a.z - b.z) / (b - a).xy().norm().max(1e-12));
            }
            tips.push(b);
            k += 1;
        }
        total += path_time_estimate(&tips, 2400.0, &UCP710);
    }
    (total, steepest)
}

/// On the closed pocket, with the UCP 710's dynamics the entries take less
/// time than the largest helices that fit (by the estimate), none descends
/// more steeply than those of the largest helices' program, and the program
/// proves itself (no rapid into stock, no shank or holder collision, no
/// gouge).
#[test]
fn the_closed_pocket_is_entered_faster_against_the_machines_dynamics() {
    let part = closed_pocket(&Default::default()).unwrap();
    let (bottom, flanks, depth) = common::bottom_flanks(&part);
    let tool = common::torus(30.0, 100.0);
    let largest = common::settings(depth);
    let timed = Rough5Settings { entry_dynamics: Some(UCP710), ..largest };
    let before = plan_rough5(&bottom, &flanks, &part.stock, &tool, &largest, &|_, _| {}).unwrap();
    let after = plan_rough5(&bottom, &flanks, &part.stock, &tool, &timed, &|_, _| {}).unwrap();
    let ((t0, steep0), (t1, steep1)) = (entry_times(&before), entry_times(&after));
    assert!(t1 < t0 - 1.0, "entries {t0} s before, {t1} s after ({:?} -> {:?})", before.entries, after.entries);
    // The levels are not flat, so an entry along them descends by the ramp
    // angle plus their slope: none steeper than the largest helices' program had.
    assert!(steep1 <= steep0 + 1e-9, "an entry descends by {steep1} mm/mm, before by {steep0} mm/mm");
    assert_eq!(after.entries.plunge, 0, "{:?}", after.plunged_at);
    let proof_settings = ProofSettings { resolution: 1.0, axis_tolerance: 0.05 };
    let proof = prove(&after.toolpath, &tool, &part.stock, &part.mesh, &proof_settings, &|_, _| {}).unwrap();
    assert!(proof.gouge_depth <= proof_settings.axis_tolerance, "{proof:?}");
}
