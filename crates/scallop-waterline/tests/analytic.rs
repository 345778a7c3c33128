//! Analytic cases: contours whose exact shape is known in closed form.
//! Every mesh is generated here.

use std::f64::consts::PI;

use scallop_cutter::{Cutter, CutterShape};
use scallop_geom::{Point2, Point3};
use scallop_mesh::{MeshIndex, TriMesh};
use scallop_waterline::{Loop, WaterlineError, WaterlineGrid, WaterlineOptions, tol, waterline};

#[allow(dead_code)] // the contact checks of the other tests
mod common;

fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

/// A box [0, a] x [0, b] x [0, h]: its top and four walls.
fn box_mesh(a: f64, b: f64, h: f64) -> TriMesh {
    TriMesh::from_soup(&common::box_soup(0.0, 0.0, a, b, h)).expect("valid box").0
}

/// Distance in XY from `q` to the rectangle [0, a] x [0, b] (0 inside).
fn distance_to_rectangle(q: Point2, a: f64, b: f64) -> f64 {
    let dx = (-q.x).max(q.x - a).max(0.0);
    let dy = (-q.y).max(q.y - b).max(0.0);
    dx.hypot(dy)
}

fn midpoints(l: &Loop) -> impl Iterator<Item = Point2> + '_ {
    let n = l.points.len();
    (0..n).map(move |i| {
        let (a, b) = (l.points[i], l.points[(i + 1) % n]);
        Point2::new(0.5 * (a.x + b.x), 0.5 * (a.y + b.y))
    })
}

/// Rounding allowance of the distance checks (mm), far below the tolerances under test.
const ROUNDING: f64 = 1e-9;

/// Each shape on a box: the contour is the rectangle offset by the cutter's
/// radius at the height of the box's top above the tip, `radius_at(h - z)`
/// (the widest part of the cutter that meets the walls), with round corners.
#[test]
fn every_shape_on_a_box_gives_the_rectangle_offset_by_its_radius_at_that_height() {
    let (a, b, h) = (20.0, 12.0, 10.0);
    let mesh = box_mesh(a, b, h);
    let index = MeshIndex::build(&mesh);
    let shapes = [
        CutterShape::Flat { radius: 2.0 },
        CutterShape::Ball { radius: 2.0 },
        CutterShape::Bull { radius: 2.0, corner: 0.5 },
        CutterShape::Cone { radius: 2.0, half_angle: PI / 4.0 },
    ];
    let options = WaterlineOptions::default();
    for shape in shapes {
        let cutter = Cutter::new(shape, 30.0).expect("cutter");
        let grid = WaterlineGrid::new(&cutter, &index, &options).expect("grid");
        for z in [0.0, 3.0, 8.7, 9.0, 9.6] {
            let offset = shape.radius_at(h - z);
            let loops = grid.loops(z).expect("level");
            assert_eq!(loops.len(), 1, "{shape:?} z {z}");
            let l = &loops[0];
            assert!(l.is_outer(), "{shape:?} z {z}: counter-clockwise around the box");
            assert!(l.points.iter().all(|q| q.x.is_finite() && q.y.is_finite()));
            for q in &l.points {
                let d = distance_to_rectangle(*q, a, b);
                // The kept end of each bracket is outside: d >= offset, and within the bracket width.
                assert!(
                    d >= offset - ROUNDING && d <= offset + options.crossing_tolerance + ROUNDING,
                    "{shape:?} z {z}: point {q:?} at {d} from the box, expected {offset}"
                );
            }
            for m in midpoints(l) {
                let d = distance_to_rectangle(m, a, b);
                assert!(
                    d >= offset - options.chord_tolerance - ROUNDING
                        && d <= offset + options.crossing_tolerance + ROUNDING,
                    "{shape:?} z {z}: chord midpoint {m:?} at {d}, expected {offset} within the chord tolerance"
                );
            }
            let area = a * b + 2.0 * (a + b) * offset + PI * offset * offset;
            let sagitta_bound = (a + b + 2.0 * PI * offset) * 2.0 * options.chord_tolerance;
            assert!(
                (l.signed_area() - area).abs() <= sagitta_bound,
                "{shape:?} z {z}: area {} vs {area}",
                l.signed_area()
            );
        }
    }
}

/// A UV sphere of radius `s` centred at the origin, vertices on the sphere.
fn sphere_mesh(s: f64, n_lon: usize, n_lat: usize) -> TriMesh {
    let at = |i: usize, j: usize| {
        let lon = 2.0 * PI * i as f64 / n_lon as f64;
        let lat = -0.5 * PI + PI * j as f64 / n_lat as f64;
        p(s * lat.cos() * lon.cos(), s * lat.cos() * lon.sin(), s * lat.sin())
    };
    let mut soup = Vec::new();
    for i in 0..n_lon {
        for j in 0..n_lat {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            if j > 0 {
                soup.push([a, b, c]);
            }
            if j + 1 < n_lat {
                soup.push([a, c, d]);
            }
        }
    }
    TriMesh::from_soup(&soup).expect("valid sphere").0
}

/// A ball of radius R on a sphere of radius S: the centre of the ball at
/// height z + R touches the sphere at distance S + R from its centre, so the
/// contour is the circle of radius sqrt((S+R)^2 - max(z+R, 0)^2). The mesh is
/// inscribed: its drop-cutter lies between the ones of the spheres of radius
/// S and S cos(theta), theta the angular diameter of a facet.
#[test]
fn a_ball_on_a_sphere_gives_a_circle_of_the_known_radius() {
    let (s, r, n_lon, n_lat) = (10.0, 3.0, 128, 64);
    let mesh = sphere_mesh(s, n_lon, n_lat);
    let index = MeshIndex::build(&mesh);
    let inscribed = s * (2.0 * PI / n_lon as f64).hypot(PI / n_lat as f64).cos();
    let ball = Cutter::new(CutterShape::Ball { radius: r }, 30.0).expect("cutter");
    let options = WaterlineOptions::default();
    let grid = WaterlineGrid::new(&ball, &index, &options).expect("grid");
    for z in [-9.0, -4.0, -1.0, 0.0, 2.5, 5.0, 8.0, 9.5] {
        let radius = |sphere: f64| ((sphere + r).powi(2) - (z + r).max(0.0).powi(2)).max(0.0).sqrt();
        let (lo, hi) = (radius(inscribed), radius(s));
        let loops = grid.loops(z).expect("level");
        assert_eq!(loops.len(), 1, "z {z}");
        assert!(loops[0].is_outer());
        for q in &loops[0].points {
            let rho = q.coords.norm();
            assert!(rho >= lo - ROUNDING && rho <= hi + options.crossing_tolerance, "z {z}: {rho} not in [{lo}, {hi}]");
        }
    }
}

/// A vertical cylinder (a regular prism with its top) and a flat cutter: the
/// contour is the prism's polygon offset by R, between the circles of radius
/// Rc cos(pi/n) + R and Rc + R.
#[test]
fn a_flat_cutter_on_a_cylinder_gives_the_offset_circle() {
    let (rc, height, n) = (8.0, 10.0, 96);
    let at = |i: usize, z: f64| {
        let t = 2.0 * PI * i as f64 / n as f64;
        p(rc * t.cos(), rc * t.sin(), z)
    };
    let centre = p(0.0, 0.0, height);
    let mut soup = Vec::new();
    for i in 0..n {
        soup.push([centre, at(i, height), at(i + 1, height)]);
        soup.push([at(i, 0.0), at(i + 1, 0.0), at(i + 1, height)]);
        soup.push([at(i, 0.0), at(i + 1, height), at(i, height)]);
    }
    let mesh = TriMesh::from_soup(&soup).expect("valid cylinder").0;
    let index = MeshIndex::build(&mesh);
    let r = 2.5;
    let flat = Cutter::new(CutterShape::Flat { radius: r }, 30.0).expect("cutter");
    let options = WaterlineOptions::default();
    let (lo, hi) = (rc * (PI / n as f64).cos() + r, rc + r);
    for z in [0.5, 4.0, 9.9] {
        let loops = waterline(&flat, &index, z, &options).expect("level");
        assert_eq!(loops.len(), 1);
        assert!(loops[0].is_outer());
        for q in &loops[0].points {
            let rho = q.coords.norm();
            assert!(rho >= lo - ROUNDING && rho <= hi + options.crossing_tolerance, "z {z}: {rho} not in [{lo}, {hi}]");
        }
        // The chords stay within the chord tolerance of the true (convex) contour.
        for m in midpoints(&loops[0]) {
            assert!(m.coords.norm() >= lo - options.chord_tolerance - ROUNDING);
        }
    }
}

/// A square pocket in a plate: the loop around the pocket runs clockwise (the
/// material, where the cutter would cut, is outside it), inset by R.
#[test]
fn a_pocket_gives_a_clockwise_loop_inset_by_the_radius() {
    // Plate [0, 30]^2 at height 10 with a pocket [10, 20]^2 down to height 2.
    let (lo, hi, top, bottom) = (10.0, 20.0, 10.0, 2.0);
    let q = |x, y, z| p(x, y, z);
    let mut soup = vec![
        // plate top around the pocket (four trapezoids, two triangles each)
        [q(0., 0., top), q(30., 0., top), q(hi, lo, top)],
        [q(0., 0., top), q(hi, lo, top), q(lo, lo, top)],
        [q(30., 0., top), q(30., 30., top), q(hi, hi, top)],
        [q(30., 0., top), q(hi, hi, top), q(hi, lo, top)],
        [q(30., 30., top), q(0., 30., top), q(lo, hi, top)],
        [q(30., 30., top), q(lo, hi, top), q(hi, hi, top)],
        [q(0., 30., top), q(0., 0., top), q(lo, lo, top)],
        [q(0., 30., top), q(lo, lo, top), q(lo, hi, top)],
        // pocket floor
        [q(lo, lo, bottom), q(hi, lo, bottom), q(hi, hi, bottom)],
        [q(lo, lo, bottom), q(hi, hi, bottom), q(lo, hi, bottom)],
    ];
    let corners = [q(lo, lo, 0.), q(hi, lo, 0.), q(hi, hi, 0.), q(lo, hi, 0.)];
    for k in 0..4 {
        let (a, b) = (corners[k], corners[(k + 1) % 4]);
        let (a0, b0, a1, b1) = (q(a.x, a.y, bottom), q(b.x, b.y, bottom), q(a.x, a.y, top), q(b.x, b.y, top));
        soup.push([a0, b0, b1]);
        soup.push([a0, b1, a1]);
    }
    let mesh = TriMesh::from_soup(&soup).expect("valid pocket").0;
    let index = MeshIndex::build(&mesh);
    let r = 2.0;
    let flat = Cutter::new(CutterShape::Flat { radius: r }, 30.0).expect("cutter");
    let options = WaterlineOptions::default();
    let loops = waterline(&flat, &index, 5.0, &options).expect("level");
    assert_eq!(loops.len(), 2, "the outside of the plate and the pocket");
    let outer: Vec<_> = loops.iter().filter(|l| l.is_outer()).collect();
    let pocket: Vec<_> = loops.iter().filter(|l| !l.is_outer()).collect();
    assert_eq!((outer.len(), pocket.len()), (1, 1));
    // Inside the pocket a flat cutter at z fits where it is at least R from every wall:
    // the square [lo + R, hi - R]^2 with sharp corners.
    for q in &pocket[0].points {
        let inset = (q.x - lo).min(hi - q.x).min(q.y - lo).min(hi - q.y);
        assert!(inset >= r - ROUNDING && inset <= r + options.crossing_tolerance + ROUNDING, "{q:?}: {inset}");
    }
    let side = hi - lo - 2.0 * r;
    assert!((pocket[0].signed_area() + side * side).abs() < 1e-3, "{}", pocket[0].signed_area());
}

#[test]
fn bad_inputs_are_typed_errors() {
    let mesh = box_mesh(4.0, 4.0, 2.0);
    let index = MeshIndex::build(&mesh);
    let ball = Cutter::new(CutterShape::Ball { radius: 1.0 }, 10.0).expect("cutter");
    let o = WaterlineOptions::default();
    assert!(matches!(waterline(&ball, &index, f64::NAN, &o), Err(WaterlineError::NonFiniteZ { .. })));
    assert!(matches!(waterline(&ball, &index, f64::INFINITY, &o), Err(WaterlineError::NonFiniteZ { .. })));
    assert!(matches!(waterline(&ball, &index, 2.0, &o), Err(WaterlineError::ZOutsidePart { .. })));
    assert!(matches!(waterline(&ball, &index, -0.1, &o), Err(WaterlineError::ZOutsidePart { .. })));
    for step in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e-8] {
        let bad = WaterlineOptions { step: Some(step), ..o };
        assert!(matches!(waterline(&ball, &index, 1.0, &bad), Err(WaterlineError::BadStep { .. })), "{step}");
    }
    let absurd = WaterlineOptions { step: Some(1e-5), ..o };
    assert!(matches!(waterline(&ball, &index, 1.0, &absurd), Err(WaterlineError::TooManySamples { .. })));
    for value in [0.0, -1.0, f64::NAN, 1e-30] {
        let bad = WaterlineOptions { chord_tolerance: value, ..o };
        assert!(matches!(waterline(&ball, &index, 1.0, &bad), Err(WaterlineError::BadTolerance { .. })));
        let bad = WaterlineOptions { crossing_tolerance: value, ..o };
        assert!(matches!(waterline(&ball, &index, 1.0, &bad), Err(WaterlineError::BadTolerance { .. })));
    }
    // The messages name the fix.
    let e = waterline(&ball, &index, 7.0, &o).expect_err("above the part");
    assert!(e.to_string().contains("give a z in that range"), "{e}");
    assert!(tol::CROSSING_TOLERANCE < tol::CHORD_TOLERANCE);
}
