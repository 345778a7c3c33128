//! The network planner on inclined rectangular planes (finishing.md 14.1, 8.2,
//! 8.3): path length and time against the analytic plane formulas, the
//! worst-point rule's pass count, and a 3+2 orientation that makes the plane
//! horizontal.
#![allow(clippy::unwrap_used)]

mod network_common;

use std::f64::consts::{FRAC_PI_2, PI};

use network_common::{inclined_plane, params, rel, spacing_at};
use proptest::prelude::*;
use scallop_analysis::{Cutter, FeedDirection, MachineLimits, Rectangle, plane_time};
use scallop_geom::{Point3, Vec3};
use scallop_network::{Margins, Network, Orientation, Transitions, plan_zone, surface_time};

const TORUS: Cutter = Cutter::Toroidal { radius: 5.0, corner: 2.0 };
const BALL: Cutter = Cutter::Ball { radius: 5.0 };

/// Length and time of `n` passes of `pass` mm joined by connections of total
/// length `extent - sod` (half-step margins: the first and last planes half a
/// step inside), `n - 2` of them `sod` long: the analytic formulas of 8.2 and
/// 8.3 at the integer pass count.
fn integer_count(n: f64, pass: f64, extent: f64, sod: f64, machine: &MachineLimits) -> (f64, f64) {
    let last = extent - sod - (n - 2.0) * sod;
    let length = n * pass + extent - sod;
    let time = n * machine.segment_time(pass) + (n - 2.0) * machine.segment_time(sod) + machine.segment_time(last);
    (length, time)
}

#[test]
fn toroidal_along_slope_matches_t1_l1() {
    let network = Network::new(&inclined_plane(56.0, 28.0, 60f64.to_radians()), 0.5).unwrap();
    let plan = plan_zone(&network, None, 0, &params(0.0, TORUS, 0.01)).unwrap();
    let rect = Rectangle { width: 56.0, height: 28.0, slope: 60f64.to_radians() };
    let machine = MachineLimits::default();
    let analytic = plane_time(&rect, &TORUS, FeedDirection::SteepestSlope, 0.01, &machine);
    assert_eq!(plan.passes, (56.0 / analytic.step_over).ceil() as usize); // 85 for 84.7
    let length = plan.cut_length_mm + plan.link_length_mm;
    assert!(rel(length, analytic.length) < 0.005, "{length} vs {}", analytic.length);
    assert!(rel(plan.time_s, analytic.time) < 0.005, "{} vs {}", plan.time_s, analytic.time);
    let whole = surface_time(std::slice::from_ref(&plan), &Transitions::default(), &machine);
    assert!((whole.total_s - plan.time_s).abs() < 1e-12 && (whole.length_mm - length).abs() < 1e-9);
}

#[test]
fn ball_along_principal_matches_t2_l2_at_the_integer_pass_count() {
    let network = Network::new(&inclined_plane(56.0, 28.0, 60f64.to_radians()), 0.5).unwrap();
    let plan = plan_zone(&network, None, 0, &params(FRAC_PI_2, BALL, 0.01)).unwrap();
    let rect = Rectangle { width: 56.0, height: 28.0, slope: 60f64.to_radians() };
    let machine = MachineLimits::default();
    let analytic = plane_time(&rect, &BALL, FeedDirection::Principal, 0.01, &machine);
    let n = (28.0 / analytic.step_over).ceil(); // 45 for 44.3
    assert_eq!(plan.passes, n as usize);
    let (length, time) = integer_count(n, 56.0, 28.0, analytic.step_over, &machine);
    let planned = plan.cut_length_mm + plan.link_length_mm;
    assert!(rel(planned, length) < 0.005, "{planned} vs {length}");
    assert!(rel(plan.time_s, time) < 0.005, "{} vs {time}", plan.time_s);
    // Against the real-valued count the gap is the fractional pass (1.6 %).
    assert!(rel(planned, analytic.length) < 0.02);
}

#[test]
fn spec_margins_add_the_final_plane() {
    let network = Network::new(&inclined_plane(56.0, 28.0, 60f64.to_radians()), 0.5).unwrap();
    let mut p = params(0.0, TORUS, 0.01);
    p.margins = Margins::Fixed { start: 0.0, end: 0.0 };
    let plan = plan_zone(&network, None, 0, &p).unwrap();
    let sod = TORUS.step_over(0.01, 60f64.to_radians(), 0.0);
    // Planes at 0, sod, ..., 84 sod, then d_max (residual 0.73 sod > sod / 2).
    assert_eq!(plan.passes, (56.0 / sod).floor() as usize + 2);
    assert!((plan.planes[0].offset - plan.planes[0].passes[0].points[0].y).abs() < 1e-6);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Along the slope (torus) or the principal direction (ball), any rectangle:
    /// `ceil(width / sod)` passes and the analytic length and time at that count
    /// within 0.5 %.
    #[test]
    fn rectangles_match_the_analytic_model(
        width in 20.0f64..90.0,
        height in 20.0f64..60.0,
        slope_deg in 5.0f64..75.0,
        ball in any::<bool>(),
    ) {
        let slope = slope_deg.to_radians();
        let network = Network::new(&inclined_plane(width, height, slope), 0.5).unwrap();
        let (tool, theta, feed, extent, pass) = if ball {
            (BALL, FRAC_PI_2, FeedDirection::Principal, height, width)
        } else {
            (TORUS, 0.0, FeedDirection::SteepestSlope, width, height)
        };
        let machine = MachineLimits::default();
        let rect = Rectangle { width, height, slope };
        let sod = plane_time(&rect, &tool, feed, 0.01, &machine).step_over;
        let n = (extent / sod).ceil();
        prop_assume!(n - extent / sod > 1e-6 && n >= 3.0);
        let plan = plan_zone(&network, None, 0, &params(theta, tool, 0.01)).unwrap();
        prop_assert_eq!(plan.passes, n as usize);
        let (length, time) = integer_count(n, pass, extent, sod, &machine);
        let planned = plan.cut_length_mm + plan.link_length_mm;
        prop_assert!(rel(planned, length) < 0.005, "{} vs {}", planned, length);
        prop_assert!(rel(plan.time_s, time) < 0.005, "{} vs {}", plan.time_s, time);
    }

    /// The worst-point rule on a plane at any feed direction: every gap is the
    /// constant `sod sqrt(1 - (n . m)^2)`, and the plane count is the extent
    /// along `m` over it, rounded up.
    #[test]
    fn plane_spacing_is_the_rule_at_any_direction(
        slope_deg in 3.0f64..70.0,
        theta in 0.0f64..PI,
        ball in any::<bool>(),
    ) {
        let slope = slope_deg.to_radians();
        let patch = inclined_plane(40.0, 30.0, slope);
        let network = Network::new(&patch, 1.0).unwrap();
        let tool = if ball { BALL } else { TORUS };
        let n = Vec3::new(-slope.sin(), 0.0, slope.cos());
        let delta = spacing_at(&n, theta, &tool, 0.01);
        let m = Vec3::new(-theta.sin(), theta.cos(), 0.0);
        let corners = [(0., 0.), (0., 1.), (1., 0.), (1., 1.)].map(|(u, v)| patch.point(u, v).coords.dot(&m));
        let extent = corners.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
            - corners.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        let count = (extent / delta).ceil();
        prop_assume!(count - extent / delta > 1e-6 && count >= 3.0);
        let plan = plan_zone(&network, None, 0, &params(theta, tool, 0.01)).unwrap();
        prop_assert_eq!(plan.planes.len(), count as usize);
        for w in plan.planes.windows(2).take(plan.planes.len() - 2) {
            prop_assert!(rel(w[1].offset - w[0].offset, delta) < 1e-9);
        }
    }

    /// 3+2 (finishing.md 4.5): orienting an inclined plane so that its normal is
    /// the tool axis gives the plan of the same rectangle lying flat.
    #[test]
    fn oriented_plane_plans_as_the_horizontal_plane(
        slope_deg in 5.0f64..80.0,
        theta in 0.0f64..PI,
        ball in any::<bool>(),
    ) {
        let slope = slope_deg.to_radians();
        let tool = if ball { BALL } else { TORUS };
        let tilted = Network::new(&inclined_plane(50.0, 30.0, slope), 1.0).unwrap();
        // Tool axis = the plane's normal (-sin s, 0, cos s): tilt s, azimuth pi.
        let orientation = Orientation::new(slope, PI, Point3::new(1.0, 2.0, 3.0));
        let axis = orientation.tool_axis();
        prop_assert!((axis - Vec3::new(-slope.sin(), 0.0, slope.cos())).norm() < 1e-12);
        let oriented = tilted.oriented(&orientation);
        prop_assert!(oriented.normals().iter().all(|n| (n - Vec3::z()).norm() < 1e-12));
        let flat = Network::new(&inclined_plane(50.0, 30.0, 0.0), 1.0).unwrap();
        let a = plan_zone(&oriented, None, 0, &params(theta, tool, 0.01)).unwrap();
        let b = plan_zone(&flat, None, 0, &params(theta, tool, 0.01)).unwrap();
        prop_assert_eq!(a.passes, b.passes);
        prop_assert!(rel(a.cut_length_mm, b.cut_length_mm) < 1e-9);
        prop_assert!(rel(a.time_s, b.time_s) < 1e-9);
        // Start and end are reported in the part frame: on the tilted plane.
        let n = Vec3::new(-slope.sin(), 0.0, slope.cos());
        prop_assert!(a.start.coords.dot(&n).abs() < 1e-9 && a.end.coords.dot(&n).abs() < 1e-9);
    }
}

#[test]
fn planning_is_deterministic() {
    let set = scallop_surface::builtin("rubio").unwrap();
    let network = Network::new(&set.patches()[0], 0.5).unwrap();
    let p = params(0.3, TORUS, 0.01);
    assert_eq!(plan_zone(&network, None, 0, &p).unwrap(), plan_zone(&network, None, 0, &p).unwrap());
}
