//! Generated parts and cutter shapes shared by the tests and benches
//! (benches include this file by path).

#![allow(dead_code, reason = "each test or bench binary uses a subset")]

use scallop_geom::Point3;

/// The height field `z = f(x, y)` over `[0, size]^2` as a triangle soup: `n x n`
/// cells, two triangles each, split along the diagonal from `(i, j)` to `(i + 1, j + 1)`.
pub fn height_field(size: f64, n: u32, f: impl Fn(f64, f64) -> f64) -> Vec<[Point3; 3]> {
    let s = |i: u32| size * f64::from(i) / f64::from(n);
    let q = |i: u32, j: u32| Point3::new(s(i), s(j), f(s(i), s(j)));
    let mut soup = Vec::new();
    for i in 0..n {
        for j in 0..n {
            soup.push([q(i, j), q(i + 1, j), q(i + 1, j + 1)]);
            soup.push([q(i, j), q(i + 1, j + 1), q(i, j + 1)]);
        }
    }
    soup
}

/// Every cutter shape with its radius in `radius`, the bull-nose corner a
/// fraction `corner` of the radius and the cone's half angle in `half_angle` (rad).
pub fn shapes(
    radius: std::ops::Range<f64>,
    corner: std::ops::Range<f64>,
    half_angle: std::ops::Range<f64>,
) -> impl proptest::strategy::Strategy<Value = scallop_cutter::CutterShape> {
    use proptest::prelude::*;
    use scallop_cutter::CutterShape;
    prop_oneof![
        radius.clone().prop_map(|radius| CutterShape::Flat { radius }),
        radius.clone().prop_map(|radius| CutterShape::Ball { radius }),
        (radius.clone(), corner).prop_map(|(radius, k)| CutterShape::Bull { radius, corner: k * radius }),
        (radius, half_angle).prop_map(|(radius, half_angle)| CutterShape::Cone { radius, half_angle }),
    ]
}
