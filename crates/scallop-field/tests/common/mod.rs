//! Test geometry and brute-force oracles shared by the field's tests.
#![allow(dead_code, reason = "each test file uses part of the helpers")]
#![allow(clippy::unwrap_used, reason = "test geometry is valid by construction")]

use scallop_geom::{Point3, Vec3};
use scallop_mesh::{FastMap, TriMesh};

pub fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

/// An icosphere of `radius` about the origin, `levels` subdivisions, outward.
pub fn sphere(radius: f64, levels: usize) -> TriMesh {
    let t = f64::midpoint(1.0, 5f64.sqrt());
    let mut v: Vec<Point3> = [
        (-1., t, 0.),
        (1., t, 0.),
        (-1., -t, 0.),
        (1., -t, 0.),
        (0., -1., t),
        (0., 1., t),
        (0., -1., -t),
        (0., 1., -t),
        (t, 0., -1.),
        (t, 0., 1.),
        (-t, 0., -1.),
        (-t, 0., 1.),
    ]
    .iter()
    .map(|&(x, y, z)| Point3::from(Vec3::new(x, y, z).normalize() * radius))
    .collect();
    let mut f: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid: FastMap<(usize, usize), usize> = FastMap::default();
        let mut next = Vec::new();
        for tri in &f {
            let m = [0, 1, 2].map(|k| {
                let (a, b) = (tri[k].min(tri[(k + 1) % 3]), tri[k].max(tri[(k + 1) % 3]));
                *mid.entry((a, b)).or_insert_with(|| {
                    v.push(Point3::from(((v[a].coords + v[b].coords) * 0.5).normalize() * radius));
                    v.len() - 1
                })
            });
            next.extend([[tri[0], m[0], m[2]], [tri[1], m[1], m[0]], [tri[2], m[2], m[1]], m]);
        }
        f = next;
    }
    TriMesh::from_indexed(&v, &f).unwrap().0
}

/// A closed cylinder about the z axis from z = 0 to `length`, `n` sides, outward.
pub fn cylinder(radius: f64, length: f64, n: usize) -> TriMesh {
    let mut v = vec![p(0., 0., 0.), p(0., 0., length)];
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        v.push(p(radius * a.cos(), radius * a.sin(), 0.));
        v.push(p(radius * a.cos(), radius * a.sin(), length));
    }
    let mut f = Vec::new();
    for k in 0..n {
        let (b0, t0, b1, t1) = (2 + 2 * k, 3 + 2 * k, 2 + 2 * ((k + 1) % n), 3 + 2 * ((k + 1) % n));
        f.extend([[b0, b1, t1], [b0, t1, t0], [0, b1, b0], [1, t0, t1]]);
    }
    TriMesh::from_indexed(&v, &f).unwrap().0
}

/// A square of side `s` in the plane z = `z`, normal +z, split into 2 n^2 triangles.
pub fn square(s: f64, z: f64, n: usize) -> TriMesh {
    let mut v = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            v.push(p(s * i as f64 / n as f64, s * j as f64 / n as f64, z));
        }
    }
    let mut f = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            f.extend([[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]]);
        }
    }
    TriMesh::from_indexed(&v, &f).unwrap().0
}

fn segment_distance(q: &Point3, a: &Point3, b: &Point3) -> f64 {
    let ab = b - a;
    let t = ((q - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
    (a + ab * t - q).norm()
}

/// Distance from `q` to a triangle, by the plane projection when it falls
/// inside (barycentric signs) or else the nearest edge: independent of the
/// crate's Voronoi-region closest point.
pub fn triangle_distance(q: &Point3, t: &[Point3; 3]) -> f64 {
    let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
    let foot = q - n * ((q - t[0]).dot(&n) / n.norm_squared());
    let inside = (0..3).all(|k| (t[(k + 1) % 3] - t[k]).cross(&(foot - t[k])).dot(&n) >= 0.0);
    if inside {
        return (q - foot).norm();
    }
    (0..3).map(|k| segment_distance(q, &t[k], &t[(k + 1) % 3])).fold(f64::INFINITY, f64::min)
}

/// Distance from `q` to the mesh, over every triangle.
pub fn brute_distance(q: &Point3, mesh: &TriMesh) -> f64 {
    (0..mesh.triangles().len()).map(|t| triangle_distance(q, &mesh.triangle(t))).fold(f64::INFINITY, f64::min)
}

/// Edge use counts: (edges used once, edges used more than twice).
pub fn open_and_nonmanifold_edges(mesh: &TriMesh) -> (usize, usize) {
    let mut edges: FastMap<(u32, u32), usize> = FastMap::default();
    for t in mesh.triangles() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    (edges.values().filter(|&&c| c == 1).count(), edges.values().filter(|&&c| c > 2).count())
}

fn segment_hits_triangle(a: &Point3, b: &Point3, t: &[Point3; 3]) -> bool {
    // Moeller-Trumbore with the segment parameter in (0, 1).
    let (e1, e2, d) = (t[1] - t[0], t[2] - t[0], b - a);
    let pv = d.cross(&e2);
    let det = e1.dot(&pv);
    if det.abs() < 1e-14 {
        return false;
    }
    let s = a - t[0];
    let u = s.dot(&pv) / det;
    let qv = s.cross(&e1);
    let v = d.dot(&qv) / det;
    let w = e2.dot(&qv) / det;
    let eps = 1e-9;
    u > eps && v > eps && u + v < 1.0 - eps && w > eps && w < 1.0 - eps
}

/// Pairs of triangles sharing no vertex that intersect (an edge of one crosses
/// the other), by brute force over all pairs with a box prefilter.
pub fn self_intersections(mesh: &TriMesh) -> usize {
    let tris = mesh.triangles();
    let boxes: Vec<(Point3, Point3)> = (0..tris.len())
        .map(|i| {
            let [a, b, c] = mesh.triangle(i);
            (a.inf(&b).inf(&c), a.sup(&b).sup(&c))
        })
        .collect();
    let mut hits = 0;
    for i in 0..tris.len() {
        for j in i + 1..tris.len() {
            if tris[i].iter().any(|x| tris[j].contains(x)) {
                continue;
            }
            let (bi, bj) = (&boxes[i], &boxes[j]);
            if (0..3).any(|k| bi.1[k] < bj.0[k] || bj.1[k] < bi.0[k]) {
                continue;
            }
            let (ti, tj) = (mesh.triangle(i), mesh.triangle(j));
            let crosses =
                |s: &[Point3; 3], o: &[Point3; 3]| (0..3).any(|k| segment_hits_triangle(&s[k], &s[(k + 1) % 3], o));
            if crosses(&ti, &tj) || crosses(&tj, &ti) {
                hits += 1;
            }
        }
    }
    hits
}
