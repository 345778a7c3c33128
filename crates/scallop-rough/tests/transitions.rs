//! Offset clearing's transitions from a ring to the next one out
//! (docs/roughing.md, "Offset clearing", transitions), judged by the
//! simulator's engagement evaluation (`scallop_sim::pocket_engagement`): on
//! discs, where the rings are wide enough for their curvature to keep the
//! engagement within 1.1 x the target (radius 6.3 mm and more for R 1.5 mm
//! at 0.4 R: `cos phi = 1 - ae / R - (R - ae) ae / (rho R)` for concentric
//! circles; the test looks beyond 12 mm), no link crosses a band (the tool goes from ring to ring along a
//! transition) and nothing engages more than 1.1 x the target (a straight
//! link across a band reads up to twice the target at its end). An
//! ellipse's rings exceed the bound at their ends by their curvature alone.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use proptest::prelude::*;
use scallop_contour::{Contour, Region};
use scallop_geom::Point2;
use scallop_rough::{ClearOptions, Direction, Motion, Pattern, pocket_toolpath};
use scallop_sim::{EngagementOptions, Pocket, engagement_angle, pocket_engagement};
use scallop_toolpath::MoveKind;

const R: f64 = 1.5;
const AE: f64 = 0.4 * R;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4))]

    #[test]
    fn rings_are_joined_by_transitions_within_the_bound(
        a in 14.5..17.0f64, phase in 0.0..1.0f64, climb in any::<bool>(),
    ) {
        let (cx, cy) = (20.0, 20.0);
        #[allow(clippy::cast_precision_loss, reason = "a small count")]
        let ring: Vec<[f64; 2]> = (0..160)
            .map(|k| {
                let t = std::f64::consts::TAU * (k as f64 + phase) / 160.0;
                [cx + a * t.cos(), cy + a * t.sin()]
            })
            .collect();
        let wall = Region::with_holes(Contour::polygon(&ring, true).unwrap(), Vec::new()).unwrap();
        let region = wall.offset(R);
        let direction = if climb { Direction::Climb } else { Direction::Conventional };
        let options =
            ClearOptions { tool_radius: R, stepover: AE, direction, chord_tolerance: 1e-3, pattern: Pattern::Offset };
        let motion = Motion { clearance_z: 5.0, feed: 1000.0 };
        let plan = pocket_toolpath(&region, &options, -1.0, 0.0, &motion).unwrap();
        let pocket = Pocket::new(vec![ring.iter().map(|p| Point2::new(p[0], p[1])).collect()]).unwrap();
        let eopts = EngagementOptions { gouge_tolerance: 0.03, ..EngagementOptions::default() };
        let target = engagement_angle(AE, R);
        let report = pocket_engagement(&pocket, R, &plan.toolpath, target, &eopts).unwrap();
        prop_assert!(report.uncut_area <= 0.05, "uncut {} mm2", report.uncut_area);
        // Where the rings' curvature keeps the engagement within the bound
        // with a margin for the simulator's raster (the rings 55.7 degrees at
        // 12 mm, their transitions planned within 56.8).
        let far = |p: &scallop_geom::Point3| (p.x - cx).hypot(p.y - cy) >= 12.0;
        let moves = plan.toolpath.moves();
        let mut joined = 0usize;
        for (i, w) in moves.windows(2).enumerate() {
            let (from, m) = (&w[0].to, &w[1]);
            if m.to.z > -0.5 || from.z > -0.5 || !far(from) || !far(&m.to) {
                continue;
            }
            let length = (m.to.x - from.x).hypot(m.to.y - from.y);
            prop_assert!(
                m.kind != MoveKind::Link || length <= 1e-6,
                "move {}: a link {length:.3} mm long across a band", i + 1
            );
            let phi = report.move_phi[i + 1];
            prop_assert!(phi <= 1.1 * target, "move {} to {:?}: {:.1} deg", i + 1, m.to, phi.to_degrees());
            joined += 1;
        }
        prop_assert!(joined > 0, "no move away from the innermost rings");
    }
}
