//! Limit curves, scalar morphing and the pairing of path and tilt curves
//! (Jousselin 2020, Ch. 2 §3.2; docs/guides-curves.md): no spurious morph
//! loop, the count rule's three steps on the two-circle counterexample, the
//! swap rule, spacing within a_e + facet size on both levels.

#![allow(clippy::unwrap_used, clippy::float_cmp, reason = "tests: a panic is the failure report")]

mod common;

use std::f64::consts::TAU;

use common::*;
use scallop_guides::{Curve, Level, Support, limit_curves, morph_level, offset_curves, pair_levels};
use scallop_mesh::TriMesh;

fn radius_range(c: &Curve) -> (f64, f64) {
    let r = c.line.points.iter().map(|p| p.x.hypot(p.y));
    (r.clone().fold(f64::INFINITY, f64::min), r.fold(0.0, f64::max))
}

fn on_mesh(support: &Support, c: &Curve) -> bool {
    c.line.points.iter().all(|p| support.query().closest_point(p).distance <= 1e-6)
}

#[test]
fn morph_between_circles_has_no_spurious_loop() {
    let support = flat(0.0, 30.0, 0.5);
    let inner = vec![on(&support, circle(p(0.0, 0.0, 0.0), 10.0, 300))];
    let outer = vec![on(&support, circle(p(0.0, 0.0, 0.0), 20.0, 600))];
    let h = support.facet_size();
    for (m, r) in [(0.25, 12.5), (0.75, 17.5), (0.5, 15.0)] {
        let loops = morph_level(&support, &inner, &outer, m);
        assert_eq!(loops.len(), 1, "m = {m}: {} loops", loops.len());
        let (lo, hi) = radius_range(&loops[0]);
        assert!(lo >= r - h && hi <= r + h, "m = {m}: radii {lo}..{hi}, not {r}");
        assert!(loops[0].line.closed && on_mesh(&support, &loops[0]));
        assert!(!self_intersects_xy(&loops[0].line));
    }
}

/// Builds a planar level at `z` with a circle of radius `r` and its offsets.
fn planar_level(z: f64, r: f64, a_e: f64) -> (Support, Curve, Vec<scallop_guides::OffsetStep>) {
    let support = flat(z, r + 4.0, 0.25);
    let limit = on(&support, circle(p(0.0, 0.0, z), r, 720));
    let offsets = offset_curves(&support, std::slice::from_ref(&limit), a_e).unwrap();
    (support, limit, offsets)
}

#[test]
fn count_rule_gives_three_steps_on_the_counterexample() {
    let a_e = 4.5;
    let (s0, c0, o0) = planar_level(0.0, 10.0, a_e);
    let (s1, c1, o1) = planar_level(10.0, 12.0, a_e);
    assert_eq!((o0.len(), o1.len()), (2, 2), "offsets at 5.5, 1.0 and at 7.5, 3.0");
    let pairs = pair_levels(
        &Level { support: &s0, limit: &c0, offsets: &o0 },
        &Level { support: &s1, limit: &c1, offsets: &o1 },
        a_e,
    )
    .unwrap();
    assert_eq!(pairs.steps, 3, "the swap rule alone would give 2 steps, 5.5 mm apart");
    assert_eq!((pairs.path.len(), pairs.tilt.len()), (4, 4));
    assert!(pairs.path_morphed && pairs.tilt_morphed);
    assert_eq!(pairs.tilt.last(), Some(&c1), "the outermost tilt curve is C_n+1");
    assert_eq!(pairs.path.last(), Some(&c0));
    let h = s0.facet_size().max(s1.facet_size());
    assert!(
        pairs.path_spacing <= a_e + h && pairs.tilt_spacing <= a_e + h,
        "{} {}",
        pairs.path_spacing,
        pairs.tilt_spacing
    );
    assert!(pairs.tilt.iter().all(|c| on_mesh(&s1, c)) && pairs.path.iter().all(|c| on_mesh(&s0, c)));
    assert_eq!(pairs.projection_fallbacks, 0);
}

#[test]
fn swap_rule_keeps_the_offsets_of_the_larger_level() {
    let a_e = 4.5;
    let (s0, c0, o0) = planar_level(0.0, 10.0, a_e);
    let (s1, c1, o1) = planar_level(8.0, 20.0, a_e);
    assert!(o1.len() > o0.len());
    let pairs = pair_levels(
        &Level { support: &s0, limit: &c0, offsets: &o0 },
        &Level { support: &s1, limit: &c1, offsets: &o1 },
        a_e,
    )
    .unwrap();
    assert!(!pairs.tilt_morphed && pairs.path_morphed);
    assert_eq!(pairs.steps, o1.len());
    assert_eq!(pairs.path.len(), pairs.tilt.len());
    let h = s0.facet_size().max(s1.facet_size());
    assert!(pairs.path_spacing <= a_e + h && pairs.tilt_spacing <= a_e + h);
    assert!(pairs.path.iter().all(|c| c.line.closed && !self_intersects_xy(&c.line)));
}

/// The drafted flank offset of a pocket: a cone about the z axis, radius `r0`
/// at z = -10 opening to `r1` at z = 10, normals inward (towards the pocket).
fn drafted_flank(cx: f64, r0: f64, r1: f64) -> TriMesh {
    grid_surface(180, 20, |u, v| {
        let (a, r) = (-TAU * u, r0 + (r1 - r0) * v);
        p(cx + r * a.cos(), r * a.sin(), -10.0 + 20.0 * v)
    })
}

#[test]
fn limit_curve_of_a_tilted_level_in_a_drafted_pocket() {
    use scallop_geom::Vec3;
    let e1 = Vec3::new(1.0, 0.0, 0.2).normalize();
    let level = plane(p(0.0, 0.0, 0.0), e1, Vec3::y(), 40.0, 1.0);
    let flank = drafted_flank(0.0, 20.0, 30.0);
    let limits = limit_curves(&level, &flank);
    assert_eq!((limits.loops.len(), limits.open.len(), limits.nested), (1, 0, 0));
    let c = &limits.loops[0];
    assert!(c.signed_area() > 0.0);
    let fq = scallop_mesh::MeshQuery::new(&flank);
    assert!(c.line.points.iter().all(|x| fq.closest_point(x).distance <= 1e-9));
    assert!(on_mesh(&level, c));
    let offsets = offset_curves(&level, std::slice::from_ref(c), 4.5).unwrap();
    assert!(offsets.len() >= 4);
    assert!(offsets.iter().all(|s| s.curves.len() == 1 && s.curves[0].line.closed));
    // An island (a second, smaller cone inside) is reported as nested.
    let island = drafted_flank(5.0, 3.0, 4.0);
    let both = TriMesh::from_soup(&[flank.soup(), island.soup()].concat()).unwrap().0;
    let limits = limit_curves(&level, &both);
    assert_eq!((limits.loops.len(), limits.nested), (2, 1));
}

#[test]
fn vectorial_morph_lands_on_the_support_and_matches_the_scalar_morph() {
    // A sphere cap: the straight walks leave the support and are projected back.
    let support = sphere_cap(40.0, 0.9, 1.0);
    let lift = |r: f64, n: usize| {
        let mut c = circle(p(0.0, 0.0, 0.0), r, n);
        for x in &mut c.points {
            *x = p(x.x, x.y, (1600.0 - x.x * x.x - x.y * x.y).sqrt());
        }
        on(&support, c)
    };
    let (inner, outer) = (lift(8.0, 160), lift(24.0, 480));
    let steps = 4;
    let vect = scallop_guides::morph_vectorial(&support, &inner, &outer, steps);
    assert_eq!(vect.len(), steps - 1);
    let h = support.facet_size();
    for (k, c) in vect.iter().enumerate() {
        assert!(on_mesh(&support, c));
        let m = (k + 1) as f64 / steps as f64;
        let scalar = morph_level(&support, std::slice::from_ref(&inner), std::slice::from_ref(&outer), m);
        assert_eq!(scalar.len(), 1);
        assert!(on_mesh(&support, &scalar[0]));
        // Chord (3D) and geodesic ratios differ a little on the sphere: within two facets.
        assert!(max_distance(std::slice::from_ref(c), &scalar) <= 2.0 * h, "k = {k}");
    }
}

#[test]
fn pairing_does_not_depend_on_the_thread_count() {
    let a_e = 4.5;
    let (s0, c0, o0) = planar_level(0.0, 10.0, a_e);
    let (s1, c1, o1) = planar_level(10.0, 12.0, a_e);
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            pair_levels(
                &Level { support: &s0, limit: &c0, offsets: &o0 },
                &Level { support: &s1, limit: &c1, offsets: &o1 },
                a_e,
            )
            .unwrap()
        })
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn exact_normals_are_kept_and_checked() {
    let mesh = flat(0.0, 5.0, 1.0).mesh().clone();
    let n = mesh.vertices().len();
    let tilted = scallop_geom::Vec3::new(0.0, 0.0, 2.0);
    let s = Support::with_normals(mesh.clone(), vec![tilted; n]).unwrap();
    assert_eq!(s.vertex_normal(0), scallop_geom::Vec3::z());
    assert!(Support::with_normals(mesh.clone(), vec![tilted; n - 1]).is_err());
    assert!(Support::with_normals(mesh, vec![scallop_geom::Vec3::zeros(); n]).is_err());
}
