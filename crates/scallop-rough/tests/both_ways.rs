//! Adaptive clearing both ways (`Direction::Both`, docs/roughing.md,
//! "Adaptive clearing", both ways), judged by the simulator's engagement
//! evaluation (`scallop_sim::pocket_engagement`): on straight-walled pockets
//! the passes that climbing links back to their frontier's upstream end go
//! back along it instead, so the tool-down links shrink to the issue's
//! bound while the engagement bound, the walls and the clearing hold as
//! when climbing; and the plan is the same on one and two threads.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use proptest::prelude::*;
use scallop_contour::{Contour, Region};
use scallop_geom::Point2;
use scallop_rough::{ClearOptions, Direction, Motion, Pattern, RoughPlan, pocket_toolpath};
use scallop_sim::{EngagementOptions, EngagementReport, Pocket, engagement_angle, pocket_engagement};

/// The bench's tool and stepover (bench/freecad/pockets.py: D 6 mm, 0.2 D).
const R: f64 = 3.0;
const AE: f64 = 1.2;

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<[f64; 2]> {
    vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
}

/// The plan of the pocket bounded by `rings` (the wall first) in `direction`,
/// and the simulator's reading of it.
fn judged(rings: &[Vec<[f64; 2]>], direction: Direction) -> (RoughPlan, EngagementReport) {
    let mut it = rings.iter().map(|q| Contour::polygon(q, true).unwrap());
    let outer = it.next().unwrap();
    let wall = Region::with_holes(outer, it.collect()).unwrap();
    let options =
        ClearOptions { tool_radius: R, stepover: AE, direction, chord_tolerance: 1e-3, pattern: Pattern::Adaptive };
    let motion = Motion { clearance_z: 5.0, feed: 5000.0 };
    let plan = pocket_toolpath(&wall.offset(R), &options, -1.0, 0.0, &motion).unwrap();
    let pocket =
        Pocket::new(rings.iter().map(|q| q.iter().map(|p| Point2::new(p[0], p[1])).collect()).collect()).unwrap();
    // A reach beyond a wall fails here (`PocketGouge`).
    let report =
        pocket_engagement(&pocket, R, &plan.toolpath, engagement_angle(AE, R), &EngagementOptions::default()).unwrap();
    (plan, report)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3))]

    #[test]
    fn straight_walled_pockets_link_little_both_ways(
        w in 70.0..100.0f64,
        h in 45.0..60.0f64,
        notch in proptest::bool::ANY,
    ) {
        let rings = if notch {
            // An L: the rectangle less its top right quarter.
            vec![vec![[0.0, 0.0], [w, 0.0], [w, 0.5 * h], [0.5 * w, 0.5 * h], [0.5 * w, h], [0.0, h]]]
        } else {
            vec![rect(0.0, 0.0, w, h)]
        };
        let (_, climb) = judged(&rings, Direction::Climb);
        let (_, both) = judged(&rings, Direction::Both);
        // As when climbing: nothing reachable left, no slot, the engagement
        // within 1.1 x the target outside the entries.
        prop_assert!(both.uncut_area <= 0.05, "uncut {} mm2", both.uncut_area);
        prop_assert!(both.slot_length <= 0.0, "slot {:.2} mm", both.slot_length);
        prop_assert!(both.max <= 1.1 * both.target, "max {:.1} deg", both.max.to_degrees());
        // Climbing, about a third of the feed length links back to the
        // frontiers' upstream ends; both ways, at most the 15 % on
        // pockets of the bench's size (on one of 45 x 30 mm, 17 %: the
        // corners' links weigh more).
        prop_assert!(both.link_share() <= 0.15, "links {:.1} %", 100.0 * both.link_share());
        prop_assert!(
            both.link_share() < 0.5 * climb.link_share(),
            "links {:.1} % both ways, {:.1} % climbing",
            100.0 * both.link_share(),
            100.0 * climb.link_share()
        );
    }
}

#[test]
fn both_ways_the_same_plan_on_one_and_two_threads() {
    let rings = vec![rect(0.0, 0.0, 50.0, 30.0)];
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let (plan, _) = judged(&rings, Direction::Both);
            plan.toolpath.moves().iter().map(|m| (m.kind, m.to.x, m.to.y, m.to.z)).collect::<Vec<_>>()
        })
    };
    let one = run(1);
    assert!(!one.is_empty());
    assert_eq!(one, run(2));
}
