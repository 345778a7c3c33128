//! Evaluation: closed forms, finite differences, Bezier/NURBS agreement, normals.

mod common;

use common::{assert_vec_near, builtin_patch, p, quarter_cylinder, rational_nurbs, rubio_split_as_nurbs};
use scallop_geom::{Vec3, assert_near};
use scallop_surface::{Domain, Patch};

/// Checks the exact derivatives of `patch` at `(u, v)` against central differences
/// of the point (first derivatives) and of the exact first derivatives (second).
fn check_against_finite_differences(patch: &Patch, u: f64, v: f64) {
    let d = patch.derivatives(u, v);
    let domain = patch.domain();
    let h = 1e-5 * (domain.u[1] - domain.u[0]).max(domain.v[1] - domain.v[0]);
    let s = |u: f64, v: f64| patch.derivatives(u, v);
    let fd_u = (s(u + h, v).point - s(u - h, v).point) / (2.0 * h);
    let fd_v = (s(u, v + h).point - s(u, v - h).point) / (2.0 * h);
    let fd_uu = (s(u + h, v).du - s(u - h, v).du) / (2.0 * h);
    let fd_uv = (s(u, v + h).du - s(u, v - h).du) / (2.0 * h);
    let fd_vu = (s(u + h, v).dv - s(u - h, v).dv) / (2.0 * h);
    let fd_vv = (s(u, v + h).dv - s(u, v - h).dv) / (2.0 * h);
    let tol = 1e-6;
    let at = format!("{} at ({u}, {v})", patch.name());
    assert_vec_near(&d.du, &fd_u, tol, &format!("Su {at}"));
    assert_vec_near(&d.dv, &fd_v, tol, &format!("Sv {at}"));
    assert_vec_near(&d.duu, &fd_uu, tol, &format!("Suu {at}"));
    assert_vec_near(&d.duv, &fd_uv, tol, &format!("Suv {at}"));
    assert_vec_near(&d.duv, &fd_vu, tol, &format!("Svu {at}"));
    assert_vec_near(&d.dvv, &fd_vv, tol, &format!("Svv {at}"));
}

#[test]
fn derivatives_match_finite_differences() {
    let patches = [
        builtin_patch("choi"),
        builtin_patch("rubio"),
        quarter_cylinder(12.0, 30.0),
        rational_nurbs(),
        rubio_split_as_nurbs(),
    ];
    for patch in &patches {
        let domain = patch.domain();
        // Fractions chosen away from every knot of the fixtures (finite differences
        // across a knot see the jump of the second derivative).
        for s in [0.07, 0.31, 0.46, 0.58, 0.93] {
            for t in [0.11, 0.37, 0.64, 0.89] {
                let (u, v) = domain.lerp(s, t);
                check_against_finite_differences(patch, u, v);
            }
        }
    }
}

#[test]
fn bilinear_patch_has_closed_form_derivatives() {
    let (p00, p10, p01, p11) = (p(0., 0., 1.), p(10., 1., 0.), p(-1., 8., 2.), p(12., 9., 7.));
    let patch = Patch::bezier("bilinear", [1, 1], &[vec![p00, p01], vec![p10, p11]], None).expect("valid");
    for (u, v) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.25), (0.5, 1.0)] {
        let d = patch.derivatives(u, v);
        let point = p00.coords * ((1. - u) * (1. - v))
            + p10.coords * (u * (1. - v))
            + p01.coords * ((1. - u) * v)
            + p11.coords * (u * v);
        assert_vec_near(&d.point.coords, &point, 1e-14, "S");
        assert_vec_near(&d.du, &((p10 - p00) * (1. - v) + (p11 - p01) * v), 1e-14, "Su");
        assert_vec_near(&d.dv, &((p01 - p00) * (1. - u) + (p11 - p10) * u), 1e-14, "Sv");
        assert_eq!(d.duu, Vec3::zeros());
        assert_eq!(d.dvv, Vec3::zeros());
        assert_vec_near(&d.duv, &(p11.coords - p10.coords - p01.coords + p00.coords), 1e-14, "Suv");
    }
}

#[test]
fn quarter_cylinder_is_exact() {
    let (r, h) = (12.0, 30.0);
    let cylinder = quarter_cylinder(r, h);
    for k in 0..=40 {
        let u = f64::from(k) / 40.0;
        for v in [0.0, 0.35, 1.0] {
            let d = cylinder.derivatives(u, v);
            let radial = Vec3::new(d.point.x, d.point.y, 0.0);
            // On the cylinder, at the right height, in the first quadrant.
            assert_near!(radial.norm(), r, 1e-12 * r);
            assert_near!(d.point.z, v * h, 1e-12 * h);
            assert!(d.point.x >= -1e-12 && d.point.y >= -1e-12);
            // Sv = (0, 0, h); Suv = Svv = 0 (linear in v, weights independent of v).
            assert_vec_near(&d.dv, &Vec3::new(0., 0., h), 1e-13, "Sv");
            assert!(d.duv.norm() <= 1e-12 && d.dvv.norm() <= 1e-12, "{:?} {:?}", d.duv, d.dvv);
            // Su is tangent to the circle; the normal part of Suu is the circle's
            // centripetal acceleration |Su|^2 / r towards the axis.
            let e = radial / r;
            assert_near!(d.du.dot(&e), 0.0, 1e-12 * d.du.norm());
            assert_near!(d.duu.dot(&e), -d.du.norm_squared() / r, 1e-11 * d.du.norm_squared() / r);
            // The normal Su x Sv is radial (outward for this orientation).
            assert_vec_near(&cylinder.normal(u, v), &e, 1e-12, "normal");
        }
    }
    // End tangents: along +y at u = 0, along -x at u = 1 (speed 2 w r / 1 = sqrt(2) r for w = 1/sqrt 2).
    let speed = std::f64::consts::SQRT_2 * r;
    assert_vec_near(&cylinder.derivatives(0.0, 0.5).du, &Vec3::new(0., speed, 0.), 1e-13, "Su(0)");
    assert_vec_near(&cylinder.derivatives(1.0, 0.5).du, &Vec3::new(-speed, 0., 0.), 1e-13, "Su(1)");
}

#[test]
fn bezier_and_split_nurbs_are_the_same_surface() {
    let rubio = builtin_patch("rubio");
    let split = rubio_split_as_nurbs();
    assert!(!split.is_bezier() && rubio.is_bezier());
    assert_eq!(split.span_breaks(scallop_surface::Direction::U), vec![0.0, 0.5, 1.0]);
    for k in 0..=20 {
        for l in 0..=20 {
            let (u, v) = (f64::from(k) / 20.0, f64::from(l) / 20.0);
            let (a, b) = (rubio.derivatives(u, v), split.derivatives(u, v));
            let what = format!("({u}, {v})");
            assert_vec_near(&a.point.coords, &b.point.coords, 1e-13, &what);
            assert_vec_near(&a.du, &b.du, 1e-13, &what);
            assert_vec_near(&a.dv, &b.dv, 1e-13, &what);
            assert_vec_near(&a.duu, &b.duu, 1e-12, &what);
            assert_vec_near(&a.duv, &b.duv, 1e-12, &what);
            assert_vec_near(&a.dvv, &b.dvv, 1e-12, &what);
        }
    }
}

#[test]
fn bezier_as_clamped_nurbs_matches_and_weights_of_one_change_nothing() {
    let choi = builtin_patch("choi");
    let [rows, columns] = choi.control_shape();
    let net: Vec<Vec<_>> = (0..rows).map(|i| (0..columns).map(|j| choi.control_point(i, j)).collect()).collect();
    let clamped = vec![0., 0., 0., 0., 1., 1., 1., 1.];
    let nurbs = Patch::nurbs("choi-nurbs", [3, 3], [clamped.clone(), clamped], &net, None).expect("valid");
    let rational = Patch::bezier("choi-rational", [3, 3], &net, Some(&vec![vec![2.5; 4]; 4])).expect("valid");
    for (u, v) in [(0.0, 0.0), (0.2, 0.9), (0.5, 0.5), (1.0, 1.0), (0.73, 0.0)] {
        let a = choi.derivatives(u, v);
        for other in [&nurbs, &rational] {
            let b = other.derivatives(u, v);
            assert_vec_near(&a.point.coords, &b.point.coords, 1e-13, "S");
            assert_vec_near(&a.du, &b.du, 1e-12, "Su");
            assert_vec_near(&a.duv, &b.duv, 1e-12, "Suv");
            assert_vec_near(&a.dvv, &b.dvv, 1e-12, "Svv");
        }
    }
}

#[test]
fn nurbs_domain_is_the_knot_range_and_evaluation_clamps() {
    let wavy = rational_nurbs();
    assert_eq!(wavy.domain(), Domain { u: [1.0, 3.0], v: [2.0, 4.0] });
    assert_eq!(wavy.point(-5.0, 100.0), wavy.point(1.0, 4.0));
    assert_eq!(wavy.point(f64::NAN, 3.0), wavy.point(1.0, 3.0));
    // The last knot belongs to the last span: continuous up to the end.
    let end = wavy.point(3.0, 4.0);
    let near = wavy.point(3.0 - 1e-12, 4.0 - 1e-12);
    assert!((end - near).norm() < 1e-9);
    // The corner of a clamped direction interpolates the corner control row.
    let choi = builtin_patch("choi");
    assert_eq!(choi.point(1.0, 0.0), choi.control_point(3, 0));
    assert_eq!(choi.point(0.0, 1.0), choi.control_point(0, 3));
}

#[test]
fn normal_is_normalised_cross_product_and_falls_back_at_collapsed_edges() {
    let choi = builtin_patch("choi");
    let d = choi.derivatives(0.4, 0.6);
    let n = d.du.cross(&d.dv).normalize();
    assert_vec_near(&choi.normal(0.4, 0.6), &n, 1e-15, "regular normal");

    // A degree 2 x 1 patch whose edge v = 0 collapses to a point (a fan).
    let apex = p(0., 0., 5.);
    let fan = Patch::bezier(
        "fan",
        [2, 1],
        &[vec![apex, p(10., 0., 0.)], vec![apex, p(10., 10., 1.)], vec![apex, p(0., 10., 0.)]],
        None,
    )
    .expect("valid");
    for u in [0.0, 0.3, 1.0] {
        let at_edge = fan.normal(u, 0.0);
        let inside = fan.normal(u, 1e-7);
        assert_near!(at_edge.norm(), 1.0, 1e-12);
        assert!((at_edge - inside).norm() < 1e-5, "u = {u}: {at_edge:?} vs {inside:?}");
    }
    // A surface that is a single point: +Z.
    let o = p(1., 2., 3.);
    let point = Patch::bezier("point", [1, 1], &[vec![o, o], vec![o, o]], None).expect("valid");
    assert_eq!(point.normal(0.5, 0.5), Vec3::z());
}
