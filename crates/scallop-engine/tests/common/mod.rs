//! Geometry shared by the engine's integration tests.

use scallop_geom::Point3;
use scallop_mesh::TriMesh;

/// Closed boxes given by their (min, max) corners, as one mesh: each box's
/// 12 triangles from its 8 corners (corner bit i: x, y, z high).
#[allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]
pub fn boxes_mesh(boxes: &[([f64; 3], [f64; 3])]) -> TriMesh {
    const FACES: [[usize; 4]; 6] = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let mut soup = Vec::new();
    for &(lo, hi) in boxes {
        let corner = |i: usize| {
            let pick = |k: usize| if i >> k & 1 == 1 { hi[k] } else { lo[k] };
            Point3::new(pick(0), pick(1), pick(2))
        };
        for f in FACES {
            soup.push([corner(f[0]), corner(f[1]), corner(f[2])]);
            soup.push([corner(f[0]), corner(f[2]), corner(f[3])]);
        }
    }
    TriMesh::from_soup(&soup).unwrap().0
}
