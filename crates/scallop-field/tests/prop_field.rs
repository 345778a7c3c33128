//! Property tests of the field engine: random spheres and offsets keep the
//! h / 2 bound and watertightness; the side test agrees with the geometry;
//! the block-skipping distance field equals brute force inside the band.

#![allow(clippy::unwrap_used, reason = "tests")]

mod common;

use common::{brute_distance, open_and_nonmanifold_edges, sphere};
use proptest::prelude::*;
use scallop_field::{Grid, LevelOptions, Side, Surface, distance_field, offset_levels, tol};
use scallop_geom::{Point3, Vec3};

proptest! {
    #![proptest_config(ProptestConfig { cases: 8, ..ProptestConfig::default() })]

    /// The two sheets of the unsigned offset (at r - d and r + d) stay apart
    /// when 2 d >= 2 sqrt(3) h (docs/guides.md, "Accuracy"): d >= 1.8 for h <= 1.
    #[test]
    fn random_sphere_offsets_stay_within_half_a_voxel(
        r in 2.0f64..6.0,
        d in 1.8f64..3.0,
        cx in -50.0f64..50.0,
        cy in -50.0f64..50.0,
        h in prop::sample::select(vec![1.0, 0.5]),
    ) {
        let mesh = sphere(r, 2).translated(&Vec3::new(cx, cy, 0.0));
        let options = LevelOptions { voxel: h, side: Side::Along, ..LevelOptions::default() };
        let level = offset_levels(&Surface::new(&mesh), &[d], &options).unwrap();
        for v in level[0].vertices() {
            let e = brute_distance(v, &mesh) - d;
            prop_assert!(e.abs() <= 0.5 * h, "{v:?}: {e}");
        }
        prop_assert_eq!(open_and_nonmanifold_edges(&level[0]), (0, 0));
    }

    #[test]
    fn side_matches_inside_and_outside_of_a_sphere(x in -8.0f64..8.0, y in -8.0f64..8.0, z in -8.0f64..8.0) {
        let mesh = sphere(5.0, 2);
        let p = Point3::new(x, y, z);
        let d = brute_distance(&p, &mesh);
        prop_assume!(d > 1e-6);
        let side = Surface::new(&mesh).side(&p);
        // The mesh is inscribed in the sphere: the sphere decides away from it.
        let r = p.coords.norm();
        if r > 5.0 {
            prop_assert!(side > 0.0);
        } else if r < 4.5 {
            prop_assert!(side < 0.0);
        }
    }

    #[test]
    fn band_field_equals_brute_force_where_computed(r in 2.0f64..5.0, cutoff in 0.5f64..3.0) {
        let mesh = sphere(r, 1);
        let surface = Surface::new(&mesh);
        let grid = Grid::around(&mesh.bounds(), cutoff + 1.0, 0.7, tol::DEFAULT_MAX_SAMPLES).unwrap();
        let field = distance_field(&surface, grid, cutoff);
        let [nx, ny, nz] = grid.dims();
        for k in (0..nz).step_by(3) {
            for j in (0..ny).step_by(3) {
                for i in (0..nx).step_by(3) {
                    let exact = brute_distance(&grid.point(i, j, k), &mesh);
                    let v = field.value(i, j, k);
                    if exact <= cutoff {
                        prop_assert!((v - exact).abs() <= 1e-9 * (1.0 + exact), "{v} vs {exact}");
                    } else {
                        prop_assert!(v > cutoff);
                    }
                }
            }
        }
    }
}
