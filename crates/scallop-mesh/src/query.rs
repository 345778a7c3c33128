//! Point queries on a triangle mesh through a 3D [`Bvh`]: the closest point
//! (the `Projection` service of Jousselin 2020, Ch. 2 §1.3) and the projection
//! of a point along a direction (ray casting, both ways).

use scallop_geom::{Aabb3, Point3, Vec3};

use crate::{Bvh, TriMesh};

/// The closest point of a mesh to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestPoint {
    /// The point on the mesh (mm).
    pub point: Point3,
    /// The triangle it lies on (number in the source mesh).
    pub triangle: usize,
    /// Its distance to the query point (mm).
    pub distance: f64,
}

/// A hit of a line on a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// The point on the mesh (mm).
    pub point: Point3,
    /// The triangle hit (number in the source mesh).
    pub triangle: usize,
    /// Signed parameter along the unit direction: `point = origin + t dir` (mm).
    pub t: f64,
}

/// A mesh with a 3D hierarchy over its triangles, for closest-point and ray
/// queries. Deterministic: ties go to the lower triangle number.
#[derive(Debug, Clone)]
pub struct MeshQuery {
    tris: Vec<[Point3; 3]>,
    normals: Vec<Vec3>,
    bvh: Bvh,
}

impl MeshQuery {
    /// Indexes `mesh`.
    ///
    /// ```
    /// use scallop_geom::Point3;
    /// use scallop_mesh::{MeshQuery, TriMesh};
    /// let p = |x, y, z| Point3::new(x, y, z);
    /// let (mesh, _) = TriMesh::from_soup(&[[p(0., 0., 0.), p(4., 0., 0.), p(0., 4., 0.)]]).unwrap();
    /// let q = MeshQuery::new(&mesh);
    /// let c = q.closest_point(&p(1., 1., 3.));
    /// assert_eq!(c.point, p(1., 1., 0.));
    /// assert_eq!(c.distance, 3.0);
    /// ```
    #[must_use]
    pub fn new(mesh: &TriMesh) -> MeshQuery {
        let tris: Vec<[Point3; 3]> = (0..mesh.triangles().len()).map(|i| mesh.triangle(i)).collect();
        let boxes: Vec<Aabb3> = tris.iter().map(triangle_box).collect();
        let normals = tris
            .iter()
            .map(|t| {
                let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
                let len = n.norm();
                if len > 0.0 { n / len } else { Vec3::zeros() }
            })
            .collect();
        MeshQuery { tris, normals, bvh: Bvh::build(&boxes) }
    }

    /// Corners of triangle `i`.
    #[must_use]
    pub fn triangle(&self, i: usize) -> &[Point3; 3] {
        &self.tris[i]
    }

    /// Unit normal of triangle `i` by its winding (right-hand rule).
    #[must_use]
    pub fn normal(&self, i: usize) -> Vec3 {
        self.normals[i]
    }

    /// Number of triangles.
    #[must_use]
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    /// Whether there is no triangle (never for a valid mesh).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The point of the mesh closest to `p`.
    #[must_use]
    pub fn closest_point(&self, p: &Point3) -> ClosestPoint {
        self.closest_within(p, f64::INFINITY).unwrap_or(ClosestPoint {
            point: *p,
            triangle: 0,
            distance: f64::INFINITY,
        })
    }

    /// The point of the mesh closest to `p` if it is within `max_distance`.
    #[must_use]
    pub fn closest_within(&self, p: &Point3, max_distance: f64) -> Option<ClosestPoint> {
        let (i, d2) = self
            .bvh
            .nearest(p, max_distance * max_distance, |i| (closest_on_triangle(p, &self.tris[i]) - p).norm_squared())?;
        let point = closest_on_triangle(p, &self.tris[i]);
        Some(ClosestPoint { point, triangle: i, distance: d2.sqrt() })
    }

    /// The first hit of the half line `origin + t dir`, `t >= 0` (`dir` need
    /// not be unit; `t` is returned for the unit direction).
    #[must_use]
    pub fn ray_cast(&self, origin: &Point3, dir: &Vec3) -> Option<RayHit> {
        let len = dir.norm();
        if len.is_nan() || len <= 0.0 || len.is_infinite() {
            return None;
        }
        let d = dir / len;
        let mut best: Option<(usize, f64)> = None;
        self.bvh.visit_ray(origin, &d, 0.0, f64::INFINITY, |i| {
            let t = ray_triangle(origin, &d, &self.tris[i])?;
            let better = match best {
                None => true,
                Some((b, bt)) => t.total_cmp(&bt).then(i.cmp(&b)).is_lt(),
            };
            if better {
                best = Some((i, t));
            }
            Some(t)
        });
        best.map(|(i, t)| RayHit { point: origin + d * t, triangle: i, t })
    }

    /// Directional projection: the hit of the whole line through `origin`
    /// along `dir` nearest to `origin` (forward on ties); `t` is negative for a
    /// hit behind.
    #[must_use]
    pub fn project_along(&self, origin: &Point3, dir: &Vec3) -> Option<RayHit> {
        let fwd = self.ray_cast(origin, dir);
        let back = self.ray_cast(origin, &-dir).map(|h| RayHit { t: -h.t, ..h });
        match (fwd, back) {
            (Some(f), Some(b)) => Some(if -b.t < f.t { b } else { f }),
            (f, b) => f.or(b),
        }
    }
}

/// The box of a triangle.
#[must_use]
pub fn triangle_box(t: &[Point3; 3]) -> Aabb3 {
    Aabb3 { min: t[0].inf(&t[1]).inf(&t[2]), max: t[0].sup(&t[1]).sup(&t[2]) }
}

/// The point of triangle `t` closest to `p` (Ericson 2005, "Real-Time
/// Collision Detection", §5.1.5: Voronoi regions of the corners and edges).
#[must_use]
pub fn closest_on_triangle(p: &Point3, t: &[Point3; 3]) -> Point3 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom.is_nan() || denom == 0.0 {
        return a;
    }
    a + ab * (vb / denom) + ac * (vc / denom)
}

/// Parameter `t >= 0` where the half line `o + t d` meets triangle `tri`
/// (closed), by Möller & Trumbore 1997; `None` for a miss or a line in the
/// triangle's plane.
#[must_use]
pub fn ray_triangle(o: &Point3, d: &Vec3, tri: &[Point3; 3]) -> Option<f64> {
    let (e1, e2) = (tri[1] - tri[0], tri[2] - tri[0]);
    let h = d.cross(&e2);
    let det = e1.dot(&h);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - tri[0];
    let u = s.dot(&h) * inv;
    let slack = crate::tol::RAY_EDGE_SLACK;
    if u < -slack || u > 1.0 + slack {
        return None;
    }
    let q = s.cross(&e1);
    let v = d.dot(&q) * inv;
    if v < -slack || u + v > 1.0 + slack {
        return None;
    }
    let t = e2.dot(&q) * inv;
    (t >= 0.0).then_some(t)
}
