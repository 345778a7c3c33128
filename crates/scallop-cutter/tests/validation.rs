//! Issue 21: cutter sizes outside the physical range are refused on construction, with
//! the size named (a 1e308 or 1e12 mm diameter once reached the planner and the stock).

#![allow(clippy::float_cmp, reason = "the bounds are compared exactly")]

use scallop_cutter::{Cutter, CutterError, CutterShape, HolderSegment, tol};

#[test]
fn absurd_sizes_are_refused_with_the_range() {
    for radius in [5e307, 5e11, 5e5, tol::MAX_RADIUS * 1.000_001, tol::MIN_RADIUS * 0.5] {
        for shape in [
            CutterShape::Ball { radius },
            CutterShape::Flat { radius },
            CutterShape::Bull { radius, corner: (radius / 2.0).min(1.0) },
            CutterShape::Cone { radius, half_angle: 0.5 },
        ] {
            match Cutter::new(shape, 30.0) {
                Err(CutterError::OutOfRange { what: "cutter radius", value, min, max }) => {
                    assert_eq!(value.to_bits(), radius.to_bits());
                    assert!(min == tol::MIN_RADIUS && max == tol::MAX_RADIUS);
                }
                other => panic!("{shape:?}: {other:?}"),
            }
        }
    }
    // The ends of the range are real cutters.
    assert!(Cutter::new(CutterShape::Flat { radius: tol::MAX_RADIUS }, 100.0).is_ok());
    assert!(Cutter::new(CutterShape::Ball { radius: tol::MIN_RADIUS }, 1.0).is_ok());
    // Lengths.
    let ball = CutterShape::Ball { radius: 3.0 };
    assert!(matches!(Cutter::new(ball, 1e9), Err(CutterError::OutOfRange { what: "flute length", .. })));
    let c = Cutter::new(ball, 30.0).expect("ball");
    assert!(c.clone().with_shank(3.0, 1e308).is_err());
    let huge = HolderSegment { length: 10.0, bottom_radius: 1e300, top_radius: 10.0 };
    assert!(c.with_holder(vec![huge]).is_err());
}
