//! Marching Facets checks (Jousselin 2020, Ch. 2 §3.2.1; docs/guides-curves.md):
//! edge points at a_e from the previous curve, k a_e from C_n on a plane,
//! spacing a_e on a cylinder, offset counts of convex loops, splitting of a
//! dumbbell, medial-axis facets, no self-intersection, nothing outside C_n.

#![allow(clippy::unwrap_used, clippy::float_cmp, reason = "tests: a panic is the failure report")]

mod common;

use common::*;
use proptest::prelude::*;
use scallop_geom::{Point3, Vec3};
use scallop_guides::{Curve, GuideError, OffsetStep, offset_curves};
use scallop_mesh::{Polyline3, PolylineQuery};

/// Every vertex of every offset is a_e from the curve before (root finding:
/// within 1e-6 mm), the first from `limit`.
fn check_spacing(limit: &[Curve], steps: &[OffsetStep], a_e: f64) {
    let mut prev = limit.to_vec();
    for (k, s) in steps.iter().enumerate() {
        let q = PolylineQuery::new(prev.iter().map(|c| c.line.clone()).collect());
        for x in s.curves.iter().flat_map(|c| c.line.points.iter()) {
            let d = q.distance(x);
            assert!((d - a_e).abs() <= 1e-6, "step {k}: point {x} at {d} from the previous curve, not {a_e}");
        }
        prev = s.curves.clone();
    }
}

#[test]
fn plane_circle_offsets_are_k_ae_from_the_limit() {
    let support = flat(0.0, 25.0, 1.0);
    let limit = vec![on(&support, circle(p(0.3, -0.2, 0.0), 20.0, 400))];
    let a_e = 4.5;
    let steps = offset_curves(&support, &limit, a_e).unwrap();
    check_spacing(&limit, &steps, a_e);
    let h = support.facet_size();
    assert!((steps.len() as i64 - 4).abs() <= 1, "{} offsets", steps.len());
    for (k, s) in steps.iter().enumerate() {
        assert_eq!(s.curves.len(), 1);
        assert!(s.curves[0].line.closed);
        let kae = (k + 1) as f64 * a_e;
        let (lo, hi) = (min_distance(&s.curves, &limit), max_distance(&s.curves, &limit));
        assert!(lo >= kae - h && hi <= kae + h, "step {k}: {lo}..{hi} from C_n, not {kae}");
        assert!(!self_intersects_xy(&s.curves[0].line));
        assert!(s.curves[0].line.points.iter().all(|x| winding_xy(&limit[0].line, x) == 1));
        assert!(s.curves[0].signed_area() > 0.0, "inside stays on the left");
    }
}

#[test]
fn cylinder_generator_offsets_stay_ae_apart() {
    let (r, a_e) = (20.0, 4.5);
    let support = cylinder(r, -0.3, 2.5, 30.0, 0.5);
    // A generator at angle 0 travelled downwards: its left (n x T) is +angle.
    let generator = Polyline3::new(vec![p(r, 0.0, 30.0), p(r, 0.0, 0.0)], false);
    let limit = vec![support.curve(generator).unwrap()];
    let steps = offset_curves(&support, &limit, a_e).unwrap();
    check_spacing(&limit, &steps, a_e);
    let dtheta = 2.0 * (a_e / (2.0 * r)).asin();
    let h = support.facet_size();
    assert!(steps.len() >= 5);
    let mut prev = limit.clone();
    for (k, s) in steps.iter().enumerate() {
        assert_eq!(s.curves.len(), 1);
        // Consecutive spacing a_e both ways (not the drifting iso-levels of one field).
        assert!((max_distance(&prev, &s.curves) - a_e).abs() <= h);
        for x in &s.curves[0].line.points {
            let angle = x.y.atan2(x.x);
            assert!((angle - (k + 1) as f64 * dtheta).abs() * r <= h, "step {k}: angle {angle}");
        }
        prev = s.curves.clone();
    }
}

#[test]
fn sphere_latitude_offsets_are_exact() {
    let support = sphere_cap(30.0, 1.2, 1.0);
    let ring = 30.0 * 1.1f64.sin();
    let mut limit_line = circle(p(0.0, 0.0, 30.0 * 1.1f64.cos()), ring, 300);
    for x in &mut limit_line.points {
        *x = support.query().closest_point(x).point;
    }
    let limit = vec![on(&support, limit_line)];
    let steps = offset_curves(&support, &limit, 3.0).unwrap();
    assert!(steps.len() >= 5);
    check_spacing(&limit, &steps, 3.0);
    assert!(steps.iter().all(|s| s.curves.len() == 1 && s.curves[0].line.closed));
}

#[test]
fn dumbbell_offsets_split_in_two() {
    let support = flat(0.0, 34.0, 0.5);
    let limit = vec![on(&support, dumbbell(12.0, 18.0, 4.0, 0.5))];
    let a_e = 3.0;
    let steps = offset_curves(&support, &limit, a_e).unwrap();
    check_spacing(&limit, &steps, a_e);
    assert_eq!(steps[0].curves.len(), 1, "the neck (half-width 4) survives a 3 mm offset");
    let split = steps.iter().position(|s| s.split).unwrap();
    assert_eq!(split, 1, "the neck vanishes at 6 mm");
    assert_eq!(steps[split].curves.len(), 2);
    for s in &steps {
        for c in &s.curves {
            assert!(c.line.closed && !self_intersects_xy(&c.line));
            assert!(c.line.points.iter().all(|x| winding_xy(&limit[0].line, x) == 1));
        }
    }
}

#[test]
fn medial_axis_facets_give_no_wrong_segment() {
    // A square's offsets turn at the diagonals (its medial axis).
    let support = flat(0.0, 22.0, 1.0);
    let sq = |s: f64| Polyline3::new(vec![p(-s, -s, 0.0), p(s, -s, 0.0), p(s, s, 0.0), p(-s, s, 0.0)], true);
    let limit = vec![on(&support, sq(18.0))];
    let a_e = 4.0;
    let steps = offset_curves(&support, &limit, a_e).unwrap();
    check_spacing(&limit, &steps, a_e);
    assert!(steps.iter().map(|s| s.flagged).sum::<usize>() > 0);
    assert!(steps.iter().map(|s| s.repaired).sum::<usize>() > 0);
    let h = support.facet_size();
    let mut prev = limit.clone();
    for s in &steps {
        let q = PolylineQuery::new(prev.iter().map(|c| c.line.clone()).collect());
        for c in &s.curves {
            for i in 0..c.line.segment_count() {
                let (a, b) = c.line.segment(i);
                let d = q.distance(&Point3::from((a.coords + b.coords) * 0.5));
                assert!((d - a_e).abs() <= h / 2.0, "segment {a} {b}: middle at {d}");
            }
        }
        prev = s.curves.clone();
    }
    // The k-th offset of a square of half-side 18 is the square of half-side 18 - k a_e.
    assert_eq!(steps.len(), 4);
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let support = flat(0.0, 34.0, 1.0);
    let limit = vec![on(&support, dumbbell(12.0, 18.0, 4.0, 1.0))];
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| offset_curves(&support, &limit, 3.0).unwrap())
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn bad_inputs_are_errors() {
    let support = flat(0.0, 10.0, 1.0);
    let limit = vec![on(&support, circle(p(0.0, 0.0, 0.0), 5.0, 40))];
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(offset_curves(&support, &limit, bad), Err(GuideError::BadLength { .. })));
    }
    let dot = Polyline3::new(vec![p(0.0, 0.0, 0.0)], true);
    assert!(matches!(support.curve(dot), Err(GuideError::BadCurve { .. })));
    let nan = Polyline3::new(vec![p(0.0, 0.0, 0.0), p(f64::NAN, 0.0, 0.0)], false);
    assert!(matches!(support.curve(nan), Err(GuideError::BadCurve { .. })));
    // A curve off the mesh: offsets on the mesh or none, never a panic.
    let far = vec![support.curve(circle(p(100.0, 0.0, 0.0), 5.0, 40)).unwrap()];
    assert!(offset_curves(&support, &far, 1.0).is_ok());
    let _ = Vec3::zeros();
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// A convex loop on a plane gets floor(inradius / a_e) +- 1 offsets.
    #[test]
    fn convex_loop_offset_count(a in 8.0..18.0f64, ratio in 0.5..1.0f64, sides in 3usize..12, a_e in 2.0..6.0f64) {
        let support = flat(0.0, 20.0, 1.0);
        let b = a * ratio;
        let n = sides.max(3) * 8;
        // An ellipse with semi-axes a, b sampled at n points (inradius b).
        let pts: Vec<Point3> = (0..n)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / n as f64;
                p(a * t.cos(), b * t.sin(), 0.0)
            })
            .collect();
        let limit = vec![on(&support, Polyline3::new(pts, true))];
        let steps = offset_curves(&support, &limit, a_e).unwrap();
        let expected = (b / a_e).floor() as i64;
        prop_assert!((steps.len() as i64 - expected).abs() <= 1, "{} offsets, expected {}", steps.len(), expected);
        for s in &steps {
            prop_assert_eq!(s.curves.len(), 1);
            prop_assert!(!self_intersects_xy(&s.curves[0].line));
            prop_assert!(s.curves[0].line.points.iter().all(|x| winding_xy(&limit[0].line, x) == 1));
        }
    }
}

#[test]
fn a_far_mesh_component_adds_no_loop() {
    let near = flat(0.0, 15.0, 1.0);
    let far = flat(40.0, 15.0, 1.0);
    let both = scallop_mesh::TriMesh::from_soup(&[near.mesh().soup(), far.mesh().soup()].concat()).unwrap().0;
    let support = scallop_guides::Support::new(both);
    let limit = vec![on(&support, circle(p(0.0, 0.0, 0.0), 13.0, 260))];
    let steps = offset_curves(&support, &limit, 4.0).unwrap();
    assert_eq!(steps.len(), 3);
    assert!(steps.iter().all(|s| s.curves.len() == 1 && s.curves[0].line.points.iter().all(|x| x.z == 0.0)));
    check_spacing(&limit, &steps, 4.0);
}

#[test]
fn hand_built_curves_are_checked() {
    let support = flat(0.0, 10.0, 1.0);
    let mut c = on(&support, circle(p(0.0, 0.0, 0.0), 5.0, 40));
    c.normals.pop();
    assert!(matches!(offset_curves(&support, std::slice::from_ref(&c), 1.0), Err(GuideError::BadCurve { .. })));
    assert!(matches!(scallop_guides::offset_curve(&support, &[c], 1.0), Err(GuideError::BadCurve { .. })));
    let empty = Curve { line: Polyline3::new(vec![], true), normals: vec![] };
    assert_eq!(empty.signed_area(), 0.0);
    assert!(
        scallop_guides::morph_level(&support, std::slice::from_ref(&empty), std::slice::from_ref(&empty), 0.5)
            .is_empty()
    );
}
