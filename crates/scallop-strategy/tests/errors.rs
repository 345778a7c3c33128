//! Rejected plans name the parameter and the fix.
#![allow(clippy::unwrap_used)]

mod common;

use common::{ball, bull, inclined_plane, params};
use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::Tolerances;
use scallop_strategy::{Pattern, StrategyError, plan_finishing};

const TOL: Tolerances = Tolerances { path: 0.01, gouge: 0.0 };

/// Breaks one parameter.
type Edit = fn(&mut scallop_strategy::FinishingParams);

#[test]
fn bad_parameters_are_named() {
    let index = inclined_plane(20.0, 10.0, 30.0);
    let cases: [(&str, Edit); 5] = [
        ("scallop_height", |p| p.scallop_height = -0.01),
        ("max_step", |p| p.max_step = 0.0),
        ("clearance", |p| p.clearance = f64::NAN),
        ("machine.jerk", |p| p.machine.jerk = -1.0),
        ("sharp_corner", |p| p.sharp_corner = 4.0),
    ];
    for (name, edit) in cases {
        let mut p = params(0.0, Pattern::Zigzag, 0.01, 0.5);
        edit(&mut p);
        match plan_finishing(&index, &ball(3.0), &p, &TOL) {
            Err(e @ StrategyError::BadParameter { name: n, .. }) => {
                assert_eq!(n, name);
                assert!(e.to_string().contains(name));
            }
            other => panic!("{name}: {other:?}"),
        }
    }
    let bad_tol = Tolerances { path: 0.0, gouge: 0.0 };
    assert!(matches!(
        plan_finishing(&index, &ball(3.0), &params(0.0, Pattern::Zigzag, 0.01, 0.5), &bad_tol),
        Err(StrategyError::BadParameter { name: "tolerances.path", .. })
    ));
}

#[test]
fn scallop_height_must_be_below_the_radius() {
    let index = inclined_plane(20.0, 10.0, 30.0);
    let e = plan_finishing(&index, &ball(3.0), &params(0.0, Pattern::Zigzag, 3.0, 0.5), &TOL).unwrap_err();
    assert!(matches!(e, StrategyError::ScallopTooLarge { .. }), "{e}");
    let e = plan_finishing(&index, &bull(5.0, 0.5), &params(0.0, Pattern::Zigzag, 0.6, 0.5), &TOL).unwrap_err();
    assert!(e.to_string().contains("corner radius"), "{e}");
}

/// A cone (V) cutter feeding down a 30° plane: the section across the feed is
/// level, so the grooves start `2 sh tan(half angle)` apart (conservative: the
/// scallop is measured along the normal); the measured scallop holds and the
/// pass count is the width over that spacing.
#[test]
fn cone_cutters_plan_at_the_v_spacing() {
    let (width, half_angle, sh) = (20.0, 0.5_f64, 0.05);
    let index = inclined_plane(width, 10.0, 30.0);
    let cone = Cutter::new(CutterShape::Cone { radius: 3.0, half_angle }, 20.0).unwrap();
    let planned = plan_finishing(&index, &cone, &params(0.0, Pattern::Zigzag, sh, 0.5), &TOL).unwrap();
    let r = &planned.report;
    // Measured along the normal: the level ridge's height times cos 30° (0.0433 mm).
    assert!(r.max_scallop_mm <= sh && r.max_scallop_mm > 0.75 * sh, "{r:?}");
    let spacing = 2.0 * sh * half_angle.tan();
    #[allow(clippy::cast_precision_loss, reason = "a few hundred passes")]
    let passes = r.passes as f64;
    assert!((passes - width / spacing).abs() <= 2.0, "{passes} passes, {} expected", width / spacing);
}

#[test]
fn a_part_smaller_than_the_step_is_an_empty_region() {
    let index = inclined_plane(0.2, 0.2, 10.0);
    let e = plan_finishing(&index, &ball(3.0), &params(0.0, Pattern::Zigzag, 0.01, 5.0), &TOL).unwrap_err();
    assert!(matches!(e, StrategyError::EmptyRegion { .. }), "{e}");
}

/// finishing.md A19: at 45 degrees to the slope the toroidal cutter's spacing
/// follows the horizontal-angle Eq. 1.5 (4.77 mm), and the scallop holds.
#[test]
fn oblique_feed_keeps_the_scallop() {
    let index = inclined_plane(56.0, 28.0, 60.0);
    let planned =
        plan_finishing(&index, &bull(5.0, 2.0), &params(45f64.to_radians(), Pattern::OneWay, 0.01, 0.5), &TOL).unwrap();
    let s = &planned.scallop;
    assert!(s.max_mm <= 0.01 && s.mean_mm > 0.009, "{s:?}");
    assert_eq!(s.histogram.last(), Some(&0));
    assert!(planned.report.retracts + 1 == planned.report.passes);
}

#[test]
fn work_over_the_budget_is_refused_with_the_estimate() {
    // Issue 21: max_step = 1e-6 mm on a 20 mm part planned for minutes and gigabytes.
    let index = inclined_plane(20.0, 10.0, 30.0);
    let e = plan_finishing(&index, &ball(3.0), &params(0.0, Pattern::Zigzag, 0.01, 1e-6), &TOL).unwrap_err();
    match &e {
        StrategyError::TooMuchWork { passes, samples, estimate, budget, .. } => {
            assert!(*samples > 1.0e7 && *passes >= 1.0, "{e}");
            assert!((*estimate - passes * samples).abs() <= 1e-9 * estimate);
            assert!(estimate > budget);
        }
        other => panic!("{other:?}"),
    }
    assert!(e.to_string().contains("max_step"), "{e}");
    // An ordinary plan is under the budget.
    assert!(plan_finishing(&index, &ball(3.0), &params(0.0, Pattern::Zigzag, 0.01, 0.5), &TOL).is_ok());
    // A path tolerance below 1e-4 mm only multiplies samples.
    let fine = Tolerances { path: 1e-12, gouge: 0.0 };
    assert!(matches!(
        plan_finishing(&index, &ball(3.0), &params(0.0, Pattern::Zigzag, 0.01, 0.5), &fine),
        Err(StrategyError::BadParameter { name: "tolerances.path", .. })
    ));
}
