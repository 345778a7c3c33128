//! Shared fixtures and oracles of the integration tests.
#![allow(dead_code)]

use scallop_geom::{Point3, Vec3};
use scallop_surface::{Patch, SurfaceSet, builtin};

pub fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

/// The single patch of a built-in set.
pub fn builtin_patch(name: &str) -> Patch {
    builtin(name).expect("built-in exists").into_patches().remove(0)
}

/// Quarter cylinder of radius `r` and height `h` around the z axis, from +x (u = 0)
/// to +y (u = 1): rational quadratic in u (weights 1, sqrt(2)/2, 1), linear in v.
pub fn quarter_cylinder(r: f64, h: f64) -> Patch {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    Patch::bezier(
        "cylinder",
        [2, 1],
        &[vec![p(r, 0., 0.), p(r, 0., h)], vec![p(r, r, 0.), p(r, r, h)], vec![p(0., r, 0.), p(0., r, h)]],
        Some(&[vec![1.0, 1.0], vec![w, w], vec![1.0, 1.0]]),
    )
    .expect("valid cylinder")
}

/// Rubio written as a NURBS patch: each u-column split at u = 1/2 by de Casteljau,
/// knots [0, 0, 0, 1/2, 1/2, 1, 1, 1] (a double interior knot). Same surface.
pub fn rubio_split_as_nurbs() -> Patch {
    let rubio = builtin_patch("rubio");
    let mut rows: Vec<Vec<Point3>> = vec![Vec::new(); 5];
    for j in 0..3 {
        let [a, b, c] = [0, 1, 2].map(|i| rubio.control_point(i, j).coords);
        let ab = (a + b) * 0.5;
        let bc = (b + c) * 0.5;
        let mid = (ab + bc) * 0.5;
        for (row, q) in rows.iter_mut().zip([a, ab, mid, bc, c]) {
            row.push(Point3::from(q));
        }
    }
    Patch::nurbs(
        "rubio-split",
        [2, 2],
        [vec![0., 0., 0., 0.5, 0.5, 1., 1., 1.], vec![0., 0., 0., 1., 1., 1.]],
        &rows,
        None,
    )
    .expect("valid split")
}

/// A rational bicubic NURBS patch with interior knots, unclamped in v, on the domain
/// [1, 3] x [knot range]; wavy and not too curved.
pub fn rational_nurbs() -> Patch {
    let (rows, columns) = (6, 5);
    let control: Vec<Vec<Point3>> = (0..rows)
        .map(|i| {
            (0..columns)
                .map(|j| {
                    let (x, y) = (10.0 * i as f64, 8.0 * j as f64);
                    p(x, y, 3.0 * ((i * 7 + j * 3) % 5) as f64)
                })
                .collect()
        })
        .collect();
    let weights: Vec<Vec<f64>> =
        (0..rows).map(|i| (0..columns).map(|j| 0.6 + 0.2 * ((i + 2 * j) % 4) as f64).collect()).collect();
    let knots_u = vec![1., 1., 1., 1., 1.5, 2.25, 3., 3., 3., 3.];
    let knots_v = vec![0., 0.5, 1., 2., 3., 4., 5., 5.5, 6.]; // unclamped, degree 3: domain [2, 4]
    Patch::nurbs("wavy", [3, 3], [knots_u, knots_v], &control, Some(&weights)).expect("valid NURBS")
}

pub fn set_of(patches: Vec<Patch>) -> SurfaceSet {
    SurfaceSet::new(patches).expect("valid set")
}

/// Distance from `q` to triangle `abc`.
pub fn point_triangle_distance(q: &Point3, t: [Point3; 3]) -> f64 {
    (q - scallop_mesh::closest_on_triangle(q, &t)).norm()
}

/// `|a - b| <= tol * max(1, |b|)`, with a message naming `what`.
pub fn assert_vec_near(a: &Vec3, b: &Vec3, tol: f64, what: &str) {
    let scale = b.norm().max(1.0);
    assert!((a - b).norm() <= tol * scale, "{what}: {a:?} vs {b:?} (|diff| = {:e}, scale {scale})", (a - b).norm());
}
