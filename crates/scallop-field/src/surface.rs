//! A triangle mesh prepared for distance queries: a bounding-volume hierarchy
//! over its triangles, closest points with the feature they lie on, and the
//! angle-weighted pseudo-normals that tell the side of a point (Baerentzen and
//! Aanaes 2005, "Signed distance computation using the angle weighted
//! pseudonormal", IEEE TVCG 11(3), section 3).

use scallop_geom::{Point3, Vec3};
use scallop_mesh::{FastMap, TriMesh};

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

#[derive(Debug, Clone, Copy)]
struct Node {
    min: Point3,
    max: Point3,
    /// Leaf: first triangle slot; inner: index of the left child (right = left + 1).
    first: u32,
    /// Triangles in a leaf, 0 for an inner node.
    count: u32,
}

/// A triangle mesh with its hierarchy and pseudo-normals.
#[derive(Debug, Clone)]
pub struct Surface {
    mesh: TriMesh,
    nodes: Vec<Node>,
    order: Vec<u32>,
    face_normals: Vec<Vec3>,
    edge_normals: Vec<[Vec3; 3]>,
    vertex_normals: Vec<Vec3>,
}

const LEAF: usize = 4;

impl Surface {
    /// Prepares `mesh` (its triangle orientation gives the sides: a point is on
    /// the positive side when it lies where the normals point).
    #[must_use]
    pub fn new(mesh: &TriMesh) -> Surface {
        let n = mesh.triangles().len();
        let boxes: Vec<(Point3, Point3, Point3)> = (0..n)
            .map(|t| {
                let [a, b, c] = mesh.triangle(t);
                (a.inf(&b).inf(&c), a.sup(&b).sup(&c), Point3::from((a.coords + b.coords + c.coords) / 3.0))
            })
            .collect();
        #[allow(clippy::cast_possible_truncation, reason = "a TriMesh indexes with u32")]
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n / LEAF + 2);
        nodes.push(Node { min: Point3::origin(), max: Point3::origin(), first: 0, count: 0 });
        build(&mut nodes, 0, &mut order, 0, &boxes);
        let (face_normals, edge_normals, vertex_normals) = pseudo_normals(mesh);
        Surface { mesh: mesh.clone(), nodes, order, face_normals, edge_normals, vertex_normals }
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
        let mut best: Option<Closest> = None;
        let mut bound = if max_dist.is_finite() { max_dist * max_dist } else { f64::INFINITY };
        let mut stack: Vec<(u32, f64)> = vec![(0, box_dist2(&self.nodes[0], p))];
        while let Some((id, d2)) = stack.pop() {
            if d2 > bound {
                continue;
            }
            let node = &self.nodes[id as usize];
            if node.count == 0 {
                let (l, r) = (node.first, node.first + 1);
                let dl = box_dist2(&self.nodes[l as usize], p);
                let dr = box_dist2(&self.nodes[r as usize], p);
                // Nearer child last, so it is popped first.
                if dl <= dr {
                    stack.push((r, dr));
                    stack.push((l, dl));
                } else {
                    stack.push((l, dl));
                    stack.push((r, dr));
                }
                continue;
            }
            for slot in node.first..node.first + node.count {
                let t = self.order[slot as usize] as usize;
                let (q, feature) = closest_on_triangle(p, &self.mesh.triangle(t));
                let dist2 = (q - p).norm_squared();
                // Ties go to the lower triangle number, so the feature does not depend
                // on the visiting order.
                let better = best.is_none_or(|b| dist2.total_cmp(&b.dist2).then(t.cmp(&b.triangle)).is_lt());
                if dist2 <= bound && better {
                    bound = dist2;
                    best = Some(Closest { point: q, dist2, triangle: t, feature });
                }
            }
        }
        best
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

fn box_dist2(n: &Node, p: &Point3) -> f64 {
    let mut d = 0.0;
    for a in 0..3 {
        let e = (n.min[a] - p[a]).max(p[a] - n.max[a]).max(0.0);
        d += e * e;
    }
    d
}

/// Median split on the longest axis of the centroids; ties by triangle number,
/// so the hierarchy depends only on the mesh.
fn build(nodes: &mut Vec<Node>, id: usize, order: &mut [u32], first: usize, boxes: &[(Point3, Point3, Point3)]) {
    let mut min = Point3::from(Vec3::repeat(f64::INFINITY));
    let mut max = Point3::from(Vec3::repeat(f64::NEG_INFINITY));
    let mut cmin = min;
    let mut cmax = max;
    for &t in order.iter() {
        let (lo, hi, c) = &boxes[t as usize];
        min = min.inf(lo);
        max = max.sup(hi);
        cmin = cmin.inf(c);
        cmax = cmax.sup(c);
    }
    #[allow(clippy::cast_possible_truncation, reason = "a TriMesh indexes with u32")]
    if order.len() <= LEAF {
        nodes[id] = Node { min, max, first: first as u32, count: order.len() as u32 };
        return;
    }
    let ext = cmax - cmin;
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    order.sort_unstable_by(|&a, &b| boxes[a as usize].2[axis].total_cmp(&boxes[b as usize].2[axis]).then(a.cmp(&b)));
    let mid = order.len() / 2;
    let left = nodes.len();
    #[allow(clippy::cast_possible_truncation, reason = "node count below 2^32 for a u32-indexed mesh")]
    {
        nodes[id] = Node { min, max, first: left as u32, count: 0 };
    }
    let blank = nodes[id];
    nodes.push(blank);
    nodes.push(blank);
    let (lo, hi) = order.split_at_mut(mid);
    build(nodes, left, lo, first, boxes);
    build(nodes, left + 1, hi, first + mid, boxes);
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
