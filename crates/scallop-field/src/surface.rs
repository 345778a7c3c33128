//! A triangle mesh prepared for distance queries: a bounding-volume hierarchy
//! over its triangles, closest points with the feature they lie on, and the
//! angle-weighted pseudo-normals that tell the side of a point (Baerentzen and
//! Aanaes 2005, "Signed distance computation using the angle weighted
//! pseudonormal", IEEE TVCG 11(3), section 3).

use scallop_geom::{Aabb3, Point3, Vec3};
use scallop_mesh::{Bvh, FastMap, TriMesh, triangle_box};

/// Where on its triangle a closest point lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feature {
    /// Inside the triangle.
    Face,
    /// On edge `k` (corner `k` to corner `k + 1`), not at a corner.
    Edge(u8),
    /// At corner `k`.
    Vertex(u8),
}

/// The closest point of a surface to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    /// The point on the surface.
    pub point: Point3,
    /// Squared distance (mm^2).
    pub dist2: f64,
    /// Triangle number in the mesh.
    pub triangle: usize,
    /// Feature of that triangle.
    pub feature: Feature,
}

/// A triangle mesh with its hierarchy and pseudo-normals.
#[derive(Debug, Clone)]
pub struct Surface {
    mesh: TriMesh,
    bvh: Bvh,
    face_normals: Vec<Vec3>,
    edge_normals: Vec<[Vec3; 3]>,
    vertex_normals: Vec<Vec3>,
}

impl Surface {
    /// Prepares `mesh` (its triangle orientation gives the sides: a point is on
    /// the positive side when it lies where the normals point).
    #[must_use]
    pub fn new(mesh: &TriMesh) -> Surface {
        let boxes: Vec<Aabb3> = (0..mesh.triangles().len()).map(|t| triangle_box(&mesh.triangle(t))).collect();
        let bvh = Bvh::build(&boxes);
        let (face_normals, edge_normals, vertex_normals) = pseudo_normals(mesh);
        Surface { mesh: mesh.clone(), bvh, face_normals, edge_normals, vertex_normals }
    }

    /// The mesh.
    #[must_use]
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// The closest point within `max_dist` (mm; may be infinite), or `None` when
    /// no triangle comes that close.
    #[must_use]
    pub fn closest(&self, p: &Point3, max_dist: f64) -> Option<Closest> {
        let bound = if max_dist.is_finite() { max_dist * max_dist } else { f64::INFINITY };
        // Ties go to the lower triangle number (`Bvh::nearest`), so the
        // feature does not depend on the visiting order.
        let (t, dist2) =
            self.bvh.nearest(p, bound, |t| (closest_on_triangle(p, &self.mesh.triangle(t)).0 - p).norm_squared())?;
        let (point, feature) = closest_on_triangle(p, &self.mesh.triangle(t));
        Some(Closest { point, dist2, triangle: t, feature })
    }

    /// The pseudo-normal of a closest point's feature: the face normal inside a
    /// triangle, the sum of the two face normals on an edge, the angle-weighted
    /// sum at a vertex. `(p - c.point) . n` has the sign of the side of `p`.
    #[must_use]
    pub fn pseudo_normal(&self, c: &Closest) -> Vec3 {
        match c.feature {
            Feature::Face => self.face_normals[c.triangle],
            Feature::Edge(k) => self.edge_normals[c.triangle][k as usize],
            Feature::Vertex(k) => {
                let v = self.mesh.triangles()[c.triangle][k as usize];
                self.vertex_normals[v as usize]
            }
        }
    }

    /// The side of `p`: positive where the normals point, negative behind, zero
    /// on the surface (or when no pseudo-normal decides).
    #[must_use]
    pub fn side(&self, p: &Point3) -> f64 {
        self.side_within(p, f64::INFINITY)
    }

    /// [`Surface::side`] for a point known to lie within `max_dist` (mm) of the
    /// surface (a bounded, faster search); zero when nothing is that close.
    #[must_use]
    pub fn side_within(&self, p: &Point3, max_dist: f64) -> f64 {
        self.closest(p, max_dist).map_or(0.0, |c| (p - c.point).dot(&self.pseudo_normal(&c)))
    }
}

/// Closest point of triangle `t` to `p` and its feature (Ericson 2005,
/// "Real-Time Collision Detection", section 5.1.5: Voronoi regions in turn).
fn closest_on_triangle(p: &Point3, t: &[Point3; 3]) -> (Point3, Feature) {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, Feature::Vertex(0));
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + ab * v, Feature::Edge(0));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w, Feature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, Feature::Edge(1));
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (a + ab * v + ac * w, Feature::Face)
}

type Normals = (Vec<Vec3>, Vec<[Vec3; 3]>, Vec<Vec3>);

fn pseudo_normals(mesh: &TriMesh) -> Normals {
    let tris = mesh.triangles();
    let mut faces = Vec::with_capacity(tris.len());
    let mut vertex = vec![Vec3::zeros(); mesh.vertices().len()];
    let mut edges: FastMap<(u32, u32), Vec3> = FastMap::default();
    for (t, tri) in tris.iter().enumerate() {
        let p = mesh.triangle(t);
        let n = (p[1] - p[0]).cross(&(p[2] - p[0])).try_normalize(0.0).unwrap_or_else(Vec3::zeros);
        faces.push(n);
        for k in 0..3 {
            let (u, w) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            let angle = u.angle(&w);
            vertex[tri[k] as usize] += n * angle;
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_insert_with(Vec3::zeros) += n;
        }
    }
    let per_tri = tris
        .iter()
        .map(|tri| {
            [0, 1, 2].map(|k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                edges.get(&(a.min(b), a.max(b))).copied().unwrap_or_else(Vec3::zeros)
            })
        })
        .collect();
    (faces, per_tri, vertex)
}
