//! Adaptive clearing of channels narrower than 2 R of tool-centre width
//! (docs/roughing.md, "Adaptive clearing", narrow channels), judged by the
//! simulator's engagement evaluation (`scallop_sim::pocket_engagement`): the
//! passes cross the channel from wall to wall, and a short pass no longer
//! ends with a step slid along the far wall (a tight turn the tool crawls
//! through before its link); nothing reachable is left, nothing slotted,
//! nothing cut beyond a wall, the engagement within 1.1 x the target, climbing
//! and both ways.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use proptest::prelude::*;
use scallop_contour::{Contour, Region};
use scallop_geom::Point2;
use scallop_rough::{ClearOptions, Direction, Motion, Pattern, RoughPlan, pocket_toolpath};
use scallop_sim::{EngagementOptions, EngagementReport, Pocket, engagement_angle, pocket_engagement};
use scallop_toolpath::MoveKind;

/// The bench's tool and stepover (bench/freecad/pockets.py: D 6 mm, 0.2 D).
const R: f64 = 3.0;
const AE: f64 = 1.2;

/// A channel `len` long and `width` wide along x, closed at both ends.
fn channel(len: f64, width: f64) -> Vec<[f64; 2]> {
    vec![[0.0, 0.0], [len, 0.0], [len, width], [0.0, width]]
}

/// The plan of the pocket bounded by `ring` in `direction`, and the
/// simulator's reading of it.
fn judged(ring: &[[f64; 2]], direction: Direction) -> (RoughPlan, EngagementReport) {
    let wall = Region::with_holes(Contour::polygon(ring, true).unwrap(), Vec::new()).unwrap();
    let options =
        ClearOptions { tool_radius: R, stepover: AE, direction, chord_tolerance: 1e-3, pattern: Pattern::Adaptive };
    let motion = Motion { clearance_z: 5.0, feed: 5000.0 };
    let plan = pocket_toolpath(&wall.offset(R), &options, -1.0, 0.0, &motion).unwrap();
    let pocket = Pocket::new(vec![ring.iter().map(|p| Point2::new(p[0], p[1])).collect()]).unwrap();
    // A reach beyond a wall fails here (`PocketGouge`).
    let report =
        pocket_engagement(&pocket, R, &plan.toolpath, engagement_angle(AE, R), &EngagementOptions::default()).unwrap();
    (plan, report)
}

/// The pass ends (a cutting move followed by a tool-down link) and, of them,
/// those that end on one of the channel's long walls (the tool centre on the
/// line R from the wall, within `tol`).
fn ends_on_walls(plan: &RoughPlan, width: f64, tol: f64) -> (usize, usize) {
    let moves = plan.toolpath.moves();
    let on_wall = |y: f64| (y - R).abs() <= tol || (y - (width - R)).abs() <= tol;
    let (mut ends, mut on) = (0, 0);
    for i in 1..moves.len() {
        let b = moves[i - 1].to;
        if moves[i - 1].kind != MoveKind::Feed || moves[i].kind != MoveKind::Link || b.z > -0.5 {
            continue;
        }
        ends += 1;
        if on_wall(b.y) {
            on += 1;
        }
    }
    (ends, on)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4))]

    #[test]
    fn narrow_channels_are_cleared_within_the_bound(
        len in 30.0..45.0f64,
        across in 0.9 * R..1.9 * R,
        both in proptest::bool::ANY,
    ) {
        // A channel 2 R + `across` wide: a tool-centre channel 2.7 to 5.7 mm
        // wide, where every pass crosses from wall to wall.
        let width = 2.0 * R + across;
        let direction = if both { Direction::Both } else { Direction::Climb };
        let (_, report) = judged(&channel(len, width), direction);
        let bound = 1.1 * engagement_angle(AE, R);
        prop_assert!(report.uncut_area <= 0.05, "uncut {} mm2", report.uncut_area);
        prop_assert!(report.slot_length <= 0.0, "slot {:.2} mm", report.slot_length);
        prop_assert!(
            report.max <= bound,
            "max {:.1} deg at {:?}, bound {:.1} deg",
            report.max.to_degrees(),
            report.max_at,
            bound.to_degrees()
        );
    }
}

#[test]
fn short_passes_across_a_narrow_channel_end_where_the_far_wall_turns_them() {
    // A channel 10 mm wide for a 6 mm tool (the bench's branching pocket's
    // bar): a tool-centre channel of 4 mm, each pass a crossing shorter than
    // 2 R. Its last step was the one the far wall turned to slide along it,
    // ending on the wall: a tight turn the tool crawled through before its
    // link. That step is not cut now: 97 of 120 pass ends (climbing) and 112
    // of 126 (both ways) lay on a wall before, 51 of 121 and 40 of 128 now
    // (the others end where the engagement, not the wall, turned the step).
    for direction in [Direction::Climb, Direction::Both] {
        let width = 10.0;
        let (plan, report) = judged(&channel(60.0, width), direction);
        assert!(report.uncut_area <= 0.05, "uncut {} mm2", report.uncut_area);
        assert!(report.slot_length <= 0.0, "slot {:.2} mm", report.slot_length);
        let (ends, on) = ends_on_walls(&plan, width, 1e-3);
        // The check is not vacuous: the passes are many.
        assert!(ends >= 30, "{direction:?}: {ends} pass ends");
        assert!(5 * on <= 3 * ends, "{direction:?}: {on} of {ends} pass ends on a wall");
    }
}
