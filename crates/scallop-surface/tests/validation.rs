//! Constructors reject invalid patches with the place in structured form.

mod common;

use common::{builtin_patch, p};
use scallop_geom::Point3;
use scallop_surface::{Direction, Patch, PatchLabel, SurfaceError, SurfaceSet};

fn net(rows: usize, columns: usize) -> Vec<Vec<Point3>> {
    (0..rows).map(|i| (0..columns).map(|j| p(i as f64, j as f64, ((i * j) % 3) as f64)).collect()).collect()
}

fn label(name: &str) -> PatchLabel {
    PatchLabel { index: None, name: name.to_owned() }
}

#[test]
fn bezier_constructor_checks() {
    let err = Patch::bezier("a", [2, 0], &net(3, 1), None).expect_err("degree");
    assert_eq!(err, SurfaceError::DegreeTooLow { patch: label("a"), direction: Direction::V, degree: 0 });
    let err = Patch::bezier("a", [2, 1], &net(2, 2), None).expect_err("rows");
    assert!(matches!(err, SurfaceError::ControlRows { found: 2, expected: 3, .. }), "{err:?}");
    let mut ragged = net(3, 2);
    ragged[2].push(p(0., 0., 0.));
    let err = Patch::bezier("a", [2, 1], &ragged, None).expect_err("columns");
    assert!(matches!(err, SurfaceError::ControlColumns { row: 2, found: 3, expected: 2, .. }), "{err:?}");
    let mut bad = net(3, 2);
    bad[1][0].z = f64::NEG_INFINITY;
    let err = Patch::bezier("a", [2, 1], &bad, None).expect_err("finite");
    assert!(matches!(err, SurfaceError::NonFiniteControlPoint { i: 1, j: 0, .. }), "{err:?}");
    let err = Patch::bezier("a", [2, 1], &net(3, 2), Some(&vec![vec![1.0; 2]; 2])).expect_err("weight rows");
    assert!(matches!(err, SurfaceError::WeightsShape { found: 2, expected: 3, .. }), "{err:?}");
    let err = Patch::bezier("a", [2, 1], &net(3, 2), Some(&[vec![1.0, 1.0], vec![1.0, f64::NAN], vec![1.0, 1.0]]))
        .expect_err("weight");
    assert!(matches!(err, SurfaceError::BadWeight { i: 1, j: 1, .. }), "{err:?}");
}

#[test]
fn nurbs_constructor_checks() {
    let knots = |n: usize, p: usize| -> Vec<f64> {
        // Clamped uniform knots for n control points of degree p.
        let inner = n - p;
        let mut k = vec![0.0; p + 1];
        k.extend((1..inner).map(|i| i as f64 / inner as f64));
        k.extend(vec![1.0; p + 1]);
        k
    };
    assert!(Patch::nurbs("ok", [2, 3], [knots(5, 2), knots(6, 3)], &net(5, 6), None).is_ok());
    let err = Patch::nurbs("a", [3, 1], [knots(3, 3), knots(2, 1)], &net(3, 2), None).expect_err("too few rows");
    assert!(matches!(err, SurfaceError::ControlRows { found: 3, expected: 4, .. }), "{err:?}");
    let err = Patch::nurbs("a", [2, 2], [knots(5, 2), knots(5, 2)], &net(5, 6), None).expect_err("knot count");
    assert_eq!(
        err,
        SurfaceError::KnotCount {
            patch: label("a"),
            direction: Direction::V,
            found: 8,
            expected: 9,
            control_points: 6,
            degree: 2
        }
    );
    let mut decreasing = knots(5, 2);
    decreasing.swap(3, 4);
    let err = Patch::nurbs("a", [2, 2], [decreasing, knots(5, 2)], &net(5, 5), None).expect_err("order");
    assert!(matches!(err, SurfaceError::KnotsDecreasing { direction: Direction::U, index: 4, .. }), "{err:?}");
    // Interior knot of multiplicity p + 1 = 3 (a discontinuity): at most p = 2 inside.
    let triple = vec![0., 0., 0., 0.5, 0.5, 0.5, 1., 1., 1.];
    let err = Patch::nurbs("a", [2, 2], [triple, knots(5, 2)], &net(6, 5), None).expect_err("multiplicity");
    assert!(matches!(err, SurfaceError::KnotMultiplicity { index: 3, multiplicity: 3, max: 2, .. }), "{err:?}");
    // End knot of multiplicity p + 2: a basis function would vanish.
    let err = Patch::nurbs("a", [1, 1], [vec![0., 0., 0., 1., 1.], knots(2, 1)], &net(3, 2), None)
        .expect_err("end multiplicity");
    assert!(matches!(err, SurfaceError::KnotMultiplicity { index: 0, multiplicity: 3, max: 2, .. }), "{err:?}");
}

#[test]
fn sets_need_patches_with_distinct_names() {
    assert_eq!(SurfaceSet::new(Vec::new()).expect_err("empty"), SurfaceError::EmptySet);
    let err = SurfaceSet::new(vec![builtin_patch("choi"), builtin_patch("rubio"), builtin_patch("choi")])
        .expect_err("duplicate");
    assert_eq!(
        err,
        SurfaceError::DuplicateName { patch: PatchLabel { index: Some(2), name: "choi".to_owned() }, first: 0 }
    );
    // Errors of single patches learn their index from the builder.
    let err = Patch::bezier("x", [1, 1], &net(3, 2), None).expect_err("rows").with_patch_index(4);
    assert!(err.to_string().starts_with("patch #4 \"x\": the control net has 3 rows"), "{err}");
}

#[test]
fn huge_degrees_are_refused_before_any_allocation() {
    // Issue 21: degree 2^31 tried to allocate 154 GB, 2^63 - 1 overflowed a capacity.
    for degree in [2_147_483_648usize, 9_223_372_036_854_775_807, usize::MAX, scallop_surface::tol::MAX_DEGREE + 1] {
        let err = Patch::bezier("a", [2, degree], &net(3, 3), None).expect_err("degree");
        assert!(
            matches!(err, SurfaceError::DegreeTooHigh { degree: d, direction: Direction::V, .. } if d == degree),
            "{err:?}"
        );
        let err = Patch::nurbs("a", [degree, 1], [vec![0.0; 4], vec![0.0, 0.0, 1.0, 1.0]], &net(3, 2), None)
            .expect_err("degree");
        assert!(matches!(err, SurfaceError::DegreeTooHigh { direction: Direction::U, .. }), "{err:?}");
    }
    // The cap itself is a valid degree.
    let d = scallop_surface::tol::MAX_DEGREE;
    assert!(Patch::bezier("a", [1, d], &net(2, d + 1), None).is_ok());
}
