//! The built-in test surfaces against the derived values of finishing.md 14.2 and 14.3.

mod common;

use common::builtin_patch;
use scallop_geom::nalgebra::{Matrix3, SymmetricEigen};
use scallop_geom::{Point3, assert_near};
use scallop_surface::{BUILTIN_NAMES, builtin};

#[test]
fn every_builtin_name_resolves_to_one_patch_of_that_name() {
    for name in BUILTIN_NAMES {
        let set = builtin(name).expect("exists");
        assert_eq!(set.len(), 1);
        assert_eq!(set.patches()[0].name(), name);
        assert!(set.get(name).is_some());
    }
    assert!(builtin("Choi").is_none());
}

#[test]
fn table_reading_rule_i_is_the_u_index() {
    // P_ij with i along u: S(1, 0) = P_20 and S(0, 1) = P_02 (corners interpolate).
    let rubio = builtin_patch("rubio");
    assert_eq!(rubio.degree(), [2, 2]);
    assert_eq!(rubio.point(1.0, 0.0), Point3::new(80.0, -28.17, 2.46));
    assert_eq!(rubio.point(0.0, 1.0), Point3::new(0.0, 15.32, 12.85));
    let choi = builtin_patch("choi");
    assert_eq!(choi.degree(), [3, 3]);
    assert_eq!(choi.point(1.0, 0.0), Point3::new(56.02, 0.0, 19.25));
    assert_eq!(choi.point(0.0, 1.0), Point3::new(7.92, 61.2, 37.26));
}

fn assert_box(name: &str, min: [f64; 3], max: [f64; 3]) {
    let b = builtin(name).expect("exists").bounds();
    for k in 0..3 {
        assert_near!(b.min[k], min[k], 0.01);
        assert_near!(b.max[k], max[k], 0.01);
    }
    // The tight box lies inside the control-net box.
    let c = builtin_patch(name).control_bounds();
    for k in 0..3 {
        assert!(c.min[k] <= b.min[k] + 1e-12 && b.max[k] <= c.max[k] + 1e-12, "{name} axis {k}: {b:?} vs {c:?}");
    }
}

#[test]
fn bounding_boxes_match_the_spec() {
    assert_box("rubio", [0.0, -28.17, -12.85], [80.0, 15.32, 28.17]);
    assert_box("choi", [6.73, 0.0, 13.66], [56.02, 61.2, 37.26]);
    // The interior extremes of Choi in closed form: x on u = 0 and z on u = 1 at v = 1/2.
    let b = builtin_patch("choi").bounds();
    assert_near!(b.min.x, (2.0 * 7.92 + 6.0 * 6.33) / 8.0, 1e-12);
    assert_near!(b.min.z, (2.0 * 19.25 + 6.0 * 11.79) / 8.0, 1e-12);
}

#[test]
fn areas_match_the_spec() {
    for (name, expected) in [("rubio", 3494.0), ("choi", 3241.0)] {
        let set = builtin(name).expect("exists");
        let area = set.area();
        assert!((area - expected).abs() <= 0.005 * expected, "{name}: area {area} vs {expected}");
        // The quadrature agrees with a fine tessellation (chordal error 1 micron).
        let mesh_area = set.tessellate(0.001).expect("tessellates").mesh.area();
        assert!((mesh_area - area).abs() <= 1e-4 * area, "{name}: mesh {mesh_area} vs {area}");
    }
}

/// Eigenvalues (descending) of the population covariance of S at the 80 x 80 cell
/// centres, the convention of finishing.md 0.3 / 14.2.
fn pca(name: &str) -> [f64; 3] {
    let patch = builtin_patch(name);
    let n = 80;
    let points: Vec<Point3> = (0..n)
        .flat_map(|a| (0..n).map(move |b| (a, b)))
        .map(|(a, b)| patch.point((f64::from(a) + 0.5) / f64::from(n), (f64::from(b) + 0.5) / f64::from(n)))
        .collect();
    let count = points.len() as f64;
    let mean = points.iter().fold(Point3::origin().coords, |s, p| s + p.coords) / count;
    let mut cov = Matrix3::zeros();
    for q in &points {
        let d = q.coords - mean;
        cov += d * d.transpose();
    }
    cov /= count;
    let mut values: Vec<f64> = SymmetricEigen::new(cov).eigenvalues.iter().copied().collect();
    values.sort_by(|a, b| b.total_cmp(a));
    [values[0], values[1], values[2]]
}

#[test]
fn pca_reproduces_the_published_values_so_the_tables_are_read_right() {
    // finishing.md 14.2 / 14.3, derived values (thesis: 572.62 / 133.31 and 312.07 / 219.02).
    let rubio = pca("rubio");
    assert_near!(rubio[0], 572.61, 0.01);
    assert_near!(rubio[1], 133.23, 0.01);
    assert_near!(rubio[2], 3.56, 0.01);
    let choi = pca("choi");
    assert_near!(choi[0], 312.07, 0.01);
    assert_near!(choi[1], 219.02, 0.01);
    assert_near!(choi[2], 3.21, 0.01);
}
