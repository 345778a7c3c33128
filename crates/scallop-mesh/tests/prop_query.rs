//! Mesh services against brute force: closest point, ray projection,
//! point-to-polyline distance and mesh-mesh intersection chaining.

#![allow(
    clippy::unwrap_used,
    clippy::float_cmp,
    reason = "tests: a panic is the failure report; exact cases compare exactly"
)]

use proptest::prelude::*;
use scallop_geom::{Point3, Vec3};
use scallop_mesh::{
    MeshQuery, Polyline3, PolylineQuery, TriMesh, closest_on_triangle, intersect_meshes, ray_triangle,
    segment_parameter,
};

fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

/// A grid surface `z = height(x, y)` over `[-half, half]^2` with `n` cells a side.
fn grid(n: usize, half: f64, height: impl Fn(f64, f64) -> f64) -> TriMesh {
    let step = 2.0 * half / n as f64;
    let mut v = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (-half + i as f64 * step, -half + j as f64 * step);
            v.push(p(x, y, height(x, y)));
        }
    }
    let mut t = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            t.push([a, a + 1, a + n + 2]);
            t.push([a, a + n + 2, a + n + 1]);
        }
    }
    TriMesh::from_indexed(&v, &t).unwrap().0
}

/// A closed UV sphere with `rings` latitude bands and `segs` longitudes.
fn sphere(c: Point3, r: f64, rings: usize, segs: usize) -> TriMesh {
    let mut v = vec![c + Vec3::new(0.0, 0.0, -r)];
    for i in 1..rings {
        let phi = -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..segs {
            let th = std::f64::consts::TAU * j as f64 / segs as f64;
            v.push(c + Vec3::new(r * phi.cos() * th.cos(), r * phi.cos() * th.sin(), r * phi.sin()));
        }
    }
    v.push(c + Vec3::new(0.0, 0.0, r));
    let top = v.len() - 1;
    let ring = |i: usize, j: usize| 1 + (i - 1) * segs + j % segs;
    let mut t = Vec::new();
    for j in 0..segs {
        t.push([0, ring(1, j + 1), ring(1, j)]);
        t.push([top, ring(rings - 1, j), ring(rings - 1, j + 1)]);
        for i in 1..rings - 1 {
            t.push([ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)]);
            t.push([ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)]);
        }
    }
    TriMesh::from_indexed(&v, &t).unwrap().0
}

fn coord() -> impl Strategy<Value = f64> {
    -10.0..10.0f64
}

fn point() -> impl Strategy<Value = Point3> {
    (coord(), coord(), coord()).prop_map(|(x, y, z)| p(x, y, z))
}

fn wavy() -> TriMesh {
    grid(12, 10.0, |x, y| 2.0 * (0.3 * x).sin() * (0.2 * y).cos())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The BVH closest point equals the minimum over all triangles.
    #[test]
    fn closest_point_is_brute_force(q in point()) {
        let mesh = wavy();
        let query = MeshQuery::new(&mesh);
        let c = query.closest_point(&q);
        let brute = (0..mesh.triangles().len())
            .map(|i| (closest_on_triangle(&q, &mesh.triangle(i)) - q).norm())
            .fold(f64::INFINITY, f64::min);
        prop_assert_eq!(c.distance, brute);
        prop_assert!(((c.point - q).norm() - c.distance).abs() <= 1e-12);
    }

    /// The closest point on a triangle beats every sample of the triangle.
    #[test]
    fn closest_on_triangle_beats_samples(q in point(), a in point(), b in point(), c in point()) {
        let t = [a, b, c];
        let best = (closest_on_triangle(&q, &t) - q).norm();
        for i in 0..=10 {
            for j in 0..=(10 - i) {
                let (u, v) = (f64::from(i) / 10.0, f64::from(j) / 10.0);
                let s = a + (b - a) * u + (c - a) * v;
                prop_assert!(best <= (s - q).norm() + 1e-9);
            }
        }
    }

    /// The first ray hit equals the nearest hit over all triangles.
    #[test]
    fn ray_cast_is_brute_force(o in point(), d in point()) {
        prop_assume!(d.coords.norm() > 1e-3);
        let mesh = wavy();
        let query = MeshQuery::new(&mesh);
        let dir = d.coords.normalize();
        let brute = (0..mesh.triangles().len())
            .filter_map(|i| ray_triangle(&o, &dir, &mesh.triangle(i)))
            .fold(f64::INFINITY, f64::min);
        match query.ray_cast(&o, &d.coords) {
            Some(hit) => prop_assert!((hit.t - brute).abs() <= 1e-9),
            None => prop_assert!(brute.is_infinite()),
        }
    }

    /// A vertical projection onto the height field lands at the height.
    #[test]
    fn project_along_hits_height_field(x in -9.0..9.0f64, y in -9.0..9.0f64, z in -20.0..20.0f64) {
        let mesh = grid(12, 10.0, |x, y| 0.1 * x + 0.05 * y);
        let hit = MeshQuery::new(&mesh).project_along(&p(x, y, z), &Vec3::z()).unwrap();
        prop_assert!((hit.point.z - (0.1 * x + 0.05 * y)).abs() <= 1e-9);
        prop_assert!((hit.t - (hit.point.z - z)).abs() <= 1e-9);
    }

    /// The polyline query equals the minimum over all segments.
    #[test]
    fn polyline_distance_is_brute_force(q in point(), pts in prop::collection::vec(point(), 2..30), closed in any::<bool>()) {
        let line = Polyline3::new(pts, closed);
        let brute = (0..line.segment_count())
            .map(|i| {
                let (a, b) = line.segment(i);
                (a + (b - a) * segment_parameter(&q, &a, &b) - q).norm()
            })
            .fold(f64::INFINITY, f64::min);
        let f = PolylineQuery::new(vec![line]).closest(&q).unwrap();
        prop_assert!((f.distance - brute).abs() <= 1e-12);
    }

    /// A hinted search finds the same foot as a plain one, whatever the hint.
    #[test]
    fn hinted_polyline_search_is_the_plain_one(q in point(), h in point(), pts in prop::collection::vec(point(), 2..30)) {
        let query = PolylineQuery::new(vec![Polyline3::new(pts, true)]);
        let hint = query.closest(&h).unwrap();
        for reach in [f64::INFINITY, 5.0] {
            prop_assert_eq!(query.closest_near(&q, reach, &hint), query.closest_within(&q, reach));
        }
    }

    /// A plane through a closed sphere cuts one closed loop on the sphere and the plane.
    #[test]
    fn plane_cuts_sphere_in_one_loop(c in -7.0..7.0f64, tilt in -0.5..0.5f64) {
        let s = sphere(p(0.0, 0.0, 0.0), 8.0, 12, 24);
        let plane = grid(6, 15.0, |x, _| c + tilt * x);
        let x = intersect_meshes(&plane, &s);
        prop_assert_eq!(x.chains.len(), 1);
        prop_assert!(x.chains[0].closed);
        prop_assert_eq!(x.odd_pairs, 0);
        let sq = MeshQuery::new(&s);
        for q in &x.chains[0].points {
            prop_assert!((q.z - (c + tilt * q.x)).abs() <= 1e-9);
            prop_assert!(sq.closest_point(q).distance <= 1e-9);
        }
    }
}

/// Vertices of one mesh lying exactly on the other (the sphere's equator ring
/// on the plane z = 0, shared grid coordinates) still chain into one loop.
#[test]
fn exact_vertex_contacts_chain() {
    let s = sphere(p(0.0, 0.0, 0.0), 8.0, 12, 24);
    for plane in [grid(4, 16.0, |_, _| 0.0), grid(16, 16.0, |_, _| 0.0)] {
        let x = intersect_meshes(&plane, &s);
        assert_eq!((x.chains.len(), x.odd_pairs), (1, 0));
        assert!(x.chains[0].closed);
        assert!(x.chains[0].points.iter().all(|q| q.z == 0.0 && (q.coords.norm() - 8.0).abs() < 0.6));
    }
}

/// Coplanar overlapping pieces: a grid and a bent sheet sharing the plane
/// z = 0 over half its extent give chains on the shared plane's edge, never
/// an odd pair.
#[test]
fn coplanar_pieces_are_consistent() {
    let flat = grid(8, 10.0, |_, _| 0.0);
    let bent = grid(8, 10.0, |x, _| if x > 0.0 { 0.5 * x } else { 0.0 });
    let x = intersect_meshes(&flat, &bent);
    assert_eq!(x.odd_pairs, 0);
    assert!(x.chains.iter().all(|c| c.points.iter().all(|q| q.z == 0.0)));
    // Shifted apart in z the sheets meet along x = 0.2 / 0.5 only.
    let lifted = grid(8, 10.0, |x, _| if x > 0.0 { 0.5 * x - 0.2 } else { -0.2 });
    let x = intersect_meshes(&flat, &lifted);
    assert_eq!(x.chains.len(), 1);
    assert!(!x.chains[0].closed);
    assert!(x.chains[0].points.iter().all(|q| (q.x - 0.4).abs() < 1e-12));
}
