//! The main job (finishing.md 14.3, 13): the Choi surface with a
//! bull-nose R = 5, r = 2 mm along the steepest-slope direction of its PCA plane,
//! sh = 0.01 mm, V = 5 m/min, A = 6 m/s^2, J = 40 m/s^3.
#![allow(clippy::unwrap_used)]

mod common;

use common::{bull, choi_analysed, params};
use scallop_analysis::Recommendation;
use scallop_geom::Tolerances;
use scallop_strategy::{Pattern, plan_finishing};

#[test]
fn choi_bull_nose_along_the_steepest_slope() {
    let tol = Tolerances { path: 0.01, gouge: 0.0 };
    let (index, analysis) = choi_analysed(&tol);
    assert_eq!(analysis.recommendation, Recommendation::ToroidalAlongSlope);
    let p = params(analysis.slope_direction_deg.to_radians(), Pattern::Zigzag, 0.01, 0.5);
    let planned = plan_finishing(&index, &bull(5.0, 2.0), &p, &tol).unwrap();
    let r = &planned.report;
    assert!(r.max_scallop_mm <= 0.01 && r.max_scallop_mm > 0.009, "{r:?}");
    assert_eq!(r.retracts, 0, "{r:?}");
    // The PCA-rectangle estimate (Eq. 2.4) is a lower bound of sorts: the real
    // surface is curved and its worst points set the spacing.
    let estimate = analysis.toroidal_along_slope.estimate;
    assert!(r.machining_time_s > estimate.time && r.machining_time_s < 2.0 * estimate.time, "{r:?} vs {estimate:?}");
    assert!(r.machining_time_lookahead_s > 0.0 && r.rapid_time_s > 0.0);
}
