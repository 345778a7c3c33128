//! The vectorial offset (Jousselin 2020, Annex A, Alg. 1-3) against Eq. 2.9
//! and against the scalar method (Marching Facets).

#![allow(clippy::unwrap_used, reason = "tests: a panic is the failure report")]

mod common;

use common::*;
use scallop_guides::{Curve, Support, VectorialOptions, offset_curve, vectorial_offset};
use scallop_mesh::{Polyline3, PolylineQuery};

const OPTS: VectorialOptions = VectorialOptions { d_tol: 0.01, k_max: 20, spacing: 0.25 };

fn l_shape() -> Polyline3 {
    let q = |x, y| p(x, y, 0.0);
    Polyline3::new(vec![q(-15., -15.), q(15., -15.), q(15., 0.), q(0., 0.), q(0., 15.), q(-15., 15.)], true)
}

/// Both ways, every point of one within `tol` of the other.
fn close(a: &Curve, b: &[Curve], tol: f64) {
    let (d1, d2) = (max_distance(std::slice::from_ref(a), b), max_distance(b, std::slice::from_ref(a)));
    assert!(d1 <= tol && d2 <= tol, "{d1} {d2} > {tol}");
}

fn check(support: &Support, limit: &Curve, d: f64) {
    let v = vectorial_offset(support, limit, d, &OPTS).unwrap();
    let whole = PolylineQuery::new(vec![limit.line.clone()]);
    // Eq. 2.9 for every point (the output chords are 0.25 mm: sagitta below 0.003 mm).
    let sagitta = OPTS.spacing * OPTS.spacing / (8.0 * d);
    for x in &v.curve.line.points {
        assert!(whole.distance(x) >= d - OPTS.d_tol / 2.0 - sagitta, "{x} at {}", whole.distance(x));
    }
    for i in 0..v.curve.line.segment_count() {
        assert!(v.curve.line.segment_length(i) <= OPTS.spacing + 1e-9);
    }
    let scalar = offset_curve(support, std::slice::from_ref(limit), d).unwrap();
    assert_eq!(scalar.curves.len(), 1);
    close(&v.curve, &scalar.curves, support.facet_size() + OPTS.d_tol);
}

#[test]
fn l_shape_reflex_corner_is_filled_and_matches_the_scalar_offset() {
    let support = flat(0.0, 18.0, 1.0);
    let limit = on(&support, l_shape());
    let v = vectorial_offset(&support, &limit, 4.0, &OPTS).unwrap();
    assert!(v.filled > 0, "the reflex corner's gap is filled");
    assert!(v.rejected + v.unlooped > 0, "the convex corners' points are dropped");
    check(&support, &limit, 4.0);
}

#[test]
fn sphere_latitude_matches_the_scalar_offset() {
    let support = sphere_cap(30.0, 1.2, 1.0);
    let mut line = circle(p(0.0, 0.0, 30.0 * 1.1f64.cos()), 30.0 * 1.1f64.sin(), 300);
    for x in &mut line.points {
        *x = support.query().closest_point(x).point;
    }
    let limit = on(&support, line);
    check(&support, &limit, 3.0);
}

#[test]
fn bad_settings_are_errors() {
    let support = flat(0.0, 18.0, 1.0);
    let limit = on(&support, l_shape());
    for opts in [VectorialOptions { d_tol: 0.0, ..OPTS }, VectorialOptions { spacing: f64::NAN, ..OPTS }] {
        assert!(vectorial_offset(&support, &limit, 4.0, &opts).is_err());
    }
    assert!(vectorial_offset(&support, &limit, -1.0, &OPTS).is_err());
    // An offset wider than the region vanishes: an error, not a panic.
    assert!(vectorial_offset(&support, &limit, 40.0, &OPTS).is_err());
}
