//! A support surface (an axial level S_n) and curves lying on it: the
//! mesh-first data model of Jousselin 2020, Ch. 4 §1.2 (meshes with vertex
//! normals, polylines).

use scallop_geom::{Point3, Vec3};
use scallop_mesh::{MeshQuery, Polyline3, TriMesh};

use crate::GuideError;

/// A triangle mesh with unit vertex normals, facet normals by winding and a
/// closest-point index. Curves "inside" are on the left of their travel
/// direction seen from the side the normals point to.
#[derive(Debug, Clone)]
pub struct Support {
    mesh: TriMesh,
    query: MeshQuery,
    vertex_normals: Vec<Vec3>,
    facet_size: f64,
    /// Per vertex, the vertices sharing an edge with it, ascending.
    adjacency: Rows,
    /// Per vertex, the facets using it, ascending.
    incidence: Rows,
}

impl Support {
    /// A support whose vertex normals are the area-weighted averages of the
    /// facet normals (by winding).
    #[must_use]
    pub fn new(mesh: TriMesh) -> Support {
        let normals = area_weighted_normals(&mesh, Vec3::z());
        Support::assemble(mesh, normals)
    }

    /// A support with the exact normals kept from tessellation (one unit
    /// normal per vertex; Jousselin 2020, Ch. 4 §1.2).
    ///
    /// # Errors
    /// [`GuideError::BadNormals`] when the count differs or a normal is not
    /// finite and non-zero.
    pub fn with_normals(mesh: TriMesh, normals: Vec<Vec3>) -> Result<Support, GuideError> {
        let ok = normals.len() == mesh.vertices().len()
            && normals.iter().all(|n| n.iter().all(|c| c.is_finite()) && n.norm() > 0.0);
        if !ok {
            return Err(GuideError::BadNormals { given: normals.len(), vertices: mesh.vertices().len() });
        }
        let normals = normals.iter().map(|n| n.normalize()).collect();
        Ok(Support::assemble(mesh, normals))
    }

    fn assemble(mesh: TriMesh, vertex_normals: Vec<Vec3>) -> Support {
        let facet_size = (0..mesh.triangles().len())
            .map(|i| {
                let c = mesh.triangle(i);
                (c[1] - c[0]).norm().max((c[2] - c[1]).norm()).max((c[0] - c[2]).norm())
            })
            .fold(0.0, f64::max);
        let query = MeshQuery::new(&mesh);
        let (adjacency, incidence) = (neighbours(&mesh), incidence(&mesh));
        Support { mesh, query, vertex_normals, facet_size, adjacency, incidence }
    }

    /// The vertices sharing an edge with vertex `v`, ascending.
    #[must_use]
    pub fn neighbours(&self, v: usize) -> &[u32] {
        self.adjacency.row(v)
    }

    /// The facets using vertex `v`, ascending.
    #[must_use]
    pub fn vertex_facets(&self, v: usize) -> &[u32] {
        self.incidence.row(v)
    }

    /// The mesh.
    #[must_use]
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// The closest-point and ray index.
    #[must_use]
    pub fn query(&self) -> &MeshQuery {
        &self.query
    }

    /// Unit normal at vertex `v`.
    #[must_use]
    pub fn vertex_normal(&self, v: usize) -> Vec3 {
        self.vertex_normals[v]
    }

    /// The longest edge of any facet (mm): the chord accuracy of the curves.
    #[must_use]
    pub fn facet_size(&self) -> f64 {
        self.facet_size
    }

    /// Unit normal at a point of the mesh near `p`: the vertex normals of its
    /// closest triangle, weighted by barycentric coordinates.
    #[must_use]
    pub fn normal_at(&self, p: &Point3) -> Vec3 {
        let c = self.query.closest_point(p);
        let tri = self.mesh.triangles()[c.triangle];
        let w = barycentric(&c.point, &self.mesh.triangle(c.triangle));
        let n: Vec3 = (0..3).map(|k| self.vertex_normals[tri[k] as usize] * w[k]).sum();
        let len = n.norm();
        if len > 0.0 { n / len } else { self.query.normal(c.triangle) }
    }

    /// `line` as a curve on this support, with normals from the mesh.
    ///
    /// # Errors
    /// [`GuideError::BadCurve`] for fewer than 2 distinct points or a
    /// non-finite coordinate.
    pub fn curve(&self, line: Polyline3) -> Result<Curve, GuideError> {
        check_line(&line, 0)?;
        let mut points = line.points;
        points.dedup();
        if line.closed && points.len() > 1 && points.first() == points.last() {
            points.pop();
        }
        if points.len() < 2 {
            return Err(GuideError::BadCurve { curve: 0, reason: "fewer than 2 distinct points" });
        }
        let normals = points.iter().map(|p| self.normal_at(p)).collect();
        Ok(Curve { line: Polyline3::new(points, line.closed), normals })
    }
}

/// A polyline on a support with the surface normal at each point.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// The points.
    pub line: Polyline3,
    /// Unit surface normal at each point.
    pub normals: Vec<Vec3>,
}

impl Curve {
    /// The same curve travelled the other way (inside on the other side).
    #[must_use]
    pub fn reversed(&self) -> Curve {
        let mut normals = self.normals.clone();
        normals.reverse();
        Curve { line: self.line.reversed(), normals }
    }

    /// Signed area of a closed curve about its mean normal (positive when the
    /// curve turns counter-clockwise seen from the normals' side, i.e. when
    /// its inside is on its left).
    #[must_use]
    pub fn signed_area(&self) -> f64 {
        let n: Vec3 = self.normals.iter().sum();
        let n = if n.norm() > 0.0 { n.normalize() } else { Vec3::z() };
        let pts = &self.line.points;
        let Some(&o) = pts.first() else { return 0.0 };
        (1..pts.len().saturating_sub(1)).map(|i| 0.5 * (pts[i] - o).cross(&(pts[i + 1] - o)).dot(&n)).sum()
    }

    /// The curve turned so that its inside is on its left (a closed curve with
    /// a negative [`Curve::signed_area`] is reversed; Jousselin 2020, Ch. 2
    /// §3.2.1, the orientation that makes `N ∧ T` point inward).
    #[must_use]
    pub fn inside_left(self) -> Curve {
        if self.line.closed && self.signed_area() < 0.0 { self.reversed() } else { self }
    }
}

/// Unit vertex normals of `mesh`: area-weighted averages of the facet normals
/// (by winding), `fallback` where they cancel.
pub(crate) fn area_weighted_normals(mesh: &TriMesh, fallback: Vec3) -> Vec<Vec3> {
    let mut normals = vec![Vec3::zeros(); mesh.vertices().len()];
    for (i, t) in mesh.triangles().iter().enumerate() {
        let c = mesh.triangle(i);
        let n = (c[1] - c[0]).cross(&(c[2] - c[0]));
        for &v in t {
            normals[v as usize] += n;
        }
    }
    for n in &mut normals {
        let len = n.norm();
        *n = if len > 0.0 { *n / len } else { fallback };
    }
    normals
}

/// Compressed rows: row `i` is `items[offsets[i]..offsets[i + 1]]`.
#[derive(Debug, Clone, Default)]
struct Rows {
    offsets: Vec<u32>,
    items: Vec<u32>,
}

impl Rows {
    /// Rows `0..rows` from `(row, item)` pairs, each row ascending and
    /// without repeats.
    fn from_pairs(rows: usize, mut pairs: Vec<(u32, u32)>) -> Rows {
        pairs.sort_unstable();
        pairs.dedup();
        let mut offsets = vec![0u32; rows + 1];
        for &(a, _) in &pairs {
            offsets[a as usize + 1] += 1;
        }
        for v in 0..rows {
            offsets[v + 1] += offsets[v];
        }
        Rows { offsets, items: pairs.into_iter().map(|p| p.1).collect() }
    }

    fn row(&self, i: usize) -> &[u32] {
        &self.items[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }
}

/// Vertex adjacency.
fn neighbours(mesh: &TriMesh) -> Rows {
    let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(6 * mesh.triangles().len());
    for t in mesh.triangles() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            pairs.push((a, b));
            pairs.push((b, a));
        }
    }
    Rows::from_pairs(mesh.vertices().len(), pairs)
}

/// The facets of each vertex.
fn incidence(mesh: &TriMesh) -> Rows {
    let pairs = (0..mesh.triangles().len())
        .flat_map(|f| mesh.triangles()[f].map(|v| (v, u32::try_from(f).unwrap_or(u32::MAX))))
        .collect();
    Rows::from_pairs(mesh.vertices().len(), pairs)
}

/// [`check_line`] plus one normal per point.
pub(crate) fn check_curve(c: &Curve, curve: usize) -> Result<(), GuideError> {
    check_line(&c.line, curve)?;
    if c.normals.len() == c.line.points.len() {
        Ok(())
    } else {
        Err(GuideError::BadCurve { curve, reason: "not one normal per point" })
    }
}

pub(crate) fn check_line(line: &Polyline3, curve: usize) -> Result<(), GuideError> {
    if line.points.len() < 2 {
        return Err(GuideError::BadCurve { curve, reason: "fewer than 2 points" });
    }
    if !line.points.iter().all(|p| p.iter().all(|c| c.is_finite())) {
        return Err(GuideError::BadCurve { curve, reason: "non-finite coordinate" });
    }
    Ok(())
}

/// Barycentric coordinates of `p` (on or near the plane of `t`), clamped to
/// the triangle.
pub(crate) fn barycentric(p: &Point3, t: &[Point3; 3]) -> [f64; 3] {
    let (e0, e1, ep) = (t[1] - t[0], t[2] - t[0], p - t[0]);
    let (d00, d01, d11) = (e0.dot(&e0), e0.dot(&e1), e1.dot(&e1));
    let (d20, d21) = (ep.dot(&e0), ep.dot(&e1));
    let den = d00 * d11 - d01 * d01;
    if den.is_nan() || den <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let v = ((d11 * d20 - d01 * d21) / den).clamp(0.0, 1.0);
    let w = ((d00 * d21 - d01 * d20) / den).clamp(0.0, 1.0 - v);
    [1.0 - v - w, v, w]
}
