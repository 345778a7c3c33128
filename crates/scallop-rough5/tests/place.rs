//! Tool placement along an axis: analytic cases (ball and torus on a plane,
//! spec 12.1 item 2), Eq. 1.1 consistency, a brute-force non-penetration
//! oracle, and equality with the 3-axis drop-cutter for axis +Z.
#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

use proptest::prelude::*;
use scallop_cutter::{Cutter, CutterShape, drop_cutter};
use scallop_geom::{Point2, Point3, Vec3};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_rough5::{Feature, Placer, tool_frame};

fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

/// A square plane z = 0 of side 200 in two triangles.
fn plane() -> TriMesh {
    TriMesh::from_soup(&[
        [p(-100., -100., 0.), p(100., -100., 0.), p(100., 100., 0.)],
        [p(-100., -100., 0.), p(100., 100., 0.), p(-100., 100., 0.)],
    ])
    .unwrap()
    .0
}

/// A bumpy height field over [-20, 20]^2 in 2 mm cells.
fn bumps(a: f64, b: f64, c: f64) -> TriMesh {
    let n = 20;
    let z = |x: f64, y: f64| a * (0.3 * x).sin() + b * (0.25 * y).cos() + c * (0.1 * x * y).sin();
    let v: Vec<Point3> = (0..=n)
        .flat_map(|j| (0..=n).map(move |i| (f64::from(i) * 2.0 - 20.0, f64::from(j) * 2.0 - 20.0)))
        .map(|(x, y)| p(x, y, z(x, y)))
        .collect();
    let n = n as usize;
    let t: Vec<[usize; 3]> = (0..n)
        .flat_map(|j| {
            (0..n).flat_map(move |i| {
                let a = j * (n + 1) + i;
                [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]]
            })
        })
        .collect();
    TriMesh::from_indexed(&v, &t).unwrap().0
}

fn cutter(kind: u8, radius: f64, corner: f64) -> Cutter {
    let shape = match kind {
        0 => CutterShape::Ball { radius },
        1 => CutterShape::Flat { radius },
        _ => CutterShape::Bull { radius, corner: corner.min(radius) },
    };
    Cutter::new(shape, 30.0).unwrap()
}

fn axis(theta: f64, phi: f64) -> Vec3 {
    Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
}

/// Height of the tool's lower surface above its tip at radial distance rho.
fn profile(c: &Cutter, rho: f64) -> f64 {
    c.shape().height_at(rho.min(c.radius()))
}

/// Eq. 1.1 (Jousselin 2020, Ch. 1 §1.5): C_L from C_C, n and u.
fn eq_1_1(contact: &Point3, n: &Vec3, u: &Vec3, radius: f64, corner: f64) -> Point3 {
    let perp = n - u * n.dot(u);
    let side = if perp.norm() > 1e-9 { perp.normalize() * (radius - corner) } else { Vec3::zeros() };
    contact + n * corner + side
}

proptest! {
    #[test]
    fn ball_on_a_plane_sits_at_its_radius(theta in 0.0..1.2f64, phi in 0.0..6.3f64, r in 1.0..8.0f64, s in 0.0..1.0f64,
                                          x in -30.0..30.0f64, y in -30.0..30.0f64) {
        let ball = cutter(0, r, r);
        let placer = Placer::new(&plane(), &ball, s).unwrap();
        let u = axis(theta, phi);
        let placed = placer.place(&p(x, y, 10.0), &u).unwrap();
        // The ball's centre (C_L) is r + s above the plane, the contact under it.
        prop_assert!((placed.cl.z - (r + s)).abs() < 1e-9, "{placed:?}");
        prop_assert!((placed.contact - (placed.cl - Vec3::z() * r)).norm() < 1e-9);
        prop_assert!((placed.normal - Vec3::z()).norm() < 1e-9);
        prop_assert!((placed.tip - (placed.cl - u * r)).norm() < 1e-9);
    }

    #[test]
    fn torus_on_a_tilted_plane_follows_eq_1_1(theta in 0.0..1.2f64, phi in 0.0..6.3f64, big in 2.0..8.0f64,
                                              small in 0.2..2.0f64, s in 0.0..0.8f64) {
        let torus = cutter(2, big, small);
        let placer = Placer::new(&plane(), &torus, s).unwrap();
        let u = axis(theta, phi);
        let placed = placer.place(&p(1.0, -2.0, 40.0), &u).unwrap();
        // Spec 12.1 item 2, on the plane offset by s.
        prop_assert!((placed.cl.z - (small + s + (big - small) * theta.sin())).abs() < 1e-9, "{placed:?}");
        let expected = eq_1_1(&placed.contact, &placed.normal, &u, big, small);
        prop_assert!((placed.cl - expected).norm() < 1e-9, "{placed:?} vs {expected:?}");
    }

    #[test]
    fn placed_tool_never_penetrates_the_mesh(kind in 0u8..3, radius in 1.0..6.0f64, corner in 0.3..3.0f64,
                                             theta in 0.0..0.9f64, phi in 0.0..6.3f64,
                                             x in -12.0..12.0f64, y in -12.0..12.0f64,
                                             a in 0.0..3.0f64, b in 0.0..3.0f64, c in 0.0..2.0f64) {
        let tool = cutter(kind, radius, corner);
        let mesh = bumps(a, b, c);
        let placer = Placer::new(&mesh, &tool, 0.0).unwrap();
        let u = axis(theta, phi);
        let Some(placed) = placer.place(&p(x, y, 30.0), &u) else { return Ok(()); };
        let (e1, e2) = tool_frame(&u);
        // Brute force over every triangle: dense barycentric samples lie on or
        // below the tool's lower surface (within its radius).
        let mut closest = f64::INFINITY;
        for i in 0..mesh.triangles().len() {
            let t = mesh.triangle(i);
            for (ia, ib) in (0..=8).flat_map(|ia| (0..=8 - ia).map(move |ib| (ia, ib))) {
                let (wa, wb) = (f64::from(ia) / 8.0, f64::from(ib) / 8.0);
                let q = t[0] + (t[1] - t[0]) * wa + (t[2] - t[0]) * wb;
                let d = q - placed.tip;
                let rho = d.dot(&e1).hypot(d.dot(&e2));
                if rho <= tool.radius() {
                    let gap = profile(&tool, rho) - d.dot(&u);
                    prop_assert!(gap >= -1e-9, "penetration {gap} at {q:?}: {placed:?}");
                    closest = closest.min(gap);
                }
            }
        }
        // The contact lies on the tool's surface.
        let d = placed.contact - placed.tip;
        let rho = d.dot(&e1).hypot(d.dot(&e2));
        prop_assert!(rho <= tool.radius() + 1e-9);
        prop_assert!((profile(&tool, rho) - d.dot(&u)).abs() < 1e-7, "{placed:?}");
        prop_assert!(closest.is_finite());
    }

    #[test]
    fn axis_z_equals_the_three_axis_drop_cutter(kind in 0u8..3, radius in 1.0..6.0f64, corner in 0.3..3.0f64,
                                                x in -15.0..15.0f64, y in -15.0..15.0f64,
                                                a in 0.0..3.0f64, b in 0.0..3.0f64, c in 0.0..2.0f64) {
        let tool = cutter(kind, radius, corner);
        let mesh = bumps(a, b, c);
        let placed = Placer::new(&mesh, &tool, 0.0).unwrap().place(&p(x, y, 50.0), &Vec3::z()).unwrap();
        let cl = drop_cutter(&tool, &MeshIndex::build(&mesh), Point2::new(x, y), -100.0);
        prop_assert!((placed.tip - cl.tip).norm() < 1e-9, "{placed:?} vs {cl:?}");
    }
}

#[test]
fn flat_tool_square_on_a_plane_touches_with_its_disc() {
    let flat = cutter(1, 4.0, 0.0);
    let placed = Placer::new(&plane(), &flat, 0.0).unwrap().place(&p(3.0, -4.0, 10.0), &Vec3::z()).unwrap();
    assert_eq!(placed.feature, Feature::Facet);
    assert!((placed.tip - p(3.0, -4.0, 0.0)).norm() < 1e-12);
    // The n || u case of spec 5.1: C_L = C_C + r n with r = 0.
    assert!((placed.cl - placed.tip).norm() < 1e-12);
}

#[test]
fn a_line_that_misses_the_mesh_places_nothing() {
    let ball = cutter(0, 2.0, 2.0);
    let placer = Placer::new(&plane(), &ball, 0.0).unwrap();
    assert!(placer.place(&p(500.0, 0.0, 10.0), &Vec3::z()).is_none());
    // A cone is refused with its fix.
    let cone = Cutter::new(CutterShape::Cone { radius: 3.0, half_angle: 0.5 }, 20.0).unwrap();
    assert!(Placer::new(&plane(), &cone, 0.0).is_err());
}
