//! Generated meshes shared by the drop-cutter bench and the profiling example
//! (which includes this file by path).

#![allow(dead_code, reason = "the example uses only the terrain")]

use scallop_geom::Point3;
use scallop_mesh::{MeshIndex, TriMesh};

/// The indexed mesh of `f` over the unit square: `n x n` cells, two triangles each.
pub fn grid_mesh(n: u32, f: impl Fn(f64, f64) -> Point3) -> MeshIndex {
    let mut soup = Vec::new();
    let s = |i: u32| f64::from(i) / f64::from(n);
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (f(s(i), s(j)), f(s(i + 1), s(j)), f(s(i), s(j + 1)), f(s(i + 1), s(j + 1)));
            soup.push([a, b, c]);
            soup.push([b, d, c]);
        }
    }
    let (mesh, _) = TriMesh::from_soup(&soup).expect("generated mesh is valid");
    MeshIndex::build(&mesh)
}

/// `dense_freeform`: a wavy 100 x 100 mm terrain of 45,000 triangles.
pub fn terrain() -> MeshIndex {
    grid_mesh(150, |u, v| {
        let (x, y) = (100.0 * u, 100.0 * v);
        Point3::new(x, y, 5.0 * (x * 0.13).sin() * (y * 0.09).cos() + 2.0 * (0.31 * x + 0.17 * y).sin())
    })
}
