//! Adaptive clearing of a comb of narrow branches both ways (docs/roughing.md,
//! "Adaptive clearing", narrow channels): a 10 mm bar with fingers 8 and 9 mm
//! wide off it, a tool of 6 mm, so tool-centre channels of 4, 2 and 3 mm,
//! as in the FreeCAD bench's branching pocket (bench/freecad/pockets.py).
//! Judged by the simulator's engagement evaluation
//! (`scallop_sim::pocket_engagement`) and the look-ahead jerk-limited time
//! model at the bench's settings (`scallop_strategy::lookahead_time`, 5000
//! mm/min, the default machine, blending 0.01 mm): the cycle time within a
//! bound that the plans of the sixteenth session (the largest link turn
//! first, crossings of the bar peeled from their tails) exceed, the
//! engagement within 1.1 x the target up to its maximum, nothing
//! reachable left, nothing slotted, nothing cut beyond a wall.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use scallop_analysis::MachineLimits;
use scallop_contour::{Contour, Region};
use scallop_geom::Point2;
use scallop_rough::{ClearOptions, Direction, Motion, Pattern, RoughPlan, pocket_toolpath};
use scallop_sim::{EngagementOptions, EngagementReport, Pocket, engagement_angle, pocket_engagement};
use scallop_strategy::{Boundary, FinishingParams, Pattern as FinishPattern, lookahead_time};

/// The bench's tool and stepover (bench/freecad/pockets.py: D 6 mm, 0.2 D).
const R: f64 = 3.0;
const AE: f64 = 1.2;

/// A bar 60 x 10 mm along x with two fingers 25 mm high off its top: 8 mm
/// wide at x = 12 and 9 mm wide at x = 36.
fn comb() -> Vec<[f64; 2]> {
    vec![
        [0.0, 0.0],
        [60.0, 0.0],
        [60.0, 10.0],
        [45.0, 10.0],
        [45.0, 35.0],
        [36.0, 35.0],
        [36.0, 10.0],
        [20.0, 10.0],
        [20.0, 35.0],
        [12.0, 35.0],
        [12.0, 10.0],
        [0.0, 10.0],
    ]
}

/// The plan of the pocket bounded by `ring` both ways, the simulator's
/// reading of it and the model's cycle time (s).
fn judged(ring: &[[f64; 2]]) -> (RoughPlan, EngagementReport, f64) {
    let wall = Region::with_holes(Contour::polygon(ring, true).unwrap(), Vec::new()).unwrap();
    let options = ClearOptions {
        tool_radius: R,
        stepover: AE,
        direction: Direction::Both,
        chord_tolerance: 1e-3,
        pattern: Pattern::Adaptive,
    };
    let motion = Motion { clearance_z: 5.0, feed: 5000.0 };
    let plan = pocket_toolpath(&wall.offset(R), &options, -1.0, 0.0, &motion).unwrap();
    let pocket = Pocket::new(vec![ring.iter().map(|p| Point2::new(p[0], p[1])).collect()]).unwrap();
    // A reach beyond a wall fails here (`PocketGouge`).
    let report =
        pocket_engagement(&pocket, R, &plan.toolpath, engagement_angle(AE, R), &EngagementOptions::default()).unwrap();
    // The settings of `scallop engagement` (its defaults: 5000 mm/min, rapids
    // 10000 mm/min, blending 0.01 mm).
    let params = FinishingParams {
        direction: 0.0,
        pattern: FinishPattern::Zigzag,
        scallop_height: 0.01,
        boundary: Boundary::ContactInside,
        max_step: 1.0,
        clearance: 1.0,
        machine: MachineLimits { feed: 5000.0 / 60.0, ..MachineLimits::default() },
        plunge_feed: 5000.0 / 60.0,
        rapid_rate: 10000.0 / 60.0,
        sharp_corner: 0.5,
        blend_tolerance: 0.01,
    };
    let time = lookahead_time(&plan.toolpath, &params).total();
    (plan, report, time)
}

#[test]
fn a_comb_of_narrow_branches_is_cleared_faster_within_the_bound() {
    let (plan, report, time) = judged(&comb());
    let bound = 1.1 * report.target;
    assert!(report.uncut_area <= 0.05, "uncut {} mm2", report.uncut_area);
    assert!(report.slot_length <= 0.0, "slot {:.2} mm", report.slot_length);
    assert!(report.p99 <= bound, "p99 {:.1} deg", report.p99.to_degrees());
    assert!(report.max <= bound, "max {:.1} deg", report.max.to_degrees());
    // 61.4 s before (links 35 %, the largest turns first and the bar's
    // crossings peeled from their tails), 56.4 s after.
    assert!(
        time <= 58.0,
        "cycle time {time:.2} s, links {:.1} %, {} retracts",
        100.0 * report.link_share(),
        plan.retracts
    );
}
