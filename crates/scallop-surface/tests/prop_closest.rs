//! Closest point: recovery of offset points (property), edges and corners, and a
//! brute-force oracle.

mod common;

use common::{builtin_patch, p, quarter_cylinder, rational_nurbs};
use proptest::prelude::*;
use scallop_geom::rng::SplitMix64;
use scallop_geom::{Point3, assert_near};
use scallop_surface::Patch;

/// `P = S(u0, v0) + d N(u0, v0)` must give back `(u0, v0)` and `|d|`.
fn check_recovery(patch: &Patch, s: f64, t: f64, d: f64) -> Result<(), TestCaseError> {
    let (u0, v0) = patch.domain().lerp(s, t);
    let query = patch.point(u0, v0) + patch.normal(u0, v0) * d;
    let c = patch.closest_point(&query);
    let width = patch.domain().u[1] - patch.domain().u[0];
    prop_assert!((c.u - u0).abs() <= 1e-8 * width, "{}: u {} vs {u0} (d = {d})", patch.name(), c.u);
    prop_assert!((c.v - v0).abs() <= 1e-8 * width, "{}: v {} vs {v0} (d = {d})", patch.name(), c.v);
    prop_assert!((c.distance - d.abs()).abs() <= 1e-9, "{}: distance {} vs {}", patch.name(), c.distance, d.abs());
    prop_assert!((c.point - patch.point(c.u, c.v)).norm() == 0.0);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn choi_recovers_offset_points(s in 0.02..0.98f64, t in 0.02..0.98f64, d in -4.0..4.0f64) {
        check_recovery(&builtin_patch("choi"), s, t, d)?;
    }

    #[test]
    fn rubio_recovers_offset_points(s in 0.02..0.98f64, t in 0.02..0.98f64, d in -4.0..4.0f64) {
        check_recovery(&builtin_patch("rubio"), s, t, d)?;
    }

    #[test]
    fn cylinder_recovers_offset_points(s in 0.02..0.98f64, t in 0.02..0.98f64, d in -8.0..8.0f64) {
        // Radius 12: any point closer to the surface than the axis projects radially.
        check_recovery(&quarter_cylinder(12.0, 30.0), s, t, d)?;
    }

    #[test]
    fn rational_nurbs_recovers_offset_points(s in 0.05..0.95f64, t in 0.05..0.95f64, d in -1.0..1.0f64) {
        check_recovery(&rational_nurbs(), s, t, d)?;
    }
}

#[test]
fn points_beyond_edges_and_corners_project_onto_them() {
    let square = Patch::bezier(
        "square",
        [1, 1],
        &[vec![p(0., 0., 0.), p(0., 20., 0.)], vec![p(10., 0., 0.), p(10., 20., 0.)]],
        None,
    )
    .expect("valid");
    // Beyond the edge u = 1.
    let c = square.closest_point(&p(13., 5., 4.));
    assert_near!(c.u, 1.0, 0.0);
    assert_near!(c.v, 0.25, 1e-12);
    assert_near!(c.distance, 5.0, 1e-12);
    // Beyond the corner (0, 1).
    let c = square.closest_point(&p(-3., 24., 0.));
    assert_eq!((c.u, c.v), (0.0, 1.0));
    assert_near!(c.distance, 5.0, 1e-12);

    // A curved edge: beyond the end of the quarter cylinder (v = 1, z = h), the
    // nearest point lies on the top circle, radially.
    let cylinder = quarter_cylinder(12.0, 30.0);
    let q = p(20.0 * 0.6, 20.0 * 0.8, 37.0);
    let c = cylinder.closest_point(&q);
    assert_near!(c.v, 1.0, 0.0);
    assert_near!(c.point.x, 12.0 * 0.6, 1e-9);
    assert_near!(c.point.y, 12.0 * 0.8, 1e-9);
    assert_near!(c.distance, (64.0_f64 + 49.0).sqrt(), 1e-9);
}

/// The result is never farther than the nearest of a dense sample grid (so it is
/// the global minimum up to the grid's resolution), and satisfies the first-order
/// conditions: (S - P) . Su = 0 unless u is on a bound (then the gradient points out).
#[test]
fn closest_point_beats_dense_sampling_and_is_stationary() {
    let mut rng = SplitMix64::new(7);
    for patch in [builtin_patch("choi"), builtin_patch("rubio"), rational_nurbs()] {
        let bounds = patch.bounds();
        let n = 120;
        let domain = patch.domain();
        let samples: Vec<Point3> = (0..=n)
            .flat_map(|a| (0..=n).map(move |b| (a, b)))
            .map(|(a, b)| {
                let (u, v) = domain.lerp(f64::from(a) / f64::from(n), f64::from(b) / f64::from(n));
                patch.point(u, v)
            })
            .collect();
        for _ in 0..40 {
            let q = p(
                rng.uniform(bounds.min.x - 15.0, bounds.max.x + 15.0),
                rng.uniform(bounds.min.y - 15.0, bounds.max.y + 15.0),
                rng.uniform(bounds.min.z - 15.0, bounds.max.z + 15.0),
            );
            let c = patch.closest_point(&q);
            let brute = samples.iter().map(|s| (s - q).norm()).fold(f64::INFINITY, f64::min);
            assert!(c.distance <= brute + 1e-9, "{}: {q:?}: {} > sampled {brute}", patch.name(), c.distance);
            let d = patch.derivatives(c.u, c.v);
            let r = d.point - q;
            let scale = r.norm() * d.du.norm().max(d.dv.norm()) + 1e-300;
            for (g, t, [lo, hi]) in [(d.du.dot(&r), c.u, domain.u), (d.dv.dot(&r), c.v, domain.v)] {
                let on_low = t <= lo && g >= 0.0;
                let on_high = t >= hi && g <= 0.0;
                assert!(on_low || on_high || g.abs() <= 1e-9 * scale, "{}: {q:?}: gradient {g} at {t}", patch.name());
            }
        }
    }
}
