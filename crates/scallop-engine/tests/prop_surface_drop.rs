//! Drop-cutter on parametric surfaces through their tessellation: the error
//! against the true surface stays within the budgeted chordal tolerance.

use proptest::prelude::*;
use scallop_cutter::{Contact, Cutter, CutterShape, drop_cutter};
use scallop_engine::{Part, prepare_part};
use scallop_geom::{Point2, Point3, Tolerances};

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// A ball dropped on the tessellated Choi or Rubio surface neither gouges the
    /// true surface nor floats above it by more than the tessellation bound:
    /// the distance from the ball's centre to the surface is R within the bound.
    #[test]
    fn ball_on_tessellation_is_within_the_chordal_budget(
        which in 0usize..2, u in 0.2f64..0.8, v in 0.2f64..0.8, radius in 1.0f64..5.0
    ) {
        let name = ["choi", "rubio"][which];
        let part = Part::builtin(name).expect("built-in");
        let Part::Surfaces(set) = &part else { unreachable!("built-ins are surfaces") };
        let tol = Tolerances { path: 0.02, gouge: 0.0 };
        let prepared = prepare_part(&part, &tol).expect("prepare");
        prop_assert!(prepared.chordal_error <= tol.tessellation() * (1.0 + 1e-9));
        // A point well inside the part's XY extent.
        let b = prepared.mesh.bounds();
        let xy = Point2::new(b.min.x + u * (b.max.x - b.min.x), b.min.y + v * (b.max.y - b.min.y));
        let cutter = Cutter::new(CutterShape::Ball { radius }, 5.0 * radius).expect("cutter");
        let cl = drop_cutter(&cutter, &prepared.index, xy, b.min.z - 100.0);
        prop_assume!(!matches!(cl.contact, Contact::Floor));
        let center = Point3::new(cl.tip.x, cl.tip.y, cl.tip.z + radius);
        let (_, closest) = set.closest_point(&center);
        let slack = 1e-7;
        prop_assert!(closest.distance >= radius - prepared.chordal_error - slack,
            "{name}: gouge: centre {} from the surface, R = {radius}, bound {}", closest.distance, prepared.chordal_error);
        prop_assert!(closest.distance <= radius + prepared.chordal_error + slack,
            "{name}: floats: centre {} from the surface, R = {radius}, bound {}", closest.distance, prepared.chordal_error);
    }
}
