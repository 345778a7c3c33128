//! Tessellation: every sampled surface point lies within the tolerance of the mesh.

mod common;

use common::{
    builtin_patch, p, point_triangle_distance, quarter_cylinder, rational_nurbs, rubio_split_as_nurbs, set_of,
};
use scallop_geom::Point3;
use scallop_geom::rng::SplitMix64;
use scallop_mesh::TriMesh;
use scallop_surface::{Direction, Patch, SurfaceError, Tessellation};

/// Largest distance from surface points to the mesh, by brute force: `samples`
/// random points, plus (for Bezier patches, whose grid is uniform) the centre of
/// every cell, the midpoint of the diagonal, where the bound's maximum sits.
fn max_deviation(patch: &Patch, mesh: &TriMesh, cells: Option<[usize; 2]>, samples: usize, seed: u64) -> f64 {
    let mut rng = SplitMix64::new(seed);
    let soup = mesh.soup();
    let domain = patch.domain();
    let mut params: Vec<(f64, f64)> = (0..samples).map(|_| domain.lerp(rng.unit(), rng.unit())).collect();
    if let (true, Some([nu, nv])) = (patch.is_bezier(), cells) {
        for i in 0..nu {
            for j in 0..nv {
                params.push(((i as f64 + 0.5) / nu as f64, (j as f64 + 0.5) / nv as f64));
            }
        }
    }
    let mut worst = 0.0_f64;
    for (u, v) in params {
        let q = patch.point(u, v);
        let d = soup.iter().map(|t| point_triangle_distance(&q, *t)).fold(f64::INFINITY, f64::min);
        worst = worst.max(d);
    }
    worst
}

fn check(patch: &Patch, tolerance: f64, samples: usize) -> Tessellation {
    let t = patch.tessellate(tolerance).expect("tessellates");
    assert!(t.chordal_bound <= tolerance, "{}: bound {} > {tolerance}", patch.name(), t.chordal_bound);
    let worst = max_deviation(patch, &t.mesh, Some(t.cells[0]), samples, 11);
    eprintln!(
        "{}: tol {tolerance}, bound {:.3e}, measured {worst:.3e}, cells {:?}",
        patch.name(),
        t.chordal_bound,
        t.cells
    );
    assert!(worst <= tolerance, "{}: deviation {worst} > {tolerance} (bound {})", patch.name(), t.chordal_bound);
    assert!(worst <= t.chordal_bound + 1e-12, "{}: deviation {worst} > bound {}", patch.name(), t.chordal_bound);
    t
}

#[test]
fn builtins_stay_within_tolerance() {
    for (name, tolerance) in [("choi", 0.05), ("choi", 0.01), ("rubio", 0.05), ("rubio", 0.01)] {
        let patch = builtin_patch(name);
        let t = check(&patch, tolerance, 1500);
        assert!(t.guaranteed);
        let [nu, nv] = t.cells[0];
        assert_eq!(t.mesh.triangles().len(), 2 * nu * nv, "{name}: no triangle is degenerate");
    }
}

#[test]
fn rational_and_nurbs_patches_stay_within_tolerance() {
    let cylinder = check(&quarter_cylinder(12.0, 30.0), 0.01, 1500);
    assert!(!cylinder.guaranteed, "rational: sampled bound");
    let wavy = check(&rational_nurbs(), 0.02, 1000);
    assert!(!wavy.guaranteed);
    let split = check(&rubio_split_as_nurbs(), 0.02, 1000);
    assert!(split.guaranteed);
}

#[test]
fn grid_lines_include_knots_so_creases_are_exact() {
    // Degree 2 in u with a double interior knot at 0.4: a C0 crease along u = 0.4.
    let rows = [p(0., 0., 0.), p(2., 0., 5.), p(4., 0., 0.), p(6., 0., 3.), p(8., 0., 0.)];
    let control: Vec<Vec<Point3>> = rows.iter().map(|r| vec![*r, r + scallop_geom::Vec3::new(0., 10., 0.)]).collect();
    let crease =
        Patch::nurbs("crease", [2, 1], [vec![0., 0., 0., 0.4, 0.4, 1., 1., 1.], vec![0., 0., 1., 1.]], &control, None)
            .expect("valid");
    assert_eq!(crease.span_breaks(Direction::U), vec![0.0, 0.4, 1.0]);
    let t = check(&crease, 0.01, 1000);
    // The crease point S(0.4, v) = (4, v, 0) is a mesh vertex.
    assert!(t.mesh.vertices().iter().any(|v| (v - p(4., 0., 0.)).norm() < 1e-12));
}

#[test]
fn flat_patches_need_one_cell() {
    let flat =
        Patch::bezier("flat", [1, 1], &[vec![p(0., 0., 0.), p(1., 5., 0.)], vec![p(7., 0., 1.), p(8., 5., 1.)]], None)
            .expect("valid");
    let t = flat.tessellate(1e-6).expect("tessellates");
    assert_eq!(t.cells, vec![[1, 1]]);
    assert!(t.chordal_bound.abs() <= 0.0, "{}", t.chordal_bound);
}

#[test]
fn triangles_face_like_su_cross_sv() {
    let choi = builtin_patch("choi");
    let t = choi.tessellate(0.05).expect("tessellates");
    for tri in t.mesh.soup() {
        let [a, b, c] = tri;
        let n = (b - a).cross(&(c - a));
        let centroid = Point3::from((a.coords + b.coords + c.coords) / 3.0);
        let q = choi.closest_point(&centroid);
        assert!(n.dot(&choi.normal(q.u, q.v)) > 0.0);
    }
}

#[test]
fn sets_tessellate_into_one_mesh() {
    let set = set_of(vec![builtin_patch("choi"), builtin_patch("rubio"), quarter_cylinder(12.0, 30.0)]);
    let t = set.tessellate(0.05).expect("tessellates");
    assert_eq!(t.cells.len(), 3);
    assert!(!t.guaranteed);
    let cells: usize = t.cells.iter().map(|[a, b]| a * b).sum();
    assert_eq!(t.mesh.triangles().len(), 2 * cells);
    for (patch, seed) in set.patches().iter().zip(1..) {
        let worst = max_deviation(patch, &t.mesh, None, 400, seed);
        assert!(worst <= 0.05, "{}: {worst}", patch.name());
    }
    let area = set.area();
    assert!((t.mesh.area() - area).abs() < 1e-3 * area);
}

#[test]
fn bad_requests_are_errors() {
    let choi = builtin_patch("choi");
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(choi.tessellate(bad), Err(SurfaceError::BadTolerance { .. })), "{bad}");
    }
    let set = set_of(vec![builtin_patch("rubio"), choi]);
    let err = set.tessellate(1e-9).expect_err("too fine");
    assert!(matches!(&err, SurfaceError::TooFine { patch, .. } if patch.index == Some(0) && patch.name == "rubio"));
    assert!(err.to_string().starts_with("patch #0 \"rubio\": meeting the chordal tolerance needs"), "{err}");
    // A patch that is a curve has no triangles.
    let line =
        Patch::bezier("line", [1, 1], &[vec![p(0., 0., 0.), p(1., 0., 0.)], vec![p(2., 0., 0.), p(3., 0., 0.)]], None)
            .expect("valid");
    assert!(matches!(line.tessellate(0.1), Err(SurfaceError::Mesh { .. })));
}
